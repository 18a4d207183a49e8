"""The tuning constants of pipelay_fast, named or inline: a reproducible count.

    python benchmarks/constants.py [TREE] [--markdown]

TREE is a checkout (default: this one); the package is ``TREE/pipelay_fast``.
It prints each constant (module, line, name or literal, its value, and the
comment above or beside it, if any), then the count; ``--markdown`` prints
the same as a markdown table (for a closing note).

A tuning constant is a number that sets how the code works rather than what
it models: a tolerance, a cap, a budget, a step or growth rule, a mesh or
sampling density, a cache or chunk size, a progress interval. Counted:

1. A module-level assignment to an UPPER_CASE name (a leading underscore
   allowed) whose value holds a numeric literal: one per name (a tuple of
   names assigned a tuple of numbers counts each name). A name assigned only
   other names, or their inverse (``1.0 / BACKTRACK``), is *derived*: listed,
   not counted.
2. A numeric literal in a function's body, its default arguments or its
   decorators, unless a rule below or the exclusion table says why it is not
   a tuning number.

Not counted (the rules; each exclusion of the table names its reason):

- 0, 1, 2 and 0.5 and their negatives as arithmetic (halves, doubles,
  signs, floors of one), unless listed in ``TRIVIAL_TUNING`` (a tuning
  factor written as 2 or 0.5; found by reading, so an older tree's may be
  missing: see the note at the end of the output);
- indices and slice bounds (positions, not settings);
- the shape argument of ``np.zeros``/``np.empty``/``np.ones``/``np.full``;
- the exponent of ``**`` (a power or a root of a formula);
- a literal inside an f-string (a display unit: ``/ 1e3`` for kN);
- 3 compared with a dimension (``nd == 3``: space is three-dimensional);
- the exclusion table below: closed forms and their coefficients (shape
  functions, series, quadrature weights), a standard's values
  (DNV-ST-F101), unit conversions, angle ranges of geometry, machine
  constants, index and layout constants, and presentation (figure sizes,
  column widths);
- class attributes (the case keys' defaults: user parameters, documented
  in docs/reference/keys.md, not constants of the code).
"""

from __future__ import annotations

import argparse
import ast
import fnmatch
import pathlib
import sys

TRIVIAL = (0, 1, 2, 0.5)  # and their negatives


def _table(text: str) -> dict:
    """A table of ``glob | glob [| value [| text]] | reason`` lines (``#``
    a comment line): the key's fields (a value parsed as a number unless it
    is ``*``) -> the reason."""
    rows = {}
    for line in text.strip().splitlines():
        if line.startswith("#"):
            continue
        *key, reason = (f.strip() for f in line.split(" | "))
        rows[tuple(f if i < 2 or f == "*" or i == 3 else ast.literal_eval(f)
                   for i, f in enumerate(key))] = reason
    return rows


# Module-level names that are not tuning constants: (module glob, name glob) -> reason.
EXCLUDED_NAMES = _table("""
*kernels/layout.py | * | index, column and status-code layout
*kernels/newton.py | I_* | index layout (info vector)
*kernels/newton.py | N_INFO | index layout (info vector)
*kernels/newton.py | B_* | index layout (boundaries)
*kernels/contact.py | ST_* | index layout (stinger columns)
*kernels/contact.py | N_STINGER | index layout (stinger columns)
*kernels/element*.py | * | Gauss points and weights, work-array layout (the element)
*kernels/grading.py | NOT_ANCHOR | a code (boundary_map's kind)
*kernels/tuning.py | EPS | machine epsilon of double precision (not a choice)
*grades.py | MPA | unit conversion
*grades.py | _API | the standard's grade table (API 5L)
*checks.py | * | DNV-ST-F101's factors and limits (the standard's values)
*plot.py | * | presentation (figure size, dpi)
*select_format.py | LEGEND_WIDTH | presentation (text width)
*runner.py | LOG_STYLE | presentation (a log's bar width and height)
*cli.py | DISPLAY_UNITS | unit conversion
*cli.py | EXIT_* | exit codes
*limits.py | _DISPLAY | unit conversion
*laytable.py | LAY_TABLE_COLUMNS | unit conversion and display format
*frame.py | _EXACT | a precision that makes the decimal sum exact (its comment)
*study/limits.py | DEFAULT_MAX_UTILISATION | the unity check (utilisation 1)
""")

# Inline literals that are not tuning numbers: (module glob, function glob, value or "*") -> reason.
EXCLUDED_INLINE = _table("""
# closed forms and their coefficients
*kernels/element*.py | * | * | the element: shape functions, Gauss rule, work layout
*kernels/geometry.py | * | * | cubic Hermite interpolation and its derivatives
*kernels/bed.py | bed_height | * | cubic Hermite interpolation of the profile
*profile.py | bed_heights | * | cubic Hermite interpolation of the profile
*kernels/contact.py | tip_geometry | * | cubic Hermite interpolation
*kernels/supports.py | turned_curve | 4.0 | the quadratic's discriminant b^2 - 4ac
*kernels/newton.py | _work | * | band storage's rows (3 kl + 1) and shapes
*kernels/newton.py | _friction_answer | 4 | band width 4 nd + 1
*kernels/newton.py | system_* | * | band widths 4 nd + 1 (9, 13)
*kernels/system.py | system_* | * | band widths 4 nd + 1 (9, 13)
*kernels/system.py | * | 4 | band width 4 nd + 1
*kernels/newton.py | _to_nodal_* | 4 | band width 4 nd + 1
*kernels/newton.py | _roundoff_ratio | 4 | band width 4 nd + 1
*beam.py | bending_dominated | 3.0 | the heavy elastica's length (EI/w)^(1/3)
*beam.py | _span | 24.0 | the weightless beam's span w L^4 / (24 EI)
*beam.py | _span | 0.25 | a fourth root
*bed_guess.py | laid_on_foundation | 4.0 | the foundation length (4 EI / k)^(1/4)
*bed_guess.py | laid_on_foundation | 3 | a second difference's stencil: 3 intervals
*bed_guess.py | laid_on_foundation | 5 | pentadiagonal band storage: 5 rows
*boundaries.py | _gap_closure | * | the power series' coefficients
*friction.py | drag_share | * | the integral's closed forms and Simpson's rule
*friction.py | friction_laid_length | 4.0 | the foundation length (4 EI ...)^(1/4)
*friction.py | friction_laid_length | 0.25 | a fourth root
*problem.py | _mesh_sizes | 4.0 | the foundation length (4 EI / k)^(1/4)
*problem.py | _mesh_sizes | 0.25 | a fourth root
*problem.py | _mesh_stats | 3.0 | the heavy elastica's length (EI/w)^(1/3)
*problem.py | friction_laid_length | * | the foundation length (4 EI ...)^(1/4)
*problem.py | _onto_stinger | 3.0 | cubic Hermite
*warm.py | _onto_stinger | 3.0 | cubic Hermite
*parabola.py | * | 4.0 | the parabola's arc length and the quadratic's root
*pipe.py | * | * | section areas and second moments (pi D^2 / 4, pi D^4 / 64)
*case.py | *_area | 4.0 | section areas (pi D^2 / 4)
*case.py | second_moment | * | pi D^4 / 64
* | curvature | 1.5 | a curve's curvature (1 + x'^2)^(3/2)
* | shape | 1.5 | a curve's curvature (1 + x'^2)^(3/2)
*limits.py | stinger_bending_strain | 1.5 | a curve's curvature (1 + x'^2)^(3/2)
*results.py | liftoff_reaction | * | a linear load's resultant h (2 p0 + p1) / 6
*results.py | build_profile | 3.0 | von Mises' 3 tau^2
*results.py | interior_peak | 3 | a peak has 3 samples
*design.py | interior_peak | 3 | a peak has 3 samples
*select.py | _select_group | 3 | a minimum inside needs 3 grid points
*select.py | _select_group | 100 | per cent
*sensitivity.py | hermite_root | * | the cubic Hermite's coefficients
*checks.py | hardening_beta | * | DNV-ST-F101 eq. 5.13's beta
*checks.py | pressure_containment_resistance | * | DNV-ST-F101 eq. 5.8 (1.15, 2/sqrt 3)
*checks.py | collapse_pressure | 3 | DNV-ST-F101 eq. 5.11, a cube
*checks.py | lcc_utilisation | * | DNV-ST-F101 eq. 5.19-5.20
# geometry and conventions
*environment.py | __post_init__ | 180.0 | angle range of a heading [deg]
*environment.py | __post_init__ | 360.0 | angle range of a heading [deg]
* | _check_trim | 90.0 | a right angle
* | _check_top_angle | 90.0 | a right angle
*trim.py | * | 90.0 | a right angle
*rollers.py | __post_init__ | 3 | a roller's three numbers (z, x, kind)
*case.py | __post_init__ | 3 | a vector in space
*lay.py | __post_init__ | 3 | a vector in space
*model.py | dimension_of | 3 | the dimension of space
*problem.py | _problem | 3 | the dimension of space
# display and identities
*cli.py | * | * | display units
*plot.py | * | * | presentation
*select_format.py | * | * | presentation
*select.py | format_selection | * | presentation
*select.py | _mpa | * | display units
*results.py | __repr__ | * | display units
""")

# Literals among TRIVIAL that are tuning factors, not arithmetic:
# (module glob, function glob, value, text of the line) -> what they set.
TRIVIAL_TUNING = _table("""
*beam.py | _span | 2.0 | 2.0 * max( | the root's bracket: twice the larger limit's span
*guess.py | _on_profile | 0.5 | 0.5 * (g.laid | the foundation beam's end: at most half way up
*problem.py | _guess | 2.0 | 2.0 * math.sqrt | the default laid pipe: twice the flexural length
*continuation.py | newton_with_fallback | 0.5 | largest=0.5 | the homotopy's largest step
""")

ARRAY_MAKERS = {"zeros", "empty", "ones", "full"}


def _comment(lines: list[str], lineno: int) -> str:
    """The comment beside line ``lineno`` (1-based), else the comment lines just above it."""
    line = lines[lineno - 1]
    if "#" in line:
        return line.split("#", 1)[1].strip()
    above = []
    k = lineno - 2
    while k >= 0 and lines[k].strip().startswith("#"):
        above.insert(0, lines[k].strip().lstrip("#").strip())
        k -= 1
    return " ".join(above)


def _match(table: dict, module: str, *keys) -> str | None:
    for pattern, reason in table.items():
        mod, rest = pattern[0], pattern[1:]
        if not fnmatch.fnmatch(module, mod):
            continue
        ok = True
        for k, (want, have) in enumerate(zip(rest, keys, strict=False)):
            if want == "*":
                continue
            if k == 2:
                ok = want in have
            elif isinstance(want, str):
                ok = fnmatch.fnmatch(str(have), want)
            else:
                ok = type(want) is type(have) and want == have
            if not ok:
                break
        if ok:
            return reason
    return None


def _numbers(node) -> list:
    return [n.value for n in ast.walk(node) if isinstance(n, ast.Constant)
            and isinstance(n.value, (int, float)) and not isinstance(n.value, bool)]


def _is_upper(name: str) -> bool:
    bare = name.lstrip("_")
    return bool(bare) and bare[0].isalpha() and bare == bare.upper()


def _parents(tree) -> dict:
    up = {}
    for node in ast.walk(tree):
        for child in ast.iter_child_nodes(node):
            up[child] = node
    return up


def _generic(node, up) -> str | None:
    """Why an inline literal is not a tuning number by the rules, or None."""
    child, parent = node, up.get(node)
    while parent is not None:
        if isinstance(parent, ast.Subscript) and child is parent.slice:
            return "index"
        if isinstance(parent, ast.Slice):
            return "index"
        if isinstance(parent, ast.JoinedStr):
            return "display"
        if (isinstance(parent, ast.BinOp) and isinstance(parent.op, ast.Pow)
                and child is parent.right):
            return "exponent"
        if isinstance(parent, ast.Call):
            f = parent.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if name in ARRAY_MAKERS and parent.args and child is parent.args[0]:
                return "array shape"
            break
        if isinstance(parent, ast.Compare) and node.value == 3:
            names = {n.id for n in ast.walk(parent) if isinstance(n, ast.Name)}
            if names & {"nd", "dimension", "dim"} or any(
                    isinstance(n, ast.Call) and getattr(n.func, "id", "") == "dimension_of"
                    for n in ast.walk(parent)) or any(
                    isinstance(n, ast.Attribute) and n.attr == "nd" for n in ast.walk(parent)):
                return "dimension"
        if isinstance(parent, (ast.stmt, ast.Lambda)):
            break
        child, parent = parent, up.get(parent)
    return None



def inventory(tree_dir: pathlib.Path) -> tuple[list[dict], list[dict]]:
    """(counted constants, derived names) of the package under ``tree_dir``."""
    root = tree_dir / "pipelay_fast"
    counted, derived = [], []
    for path in sorted(root.rglob("*.py")):
        module = str(path.relative_to(tree_dir))
        src = path.read_text()
        lines = src.splitlines()
        tree = ast.parse(src)
        for stmt in tree.body:  # 1. module-level names
            targets, value = [], None
            if isinstance(stmt, ast.Assign):
                targets, value = stmt.targets, stmt.value
            elif isinstance(stmt, ast.AnnAssign) and stmt.value is not None:
                targets, value = [stmt.target], stmt.value
            for target in targets:
                pairs = []
                if isinstance(target, ast.Name):
                    pairs = [(target.id, value)]
                elif isinstance(target, ast.Tuple) and isinstance(value, ast.Tuple):
                    pairs = [(t.id, v) for t, v in zip(target.elts, value.elts, strict=False)
                             if isinstance(t, ast.Name)]
                for name, val in pairs:
                    if not _is_upper(name) or _match(EXCLUDED_NAMES, module, name):
                        continue
                    nums = _numbers(val)
                    if not nums:
                        if isinstance(val, ast.Name) and _is_upper(val.id):
                            derived.append({"module": module, "line": stmt.lineno, "name": name,
                                            "value": val.id, "why": ""})
                        continue
                    row = {"module": module, "line": stmt.lineno, "name": name,
                           "value": ast.unparse(val), "why": _comment(lines, stmt.lineno)}
                    plain = isinstance(val, ast.Constant) or (
                        isinstance(val, ast.UnaryOp) and isinstance(val.operand, ast.Constant))
                    if (plain or any(abs(v) not in TRIVIAL for v in nums)
                            or isinstance(val, ast.Tuple)):
                        counted.append(row)
                    elif isinstance(val, (ast.Name, ast.BinOp, ast.UnaryOp, ast.Attribute)):
                        derived.append(row)
        up = _parents(tree)
        seen = set()
        for fn in ast.walk(tree):  # 2. inline literals
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(fn):
                if not (isinstance(node, ast.Constant) and isinstance(node.value, (int, float))
                        and not isinstance(node.value, bool)) or id(node) in seen:
                    continue
                seen.add(id(node))
                owner = fn.name
                value = node.value
                if isinstance(up.get(node), ast.UnaryOp) and isinstance(up[node].op, ast.USub):
                    value = -value
                tuning = _match(TRIVIAL_TUNING, module, owner, node.value,
                                lines[node.lineno - 1])
                if not tuning:
                    if abs(value) in TRIVIAL:
                        continue
                    if _generic(node, up) or _match(EXCLUDED_INLINE, module, owner, node.value):
                        continue
                counted.append({"module": module, "line": node.lineno,
                                "name": f"{owner}: {value!r}",
                                "value": lines[node.lineno - 1].strip(),
                                "why": tuning or _comment(lines, node.lineno)})
    # a nested function's literals are seen once, by the outermost function walked first
    counted.sort(key=lambda r: (r["module"], r["line"]))
    return counted, derived


def _cell(text: str, width: int = 90) -> str:
    text = text.replace("|", "\\|")
    return text if len(text) <= width else text[:width - 3] + "..."


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tree", nargs="?", default=str(pathlib.Path(__file__).resolve().parents[1]))
    ap.add_argument("--markdown", action="store_true", help="print a markdown table")
    args = ap.parse_args(argv)
    counted, derived = inventory(pathlib.Path(args.tree))
    if args.markdown:
        print("| # | module | line | name or literal | value | why (comment) |")
        print("|---|---|---|---|---|---|")
        for i, r in enumerate(counted, 1):
            print(f"| {i} | {r['module']} | {r['line']} | {_cell(r['name'], 40)} | "
                  f"{_cell(r['value'], 60)} | {_cell(r['why'])} |")
        print()
        print("Derived (named from other constants, not counted): "
              + ", ".join(f"{r['name']} = {r['value']}" for r in derived))
    else:
        for r in counted:
            print(f"{r['module']}:{r['line']}: {r['name']} = {_cell(r['value'], 60)}"
                  f"  # {_cell(r['why'], 100)}")
        print("derived:", ", ".join(f"{r['name']} = {r['value']}" for r in derived))
    print(f"\n{len(counted)} tuning constants ({len(derived)} derived names not counted)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
