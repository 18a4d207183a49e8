"""Every tuning constant of the engine, each with the reason for its value.

A value is a derivation (stated), a measurement (the benchmark script that
makes it; its figures are in that script's report, not here) or a standard
choice (named). The kernels' constants are :mod:`pipelay_fast.kernels.layout`'s
and the Newton kernel's phases'; the input layer's limits are
:mod:`pipelay_fast.input.limits`'.
"""

from __future__ import annotations

# --- round-off -----------------------------------------------------------------
# Relative difference [-] below which two arc lengths, mesh lengths or element
# counts are the same: sums of up to ~1e5 terms in float64 (1e5 * 2.2e-16 =
# 2e-11), with a margin of 50.
REL_ROUNDOFF = 1e-9

# --- boundary layers -------------------------------------------------------------
# A boundary layer of length lam (the flexural length sqrt(EI/T)) decays as
# exp(-s / lam): three lengths leave exp(-3) = 5 %. The mesh each contact
# boundary carries with it (its zone, :func:`.boundaries.follow_nodes`), and the
# sticking zone kept behind the slipping one (:func:`.friction.slipping_length_bound`).
DECAY_LENGTHS = 3.0

# --- Newton's steps of the contact boundaries (:func:`.continuation.boundary_step`)
# The largest move of a boundary in one Newton step: MAX_BOUNDARY_STEP elements
# (href), or BOUNDARY_STEP_LAYER boundary layers in a tension-dominated lay, the
# larger. Measured: cold iterations on the grid and the random cases,
# benchmarks/bench_contact.py parts 1 and 6 (larger steps lose random cases;
# elements alone hold fine meshes to short steps).
MAX_BOUNDARY_STEP = 2.0
BOUNDARY_STEP_LAYER = 0.2

# --- load paths (:func:`.continuation.continuation`) ------------------------------
# The first step of every load path, a quarter of the load. The bisection
# rule: a converged step multiplies the next by LOAD_STEP_FACTOR, a failed one
# divides it (bisection: a cut step is the half of the failed one that starts
# from the last converged state, and growth undoes one cut).
FIRST_LOAD_STEP = 0.25
LOAD_STEP_FACTOR = 2.0
# The homotopy from the first guess: steps of at most half the load; a step cut
# below HOMOTOPY_SMALLEST fails the solve (the first step halved 12 times).
HOMOTOPY_LARGEST = 0.5
HOMOTOPY_SMALLEST = 1e-4
# The current's path: friction is path dependent, so its steps stay a quarter
# (half steps follow another slip path on fine meshes: S125 3D,
# benchmarks/bench_contact.py part 2); a step cut below CURRENT_SMALLEST (8
# halvings) fails, and the path may take CURRENT_STEPS times
# solver.max_load_steps steps (four times the homotopy's: its steps are smaller).
CURRENT_LARGEST = 0.25
CURRENT_SMALLEST = 1e-3
CURRENT_STEPS = 4
# A predicted start of a load step (a warm start's neighbour's increment, or
# the path's secant) may take at most this many times the iterations of the
# path's hardest converged call before the step is solved again from the last
# converged state (measured: the random 3D cases, bench_contact.py part 6).
PREDICTED_CAP = 2

# --- the regime at the stinger's tip (:mod:`.boundaries`) -------------------------
# Switches between bearing on the tip and lifting off in one Newton solve: one
# each way.
MAX_TIP_SWITCHES = 2

# --- meshes ----------------------------------------------------------------------
# Geometric growth of neighbouring elements of a graded mesh (:mod:`.mesh`).
GROWTH = 1.2
# A mesh is graded at its foci when no node is further than ON_FOCUS h_min from
# the graded mesh's (the error of a node off its focus by d is O(d^2)).
ON_FOCUS = 0.02
# The shortest element [h_min] between lift-off and the tip's point, and the
# move of re-contact below which bear_on_tip leaves it (:mod:`.boundaries`).
HOLD_SPLIT = 0.1
# Regrading passes at the boundaries found (:func:`.solver._solve_mesh`): the
# first mesh, the one graded at its answer, and two more.
MAX_MESH_PASSES = 4
# Newton's tolerance [-] on the first mesh, which only finds where the
# boundaries are (regrading moves them by its own discretisation): measured,
# cold iterations and answers on the quick grid, bench_contact.py parts 1 to 3.
LOOSE_TOLERANCE = 1e-3
# The roller problem: the material point over each roller found by this many
# projections on the guide answer's tangent from the nearest node; a roller
# bears at the start within ROLLER_ON h_min of the pipe (:mod:`.problem`).
ROLLER_PROJECTIONS = 2
ROLLER_ON = 1e-6

# --- laid pipe (:func:`.solver.laid_short`, :func:`.solver.more_laid`) ----------------
# The laid pipe a mesh models behind touchdown: at least one flexural length
# sqrt(EI/T) (the boundary layer over which the pipe leaves the seabed),
# doubled to at least two when short. The first mesh has two and five
# elements (:func:`.problem.build_problem`); a solve adds laid pipe until the
# mesh would exceed solver.max_elements.
LAID_LENGTHS = 1.0
# The largest share of the laid pipe's lateral force the held lower end may
# carry before the laid pipe is doubled: measured, the shares left with the
# sticking zone of DECAY_LENGTHS on the 3D grid, bench_contact.py part 1.
LOWER_END_SHARE = 0.01

# --- the first guess (:mod:`.guess`) ------------------------------------------------
# A guess that lifts off below the tip by less than this share of lam starts
# from the tip, lifting off (within the guess's first-order error in lam);
# measured: cold iterations on the grid, bench_contact.py part 1.
GUESS_LIFTOFF_ERROR = 0.05
# A roller stinger's guide (the quadratic through its rollers) on elements this
# many times the case's: its answer is only a start (measured:
# benchmarks/bench_rollers.py parts 1 and 3).
GUIDE_COARSENING = 2.0
