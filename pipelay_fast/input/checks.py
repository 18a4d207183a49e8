"""Lay code checks of DNV-ST-F101: the ``[checks]`` table and its equations.

The engine's static answer is checked the way a pipelay engineer checks a lay:

* **overbend**, where the pipe conforms to the stinger and its curvature is
  imposed (a displacement-controlled condition): the extreme-fibre strain
  |Tw/EA| + (Do/2) kappa over the user's limit ``overbend_strain_limit``;
* **sagbend**, where the free span carries its moment (a load-controlled
  condition): the local-buckling criterion for combined loading of
  DNVGL-ST-F101 (2017) Sec.5, pipe members under bending moment M_Sd,
  effective axial force S_Sd and overpressure. With g = gamma_m gamma_SC
  and the bending part

      B = g |M_Sd| / (alpha_c M_p) + (g S_Sd / (alpha_c S_p))^2,

  external overpressure (p_e >= p_i)::

      B^2 + (g (p_e - p_min) / p_c)^2 <= 1

  and internal overpressure (p_i > p_e)::

      B^2 + (alpha_p (p_i - p_e) / (alpha_c p_b))^2 <= 1,
      alpha_p = 1 - beta                          for (p_i - p_e)/p_b < 2/3,
                1 - 3 beta (1 - (p_i - p_e)/p_b)  otherwise

  (the two alpha_p branches meet at 2/3, and the two forms at p_i = p_e,
  where the pressure term vanishes in both). M_p = f_y (D - t2)^2 t2 and
  S_p = f_y pi (D - t2) t2 are the plastic capacities, alpha_c = (1 - beta)
  + beta f_u / f_y the flow-stress parameter (beta = 0.5 for D/t2 < 15,
  (60 - D/t2)/90 up to 60, 0 beyond), p_c the characteristic collapse
  pressure, the real root of [5.4.4.2]'s cubic (eq. 5.11) (p_c - p_el)(p_c^2
  - p_p^2) = p_c p_el p_p f0 D/t2, p_el = 2E (t2/D)^3 / (1 - nu^2) (eq.
  5.12), p_p = f_y alpha_fab 2 t2/D (eq. 5.13), f0 >= 0.005 (eq. 5.14), and
  p_b = 2 t2/(D - t2) f_cb 2/sqrt(3), f_cb = min(f_y, f_u/1.15), the
  pressure containment resistance ([5.4.2.2], eq. 5.8). p_min, the least
  internal pressure sustained, and p_i are the case's contents pressure (0
  for an empty pipe). The left-hand side is reported as the utilisation (1
  meets the criterion). During installation t2 = t, the nominal wall (Sec.5
  Table 5-5: t2 carries no fabrication tolerance, and no corrosion allowance
  before operation).

The criterion is stated for a range (as remembered: see "Not confirmed"
below): 15 <= D/t2 <= 45 (a ``[checks]`` table on a pipe outside it is
refused) and |S_Sd|/S_p < 0.4. The utilisation is
evaluated at every section, also where |S_Sd|/S_p >= 0.4: the summary
reports |S_Sd|/S_p at the section of the peak utilisation
(``sagbend_lcc_axial_ratio``, :func:`lcc_axial_ratio`), so that a peak
outside the range is seen (deep J-lay near the hang-off goes there: its
utilisation is then not the standard's).

Design load effects (Sec.4, the design load effect of the load effect
factor combinations) are L_Sd = gamma_F gamma_c L_F + gamma_E L_E for the
moment M and the effective axial force S: the functional part L_F is the
answer of the same case without current (weight and tension), the
environmental part L_E = L - L_F the current's share (current is among
Sec.4's environmental loads; OrcaFlex's F101 code check likewise takes the
functional load case as a static state without drag from current),
vectors of the moment added before the magnitude is taken. That costs a
second solve of a case with a current; ``current_load = "functional"``
factors the whole static answer by gamma_F gamma_c instead, with one solve.
The ULS load effect factors come in two combinations (Sec.4 Table 4-4):
a) gamma_F = 1.2, gamma_E = 0.7 (system effects present) and b) gamma_F =
1.1, gamma_E = 1.3 (not present); both are evaluated and the larger
utilisation reported, unless the user gives one pair. The overbend strain
is compared with its limit as computed (the limit is the project's).

Characteristic strengths are f_y = SMYS alpha_U and f_u = SMTS alpha_U
(Sec.5 [5.3.3.2], eq. 5.4 and 5.5) with no temperature derating: a lay is at
ambient temperature, below the 50 deg C where the derating of C-Mn steel
starts (Sec.5 [5.3.3.4], Figure 5-2).

Sources checked (facts and figures only; no copy of the standard's text
was found, so every item below is a secondary source's):

* DNVGL-ST-F101 (2017) clause, table and equation numbers and values as
  PDover2t cites and implements them (github.com/qwilka/PDover2t,
  pdover2t/dnvgl_st_f101/factor.py, material.py, pipe_collapse.py,
  pressure_containment.py, in the repository's history): Table 5-1
  ([5.3.2.3]) gamma_m 1.15 ULS; Table 5-2 ([5.3.2.4]) gamma_SC 1.04, 1.14,
  1.26; Table 5-3 ([5.3.3.6]) alpha_U 0.96, 1.00; Table 5-4 ([5.3.3.7])
  alpha_fab 1.00, 0.93, 0.85; eq. 5.4, 5.5 ([5.3.3.2]); Figure 5-2
  ([5.3.3.4]); [5.4.4.2] eq. 5.11 to 5.14 (the cubic, p_el, p_p, f0 >=
  0.005); [5.4.2.2] eq. 5.8, p_b with f_cb = min(f_y, f_u/1.15); Table 5-5,
  t2 without fabrication tolerance, no corrosion allowance before operation;
  collapse at [5.4.4] and propagation buckling at [5.4.5];
* the combined-loading criterion's definitions, from the paper that derives
  it (Collberg and Levold, DNV GL-ST-F101 combined loading criterion -
  background and derivation, OMAE2016-54238): S the effective force N -
  p_i A_i + p_e A_e, S_p = f_y (D - t) pi t, M_p = D_m^2 t f_y, alpha_c the
  strain-hardening correction, the criterion in this form since the 2007
  revision;
* the criterion's two forms, alpha_p and p_b as written above, in three
  independent public implementations that agree with each other (found by
  the code search, repositories not named by it: a numpy ``lcc`` "library
  of limit states", a JavaScript ``localBuckling``, a Python
  ``calculate_capacity_parameters_STF101``);
* DNV-OS-F101 (2012) Table 2-4: the temporary phase in the low safety class
  for every fluid category and location class (github.com/benranderson/
  wallthick, wallthick/dnvf101.py);
* the load effect factors gamma_F 1.1, gamma_E 1.3 of combination b as
  Flexcom's code-check defaults (flexcom.fea.solutions/
  kwd_codechecking_loadfactor.html); the functional load case without
  current (orcina.com/webhelp/OrcaFlex/Content/html/
  Codechecks,DNVfunctionalload.htm).

* the criterion's clause, [5.4.6] "Local buckling - combined loading
  criteria": DNV-ST-F101 (2021), "Changes - current", which lists an
  amendment to [5.4.6.6] under that title (the standard's preview copy,
  scribd.com/document/617918744);
* Table 4-4's two ULS combinations, a) gamma_F 1.2, gamma_E 0.7 (system
  effects present) and b) 1.1, 1.3, in three independent scripts that agree:
  pypelay's S-lay design (github.com/Pyseas/pypelay, src/pypelay/stinger.py,
  which sets combination a for the lay's load-controlled check), two
  OrcFxAPI code-check examples that loop over "condition a" and "condition
  b", and a DNV-ST-F101 (2021) load-controlled check found by the code
  search (its repository not named) that cites Table 4-4 for both;
* Table 4-5's condition load effect factor gamma_c: 1.00 "otherwise", 0.80
  for the load-controlled check of S-lay on the stinger (with 1.07 uneven
  seabed, 0.82 J-tube pull-in, 0.93 system pressure test, 0.77 and 0.82
  reeling), in that same DNV-ST-F101 (2021) implementation; pypelay applies
  1.00 in the sagbend and 0.80 over the stinger. The check here is the
  sagbend's, so the default is the "otherwise" row;
* the upper end of the criterion's range, D/t2 <= 45: the same
  implementation refuses a thicker ratio.

Not confirmed (as remembered from the 2017 edition; no source found): the
criterion's equation numbers; the lower end of its range, 15 <= D/t2, and
|S_Sd|/S_p < 0.4 (reported, not refused).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .validate import choice, fail, set_numbers

__all__ = ["CURRENT_LOADS", "Checks", "FABRICATION_FACTORS", "LCC_AXIAL_LIMIT",
           "LOAD_COMBINATIONS", "SAFETY_CLASS_FACTORS", "check_inputs", "collapse_pressure",
           "design_load_effects", "flow_stress_factor", "hardening_beta", "lcc_axial_ratio",
           "lcc_utilisation", "pressure_containment_resistance"]

# DNVGL-ST-F101 (2017) Sec.5 Table 5-2: safety class resistance factor gamma_SC
# for all checks but pressure containment
SAFETY_CLASS_FACTORS = {"low": 1.04, "medium": 1.14, "high": 1.26}
# DNVGL-ST-F101 (2017) Sec.5 Table 5-4: maximum fabrication factor alpha_fab
FABRICATION_FACTORS = {"seamless": 1.00, "UO": 0.93, "TRB": 0.93, "ERW": 0.93, "HFW": 0.93,
                       "UOE": 0.85}
# DNVGL-ST-F101 (2017) Sec.4 Table 4-4, ULS: load effect factor combinations
# (gamma_F, gamma_E), a) system effects present, b) not present
LOAD_COMBINATIONS = {"a": (1.2, 0.7), "b": (1.1, 1.3)}
SAFETY_CLASSES = tuple(SAFETY_CLASS_FACTORS)
CURRENT_LOADS = ("environmental", "functional")  # how the current's load effects are factored
MIN_OVALITY = 0.005  # Sec.5 [5.4.4.2], eq. 5.14: f0 not to be taken below 0.5 %
# the D/t2 range and the |S_Sd|/S_p bound the load-controlled criterion is stated for
# (45 confirmed by a secondary source; 15 and 0.4 as remembered from the 2017 edition)
LCC_SLENDERNESS = (15.0, 45.0)
LCC_AXIAL_LIMIT = 0.4


@dataclass(frozen=True, slots=True)
class Checks:
    """Code-check inputs, table ``[checks]`` (DNVGL-ST-F101, 2017 edition).

    Without the table the code-check columns are NaN. With it, the pipe
    needs ``pipe.smts`` (and uses ``pipe.smys``): from ``pipe.grade`` or
    given.

    Attributes
    ----------
    overbend_strain_limit : float
        Largest overbend strain accepted [-], axial plus bending at the
        extreme fibre; required (the standard's simplified overbend criteria,
        Sec.13, depend on the grade and the lay: the user's to give).
    ovality : float
        Initial out-of-roundness f0 = (Dmax - Dmin)/D [-], required, at least
        0.005 (Sec.5 [5.4.4.2], eq. 5.14): the linepipe's tolerance is the
        purchase specification's.
    alpha_fab : float or None
        Fabrication factor [-], in (0, 1]; or ``fabrication`` names the
        process: "seamless" 1.00, "UO", "TRB", "ERW", "HFW" 0.93, "UOE" 0.85
        (Sec.5 Table 5-4). Exactly one of the two is required.
    fabrication : str or None
        See ``alpha_fab``.
    safety_class : str
        "low" | "medium" | "high"; default "low", the normal class of the
        temporary phases, installation among them, for every fluid category
        and location class (Sec.2 Table 2-4).
    gamma_SC : float or None
        Safety class resistance factor [-]; default from ``safety_class``:
        1.04, 1.14, 1.26 (Sec.5 Table 5-2).
    gamma_m : float
        Material resistance factor [-]; default 1.15, ULS (Sec.5 Table 5-1).
    gamma_F, gamma_E : float or None
        Functional and environmental load effect factors [-], given as a
        pair or not at all. Not given: both ULS combinations of Sec.4
        Table 4-4, a) 1.2 and 0.7, b) 1.1 and 1.3, are checked and the larger
        utilisation is reported (:attr:`load_combinations`).
    gamma_c : float
        Condition load effect factor [-]; default 1.00, Sec.4 Table 4-5's
        "otherwise" row: the check is the sagbend's, where none of the
        table's conditions applies (its 0.80 is for the load-controlled
        check of S-lay on the stinger). Give the table's value where a
        condition of the lay applies.
    current_load : str
        "environmental" (the default: the current is an environmental load,
        Sec.4; its share of the load effects, found by solving the case
        a second time without current, is factored by gamma_E) or
        "functional" (the whole static answer by gamma_F gamma_c; one solve).
    alpha_U : float
        Material strength factor [-]; default 0.96, 1.00 with supplementary
        requirement U (Sec.5 Table 5-3).
    """

    overbend_strain_limit: float
    ovality: float
    alpha_fab: float | None = None
    fabrication: str | None = None
    safety_class: str = "low"
    gamma_SC: float | None = None
    gamma_m: float = 1.15
    gamma_F: float | None = None
    gamma_E: float | None = None
    gamma_c: float = 1.0
    current_load: str = "environmental"
    alpha_U: float = 0.96

    def __post_init__(self):
        p = "checks"
        choice(f"{p}.safety_class", self.safety_class, SAFETY_CLASSES)
        choice(f"{p}.current_load", self.current_load, CURRENT_LOADS)
        given = [name for name in ("alpha_fab", "fabrication") if getattr(self, name) is not None]
        if not given:
            raise ValueError(f"missing key {p}.alpha_fab (or {p}.fabrication): the fabrication "
                             "factor of DNVGL-ST-F101 Table 5-4 depends on how the pipe is made")
        if len(given) == 2:
            fail(f"{p}.alpha_fab", self.alpha_fab,
                 f"is given with {p}.fabrication = {self.fabrication!r}: give one of the two")
        if self.fabrication is not None:
            choice(f"{p}.fabrication", self.fabrication, tuple(FABRICATION_FACTORS))
        factors = [name for name in ("gamma_F", "gamma_E") if getattr(self, name) is not None]
        if len(factors) == 1:
            other = "gamma_E" if factors == ["gamma_F"] else "gamma_F"
            raise ValueError(f"missing key {p}.{other}: {p}.{factors[0]} is given, and the load "
                             "effect factors go as a pair (DNVGL-ST-F101 Table 4-4); give both "
                             "or neither (neither: combinations a and b)")
        optional = [name for name in ("alpha_fab", "gamma_SC", *factors)
                    if getattr(self, name) is not None]
        set_numbers(self, p, positive=("overbend_strain_limit", "ovality", "gamma_m", "gamma_c",
                                       "alpha_U", *optional))
        if self.ovality < MIN_OVALITY:
            fail(f"{p}.ovality", self.ovality, f"is below {MIN_OVALITY}, the least "
                 "DNVGL-ST-F101 eq. 5.14 allows")
        for name in ("alpha_fab", "alpha_U"):
            if getattr(self, name) is not None and getattr(self, name) > 1.0:
                fail(f"{p}.{name}", getattr(self, name), "must not exceed 1")

    @property
    def safety_factor(self) -> float:
        """gamma_SC [-]: as given, else the safety class's (Table 5-2)."""
        return self.gamma_SC if self.gamma_SC is not None else SAFETY_CLASS_FACTORS[
            self.safety_class]

    @property
    def fabrication_factor(self) -> float:
        """alpha_fab [-]: as given, else the fabrication process's (Table 5-4)."""
        return self.alpha_fab if self.alpha_fab is not None else FABRICATION_FACTORS[
            self.fabrication]

    @property
    def resistance_factor(self) -> float:
        """gamma_m gamma_SC [-]."""
        return self.gamma_m * self.safety_factor

    @property
    def load_combinations(self) -> tuple[tuple[float, float], ...]:
        """The (gamma_F, gamma_E) pairs [-] checked: the one given, else
        Table 4-4's combinations a and b."""
        if self.gamma_F is not None:
            return ((self.gamma_F, self.gamma_E),)
        return tuple(LOAD_COMBINATIONS.values())

    def splits_current(self, case) -> bool:
        """Whether ``case``'s current is factored apart (it has one, and
        ``current_load`` is "environmental")."""
        return self.current_load == "environmental" and case.environment.current.speed > 0.0


def check_inputs(pipe, checks: Checks | None) -> None:
    """Refuse a ``[checks]`` table the pipe cannot be checked with: no
    ``pipe.smts`` (SMYS given without it), or D/t outside the criterion's 15
    to 45. (:class:`pipelay_fast.input.pipe.Pipe` refuses SMTS below SMYS.)"""
    if checks is None:
        return
    if pipe.smts is None:
        raise ValueError("missing key pipe.smts: the [checks] need the specified minimum "
                         "tensile strength SMTS [Pa] (DNVGL-ST-F101 eq. 5.5); give "
                         "pipe.smts with pipe.smys, or pipe.grade instead of both")
    slenderness = pipe.outer_diameter / pipe.wall_thickness
    lo, hi = LCC_SLENDERNESS
    if not lo <= slenderness <= hi:
        fail("pipe.inner_diameter", pipe.inner_diameter,
             f"makes D/t = {slenderness:.4g}, outside {lo:g} to {hi:g} where the "
             "load-controlled check of DNVGL-ST-F101 is stated; remove [checks]")


def hardening_beta(slenderness: float) -> float:
    """beta [-] of D/t2 = ``slenderness``: 0.5 below 15, (60 - D/t2)/90 up
    to 60, 0 beyond."""
    if slenderness < 15.0:
        return 0.5
    if slenderness <= 60.0:
        return (60.0 - slenderness) / 90.0
    return 0.0


def flow_stress_factor(slenderness: float, fy: float, fu: float) -> float:
    """alpha_c = (1 - beta) + beta f_u/f_y [-] of D/t2 = ``slenderness``."""
    beta = hardening_beta(slenderness)
    return (1.0 - beta) + beta * fu / fy


def pressure_containment_resistance(pipe, checks: Checks) -> float:
    """p_b = 2 t/(D - t) f_cb 2/sqrt(3) [Pa], f_cb = min(f_y, f_u/1.15), of
    ``pipe``'s nominal wall t (t2 during installation)."""
    d, t = pipe.outer_diameter, pipe.wall_thickness
    f_cb = min(pipe.smys, pipe.smts / 1.15) * checks.alpha_U
    return 2.0 * t / (d - t) * f_cb * 2.0 / math.sqrt(3.0)


def collapse_pressure(pipe, checks: Checks) -> float:
    """Characteristic collapse pressure p_c [Pa] of ``pipe``.

    The cubic (p_c - p_el)(p_c^2 - p_p^2) = p_c p_el p_p f0 D/t, written
    p^3 - p_el p^2 - (p_p^2 + p_el p_p f0 D/t) p + p_el p_p^2 = 0, has three
    real roots; p_c is the one below both p_el and p_p (the cubic is positive
    at 0 and negative at min(p_el, p_p)), found by bisection down to
    neighbouring floats (some 60 halvings of a cubic: no cache).
    """
    d, t, fy = pipe.outer_diameter, pipe.wall_thickness, pipe.smys * checks.alpha_U
    youngs_modulus, poisson_ratio = pipe.youngs_modulus, pipe.poisson_ratio
    fabrication_factor, ovality = checks.fabrication_factor, checks.ovality
    p_el = 2.0 * youngs_modulus * (t / d) ** 3 / (1.0 - poisson_ratio**2)
    p_p = fy * fabrication_factor * 2.0 * t / d
    c1 = p_p**2 + p_el * p_p * ovality * d / t

    def cubic(p):
        return ((p - p_el) * p - c1) * p + p_el * p_p**2

    lo, hi = 0.0, min(p_el, p_p)
    while True:
        mid = 0.5 * (lo + hi)
        if not lo < mid < hi:  # the bracket is two neighbouring floats
            return mid
        if cubic(mid) > 0.0:
            lo = mid
        else:
            hi = mid


def design_load_effects(checks: Checks, combination, moment, tension, functional=None):
    """(|M_Sd| [N m], S_Sd [N]) per section, Sec.4's design load effect with
    the load effect factors ``combination`` = (gamma_F, gamma_E), from the moment
    vectors ``moment`` (shape (n, 3)) and effective tensions ``tension``;
    ``functional``: the same of the functional load case (weight and tension
    alone), whose difference from the total is the environmental share. None:
    all functional (factored by gamma_F gamma_c)."""
    gamma_f, gamma_e = combination
    on_functional = gamma_f * checks.gamma_c
    moment = np.asarray(moment, dtype=float)
    tension = np.asarray(tension, dtype=float)
    if functional is None:
        return on_functional * np.linalg.norm(moment, axis=1), on_functional * tension
    m_f, t_f = (np.asarray(v, dtype=float) for v in functional)
    m_sd = on_functional * m_f + gamma_e * (moment - m_f)
    s_sd = on_functional * t_f + gamma_e * (tension - t_f)
    return np.linalg.norm(m_sd, axis=1), s_sd


def lcc_axial_ratio(pipe, checks: Checks, design_tension):
    """|S_Sd|/S_p [-] per section, S_p = f_y pi (D - t2) t2: the
    load-controlled criterion is stated for values below ``LCC_AXIAL_LIMIT``
    = 0.4 (as remembered; not confirmed by a source)."""
    d, t = pipe.outer_diameter, pipe.wall_thickness
    s_p = pipe.smys * checks.alpha_U * math.pi * (d - t) * t
    return np.abs(np.asarray(design_tension, dtype=float)) / s_p


def lcc_utilisation(pipe, checks: Checks, design_moment, design_tension, external_pressure,
                    internal_pressure):
    """Left-hand side of the load-controlled criterion [-] per section.

    ``design_moment`` |M_Sd| [N m] and ``design_tension`` S_Sd [N] (the
    factored effects, :func:`design_load_effects`), pressures [Pa]: arrays
    of one value per section. Where the external pressure is at least the
    contents pressure, the external-overpressure form (p_min the contents
    pressure); where the contents pressure exceeds it, the
    internal-overpressure form with alpha_p and p_b
    (:func:`pressure_containment_resistance`). Where |S_Sd|/S_p >= 0.4
    (:func:`lcc_axial_ratio`) the value is outside the range the criterion
    is stated for.
    """
    d, t = pipe.outer_diameter, pipe.wall_thickness
    fy, fu = pipe.smys * checks.alpha_U, pipe.smts * checks.alpha_U
    beta = hardening_beta(d / t)
    alpha_c = flow_stress_factor(d / t, fy, fu)
    m_p = fy * (d - t) ** 2 * t
    s_p = fy * math.pi * (d - t) * t
    g = checks.resistance_factor
    m_sd = np.abs(np.asarray(design_moment, dtype=float))
    s_sd = np.asarray(design_tension, dtype=float)
    over = np.asarray(external_pressure, dtype=float) - np.asarray(internal_pressure, dtype=float)
    bending = (g * m_sd / (alpha_c * m_p) + (g * s_sd / (alpha_c * s_p)) ** 2) ** 2
    external = bending + (g * over / collapse_pressure(pipe, checks)) ** 2
    p_b = pressure_containment_resistance(pipe, checks)
    burst = -over / p_b  # (p_i - p_e)/p_b
    alpha_p = np.where(burst < 2.0 / 3.0, 1.0 - beta, 1.0 - 3.0 * beta * (1.0 - burst))
    internal = bending + (alpha_p * burst / alpha_c) ** 2
    return np.where(over >= 0.0, external, internal)
