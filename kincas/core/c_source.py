"""Rewrites of casadi's generated C that keep every value and cost fewer instructions.

casadi writes each function so that any caller may pass a null pointer for an input (read as
zeros) or an output (not wanted): every element read is `arg[i]? arg[i][k] : 0` and every
element written `if (res[i]!=0) res[i][k]=...`, a test and a branch per number. kincas's C
loops (kincas/core/kernel.py, designs_kernel.py, compiled.py) pass a pointer for every input
and output; casadi's own calls between its functions pass null only where the call site says
so. `trust_pointers` drops the tests that no call can need (on 40 chained four-bars, 7 % of
a pose's instructions). The other two rewrites: each angle's sine and cosine in one call
(`pair_sincos`), max and min inline (`inline_minmax`).

>>> src = '''/* f:(i0,i1)->(o0) */
... static int casadi_f0(const casadi_real** arg, casadi_real** res, casadi_int* iw, casadi_real* w, int mem) {
...   a0=arg[0]? arg[0][0] : 0;
...   if (res[0]!=0) res[0][0]=a0;
...   return 0;
... }'''
>>> print(trust_pointers(src).splitlines()[2:4])
['  a0=arg[0][0];', '  res[0][0]=a0;']
"""
from __future__ import annotations

import re

# Sine and cosine of one angle together, as fdlibm computes them (FreeBSD msun: e_rem_pio2.c's
# medium case, k_sin.c, k_cos.c): x reduced by Cody and Waite's three-part pi/2 to y0 + y1,
# |y0| <= pi/4, then the kernels' minimax polynomials, each result within 1 ulp, as glibc's
# (tests/test_c_source.py checks it against 40-digit mpmath). glibc's sincos takes a more
# exact path and sets and restores the rounding mode at every call: alone, in a loop, 19 ns a
# call against fdlibm's 8 (inline or a call alike). Inline (Library's trig "inline"): 40
# chained four-bars 25.0k -> 22.4k instructions a pose; compiling takes longer (gcc -O3, CPU:
# 40 chained four-bars' 1.3 -> 2.3 s, Jansen's leg 0.63 -> 0.78 s). As one function that each
# use calls (KINCAS_TRIG_CALL, trig "call"): compiling costs what libm's calls cost (Jansen's
# leg 0.67 s, a four-bar 0.40 s as with libm), and a warm 360-pose sweep's compiled pass
# takes 60 us instead of 69 on a four-bar, 143 instead of 167 on Jansen's leg (inline: 62,
# 141). Beyond |x| = 2^20 pi/2, infinities and NaNs: libm's. The virtual machine keeps
# casadi's sin and cos (libm's), so compiled and virtual machine sweeps agree to rounding, not
# bit for bit; KINCAS_LIBM_TRIG=1 (`libm_trig`, trig "libm") compiles libm's instead, which
# the tests that hold the C loop to the virtual machine bit for bit use. The compiled sweep's
# loop computes a flat kernel's sines and cosines itself, at one site, by kincas_sincos_inline:
# fdlibm's inline whatever the trig (kincas/core/sweep_loop.py TRIG_C).
SINCOS_C = """#ifdef __GLIBC__
#define kincas_libm_sincos(x, s, c) sincos(x, s, c)
#else
#define kincas_libm_sincos(x, s, c) (*(s) = sin(x), *(c) = cos(x))
#endif
#ifdef KINCAS_LIBM_TRIG
#define kincas_sincos(x, s, c) kincas_libm_sincos(x, s, c)
#define kincas_sincos_inline(x, s, c) kincas_libm_sincos(x, s, c)
#define kincas_sin(x) sin(x)
#define kincas_cos(x) cos(x)
#else
#if defined(KINCAS_TRIG_CALL) && (defined(__GNUC__) || defined(__clang__))
#define KINCAS_INLINE static __attribute__((noinline))
#elif defined(__GNUC__) || defined(__clang__)
#define KINCAS_INLINE static inline __attribute__((always_inline))
#else
#define KINCAS_INLINE static inline
#endif
#if defined(__GNUC__) || defined(__clang__)
#define KINCAS_ALWAYS_INLINE static inline __attribute__((always_inline))
#else
#define KINCAS_ALWAYS_INLINE static inline
#endif
/*
 * ====================================================
 * Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
 *
 * Developed at SunPro, a Sun Microsystems, Inc. business.
 * Permission to use, copy, modify, and distribute this
 * software is freely granted, provided that this notice
 * is preserved.
 * ====================================================
 * (fdlibm's __ieee754_rem_pio2 medium case, __kernel_sin and __kernel_cos, as in FreeBSD's msun.)
 */
static inline double kincas_ksin(double x, double y, int iy) {
  const double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
    S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
    S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  double z = x*x, w = z*z, r = S2 + z*(S3 + z*S4) + z*w*(S5 + z*S6), v = z*x;
  if (iy == 0) return x + v*(S1 + z*r);
  return x - ((z*(0.5*y - v*r) - y) - v*S1);
}
static inline double kincas_kcos(double x, double y) {
  const double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
    C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
    C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  double z = x*x, w = z*z, r = z*(C1 + z*(C2 + z*C3)) + w*w*(C4 + z*(C5 + z*C6));
  double hz = 0.5*z;
  w = 1.0 - hz;
  return w + (((1.0 - w) - hz) + (z*r - x*y));
}
static inline uint32_t kincas_high(double x) { uint64_t b; memcpy(&b, &x, 8); return (uint32_t) (b >> 32); }
KINCAS_ALWAYS_INLINE void kincas_sincos_inline(double x, double* s, double* c) {
  const double invpio2 = 6.36619772367581382433e-01, pio2_1 = 1.57079632673412561417e+00,
    pio2_1t = 6.07710050650619224932e-11, pio2_2 = 6.07710050630396597660e-11,
    pio2_2t = 2.02226624879595063154e-21, pio2_3 = 2.02226624871116645580e-21,
    pio2_3t = 8.47842766036889956997e-32, shift = 6755399441055744.0;  /* 1.5 * 2^52 */
  uint32_t ix = kincas_high(x) & 0x7fffffff;
  double fn, r, w, t, y0, y1, sn, cs;
  int32_t j, i;
  if (ix < 0x3e400000) { *s = x; *c = 1.0; return; }  /* |x| < 2^-27: x (and -0 stays -0), 1 */
  if (ix <= 0x3fe921fb) { *s = kincas_ksin(x, 0.0, 0); *c = kincas_kcos(x, 0.0); return; }  /* |x| <= pi/4 */
  if (ix > 0x413921fb) { kincas_libm_sincos(x, s, c); return; }  /* |x| > 2^20 pi/2, inf, NaN: libm's */
  fn = (x*invpio2 + shift) - shift;  /* x / (pi/2) to the nearest integer */
  r = x - fn*pio2_1;
  w = fn*pio2_1t;  /* first round, good to 85 bits */
  y0 = r - w;
  j = (int32_t) (ix >> 20);
  i = j - (int32_t) ((kincas_high(y0) >> 20) & 0x7ff);
  if (i > 16) {  /* second round, good to 118 bits */
    t = r; w = fn*pio2_2; r = t - w; w = fn*pio2_2t - ((t - r) - w); y0 = r - w;
    i = j - (int32_t) ((kincas_high(y0) >> 20) & 0x7ff);
    if (i > 49) { t = r; w = fn*pio2_3; r = t - w; w = fn*pio2_3t - ((t - r) - w); y0 = r - w; }
  }
  y1 = (r - y0) - w;
  sn = kincas_ksin(y0, y1, 1); cs = kincas_kcos(y0, y1);
  switch (((int) fn) & 3) {
    case 0: *s = sn; *c = cs; break;
    case 1: *s = cs; *c = -sn; break;
    case 2: *s = -sn; *c = -cs; break;
    default: *s = -cs; *c = sn;
  }
}
/* each use of the kernel's own code calls this one (KINCAS_TRIG_CALL) or has it inline; the
   compiled loop's few sites (kincas/core/sweep_loop.py) have kincas_sincos_inline either way */
KINCAS_INLINE void kincas_sincos(double x, double* s, double* c) { kincas_sincos_inline(x, s, c); }
static inline double kincas_sin(double x) { double s, c; kincas_sincos(x, &s, &c); return s; }
static inline double kincas_cos(double x) { double s, c; kincas_sincos(x, &s, &c); return c; }
#endif
"""
_PRELUDE = """#define _GNU_SOURCE
#include <math.h>
#include <stdint.h>
#include <string.h>
""" + SINCOS_C + """
/* C99's fmax and fmin (a NaN argument gives the other one), written out so that they stay
   inline: libm's are calls, and every call spills the live registers. One condition, not
   nested ones: y is taken unless it is NaN or x beats it (x NaN: y, since NaN > y is false),
   which gcc compiles without branches (nested tests: a branch each, and 40 chained four-bars
   ran a fifth slower) */
static inline double kincas_fmax(double x, double y) { return (y != y || x > y) ? x : y; }
static inline double kincas_fmin(double x, double y) { return (y != y || x < y) ? x : y; }
"""
_TRIG = re.compile(r"^(\s*)(a\w+)=(sin|cos)\((a\w+)\);$")


def pair_sincos(source: str) -> str:
    r"""Casadi's generated `x=sin(a); ... y=cos(a);` as one call of `kincas_sincos` (SINCOS_C),
    a sine or cosine alone as `kincas_sin` / `kincas_cos` (the same arithmetic): each
    angle's sine and cosine cost one call. Most of a sweep's time is
    this trigonometry, and once the casadi functions are inlined into the C loop the
    compiler stops pairing them itself. A pair is joined only within one block and while
    `a` is not reassigned between; anything else is left as it is.

    >>> print(pair_sincos("  a1=sin(a0);\n  a2=(a1*a0);\n  a3=cos(a0);\n  a4=cos(a2);"))
      casadi_real kt0; kincas_sincos(a0, &a1, &kt0);
      a2=(a1*a0);
      a3=kt0;
      a4=kincas_cos(a2);
    """
    lines, n = source.split("\n"), 0
    for i, line in enumerate(lines):
        m = _TRIG.match(line)
        if not m or m[2] == m[4]:  # x=sin(x): the angle is overwritten here
            continue
        indent, target, f, a = m.groups()
        for j in range(i + 1, len(lines)):
            mj = _TRIG.match(lines[j])
            if mj and mj[4] == a and mj[3] != f:
                s, c = (target, f"kt{n}") if f == "sin" else (f"kt{n}", target)
                lines[i] = f"{indent}casadi_real kt{n}; kincas_sincos({a}, &{s}, &{c});"
                lines[j] = f"{mj[1]}{mj[2]}=kt{n};"
                n += 1
                break
            if "{" in lines[j] or "}" in lines[j] or re.match(rf"^\s*{a}=", lines[j]):
                break
    for i, line in enumerate(lines):  # a sine or cosine alone: the same function's
        m = _TRIG.match(line)
        if m:
            lines[i] = f"{m[1]}{m[2]}=kincas_{m[3]}({m[4]});"
    return "\n".join(lines)


def inline_minmax(source: str) -> str:
    """Casadi's `casadi_fmax` and `casadi_fmin` helpers calling the prelude's inline
    `kincas_fmax` / `kincas_fmin` instead of libm's `fmax` / `fmin`: the same values (C99's
    rule: a NaN argument gives the other one; only the sign of a zero maximum may differ,
    and every comparison treats -0 as 0), without a library call per maximum. The kernel's
    residual and step tests take a maximum per equation and unknown: as calls they cost a
    fifth of a chained mechanism's pose (the call clobbers every floating-point register).

    >>> inline_minmax("  return fmax(x, y);")
    '  return kincas_fmax(x, y);'
    """
    return source.replace("return fmax(x, y);", "return kincas_fmax(x, y);").replace(
        "return fmin(x, y);", "return kincas_fmin(x, y);")




# --- pointers that no call leaves null ---

_DEF = re.compile(r"^static int (casadi_f\d+)\(const casadi_real\*\* arg, casadi_real\*\* res, ")
_SIG = re.compile(r"^/\* [\w]+:\((.*)\)->\((.*)\) \*/$")
_SET = re.compile(r"^\s*(arg1|res1)\[(\d+)\]=([^;]*);$")
_WR = re.compile(r"^\s*(wr\d+) = (.*);$")
# what casadi passes for an input or output with entries: its work vectors, a scalar's address,
# an input read through `wr = arg[i] ? arg[i] : casadi_zeros` (or an offset of one)
_SAFE = re.compile(r"w\d+|\(&w\d+\)|casadi_c\d+")
_SAFE_WR = re.compile(r"arg\[(\d+)\] \? arg\[\1\] : casadi_zeros|(wr\d+)\+\d+")
_CALL = re.compile(r"\b(casadi_f\d+)\(")
_LOAD = re.compile(r"arg\[(\d+)\]\? arg\[\1\]\[(\d+)\] : 0")
_STORE = re.compile(r"if \(res\[(\d+)\]!=0\) (res\[\1\]\[\d+\]=)")
_ALL = None  # a call not understood: every pointer of the callee may be null


def _count(items: str) -> int:
    """The number of inputs (or outputs) in a casadi signature's list `i0[8],i1,i2[0]`."""
    return len(re.findall(r"\b[io]\d+\b", items))


def trust_pointers(source: str) -> str:
    """casadi's generated C without the null-pointer tests that no call can need, for a
    library whose C loop passes a pointer for every input and output of the functions it
    calls (each exported function): an input (output) of an internal function keeps its tests
    where one of its call sites passes null (0) for it, an argument of its caller (which
    may be null), or anything this reading does not recognise; a call written in any other
    way keeps all of the callee's tests. Values are unchanged: only `arg[i]? arg[i][k] : 0`
    becomes `arg[i][k]` and `if (res[i]!=0) res[i][k]=...` becomes `res[i][k]=...`."""
    lines = source.split("\n")
    bodies, sizes, i = {}, {}, 0
    while i < len(lines):
        m = _DEF.match(lines[i])
        if m:
            sig = _SIG.match(lines[i - 1]) if i else None
            j = i + 1
            while j < len(lines) and lines[j] != "}":
                j += 1
            bodies[m[1]], sizes[m[1]] = (i, j), ((_count(sig[1]), _count(sig[2])) if sig else None)
            i = j
        i += 1
    nulls = {name: (set(), set()) for name in bodies}  # per function, inputs and outputs that may be null

    def spoil(name):
        nulls[name] = _ALL

    inside = set()
    for name, (a, b) in bodies.items():
        inside.update(range(a, b + 1))
        safe_wr, given = set(), {"arg1": {}, "res1": {}}
        for line in lines[a + 1:b]:
            m = _WR.match(line)
            if m:
                w = _SAFE_WR.fullmatch(m[2])
                (safe_wr.add if w and (w[2] is None or w[2] in safe_wr) else safe_wr.discard)(m[1])
                continue
            m = _SET.match(line)
            if m:
                given[m[1]][int(m[2])] = m[3].strip()
                continue
            for c in _CALL.finditer(line):
                callee = c[1]
                if callee not in nulls or nulls[callee] is _ALL:
                    continue
                if line.strip() != f"if ({callee}(arg1, res1, iw, w, 0)) return 1;" or sizes[callee] is None:
                    spoil(callee)
                    continue
                for kind, n, bad in (("arg1", sizes[callee][0], nulls[callee][0]),
                                     ("res1", sizes[callee][1], nulls[callee][1])):
                    for k in range(n):
                        e = given[kind].get(k)
                        if e is None or not (_SAFE.fullmatch(e) or e in safe_wr):
                            bad.add(k)
            if _CALL.search(line):
                given = {"arg1": {}, "res1": {}}  # each call's pointers are set anew before it
    for i, line in enumerate(lines):  # calls outside any body: the exported functions' own
        if i not in inside:
            for c in _CALL.finditer(line):
                if c[1] in nulls and line.strip() != f"return {c[1]}(arg, res, iw, w, mem);":
                    spoil(c[1])
    for name, (a, b) in bodies.items():
        if nulls[name] is _ALL:
            continue
        bad_in, bad_out = nulls[name]
        for i in range(a + 1, b):
            lines[i] = _LOAD.sub(lambda m: m[0] if int(m[1]) in bad_in else f"arg[{m[1]}][{m[2]}]", lines[i])
            lines[i] = _STORE.sub(lambda m: m[0] if int(m[1]) in bad_out else m[2], lines[i])
    return "\n".join(lines)
