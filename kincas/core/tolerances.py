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
FREE_LINKS = 6  # links left free by a guess that are tried in several turns (core/guessed.py), at most
NEARER = 1e-9  # another start's assembly is nearer the guessed points when its cost is below (1 - this) times
CHOICE_STARTS = 128  # scattered starts finding a guessless sweep's other assemblies (analysis/choice.py)
CHOICE_TRIES = 8  # of which at most this many are swept
