"""A sweep: its scenes, and the cases they expand into (one per combination
of their axes' values), grouped into chains solved with warm starts.

Read from a sweep file by :func:`pipelay_fast.study.sweep_file.load_sweep`
(the file's format is described there). Cases that differ only in the
chain axis (``a``, a roller stinger's radius or shift; for J-lay the first
varied of current speed, tension, heading) form a chain, solved in order
with warm starts.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import pandas as pd

from ..api.target import unit_text
from ..input.case import Case, load_case, with_tables
from ..input.validate import put_path
from ..output.results import remember_case_id, stinger_columns, tables_id

__all__ = ["AXES", "Scene", "Sweep", "SweepCase", "chains", "target_bounds"]

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
    "depth": ("environment.water_depth", "water_depth", "m"),
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

SCENE_GEOMETRY = {  # scene key -> case key
    "water_depth": "environment.water_depth",
    "stinger_lower": "lay.stinger.lower",
    "stinger_upper": "lay.stinger.upper",
    "top": "lay.top",
    "top_angle": "lay.top_angle",
}


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
        key), "bounds" (lo, hi) at the scene case's water depth, and with
        "bounds_per_depth" (dlo, dhi) [the key's unit per m] the depth
        "depth" [m] they are given at (:func:`target_bounds`); None: plain
        solves.
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
        """:meth:`case_for` and its :func:`pipelay_fast.output.results.case_id`,
        both from the base case's tables with the axis values put in (only
        the tables they change validated anew,
        :func:`pipelay_fast.input.case.with_tables`; the id hashes those
        tables, which are the case's ``to_dict()``)."""
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
        target = None if self.target is None else {
            **self.target, **{k: list(self.target[k]) for k in ("bounds", "bounds_per_depth")
                              if k in self.target}}
        return {"name": self.name, "case": self.case.to_dict(),
                "axes": {k: list(v) for k, v in self.axes.items()},
                "reference_a": None if math.isnan(self.reference_a) else self.reference_a,
                "target": target}

    @property
    def target_text(self) -> str:
        """The target as the summary's ``target`` column writes it ("" without one)."""
        t = self.target
        if t is None:
            return ""
        text = (f"{t['column']} = {t['goal']!r}{unit_text(t['column'])} by {t['vary']} in "
                f"{list(t['bounds'])}")
        if "bounds_per_depth" in t:
            text += f" at {t['depth']!r} m + {list(t['bounds_per_depth'])} per m of depth"
        return text


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
        """The name of the case's scene."""
        return self.source.name

    def _build(self) -> tuple:
        """(case or None, validation error or "", case id), built once."""
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
        """The validated case; None when the axis values make it invalid."""
        return self._build()[0]

    @property
    def error(self) -> str:
        """The validation message of an invalid case; "" for a valid one."""
        return self._build()[1]

    @property
    def case_id(self) -> str:
        """16 hex digits: the case's inputs (those requested, for an invalid
        case), and its target when the scene has one."""
        return self._build()[2]

    @property
    def inputs(self) -> dict:
        """The summary's input columns (SI): method, dimension, the stinger's,
        water depth, current, the given tension, and the axis values as
        requested."""
        return _inputs(self.source, self.case, self.values)


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep file.

    Attributes
    ----------
    name : str
        The sweep's name (the results directory's default).
    scenes : tuple of Scene
    description : str
        Free text of the file.
    source : str
        The file's path ("" for a dict or a stored spec).
    limits : dict
        The file's ``[select]`` table, the limits ``select`` applies
        (:func:`pipelay_fast.study.limits.check_limits`; SI).
    """

    name: str
    scenes: tuple[Scene, ...]
    description: str = ""
    source: str = ""
    limits: dict = field(default_factory=dict, compare=False)
    _cases: list = field(default_factory=list, compare=False, repr=False)

    def scene(self, name: str) -> Scene:
        """The scene called ``name``; KeyError if none is."""
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
        """JSON-able description (name, description, scenes, the ``[select]``
        limits), read back by :meth:`from_spec`."""
        return {"name": self.name, "description": self.description,
                "scenes": [scene.to_spec() for scene in self.scenes],
                "select": dict(self.limits)}

    @classmethod
    def from_spec(cls, spec: Mapping) -> Sweep:
        """The sweep stored by :meth:`to_spec` (in a results directory's ``sweep.json``)."""
        scenes = tuple(
            Scene(s["name"], load_case(s["case"]),
                  {k: tuple(v) for k, v in s["axes"].items()},
                  math.nan if s.get("reference_a") is None else float(s["reference_a"]),
                  _spec_target(s.get("target")))
            for s in spec["scenes"])
        return cls(spec["name"], scenes, spec.get("description", ""),
                   limits=dict(spec.get("select", {})))


# --------------------------------------------------------------------------- loading


def _spec_target(spec) -> dict | None:
    """A scene's target from its JSON spec (bounds back to tuples)."""
    if spec is None:
        return None
    return {**spec, **{k: tuple(spec[k]) for k in ("bounds", "bounds_per_depth") if k in spec}}


def target_bounds(target: Mapping, case: Case) -> tuple[float, float]:
    """The bracket (lo, hi) of a scene's ``target`` for ``case``: its
    "bounds", moved by "bounds_per_depth" (dlo, dhi) [the key's unit per m]
    times the case's water depth less the depth they are given at."""
    lo, hi = target["bounds"]
    if "bounds_per_depth" not in target:
        return (lo, hi)
    shift = case.environment.water_depth - target["depth"]
    dlo, dhi = target["bounds_per_depth"]
    return (lo + dlo * shift, hi + dhi * shift)


def _with_target(identity: str, scene: Scene) -> str:
    """A case id that tells target solves apart from plain ones (and from each other)."""
    if scene.target is None:
        return identity
    text = identity + json.dumps(scene.to_spec()["target"], sort_keys=True)
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def _changes(values: Mapping[str, float]) -> dict:
    """The dotted case keys axis values set (a tension axis clears the other
    tension keys)."""
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
    """The scene's cases: every combination of its other axes, each a chain
    over the chain axis cut into pieces of at most MAX_CHAIN_LENGTH."""
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
