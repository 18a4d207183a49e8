"""Section properties are per-element data (``Model.section``, layout ``S_*``):
the engine maps the sections along the line onto the elements
(:func:`pipelay_fast.engine.model.section_array`), each element kernel reads
its own row, and a line split into sections with the same properties gives
the same bits as one section."""

import numpy as np
import pytest

import pipelay_fast.engine.problem as problem_module
from pipelay_fast.api.solve import solve
from pipelay_fast.engine.model import section_array, section_row, sections_of
from pipelay_fast.input.case import load_case
from pipelay_fast.kernels import layout as L
from pipelay_fast.kernels.assembly import element_force
from pipelay_fast.kernels.system import system_2d, system_3d
from pipelay_fast.kernels.types import Ends, Model, load_factors
from tests.helpers import EXAMPLES


def test_section_array_maps_each_element_by_its_midpoint_from_the_top():
    s = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0])  # midpoints 4.5 ... 0.5 m from the top
    top, low = np.full(L.N_SECTION, 1.0), np.full(L.N_SECTION, 2.0)
    sec = section_array(s, [(0.0, top), (2.0, low)])
    assert sec.shape == (5, L.N_SECTION) and sec.dtype == np.float64
    assert sec.flags.c_contiguous
    np.testing.assert_array_equal(sec[:, 0], [2.0, 2.0, 2.0, 1.0, 1.0])
    # a joint inside an element: the element takes its midpoint's section
    np.testing.assert_array_equal(section_array(s, [(0.0, top), (2.4, low)])[:, 0],
                                  [2.0, 2.0, 2.0, 1.0, 1.0])
    np.testing.assert_array_equal(section_array(s, [(0.0, top), (2.6, low)])[:, 0],
                                  [2.0, 2.0, 1.0, 1.0, 1.0])
    one = section_array(s, [(0.0, top)])
    np.testing.assert_array_equal(one, np.ones((5, L.N_SECTION)))


def _system(nd, s, u, props, section):
    """The assembled residual (no tangent) of the elements on nodes ``s``."""
    nn = s.size
    g = np.zeros_like(u)
    ends = Ends(np.zeros_like(u), np.zeros_like(u), np.zeros(1), -1, nn - 1, 0.0)
    model = Model(props, np.zeros((1, 2)), load_factors(1.0, False), section)
    system = system_2d if nd == 2 else system_3d
    system(np.diff(s), u, model, np.zeros(nn - 1), np.zeros((2, 2)).T, g, ends, False,
           np.zeros((L.B_PT, nn)), np.full(L.B_PT, -1, dtype=np.int64), np.zeros((L.B_PT, 1)))
    return g


@pytest.mark.parametrize("nd", [2, 3])
def test_each_element_bends_and_weighs_with_its_own_row(nd):
    """A uniformly bent beam, x = k s^2 / 2, z = s (a quadratic: exact in the
    cubic elements), lam = 0, inextensible, in air without contents: element
    e's residual is EI_e k (-1, +1) on its end slopes x'_a, x'_b (the end
    moments) and its weight w_e on dr, w_e le/2 on each end's x and
    +-w_e le^2/12 on x'_a, x'_b. Element 1 has twice element 0's EI and
    another weight, so node 1's rows are the difference of the two."""
    ndn = 2 * nd + 1
    s = np.array([0.0, 1.5, 3.0])
    k = 0.02
    u = np.zeros(s.size * ndn)
    u[0::ndn] = 0.5 * k * s**2  # x
    u[nd - 1::ndn] = s  # z
    u[nd::ndn] = k * s  # x'
    u[2 * nd - 1::ndn] = 1.0  # z'
    props = np.zeros(L.N_PROPS)
    props[L.DEPTH] = props[L.H_CONT] = -1.0  # above the water and the contents
    ei = np.array([2.0e6, 4.0e6])
    w = np.array([300.0, 700.0])
    section = np.zeros((2, L.N_SECTION))
    section[:, L.S_EI] = ei
    section[:, L.S_EA] = 1.0e9
    section[:, L.S_W_DRY] = w
    section[:, L.S_W_BUOY] = section[:, L.S_W_CONT] = 1.0e5  # not acting: x above both levels
    g = _system(nd, s, u, props, section)
    le = 1.5
    expected_x = [w[0] * le / 2, (w[0] + w[1]) * le / 2, w[1] * le / 2]
    expected_slope = [-ei[0] * k + w[0] * le**2 / 12,
                      ei[0] * k - ei[1] * k - w[0] * le**2 / 12 + w[1] * le**2 / 12,
                      ei[1] * k - w[1] * le**2 / 12]
    np.testing.assert_allclose(g[0::ndn], expected_x, rtol=1e-12)
    np.testing.assert_allclose(g[nd::ndn], expected_slope, rtol=1e-10)
    # one section with element 0's row: node 1's slope row balances the bending
    same = _system(nd, s, u, props, np.ascontiguousarray(section[[0, 0]]))
    assert abs(same[ndn + nd]) < 1e-9 * ei[0] * k


@pytest.mark.parametrize("nd", [2, 3])
def test_assembly_gives_element_e_the_row_e(nd):
    """Random rows (stiffnesses, weights, areas, drag) on a bent line
    crossing the contents level and the water surface under a current: the
    assembled residual is the sum of each element's own residual with its
    row (:func:`.assembly.element_force`)."""
    rng = np.random.default_rng(5)
    ndn = 2 * nd + 1
    nel = 6
    s = np.cumsum(np.r_[0.0, rng.uniform(2.0, 4.0, nel)])
    u = np.zeros(s.size * ndn)
    th = np.linspace(0.9, 1.2, s.size)  # steep: crossing 40 m and 45 m
    u[0::ndn] = 35.0 + np.cumsum(np.r_[0.0, np.diff(s) * np.sin(th[:-1])])
    u[nd - 1::ndn] = np.cumsum(np.r_[0.0, np.diff(s) * np.cos(th[:-1])])
    u[nd::ndn] = np.sin(th) * 1.001
    u[2 * nd - 1::ndn] = np.cos(th)
    u[2 * nd::ndn] = rng.uniform(1e5, 2e5, s.size)
    if nd == 3:
        u[1::ndn] = rng.normal(0.0, 0.05, s.size)
        u[nd + 1::ndn] = rng.normal(0.0, 0.01, s.size)
    props = np.zeros(L.N_PROPS)
    props[L.EI_REF] = 1.0e8
    props[L.DEPTH], props[L.H_CONT] = 45.0, 40.0
    props[L.RHOW_G], props[L.RHOI_G] = 1025 * 9.81, 900 * 9.81
    props[L.CUR_SPEED], props[L.CUR_PROFILE] = 1.2, L.PROFILE_UNIFORM
    props[L.CUR_EY], props[L.CUR_EZ] = (0.6, 0.8) if nd == 3 else (0.0, 1.0)
    props[L.EXTENSIBLE] = 1.0
    section = np.empty((nel, L.N_SECTION))
    section[:, L.S_EI] = rng.uniform(5e7, 3e8, nel)
    section[:, L.S_EA] = rng.uniform(3e9, 8e9, nel)
    section[:, L.S_W_DRY] = rng.uniform(5e3, 1e4, nel)
    section[:, L.S_W_CONT] = rng.uniform(1e3, 2e3, nel)
    section[:, L.S_W_BUOY] = rng.uniform(2e3, 4e3, nel)
    section[:, L.S_AREA_I] = rng.uniform(0.2, 0.3, nel)
    section[:, L.S_AREA_E] = section[:, L.S_AREA_I] + rng.uniform(0.01, 0.05, nel)
    section[:, L.S_DRAG] = rng.uniform(200.0, 400.0, nel)
    g = _system(nd, s, u, props, section)
    ref = np.zeros_like(u)
    ne = 2 * ndn
    for e in range(nel):
        fe = np.zeros(ne)
        element_force(nd, s[e + 1] - s[e], u[e * ndn:e * ndn + ne].copy(), props, section[e],
                      np.zeros((1, 2)), 0.0, fe, np.zeros((ne, ne)), False)
        ref[e * ndn:e * ndn + ne] += fe
    np.testing.assert_allclose(g, ref, rtol=1e-12, atol=1e-9 * np.abs(ref).max())
    # and it is not the first row's alone
    g0 = _system(nd, s, u, props, np.ascontiguousarray(np.repeat(section[:1], nel, axis=0)))
    assert np.abs(g - g0).max() > 1e-3 * np.abs(g).max()


def _answer(result):
    """A solve's state and its profile and summary (but the timings)."""
    pb = result.state
    out = {"u": pb.u, "s": pb.s, "tb": pb.tb}
    out.update({f"col/{k}": np.asarray(v) for k, v in result.columns.items()})
    out.update({f"sum/{k}": np.asarray(v) for k, v in result.summary.items()
                if isinstance(v, (int, float, np.number)) and "seconds" not in k})
    return out


def _same_bits(a, b):
    assert a.keys() == b.keys()
    return [k for k in a if not np.array_equal(a[k], b[k], equal_nan=a[k].dtype.kind == "f")]


def _split_at(monkeypatch, joint, scale=1.0):
    """Solve with the case's pipe as two sections (the engine's hook,
    :func:`.model.sections_of`), the lower one from ``joint`` [m] from the
    top, its EI times ``scale`` (1: another array of the same values);
    returns the list of each mesh's (nodes, section array) as it is built."""
    built = []

    def two_sections(case):
        (start, row), = sections_of(case)
        lower = row.copy()
        lower[L.S_EI] *= scale
        return [(start, row), (joint, lower)]

    def mapped(s, sections):
        arr = section_array(s, sections)
        built.append((s.copy(), arr))
        return arr

    monkeypatch.setattr(problem_module, "sections_of", two_sections)
    monkeypatch.setattr(problem_module, "section_array", mapped)
    return built


@pytest.mark.parametrize("name", ["s67", "s67_3d"])
def test_two_sections_with_the_same_properties_give_the_same_bits(name, monkeypatch):
    """S67 in 2D and in 3D under a lateral current, solved with one section
    and with two of the same properties, the joint on the answer's node
    nearest mid-line (an element boundary) and at 0.437 of the line from the
    top (inside an element): the same state, profile and summary, bit for
    bit. With the lower section's EI changed, the same split changes the
    answer (the split reaches the kernels)."""
    case = load_case(EXAMPLES / f"{name}.toml")
    one = _answer(solve(case))
    s = one["s"]
    node = int(np.argmin(np.abs(s - 0.5 * (s[0] + s[-1]))))
    for joint in (float(s[-1] - s[node]), 0.437 * float(s[-1] - s[0])):
        built = _split_at(monkeypatch, joint)
        two = _answer(solve(case))
        assert built, "the engine did not map the sections onto the mesh"
        for nodes, arr in built:  # the joint inside the line: both sections have elements
            depth = nodes[-1] - 0.5 * (nodes[:-1] + nodes[1:])
            assert (depth < joint).any() and (depth >= joint).any()
            assert arr.shape == (nodes.size - 1, L.N_SECTION)
        assert _same_bits(one, two) == []
        monkeypatch.undo()

    _split_at(monkeypatch, 0.437 * float(s[-1] - s[0]), scale=1.5)
    stiffer = _answer(solve(case))
    assert "u" in _same_bits(one, stiffer)


def test_a_case_has_one_section_its_pipe():
    case = load_case(EXAMPLES / "s67.toml")
    (start, row), = sections_of(case)
    assert start == 0.0
    np.testing.assert_array_equal(row, section_row(case))
    assert row[L.S_EI] == case.pipe.bending_stiffness
    assert row[L.S_EA] == case.pipe.axial_stiffness
    assert row[L.S_W_DRY] == case.weight_dry
