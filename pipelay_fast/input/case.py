"""Validated, immutable description of one static pipelay case.

A case is read by :func:`load_case` from a TOML file (or a dict with the same
tables: ``pipe``, ``environment`` (+ ``current``), ``seabed``, ``lay``
(+ ``stinger``), ``solver``, and optionally ``checks``, the code-check inputs
of :class:`pipelay_fast.input.checks.Checks`). Every value is in SI units;
coordinates follow the paper: ``x`` is the height above the seabed, ``y``
lateral, ``z`` along the lay; the vessel's heights may be given from the
still water level instead (``lay.frame``, :mod:`pipelay_fast.input.frame`).
Part of the input layer.

Every dataclass checks itself on construction, so a case built in Python, loaded
from a file or modified with :meth:`Case.with_changes` is always valid. A bad
value raises :class:`ValueError` naming the key by its dotted path and its value;
nothing is clamped. A case outside the model is refused the same way: a
stinger that is concave up, falls towards the vessel or overhangs
(:class:`Stinger`), and inputs that alone imply a strain beyond
``solver.max_strain`` (the tension at a given end over EA, the bending strain on
the stinger: :func:`pipelay_fast.input.limits.check_case`).
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field, fields

import numpy as np

from .checks import Checks, check_inputs
from .environment import Current, Environment, Seabed, check_slope
from .examples import case_file
from .frame import to_seabed
from .lay import Lay, RollerStinger, Stinger
from .limits import ROUNDOFF, check_case
from .pipe import Pipe
from .surface import check_vessel
from .trim import trimmed
from .validate import (
    assign,
    choice,
    fail,
    flag,
    from_toml,
    get_path,
    instance,
    integer,
    plain,
    put_path,
    reject_unknown,
    set_numbers,
    vectorised,
)

__all__ = [
    "Case",
    "Current",
    "Environment",
    "Lay",
    "Pipe",
    "Seabed",
    "Solver",
    "RollerStinger",
    "Stinger",
    "load_case",
]

DIMENSIONS = ("auto", "2d", "3d")


# --------------------------------------------------------------------------- tables


@dataclass(frozen=True, slots=True)
class Solver:
    """Numerical settings, table ``[solver]``.

    Attributes
    ----------
    dimension : str
        "auto" (2D when the case is planar), "2d" or "3d".
    element_length : float
        Target element length [m]; default 4.0 (chosen from the solve time
        against the stress error of the paper's scenes, the error bound
        0.1 %: benchmarks/speed_vs_error.py).
    min_element_length : float or None
        Finest graded element [m], <= element_length; None: the solver picks.
    grading : bool
        Grade the mesh at touchdown and lift-off; default true. Ungraded, the
        elements are about element_length long, with a node on each contact
        boundary (touchdown, lift-off, the tip) and, in 3D, one where the
        stinger's lateral hold ends.
    laid_length : float or None
        Length of pipe modelled on the seabed [m]; None: the solver picks.
    tolerance : float
        Relative convergence tolerance [-], in (0, 1e-2); default 1e-8.
    max_iterations, max_load_steps : int
        Newton iterations per step, and load steps per load path [-] (the
        homotopy from the first guess, the current's path); defaults 100
        and 64.
    max_iterations_total : int
        Newton iterations of one solve in all [-], over load steps, current
        steps, remeshing passes and laid-length doublings (a warm start that
        fails leaves the cold start a budget of its own); default 1000, well
        above the iterations of the paper's scenes and the tests' hardest
        cases (measured: benchmarks/bench_contact.py); a case that needs more
        is following its load path in fragments. Past it a SolveError names
        the key.
    max_elements : int
        Largest mesh [-], counted before any array is built; default 20000,
        the paper's scenes on elements of about 0.02 m (the time of a Newton
        iteration against the mesh size: benchmarks/bench_scaling.py). Past
        it a ValueError names solver.element_length, the laid length
        (solver.laid_length or what set its default) and the count.
    max_strain : float
        Largest extreme-fibre strain |Tw/EA| + (Do/2) kappa [-] the
        small-strain model is trusted to (bending alone for an inextensible
        pipe), in (0, 0.1]; default 0.02, where the strain measures the linear
        law could be written in give forces 1 % apart (the reasoning:
        :mod:`pipelay_fast.input.limits`). Inputs that imply more are refused with a
        ValueError naming their keys, answers with a SolveError naming the
        strain, where it is and the limit.
    """

    dimension: str = "auto"
    element_length: float = 4.0
    min_element_length: float | None = None
    grading: bool = True
    laid_length: float | None = None
    tolerance: float = 1e-8
    max_iterations: int = 100
    max_load_steps: int = 64
    max_iterations_total: int = 1000
    max_elements: int = 20000
    max_strain: float = 0.02

    def __post_init__(self):
        choice("solver.dimension", self.dimension, DIMENSIONS)
        optional = [name for name in ("min_element_length", "laid_length")
                    if getattr(self, name) is not None]
        set_numbers(self, "solver", positive=("element_length", "tolerance", *optional))
        if self.min_element_length is not None and self.min_element_length > self.element_length:
            fail("solver.min_element_length", self.min_element_length,
                 f"must not exceed solver.element_length = {self.element_length!r}")
        if self.tolerance >= 1e-2:
            fail("solver.tolerance", self.tolerance, "must be below 1e-2")
        assign(self, "grading", flag("solver.grading", self.grading))
        assign(self, "max_iterations", integer("solver.max_iterations", self.max_iterations, 1))
        assign(self, "max_load_steps", integer("solver.max_load_steps", self.max_load_steps, 1))
        assign(self, "max_iterations_total",
               integer("solver.max_iterations_total", self.max_iterations_total, 1))
        assign(self, "max_elements", integer("solver.max_elements", self.max_elements, 2))
        set_numbers(self, "solver", positive=("max_strain",))
        if self.max_strain > 0.1:
            fail("solver.max_strain", self.max_strain, "must not exceed 0.1: beyond it the "
                 "strain measures of the small-strain model differ by over 5 %")


# --------------------------------------------------------------------------- case


@dataclass(frozen=True, slots=True, weakref_slot=True)
class Case:
    """One static pipelay case: the tables of a case file, validated.

    Heights ``x`` [m] below are above the seabed; loads are per unit length.

    Attributes
    ----------
    name : str
        Case name (file stem by default).
    pipe, environment, seabed, lay, solver
        The tables; ``lay`` is held in the seabed frame, whatever its
        ``lay.frame`` (:func:`pipelay_fast.input.frame.to_seabed`), and
        trimmed (:func:`pipelay_fast.input.trim.trimmed`: its trim 0).
    checks : Checks or None
        Table ``[checks]``, the code-check inputs; None: no code checks (their
        summary columns are NaN).
    given_lay : Lay
        The lay as given, in its own frame (``lay.frame``): what
        :meth:`to_dict` writes and :meth:`with_changes` changes. Set on
        construction, and compared: two cases are equal when their tables
        are (a waterline-frame case and its seabed-frame twin have equal
        ``lay`` and differ in ``given_lay``).
    """

    name: str
    pipe: Pipe
    environment: Environment
    seabed: Seabed
    lay: Lay
    solver: Solver
    checks: Checks | None = None
    given_lay: Lay = field(init=False, repr=False)

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            fail("name", self.name, "must be a non-empty string")
        for part, cls in _TABLES.items():
            instance(part, getattr(self, part), cls)
        if self.checks is not None:
            instance("checks", self.checks, Checks)
        depth = self.environment.water_depth
        assign(self, "given_lay", self.lay)
        assign(self, "lay", trimmed(to_seabed(self.lay, depth)))
        if self.solver.dimension == "2d" and not self.is_planar:
            fail("solver.dimension", "2d", "cannot be used: the case has lateral loads "
                 "(lateral current, torque or distributed moment about x or z)")
        check_slope(self)
        check_vessel(self)  # the trimmed, seabed-frame vessel above the seabed
        check_case(self)  # the model's limits first, then what the code checks need
        check_inputs(self.pipe, self.checks)

    @property
    def weight_dry(self) -> float:
        """Weight of steel and coating in air [N/m]."""
        return self.environment.gravity * (self.pipe.steel_mass + self.pipe.coating_mass)

    @property
    def weight_contents(self) -> float:
        """Weight of the contents where x < contents_level [N/m]."""
        return self.environment.gravity * self.pipe.contents_mass

    @property
    def buoyancy(self) -> float:
        """rho_w g pi Dc^2/4 where x < water_depth [N/m]."""
        env = self.environment
        return env.water_density * env.gravity * self.pipe.displaced_area

    def effective_weight(self, x):
        """Effective weight w(x) [N/m] at height x [m]; vectorised."""
        level, depth = self.pipe.contents_level, self.environment.water_depth
        return vectorised(x, lambda x: self.weight_dry + self.weight_contents * (x < level)
                           - self.buoyancy * (x < depth))

    def external_pressure(self, x):
        """pe(x) = rho_w g (d - x) below the surface, else 0 [Pa]; vectorised."""
        env = self.environment
        d = env.water_depth
        return vectorised(x, lambda x: np.where(
            x < d, env.water_density * env.gravity * (d - x), 0.0))

    def internal_pressure(self, x):
        """pi(x) = rho_i g (Hi - x) where positive, else 0 [Pa]; vectorised."""
        pipe, g = self.pipe, self.environment.gravity
        return vectorised(x, lambda x: np.maximum(
            pipe.contents_density * g * (pipe.contents_level - x), 0.0))

    def wall_tension(self, effective_tension, x):
        """Tw = Te + pi Ai - pe Ae [N] from effective tension Te [N] at height x [m]."""
        te = np.asarray(effective_tension, dtype=np.float64)
        return (te + self.internal_pressure(x) * self.pipe.inner_area
                - self.external_pressure(x) * self.pipe.outer_area)[()]

    def effective_tension(self, wall_tension, x):
        """Te = Tw - pi Ai + pe Ae [N] from wall tension Tw [N] at height x [m]."""
        tw = np.asarray(wall_tension, dtype=np.float64)
        return (tw - self.internal_pressure(x) * self.pipe.inner_area
                + self.external_pressure(x) * self.pipe.outer_area)[()]

    def current_speed_at(self, x):
        """Current speed [m/s] at height x [m]: 0 above the surface and below the
        seabed; vectorised."""
        cur, d = self.environment.current, self.environment.water_depth

        def profile(x):
            if cur.profile == "uniform":
                v = np.full_like(x, cur.speed)
            elif cur.profile == "linear":
                v = cur.speed * x / d
            elif cur.profile == "power":
                v = cur.speed * np.power(np.clip(x / d, 0.0, None), cur.exponent)
            else:
                heights, speeds = np.array(cur.table).T
                v = np.interp(x, heights, speeds)
            return np.where((x >= 0.0) & (x <= d), v, 0.0)

        return vectorised(x, profile)

    @property
    def current_direction(self) -> tuple[float, float]:
        """Unit vector (ey, ez) [-] of the current in the y-z plane."""
        heading = math.radians(self.environment.current.heading)
        return (math.sin(heading), math.cos(heading))

    @property
    def is_planar(self) -> bool:
        """True when every load lies in the x-z plane (the 2D reduction is exact)."""
        lateral_current = (self.environment.current.speed > 0.0
                           and abs(self.current_direction[0]) >= ROUNDOFF)
        mx, _, mz = self.lay.distributed_moment
        return not lateral_current and self.lay.torque == 0.0 and mx == 0.0 and mz == 0.0

    @property
    def resolved_dimension(self) -> str:
        """The dimension to solve in, "2d" or "3d" ("auto" resolved by :attr:`is_planar`)."""
        if self.solver.dimension != "auto":
            return self.solver.dimension
        return "2d" if self.is_planar else "3d"

    def to_dict(self) -> dict:
        """Nested dict of TOML-able values; ``load_case(case.to_dict()) == case``."""
        tables = {"name": self.name} | {part: plain(getattr(self, part)) for part in _TABLES}
        tables["lay"] = plain(self.given_lay)
        if tables["lay"]["frame"] == "seabed":
            del tables["lay"]["frame"]  # the default: a seabed-frame case's tables as before
        if tables["lay"]["trim_deg"] == 0.0:
            del tables["lay"]["trim_deg"]  # (likewise untrimmed)
        tables["seabed"].setdefault("stiffness", "rigid")
        if self.checks is not None:
            tables["checks"] = plain(self.checks)
        return tables

    def with_changes(self, changes: Mapping[str, object] | None = None, /, **dotted) -> Case:
        """A new, re-validated case with dotted keys replaced.

        ``case.with_changes({"lay.stinger.a": -0.0011})``; a value of None removes
        the key (its default applies). A derived default follows its source when
        it was equal to it and is not itself changed: coating_outer_diameter
        follows outer_diameter, hydrodynamic_diameter follows
        coating_outer_diameter, lay.top follows lay.stinger.upper; pipe.smys
        and pipe.smts follow pipe.grade, and changing either of them without
        the grade drops the grade (the steel is then the given strengths).
        Raises ValueError, naming the key, when the new case is invalid.
        """
        updates = {**(changes or {}), **dotted}
        old = self.to_dict()
        new = copy.deepcopy(old)
        for path, value in updates.items():
            put_path(new, path, plain(value))
        rederived = set()  # keys removed so that their default is derived afresh
        for dependent, source in _FOLLOWERS:
            touched = any(dependent == p or dependent.startswith(p + ".") for p in updates)
            moved = source in rederived or get_path(new, source) not in (
                None, get_path(old, source))
            if moved and not touched and get_path(old, dependent) == get_path(old, source):
                put_path(new, dependent, None)
                rederived.add(dependent)
        _follow_grade(new, updates)
        return load_case(new)

    def with_number(self, key: str, value: float) -> Case:
        """The case with the numeric dotted ``key`` set to ``value``: the
        case :meth:`with_changes` gives, built by replacing the value in the
        tables on its path (each re-validated by its own construction, then
        the case as a whole), with no round trip through :meth:`to_dict`
        (a sixth of the time). A key that a derived default follows, the
        pipe's grade and strengths, and a key of a table the case does not
        have go through :meth:`with_changes`.
        Raises ValueError as :meth:`with_changes` does."""
        if any(key in pair for pair in _FOLLOWERS) or key in _GRADE_KEYS:
            return self.with_changes({key: value})
        head, *path = key.split(".")
        table = self.given_lay if head == "lay" else getattr(self, head, None)
        if head not in {*_TABLES, *_OPTIONAL_TABLES} or table is None or not path:
            return self.with_changes({key: value})
        # the lay as given (its frame and trim), which the new case converts again
        return dataclasses.replace(self, **{"lay": self.given_lay,
                                            head: _replaced(table, path, value)})


def _replaced(table, path: list[str], value):
    """``table`` (a dataclass) with the field at ``path`` set to ``value``,
    each dataclass on the way built anew (and so checked)."""
    name = path[0]
    if not dataclasses.is_dataclass(table) or name not in {f.name for f in fields(table)}:
        raise ValueError(f"unknown key {'.'.join(path)} in its table")
    inner = value if len(path) == 1 else _replaced(getattr(table, name), path[1:], value)
    return dataclasses.replace(table, **{name: inner})


_GRADE_KEYS = ("pipe.grade", "pipe.smys", "pipe.smts")


def _follow_grade(tables: dict, updates: Mapping) -> None:
    """In ``tables`` changed by ``updates``: a new pipe.grade re-derives the
    strengths not changed with it; a strength changed without the grade
    drops the grade."""
    if "pipe" in updates:
        return
    strengths = ("pipe.smys", "pipe.smts")
    if "pipe.grade" in updates:
        for key in strengths:
            if key not in updates:
                put_path(tables, key, None)
    elif any(key in updates for key in strengths):
        put_path(tables, "pipe.grade", None)


_TABLES = {"pipe": Pipe, "environment": Environment, "seabed": Seabed, "lay": Lay,
           "solver": Solver}
_OPTIONAL_TABLES = {"checks": Checks}  # absent: None
_SUBTABLES = {"current": Current, "stinger": Stinger}
_FOLLOWERS = (
    ("pipe.coating_outer_diameter", "pipe.outer_diameter"),
    ("pipe.hydrodynamic_diameter", "pipe.coating_outer_diameter"),
    ("lay.top", "lay.stinger.upper"),
)


# --------------------------------------------------------------------------- loading


def _build(cls, table, path):
    """Construct ``cls`` from a TOML table after checking its key names."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table")
    names = [f.name for f in fields(cls)]
    reject_unknown(table, names, f"{path}.")
    for f in fields(cls):
        required = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if required and f.name not in table:
            raise ValueError(f"missing required key {path}.{f.name}")
    kwargs = dict(table)
    for key, sub in _SUBTABLES.items():
        if key in names and key in kwargs:
            if key == "stinger":
                sub = _stinger_class(kwargs[key], f"{path}.{key}")
            kwargs[key] = _build(sub, kwargs[key], f"{path}.{key}")
    return cls(**kwargs)


def _stinger_class(table, path):
    """The quadratic stinger (key ``a``) or the roller stinger (``rollers`` or
    ``radius``) a ``[lay.stinger]`` table describes."""
    if not isinstance(table, Mapping):
        fail(path, table, "must be a table")
    rollers = [k for k in table if k in _ROLLER_KEYS]
    if "a" in table and rollers:
        fail(f"{path}.{rollers[0]}", table[rollers[0]], f"is given with {path}.a: a stinger is "
             "the quadratic curve (a, lower, upper) or rollers (rollers, or radius), not both")
    return RollerStinger if rollers else Stinger


# the keys that make a [lay.stinger] table a roller stinger
_ROLLER_KEYS = {f.name for f in fields(RollerStinger)}


def load_case(source: str | os.PathLike | Mapping) -> Case:
    """Read and validate a case from a bundled example's name (``"s67"``,
    :func:`pipelay_fast.input.examples.case_file`), a TOML file path or a
    dict of tables.

    Raises
    ------
    ValueError
        For any bad value, naming the key by its dotted path (prefixed by the
        file name when reading a file), for invalid TOML, and for a bare name
        that is neither an example nor a file (the message lists the examples
        and suggests the closest).
    TypeError
        When ``source`` is neither a path nor a mapping.
    OSError
        When the file cannot be read.
    """
    if isinstance(source, Mapping):
        return _case_from_tables(source, "case")
    if not isinstance(source, (str, os.PathLike)):
        raise TypeError(f"load_case needs a path or a dict, not {type(source).__name__}")
    path = case_file(source)
    return from_toml(path, lambda tables: _case_from_tables(tables, path.stem))


def with_tables(base: Case, tables: Mapping, changed) -> Case:
    """The case of ``tables``: ``base.to_dict()`` with keys of the top-level
    tables named in ``changed`` replaced (no key a derived default follows).
    Those tables are validated anew, the others are ``base``'s (already
    valid), then the case as a whole: the case :func:`load_case` gives for
    ``tables``, without building and checking the unchanged tables again (a
    sweep builds one case per axis value). Raises ValueError as
    :func:`load_case` does."""
    parts = {part: _build(cls, tables.get(part, {}), part) if part in changed
             else getattr(base, "given_lay" if part == "lay" else part)
             for part, cls in _TABLES.items()}
    for part, cls in _OPTIONAL_TABLES.items():
        if part not in changed:
            parts[part] = getattr(base, part)
        elif part in tables:
            parts[part] = _build(cls, tables[part], part)
    return Case(name=tables.get("name", base.name), **parts)


def _case_from_tables(tables: Mapping, default_name: str) -> Case:
    """The case of a dict of tables, named ``default_name`` unless it has a name."""
    reject_unknown(tables, ["name", *_TABLES, *_OPTIONAL_TABLES], "")
    parts = {part: _build(cls, tables.get(part, {}), part) for part, cls in _TABLES.items()}
    parts |= {part: _build(cls, tables[part], part)
              for part, cls in _OPTIONAL_TABLES.items() if part in tables}
    return Case(name=tables.get("name", default_name), **parts)
