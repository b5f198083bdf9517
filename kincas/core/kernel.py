"""The fast sweep's kernel: casadi functions for one pose, and the C loop that drives them.

The functions, every linear solve done Assur group by Assur group (kincas/core/blocks.py),
so their size grows with the number of groups, not with nq^3:

- kP: the prediction from the last two solved poses (tangent, second- and third-order terms);
  kP5: from the last three, of fifth order, run while it pays (kincas/core/prediction.py);
  both evaluated by the virtual machine; the C loop forms the same numbers from kW, their
  scalars, in a loop over the unknowns of its own (the same operations in the same order);
- kN: at q, the Newton step g_q^-1 g (Gauss-Newton's (g_q'g_q)^-1 g_q' g for a tall group:
  redundant joints, kincas/core/blocks.py) and the measures that stop Newton (max |g| / L and the
  step's size in radians or lengths / L, each equation and unknown against its own Assur
  group's length L, as on the careful path): nothing else is evaluated at a Newton iterate;
- kF: once per pose, at the final q: g_q, the tangent dq/du, the residual, the branch test
  against the last pose (Jacobian change per group, size of the correction), the singular
  measures (the sign of each group's det and a lower bound of its smallest singular value,
  columns scaled to O(1)) and the reported quantities, sharing one set of sines and cosines;
- kL: each group's length (`Structure.length_function`), once per call of the C loop, so a
  far point elsewhere in the drawing loosens no group's tests.

One stopping rule: a pose is converged when the Newton step that would follow is below STEP
(radians, or lengths / L) and the residual below RESIDUAL; that last step is applied, so a
pose ends where quadratic convergence puts it (rounding). kN iterates until its step is
below KERNEL_NEAR (quadratic convergence then makes the next one ~KERNEL_NEAR^2), and kF, which needs g
and g_q at the final q anyway, gives that next step: a pose usually costs one or two kN and
one kF. Where convergence is not quadratic (near a singular position) the next step stays
above STEP and the pose goes to the careful path, whose Newton goes on while its steps
shrink and stops at rounding there (kincas/core/newton.py): the kernel accepts only what
both rules accept alike, a negligible next step.
"""
from __future__ import annotations

import casadi as ca

from .prediction import cubic, cubic_weights, quintic, quintic_weights
from .group_kernel import GroupFunctions, _max_abs, group_correction, group_scales
from .structure import Structure
from ..model.names import parse_quantity
from .blocks import block_change, block_measures, block_solve, diagonal_blocks, diagonal_size, reciprocal, is_tall
from .tolerances import ACCEPT, CORRECTION, JAC_CHANGE, KERNEL_NEAR, MAX_EVALS, QUINTIC_ON, QUINTIC_TRY, TOL  # noqa: F401

RESIDUAL = ACCEPT  # max |g| / L at an accepted pose, as on the careful path
# The next Newton step's largest entry (radians, or lengths / L), applied before stopping: the
# largest entry, not a sum, so that rounding in a long chain of groups does not add up past it
STEP = TOL
# JAC_CHANGE, CORRECTION, MAX_EVALS and KERNEL_NEAR: kincas/core/tolerances.py
# From this many groups on, kN and kF call one small function per kind of run of GROUP_RUN
# consecutive groups (kincas/core/group_kernel.py) instead of being one expression: the C
# compiler's time grows faster than the size of one function (gcc -O3 on 40 chained
# four-bars, flat: 6.3 s of CPU against 1.6 s). Within a run the arithmetic is the flat
# kernel's (one sine and cosine per angle); between runs, calls and copies. Measured on 40
# chained four-bars, 3,600 poses, kernel only, interleaved (bit-identical results): runs of
# 1 group 4.9 us a pose, 4 groups 4.0, 8 groups 4.0, 20 groups 4.1, flat 4.0; compiled in
# 7.5 s (4 groups), 8.8 s (1) and 23 s (flat) of a loaded machine's wall clock.
GROUPS_APART = 16
GROUP_RUN = 4  # consecutive groups per function written group by group (measured above)
# From this many unknowns on, the kernel has the quintic prediction kP5 (kincas/core/
# prediction.py): where it lets a pose skip its Newton step, it saves a kN (40 chained
# four-bars, 360 poses over 60 deg: 41k -> 26k instructions a pose). On a small kernel the
# step costs little and the quintic's scalars (kW) cost a four-bar's pose ~150 instructions
# (its cubic, ~30); written as casadi code the quintic also cost compiling (gcc 0.27 -> 0.37
# s of CPU for a four-bar's kernel, which a user's first sweeps wait for).
QUINTIC_UNKNOWNS = 16


# --- the casadi functions ---


def kernel_functions(sym, blocks, report=(), structure=None, grouped=None) -> list[ca.Function]:
    """[kP, kN, kF, kL, kP5, kW] (see the module text), outputs dense so that C can index
    them; kP5 None below QUINTIC_UNKNOWNS unknowns; kW the scalars of both predictions
    (v0, v1, c of `cubic_weights`, then, with kP5, use, w1, w2, e0, e1, e2 of
    `quintic_weights`), for the C loop, which forms the predictions from them (kP and kP5 are the virtual machine's).
    `structure` (the `Structure` whose blocks these are, built from `sym` if not given)
    gives the groups' lengths.

    kP predicts the next pose by Hermite's cubic through the last two solved poses (q, T =
    dq/du, u each, newest first), kP5 by the quintic through the last three where the steps
    are even enough (kincas/core/prediction.py). Error O(h^4), O(h^6), on a straight sweep:
    on a dense sweep the prediction is converged to STEP and the pose costs kF alone (no
    kN); 40 chained four-bars that are not parallelograms (benchmarks/cases.py `chain`) need
    no Newton step at most poses from 360 poses a sixth of a turn on with kP5, where kP needs
    one at every pose."""
    nq, nu = sym.nq, sym.nu
    solve = lambda A, b: block_solve(A, b, blocks)
    q, qp, J0 = ca.SX.sym("q", nq), ca.SX.sym("qp", nq), ca.SX.sym("J0", diagonal_size(blocks))
    T0, u0, u = ca.SX.sym("T0", nq, nu), ca.SX.sym("u0", nu), ca.SX.sym("u", nu)
    T1, u1, q1 = ca.SX.sym("T1", nq, nu), ca.SX.sym("u1", nu), ca.SX.sym("q1", nq)
    T2, u2, q2 = ca.SX.sym("T2", nq, nu), ca.SX.sym("u2", nu), ca.SX.sym("q2", nq)
    p, L, ud, udd = ca.SX.sym("p", sym.np), ca.SX.sym("L"), ca.SX.sym("ud", nu), ca.SX.sym("udd", nu)
    # the reported quantities take q' = (dq/du) u' from the tangent kF computes anyway: one
    # linear solve through the chain fewer per pose. Not with a sensitivity d(Q)/d(p): it
    # differentiates Q with q' written in (q, u, p), which a q' given as input is not.
    tangent = not any(parse_quantity(n)[0] == "sens" for n in report)
    qf = sym.quantity_function(list(report), lsolve=lambda b: block_solve(sym.Jq, b, blocks),
                               velocity=tangent) if report else None
    given = (lambda a, qd: qf(*a, qd)) if tangent else (lambda a, qd: qf(*a))
    d, o = ca.densify, {"cse": True}  # cse: one sin and cos per angle, shared by everything
    kL = (structure or Structure(sym)).length_function()
    Lb = ca.SX.sym("Lb", len(blocks))  # each group's length
    is_length = ca.DM(sym.is_length.astype(float))
    Lq, Lg = group_scales(Lb, blocks, sym.nq, sym.ng)
    D = ca.if_else(is_length, Lq, 1)  # the scale of each unknown: its group's length or 1
    kP = ca.Function("kP", [q, T0, u0, u, T1, u1, q1], [d(cubic(q, T0, u0, u, T1, u1, q1))], o)
    kP5 = ca.Function("kP5", [q, T0, u0, u, T1, u1, q1, T2, u2, q2, Lb],
                      [d(v) for v in quintic(q, T0, u0, u, T1, u1, q1, T2, u2, q2, D)], o) \
        if nq >= QUINTIC_UNKNOWNS else None
    # kW: the predictions' scalars, from which the C loop forms kP's (and kP5's) numbers
    # unknown by unknown in a loop of its own (the same operations in the same order:
    # prediction.py `cubic`, `quintic`) that the compiler vectorises, where casadi's code
    # for kP5 takes ~40 instructions an unknown (40 chained four-bars: 3k of 25k a pose);
    # the quintic's scalars only where kP5 is (they cost a four-bar more than its cubic)
    kW = ca.Function("kW", [u0, u, u1, u2], [d(ca.vertcat(*cubic_weights(u0, u, u1), *(
        quintic_weights(u0, u, u1, u2) if kP5 is not None else ())))], o)
    if not is_tall(blocks) and (grouped or (grouped is None and len(blocks) >= GROUPS_APART)):
        # one small function per kind of group, the quantities apart
        qd = ca.SX.sym("qd", nq)
        kY = ca.Function("kY", [q, u, p, ud, udd, qd], [ca.densify(given((q, u, p, ud, udd), qd))], o) if report else None
        return [kP, *GroupFunctions(sym, blocks, GROUP_RUN).kernel(kY), kL, kP5, kW]
    cs = ca.if_else(is_length, 1, reciprocal(L))  # g_q's columns to O(1): 1 (lengths), 1/L (angles)
    g, Jq, Ju = ca.Function("G", [sym.q, sym.u, sym.p], [sym.g, sym.Jq, sym.Ju])(q, u, p)
    step = solve(Jq, g)
    rs = ca.vertcat(_max_abs(g * reciprocal(Lg)), _max_abs(step * reciprocal(D)))
    T = -solve(Jq, Ju)
    y = ca.densify(given((q, u, p, ud, udd), ca.mtimes(T, ud))) if report else ca.SX(0, 1)
    tall = is_tall(blocks)
    change = block_change(J0, Jq, D, blocks, cs if tall else None)
    signs, sigma = block_measures(Jq, cs, blocks)
    kF = ca.Function("kF", [q, u, p, L, ud, udd, J0, qp, Lb],
                     [diagonal_blocks(Jq, blocks), d(T), rs, ca.vertcat(change, group_correction((q - qp) / D, blocks)),
                      ca.vertcat(signs, sigma), y, d(step), *((Jq, D) if tall else ())], o)
    if tall:
        kF = _exact_where_needed(kF, blocks)
    return [kP, ca.Function("kN", [q, u, p, Lb], [d(step), rs], o), kF, kL, kP5, kW]


def _exact_where_needed(kF, blocks) -> ca.Function:
    """kF of a tall kernel (redundant joints): its Jacobian change is the cheap bound of
    `block_change` (a tall group's exact measure solves its normal equations for all n
    columns: n^3 instructions written out, 40k of Bennett's linkage's 50k); where that bound
    is above JAC_CHANGE, the exact measure, by a numeric sparse LDL' (MX: a loop in the
    generated C, evaluated only then: a switch). Both certify that g_q keeps full column
    rank between the two poses when below 1. kF's last two outputs (g_q, the scales D) are
    for that; the function returned has the outputs of a square kernel's kF."""
    ins = [ca.MX.sym(kF.name_in(i), kF.sparsity_in(i)) for i in range(kF.n_in())]
    *outs, Jq, D = kF(*ins)
    b, J0s, Js, Ds = (ca.MX.sym(n, a.sparsity()) for n, a in
                      (("b", outs[3][0]), ("J0", ins[6]), ("J", Jq), ("D", D)))
    exact = ca.Function("kC", [b, J0s, Js, Ds], [block_change(J0s, Js, Ds, blocks)])
    change = ca.Function.conditional("kC_or_bound", [exact], ca.Function("kB", [b, J0s, Js, Ds], [b]))
    bound, corr = outs[3][0], outs[3][1]  # index 0 (the bound above JAC_CHANGE, or NaN): exact
    outs[3] = ca.vertcat(change(bound <= JAC_CHANGE, bound, ins[6], Jq, D), corr)
    return ca.Function("kF", ins, outs)


def state_function(sym, blocks) -> ca.Function:
    """kT(q, u, p) -> (g_q's diagonal blocks, dq/du dense): the kernel's state at a pose
    solved elsewhere."""
    q, u, p = ca.SX.sym("q", sym.nq), ca.SX.sym("u", sym.nu), ca.SX.sym("p", sym.np)
    Jq, Ju = ca.Function("G", [sym.q, sym.u, sym.p], [sym.Jq, sym.Ju])(q, u, p)
    return ca.Function("kT", [q, u, p], [diagonal_blocks(Jq, blocks), ca.densify(-block_solve(Jq, Ju, blocks))],
                       {"cse": True})


def vm_step(kP, kN, kF, kL, kP5, nq, nu, max_evals, skip: bool = True) -> ca.Function:
    """One pose for the virtual machine, the compiled loop's arithmetic: where the last pose
    was predicted to within STEP (`near`), kF at the prediction first, its step the last if
    negligible; else kN evaluated until its step is below KERNEL_NEAR (at most max_evals
    times; kF's step at the prediction, the same as kN's there, counts as the first), then kF.
    With `skip`, the first evaluation is a switch on `near`, each later one a switch that the
    virtual machine skips once converged, and the last kF a switch that passes the first one's
    on where it converged, so a pose costs what it costs in C (a large kernel: 40 chained
    four-bars); without, the pose is one flat SX function evaluating kF at the prediction
    (as the first Newton step where it does not converge) and kN max_evals - 1 times, q held
    once converged (a small kernel: the switch's function calls cost more than a 2x2 kN).
    info = (residual, next step, Jacobian change, correction, kN steps, converged). The
    groups' lengths Lb are an input, computed once per sweep as the compiled loop does.
    Functions written group by group are inlined (`expand`) for the virtual machine; those
    of a tall kernel (numeric linear solves, which have no SX form) stay MX, with `skip`."""
    kP, kN, kF = (_expanded(f) for f in (kP, kN, kF))
    kP5 = _expanded(kP5) if kP5 is not None else None
    skip = skip or kN.is_a("MXFunction") or kF.is_a("MXFunction")
    X = ca.MX if skip else ca.SX
    q0, J0, T0, u0 = X.sym("q0", nq), X.sym("J0", kF.size1_in(6)), X.sym("T0", nq, nu), X.sym("u0", nu)
    u, p, L, thr = X.sym("u", nu), X.sym("p", kN.size1_in(2)), X.sym("L"), X.sym("t", 5)
    Lb, near, five = X.sym("Lb", kL.size1_out(0)), X.sym("near"), X.sym("five")
    ud, udd, T1, u1 = X.sym("ud", nu), X.sym("udd", nu), X.sym("T1", nq, nu), X.sym("u1", nu)
    q1, T2, u2, q2 = X.sym("q1", nq), X.sym("T2", nq, nu), X.sym("u2", nu), X.sym("q2", nq)
    # the C loop's choice of prediction (both evaluated here: the same numbers, chosen)
    qp = kP(q0, T0, u0, u, T1, u1, q1)
    if kP5 is not None:
        qQ, missQ = kP5(q0, T0, u0, u, T1, u1, q1, T2, u2, q2, Lb)
        qp = ca.if_else(five, qQ, qp)
    converged = lambda rs: ca.logic_and(rs[0] <= thr[0], rs[1] <= thr[1])
    if skip:
        Y = ca.MX if kN.is_a("MXFunction") else ca.SX
        x, ux, px = Y.sym("q", nq), Y.sym("u", nu), Y.sym("p", kN.size1_in(2))
        Lx, t4 = Y.sym("Lb", kL.size1_out(0)), Y.sym("t4")
        dq, rs = kN(x, ux, px, Lx)
        once = ca.Function.conditional(  # index 0 (not converged): one Newton step; else stay
            "vm_newton", [ca.Function("vm_step", [x, ux, px, Lx, t4], [x - dq, rs[1] <= t4])],
            ca.Function("vm_stay", [x, ux, px, Lx, t4], [x, Y(1)]))
        # the first evaluation: kN at the prediction, or (near) kF there, whose outputs the
        # last evaluation passes on where it converged
        fin = [ca.MX.sym(f"f{i}", kF.sparsity_out(i)) for i in range(kF.n_out())]
        ins = [qp, u, p, L, ud, udd, J0, Lb, thr]
        sym_ins = [ca.MX.sym(f"i{i}", v.sparsity()) for i, v in enumerate(ins)]
        sq, su, sp, sL, sud, sudd, sJ0, sLb, st = sym_ins
        dq, rs = kN(sq, su, sp, sLb)
        zero = [ca.MX.zeros(f.sparsity()) for f in fin]
        by_newton = ca.Function("vm_first_newton", sym_ins, [sq - dq, rs[1] <= st[4], ca.MX(1), ca.MX(0), *zero])
        F = kF(sq, su, sp, sL, sud, sudd, sJ0, sq, sLb)
        c1 = ca.logic_and(F[2][0] <= st[0], F[2][1] <= st[1])
        by_final = ca.Function("vm_first_final", sym_ins,
                               [ca.if_else(c1, sq, sq - F[6]), ca.logic_or(c1, F[2][1] <= st[4]), 1 - c1, c1, *F])
        first = ca.Function.conditional("vm_first", [by_newton], by_final)
        q, done, evals, conv1, *F1 = first(near, *ins)
        for _ in range(max_evals - 1):
            evals += 1 - done
            q, conv = once(done, q, u, p, Lb, thr[4])
            done = ca.logic_or(done, conv)
        fin_ins = [q, u, p, L, ud, udd, J0, qp, Lb]
        sym_fin = [ca.MX.sym(f"j{i}", v.sparsity()) for i, v in enumerate(fin_ins)]
        last = ca.Function.conditional(  # index 0: kF at q; 1 (converged at the prediction): F1
            "vm_last", [ca.Function("vm_final", [*sym_fin, *fin], kF(*sym_fin))],
            ca.Function("vm_passed", [*sym_fin, *fin], fin))
        J, T, rs, mc, meas, y, dq = last(conv1, *fin_ins, *F1)
    else:  # every evaluation made, q held once converged
        J, T, rs, mc, meas, y, dq = kF(qp, u, p, L, ud, udd, J0, qp, Lb)  # (its step: kN's there)
        conv1 = ca.logic_and(near, converged(rs))
        q = ca.if_else(conv1, qp, qp - dq)
        done, evals = ca.logic_or(conv1, rs[1] <= thr[4]), 1 - conv1
        for _ in range(max_evals - 1):
            evals += 1 - done
            dq, rs = kN(q, u, p, Lb)
            q, done = ca.if_else(done, q, q - dq), ca.logic_or(done, rs[1] <= thr[4])
        J, T, rs, mc, meas, y, dq = kF(q, u, p, L, ud, udd, J0, qp, Lb)
    conv = converged(rs)
    q = ca.if_else(conv, q - dq, q)
    info = ca.vertcat(rs, mc, evals, conv)
    near_next = ca.logic_or(evals == 0, mc[1] <= thr[1])
    if kP5 is not None:
        miss = ca.if_else(five, missQ, mc[1])  # the cubic's error at this pose
        five_next = ca.logic_and(miss > QUINTIC_ON, miss <= QUINTIC_TRY)
    else:
        five_next = 0 * near
    return ca.Function("kS", [q0, J0, T0, u0, T1, u1, q1, T2, u2, q2, near, five, u, p, L, thr, ud, udd, Lb],
                       [q, J, T, u, T0, u0, q0, T1, u1, q1, near_next, five_next, info, y, meas])


def _expanded(f: ca.Function) -> ca.Function:
    """f as one SX function where it has one; an MX function that calls a numeric linear
    solver (a tall kernel's exact Jacobian change, `_exact_where_needed`) as it is."""
    if not f.is_a("MXFunction"):
        return f
    try:
        return f.expand()
    except RuntimeError:  # casadi: eval_sx not defined for its linear solver
        return f
