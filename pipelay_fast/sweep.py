"""Sweep files: a base case, scenes, and the values to vary, expanded into cases.

A sweep file is TOML (examples in ``sweeps/``)::

    name = "quick"                   # default: the file stem
    case = "j125"                    # base case: a bundled example or a path
                                     # relative to this file
    [set]                            # dotted case keys set in every case
    "solver.element_length" = 8.0

    [vary]                           # axes: a list, or a range table
    a = { start = -0.0009, stop = -0.0021, num = 13 }       # 1/m, ends included
    current_speed = [0.0, 1.0]                             # m/s
    current_heading = { start = 0.0, stop = 90.0, step = 45.0 }  # deg

    [[scenes]]                       # optional; default one scene named after the case
    name = "S67"                     # letters, digits, "_" and "-": the partition name
    case = "s67"
    water_depth = 67.0               # m
    stinger_lower = [41.5, 265.0]    # (x, z) m; stinger_upper likewise
    reference_a = -0.0012            # 1/m, a published choice shown by `select`
    set = { "seabed.lateral_friction" = 0.3 }
    vary = { a = [-0.0011, -0.0012] }   # replaces the file's axis of that name

Axes (the inputs that vary, with their summary column): ``a`` (``a``, 1/m; S-lay
scenes only, J-lay scenes ignore it), a roller stinger's ``stinger_radius``
(m, rollers placed on a radius) and ``roller_shift`` (m, the heights of
``lay.stinger.shifted`` shifted), ``current_speed`` (m/s),
``current_heading`` (``current_heading_deg``, deg), ``top_tension``,
``bottom_tension`` (``given_top_tension``, ``given_bottom_tension``, N) and
``pipe_length`` (``given_pipe_length``, m); a tension axis replaces whichever
tension the base case gives. Scene keys: ``case``, ``method`` ("S" or "J"),
``water_depth``, ``stinger_lower``, ``stinger_upper``, ``top`` (J-lay hang-off
(x, z), m), ``top_angle`` (deg), ``reference_a``, ``set`` and ``vary``.

A structural mistake (unknown key, a value of the wrong type, a bad range, a
scene whose base case is invalid) refuses the whole file with a ValueError
naming the key. A combination of axis values that makes an invalid case (a
negative tension, a stinger dipping below the seabed) is kept as a case with
its error message: the sweep records it as a failed row.

A ``[target]`` table (or a scene's ``target``, which replaces it) makes every
case of the scenes a target solve (:func:`pipelay_fast.solve_for`)::

    [target]
    tip_clearance = 0.3              # one summary column and its goal (SI)
    vary = "lay.top_tension"         # the case key solved for
    bounds = [400e3, 1500e3]         # its bracket

The key solved for must not be one that an axis varies; its value is the
summary's ``target_value`` and the target itself its ``target`` (text).

Cases that differ only in the chain axis (``a``, a roller stinger's radius or
shift; for J-lay the first varied of current speed, tension, heading) form a
chain, solved in order with warm starts.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import numbers
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

import pandas as pd

from ._validate import fail, from_toml, get_path, put_path, reject_unknown
from .case import Case, load_case, with_tables
from .results import remember_case_id, stinger_columns, tables_id
from .target import target_columns, unit_text

__all__ = ["AXES", "Scene", "Sweep", "SweepCase", "chains", "load_sweep"]

# axis name -> (case key, summary column, unit)
AXES = {
    "a": ("lay.stinger.a", "a", "1/m"),
    "stinger_radius": ("lay.stinger.radius", "stinger_radius", "m"),
    "roller_shift": ("lay.stinger.height_shift", "roller_shift", "m"),
    "current_speed": ("environment.current.speed", "current_speed", "m/s"),
    "current_heading": ("environment.current.heading", "current_heading_deg", "deg"),
    "top_tension": ("lay.top_tension", "given_top_tension", "N"),
    "bottom_tension": ("lay.bottom_tension", "given_bottom_tension", "N"),
    "pipe_length": ("lay.pipe_length", "given_pipe_length", "m"),
}
TENSION_AXES = ("top_tension", "bottom_tension", "pipe_length")
# the stinger's design axes, which `select` chooses a value of: the quadratic
# stinger's a, a roller stinger's radius (rollers placed on a radius) or the
# shift of its rollers' heights
DESIGN_AXES = ("a", "stinger_radius", "roller_shift")
# the chain axis is the first of these that a scene varies
CHAIN_ORDER = (*DESIGN_AXES, "current_speed", "top_tension", "bottom_tension", "pipe_length",
               "current_heading")
# a chain longer than this is cut into pieces (each starts cold), so that one
# long axis still spreads over the workers; independent of the worker count
MAX_CHAIN_LENGTH = 64
# the given tension's columns of the summary table (whichever the case gives), with units
INPUT_UNITS = {AXES[name][1]: AXES[name][2] for name in TENSION_AXES}
# a target solve's columns: the target as text, the value found for its key
TARGET_UNITS = {"target": "", "target_value": "SI"}

_SCENE_GEOMETRY = {  # scene key -> case key
    "water_depth": "environment.water_depth",
    "stinger_lower": "lay.stinger.lower",
    "stinger_upper": "lay.stinger.upper",
    "top": "lay.top",
    "top_angle": "lay.top_angle",
}
_SCENE_KEYS = ("name", "case", "method", *_SCENE_GEOMETRY, "reference_a", "set", "vary",
               "target")
_FILE_KEYS = ("name", "description", "case", "set", "vary", "target", "scenes")
_NAME = re.compile(r"^[A-Za-z0-9_-]+$")


# --------------------------------------------------------------------------- data


@dataclass(frozen=True)
class Scene:
    """One scene: a validated base case, the axes it varies, a reference ``a``.

    Attributes
    ----------
    name : str
        Partition name.
    case : Case
        Base case (the file's ``set`` and the scene's geometry applied).
    axes : dict
        Axis name -> tuple of values (SI, see :data:`AXES`), in sweep order.
    reference_a : float
        A published stinger curvature [1/m] to print beside the chosen one; NaN if none.
    target : dict or None
        The target solve of every case: "column", "goal" (SI), "vary" (a case
        key), "bounds" (lo, hi); None: plain solves.
    """

    name: str
    case: Case
    axes: dict
    reference_a: float = math.nan
    target: dict | None = None
    _tables: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "_tables", self.case.to_dict())

    @property
    def chain_axis(self) -> str | None:
        """The axis along which this scene's cases are warm-started."""
        return next((n for n in CHAIN_ORDER if len(self.axes.get(n, ())) > 1), None)

    def case_for(self, values: Mapping[str, float]) -> Case:
        """The base case with axis values (axis name -> value) applied; ValueError if invalid.

        The same as ``self.case.with_changes(...)`` (no axis key has a derived
        default that follows it) without re-reading the base case each time.
        """
        return self._case_and_id(values)[0]

    def _case_and_id(self, values: Mapping[str, float]) -> tuple[Case, str]:
        """:meth:`case_for` and its :func:`.results.case_id`, both from the
        base case's tables with the axis values put in (only the tables
        they change validated anew, :func:`.case.with_tables`; the id hashes
        those tables, which are the case's ``to_dict()``: tested)."""
        tables, changes = self._tables_for(values)
        case = with_tables(self.case, tables, {key.split(".")[0] for key in changes})
        cid = tables_id(tables)
        remember_case_id(case, cid)
        return case, cid

    def _tables_for(self, values: Mapping[str, float]) -> tuple[dict, dict]:
        """The base case's tables with the axis values put in, and the
        changes (dotted key -> value) that put them."""
        changes = _changes(values)
        tables = _copy_tables(self._tables)
        for key, value in changes.items():
            put_path(tables, key, value)
        return tables, changes

    def to_spec(self) -> dict:
        """JSON-able description, read back by :meth:`Sweep.from_spec`."""
        return {"name": self.name, "case": self.case.to_dict(),
                "axes": {k: list(v) for k, v in self.axes.items()},
                "reference_a": None if math.isnan(self.reference_a) else self.reference_a,
                "target": None if self.target is None else {**self.target,
                                                            "bounds": list(self.target["bounds"])}}

    @property
    def target_text(self) -> str:
        """The target as the summary's ``target`` column writes it ("" without one)."""
        t = self.target
        if t is None:
            return ""
        return (f"{t['column']} = {t['goal']!r}{unit_text(t['column'])} by {t['vary']} in "
                f"{list(t['bounds'])}")


class SweepCase:
    """One case of an expanded sweep: its scene, chain, place and axis values.

    The case itself is built (and validated) on first use, in the worker that
    solves it: ``case`` is None when the axis values make an invalid case,
    ``error`` then holds the validation message and ``case_id`` hashes the
    requested inputs. ``inputs`` are the summary's input columns (method, a,
    water_depth, ...).
    """

    __slots__ = ("_built", "chain", "position", "source", "values")

    def __init__(self, source: Scene, chain: str, position: int, values: dict):
        self.source, self.chain, self.position, self.values = source, chain, position, values
        self._built = None

    def __getstate__(self):
        return {name: getattr(self, name) for name in self.__slots__}

    def __setstate__(self, state):
        for name, value in state.items():
            setattr(self, name, value)

    def __repr__(self):
        return f"SweepCase({self.scene!r}, {self.chain!r}, {self.position}, {self.values})"

    @property
    def scene(self) -> str:
        return self.source.name

    def _build(self) -> tuple:
        if self._built is None:
            try:
                case, cid = self.source._case_and_id(self.values)
                self._built = (case, "", _with_target(cid, self.source))
            except ValueError as err:
                self._built = (None, str(err),
                               _with_target(_raw_id(self.source, self.values), self.source))
        return self._built

    @property
    def case(self) -> Case | None:
        return self._build()[0]

    @property
    def error(self) -> str:
        return self._build()[1]

    @property
    def case_id(self) -> str:
        return self._build()[2]

    @property
    def inputs(self) -> dict:
        return _inputs(self.source, self.case, self.values)


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep file: its name and scenes."""

    name: str
    scenes: tuple[Scene, ...]
    description: str = ""
    source: str = ""
    _cases: list = field(default_factory=list, compare=False, repr=False)

    def scene(self, name: str) -> Scene:
        for scene in self.scenes:
            if scene.name == name:
                return scene
        raise KeyError(f"sweep {self.name!r} has no scene {name!r}")

    def cases(self) -> list[SweepCase]:
        """Every case, scene by scene, each chain's cases together in chain order
        (not yet built: see :class:`SweepCase`)."""
        if not self._cases:
            self._cases.extend(c for scene in self.scenes for c in _expand(scene))
        return self._cases

    def case_table(self) -> pd.DataFrame:
        """One row per case (each case built): scene, case_id, chain, position,
        inputs, error."""
        rows = [{"scene": c.scene, "case_id": c.case_id, "chain": c.chain,
                 "position": c.position, **c.inputs, "error": c.error} for c in self.cases()]
        table = pd.DataFrame(rows)
        twice = table[table["case_id"].duplicated(keep=False)]
        if not twice.empty:
            raise ValueError(f"scenes {', '.join(sorted(set(twice['scene'])))} give the same "
                             f"case(s): {', '.join(sorted(set(twice['case_id'])))}")
        return table

    def to_spec(self) -> dict:
        return {"name": self.name, "description": self.description,
                "scenes": [scene.to_spec() for scene in self.scenes]}

    @classmethod
    def from_spec(cls, spec: Mapping) -> Sweep:
        """The sweep stored by :meth:`to_spec` (in a results directory's ``sweep.json``)."""
        scenes = tuple(
            Scene(s["name"], load_case(s["case"]),
                  {k: tuple(v) for k, v in s["axes"].items()},
                  math.nan if s.get("reference_a") is None else float(s["reference_a"]),
                  _spec_target(s.get("target")))
            for s in spec["scenes"])
        return cls(spec["name"], scenes, spec.get("description", ""))


# --------------------------------------------------------------------------- loading


def load_sweep(source: str | os.PathLike | Mapping, *, base_dir=None) -> Sweep:
    """Read and check a sweep file (TOML path) or a dict of the same keys.

    Relative case paths are taken from the sweep file's folder (``base_dir``
    for a dict, default the current folder). Raises ValueError naming the key
    (prefixed by the file name) for any structural mistake.
    """
    if isinstance(source, Mapping):
        return _sweep_from(source, Path(base_dir or "."), "sweep", "")
    path = Path(source)
    return from_toml(path, lambda tables: _sweep_from(tables, path.parent, path.stem, str(path)))


def _sweep_from(tables: Mapping, folder: Path, default_name: str, source: str) -> Sweep:
    reject_unknown(tables, _FILE_KEYS, "")
    name = tables.get("name", default_name)
    _check_name("name", name)
    description = tables.get("description", "")
    if not isinstance(description, str):
        fail("description", description, "must be a string")
    common = _dotted("set", tables.get("set", {}))
    axes = _axes("vary", tables.get("vary", {}))
    scene_tables = tables.get("scenes")
    if scene_tables is None:
        if "case" not in tables:
            raise ValueError("missing key case (the base case) or [[scenes]]")
        scene_tables = [{"name": _scene_name(tables["case"])}]
    if not isinstance(scene_tables, list) or not scene_tables:
        fail("scenes", scene_tables, "must be a non-empty array of tables [[scenes]]")
    target = _target("target", tables["target"]) if "target" in tables else None
    scenes = []
    for i, table in enumerate(scene_tables):
        scenes.append(_scene(f"scenes[{i}]", table, tables.get("case"), folder, common, axes,
                             target))
    names = [s.name for s in scenes]
    bases = [{**s.case.to_dict(), "name": ""} for s in scenes]
    for i, scene_name in enumerate(names):
        if scene_name in names[:i]:
            fail(f"scenes[{i}].name", scene_name, "is used by an earlier scene")
        if bases[i] in bases[:i]:
            fail(f"scenes[{i}]", scene_name, f"has the same case as scene "
                 f"{names[bases.index(bases[i])]!r}: vary its inputs in one scene instead")
    return Sweep(name, tuple(scenes), description, source)


def _scene(path, table, default_case, folder, common, axes, target) -> Scene:
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table")
    reject_unknown(table, _SCENE_KEYS, f"{path}.")
    if "name" not in table:
        raise ValueError(f"missing key {path}.name")
    name = table["name"]
    _check_name(f"{path}.name", name)
    source = table.get("case", default_case)
    if source is None:
        raise ValueError(f"missing key {path}.case (or a top-level case)")
    base = _base_case(f"{path}.case" if "case" in table else "case", source, folder)
    scene_axes = {**axes, **_axes(f"{path}.vary", table.get("vary", {}))}
    changes = dict(common)
    method = table.get("method", base.lay.method)
    if method not in ("S", "J"):
        fail(f"{path}.method", method, "must be 'S' or 'J'")
    # the quadratic stinger's top is its upper end; J-lay and a roller
    # stinger have a top of their own and no stinger ends
    curve = method == "S" and not base.lay.has_rollers
    misplaced = ("top",) if curve else ("stinger_lower", "stinger_upper")
    for key in misplaced:
        if key in table:
            fail(f"{path}.{key}", table[key], f"does not apply to a scene with method = "
                 f"{method!r}" + (" (the S-lay top is stinger_upper)" if curve else
                                  " on rollers (give top)" if method == "S" else ""))
    if method == "J" and base.lay.method == "S":
        changes.update({"lay.method": "J", "lay.stinger": None, "lay.top": None})
    elif method == "S" and base.lay.method == "J":
        changes.update({"lay.method": "S", "lay.top": None})
        if "a" in scene_axes:
            changes["lay.stinger.a"] = scene_axes["a"][0]
    for key, case_key in _SCENE_GEOMETRY.items():
        if key in table:
            changes[case_key] = table[key]
    changes.update(_dotted(f"{path}.set", table.get("set", {})))
    if method == "J":
        for axis in DESIGN_AXES:
            scene_axes.pop(axis, None)  # no stinger to vary
    reference = table.get("reference_a", math.nan)
    if isinstance(reference, bool) or not isinstance(reference, numbers.Real):
        fail(f"{path}.reference_a", reference, "must be a number (1/m)")
    changes["name"] = name
    try:
        case = base.with_changes(changes)
    except ValueError as err:
        raise ValueError(f"{path} ({name}): {err}") from None
    _check_design_axes(path, name, case, scene_axes)
    target_path = f"{path}.target" if "target" in table else "target"
    if "target" in table:
        target = _target(target_path, table["target"])
    if target is not None:
        _check_target(target_path, target, case, scene_axes)
    return Scene(name, case, scene_axes, float(reference), target)


def _check_design_axes(path, name, case, axes):
    """Refuse a stinger axis the scene's stinger does not have: ``a`` on a
    roller stinger, ``stinger_radius`` without rollers placed on a radius,
    ``roller_shift`` without rollers."""
    rollers = case.lay.has_rollers
    varied = [axis for axis in DESIGN_AXES if axis in axes]
    if len(varied) > 1 and case.lay.method == "S":
        raise ValueError(f"{path} ({name}): the axes {varied} both vary the stinger; a scene "
                         "varies one (select chooses its value), so put each in a scene of its own")
    need = {"a": (not rollers, "a quadratic stinger (lay.stinger.a)"),
            "stinger_radius": (rollers and case.lay.stinger.radius is not None,
                               "rollers placed on a radius (lay.stinger.radius)"),
            "roller_shift": (rollers, "a roller stinger (lay.stinger.rollers or radius)")}
    for axis, (ok, what) in need.items():
        if axis in axes and case.lay.method == "S" and not ok:
            raise ValueError(f"{path} ({name}): the axis {axis!r} needs {what}; the scene's "
                             "case does not have one")


def _target(path, table) -> dict:
    """A target table: one summary column with its goal, ``vary`` and ``bounds``."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table {<column> = goal, vary = key, bounds = [lo, hi]}")
    for key in ("vary", "bounds"):
        if key not in table:
            raise ValueError(f"missing key {path}.{key}")
    goals = [k for k in table if k not in ("vary", "bounds")]
    if len(goals) != 1:
        fail(path, dict(table), "must name exactly one summary column and its goal, e.g. "
             "tip_clearance = 0.3")
    reject_unknown({goals[0]: None}, list(target_columns()), f"{path}.")
    vary = table["vary"]
    if not isinstance(vary, str) or not vary:
        fail(f"{path}.vary", vary, "must be a dotted case key, e.g. \"lay.top_tension\"")
    bounds = table["bounds"]
    if not isinstance(bounds, list) or len(bounds) != 2:
        fail(f"{path}.bounds", bounds, "must be a list [lo, hi]")
    lo, hi = (_number(f"{path}.bounds[{i}]", b) for i, b in enumerate(bounds))
    if lo >= hi:
        fail(f"{path}.bounds", bounds, "must have lo < hi")
    return {"column": goals[0], "goal": _number(f"{path}.{goals[0]}", table[goals[0]]),
            "vary": vary, "bounds": (lo, hi)}


def _check_target(path, target, case, axes):
    """Refuse a target whose key an axis varies or the scene's case does not give."""
    for name in axes:
        keys = [f"lay.{t}" for t in TENSION_AXES] if name in TENSION_AXES else [AXES[name][0]]
        if target["vary"] in keys:
            fail(f"{path}.vary", target["vary"],
                 f"is varied by the axis {name!r}: a target solves for a key no axis sets")
    value = get_path(case.to_dict(), target["vary"])
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        fail(f"{path}.vary", target["vary"], f"is not a numeric key that scene {case.name!r}'s "
             f"case gives (its value: {value!r})")


def _spec_target(spec) -> dict | None:
    return None if spec is None else {**spec, "bounds": tuple(spec["bounds"])}


def _with_target(identity: str, scene: Scene) -> str:
    """A case id that tells target solves apart from plain ones (and from each other)."""
    if scene.target is None:
        return identity
    text = identity + json.dumps(scene.to_spec()["target"], sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _base_case(path, source, folder) -> Case:
    if not isinstance(source, str) or not source:
        fail(path, source, "must be a bundled example name or a case file path")
    examples = files("pipelay_fast").joinpath("examples")
    bundled = examples.joinpath(f"{source}.toml")
    if "/" not in source and not source.endswith(".toml") and bundled.is_file():
        return load_case(Path(str(bundled)))
    file = folder / source
    if not file.is_file():
        fail(path, source, f"is neither a bundled example nor a file (looked for {file})")
    return load_case(file)


def _scene_name(source) -> str:
    stem = Path(str(source)).stem
    return re.sub(r"[^A-Za-z0-9_-]", "_", stem) or "scene"


def _check_name(path, name):
    if not isinstance(name, str) or not _NAME.match(name):
        fail(path, name, "must be a non-empty name of letters, digits, '_' and '-'")


def _dotted(path, table) -> dict:
    """Flatten a table of (possibly nested or dotted) case keys to {dotted key: value}."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table of case keys, e.g. {\"solver.element_length\" = 8.0}")
    flat = {}
    for key, value in table.items():
        if isinstance(value, Mapping):
            flat.update({f"{key}.{k}": v for k, v in _dotted(f"{path}.{key}", value).items()})
        else:
            flat[str(key)] = value
    return flat


def _axes(path, table) -> dict:
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table of axes")
    reject_unknown(table, list(AXES), f"{path}.")
    return {name: _values(f"{path}.{name}", spec) for name, spec in table.items()}


def _values(path, spec) -> tuple[float, ...]:
    """An axis's values from a list or a {start, stop, num | step} table (ends included)."""
    if isinstance(spec, Mapping):
        reject_unknown(spec, ["start", "stop", "num", "step"], f"{path}.")
        for key in ("start", "stop"):
            if key not in spec:
                raise ValueError(f"missing key {path}.{key}")
        start, stop = _number(f"{path}.start", spec["start"]), _number(f"{path}.stop", spec["stop"])
        if ("num" in spec) == ("step" in spec):
            raise ValueError(f"{path} needs exactly one of {path}.num and {path}.step")
        if "num" in spec:
            num = spec["num"]
            if isinstance(num, bool) or not isinstance(num, int) or num < 1:
                fail(f"{path}.num", num, "must be a positive integer")
            if num == 1 and start != stop:
                fail(f"{path}.num", num, "must be at least 2 when start and stop differ")
            values = [start + (stop - start) * i / max(num - 1, 1) for i in range(num)]
        else:
            step = _number(f"{path}.step", spec["step"])
            if step == 0 or (stop - start) * step < 0:
                fail(f"{path}.step", step, f"must be non-zero and lead from {start!r} to {stop!r}")
            count = (stop - start) / step
            num = math.floor(count + 1e-9) + 1
            values = [start + step * i for i in range(num)]
        values = [round(v, 15) for v in values]
    elif isinstance(spec, list):
        if not spec:
            fail(path, spec, "must not be empty")
        values = [_number(f"{path}[{i}]", v) for i, v in enumerate(spec)]
    else:
        fail(path, spec, "must be a list of numbers or a table {start, stop, num} "
             "or {start, stop, step}")
    for i, v in enumerate(values):
        if v in values[:i]:
            fail(path, spec, f"repeats the value {v!r}")
    return tuple(values)


def _number(path, value) -> float:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        fail(path, value, "must be a finite number")
    return float(value)


# --------------------------------------------------------------------------- expansion


def _changes(values: Mapping[str, float]) -> dict:
    changes = {}
    for name, value in values.items():
        if name in TENSION_AXES:
            changes.update({f"lay.{t}": None for t in TENSION_AXES})
        changes[AXES[name][0]] = value
    return changes


def _copy_tables(tables: dict) -> dict:
    """A copy of nested tables deep enough for :func:`put_path` (values are shared)."""
    return {k: _copy_tables(v) if isinstance(v, dict) else v for k, v in tables.items()}


def _inputs(scene: Scene, case: Case | None, values: Mapping[str, float]) -> dict:
    """The summary's input columns of a case (from the requested values if invalid)."""
    ref = case or scene.case
    lay, cur = ref.lay, ref.environment.current
    inputs = {
        "method": ref.lay.method,
        "dimension": ref.resolved_dimension if case is not None else "",
        **stinger_columns(lay),
        "water_depth": ref.environment.water_depth,
        "current_speed": cur.speed,
        "current_heading_deg": cur.heading,
    }
    given = {AXES[t][1]: getattr(lay, t) for t in TENSION_AXES}
    if case is None and any(t in values for t in TENSION_AXES):
        given = dict.fromkeys(given)
    inputs.update({k: math.nan if v is None else float(v) for k, v in given.items()})
    for name, value in values.items():  # the requested values, valid or not
        inputs[AXES[name][1]] = value
    return inputs


def _raw_id(scene: Scene, values: Mapping[str, float]) -> str:
    """Stable id of an invalid case: a hash of its requested tables."""
    return tables_id(scene._tables_for(values)[0])


def _expand(scene: Scene) -> list[SweepCase]:
    chain_axis = scene.chain_axis
    others = [n for n in AXES if n in scene.axes and n != chain_axis]
    inner = scene.axes[chain_axis] if chain_axis else (None,)
    cases = []
    for number_, combo in enumerate(itertools.product(*(scene.axes[n] for n in others))):
        fixed = dict(zip(others, combo, strict=True))
        for position, value in enumerate(inner):
            values = dict(fixed) if chain_axis is None else {**fixed, chain_axis: value}
            piece, pos = divmod(position, MAX_CHAIN_LENGTH)
            cases.append(SweepCase(scene, f"{scene.name}/{number_}.{piece}", pos, values))
    return cases


def chains(cases: list[SweepCase]) -> list[list[SweepCase]]:
    """Group cases by chain, each in chain order; chains in first-seen order."""
    grouped: dict[str, list[SweepCase]] = {}
    for c in cases:
        grouped.setdefault(c.chain, []).append(c)
    return [sorted(g, key=lambda c: c.position) for g in grouped.values()]
