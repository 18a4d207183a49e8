"""Random realistic lay cases and their independent checks, for bench_random.py.

Generator (``case_changes``): each case is drawn from its own generator
``numpy.random.default_rng([seed, dim, index])`` (dim 2 or 3), so a case
depends only on (seed, dim, index), not on how many cases are drawn, and is
the same on any machine (PCG64 is stable across numpy versions). The changes
are applied to a bundled example (``j125_2d``, ``j125_3d``, ``s67``, ``s67_3d``)
with its ``[checks]`` table removed (one solve per case; no D/t window).

- Pipe: steel OD U(0.15, 1.2) m, D/t U(12, 45), E 207 GPa; with probability
  0.3 no coating, else U(5, 120) mm of coating at U(1900, 3400) kg/m3; the draw
  is repeated until the empty pipe's specific gravity is at least SG_MIN (a pipe
  that floats is not laid). Near-rigid variant (probability P_RIGID, J-lay
  only): E = 1e15 Pa (issue 42's class 5).
- J-lay (probability 0.5): depth log-U(50, 2500) m, hang-off U(3, 15) m above
  the surface. The natural catenary sets the tension: its sagbend strain
  Do w / (2 H) is drawn log-U(SAG_STRAIN), H = Do w / (2 strain), the top angle
  following from cos(theta) = H / (H + W), W the suspended weight; H is raised
  or lowered to keep theta in TOP_ANGLE_J. Top pinned (0.5) or on the firing
  line at theta + U(-2, 2) deg (at most 90).
- S-lay: depth log-U(20, 300) m, stinger upper end U(5, 15) m above the surface,
  tip angle U(5, 60) deg, upper slope angle U(0, min(5, tip / 3)) deg; the
  quadratic's curvature at its upper end is the turn over a length
  U(STINGER_LENGTH), at most 2 OVERBEND_STRAIN / Do; the stinger at most
  STINGER_SPAN long horizontally and its tip at least 0.2 depth above the
  seabed, the tip angle lowered when either binds (so shallow water has
  shallow tips). Straight variant (P_STRAIGHT): a = 0 at the tip angle, as
  long as drawn (class 4). Tension from the catenary leaving the tip's height at
  the sagbend strain drawn log-U(SAG_STRAIN), H kept within the departure
  angles DEPARTURE x the tip angle (at most 80 deg) of the catenary leaving the tip's height.
  Top on the firing line (0.5) or pinned.
- J-lay and S-lay: H then lowered to keep the top tension H + W within
  TENSION_STRAIN x EA and H within H_MAX (the angles' bounds give way; H at
  least a quarter of the sagbend strain's).
- Either: the top tension H + W (0.5) or the bottom tension H.
- 2D: no current (the planar references have no drag). 3D: surface current
  U(0.2, 2.5) m/s at heading U(0, 360) deg, power law exponent U(0.1, 0.3),
  lateral friction U(0.2, 1.0); with probability P_PLANAR the case has no
  lateral load (current 0, or along the lay at heading 0 or 180) and is solved
  in 3D all the same, for the 3D = 2D check.

The checks (``reference``, ``compare``, ``ref_strain``): the planar inextensible
elastica of ``tests/reference`` (J-lay ``jlay_elastica``, S-lay
``slay_elastica``; a pinned S-lay top as the engine's pin: the tension just
below it is the top tension less (EI kappa_U)^2 / (2 EI)), with weights and EI
recomputed here from the pipe data.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import pipelay_fast as pf

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))  # the repository root, for tests.reference
from tests.reference.elastica import jlay_elastica  # noqa: E402
from tests.reference.slay import slay_elastica  # noqa: E402

EXAMPLES = Path(pf.__file__).parent / "examples"
BASES = {("J", 2): "j125_2d", ("J", 3): "j125_3d", ("S", 2): "s67", ("S", 3): "s67_3d"}
SG_MIN = 1.1  # -, smallest specific gravity of the empty pipe
P_RIGID, P_STRAIGHT, P_PLANAR = 0.03, 0.05, 0.1
SAG_STRAIN = (3e-4, 6e-3)  # -, the natural catenary's sagbend strain Do w / (2 H)
TOP_ANGLE_J = (45.0, 89.5)  # deg, J-lay top angle of the natural catenary
OVERBEND_STRAIN = 5e-3  # -, largest Do/2 |kappa| at the stinger's upper end
STINGER_LENGTH = (40.0, 150.0)  # m, the stinger's length (its turn over it sets kappa)
DEPARTURE = (0.5, 1.5)  # -, S-lay departure angle of the catenary over the tip angle
TENSION_STRAIN = 2.5e-3  # -, largest top tension over EA (unless the angles need more)
H_MAX = 8e6  # N, largest horizontal tension (unless the sagbend strain needs more)
STINGER_SPAN = 250.0  # m, longest horizontal stinger span
STINGER_UPPER_Z = 400.0  # m


def weights(case: pf.Case) -> tuple[float, float, float, float]:
    """(w_sub, w_dry, EI, EA) [N/m, N/m, N m2, N] from the pipe data (empty pipe)."""
    p, env = case.pipe, case.environment
    g = env.gravity
    steel = math.pi / 4 * (p.outer_diameter**2 - p.inner_diameter**2)
    coat = math.pi / 4 * (p.coating_outer_diameter**2 - p.outer_diameter**2)
    w_dry = g * (p.steel_density * steel + p.coating_density * coat)
    w_sub = w_dry - env.water_density * g * math.pi / 4 * p.coating_outer_diameter**2
    ei = p.youngs_modulus * math.pi / 64 * (p.outer_diameter**4 - p.inner_diameter**4)
    return w_sub, w_dry, ei, p.youngs_modulus * steel


def _loguniform(rng, lo, hi):
    return float(np.exp(rng.uniform(np.log(lo), np.log(hi))))


def _pipe(rng) -> tuple[dict, dict]:
    """Pipe changes and what was drawn."""
    rho_w, rho_s = 1025.0, 7900.0
    draws = 0
    while True:
        draws += 1
        od, dt = rng.uniform(0.15, 1.2), rng.uniform(12.0, 45.0)
        bare = rng.random() < 0.3
        coat, rho_c = rng.uniform(0.005, 0.120), rng.uniform(1900.0, 3400.0)
        coat = 0.0 if bare else coat
        idia, dc = od - 2.0 * od / dt, od + 2.0 * coat
        mass = rho_s * (od**2 - idia**2) + rho_c * (dc**2 - od**2)
        if mass / (rho_w * dc**2) >= SG_MIN:
            break
    rigid = rng.random() < P_RIGID  # applied to J-lay only (case_changes)
    changes = {"pipe.outer_diameter": od, "pipe.inner_diameter": idia,
               "pipe.coating_outer_diameter": dc, "pipe.hydrodynamic_diameter": dc,
               "pipe.coating_density": rho_c if coat else 0.0,
               "pipe.youngs_modulus": 1e15 if rigid else 207e9}
    return changes, {"od": od, "d_over_t": dt, "coating_mm": 1e3 * coat,
                     "coating_density": rho_c if coat else 0.0, "rigid": rigid,
                     "pipe_draws": draws}


def _suspended_weight(w_sub, w_dry, depth, x):
    return w_sub * min(x, depth) + w_dry * max(x - depth, 0.0)


def _jlay(rng, od, w_sub, w_dry, ea) -> tuple[dict, dict]:
    depth = _loguniform(rng, 50.0, 2500.0)
    x_top = depth + rng.uniform(3.0, 15.0)
    big_w = _suspended_weight(w_sub, w_dry, depth, x_top)
    h = od * w_sub / (2.0 * _loguniform(rng, *SAG_STRAIN))
    lo, hi = (big_w * math.cos(math.radians(t)) / (1.0 - math.cos(math.radians(t)))
              for t in TOP_ANGLE_J[::-1])
    h = max(min(max(h, lo), hi, TENSION_STRAIN * ea - big_w, H_MAX), 0.25 * h)
    theta = math.degrees(math.acos(h / (h + big_w)))
    a = h / w_sub
    span = a * math.acosh(1.0 + x_top / a)
    pinned, nudge = rng.random() < 0.5, rng.uniform(-2.0, 2.0)
    changes = {"environment.water_depth": depth, "lay.top": [x_top, span + 100.0 + 0.2 * span]}
    changes["lay.top_angle"] = None if pinned else min(theta + nudge, 90.0)
    return changes, {"depth": depth, "H": h, "W": big_w, "catenary_top_deg": theta,
                     "top": "pinned" if pinned else "firing line", "flexural_ratio": None}


def _stinger(rng, od, depth, x_u, straight) -> dict:
    """The stinger's ends and a, and its actual tip angle [deg]."""
    tip = rng.uniform(5.0, 60.0)
    u_u = math.tan(math.radians(rng.uniform(0.0, min(5.0, tip / 3.0))))
    length = rng.uniform(*STINGER_LENGTH)
    u_l = math.tan(math.radians(tip))
    room = x_u - 0.2 * depth  # largest height drop: tip 0.2 depth above the seabed
    if straight:
        dx = min(STINGER_SPAN * u_l, room, length * math.sin(math.radians(tip)))
        a, dz = 0.0, dx / u_l
    else:  # the turn over the drawn length, at most OVERBEND_STRAIN at the upper end
        kappa = min((math.radians(tip) - math.atan(u_u)) / length, 2.0 * OVERBEND_STRAIN / od)
        a = -0.5 * kappa * (1.0 + u_u**2) ** 1.5
        u_l = min(u_l, u_u + 2.0 * abs(a) * STINGER_SPAN)
        dx = (u_l**2 - u_u**2) / (4.0 * abs(a))
        if dx > room:
            dx = room
            u_l = math.sqrt(u_u**2 + 4.0 * abs(a) * dx)
        dz = (u_l - u_u) / (2.0 * abs(a))
    z_u = STINGER_UPPER_Z
    return {"a": a, "lower": [x_u - dx, z_u - dz], "upper": [x_u, z_u],
            "tip_deg": math.degrees(math.atan(u_l)), "tip_drawn_deg": tip,
            "overbend_strain": 0.0 if straight else od * abs(a) / (1.0 + u_u**2) ** 1.5,
            "straight": straight}


def _slay(rng, od, w_sub, w_dry, ea) -> tuple[dict, dict]:
    depth = _loguniform(rng, 20.0, 300.0)
    x_u = depth + rng.uniform(5.0, 15.0)
    straight = rng.random() < P_STRAIGHT
    st = _stinger(rng, od, depth, x_u, straight)
    big_w = _suspended_weight(w_sub, w_dry, depth, st["lower"][0])
    h = od * w_sub / (2.0 * _loguniform(rng, *SAG_STRAIN))
    lo, hi = (big_w * math.cos(math.radians(t)) / (1.0 - math.cos(math.radians(t)))
              for t in (min(DEPARTURE[1] * st["tip_deg"], 80.0), DEPARTURE[0] * st["tip_deg"]))
    h = max(min(max(h, lo), hi, TENSION_STRAIN * ea - big_w, H_MAX), 0.25 * h)
    departure = math.acos(h / (h + big_w))
    pinned = rng.random() < 0.5
    changes = {"environment.water_depth": depth, "lay.stinger.a": st["a"],
               "lay.stinger.lower": st["lower"], "lay.stinger.upper": st["upper"],
               "lay.top_angle": "pinned" if pinned else None}
    info = {"depth": depth, "H": h, "W": _suspended_weight(w_sub, w_dry, depth, x_u),
            "top": "pinned" if pinned else "firing line", "departure_deg":
            math.degrees(departure)} | {k: v for k, v in st.items() if k not in changes}
    return changes, info | {"stinger_length_z": st["upper"][1] - st["lower"][1]}


def case_changes(seed: int, dim: int, index: int) -> tuple[str, dict, dict]:
    """(example, changes, drawn) of case ``index`` of dimension ``dim`` (2 or 3)."""
    rng = np.random.default_rng([seed, dim, index])
    method = "J" if rng.random() < 0.5 else "S"
    base = load(BASES[(method, dim)])
    pipe, drawn = _pipe(rng)
    if method == "S" and drawn["rigid"]:  # a pinned top's jump (EI kappa)^2/(2 EI) is absurd
        pipe["pipe.youngs_modulus"], drawn["rigid"] = 207e9, False
    w_sub, w_dry, ei, ea = weights(base.with_changes(pipe | {"checks": None}))
    lay, more = (_jlay if method == "J" else _slay)(rng, pipe["pipe.outer_diameter"],
                                                    w_sub, w_dry, ea)
    drawn |= more | {"method": method, "w_sub": w_sub, "w_dry": w_dry,
                     "flexural_ratio": math.sqrt(ei / more["H"]) / more["depth"]}
    top = rng.random() < 0.5
    tension = ({"lay.top_tension": more["H"] + more["W"]} if top
               else {"lay.bottom_tension": more["H"], "lay.top_tension": None})
    drawn["tension"] = "top" if top else "bottom"
    speed, heading = rng.uniform(0.2, 2.5), rng.uniform(0.0, 360.0)
    exponent, mu = rng.uniform(0.1, 0.3), rng.uniform(0.2, 1.0)
    planar = dim == 3 and rng.random() < P_PLANAR
    if planar:
        speed, heading = (0.0, 0.0) if rng.random() < 0.5 else (speed, rng.choice([0.0, 180.0]))
    current = ({"environment.current.speed": 0.0} if dim == 2 else
               {"environment.current.speed": speed, "environment.current.heading": heading,
                "environment.current.profile": "power", "environment.current.exponent": exponent,
                "seabed.lateral_friction": mu})
    drawn |= {"planar": planar or dim == 2}
    changes = pipe | lay | tension | current | {"solver.dimension": f"{dim}d", "checks": None}
    return BASES[(method, dim)], _plain(changes), drawn


def _plain(changes: dict) -> dict:
    return {k: (v if v is None or isinstance(v, str) else
                [float(x) for x in v] if isinstance(v, list) else float(v))
            for k, v in changes.items()}


def load(example: str) -> pf.Case:
    return pf.load_case(EXAMPLES / f"{example}.toml")


# --------------------------------------------------------------------------- the references


def reference(case: pf.Case) -> dict:
    """The planar elastica of ``case``: tensions [N], peak moments [N m] and the
    largest extreme-fibre strain (bending plus wall tension over EA, external
    pressure on the steel's outer diameter). Raises RuntimeError (or
    ValueError) when the reference finds no equilibrium."""
    w_sub, w_dry, ei, ea = weights(case)
    depth, lay = case.environment.water_depth, case.lay
    tension = ({"T_top": lay.top_tension} if lay.top_tension is not None
               else {"T_bottom": lay.bottom_tension})
    if lay.stinger is None:
        x_top, z_top = lay.top
        r = jlay_elastica(ei, w_sub, w_dry, depth, x_top, z_top, top_angle_deg=lay.top_angle,
                          **tension)
        # the engine's J-lay sagbend: the largest interior peak of |M|, else the largest |M|
        out = {"top_tension": r["top_tension"], "bottom_tension": r["bottom_tension"],
               "sagbend_max_moment": r["sagbend_moment"] or r["max_moment"],
               "max_moment": r["max_moment"]}
    else:
        st = lay.stinger
        jump = 0.0
        if lay.top_angle == "pinned":  # the engine's pin: the tension jumps by M_U^2 / (2 EI)
            u = 2.0 * st.a * st.upper[1] + _b(st)
            jump = 0.5 * ei * (2.0 * st.a / (1.0 + u * u) ** 1.5) ** 2
        on = dict(tension, T_top=tension["T_top"] - jump) if "T_top" in tension else tension
        try:
            r = slay_elastica(ei, w_sub, w_dry, depth, st.a, st.lower, st.upper, **on)
        except (RuntimeError, ValueError) as err:  # no lift-off nor tip regime
            r = _clear_of_stinger(case, err, ei, w_sub, w_dry, **tension)
            out = {"top_tension": r["top_tension"], "bottom_tension": r["bottom_tension"],
                   "sagbend_max_moment": r["sagbend_moment"] or r["max_moment"],
                   "regime": "clear"}
            out["max_strain"] = ref_strain(case, r, ei, ea)
            return out
        out = {"top_tension": r["top_tension"] + jump, "bottom_tension": r["bottom_tension"],
               "sagbend_max_moment": (r["sagbend_max_moment"] if r["regime"] == "liftoff"
                                      else _sag_below_tip(r, st.lower[1])),
               "overbend_max_moment": r["overbend_max_moment"], "regime": r["regime"]}
    out["max_strain"] = ref_strain(case, r, ei, ea)
    return out


def _clear_of_stinger(case: pf.Case, err: Exception, ei, w_sub, w_dry, **tension) -> dict:
    """An S-lay whose pipe touches the stinger only at its upper end, the top:
    the J-lay elastica from touchdown to the stinger's upper end, held there
    along the stinger's tangent (the firing line) or pinned, accepted when it
    lies above the stinger's curve over the whole curve (its tip included).
    Re-raises ``err``, the S-lay reference's refusal, otherwise."""
    lay, st = case.lay, case.lay.stinger
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    angle = None
    if lay.top_angle != "pinned":
        angle = (lay.top_angle if lay.top_angle is not None
                 else math.degrees(math.atan(2.0 * st.a * z_u + _b(st))))
    try:
        r = jlay_elastica(ei, w_sub, w_dry, case.environment.water_depth, x_u, z_u,
                          top_angle_deg=angle, **tension)
    except (RuntimeError, ValueError):
        raise err from None
    z, x = np.asarray(r["z"], dtype=float), np.asarray(r["x"], dtype=float)
    over = (z >= z_l) & (z < z_u - 1e-6 * (z_u - z_l))
    curve = (st.a * z + _b(st)) * z + (x_l - (st.a * z_l + _b(st)) * z_l)
    if not over.any() or np.any(x[over] < curve[over]):
        raise err
    return r


def _sag_below_tip(r: dict, z_tip: float) -> float:
    """The largest sagging moment [N m] below the tip of an S-lay reference
    bearing on it: the engine's sagbend ends at the tip (lift-off), the
    reference's takes in the stretch hovering above it. Its largest sampled
    node refined on 2001 points between the nodes either side."""
    below = np.flatnonzero(r["z"] <= z_tip)
    s, m = r["s"][below], r["moment"][below]
    k = int(np.argmax(m))
    fine = np.linspace(s[max(k - 1, 0)], s[min(k + 1, s.size - 1)], 2001)
    return max(float(np.max(r["free_state"](fine)[3])), 0.0)


def _b(st) -> float:
    (x_l, z_l), (x_u, z_u) = st.lower, st.upper
    return (x_u - x_l) / (z_u - z_l) - st.a * (z_u + z_l)


def ref_strain(case: pf.Case, r: dict, ei: float, ea: float) -> float:
    """Largest (Do/2)|M|/EI + |Tw|/EA on the reference's profile, Tw = Te + pe Ao
    (empty pipe; pe the hydrostatic pressure on the steel's outer diameter)."""
    p, env = case.pipe, case.environment
    x, m, te = (np.asarray(r[k], dtype=float) for k in ("x", "moment", "tension"))
    pe = env.water_density * env.gravity * np.maximum(env.water_depth - x, 0.0)
    tw = te + pe * math.pi / 4 * p.outer_diameter**2
    strain = 0.5 * p.outer_diameter * np.abs(m) / ei + np.abs(tw) / ea * p.extensible
    return float(strain.max())


COMPARED = ("top_tension", "bottom_tension", "sagbend_max_moment", "overbend_max_moment",
            "max_moment")


def compare(summary: dict, ref: dict) -> dict:
    """Relative differences engine - reference of the COMPARED figures the
    reference has; a moment's relative to the larger of itself and 1 % of the
    reference's largest peak moment."""
    peak = max(abs(ref.get(k) or 0.0) for k in COMPARED if "moment" in k)
    out = {}
    for key in COMPARED:
        if ref.get(key) is None or summary.get(key) is None:
            continue
        floor = 0.01 * peak if "moment" in key else 0.0
        out[key] = (summary[key] - ref[key]) / max(abs(ref[key]), floor, 1e-300)
    return out
