"""The index-reduced DAE alternative (issue [18]: "say which formulation you chose and why, with
measurements"), measured on the engine of examples/simulate_engine.toml against kincas.simulate.

    python benchmarks/bench_simulate_dae.py DURATION RELTOL      # e.g. 0.2 1e-10, or 2 1e-8

The engine written by hand as the textbook multiplier DAE (nothing of kincas): coordinates
z = (crank angle, rod angle, piston x), kinetic energy T(z, z') with the mass matrix its
Hessian in z', constraints g(z) = 0 (B = A + L e on the x axis), M z'' + c - Q - g_z' lam = 0;
CasADi's dae_reduce_index (Pantelides; index 3 -> 1), dae_map_semi_expl, consistent initial
values by dae_init_gen (IPOPT), IDAS. Prints its cost, its constraint drift, its difference
from benchmarks/bench_simulate.py's hand-written reduced-inertia solve, and kincas's.
Not a test: nothing here asserts. Numbers in docs/simulate.md.
"""
import math, time, numpy as np, casadi as ca
R, L, A_CG, M_ROD, J_ROD, M_PISTON, J_CRANK = 50, 180, 60, 0.0012, 4, 0.0008, 20 + 300
TM, W0 = 53250.0, 18000.0
ANG = [0, 15, 30, 60, 90, 120, 150, 180, 360, 540, 600, 660, 690, 720]
GAS = [8000, 25000, 20000, 10000, 5000, 2500, 1200, 0, 0, 0, 300, 1500, 4000, 8000]
S = ca.SX
z = S.sym("z", 3); v = S.sym("v", 3); dz = S.sym("dz", 3); dv = S.sym("dv", 3); lam = S.sym("lam", 2); t = S.sym("t")
th, ps, x = z[0], z[1], z[2]
A = ca.vertcat(R * ca.cos(th), R * ca.sin(th)); e = ca.vertcat(ca.cos(ps), ca.sin(ps))
g = (A + L * e - ca.vertcat(x, 0))[[1, 0]]  # the row without x first: CasADi 3.8.2's structural detection fails in the other order
G = A + A_CG * e
Gd = ca.jtimes(G, z, v)
T = 0.5 * J_CRANK * v[0] ** 2 + 0.5 * M_ROD * ca.dot(Gd, Gd) + 0.5 * J_ROD * v[1] ** 2 + 0.5 * M_PISTON * v[2] ** 2
Mz = ca.hessian(T, v)[0]
c = ca.jtimes(ca.gradient(T, v), z, v) - ca.gradient(T, z)
# interp as in kincas: linear, periodic by the user's %
deg = th * 180 / math.pi
phase = deg - 720 * ca.floor(deg / 720)
gas = lambda s: ca.pw_lin(s, ca.DM(ANG), ca.DM(GAS))
gasv = gas(phase)
Q = ca.vertcat(-TM * (v[0] * 180 / math.pi) / W0, 0, -gasv)
Gz = ca.jacobian(g, z)
res = ca.vertcat(dz - v, ca.mtimes(Mz, dv) + c - Q - ca.mtimes(Gz.T, lam), g)
dae = {"x_impl": ca.vertcat(z, v), "dx_impl": ca.vertcat(dz, dv), "z": lam, "alg": res, "t": t}
t0 = time.perf_counter()
red, stats = ca.dae_reduce_index(dae, {})
semi, to_orig, phi = ca.dae_map_semi_expl(dae, red)
print("reduce", time.perf_counter() - t0, stats, {k: semi[k].shape for k in semi})
print(semi.keys())
w0 = math.radians(18000)
xi = [0.0, 0.0, R + L, w0, -R / L * w0, 0.0]
init = ca.dae_init_gen(dae, red, "ipopt", {"x_impl": ca.DM([-1, 1, 1, -1, 1, 1])}, {"ipopt.print_level": 0, "print_time": False, "ipopt.tol": 1e-14})
t0 = time.perf_counter()
out = init(x_impl=xi, dx_impl=[0] * 6, z=[0, 0], p=[], t=0)
print("init", time.perf_counter() - t0)
x0, z0 = out["x0"], out["z0"]
print("I at start", np.max(np.abs(np.asarray(phi(x0, z0, [], 0)))))
import sys
DUR = float(sys.argv[1]) if len(sys.argv) > 1 else 0.2  # run.py calls it bare: the short case
grid = list(np.linspace(0, DUR, int(1000 * DUR) + 1)[1:])
for tol in (float(sys.argv[2]) if len(sys.argv) > 2 else 1e-10,):
    F = ca.integrator("dae", "idas", semi, 0, grid, {"reltol": tol, "abstol": tol * 1e-2 * 1e3, "max_num_steps": 100000, "show_eval_warnings": False})
    times = []
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        r = F(x0=x0, z0=z0)
        times.append((time.perf_counter() - t0, time.process_time() - c0))
    print("idas", tol, min(times))
    orig = to_orig(xf=r["xf"], zf=r["zf"])
    xs = np.asarray(orig["x_impl"])
    inv = np.asarray(phi(r["xf"], r["zf"], [], 0))
    D_THETA = np.vstack([xs[0], xs[3]])
    print("invariants drift max", np.max(np.abs(inv[:2])), "final theta", xs[0, -1], "w", xs[3, -1])
    th, ps_, xx = xs[0], xs[1], xs[2]
    print("g residual max (mm)", np.max(np.abs(np.vstack([R*np.sin(th)+L*np.sin(ps_), R*np.cos(th)+L*np.cos(ps_)-xx]))))
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parent))
import bench_simulate as B
times_ = np.linspace(0, DUR, int(1000 * DUR) + 1)
thh, wh = B.hand_written(times_)
d = D_THETA
print("DAE vs hand-written: angle", np.max(np.abs(d[0] - thh[1:])), "speed rel", np.max(np.abs(d[1] - wh[1:])) / np.max(np.abs(wh)))
from kincas.cli.scene import load
from kincas.cli.simulate import arguments_of
from kincas.analysis.simulate import simulate
sc = load(str(__import__("pathlib").Path(__file__).resolve().parent.parent / "examples" / "simulate_engine.toml")); kw = arguments_of(sc)
r = simulate(sc.mechanism, DUR, len(times_), **kw)
ts = []
for _ in range(3):
    t0, c0 = time.perf_counter(), time.process_time(); r = simulate(sc.mechanism, DUR, len(times_), **kw); ts.append((time.perf_counter() - t0, time.process_time() - c0))
print("kincas", min(ts), "angle", np.max(np.abs(r.inputs["crank.angle"] - thh)), "speed rel", np.max(np.abs(r.rates["crank.angle"] - wh)) / np.max(np.abs(wh)))
