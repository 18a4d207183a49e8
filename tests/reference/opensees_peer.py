"""OpenSeesPy peer model of a planar pipelay scene (J-lay, or S-lay on a rigid stinger).

Independent of ``pipelay_fast``'s solver: it takes only the case's data (pipe
section and weights, water depth, top point and tension, stinger end points and
``a``) and builds a different discretisation in OpenSees, so that the two
engines can be compared (``tests/test_peers.py``, ``benchmarks/peers_opensees.py``).
No drag: OpenSees has no deformation-dependent current load, so the scene is
solved without current.

Model
-----
OpenSees' plane (X, Y) is the case's (z, x): X horizontal along the lay, Y the
height above the seabed. Nodes are numbered from the lower (laid) end, 1, to
the top, N; ``s`` is unstretched arc length from the lower end.

* Pipe: ``elasticBeamColumn`` elements with ``geomTransf Corotational``, steel
  E, A = As and I of the case, uniform element length (``element_length``, the
  line divided into equal elements). The corotational element measures its
  moments from the initial geometry, so the initial (stress-free) geometry is a
  straight line (see the load path below).
* Weight: the effective weight w(x) [N/m] of the case (submerged below the
  water surface, dry above it) integrated over each element along its current
  chord (x linear between the nodes, the surface crossing located exactly) and
  lumped half to each end node as global vertical loads (not ``beamUniform``,
  which follows the corotated element). Because w depends on where a node ends
  up, the loads are a fixed point: after the solve they are recomputed from the
  deformed geometry and the difference applied, until it is below
  ``LOAD_RTOL`` of the heaviest nodal load.
* Seabed: every node but the top (and a lower end that starts on the seabed,
  held there) has a ``zeroLength`` element to a fixed
  anchor node at the same place, with an ``ElasticPPGap`` material in compression
  (gap = the node's initial height, yield force out of reach): a compression-only
  vertical spring of stiffness ``bed_stiffness`` [N/m per m of pipe] x the node's
  tributary length. Frictionless. The lower end slides freely along z.
* Stinger (S-lay): frictionless compression-only supports normal to the stinger.
  The node at unstretched arc length ``s_top`` below the top ends up near the
  stinger point at arc length ``s_top`` from the stinger's upper end (the pipe
  conforms to the stinger from the top down, the stretch moves it by
  centimetres). Each such node gets a ``zeroLength`` spring along the stinger
  normal at that target point (``-orient``), with an ``ElasticPPGap`` gap equal to
  the node's initial distance from the target's tangent line: the node is kept
  on the upper side of that tangent line and slides freely along it. The
  tangent line departs from the curve by kappa d^2 / 2 at a distance d from
  the target: 2e-7 m for the 1.3 cm slides found (reported:
  ``stinger_slide_max``; ``stinger_curve_gap_min/max``, the contact nodes'
  height above the true curve; ``stinger_free_clearance_min``, the free nodes'
  clearance over the stinger's z range).
* Ends: the top node is pinned at ``lay.top`` (J-lay without ``top_angle``) or
  clamped at the firing angle, the stinger's slope at its upper end (S-lay,
  pipelay_fast's default ``top_angle``). The lower end carries the bottom
  tension H as a horizontal force -H e_z.
* Tension: the top tension is given; H is corrected until the computed top
  tension meets it to ``TENSION_RTOL``. With frictionless supports the
  tangential equilibrium gives Te(top) = H + sum_k P_k sin(theta_k) (P_k the
  nodal weights) up to the pipe's stretch (1e-4): the start is the continuum
  form H = Te_top - int_0^x_top w dx (minus EI kappa_stinger^2 / 2 for the
  clamped S-lay top), which a pinned J-lay top meets exactly for an
  inextensible pipe (``tests/reference/elastica.py``); each correction adds the
  remaining miss, less the effect of that correction's weight change.
* Contact stiffness: both penalties are ``PATH_STIFFNESS`` along the load path
  (soft contacts keep Newton's active set from cycling while the pipe lands)
  and are raised a decade at a time to their final values at the end, each
  followed by an equilibrium iteration (``setParameter`` on the gap material).
  The penetration left is reported (``bed_penetration_max``,
  ``stinger_curve_gap_min``); at the clamped S-lay top it bends the last
  element by about 3 EI (q / k) / h^2 (q the stinger's reaction per length):
  4e-4 of the overbend moment at h = 0.5 m with k = 1e11 N/m/m.

Load path (pseudo-time t, load control, sub-stepping)
-----------------------------------------------------
The initial straight line starts at the top point and runs down at the angle
``alpha`` towards the laid end: for S-lay along the firing line (the stinger's
tangent at its upper end, so the concave stinger lies wholly below it and the
top can be clamped at once), ending in mid-water; for J-lay straight to the
seabed. Its length is the natural catenary's suspended length (from the
stinger tip, S-lay) plus the stinger's arc length plus ``laid_flex`` flexural
lengths sqrt(EI/H) of laid pipe.

1. t in [0, 1]: the bottom tension H ramps up with the lower end held at its
   height: the line is pretensioned.
2. t in [1, 2]: the weight ramps up. S-lay: the held lower end first pulls
   down on the line (its tension's vertical part), then, with weight, pushes up;
   where that reaction vanishes (interpolated from two points) it is released
   and hangs as the free end of a catenary, falling onto the seabed as the
   weight grows. The pipe sags onto the stinger and the seabed. (Lowering the
   end by an imposed displacement instead made Newton cycle at 0.5 m
   elements.) Then the contact stiffening above.
3. t in [k, k + 1], k >= 2: corrections, each a ramp of the change of the
   nodal weights (the fixed point above) and of H.

Each stage is stepped with ``LoadControl``; a step that fails (Newton, then
Newton with line search, on ``NormDispIncr``) is halved, down to ``MIN_STEP``;
steps grow again after easy ones. A case that cannot be followed raises
``RuntimeError`` naming the stage and pseudo-time.

Outputs (per node, then summary)
--------------------------------
From the element end forces (``eleResponse 'force'``, global, what the nodes
exert on the element): the effective tension at a node is the end force
projected on the node's tangent (the line's angle plus the node's rotation),
the internal moment m = M_j at an element's upper end and -M_i at its lower end
(sagging positive, EI theta'); nodal values are the mean of the two elements
meeting there (the top and the lower end: their one element). Von Mises stress
as pipelay_fast defines it (``pipelay_fast.output.results.build_profile``): wall
tension Tw = Te + pi Ai - pe Ae, sigma_a = Tw/As +- |m| Do/(2I), hoop
(pi Di - pe Do)/(2t), the larger fibre. Touchdown: the last node in seabed
contact k; the moment of the free span, which grows linearly from zero at
touchdown, is extrapolated to zero from nodes k+1 and k+2 (clipped to
[s_k - h, s_k+1]). Lift-off (S-lay): the lowest
node in stinger contact.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

LOAD_RTOL = 1e-6  # -, weight fixed point: largest nodal load change / largest nodal load
TENSION_RTOL = 1e-7  # -, |Te_top - target| / target
MAX_CORRECTIONS = 8  # correction stages (weight fixed point and bottom tension)
BED_STIFFNESS = 1e11  # N/m per m of pipe, seabed penalty
STINGER_STIFFNESS = 1e11  # N/m per m of pipe, stinger penalty
PATH_STIFFNESS = 1e5  # N/m per m of pipe, both penalties along the load path
STIFFEN_DECADES = 1.0  # decades of penalty stiffness per stiffening step
LAID_FLEX = 4.0  # -, laid pipe in flexural lengths sqrt(EI/H), catenary estimate
PROBE = 0.02  # pseudo-time of weight to sample the held lower end's reaction (S-lay)
FIRST_STEP = 0.1  # pseudo-time, first load step of a stage
MIN_STEP = 1e-4  # pseudo-time, smallest load step before giving up
MAX_STEP = 0.25  # pseudo-time, largest load step
TEST_TOL = 1e-8  # m (and rad), NormDispIncr tolerance
TEST_ITER = 25  # Newton iterations per step
ALGORITHM = ("Newton",)
FALLBACK = ("NewtonLineSearch", "-type", "Bisection")  # tried once when a step fails
_DEBUG = False  # print every step and write OpenSees' log to /tmp/opensees_peer.log
_FAR = 1e6  # pseudo-time at which the Path series end (value kept)
_BED, _ST = 100_000, 200_000  # tag offsets: seabed and stinger anchors/springs


@dataclass
class PeerResult:
    """Profile (per node) and summary of an OpenSees solve; SI units."""

    profile: dict
    summary: dict
    stats: dict = field(default_factory=dict)


class Unavailable(ImportError):
    """openseespy is not installed or cannot load; the message says how to mend it."""


# the shared libraries openseespy's extension links against, and their Debian packages
SYSTEM_LIBRARIES = {"libblas.so.3": "libblas3", "liblapack.so.3": "liblapack3"}


def opensees():
    """The ``openseespy.opensees`` module, or :class:`Unavailable` naming what is missing.

    openseespy 3.7 on Linux wraps its extension's ImportError (a system library
    not found) in ``RuntimeError("Failed to import openseespy on Linux.")``; the
    loader's own message is found in that exception's chain.
    """
    try:
        import openseespy.opensees as ops
    except (ImportError, RuntimeError) as err:
        if isinstance(err, ModuleNotFoundError) and (err.name or "").startswith("openseespy"):
            raise Unavailable("openseespy is not installed: pip install '.[test]' "
                              "(or '.[peers]')") from err
        root = err
        while root.__cause__ or root.__context__:
            root = root.__cause__ or root.__context__
        hint = ""
        if any(library in str(root) for library in SYSTEM_LIBRARIES):
            hint = (f"; it needs the system BLAS and LAPACK ({', '.join(SYSTEM_LIBRARIES)}), "
                    f"on Debian/Ubuntu: apt-get install {' '.join(SYSTEM_LIBRARIES.values())}")
        raise Unavailable(f"openseespy cannot load: {root}{hint}") from err
    return ops


# --------------------------------------------------------------------------- geometry


class _Stinger:
    """x = a z^2 + b z + c with arc length from the upper end, sigma(z) [m]."""

    def __init__(self, st):
        self.a, self.b, self.c = st.a, st.b, st.c
        (self.x_l, self.z_l), (self.x_u, self.z_u) = st.lower, st.upper
        z = np.linspace(self.z_l, self.z_u, 20001)
        ds = np.sqrt(1.0 + self.slope(z) ** 2)
        cum = np.concatenate(([0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(z))))
        self._z, self._sigma = z, cum[-1] - cum  # sigma decreasing with z
        self.length = float(cum[-1])

    def height(self, z):
        return (self.a * z + self.b) * z + self.c

    def slope(self, z):
        return 2.0 * self.a * z + self.b

    def curvature(self, z):
        return 2.0 * self.a / (1.0 + self.slope(z) ** 2) ** 1.5

    def z_at_arc(self, sigma):
        """z [m] of the point at arc length sigma [m] from the upper end."""
        return np.interp(sigma, self._sigma[::-1], self._z[::-1])


def _catenary_suspended(h, w, height):
    """Arc length [m] of a natural catenary from its vertex to a point ``height`` above."""
    a = h / w
    return math.sqrt((a + height) ** 2 - a * a)


def _weights_of_chords(case, x, lengths):
    """Nodal loads [N] of w(x) integrated along straight chords, half to each end.

    ``x`` heights of the nodes [m], ``lengths`` unstretched element lengths [m].
    """
    depth = case.environment.water_depth
    w_sub = float(case.effective_weight(0.0))
    w_dry = float(case.effective_weight(depth + 1.0))
    x0, x1 = x[:-1], x[1:]
    lo, hi = np.minimum(x0, x1), np.maximum(x0, x1)
    span = hi - lo
    with np.errstate(invalid="ignore", divide="ignore"):
        frac_dry = np.where(span > 0.0, np.clip((hi - depth) / span, 0.0, 1.0),
                            (lo >= depth).astype(float))
    if case.pipe.contents_density != 0.0:
        raise NotImplementedError("peer model: contents (a second weight level) not modelled")
    per_el = lengths * (w_sub + (w_dry - w_sub) * frac_dry)
    loads = np.zeros(x.size)
    loads[:-1] += 0.5 * per_el
    loads[1:] += 0.5 * per_el
    return loads


# --------------------------------------------------------------------------- the solve


def solve(case, element_length: float, *, laid_flex: float = LAID_FLEX,
          bed_stiffness: float = BED_STIFFNESS, stinger_stiffness: float = STINGER_STIFFNESS,
          path_stiffness: float = PATH_STIFFNESS, curve=None,
          log=None) -> PeerResult:
    """Solve the planar scene of ``case`` (no current) in OpenSees.

    Parameters
    ----------
    case : pipelay_fast.Case
        J-lay (pinned top) or S-lay (firing-line top) with ``lay.top_tension``.
    element_length : float
        Target element length [m]; the line is cut into equal elements.
    laid_flex : float
        Laid pipe to model, in flexural lengths sqrt(EI/H) [-] beyond the
        natural catenary's touchdown.
    bed_stiffness, stinger_stiffness : float
        Penalty stiffnesses [N/m per m of pipe].
    curve : pipelay_fast.input.case.Stinger or None
        A roller stinger's rollers lie on this quadratic curve (from
        ``lay.top``, held along its tangent there, to the last roller): the
        rollers are compression-only supports at the nodes the curve's arc
        length from the top puts over them, each on the curve's tangent line
        there, the line cut into elements of exactly ``element_length`` (a
        divisor of the rollers' spacing along the curve puts a node on each).
    log : str or None
        OpenSees log file; None sends OpenSees' messages to /dev/null.
    """
    ops = opensees()
    t_start = time.perf_counter()
    lay, pipe = case.lay, case.pipe
    if lay.top_tension is None:
        raise ValueError("peer model: needs lay.top_tension")
    if case.environment.current.speed != 0.0:
        raise ValueError("peer model: no current (switch environment.current.speed to 0)")
    slay = lay.method == "S"
    if not slay and lay.top_angle not in (None, "pinned"):
        raise ValueError("peer model: J-lay with a pinned top only")
    rollers = lay.roller_positions()
    if rollers is not None:
        if curve is None:
            raise ValueError("peer model: a roller stinger needs the curve its rollers lie on")
        if abs(lay.top_angle - float(curve.angle(curve.upper[1]))) > 1e-6:
            raise ValueError("peer model: rollers with the top held along the curve's tangent")
    elif slay and lay.top_angle is not None:
        raise ValueError("peer model: S-lay with the firing-line top only")
    ei = pipe.bending_stiffness
    x_top, z_top = lay.top
    depth = case.environment.water_depth
    w_sub = float(case.effective_weight(0.0))
    w_dry = float(case.effective_weight(depth + 1.0))
    lift = w_sub * min(x_top, depth) + w_dry * max(x_top - depth, 0.0)  # int_0^x_top w dx
    st = _Stinger(curve if rollers is not None else lay.stinger) if slay else None

    # bottom tension: exact statics (pinned top) / its clamped-top value as the start
    h_bottom = lay.top_tension - lift
    if slay:
        h_bottom -= 0.5 * ei * st.curvature(st.z_u) ** 2
    flex = math.sqrt(ei / h_bottom)

    # initial straight line, from the top down at angle alpha towards -z
    if slay:
        alpha = math.atan(st.slope(st.z_u))  # the firing line
        hang = _catenary_suspended(h_bottom, w_sub, st.x_l)
        length = st.length + hang + laid_flex * flex
        if length * math.sin(alpha) >= x_top:
            raise ValueError("peer model: the firing line reaches the seabed; not handled")
    else:
        hang = _catenary_suspended(h_bottom, w_sub, x_top)
        length = hang + laid_flex * flex
        alpha = math.asin(x_top / length)
    n_el = max(2, math.ceil(length / element_length - 1e-9))
    if rollers is not None:  # nodes a whole number of elements from the top
        length = n_el * element_length
    s = np.linspace(0.0, length, n_el + 1)  # from the lower end
    nn = s.size
    c_al, s_al = math.cos(alpha), math.sin(alpha)
    X0 = z_top - (length - s) * c_al  # z
    Y0 = x_top - (length - s) * s_al  # x
    Y0[0] = max(Y0[0], 0.0)
    h = np.diff(s)
    trib = np.zeros(nn)
    trib[:-1] += 0.5 * h
    trib[1:] += 0.5 * h

    ops.wipe()
    ops.logFile(log or ("/tmp/opensees_peer.log" if _DEBUG else "/dev/null"), "-noEcho")
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    for k in range(nn):
        ops.node(k + 1, float(X0[k]), float(Y0[k]))
    top = nn
    ops.fix(top, 1, 1, 0 if not slay else 1)
    ops.fix(1, 0, 1, 0)  # lower end held at its height (S-lay: released on the way)
    ops.geomTransf("Corotational", 1)
    for e in range(n_el):
        ops.element("elasticBeamColumn", e + 1, e + 1, e + 2, pipe.steel_area,
                    pipe.youngs_modulus, pipe.second_moment, 1)

    # seabed springs (compression only, gap = initial height)
    mat = 0
    # every node but the top; the lower end of a J-lay line starts on the seabed, held
    bed_nodes = list(range(1 if Y0[0] == 0.0 else 0, nn - 1))
    for k in bed_nodes:
        mat += 1
        ops.node(_BED + k + 1, float(X0[k]), float(Y0[k]))
        ops.fix(_BED + k + 1, 1, 1, 1)
        ops.uniaxialMaterial("ElasticPPGap", mat, path_stiffness * trib[k], -1e30,
                             -float(Y0[k]))
        ops.element("zeroLength", _BED + k + 1, _BED + k + 1, k + 1, "-mat", mat,
                    "-dir", 1, "-orient", 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)

    # stinger springs: node at arc s_top below the top -> stinger point at the same arc
    st_nodes, st_target = [], []
    if rollers is not None:  # the node the curve's arc puts over each roller
        sigma = np.interp(rollers[:, 1], st._z, st._sigma)
        over = [int(np.argmin(np.abs(length - s - sg))) for sg in sigma]
    if slay:
        for k in range(nn - 1):
            s_from_top = length - s[k]
            if s_from_top > st.length:
                continue
            if rollers is not None and k not in over:
                continue
            zt = float(st.z_at_arc(s_from_top))
            xt = float(st.height(zt))
            if rollers is not None:
                xt, zt = (float(v) for v in rollers[over.index(k)])
            u = float(st.slope(zt))
            nz, nx = -u / math.hypot(1.0, u), 1.0 / math.hypot(1.0, u)  # normal, up
            gap0 = (X0[k] - zt) * nz + (Y0[k] - xt) * nx
            if gap0 < -1e-9:
                raise ValueError(f"peer model: node {k + 1} starts below the stinger "
                                 f"({gap0:.3g} m)")
            mat += 1
            ops.node(_ST + k + 1, float(X0[k]), float(Y0[k]))
            ops.fix(_ST + k + 1, 1, 1, 1)
            ops.uniaxialMaterial("ElasticPPGap", mat, path_stiffness * trib[k], -1e30,
                                 -max(gap0, 0.0))
            ops.element("zeroLength", _ST + k + 1, _ST + k + 1, k + 1, "-mat", mat,
                        "-dir", 1, "-orient", nz, nx, 0.0, -nx, nz, 0.0)
            st_nodes.append(k)
            st_target.append((zt, xt, nz, nx))

    # first weights: the stinger's height on the stinger, a straight top segment
    # at the catenary's top angle (J-lay) elsewhere
    if slay:
        x_est = np.full(nn, -1.0)
        for k, (_zt, xt, _nz, _nx) in zip(st_nodes, st_target, strict=True):
            x_est[k] = xt
        x_est[-1] = x_top
    else:
        v_top = math.sqrt(lay.top_tension**2 - h_bottom**2)
        theta = math.atan2(v_top, h_bottom)
        x_est = np.maximum(x_top - (length - s) * math.sin(theta), 0.0)
    loads = _weights_of_chords(case, x_est, h)

    def ramp(tag, t0, t1):
        ops.timeSeries("Path", tag, "-time", 0.0, t0, t1, _FAR, "-values", 0.0, 0.0, 1.0, 1.0)

    ramp(1, 0.0, 1.0)
    ops.pattern("Plain", 1, 1)
    ops.load(1, -h_bottom, 0.0, 0.0)
    ramp(2, 1.0, 2.0)
    ops.pattern("Plain", 2, 2)
    for k in range(nn):
        ops.load(k + 1, 0.0, -float(loads[k]), 0.0)

    ops.constraints("Transformation")
    ops.numberer("RCM")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", TEST_TOL, TEST_ITER, 1 if _DEBUG else 0)
    ops.algorithm(*ALGORITHM)
    ops.integrator("LoadControl", FIRST_STEP)
    ops.analysis("Static")

    stats = {"steps": 0, "cuts": 0, "iterations": 0, "corrections": 0}

    def advance(t_end, stage, first=FIRST_STEP):
        dt = first
        while ops.getTime() < t_end - 1e-12:
            step = min(dt, t_end - ops.getTime())
            ops.integrator("LoadControl", step)
            ok = ops.analyze(1)
            if ok != 0:
                ops.algorithm(*FALLBACK)
                ok = ops.analyze(1)
                ops.algorithm(*ALGORITHM)
            stats["iterations"] += ops.testIter()
            if _DEBUG:
                print(f"{stage} t={ops.getTime():.4f} step={step:.4g} ok={ok} it={ops.testIter()}")
            if ok == 0:
                stats["steps"] += 1
                if ops.testIter() <= 6:
                    dt = max(dt, min(MAX_STEP, 2.0 * step))
                continue
            stats["cuts"] += 1
            dt = 0.5 * step
            if dt < MIN_STEP:
                raise RuntimeError(f"OpenSees peer: {case.name!r} stage {stage!r} stalls at "
                                   f"pseudo-time {ops.getTime():.5f} (step {step:.2g})")

    def lower_reaction():
        ops.reactions()
        return ops.nodeReaction(1, 2)

    def stiffen():
        """Contact springs from path_stiffness to their final stiffness, by decades."""
        springs = ([(_BED + k + 1, bed_stiffness, trib[k]) for k in bed_nodes]
                   + [(_ST + k + 1, stinger_stiffness, trib[k]) for k in st_nodes])
        ratio = max(bed_stiffness, stinger_stiffness) / path_stiffness
        n_up = max(0, math.ceil(math.log10(ratio) / STIFFEN_DECADES - 1e-9))
        for i in range(1, n_up + 1):
            level = path_stiffness * 10.0 ** (STIFFEN_DECADES * i)
            for tag, k_final, length_k in springs:
                ops.setParameter("-val", min(k_final, level) * length_k, "-ele", tag,
                                 "material", "1", "E")
            ops.integrator("LoadControl", 0.0)
            ok = ops.analyze(1)
            stats["iterations"] += ops.testIter()
            if _DEBUG:
                print(f"stiffen {i}/{n_up} ok={ok} it={ops.testIter()}")
            if ok != 0:
                raise RuntimeError(f"OpenSees peer: {case.name!r}: contact stiffening "
                                   f"fails at step {i} of {n_up}")

    advance(1.0, "pretension")
    if Y0[0] > 0.0:
        # S-lay: the held lower end pulls down on the line (its tension's
        # vertical part); with weight it pushes up. Where that reaction
        # vanishes (linear in the weight, from two points) the end is
        # released: it then hangs as the free end of a catenary and falls onto
        # the seabed as the weight grows.
        r0 = lower_reaction()
        advance(1.0 + PROBE, "weight")
        r1 = lower_reaction()
        t_free = 1.0 + PROBE * r0 / (r0 - r1)
        if not 1.0 + PROBE < t_free < 2.0:
            raise RuntimeError(f"OpenSees peer: {case.name!r}: the lower end does not lift "
                               f"under the weight (reactions {r0:.4g}, {r1:.4g} N)")
        advance(t_free, "weight, lower end held")
        ops.remove("sp", 1, 2)
    advance(2.0, "weight")
    stiffen()

    def state():
        disp = np.array([ops.nodeDisp(k + 1) for k in range(nn)])
        return X0 + disp[:, 0], Y0 + disp[:, 1], alpha + disp[:, 2]

    def top_tension():
        # the support's force on the pipe (the element's end force and the top
        # node's own share of the weight) along the tangent
        f = ops.eleResponse(n_el, "force")
        ang = alpha + ops.nodeDisp(top, 3)
        return f[3] * math.cos(ang) + (f[4] + loads[-1]) * math.sin(ang)

    # corrections: weights from the deformed chords, H to meet the top tension
    t_now = 2.0
    for _ in range(MAX_CORRECTIONS):
        _z, x, th = state()
        new = _weights_of_chords(case, x, h)
        d_load = new - loads
        te_top = top_tension()
        # frictionless supports: Te_top = H + sum_k P_k sin(theta_k), up to the
        # stretch (1e-4); so the weight change moves Te_top by sum dP_k sin(theta_k)
        miss = lay.top_tension - te_top
        d_h = 0.0
        if abs(miss) > TENSION_RTOL * lay.top_tension:
            d_h = miss - float(d_load @ np.sin(th))
        if _DEBUG:
            print(f"correction: max load change {np.abs(d_load).max():.3g} N, "
                  f"top tension miss {miss:.3g} N")
        if np.abs(d_load).max() <= LOAD_RTOL * loads.max() and d_h == 0.0:
            break
        stats["corrections"] += 1
        tag = 10 + stats["corrections"]
        ramp(tag, t_now, t_now + 1.0)
        ops.pattern("Plain", tag, tag)
        ops.load(1, -d_h, 0.0, 0.0)
        for k in np.flatnonzero(d_load):
            ops.load(int(k) + 1, 0.0, -float(d_load[k]), 0.0)
        loads, h_bottom = new, h_bottom + d_h
        t_now += 1.0
        advance(t_now, f"correction {stats['corrections']}", first=1.0)
    else:
        raise RuntimeError(f"OpenSees peer: {case.name!r}: weights/tension not converged "
                           f"after {MAX_CORRECTIONS} corrections")

    # ------------------------------------------------------------------ results
    z, x, theta = state()
    forces = np.array([ops.eleResponse(e + 1, "force") for e in range(n_el)])
    c, sn = np.cos(theta), np.sin(theta)
    te_lo = -(forces[:, 0] * c[:-1] + forces[:, 1] * sn[:-1])  # at element i ends
    te_hi = forces[:, 3] * c[1:] + forces[:, 4] * sn[1:]  # at element j ends
    m_lo, m_hi = -forces[:, 2], forces[:, 5]
    te = np.zeros(nn)
    mom = np.zeros(nn)
    te[:-1] += te_lo
    te[1:] += te_hi
    mom[:-1] += m_lo
    mom[1:] += m_hi
    te[1:-1] *= 0.5
    mom[1:-1] *= 0.5
    te[-1] = top_tension()
    bed_force = np.zeros(nn)
    for k in bed_nodes:
        bed_force[k] = -ops.eleResponse(_BED + k + 1, "force")[4]  # on the pipe
    st_force = np.zeros(nn)
    for k in st_nodes:
        f = ops.eleResponse(_ST + k + 1, "force")
        st_force[k] = math.hypot(f[3], f[4])
    on_bed = bed_force > 0.0
    on_bed[0] = True
    on_st = st_force > 0.0
    ops.wipe()

    vm = von_mises(case, te, mom, x)
    k_tdp = int(np.flatnonzero(on_bed).max())
    s_tdp = _touchdown(s, mom, k_tdp)
    z_tdp = float(np.interp(s_tdp, s, z))
    free = np.arange(nn) > k_tdp
    sag = free & (mom > 0.0)
    hog = free & (mom < 0.0)
    if slay:
        lift_nodes = np.flatnonzero(on_st)
        k_lift = int(lift_nodes.min()) if lift_nodes.size else nn - 1
        sag &= np.arange(nn) <= k_lift
        over_m = float(-mom[hog].min()) if hog.any() else math.nan
        over_vm = float(vm[hog].max()) if hog.any() else math.nan
        liftoff_z = float(z[k_lift])
    else:
        over_m = over_vm = liftoff_z = math.nan
    pen_bed = max(0.0, float(-x[on_bed].min())) if on_bed.any() else 0.0
    stats.update(_stinger_checks(st, st_nodes, st_target, on_st, z, x) if slay else {})
    if rollers is not None:
        stats["roller_reactions"] = st_force[over]
    stats.update({
        "bed_penetration_max": pen_bed,
        "seabed_reaction_sum": float(bed_force.sum()),
        "weight_sum": float(loads.sum()),
        "lower_end_height": float(x[0]),
        "laid_length": float(s_tdp),
        "seconds": time.perf_counter() - t_start,
    })
    summary = {
        "top_tension": float(te[-1]),
        "bottom_tension": float(h_bottom),
        "tdp_z": z_tdp,
        "liftoff_z": liftoff_z,
        "top_angle_deg": float(np.degrees(theta[-1])),
        "max_von_mises": float(vm.max()),
        "sagbend_max_von_mises": float(vm[sag].max()),
        "overbend_max_von_mises": over_vm,
        "sagbend_max_moment": float(mom[sag].max()),
        "overbend_max_moment": over_m,
        "n_elements": n_el,
        "solve_seconds": stats["seconds"],
    }
    profile = {"s": s, "x": x, "z": z, "angle_deg": np.degrees(theta), "effective_tension": te,
               "moment": mom, "von_mises": vm, "seabed_reaction": bed_force,
               "stinger_reaction": st_force}
    return PeerResult(profile, summary, stats)


def von_mises(case, te, moment, x):
    """Largest fibre von Mises stress [Pa], as ``pipelay_fast.output.results.build_profile``
    without torque.

    ``te`` effective tension [N], ``moment`` bending moment [N m], ``x`` height [m].
    """
    pipe = case.pipe
    tw = np.asarray(case.wall_tension(te, x), dtype=float)
    pe = np.asarray(case.external_pressure(x), dtype=float)
    pi_ = np.asarray(case.internal_pressure(x), dtype=float)
    hoop = (pi_ * pipe.inner_diameter - pe * pipe.outer_diameter) / (2.0 * pipe.wall_thickness)
    bend = np.abs(moment) * pipe.outer_diameter / (2.0 * pipe.second_moment)
    axial = tw / pipe.steel_area
    return np.maximum.reduce([np.sqrt(sa * sa + hoop * hoop - sa * hoop)
                              for sa in (axial + bend, axial - bend)])


def _touchdown(s, moment, k):
    """Arc length [m] where the free span's moment, linear from nodes k+1, k+2, is zero."""
    if k + 2 >= s.size:
        return float(s[k])
    (s1, s2), (m1, m2) = s[k + 1:k + 3], moment[k + 1:k + 3]
    if m2 == m1:
        return float(s[k])
    root = s1 - m1 * (s2 - s1) / (m2 - m1)
    return float(np.clip(root, s[k] - (s[k + 1] - s[k]), s[k + 1]))


def _stinger_checks(st, nodes, targets, on_st, z, x) -> dict:
    """Slide of contact nodes along their tangent lines [m], their height above
    the true stinger curve [m] (penetration if negative), and the clearance of
    the free nodes over the stinger's z range [m]."""
    slide, curve_gap = [], []
    for k, (zt, xt, nz, nx) in zip(nodes, targets, strict=True):
        if on_st[k]:
            slide.append(abs((z[k] - zt) * nx - (x[k] - xt) * nz))
            curve_gap.append(x[k] - st.height(z[k]))
    over = (z >= st.z_l) & (z <= st.z_u) & ~on_st
    over[-1] = False
    clearance = x[over] - st.height(z[over])
    return {
        "stinger_contacts": int(on_st.sum()),
        "stinger_slide_max": max(slide, default=0.0),
        "stinger_curve_gap_min": min(curve_gap, default=0.0),
        "stinger_curve_gap_max": max(curve_gap, default=0.0),
        "stinger_free_clearance_min": float(clearance.min()) if clearance.size else math.nan,
    }
