"""The case file's key registry: every key of every table with its unit,
default, check and source, read from the code, and the reference page
``docs/reference/keys.md`` rendered from it.

The tables are the dataclasses a :class:`~pipelay_fast.input.case.Case` is
made of, found by walking the field annotations down from ``Case``: a field
whose type is a dataclass is a table (``lay.stinger`` is two, the quadratic
:class:`~pipelay_fast.input.lay.Stinger` and the
:class:`~pipelay_fast.input.lay.RollerStinger`), any other field a key.
For each key:

* the description is its entry in its class's numpy-style ``Attributes``
  section (``name : type`` or ``name, other : type``, the description
  indented below it);
* the unit is the first bracketed group of the description's first clause
  (``[m]``, ``[N m/m]``, ``[-]`` for a pure number), clause numbers such as
  ``[5.4.4.2]`` aside; text and true/false keys need none;
* the default is the field's; where it is None, the description's
  "default ..." phrase (a default derived from other keys), else the key may
  be left out;
* the check is what the class's methods call on the key, read from their
  source: the :mod:`pipelay_fast.input.validate` helpers (``set_numbers``'s
  sign, ``choice``'s values, ``integer``'s least value, ``flag``,
  ``vector``'s length) and the messages of ``fail`` naming the key;
* the source is what the description cites: a standard's section, table or
  equation (prefixed by the standard its class names, e.g. DNVGL-ST-F101),
  API 5L, or the benchmark script that chose the default.

``python -m pipelay_fast.input.keys > docs/reference/keys.md`` writes the
page; tests/test_keys.py checks that the committed page is this rendering
and that every key is documented. Part of the input layer.
"""

from __future__ import annotations

import ast
import dataclasses
import functools
import inspect
import re
import sys
import textwrap
import typing
from dataclasses import dataclass

from .case import Case

__all__ = ["Key", "keys", "number_units", "render", "tables", "undocumented"]

REQUIRED = "required"


@dataclass(frozen=True)
class Key:
    """One key of a case file.

    Attributes
    ----------
    path : str
        Dotted path, as in ``Case.with_changes`` and error messages.
    table : str
        The table's dotted path ("" for the top level).
    owner : type
        The dataclass the key is a field of.
    kind : str
        "number" (any numeric value or list of them), "text" or "flag".
    description : str
        The key's ``Attributes`` entry, one paragraph ("" when missing).
    unit : str
        The unit ("-" for a pure number; "" when the description gives none).
    default : str
        The default as text: "required", a TOML value, a derived default, or "".
    check : str
        The checks made on construction, "; "-separated.
    source : str
        The standard's clauses and the scripts the description cites.
    """

    path: str
    table: str
    owner: type
    kind: str
    description: str
    unit: str
    default: str
    check: str
    source: str


# --------------------------------------------------------------------------- tables


def tables(root: type = Case) -> list[tuple[str, type]]:
    """(dotted path, dataclass) of every table, depth first from ``root``
    (path ""); a table of several classes once per class."""
    found = []

    def walk(cls, path):
        found.append((path, cls))
        for field, hint in _fields(cls):
            for sub in _dataclasses_in(hint):
                walk(sub, f"{path}.{field.name}" if path else field.name)

    walk(root, "")
    return found


def _fields(cls):
    """(field, resolved annotation) pairs of a dataclass's keys: its fields
    but those it derives itself (``init=False``, e.g. ``Case.given_lay``)."""
    hints = typing.get_type_hints(cls)
    return [(f, hints[f.name]) for f in dataclasses.fields(cls) if f.init]


def _leaves(hint):
    """The plain types an annotation is made of (unions and containers opened)."""
    args = typing.get_args(hint)
    if not args:
        return [hint]
    return [leaf for arg in args for leaf in _leaves(arg)]


def _dataclasses_in(hint):
    return [t for t in _leaves(hint) if isinstance(t, type) and dataclasses.is_dataclass(t)]


def _kind(hint) -> str:
    leaves = [t for t in _leaves(hint) if t not in (type(None), Ellipsis)]
    if any(t in (int, float) for t in leaves):
        return "number"
    return "flag" if leaves == [bool] else "text"


# --------------------------------------------------------------------------- keys


def keys(root: type = Case) -> list[Key]:
    """Every key of every table of ``root``, in the tables' order and each
    table's field order."""
    found = []
    for path, cls in tables(root):
        entries = _attributes(cls)
        checks = _checks(cls)
        standard = _standard(cls)
        for field, hint in _fields(cls):
            if _dataclasses_in(hint):
                continue
            text = entries.get(field.name, "")
            found.append(Key(
                path=f"{path}.{field.name}" if path else field.name, table=path, owner=cls,
                kind=_kind(hint), description=text, unit=_unit(text),
                default=_default(field, text), check="; ".join(checks.get(field.name, [])),
                source=_sources(text, standard)))
    return found


@functools.cache
def number_units() -> dict[str, str]:
    """{key: its unit} of the case's numeric keys (:func:`keys`)."""
    return {k.path: k.unit for k in keys() if k.kind == "number"}


_HEADER = re.compile(r"^(\w+(?:\s*,\s*\w+)*)\s*(?::.*)?$")


def _attributes(cls) -> dict[str, str]:
    """{field name: description} from the class's numpy-style Attributes
    section; an entry naming several fields gives each the description."""
    lines = inspect.cleandoc(cls.__doc__ or "").splitlines()
    starts = [i for i in range(len(lines) - 1)
              if lines[i].strip() == "Attributes" and set(lines[i + 1].strip()) == {"-"}]
    entries, names, body = {}, None, []

    def flush():
        if names:
            entries.update(dict.fromkeys(names, " ".join(body)))

    for i in range(starts[0] + 2 if starts else len(lines), len(lines)):
        line = lines[i]
        if not line.strip():
            continue
        if line[0].isspace():
            body.append(line.strip())
            continue
        header = _HEADER.match(line)
        next_line = lines[i + 1].strip() if i + 1 < len(lines) else ""
        if not header or (next_line and set(next_line) == {"-"}):
            break  # prose after the section, or the next section
        flush()
        names, body = [n.strip() for n in header.group(1).split(",")], []
    flush()
    return entries


def _unit(text: str) -> str:
    """The bracketed units of the description's first clause, ", "-joined."""
    first = re.split(r";\s|\.\s|\.$", text, maxsplit=1)[0]
    first = re.sub(r"``.*?``", "", first)
    units = [u for u in re.findall(r"\[([^\[\]]+)\]", first) if not re.fullmatch(r"[\d.]+", u)]
    return ", ".join(dict.fromkeys(units))


def _default(field, text: str) -> str:
    if field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING:
        return REQUIRED
    value = field.default if field.default_factory is dataclasses.MISSING else (
        field.default_factory())
    if value is not None:
        return _toml(value)
    phrase = re.search(r"\b[Dd]efaults? (?!from)(.+?)(?:;|:|\.(?:\s|$)|$)", text)
    if phrase is None:
        phrase = re.search(r"\b[Dd]efault (from .+?)(?::|;|\.(?:\s|$)|$)", text)
    return phrase.group(1).strip() if phrase else ""


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(map(_toml, value)) + "]"
    return str(value)


_STANDARD = re.compile(r"\b(DNVGL-ST-F\d+)(?:, (\d{4}) edition)?")
_SOURCE = re.compile(
    r"API 5L \(\d{4}\) Table \d+"
    r"|Sec\.\s?\d+(?:\s+(?:Table \d+-\d+|\[[\d.]*\d\]))?(?:,\s*eq\. \d+\.\d+)?"
    r"|Table \d+-\d+"
    r"|eq\. \d+\.\d+"
    r"|benchmarks/\w+\.py")


def _standard(cls) -> str:
    """The standard the class's first paragraph names, "DNVGL-ST-F101 (2017)", or ""."""
    match = _STANDARD.search((cls.__doc__ or "").split("\n\n", 1)[0])
    if match is None:
        return ""
    return match.group(1) + (f" ({match.group(2)})" if match.group(2) else "")


def _sources(text: str, standard: str) -> str:
    cited = []
    for match in _SOURCE.finditer(text):
        ref = match.group(0)
        if standard and not ref.startswith(("API", "benchmarks/")):
            ref = f"{standard} {ref}"
        cited.append(ref)
    return "; ".join(dict.fromkeys(cited))


# --------------------------------------------------------------------------- checks

_SIGNS = {"positive": "> 0", "non_negative": ">= 0", "finite": "a number"}
_CUT = "\0"  # where a formatted value stood in a message


def _checks(cls) -> dict[str, list[str]]:
    """{field name: [check, ...]} from the validation calls in the class's methods."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
    module = sys.modules[cls.__module__]
    found: dict[str, list[str]] = {}

    def add(name, check):
        if check and check not in found.setdefault(name, []):
            found[name].append(check)

    for func in (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)):
        local = {node.targets[0].id: node.value for node in ast.walk(func)
                 if isinstance(node, ast.Assign) and len(node.targets) == 1
                 and isinstance(node.targets[0], ast.Name)}
        for call in ast.walk(func):
            if isinstance(call, ast.Call) and isinstance(call.func, ast.Name):
                for name, check in _call_checks(call, local, module):
                    add(name, check)
    return found


def _call_checks(call: ast.Call, local: dict, module):
    """(field name, check) pairs of one call of a validation helper."""
    helper, args = call.func.id, call.args
    if helper == "set_numbers":
        for kw in call.keywords:
            for name in _strings(kw.value, local) if kw.arg in _SIGNS else ():
                yield name, _SIGNS[kw.arg]
        return
    if helper not in ("choice", "integer", "flag", "vector", "fail") or not args:
        return
    path = _text(args[0], local)
    name = re.sub(r"\[.*", "", path).rpartition(".")[2]
    if not name.isidentifier():
        return
    each = "each " if "[" in path else ""  # the check of a list's items
    if helper == "choice" and len(args) > 2:
        allowed = _constant(args[2], module)
        if allowed is not None:
            yield name, f"{each}one of " + ", ".join(f'"{a}"' for a in allowed)
    elif helper == "integer" and len(args) > 2:
        yield name, f"{each}an integer >= {ast.literal_eval(args[2])}"
    elif helper == "flag":
        yield name, "true or false"
    elif helper == "vector" and len(args) > 2:
        yield name, f"{each}a list of {ast.literal_eval(args[2])} numbers"
    elif helper == "fail" and len(args) > 2:
        message = _message(_text(args[2], local))
        yield name, f'"{message}"' if message else ""


def _constant(node, module):
    """The value of a literal, of a module constant, or of ``tuple(CONSTANT)``;
    None for any other expression."""
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
            and node.func.id in ("tuple", "list") and len(node.args) == 1):
        inner = _constant(node.args[0], module)
        return None if inner is None else tuple(inner)
    if isinstance(node, ast.Name):
        return getattr(module, node.id, None)
    try:
        return ast.literal_eval(node)
    except ValueError:
        return None


def _strings(node, local: dict, seen=()) -> list[str]:
    """The string constants in an expression, local names followed to their values."""
    out = []
    for sub in ast.walk(node):
        if isinstance(sub, ast.Constant) and isinstance(sub.value, str):
            out.append(sub.value)
        elif isinstance(sub, ast.Name) and sub.id in local and sub.id not in seen:
            out += _strings(local[sub.id], local, (*seen, sub.id))
    return out


def _text(node, local: dict) -> str:
    """A string or f-string's text: local string constants filled in, any
    other formatted value as a cut mark."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.Name) and isinstance(local.get(node.id), ast.Constant):
        return _text(local[node.id], local)
    if isinstance(node, ast.JoinedStr):
        return "".join(_text(v.value if isinstance(v, ast.FormattedValue) else v, local)
                       for v in node.values)
    return _CUT


def _message(text: str) -> str:
    """A failure message up to its first ": " or formatted value; "" when
    the value is cut mid-sentence (only "key = value" is dropped cleanly)."""
    text = text.split(": ", 1)[0]
    head, cut, _ = text.partition(_CUT)
    if cut and not head.endswith(" = "):
        return ""
    head = head.removesuffix(" = ")
    if head.count("(") > head.count(")"):  # cut inside parentheses: drop them
        head = head[:head.rfind("(")]
    return head.strip()


def undocumented(found: list[Key]) -> list[str]:
    """What is missing from the keys' documentation, one line per key: no
    ``Attributes`` entry, or a number without a unit."""
    problems = []
    for key in found:
        where = f"{key.path} ({key.owner.__module__}.{key.owner.__name__})"
        if not key.description:
            problems.append(f"{where}: no entry in the Attributes section of its docstring")
        elif key.kind == "number" and not key.unit:
            problems.append(f"{where}: a number without a [unit] in its description "
                            "([-] for a pure number)")
    return problems


# --------------------------------------------------------------------------- page

_INTRO = """\
# Case-file keys

<!-- Generated by `python -m pipelay_fast.input.keys > docs/reference/keys.md`
from the table dataclasses in pipelay_fast/input/; do not edit by hand
(tests/test_keys.py checks it). -->

Every key of a case file, table by table, read from the code: the unit and
description from each table's dataclass docstring, the default from the
dataclass, the check from the validation its class runs on construction
(in quotes, the words of an error it raises), the source from the clauses
and scripts the description cites. Values are
SI; heights x are measured from the seabed. A default of "required" must be
given; an empty default means the key may be left out, with the meaning its
description gives. A bad value raises `ValueError` naming the key by the
dotted path shown here.
"""


def render() -> str:
    """The reference page: one section per table, a table of the keys, then
    each key's description."""
    by_table: dict[tuple[str, type], list[Key]] = {}
    for key in keys():
        by_table.setdefault((key.table, key.owner), []).append(key)
    parts = [_INTRO]
    for (table, cls), rows in by_table.items():
        title = f"`[{table}]`" if table else "Top level"
        variants = [c for t, c in tables() if t == table]
        if len(variants) > 1:
            title += f" ({cls.__name__})"
        summary = inspect.cleandoc(cls.__doc__ or "").split("\n\n", 1)[0].replace("\n", " ")
        parts += [f"## {title}", "", _markdown(summary), "",
                  "| key | unit | default | check | source |", "| --- | --- | --- | --- | --- |"]
        parts += [f"| `{k.path}` | {_cell(k.unit)} | {_cell(k.default)} | {_cell(k.check)} | "
                  f"{_cell(k.source)} |" for k in rows]
        parts.append("")
        shared: dict[str, list[str]] = {}  # one entry documents several keys
        for k in rows:
            shared.setdefault(k.description, []).append(f"`{k.path}`")
        parts += [f"- {', '.join(paths)}: {_markdown(text)}" for text, paths in shared.items()]
        parts.append("")
    return "\n".join(parts)


def _markdown(text: str) -> str:
    """reST roles and double backquotes as Markdown code."""
    text = re.sub(r":(?:mod|func|class|meth|attr):`~?([^`]+)`", r"`\1`", text)
    return text.replace("``", "`")


def _cell(text: str) -> str:
    """Text for a Markdown table cell: pipes escaped, code kept."""
    return _markdown(text).replace("|", "\\|")


def main() -> None:
    """Print the reference page (``python -m pipelay_fast.input.keys``)."""
    sys.stdout.write(render())


if __name__ == "__main__":
    main()
