"""The one set of numerical thresholds of kincas's solvers (careful Newton, compiled kernel,
assembly modes, tolerance sampling, redundant joints, branch tests).

Residuals are relative: each equation's residual is divided by the length of its own Assur
group (`Model.scales`), so a mechanism of 1e-6 m and one of 1e6 m, or a small group beside a
far point, reach the same relative accuracy.

>>> TOL < ACCEPT < BRANCH
True
"""

TOL = 1e-13  # Newton stops when its next step (radians, lengths over the group's length) is below this
ACCEPT = 1e-10  # a pose whose relative residual is above this is not solved
MAX_STEP = 0.5  # largest Newton step per iteration: radians, or this times the group's length
# A solved Newton step that is not below SHRINK times the one before it is rounding (steps
# shrink quadratically at a regular root, by 1/2 per step onto a double root): stop there
SHRINK = 0.75
MAX_ITER = 40  # Newton iterations per group before giving up
BACKTRACK = 1 / 32  # shortest fraction of a Newton step tried while backtracking
DECREASE = 1e-4  # a backtracked step must lower the residual by this times its fraction
BRANCH = 1e-8  # |det| of the column-scaled g_q below this: too close to singular to tell a branch
RANK = 1e-8  # a scaled singular value below this times the largest counts as zero
RANK_GAP = 1e-4  # g_q's smallest scaled singular value above this times the largest: a regular assembly
SAME_ASSEMBLY = 1e-6  # assemblies closer than this (scaled) are one (the redundant-joint test)

# --- rounding ---
TINY = 1e-300  # floor of a scale against division by zero (not a tolerance: any tiny normal number)
# A quantity below this times its own scale is zero to the rounding of a solve (positions are
# right to about 1e-12 of the size): the dyad's closed form, a centre of curvature, a ratio
ROUNDING_REL = 1e-12
SAME_INPUT = 1e-9  # two input values (radians, or lengths) are one when they agree to this relatively
STRAIGHT = 1e-9  # a step whose direction turned by less than this (relatively) continues the previous one

# --- singular positions ---
SIGN_TOL = 1e-8  # a group whose conditioning is below this has no trustworthy sign (mode 0)
# Newton converges only linearly onto a singular position, and stops about sqrt(TOL) from
# it: a group conditioned below NEAR_SINGULAR may be *at* one; `polish_singular` decides.
NEAR_SINGULAR = 1e-5
# A pose is *at* a singular position when one satisfies g = 0 there to rounding: a pose 1e-12
# of the input away from a limit is 1e-6 of the size away from the limit's positions.
ROUNDING = 1e-15
NULL_RESIDUAL = 1e-10  # polish_singular accepts null directions whose equations are below this
FLAG_SIGMA = 1e-7  # relative smallest singular value at which a pose *is* singular
CLASSIFY = 1e-6  # relative singular value below which a singular position's kind is decided
REACHED = 1e-3  # a located position this fraction of a step away from a pose: the pose all but reached it
STEP_SLACK = 1e-9  # a position located at s in [-STEP_SLACK, 1 + STEP_SLACK] of a step lies on it
MIN_ARC_STEP = 1e-12  # following a branch gives up when its step (scaled) halves below this
WATCH = 0.5  # a group conditioned below this at either end of a step is checked for a crossing
# ... and a spatial one only where its block's smallest singular value at both ends is within
# this times the block's change over the step (Weyl: singular inside needs that much change;
# the factor allows for the block turning along the step), kincas/analysis/watch.py
WATCH_REACH = 2.0

# --- continuation (kincas/analysis/path.py: every walk along a path of poses) ---
# A corrected pose farther than WANDER_SHARE of the predicted move (or WANDER_FLOOR, scaled)
# from its prediction went elsewhere on the branch: the step is cut
WANDER_FLOOR, WANDER_SHARE = 0.02, 0.5
ILL = 1e2  # g_q's condition number (scaled, per sqrt of its rows) above which a step is predicted by the secant
SLOW = 8  # Newton iterations a step that is not the shortest may take (more: cut it)
CAREFUL_DEPTH = 8  # halvings of one step of a sweep's careful path
CARRY_DEPTH, CARRY_BUDGET = 10, 200  # halvings of, and solves spent on, one input step of a gap
CARRY_ITER = 12  # Newton iterations per group while carrying groups through a gap
# the range of an input, in arclength (scaled unknowns): first step, longest, growth on success
ARC_FIRST, ARC_LONGEST, ARC_GROW = 0.02, 0.2, 1.5
ARC_ITER = 12  # corrector iterations per arclength step
ARC_WANDER = 0.5  # an arclength corrector landing farther than this from its prediction: rejected

# --- the compiled kernel (kincas/core/kernel.py) ---
JAC_CHANGE = 0.9  # per group, sum |entries of D^-1 (A_prev^-1 A - I) D| (below 1 keeps det's sign)
CORRECTION = 0.25  # max per group of ||D^-1 (q - q_pred)||_1: Newton may not wander far from the prediction
MAX_EVALS = 5  # kN evaluations per pose at most
KERNEL_NEAR = 1e-8  # kN's step below which the next is negligible where convergence is quadratic
# The quintic prediction (three poses and their tangents) is used where the step before the
# last was between these times the last one (else the cubic of the last two): beyond, the
# extrapolation's weights grow with the unevenness and amplify rounding
QUINTIC_RATIO = (0.5, 2.0)
QUINTIC_REACH = 2.0  # ... and the step predicted is at most this times the last one
# the quintic runs at a pose where the cubic's error at the last one (scaled) lay between these
# (below, the cubic converges: a dense sweep; above, the quintic misses by more than STEP too)
QUINTIC_ON, QUINTIC_TRY = 5e-14, 3e-10
PARAM_STEP = 0.05  # designs loop: largest parameter change per continuation step, relative to the size

# --- assembly modes and starts ---
START_CONVERGED = 1e-8  # a start whose relative residual reaches this is worth polishing
GENERIC_MOVE = 0.1  # the step (rad, or times the size) that takes an assembly to a generic point
JITTER = 1e-3  # starts moved off special positions (links in line) by this times the size

# --- derived quantities ---
NULL_REL = 1e-9  # at rest / same rate, relative to the speed scale of the inputs
JAMMED = 1e-8  # redundant joints: g_q dq + g_p dp missing 0 by this (relatively): p jams the chain
MESH = 1e-9  # gears whose centre distance misses r1 +- r2 by this times the size do not mesh

# --- the assembly NLP and the JAX translation ---
IPOPT_TOL = 1e-12
REGULARIZE = 1e-6  # weight of ||x - x0||^2 in the assembly NLP: the nearest assembly among equals
TRANSLATION_RTOL, TRANSLATION_ATOL = 1e-12, 1e-14  # JAX against casadi on random arguments
FREE_LINKS = 6  # links left free by a guess that are tried in several turns (core/guessed.py), at most
NEARER = 1e-9  # another start's assembly is nearer the guessed points when its cost is below (1 - this) times
CHOICE_STARTS = 128  # scattered starts finding a guessless sweep's other assemblies (analysis/choice.py)
CHOICE_TRIES = 8  # of which at most this many are swept
CHOICE_TRIES_CERTIFIED = 40  # certified assemblies swept at most (all of them, to say with certainty that none runs)
CHOICE_CERTIFY_TIMEOUT = 10.0  # seconds msolve may take to certify a guessless sweep's first pose (else the multistart)

# --- pictures ---
END_ON = 1e-6  # a slide's unit direction drawn shorter than this is seen end on (views/projection.py)

# spatial mechanisms (core/space_model.py, core/space_symbolic.py)
IDENTITY_PULL = 1e-9  # a rigid fit's faint pull towards the identity, relative to its points' spread
PROJECTION = 1e-9  # a unit axis projected on a plane shorter than this is normal to it

# --- certified assembly modes (kincas/core/polynomial*.py, kincas/analysis/certify*.py) ---
CERTIFY_DENOMINATOR = 2 ** 20  # a driven or line angle's half-angle tangent rounded to a rational of this denominator at most (angle within ~1e-12 rad)
CERTIFY_BITS = 64  # msolve's precision of the isolating boxes (bits; boxes far smaller than a float's rounding)
CERTIFY_ROUNDING = 2.0 ** -46  # relative rounding error of a residual evaluated in floats (64 ulps), for a refined point's error bound
CERTIFY_OFF_MODEL = 100.0  # a certified root farther than ACCEPT + this x the geometry's rationalisation
# (`PolySystem.perturbation`) from the numerical model's map of it breaks an equation the model holds
# by construction (a spatial body hung on its joint): not an assembly (kincas/analysis/certify.py)
CERTIFY_TIMEOUT = 120.0  # seconds msolve may take before the certificate is given up
CERTIFY_SPLIT = 1e-2  # roots a multiple root splits into are counted within this (scaled) distance of it, at most
CERTIFY_NUDGE = 1e-7  # input change (rad, or times the size) that splits coinciding assemblies to count them

# --- forward dynamics (kincas/core/motion.py, kincas/analysis/simulate.py) ---
ROOT_ABSTOL = 1e-12  # CasADi's Newton for q(u) inside the equations of motion: residual over the size
ROOT_STEPTOL = 1e-13  # ... or a step (radians, lengths) below this
SIM_RTOL = 1e-10  # the integrator's relative tolerance unless [simulate] tolerance says
SIM_ATOL = 1e-12  # its absolute tolerance, times the state's scale (the size, or 1 rad)
SIM_SINGULAR = 1e-4  # smallest scaled singular value of g_q (over the largest) at which the motion stops: a limit (delta u ~ 1e-8 of the size) ahead
EVENT_TIME = 1e-12  # events are located to this times the duration
SIM_MAX_STEPS = 5000  # integrator steps per output interval at most: more means a singular position ahead
SIM_CLASSIFY = 30.0  # where the motion stopped, (g_q | g_u)'s smallest scaled singular value over g_q's above this: a limit
CYCLE_MATCH = 1e-9  # k turns over a load's period c is a whole number when it misses one by less than this
