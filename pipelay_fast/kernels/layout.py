"""Flat layout of the model data that reaches the kernels.

A case becomes one float64 vector ``props`` of the scene (indices below, SI
units), the per-element array ``section`` of the pipe's sections (one row per
element, the ``S_*`` columns below), plus a few arrays (element lengths, the
current table, constraint sets). Kernels index ``props`` and a ``section``
row with these module-level integer constants, which numba freezes as
compile-time constants.

Nodal unknowns, node by node (so the global matrix is banded):

* 3D: ``x, y, z, x', y', z', lam``  (7 per node, half-bandwidth 13)
* 2D: ``x, z, x', z', lam``          (5 per node, half-bandwidth 9)

``x`` is the height above the seabed, ``z`` the horizontal lay direction, ``y``
lateral; ``'`` is d/ds with s the unstretched arc length; ``lam`` is Garrett's
multiplier lambda = Te - EI kappa^2 [N]. The slot of ``x`` is component 0 in both
dimensions; ``z`` is component ``nd - 1``.
"""

# --- props vector: the scene, the same for every element --------------------
EI_REF = 0  # reference bending stiffness [N m2]: Newton's scale of the multipliers
#             (EI / href^2), not the elements' stiffness (``section``'s S_EI)
H_CONT = 1  # contents free-surface height [m]
DEPTH = 2  # water depth [m]
RHOW_G = 3  # water density * g [N/m3]
RHOI_G = 4  # contents density * g [N/m3]
CUR_SPEED = 5  # surface current speed [m/s]
CUR_EY = 6  # current direction, y component [-]
CUR_EZ = 7  # current direction, z component [-]
CUR_PROFILE = 8  # 0 uniform, 1 linear, 2 power, 3 table
CUR_EXP = 9  # power-law exponent [-]
SEABED_K = 10  # elastic seabed stiffness per length [N/m2]; 0 = rigid
EXTENSIBLE = 11  # 1.0 extensible, 0.0 inextensible
TORQUE = 12  # torque H [N m] at the top (constant when m . t = 0)
MOM_X = 13  # distributed moment, global components [N m/m]
MOM_Y = 14
MOM_Z = 15
MU_Y = 16  # lateral seabed friction coefficient [-]
MU_Z = 17  # axial seabed friction coefficient [-]
FRICTION_SLIP = 18  # displacement that mobilises full friction [m]
SEABED_TAN = 19  # tan of the seabed plane's angle [-] (0: flat); the elastic seabed's normal
SEABED_Z0 = 20  # z where the sloped plane passes through x = 0 [m]
N_PROPS = 21

# --- section: the pipe's properties, a row per element ---------------------
# ``Model.section`` is (n_elements, N_SECTION) float64, C-contiguous; element e
# reads row e (the engine maps the sections along the line onto the elements,
# :func:`pipelay_fast.engine.model.section_array`). The rod is torsionally
# rigid (the torque H is given, not a twist unknown): no torsional stiffness.
S_EI = 0  # bending stiffness [N m2]
S_EA = 1  # axial stiffness [N]
S_W_DRY = 2  # weight of steel + coating per length, in air [N/m]
S_W_CONT = 3  # weight of contents per length where x < contents level [N/m]
S_W_BUOY = 4  # buoyancy per length where x < water depth [N/m]
S_AREA_I = 5  # inner steel area pi Di^2/4 [m2]
S_AREA_E = 6  # outer steel area pi Do^2/4 [m2]
S_DRAG = 7  # 0.5 * rho_w * C_D * D_h [kg/m2]
N_SECTION = 8

# --- load-path control: the vector ``factors`` of a Model (:mod:`.types`) -------
# Not model data: the solver sets them along its load path, props stays the case's.
F_CURRENT = 0  # load factor on the current drag [-]
F_FRICTION = 1  # 1.0 while seabed friction acts (the current's load path), else 0.0
N_FACTORS = 2

# --- seabed friction state per node (columns of the ``fric`` array) -----------
# Each seabed contact carries an elastic-perfectly-plastic friction spring per
# direction: force -mu W (d / FRICTION_SLIP), capped at mu W, where d is the
# displacement from the spring's anchor. At the end of a load step a slipping
# spring's anchor follows the pipe (return mapping).
FR_DIR = 0  # lateral: 0 sticks; +1 / -1 slipping, the friction force along +y / -y
FR_Y = 1  # lateral anchor y [m]
FR_W = 2  # normal force [N]: an elastic seabed's; on a rigid one the answer's reaction
FR_DIRZ = 3  # axial: as FR_DIR, along z
FR_Z = 4  # axial anchor z [m]
FR_S = 5  # arc length [m] of the material point the anchors belong to
N_FRIC = 6

# --- contact boundaries that can be unknowns of Newton ---------------------
# (entries of ``Mesh.bnodes``, rows of ``Mesh.s_b``, entries of ``Mesh.s_bd``)
B_TD = 0  # touchdown
B_LO = 1  # lift-off from the stinger (or re-contact above a bearing tip)
B_PT = 2  # the first rigid point (the stinger's tip first); point j is boundary
#           B_PT + j: the material point over it

# --- the supports: rows of ``Supports.kind``, ``geom`` and ``active`` ------------
# Each support holds the pipe from below: its kind (``kind``, SUP_*), its
# parameters (a row of ``geom``, N_GEOM columns, named per kind below) and the
# nodes it holds (a row of ``active``, int8 per node). Row b is contact
# boundary b's support: touchdown's the seabed, lift-off's the stinger's curve,
# point j's (boundary B_PT + j) row ROW_PT + j.
SUP_NONE = 0  # an empty row: holds nothing (the curve's row of a J-lay or a roller stinger)
SUP_SEABED = 1  # the seabed, a plane x = level + tan(angle) (z - z0) (flat: angle 0), held in
#                  nodal frames turned by its angle (none when flat); friction springs
SUP_CURVE = 2  # the quadratic stinger x = a z^2 + b z + c on [zL, zU] (turned about the
#                origin by a trim), held in curve coordinates
SUP_POINT = 3  # a rigid point in the lay plane (the stinger's tip, a roller), held at
#                its boundary's node by a unilateral contact
ROW_BED = B_TD  # the seabed's row
ROW_CURVE = B_LO  # the stinger curve's row
ROW_PT = B_PT  # the first rigid point's row
N_GEOM = 6  # columns of ``geom``

# the seabed's row: x = level + tan(angle) (z - z0)
SB_LEVEL = 0  # its height x [m] at z0 (0: the reference seabed is the origin of x)
SB_ANGLE = 1  # its angle above horizontal along z [rad] (positive: rising towards +z)
SB_Z0 = 2  # z0 [m], where it passes through the level

# the stinger curve's row: x = a z^2 + b z + c on [zL, zU], x the height and z
# the lay direction [m]; a trimmed vessel's curve is that parabola in the
# coordinates (x'', z'') of a frame turned by ST_TURN about the origin, so that
# x = cos(t) x'' + sin(t) z'', z = cos(t) z'' - sin(t) x'' (t > 0: turned
# counter-clockwise seen with z to the right and x up, the stern at -z down);
# zL and zU are the ends' global z (:func:`.supports.support_height`)
ST_A = 0  # a [1/m]
ST_B = 1  # b [-]
ST_C = 2  # c [m]
ST_ZL = 3  # zL [m], the tip (its lower end)
ST_ZU = 4  # zU [m]
ST_TURN = 5  # t [rad], the vessel's trim (0: the parabola in the global frame)
N_STINGER = 6

# a rigid point's row: a node follows the material point over it (a boundary
# unknown of Newton, :mod:`.constraints`) and its normal contact is chosen by
# the complementarity min(R, c g) = 0 (columns PT_BEAR and PT_R its state,
# which the Newton kernel updates).
PT_X = 0  # the point's x [m] (the vertical, as the nodal unknown x)
PT_Z = 1  # the point's z [m]
PT_BEAR = 2  # 1 while the pipe bears on it, else 0 (the complementarity's branch)
PT_R = 3  # its normal reaction [N] while it bears
PT_HOLD = 4  # 1: while it bears it holds the pipe laterally, y = 0 (a V roller; 3D)
N_PT = 5

# --- the Newton kernel's report (the vector ``info``) -----------------------
I_STATUS = 0  # status code (below)
I_ITER = 1  # Newton iterations taken
I_RES = 2  # weighted residual (max norm) at exit [-]
I_DELTA = 3  # largest constraint violation at exit [m, rad]
I_TOP_RES = 4  # relative top-tension residual [-]
I_PAST = 5  # PAST_TIP: how far [m] along the pipe the step would take lift-off past the tip
I_TOP_TE = 6  # a call with maxit 0: the top's effective tension [N] (0: not given)
N_INFO = 7

# --- current profiles ---------------------------------------------------------
PROFILE_UNIFORM = 0
PROFILE_LINEAR = 1
PROFILE_POWER = 2
PROFILE_TABLE = 3

# --- kernel status codes (Python turns them into SolveError messages) ------
OK = 0
MAX_ITERATIONS = 1
SINGULAR = 2
NOT_FINITE = 3
TIP_CYCLE = 4
PAST_TIP = 5
SHORT_LAID = 6
SPAN_CLOSED = 7

STATUS_TEXT = {
    OK: "converged",
    MAX_ITERATIONS: "maximum number of Newton iterations reached",
    SINGULAR: "singular tangent matrix (a mechanism: is the pipe held?)",
    NOT_FINITE: "non-finite or runaway residual (the iteration diverged)",
    TIP_CYCLE: "the tip's contact kept switching between bearing and clear",
    PAST_TIP: ("lift-off reached the stinger's tip from above and Newton moves it further "
               "down, after the switches to bearing on the tip that a solve may make"),
    SPAN_CLOSED: ("bearing on the stinger's tip, Newton closes the gap span between re-contact "
                  "and the tip (the caller switches to lifting off above the tip)"),
    SHORT_LAID: ("touchdown moves more than half way to the modelled lower end in one "
                 "Newton step (the solver prepends laid pipe and goes on)"),
}

