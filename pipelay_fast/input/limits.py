"""Where the model ends and how much work a solve may take.

**The strain line** (``solver.max_strain``, default 0.02). The rod model
(README, Method in one paragraph) is linearly elastic in small strain: Tw =
EA eps with r'.r' = (1 + eps)^2, M = EI kappa per unstretched length, sections plane and
circular. Yield is not the line: steel stops being linear at SMYS/E (0.2 % for
the paper's pipe), but an answer beyond it is what the code checks downstream
exist to flag, and lay design puts static overbend strains at a few tenths of
a per cent, so the engine must report strains past yield. The line is where
the small-strain kinematics stop meaning one thing: the linear law holds in one
strain measure, and the engineering, Green (eps + eps^2/2) and logarithmic
(eps - eps^2/2) measures differ by eps/2 of the strain. At 2 % the same
stretch gives forces 1 % apart, ten times the discretisation error the engine
is built to (0.1 % on stress), and several times any strain a lay design
accepts, so the line refuses no case a code check could pass. The strain
checked is the extreme fibre's, |eps| + (Do/2) kappa; for an inextensible pipe
(``pipe.extensible = false``, centreline length held by assumption) the bending
part alone: its Tw/EA is reported for the stresses but is not in the geometry.
Hoop stress is an output of the pressures (the section keeps its shape by
assumption), not a strain of the model, and is not checked here.

Inputs that imply a strain past the line are refused before the solve with a
ValueError naming the keys (:func:`check_case`): the wall strain at the top for
a given top tension, at the lower end for a given bottom tension, and the
bending strain of a pipe conforming to the stinger. An answer past it is
refused after the solve (:func:`strain_beyond_line`).

**Budgets.** ``solver.max_elements`` bounds the mesh before any array is built
(:func:`check_mesh_size`); ``solver.max_iterations_total`` bounds the Newton
iterations of one solve, over load steps, current steps, remeshing passes and
laid-length doublings (:class:`IterationBudget`). Each ends a solve with an
error that names the key.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# The input layer's tuning constants.
# The package's round-off: the relative difference [-] below which two of its
# numbers are the same, from the user's numbers to the kernels' (one value for
# every layer; :mod:`pipelay_fast.kernels.tuning` takes it from here). The
# solver's numbers are sums of up to ~1e5 terms (arc lengths, element counts of
# a graded stretch, positions of order 1e3 m), 1e5 * EPS = 2e-11 of their size,
# with a margin of 50; those a few float operations make from the user's are
# within it too (a few ulps of 2.2e-16; sin(0) of a heading in degrees is
# 1.2e-16), and 1e-9 of a position of 1e3 m is a micrometre. Here: a stinger's
# end against lay.top, a count of roller spacings, a unit current direction's
# lateral component (planar below it), a root of a cubic in t in [0, 1]
# (np.roots, :func:`pipelay_fast.study.sensitivity.hermite_root`), a sweep
# range's count of steps.
ROUNDOFF = 1e-9
# The most a stinger may turn the pipe between its ends [deg]: beyond it the
# stinger overhangs, its tip pointing back under the pipe from the vessel.
MAX_STINGER_TURN = 90.0

__all__ = ["IterationBudget", "check_case", "check_mesh_size", "strain_beyond_line",
           "stinger_bending_strain"]


def stinger_bending_strain(outer_diameter: float, stinger) -> tuple[float, float]:
    """(largest bending strain (Do/2) kappa [-] of a pipe of steel outer diameter
    ``outer_diameter`` [m] conforming to ``stinger``, z where it is [m]).

    kappa = 2|a| / (1 + x'^2)^(3/2) is largest nearest the parabola's vertex
    z = -b / (2a), clipped to the stinger's span.
    """
    z_l, z_u = stinger.lower[1], stinger.upper[1]
    z = z_l if stinger.a == 0.0 else min(max(-stinger.b / (2.0 * stinger.a), z_l), z_u)
    kappa = 2.0 * abs(stinger.a) / (1.0 + float(stinger.slope(z)) ** 2) ** 1.5
    return 0.5 * outer_diameter * kappa, z


def check_case(case) -> None:
    """Refuse a case whose inputs alone put a strain beyond ``solver.max_strain``.

    Raises
    ------
    ValueError
        Naming the keys and the strain they give.
    """
    pipe, lay, limit = case.pipe, case.lay, case.solver.max_strain
    line = f"beyond solver.max_strain = {limit:g} of the small-strain model"
    st = lay.curve
    if st is not None:  # (rollers: the answer's strain is checked)
        st = st.vessel  # (a trim turns the curve, not its curvature)
        strain, z = stinger_bending_strain(pipe.outer_diameter, st)
        if strain > limit:
            raise ValueError(
                f"lay.stinger.a = {st.a!r} bends the pipe on the stinger to a radius of "
                f"{0.5 * pipe.outer_diameter / strain:.4g} m at z = {z:.4g} m: bending strain "
                f"(Do/2) kappa = {strain:.4g} with pipe.outer_diameter = "
                f"{pipe.outer_diameter!r} m, {line}")
    if not pipe.extensible:
        return
    ea = pipe.axial_stiffness
    ends = []
    if lay.top_tension is not None:
        ends.append(("lay.top_tension", lay.top_tension, "top", lay.top[0]))
    if lay.bottom_tension is not None:
        ends.append(("lay.bottom_tension", lay.bottom_tension, "lower end", 0.0))
    for key, tension, where, x in ends:
        strain = float(case.wall_tension(tension, x)) / ea
        if abs(strain) > limit:
            raise ValueError(
                f"the wall strain Tw/EA = {strain:.4g} at the {where} is {line}: "
                f"{key} = {tension!r} N on a steel section of {pipe.steel_area:.4g} m2 "
                f"(pipe.outer_diameter = {pipe.outer_diameter!r} m, pipe.inner_diameter = "
                f"{pipe.inner_diameter!r} m) with pipe.youngs_modulus = "
                f"{pipe.youngs_modulus!r} Pa, EA = {ea:.4g} N (x = {x:g} m, external pressure "
                f"{float(case.external_pressure(x)):.4g} Pa from environment.water_depth = "
                f"{case.environment.water_depth!r} m)")


def strain_beyond_line(case, columns: dict) -> str | None:
    """Why a solved profile lies beyond ``solver.max_strain`` (None if it does not).

    ``columns``: the profile columns (``s, x, z, axial_strain, curvature`` used).
    """
    limit = case.solver.max_strain
    bending = columns["curvature"] * (0.5 * case.pipe.outer_diameter)
    axial = np.abs(columns["axial_strain"]) if case.pipe.extensible else np.zeros_like(bending)
    fibre = axial + bending
    k = int(np.argmax(fibre))
    if fibre[k] <= limit:
        return None
    return (f"the strain reaches {fibre[k]:.4g} (axial {axial[k]:.4g}, bending "
            f"{bending[k]:.4g}) at s = {columns['s'][k]:.5g} m (x = {columns['x'][k]:.4g} m, "
            f"z = {columns['z'][k]:.5g} m), beyond solver.max_strain = {limit:g} of the "
            "small-strain model; the solution is not returned")


def check_mesh_size(case, n_elements: int, length: float, laid: float, laid_source: str) -> None:
    """Refuse a mesh of more than ``solver.max_elements`` before it is built.

    ``length`` [m] is the pipe modelled, ``laid`` [m] the part on the seabed
    behind touchdown and ``laid_source`` what set it (keys and defaults).

    Raises
    ------
    ValueError
        Naming solver.max_elements, solver.element_length and the laid length.
    """
    sv = case.solver
    if n_elements <= sv.max_elements:
        return
    raise ValueError(
        f"case {case.name!r}: the mesh would have {n_elements} elements, more than "
        f"solver.max_elements = {sv.max_elements}: {length:.4g} m of pipe at "
        f"solver.element_length = {sv.element_length!r} m, {laid:.4g} m of it laid "
        f"({laid_source}); set a longer solver.element_length or a shorter "
        "solver.laid_length, or raise solver.max_elements")


@dataclass
class IterationBudget:
    """Newton iterations left to one solve: ``limit`` is
    ``solver.max_iterations_total``; ``used`` counts the iterations the Newton
    calls report (the steps taken; a converged call's last check is not one)."""

    limit: int
    used: int = 0

    @property
    def left(self) -> int:
        """Iterations not yet spent [-]."""
        return self.limit - self.used

    def cap(self, maxit: int) -> int:
        """The ``maxit`` of the next Newton call: ``maxit`` within what is left,
        plus the check that ends a converged call."""
        return min(maxit, self.left + 1)

    def charge(self, iterations: float) -> None:
        """Count a call's reported iterations (a failed call's last, unchecked
        step past the budget is not counted)."""
        self.used += min(int(iterations), self.left)

    def spent_message(self, where: str) -> str:
        """Why a solve stopped at ``where`` (a load step) with the budget spent."""
        return (f"did not converge within solver.max_iterations_total = {self.limit} Newton "
                f"iterations, spent by {where}: the load path is being followed in ever "
                "smaller steps (an input far outside the usual, e.g. a very strong current, "
                "is the common cause); raise solver.max_iterations_total to let it go on")
