"""The compiled sweep's loop over poses (SWEEP_C), around the kernel's casadi functions
(kincas/core/kernel.py), and the sines and cosines it hands them (`loop_trig`).

A flat kernel (one SX expression, under GROUPS_APART groups) takes the sines and cosines of
its unknowns and inputs as one more input instead of computing them at every evaluation: the
loop computes the inputs' once a pose and the unknowns' at the prediction, and turns them with
each Newton step (a step of d radians: a rotation by d, its cosine and sine by their Taylor
series). A four-bar's pose evaluates kN and kF 2.3 times on average, each with 3 sines and
cosines: 6.8 of them a pose (a third of its compiled loop's instructions), 3 now. The
values agree with the unlifted functions (the virtual machine's) to rounding.

>>> import kincas
>>> from kincas.core.fast import sweeper_for
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> kN, kF, kL, kW = sweeper_for(kincas.model_of(m)).compiled_functions
>>> kN, kF, macros = loop_trig(kN, kF, libm=False)
>>> macros["KS_NTQ"], macros["KS_NTU"], kN.n_in(), kF.n_in()  # two angles, the crank's
(2, 1, 5, 10)
"""
from __future__ import annotations

from .c_library import libm_trig
from .lifting import lift_trig_pairs, trig_pairs


def loop_trig(kN, kF, libm: bool | None = None):
    """(kN, kF, macros): a flat kernel's kN and kF with the sines and cosines of their
    unknowns q (input 0) and inputs u (input 1) as a last input t (`lift_trig_pairs`, one
    layout for both), and SWEEP_C's macros that say which (KS_NTQ and KS_TRIG_Q_AT the
    unknowns, KS_NTU and KS_TRIG_U_AT the inputs). A kernel written group by group or with
    numeric solves (MX: its own calls pass sines and cosines on, kincas/core/group_kernel.py),
    or one without a sine, as it is, with no macros (SWEEP_C's defaults: none); so too every
    kernel where compiled code takes libm's sines (KINCAS_LIBM_TRIG: `libm_trig`), whose loop
    then computes the virtual machine's numbers bit for bit (`libm`: whether, None: as set)."""
    if (libm_trig() if libm is None else libm) or kN.is_a("MXFunction") or kF.is_a("MXFunction"):
        return kN, kF, {}
    pairs = trig_pairs([kN, kF], (0, 1))
    if not pairs:
        return kN, kF, {}
    at = lambda which: [e for i, e in pairs if i == which]
    c = lambda v: "{" + ", ".join(map(str, v or [0])) + "}"
    return (lift_trig_pairs(kN, pairs, "kN"), lift_trig_pairs(kF, pairs, "kF"),
            {"KS_NTQ": len(at(0)), "KS_NTU": len(at(1)), "KS_TRIG_Q_AT": c(at(0)), "KS_TRIG_U_AT": c(at(1))})


# --- the sines and cosines a flat kernel takes (C; KS_NTQ ... from `loop_trig`'s macros) ---

TRIG_C = r"""
/* The sines and cosines the kernel takes as its last input where it has one (a flat kernel:
   `loop_trig`): tq = [sin, cos] of the unknowns KS_TRIG_Q, then of the inputs KS_TRIG_U. The
   inputs' once a pose, the unknowns' at the prediction; a Newton step of d radians then turns
   each pair by d, s' = s + (s (cos d - 1) - c sin d), c' = c + (c (cos d - 1) + s sin d), with
   cos d - 1 and sin d by their Taylor series (for |d| <= KS_TURN the next terms, d^6/720 and
   d^7/5040, are below 1e-20): a few operations where a sine and cosine cost ~80 instructions,
   right to rounding as the function itself is; a longer step takes them afresh. At the
   prediction they are on every pose's path: fdlibm's inline there whatever the kernel's trig
   (`kincas_sincos_inline`, one site: a four-bar's warm 360-pose call 114 -> 107 us); a long
   step's, rarer, the kernel's form (`kincas_sincos`). */
#ifndef KS_NTQ
#define KS_NTQ 0
#define KS_NTU 0
#define KS_TRIG_Q_AT {0}
#define KS_TRIG_U_AT {0}
#endif
#define KS_NT (KS_NTQ + KS_NTU)
#define KS_TURN 1e-3
#if KS_NT > 0
#define KS_ARG_T(i) (arg[i] = tq)
#else
#define KS_ARG_T(i) ((void) 0)
#endif
static const int KS_TRIG_Q[KS_NTQ > 0 ? KS_NTQ : 1] = KS_TRIG_Q_AT;
static const int KS_TRIG_U[KS_NTU > 0 ? KS_NTU : 1] = KS_TRIG_U_AT;
/* the unknowns' at the prediction q and the inputs' at u, all at one site of the inline form */
static inline void ks_trig(const casadi_real* q, const casadi_real* u, casadi_real* t) {
  int n;
  for (n = 0; n < KS_NT; ++n)
    kincas_sincos_inline(n < KS_NTQ ? q[KS_TRIG_Q[n]] : u[KS_TRIG_U[n - KS_NTQ]], t + 2*n, t + 2*n + 1);
}
/* q <- q - dq, and the unknowns' sines and cosines in t with it: where there are some, a
   function of its own (inline at its three uses it made Jansen's leg's loop 11.3 kB of code
   instead of 6.5); else the plain step, inline */
#if KS_NTQ > 0 && (defined(__GNUC__) || defined(__clang__))
#define KS_STEP_FN static __attribute__((noinline)) void
#else
#define KS_STEP_FN static inline void
#endif
KS_STEP_FN ks_step(casadi_real* q, const casadi_real* dq, casadi_real* t) {
  int n, i;
  for (n = 0; n < KS_NTQ; ++n) {
    const int j = KS_TRIG_Q[n];
    const casadi_real qn = q[j] - dq[j], d = q[j] - qn;  /* the step as q takes it */
    if (fabs(d) <= KS_TURN) {
      const casadi_real d2 = d*d, sd = d - d*d2*(1.0/6 - d2*(1.0/120)), cm = -d2*(0.5 - d2*(1.0/24));
      const casadi_real s = t[2*n], c = t[2*n + 1];
      t[2*n] = s + (s*cm - c*sd);
      t[2*n + 1] = c + (c*cm + s*sd);
    } else {
      kincas_sincos(qn, t + 2*n, t + 2*n + 1);  /* (also NaN) */
    }
  }
  for (i = 0; i < NQ; ++i) q[i] -= dq[i];
}
"""

# --- the C loop around them (NQ, NU, NO, NM, NJ: sizes, NM - 1 groups; state s = q, g_q's
# diagonal blocks, T = dq/du, u at the last pose, then T, u and q at the one before, then at
# the one before that, then `near` (1: try kF at the prediction first) and `five` (1: predict
# by kP5, else kP); matrices column-major; L the whole mechanism's length, for the singular
# measures' column scale; QUINTIC_ON, QUINTIC_TRY: kincas/core/tolerances.py) ---

SWEEP_C = TRIG_C + """
static const int KS_LENGTH_OF[NQ > 0 ? NQ : 1] = KS_LENGTHS;  /* unknown i: -1 an angle, else its group (Lb) */
#define KS_T0 (NQ + NJ)  /* T, u at the last pose (then q1, T1, u1, ... as state_parts) */
#define KS_T1 (KS_T0 + NQ*NU + NU)
#define KS_Q1 (KS_T1 + NQ*NU + NU)
#define KS_T2 (KS_Q1 + NQ)
#define KS_Q2 (KS_T2 + NQ*NU + NU)
#define KS_NEAR (KS_Q2 + NQ)
#define KS_FIVE (KS_NEAR + 1)
/* row i of T (NQ x NU, column-major) times v, summed input by input (prediction.py `_times`) */
static inline casadi_real ks_times(const casadi_real* T, const casadi_real* v, casadi_int i) {
  casadi_real t = T[i]*v[0];
  casadi_int j;
  for (j = 1; j < NU; ++j) t = t + T[i + j*NQ]*v[j];
  return t;
}
int kincas_sweep(casadi_int n, const casadi_real* U, const casadi_real* p, const casadi_real* L,
                 const casadi_real* thr, casadi_int max_evals, casadi_real* s, casadi_real* Q,
                 casadi_real* info, casadi_int ld, const casadi_real* Ud, casadi_int sud,
                 const casadi_real* Udd, casadi_int sudd, casadi_real* vals, casadi_real* meas) {
  const casadi_real* arg[SZ_ARG]; casadi_real* res[SZ_RES]; casadi_int iw[SZ_IW]; casadi_real w[SZ_W];
  casadi_real qp[NQ], dq[NQ], miss = 0, rs[2], rf[2], mc[2], ms[NM], y[NO > 0 ? NO : 1];
  casadi_real tq[KS_NT > 0 ? 2*KS_NT : 1];  /* the kernel's sines and cosines (KS_NT pairs) */
  /* the state's poses in slots, (q, T, u) each: the last three (P0, P1, P2) and the next (PS),
     g_q's blocks at the last and the next (J0, JS); a pose accepted turns the slots round
     instead of copying them (written back to s in its layout when the loop ends) */
  casadi_real ring[4][NQ + NQ*NU + NU], jring[2][NJ > 0 ? NJ : 1];
  casadi_real *P0 = ring[0], *P1 = ring[1], *P2 = ring[2], *PS = ring[3], *J0 = jring[0], *JS = jring[1], *t_;
  casadi_real *q = PS;
  casadi_real W[5*NU + 4];  /* the predictions' scalars (kW) */
  casadi_real Lb[NM > 1 ? NM - 1 : 1];  /* each group's length, from the parameters */
  casadi_int k, i, it;
  int near = s[KS_NEAR] != 0;  /* the last pose was predicted well: try kF at the prediction first */
  int five = s[KS_FIVE] != 0;  /* predict by the quintic (kP5), else the cubic (kP) */
  if (n > 0) {
    arg[0] = U; arg[1] = p; res[0] = Lb;
    if (kL(arg, res, iw, w, 0)) return 0;
  }
  for (i = 0; i < NQ; ++i) { P0[i] = s[i]; P1[i] = s[KS_Q1 + i]; P2[i] = s[KS_Q2 + i]; }
  for (i = 0; i < NQ*NU + NU; ++i) { P0[NQ + i] = s[KS_T0 + i]; P1[NQ + i] = s[KS_T1 + i]; P2[NQ + i] = s[KS_T2 + i]; }
  for (i = 0; i < NJ; ++i) J0[i] = s[NQ + i];
  for (k = 0; k < n; ++k) {
    const casadi_real* u = U + k*NU;
    int conv = 0;
    /* the prediction (kincas/core/prediction.py `cubic`, `quintic`): its scalars by kW, then
       each unknown by the same operations in the same order as kP and kP5 */
    arg[0] = P0 + NQ + NQ*NU; arg[1] = u; arg[2] = P1 + NQ + NQ*NU; arg[3] = P2 + NQ + NQ*NU; res[0] = W;
    if (kW(arg, res, iw, w, 0)) break;
    {
      const casadi_real *q0 = P0, *T0 = P0 + NQ, *q1 = P1, *T1 = P1 + NQ, *q2 = P2, *T2 = P2 + NQ;
      const casadi_real *v0 = W, *v1 = W + NU, c = W[2*NU], *e0 = W + 2*NU + 4, *e1 = e0 + NU, *e2 = e1 + NU;
#define KS_CUBIC(i) (((q0[i] + ks_times(T0, v0, i)) + ks_times(T1, v1, i)) - c*(q0[i] - q1[i]))  /* `cubic` */
      miss = 0;
      if (HAVE_KP5 && five && W[2*NU + 1] != 0) {  /* the quintic applies: cubic and correction */
        const casadi_real w1 = W[2*NU + 2], w2 = W[2*NU + 3];
        casadi_real m0 = 0, m1 = 0, m2 = 0, m3 = 0;
        for (i = 0; i < NQ; ++i) {  /* (no branch, no reduction: the compiler vectorises it) */
          dq[i] = (((w1*(q1[i] - q0[i]) + w2*(q2[i] - q0[i])) + ks_times(T0, e0, i)) + ks_times(T1, e1, i))
                  + ks_times(T2, e2, i);
          qp[i] = KS_CUBIC(i) + dq[i];
        }
        /* the cubic's error as the quintic sees it, max |p5 - p3| / scale: kP5's miss (NaNs
           skipped as its fmax skips them; where all are NaN, 0 here and NaN there: either way
           not above QUINTIC_ON, its one use), in four running maxima (one chain of compares
           would wait on each) */
        for (i = 0; i < NQ; ++i) {
          casadi_real a = fabs(dq[i]);
          if (KS_LENGTHS_ANY && KS_LENGTH_OF[i] >= 0) a = a / Lb[KS_LENGTH_OF[i]];
          dq[i] = a;
        }
        for (i = 0; i + 3 < NQ; i += 4) {
          m0 = dq[i] > m0 ? dq[i] : m0; m1 = dq[i + 1] > m1 ? dq[i + 1] : m1;
          m2 = dq[i + 2] > m2 ? dq[i + 2] : m2; m3 = dq[i + 3] > m3 ? dq[i + 3] : m3;
        }
        for (; i < NQ; ++i) m0 = dq[i] > m0 ? dq[i] : m0;
        m0 = m1 > m0 ? m1 : m0; m2 = m3 > m2 ? m3 : m2; miss = m2 > m0 ? m2 : m0;
      } else {
        for (i = 0; i < NQ; ++i) qp[i] = KS_CUBIC(i);
      }
    }
    for (i = 0; i < NQ; ++i) q[i] = qp[i];
    ks_trig(q, u, tq);  /* the sines and cosines at the prediction; moved with each step below */
    if (near) {  /* kF at the prediction first: where its (next) step is negligible, no kN */
      arg[0] = q; arg[1] = u; arg[2] = p; arg[3] = L; arg[4] = Ud + k*sud; arg[5] = Udd + k*sudd;
      arg[6] = J0; arg[7] = qp; arg[8] = Lb; KS_ARG_T(9);
      res[0] = JS; res[1] = PS + NQ; res[2] = rf; res[3] = mc; res[4] = ms; res[5] = y; res[6] = dq;
      if (kF(arg, res, iw, w, 0)) break;
      if (rf[0] <= thr[0] && rf[1] <= thr[1]) { it = 0; goto evaluated; }
      /* else kF's step is Newton's first (kN's there is the same): applied, and counted */
      ks_step(q, dq, tq);
      it = 1;
    } else it = 0;
    if (it == 0 || !(rf[1] <= thr[4] || it >= max_evals)) {
      for (++it; ; ++it) {  /* Newton until the step just applied makes the next negligible */
        arg[0] = q; arg[1] = u; arg[2] = p; arg[3] = Lb; KS_ARG_T(4); res[0] = dq; res[1] = rs;
        if (kN(arg, res, iw, w, 0)) break;
        ks_step(q, dq, tq);
        if (rs[1] <= thr[4] || it >= max_evals) break;
      }
    }
    arg[0] = q; arg[1] = u; arg[2] = p; arg[3] = L; arg[4] = Ud + k*sud; arg[5] = Udd + k*sudd;
    arg[6] = J0; arg[7] = qp; arg[8] = Lb; KS_ARG_T(9);
    res[0] = JS; res[1] = PS + NQ; res[2] = rf; res[3] = mc; res[4] = ms; res[5] = y; res[6] = dq;
    if (kF(arg, res, iw, w, 0)) break;
  evaluated:
    conv = rf[0] <= thr[0] && rf[1] <= thr[1];  /* the next step is negligible: apply it */
    if (conv) for (i = 0; i < NQ; ++i) q[i] -= dq[i];
    for (i = 0; i < NQ; ++i) Q[k*NQ + i] = q[i];
    for (i = 0; i < NO; ++i) vals[i*ld + k] = y[i];  /* one contiguous row per quantity */
    if (meas) for (i = 0; i < NM; ++i) meas[k*NM + i] = ms[i];  /* one pose's measures together */
    info[k] = rf[0]; info[ld + k] = rf[1]; info[2*ld + k] = mc[0]; info[3*ld + k] = mc[1];
    info[4*ld + k] = (casadi_real) it;
    if (!(conv && mc[0] <= thr[2] && mc[1] <= thr[3])) break;
    near = it == 0 || mc[1] <= thr[1];
    if (!five) miss = mc[1];  /* the cubic's error at this pose (kincas/core/prediction.py) */
    five = HAVE_KP5 && miss > QUINTIC_ON && miss <= QUINTIC_TRY;
    s[KS_NEAR] = near; s[KS_FIVE] = five;  /* kept with the state: a sweep in several calls is one */
    for (i = 0; i < NU; ++i) PS[NQ + NQ*NU + i] = u[i];
    t_ = P2; P2 = P1; P1 = P0; P0 = PS; PS = q = t_;  /* this pose is the last now */
    t_ = J0; J0 = JS; JS = t_;
  }
  for (i = 0; i < NQ; ++i) { s[i] = P0[i]; s[KS_Q1 + i] = P1[i]; s[KS_Q2 + i] = P2[i]; }
  for (i = 0; i < NQ*NU + NU; ++i) { s[KS_T0 + i] = P0[NQ + i]; s[KS_T1 + i] = P1[NQ + i]; s[KS_T2 + i] = P2[NQ + i]; }
  for (i = 0; i < NJ; ++i) s[NQ + i] = J0[i];
  return (int) k;
}
"""
