"""Inputs outside the model, or beyond a solve's budget, end in an error that
names the key and the limit; none hangs and none returns an answer.

Each corrupted input is one a new user could type (from the bundled examples).
The numbers the messages must quote are computed here from the pipe data:
EA = E pi (Do^2 - Di^2)/4, EI = E pi (Do^4 - Di^4)/64, the stinger's b from
its end points. Every refusal is reached before the mesh is built, or within
a Newton budget small enough to end in seconds.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.engine.mesh import graded_nodes
from pipelay_fast.engine.tuning import SMALLEST_LOAD_STEP
from pipelay_fast.input.limits import check_case
from tests.helpers import EXAMPLES, refused

SWEEPS = Path(__file__).resolve().parents[1] / "sweeps"
RHO_G = 1025.0 * 9.81  # N/m3, the examples' sea


@pytest.fixture(scope="module")
def s67():
    return pf.load_case(EXAMPLES / "s67.toml")


def axial_stiffness(case):
    """EA [N] from the pipe keys."""
    p = case.pipe
    return p.youngs_modulus * math.pi * (p.outer_diameter**2 - p.inner_diameter**2) / 4.0


def elements_in(message):
    return int(re.search(r"would have (\d+) elements", message).group(1))


# --------------------------------------------------------------------------- strain up front


@pytest.mark.parametrize(("changes", "top_pressure"), [
    pytest.param({"pipe.youngs_modulus": 1e6}, 0.0, id="E-1-MPa"),
    pytest.param({"lay.top_tension": 1e10}, 0.0, id="top-tension-1e10-N"),
    pytest.param({"pipe.outer_diameter": 1e-6, "pipe.inner_diameter": 0.5e-6}, 0.0,
                 id="steel-OD-1-micrometre"),
    # the hang-off (x = 130 m) 1e6 - 130 m under water: pe Ae crushes the wall
    pytest.param({"environment.water_depth": 1e6}, RHO_G * (1e6 - 130.0),
                 id="hang-off-1e6-m-under-water"),
])
def test_top_tension_beyond_the_strain_line_is_refused(j125, changes, top_pressure):
    """Wall strain at the top Tw/EA, Tw = T_top - pe Ae (empty pipe)."""
    message = refused(j125, changes)
    # (without the example's [checks]: a 1 um pipe is outside their D/t range)
    case = j125.with_changes({**changes, "solver.max_strain": 0.1, "pipe.extensible": False,
                              "checks": None})
    outer = math.pi * case.pipe.outer_diameter**2 / 4.0
    strain = (case.lay.top_tension - top_pressure * outer) / axial_stiffness(case)
    assert abs(strain) > 0.1
    assert "lay.top_tension" in message and "solver.max_strain = 0.02" in message
    assert f"Tw/EA = {strain:.4g} at the top" in message
    for key, value in changes.items():  # the key that made the strain, with its value
        assert f"{key} = {value!r}" in message


def test_bottom_tension_beyond_the_strain_line_is_refused(j125):
    """At the lower end Tw = T_b - pe(0) Ae, pe(0) = rho g d."""
    changes = {"lay.top_tension": None, "lay.bottom_tension": 2e8}
    message = refused(j125, changes)
    outer = math.pi * 0.61**2 / 4.0
    strain = (2e8 - RHO_G * 125.0 * outer) / axial_stiffness(j125)
    assert "lay.bottom_tension = 200000000.0" in message
    assert f"Tw/EA = {strain:.4g} at the lower end" in message


def test_an_inextensible_pipe_is_checked_on_bending_alone(j125):
    """Its centreline length is held: the cable limit of tests/test_jlay.py
    (E = 207 kPa, Tw/EA about a hundred) is a valid case."""
    soft = {"pipe.youngs_modulus": 207e3}
    assert "pipe.youngs_modulus" in refused(j125, soft)
    case = j125.with_changes({**soft, "pipe.extensible": False})
    assert case.lay.top_tension / axial_stiffness(case) > 50.0


def test_the_strain_line_is_the_solver_key(j125):
    """Raised to 0.1, the 1e10 N top tension (1.7 strain) is still refused;
    lowered below the top's 1e-4, the bundled J125 is."""
    assert "solver.max_strain = 0.1" in refused(j125, {"lay.top_tension": 1e10,
                                                        "solver.max_strain": 0.1})
    top = j125.lay.top_tension / axial_stiffness(j125)
    assert "lay.top_tension" in refused(j125, {"solver.max_strain": 0.5 * top})


# --------------------------------------------------------------------------- stinger geometry


def stinger_b(a, lower, upper):
    (x_l, z_l), (x_u, z_u) = lower, upper
    return (x_u - x_l) / (z_u - z_l) - a * (z_u + z_l)


@pytest.mark.parametrize("a", [0.01, 0.0005])
def test_a_concave_up_stinger_is_refused(s67, a):
    message = refused(s67, {"lay.stinger.a": a})
    assert f"lay.stinger.a = {a!r}" in message and "concave down" in message


def test_a_stinger_falling_towards_the_vessel_is_refused(s67):
    message = refused(s67, {"lay.stinger.upper": [30.0, 400.0]})
    assert "lay.stinger.upper = (30.0, 400.0) lies below" in message
    assert "lay.stinger.lower = (41.5, 265.0)" in message


@pytest.mark.parametrize("a", [-0.5, -0.02])
def test_a_stinger_turning_the_pipe_past_90_degrees_is_refused(s67, a):
    """S67's ends: a = -0.02 rises 80 m above the sea between them and comes
    down to the vessel at -68 deg; a = -0.5 is a 2 km spike."""
    lower, upper = (41.5, 265.0), (72.0, 400.0)
    b = stinger_b(a, lower, upper)
    tip, top = (math.degrees(math.atan(2 * a * z + b)) for z in (lower[1], upper[1]))
    assert tip - top > 90.0
    message = refused(s67, {"lay.stinger.a": a})
    assert f"lay.stinger.a = {a!r} turns the stinger through {tip - top:.4g} deg" in message


def test_a_stinger_bending_the_pipe_past_the_strain_line_is_refused(s67):
    """A 10 m stinger, its vertex at the upper end (radius 1/(2|a|) = 10 m
    there), turns the pipe by only 45 deg but bends the 0.61 m pipe to
    (Do/2) 2|a| = 3.05 % strain."""
    a = -0.05
    message = refused(s67, {"lay.stinger.a": a, "lay.stinger.lower": [67.0, 260.0],
                            "lay.stinger.upper": [72.0, 270.0]})
    assert f"lay.stinger.a = {a!r} bends the pipe" in message
    assert f"radius of {1 / (2 * abs(a)):.4g} m at z = 270 m" in message
    assert f"strain (Do/2) kappa = {0.305 * 2 * abs(a):.4g}" in message


def test_the_stinger_bending_strain_is_the_largest_along_it(s67):
    """S67 (vertex beyond the upper end): kappa = 2|a| / (1 + x'^2)^1.5 at z_U;
    refused once max_strain is below it, accepted above."""
    a, lower, upper = -0.0012, (41.5, 265.0), (72.0, 400.0)
    slope = 2 * a * upper[1] + stinger_b(a, lower, upper)
    strain = 0.305 * 2 * abs(a) / (1 + slope**2) ** 1.5
    message = refused(s67, {"solver.max_strain": 0.99 * strain})
    assert f"strain (Do/2) kappa = {strain:.4g}" in message and "z = 400 m" in message
    s67.with_changes({"solver.max_strain": 1.01 * strain})


def paper_stinger_cases():
    """(scene name, case) over the paper sweep's range of a, each S-lay scene."""
    sweep = tomllib.loads((SWEEPS / "paper.toml").read_text())
    span = sweep["vary"]["a"]
    grid = np.arange(span["start"], span["stop"] + 0.5 * span["step"], span["step"])
    assert grid.size == 13 and grid[-1] == pytest.approx(-0.0021)
    for scene in sweep["scenes"]:
        if "stinger_lower" not in scene:
            continue
        base = pf.load_case(EXAMPLES / f"{scene['case']}.toml")
        for a in grid:
            yield scene["name"], base.with_changes({
                "lay.stinger.a": float(a), "lay.stinger.lower": scene["stinger_lower"],
                "lay.stinger.upper": scene["stinger_upper"]})


def test_the_paper_scenes_pass_the_checks():
    """Every bundled example, and S67 and S125 over the paper's a from -0.0009
    to -0.0021 (S67's upper end then slopes down at -3.3 deg: still accepted),
    pass the geometry and strain checks (the cases build: no ValueError)."""
    for path in sorted(EXAMPLES.glob("*.toml")):
        check_case(pf.load_case(path))
    names = [name for name, case in paper_stinger_cases()]
    assert names.count("S67") == names.count("S125") == 13


# --------------------------------------------------------------------------- mesh size


@pytest.mark.parametrize(("length", "foci", "h_max", "h_min", "grading"), [
    (517.6, [25.0, 517.6], 4.0, 0.5, True),
    (517.6, [25.0, 300.0, 517.6], 1.0, 0.02, True),
    (3.0, [1.0], 4.0, 4.0, True),
    (517.6, [25.0], 4.0, 0.5, False),
])
def test_element_count_is_the_size_of_the_mesh(length, foci, h_max, h_min, grading):
    """The count the size check sees before any node is placed is the mesh's."""
    seen = []
    nodes = graded_nodes(length, foci, h_max, h_min, grading=grading, check=seen.append)
    assert seen == [nodes.size - 1]


def test_tiny_elements_are_refused_before_the_mesh_is_built(j125):
    """1e-4 m elements: the pipe climbs 130 m to the hang-off, so over 1.3
    million elements (3.7 million over the ~370 m modelled)."""
    case = j125.with_changes({"solver.element_length": 1e-4})
    with pytest.raises(ValueError) as info:
        pf.solve(case)
    message = str(info.value)
    assert "solver.element_length = 0.0001 m" in message
    assert "solver.max_elements = 20000" in message
    assert elements_in(message) > 130.0 / 1e-4


def test_a_long_laid_length_is_refused_before_the_mesh_is_built(j125):
    with pytest.raises(ValueError) as info:
        pf.solve(j125.with_changes({"solver.laid_length": 1e7}))
    message = str(info.value)
    assert "solver.laid_length = 10000000.0 m" in message
    assert elements_in(message) >= 1e7 / 4.0


def test_a_millinewton_bottom_tension_is_refused_by_the_mesh_size(j125):
    """T_b = 1 mN: the default laid length of two flexural lengths
    sqrt(EI/T) would be a thousand kilometres of pipe."""
    case = j125.with_changes({"lay.top_tension": None, "lay.bottom_tension": 1e-3})
    with pytest.raises(ValueError) as info:
        pf.solve(case)
    message = str(info.value)
    p = case.pipe
    ei = p.youngs_modulus * math.pi * (p.outer_diameter**4 - p.inner_diameter**4) / 64.0
    flexural = math.sqrt(ei / 1e-3)
    assert f"sqrt(EI/T) = {flexural:.4g} m" in message and "solver.laid_length" in message
    assert "lay.bottom_tension = 0.001 N" in message  # the key that makes it long
    assert elements_in(message) >= 2.0 * flexural / 4.0


def test_a_50_metre_per_second_lateral_current_is_refused_by_the_mesh_size():
    """The drag at touchdown needs ~160 km of laid pipe for friction to carry."""
    case = pf.load_case(EXAMPLES / "j125_3d.toml").with_changes(
        {"environment.current.speed": 50.0})
    with pytest.raises(ValueError) as info:
        pf.solve(case)
    message = str(info.value)
    assert "solver.max_elements" in message and "environment.current.speed" in message
    assert "seabed.lateral_friction" in message


# --------------------------------------------------------------------------- Newton budget


def test_the_iteration_budget_counts_every_newton_iteration(s67):
    """S67 (still water) solved with exactly the iterations it reports, and
    refused, naming the budget, with one fewer."""
    still = s67.with_changes({"environment.current.speed": 0.0})
    used = pf.solve(still).summary["n_iterations"]
    assert used > 1
    pf.solve(still.with_changes({"solver.max_iterations_total": used}))
    with pytest.raises(pf.SolveError) as info:
        pf.solve(still.with_changes({"solver.max_iterations_total": used - 1}))
    assert f"did not converge within solver.max_iterations_total = {used - 1}" in str(
        info.value)


def test_a_50_metre_per_second_current_ends_within_the_budget(s67):
    """Along the lay (2D), the solve ends when a load step is cut below its
    floor or the budget (200 here, to end in a second) is spent, whichever
    comes first; the message says which, and which solve spent the budget
    (a load path's step, or a mesh's first Newton solve)."""
    with pytest.raises(pf.SolveError) as info:
        pf.solve(s67.with_changes({"environment.current.speed": 50.0,
                                   "solver.max_iterations_total": 200}))
    message = str(info.value)
    assert "'s67' did not converge" in message
    assert (("within solver.max_iterations_total = 200" in message
             and ("load step" in message or "the first Newton solve on a mesh" in message))
            or f"load step cut below {SMALLEST_LOAD_STEP:g}" in message)


# --------------------------------------------------------------------------- strain after


def test_a_vertical_top_at_580_kN_is_strained_beyond_the_line(j125):
    """Held at 90 deg, 44 deg off its natural angle at 580 kN, J125 bends to a
    15 m radius at the hang-off: the answer (2.1 % strain there, as solved
    with the line at 10 %) is refused, quoting it."""
    case = j125.with_changes({"lay.top_angle": 90.0})
    loose = pf.solve(case.with_changes({"solver.max_strain": 0.1}))
    prof = loose.profile
    fibre = prof["axial_strain"].abs() + 0.305 * prof["curvature"]
    k = int(np.argmax(fibre.to_numpy()))
    assert fibre.iloc[k] > 0.02 and k == len(prof) - 1
    with pytest.raises(pf.SolveError) as info:
        pf.solve(case)
    message = str(info.value)
    assert f"the strain reaches {fibre.iloc[k]:.4g}" in message
    assert f"s = {prof['s'].iloc[k]:.5g} m" in message
    assert "solver.max_strain = 0.02" in message and "not returned" in message
