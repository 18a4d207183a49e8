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
``bottom_tension`` (``given_top_tension``, ``given_bottom_tension``, N),
``pipe_length`` (``given_pipe_length``, m) and ``depth`` (``water_depth``, m:
the water depth of a vessel in the waterline frame, ``lay.frame =
"waterline"``, which moves the seabed and not the vessel; refused on a
seabed-frame case, whose vessel would move with the seabed) and ``trim``
(``trim_deg``, deg: ``lay.trim_deg``, the vessel's trim about the case's
``lay.trim_pivot``, which the case must give); a tension axis
replaces whichever tension the base case gives. Scene keys: ``case``,
``method`` ("S" or "J"), ``water_depth``, ``stinger_lower``, ``stinger_upper``,
``top`` ((x, z), m, x in the case's ``lay.frame``: the J-lay hang-off, or
where the vessel holds the pipe above a roller stinger), ``top_angle`` (deg),
``reference_a``, ``set``, ``vary`` and ``target``.

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
``bounds_per_depth = [dlo, dhi]`` [the key's unit per m] moves the bracket
with the water depth: at depth d it is ``bounds`` + (d - d0) ``bounds_per_depth``,
d0 the scene case's water depth (a depth axis whose tensions grow with the
suspended weight).

A ``[select]`` table gives the limits ``pipelay-fast select`` chooses the
stinger within (:mod:`.limits`; SI)::

    [select]
    min_tip_clearance = 0.2          # m
    max_utilisation = 1.0            # - (the default where the cases have [checks])
    max_overbend_strain = 0.0025     # -
    max_sagbend_strain = 0.0015      # -
    top_tension = [400e3, 900e3]     # N, the tensioner's range
    max_roller_reaction = 250e3      # N, roller stingers

A top-level ``sensitivities`` list asks for each case's derivatives with
respect to numeric case keys (:mod:`.sensitivity`)::

    sensitivities = ["lay.stinger.a", "lay.top_tension"]

Each case's summary row then has ``d_<column>__d_<key>`` for every numeric
summary column (and ``s_<peak>``, a peak's arc length), in ``<column
unit>/<key unit>`` (``d_overbend_max_von_mises__d_lay.stinger.a`` in
Pa/(1/m)), NaN where the column is not differentiable or the scene's case
does not give the key, with the reasons in ``sensitivity_reasons``. Each
key costs about one solve per case. ``select`` finds the equal peaks and
the limits' boundaries from them. A key must be given as a number by some
scene's case; sensitivities and a ``[target]`` are refused together. A
results directory holds one list of keys: a sweep with another is refused.

Cases that differ only in the chain axis (``a``, a roller stinger's radius or
shift; for J-lay the first varied of current speed, tension, heading) form a
chain, solved in order with warm starts.
"""

from __future__ import annotations

import math
import numbers
import os
import re
import sys
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path

from ..api.target import target_columns
from ..input.case import Case, load_case
from ..input.examples import case_file
from ..input.limits import ROUNDOFF
from ..input.validate import fail, from_toml, get_path, reject_unknown
from .limits import check_limits
from .sensitivity import check_sensitivities, given_keys
from .sweep import (
    AXES,
    DESIGN_AXES,
    SCENE_GEOMETRY,
    TENSION_AXES,
    Scene,
    Sweep,
)

__all__ = ["load_sweep"]

_SCENE_KEYS = ("name", "case", "method", *SCENE_GEOMETRY, "reference_a", "set", "vary",
               "target")
_FILE_KEYS = ("name", "description", "case", "set", "vary", "target", "select", "sensitivities",
              "scenes")
_NAME = re.compile(r"^[A-Za-z0-9_-]+$")


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
    """The sweep of a file's tables; relative case paths from ``folder``."""
    reject_unknown(tables, _FILE_KEYS, "", listed=True)
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
    limits = check_limits("select", tables.get("select", {}))
    keys = check_sensitivities("sensitivities", tables.get("sensitivities", []),
                               [s.case for s in scenes])
    for i, scene in enumerate(scenes):
        if keys and scene.target is not None:
            fail(f"scenes[{i}].target" if "target" in scene_tables[i] else "target",
                 scene.target_text, "cannot be combined with sensitivities (a target solve's "
                 "derivatives would hold its goal, not its key)")
    scenes = [replace(s, sensitivities=given_keys(s.case, keys)) for s in scenes]
    return Sweep(name, tuple(scenes), description, source, limits, keys)


def _scene(path, table, default_case, folder, common, axes, target) -> Scene:
    """The scene of the table at ``path``: its base case with the file's
    ``set`` (``common``), its geometry and its own ``set`` applied; the
    file's axes (``axes``) with its own; the file's ``target`` unless it
    gives one. ValueError naming the key for any mistake."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table")
    reject_unknown(table, _SCENE_KEYS, f"{path}.", listed=True)
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
    for key, case_key in SCENE_GEOMETRY.items():
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
    if "depth" in scene_axes and case.given_lay.frame != "waterline":
        fail(f"{path}.vary.depth" if "depth" in table.get("vary", {}) else "vary.depth",
             list(scene_axes["depth"]), f"needs a vessel in the waterline frame: scene {name!r}'s "
             f"case has lay.frame = {case.given_lay.frame!r}, whose vessel would move with the "
             "seabed (set lay.frame = \"waterline\" and give its heights from the still water)")
    target_path = f"{path}.target" if "target" in table else "target"
    if "target" in table:
        target = _target(target_path, table["target"])
    if target is not None:
        _check_target(target_path, target, case, scene_axes)
        if "bounds_per_depth" in target:
            target = {**target, "depth": case.environment.water_depth}
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
    goals = [k for k in table if k not in ("vary", "bounds", "bounds_per_depth")]
    if len(goals) != 1:
        fail(path, dict(table), "must name exactly one summary column and its goal, e.g. "
             "tip_clearance = 0.3")
    reject_unknown({goals[0]: None}, list(target_columns()), f"{path}.", listed=True)
    vary = table["vary"]
    if not isinstance(vary, str) or not vary:
        fail(f"{path}.vary", vary, "must be a dotted case key, e.g. \"lay.top_tension\"")
    bounds = table["bounds"]
    if not isinstance(bounds, list) or len(bounds) != 2:
        fail(f"{path}.bounds", bounds, "must be a list [lo, hi]")
    lo, hi = (_number(f"{path}.bounds[{i}]", b) for i, b in enumerate(bounds))
    if lo >= hi:
        fail(f"{path}.bounds", bounds, "must have lo < hi")
    target = {"column": goals[0], "goal": _number(f"{path}.{goals[0]}", table[goals[0]]),
              "vary": vary, "bounds": (lo, hi)}
    if "bounds_per_depth" in table:
        slope = table["bounds_per_depth"]
        if not isinstance(slope, list) or len(slope) != 2:
            fail(f"{path}.bounds_per_depth", slope, "must be a list [dlo, dhi] (per m of depth)")
        target["bounds_per_depth"] = tuple(_number(f"{path}.bounds_per_depth[{i}]", v)
                                           for i, v in enumerate(slope))
    return target


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


def _base_case(path, source, folder) -> Case:
    """The case ``source`` names: a bundled example (a bare name), else a
    file relative to ``folder`` (:func:`pipelay_fast.input.examples.case_file`)."""
    if not isinstance(source, str) or not source:
        fail(path, source, "must be a bundled example name or a case file path")
    try:
        file = case_file(source, folder)
    except ValueError as err:
        raise ValueError(f"{path} = {err}") from None
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
    """Axis name -> tuple of values [SI] of a ``vary`` table."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table of axes")
    reject_unknown(table, list(AXES), f"{path}.", listed=True)
    return {name: _values(f"{path}.{name}", spec) for name, spec in table.items()}


def _values(path, spec) -> tuple[float, ...]:
    """An axis's values from a list or a {start, stop, num | step} table (ends included)."""
    if isinstance(spec, Mapping):
        reject_unknown(spec, ["start", "stop", "num", "step"], f"{path}.", listed=True)
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
            num = math.floor(count * (1.0 + ROUNDOFF)) + 1
            values = [start + step * i for i in range(num)]
        # (to the decimal digits a double holds, 15: 0.1 * 3 is 0.3)
        values = [round(v, sys.float_info.dig) for v in values]
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
