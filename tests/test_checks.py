"""The ``[checks]`` table and the DNV-ST-F101 equations of pipelay_fast.input.checks."""

from __future__ import annotations

import numpy as np
import pytest

import pipelay_fast as pf
from pipelay_fast.input.checks import (
    Checks,
    collapse_pressure,
    flow_stress_factor,
    lcc_axial_ratio,
    lcc_utilisation,
    pressure_containment_resistance,
)
from tests.helpers import EXAMPLES

REQUIRED = {"overbend_strain_limit": 0.0025, "ovality": 0.01, "fabrication": "UOE"}


@pytest.fixture(scope="module")
def tables():
    case = pf.load_case(EXAMPLES / "s67.toml")
    out = case.to_dict()
    out.pop("checks", None)
    out["pipe"]["smts"] = 531e6
    return out


def _with(tables, checks=None, **pipe):
    new = {**tables, "pipe": {**tables["pipe"], **pipe}}
    if checks is not None:
        new["checks"] = checks
    return new


def test_defaults_name_their_tables(tables):
    checks = pf.load_case(_with(tables, REQUIRED)).checks
    assert (checks.safety_class, checks.safety_factor, checks.gamma_m, checks.gamma_F,
            checks.gamma_E, checks.gamma_c, checks.alpha_U, checks.fabrication_factor,
            checks.current_load) == ("low", 1.04, 1.15, None, None, 1.0, 0.96, 0.85,
                                     "environmental")
    # DNVGL-ST-F101 Table 4-4, ULS: a) 1.2, 0.7 (system effects present), b) 1.1, 1.3 (not)
    assert checks.load_combinations == ((1.2, 0.7), (1.1, 1.3))
    pair = Checks(**{**REQUIRED, "gamma_F": 1.1, "gamma_E": 1.3})
    assert pair.load_combinations == ((1.1, 1.3),)
    high = pf.load_case(_with(tables, {**REQUIRED, "safety_class": "high"})).checks
    assert high.safety_factor == 1.26
    assert Checks(**{**REQUIRED, "gamma_SC": 1.2}).resistance_factor == pytest.approx(1.15 * 1.2)


def test_changing_the_class_rederives_its_factor(tables):
    case = pf.load_case(_with(tables, REQUIRED))
    assert case.with_changes({"checks.safety_class": "medium"}).checks.safety_factor == 1.14
    seamless = case.with_changes({"checks.fabrication": "seamless"})
    assert seamless.checks.fabrication_factor == 1.0


@pytest.mark.parametrize(("checks", "pipe", "message"), [
    ({"ovality": 0.01, "fabrication": "UOE"}, {},
     "missing required key checks.overbend_strain_limit"),
    ({"overbend_strain_limit": 0.0025, "fabrication": "UOE"}, {},
     "missing required key checks.ovality"),
    ({"overbend_strain_limit": 0.0025, "ovality": 0.01}, {}, "missing key checks.alpha_fab"),
    ({**REQUIRED, "alpha_fab": 0.9}, {}, "checks.alpha_fab = 0.9 is given with checks.fabrication"),
    ({**REQUIRED, "ovality": 0.004}, {}, "checks.ovality = 0.004 is below 0.005"),
    ({**REQUIRED, "fabrication": "spiral"}, {}, "checks.fabrication = 'spiral' must be one of"),
    ({**REQUIRED, "safety_class": "normal"}, {}, "checks.safety_class = 'normal' must be one of"),
    ({**REQUIRED, "alpha_U": 1.1}, {}, "checks.alpha_U = 1.1 must not exceed 1"),
    ({**REQUIRED, "current_load": "steady"}, {},
     "checks.current_load = 'steady' must be one of 'environmental', 'functional'"),
    ({**REQUIRED, "gamma_m": -1.0}, {}, "checks.gamma_m = -1.0 must be positive"),
    ({**REQUIRED, "gamma_F": 1.1}, {}, "missing key checks.gamma_E"),
    ({**REQUIRED, "gamma_E": 1.3}, {}, "missing key checks.gamma_F"),
    ({**REQUIRED, "gamma_F": 1.1, "gamma_E": 0.0}, {}, "checks.gamma_E = 0.0 must be positive"),
    ({**REQUIRED, "ovallity": 0.01}, {},
     "unknown key checks.ovallity (did you mean checks.ovality?)"),
    (REQUIRED, {"smts": None}, "missing key pipe.smts"),
    (REQUIRED, {"smts": 400e6}, "pipe.smts = 400000000.0 is below pipe.smys"),
    (REQUIRED, {"inner_diameter": 0.59}, "D/t = 61, outside 15 to 45"),
    (REQUIRED, {"inner_diameter": 0.52}, "D/t = 13.56, outside 15 to 45"),
])
def test_bad_checks_are_refused_naming_the_key(tables, checks, pipe, message):
    new = _with(tables, checks, **pipe)
    if pipe.get("smts", 1) is None:
        new["pipe"].pop("smts")
    with pytest.raises(ValueError) as err:
        pf.load_case(new)
    assert message in str(err.value)


def test_no_checks_table_needs_no_smts(tables):
    new = _with(tables)
    new["pipe"].pop("smts")
    assert pf.load_case(new).checks is None


def test_case_id_unchanged_without_checks():
    """A case without [checks] keeps the id it had before the table existed."""
    case = pf.load_case(EXAMPLES / "s67.toml").with_changes({"checks": None, "pipe.smts": None})
    assert "checks" not in case.to_dict() and "smts" not in case.to_dict()["pipe"]


def test_collapse_pressure_is_the_cubic_root():
    """p_c against numpy.roots of (p - p_el)(p^2 - p_p^2) - p p_el p_p f0 D/t,
    for the paper's pipe and a thick and a thin one."""
    for di in (0.58, 0.50, 0.594):
        pipe = pf.input.case.Pipe(outer_diameter=0.61, inner_diameter=di, smys=448e6,
                            smts=531e6)
        checks = Checks(**{**REQUIRED, "fabrication": "seamless"})
        d, t = 0.61, (0.61 - di) / 2
        p_el = 2 * 207e9 * (t / d) ** 3 / (1 - 0.3**2)
        p_p = 448e6 * 0.96 * 2 * t / d
        roots = np.roots(np.polymul([1, -p_el], [1, 0, -p_p**2])
                         - np.array([0, 0, p_el * p_p * 0.01 * d / t, 0]))
        real = np.sort(roots[np.abs(roots.imag) < 1e-9 * np.abs(roots).max()].real)
        assert real.size == 3 and real[0] < 0 < real[1] < min(p_el, p_p) < real[2]
        assert collapse_pressure(pipe, checks) == pytest.approx(real[1], rel=1e-12)


def test_flow_stress_factor_branches():
    assert flow_stress_factor(10.0, 400.0, 500.0) == pytest.approx(0.5 + 0.5 * 1.25)
    assert flow_stress_factor(42.0, 400.0, 500.0) == pytest.approx(0.8 + 0.2 * 1.25)
    assert flow_stress_factor(70.0, 400.0, 500.0) == 1.0


def test_lcc_pure_bending_and_pure_pressure():
    """Each term alone (design effects given): M_Sd = M_p alpha_c / g gives
    1; p_e = p_c / g gives 1; S_Sd = 0.4 S_p (either sign) gives
    (g 0.4 / alpha_c)^4."""
    pipe = pf.input.case.Pipe(outer_diameter=0.61, inner_diameter=0.58, smys=448e6, smts=531e6)
    checks = Checks(**REQUIRED)
    d, t = 0.61, 0.015
    fy, fu = 448e6 * 0.96, 531e6 * 0.96
    alpha_c = flow_stress_factor(d / t, fy, fu)
    g = 1.15 * 1.04
    m = fy * (d - t) ** 2 * t * alpha_c / g
    p_c = collapse_pressure(pipe, checks)
    s_p = fy * np.pi * (d - t) * t
    s_sd = [0.0, 0.0, 0.4 * s_p, -0.4 * s_p]
    u = lcc_utilisation(pipe, checks, [m, 0.0, 0.0, 0.0], s_sd, [0.0, p_c / g, 0.0, 0.0],
                        np.zeros(4))
    assert u[:2] == pytest.approx([1.0, 1.0], rel=1e-12)
    assert u[2:] == pytest.approx([(g * 0.4 / alpha_c) ** 4] * 2, rel=1e-12)
    ratio = lcc_axial_ratio(pipe, checks, s_sd)
    assert ratio == pytest.approx([0.0, 0.0, 0.4, 0.4], rel=1e-12)


@pytest.mark.parametrize(("grade", "smys", "smts"), [
    ("X65", 450e6, 535e6),  # f_cb = f_y (535/1.15 = 465 > 450)
    ("X80", 555e6, 625e6),  # f_cb = f_u/1.15 (625/1.15 = 543 < 555)
])
def test_lcc_internal_overpressure_by_hand(grade, smys, smts):
    """Contents pressure above the external one: the internal-overpressure
    form {g |M|/(alpha_c M_p) + (g S/(alpha_c S_p))^2}^2 + (alpha_p (p_i -
    p_e)/(alpha_c p_b))^2, p_b = 2t/(D - t) min(f_y, f_u/1.15) 2/sqrt(3),
    alpha_p = 1 - beta below (p_i - p_e)/p_b = 2/3 and 1 - 3 beta (1 -
    (p_i - p_e)/p_b) above, evaluated here for a section on each side of
    2/3 (bending and tension both present), at 2/3 (the two alpha_p agree)
    and at p_i = p_e (both forms give the bending part)."""
    d, di = 0.61, 0.58
    pipe = pf.input.case.Pipe(outer_diameter=d, inner_diameter=di, grade=grade)
    checks = Checks(**{**REQUIRED, "safety_class": "medium"})
    t = (d - di) / 2
    fy, fu = smys * 0.96, smts * 0.96
    beta = (60 - d / t) / 90  # D/t = 40.7
    alpha_c = (1 - beta) + beta * fu / fy
    m_p, s_p = fy * (d - t) ** 2 * t, fy * np.pi * (d - t) * t
    p_b = 2 * t / (d - t) * min(fy, fu / 1.15) * 2 / np.sqrt(3)
    g = 1.15 * 1.14
    m_sd = np.array([0.3, 0.2, 0.1, 0.25]) * m_p
    s_sd = np.array([0.1, -0.15, 0.05, 0.2]) * s_p
    p_e = np.array([0.5e6, 1.0e6, 0.2e6, 0.7e6])
    dp = np.array([0.3, 0.9, 2 / 3, 0.0]) * p_b  # p_i - p_e
    bend = (g * m_sd / (alpha_c * m_p) + (g * s_sd / (alpha_c * s_p)) ** 2) ** 2
    alpha_p = np.array([1 - beta, 1 - 3 * beta * (1 - 0.9), 1 - beta, 1 - beta])
    expected = bend + (alpha_p * dp / (alpha_c * p_b)) ** 2
    u = lcc_utilisation(pipe, checks, m_sd, s_sd, p_e, p_e + dp)
    assert u == pytest.approx(expected, rel=1e-12)
    assert u[3] == pytest.approx(bend[3], rel=1e-12)
    assert 1 - 3 * beta * (1 - 2 / 3) == pytest.approx(1 - beta, rel=1e-14)
    assert pressure_containment_resistance(pipe, checks) == pytest.approx(p_b, rel=1e-14)
