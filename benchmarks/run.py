"""Benchmarks of kincas: error against run time, speed against peers, stability, growth.

    python benchmarks/run.py            # the full run (under 10 minutes on 2 cores)
    python benchmarks/run.py --quick    # a smoke run (well under a minute once peers are installed)
    python benchmarks/run.py --only stability   # one section alone, its tables printed

Installs the peers of benchmarks/requirements.txt with pip first (`--no-install` skips that; a
peer that fails to install or import is reported, not dropped), runs the four studies of
issue [4] and the other benchmark scripts beside this file (bench_*.py), and writes
benchmarks/RESULTS.md with PNG plots next to it. Every time is a median of several runs with
its spread; setup (building, compiling, JIT) is timed apart. See benchmarks/README.md.
"""
from __future__ import annotations

import argparse
import importlib.metadata as md
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
for _p in (str(HERE), str(ROOT)):
    if _p not in sys.path:
        sys.path.insert(0, _p)

PEER_PACKAGES = {"pylinkage": "pylinkage", "numba": "numba", "python-solvespace": "python_solvespace",
                 "mechanism": "mechanism"}


# --- setup: peers installed by pip, the machine described ---


def install_requirements(skip: bool) -> dict:
    """Install each requirement on its own (one failure does not stop the others); returns
    {requirement: None | error}."""
    out = {}
    lines = [ln.split("#")[0].strip() for ln in (HERE / "requirements.txt").read_text().splitlines()]
    from peers import module_available
    for req in filter(None, lines):
        name = req.split("[")[0].split("=")[0].split(">")[0].split("<")[0].strip()
        extras = req.split("[")[1].split("]")[0].split(",") if "[" in req else []
        mods = [PEER_PACKAGES.get(name, name.replace("-", "_"))] + [PEER_PACKAGES[e] for e in extras
                                                                     if e in PEER_PACKAGES]
        missing = next(filter(None, map(module_available, mods)), None)
        if missing is None or skip:
            out[req] = missing
            continue
        p = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", req],
                           capture_output=True, text=True, timeout=900)
        out[req] = None if p.returncode == 0 else ("pip failed: " + (p.stderr.strip().splitlines() or ["?"])[-1])
    return out


def machine() -> list[str]:
    def ver(d):
        try:
            return md.version(d)
        except md.PackageNotFoundError:
            return "not installed"
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip() or "?"
    dists = ["kincas", "casadi", "numpy", "scipy", "mpmath", "pylinkage", "numba", "python-solvespace", "mechanism"]
    return [f"{platform.platform()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"kincas commit {commit}", ", ".join(f"{d} {ver(d)}" for d in dists)]


# --- the studies ---


def peers_list():
    from peers import closed_form, fsolve_peer, mechanism_peer, pylinkage_peer, solvespace_peer
    return [("closed form, numpy (vectorised)", closed_form, {}),
            ("scipy fsolve, analytic Jacobian", fsolve_peer, {"jacobian": True}),
            ("scipy fsolve, estimated Jacobian", fsolve_peer, {"jacobian": False}),
            ("pylinkage step_fast (numba)", pylinkage_peer, {}),
            ("python-solvespace", solvespace_peer, {}),
            ("mechanism (pkg)", mechanism_peer, {})]


def study_main(cfg, log) -> dict:
    """Sections 1 and 2: every kincas method and every peer on the four cases, one run."""
    import cases
    from peers import kincas_runs as kr
    from peers.closed_form import reference
    from peers.measure import errors, time_tool

    labels, _ = kr.methods()
    out = {}
    for name, make in cases.MAIN.items():
        case = make(cfg["n"])
        P, V = reference(case)
        res = out[name] = {"case": case}
        for lb in labels:
            s = kr.stride(lb)
            sub = case.with_theta(case.theta[::s])
            t = time_tool(lambda: kr.prepare_method(sub, lb), cfg["repeats"])
            res[lb] = {"kind": "kincas", "t": t, "err": errors(sub, t.run, P, V, slice(None, None, s))
                       if t.error is None else (float("nan"),) * 2, "poses": len(sub.theta)}
            log(f"  {name:13s} {lb:34s} {t.median * 1e6:10.2f} us/pose  {t.error or ''}")
        for lb, mod, kw in peers_list():
            why = mod.available() or mod.supports(case)
            if why:
                res[lb] = {"kind": "peer", "why": why}
                continue
            t = time_tool(lambda: mod.prepare(case, **kw), cfg["repeats"])
            res[lb] = {"kind": "peer", "t": t, "poses": len(case.theta),
                       "err": errors(case, t.run, P, V) if t.error is None else (float("nan"),) * 2}
            log(f"  {name:13s} {lb:34s} {t.median * 1e6:10.2f} us/pose  {t.error or ''}")
    return out


def stability_tools():
    from peers import fsolve_peer, kincas_runs as kr, mechanism_peer, pylinkage_peer, solvespace_peer
    tools = [(lb, (lambda c, lb=lb: kr.prepare_method(c, lb)), None) for lb, _ in kr.sweep_variants()[0]]
    for lb, mod, kw in peers_list()[1:]:
        if "estimated" not in lb:
            tools.append((lb, (lambda c, mod=mod, kw=kw: mod.prepare(c, **kw)), mod))
    return tools


def study_stability(cfg, log) -> dict:
    """Section 3: the stiff and extreme cases of issue [2] and the branch, singular-position
    and gap cases of issue [9] through each tool, each against its closed form (mpmath, 30
    digits) and scored against every other assembly of the chain (a branch jump)."""
    import cases
    from peers.closed_form import reference, solve_numpy
    from peers.measure import classify, time_tool

    out = {}
    for case in cases.stiff_cases(cfg["n_stiff"]) + cases.branch_cases():
        P, _ = reference(case)
        # the other assemblies in float64: a pose matches one within 1e-6 L or not at all
        others = [solve_numpy(case, steps=alt)[0] for alt in cases.alternatives(case)]
        res = out[case.name] = {"case": case}
        for lb, prep, mod in stability_tools():
            why = mod and (mod.available() or mod.supports(case))
            if why:
                res[lb] = {"why": why}
                continue
            t = time_tool(lambda: prep(case), 1)
            res[lb] = {"t": t, "c": classify(case, t.run, P, others) if t.error is None else None}
            log(f"  {case.name:18s} {lb:34s} {res[lb]['c'] or t.error}")
    return out


def study_growth(cfg, log) -> dict:
    """Section 4: per-pose cost and compile time against the number of chained four-bars."""
    import cases
    import kincas
    from peers import closed_form, fsolve_peer, kincas_runs as kr, pylinkage_peer, solvespace_peer
    from peers.measure import errors, time_tool

    tools = [(lb, (lambda c, lb=lb: kr.prepare_method(c, lb))) for lb, _ in kr.sweep_variants()[0]]
    tools += [(lb, (lambda c, mod=mod, kw=kw: mod.prepare(c, **kw))) for lb, mod, kw in peers_list()
              if mod in (closed_form, fsolve_peer, pylinkage_peer, solvespace_peer) and "estimated" not in lb
              and mod.available() is None]
    out = {}
    for n in cfg["chain"]:
        case = cases.chain(n, cfg["chain_poses"])
        P, V = closed_form.solve_numpy(case)
        t0 = time.perf_counter()
        kincas.model_of(cases.to_kincas(case))  # a new structure: the symbolic model is built here
        res = out[n] = {"compile": time.perf_counter() - t0, "case": case}
        for lb, prep in tools:
            t = time_tool(lambda: prep(case), cfg["repeats"], budget=10.0)
            res[lb] = {"t": t, "err": errors(case, t.run, P, V) if t.error is None else (float("nan"),) * 2}
        log(f"  chain {n:3d}: compile {res['compile']:.2f} s, " + ", ".join(
            f"{lb} {res[lb]['t'].median * 1e6:.1f}" for lb, _ in tools))
    return out


def other_benchmarks(quick: bool, deadline: float, log) -> list[tuple[str, str, str]]:
    """Run the other bench_*.py scripts beside this file, sharing the time left before
    `deadline` (a perf_counter value): [(script, status, report)]. The report is the markdown
    a script wrote beside itself (results_*.md, written during its run), else its output.
    In a quick run the scripts' own result files are restored afterwards."""
    out = []
    scripts = sorted(HERE.glob("bench_*.py"))
    # a quick run's reports are smoke: the scripts' own result files are put back afterwards
    saved = {f: f.read_bytes() for f in HERE.glob("results_*.md")} if quick else {}
    for i, path in enumerate(scripts):
        takes_quick = "--quick" in path.read_text(encoding="utf-8", errors="replace")
        cmd = [sys.executable, str(path)] + (["--quick"] if quick and takes_quick else [])
        # each script gets its share of what is left, and never less than MIN_SHARE: a loaded
        # machine that slowed the studies above must not leave the scripts seconds each
        timeout = max(30.0 if quick else MIN_SHARE, (deadline - time.perf_counter()) / (len(scripts) - i))
        before = {f: f.stat().st_mtime_ns for f in HERE.glob("results_*.md")}
        t0 = time.perf_counter()
        try:
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=str(ROOT))
            status = f"exit {p.returncode} after {time.perf_counter() - t0:.0f} s"
            written = [f for f in sorted(HERE.glob("results_*.md")) if before.get(f) != f.stat().st_mtime_ns]
            if p.returncode == 0 and written:
                text = "\n\n".join(_demote(f.read_text(encoding="utf-8")) for f in written)
            else:
                text = p.stdout if p.returncode == 0 else "```\n" + (p.stdout + "\n" + p.stderr)[-4000:] + "\n```"
        except subprocess.TimeoutExpired:
            status, text = f"stopped after {timeout:.0f} s (its share of the time limit)", _earlier(path)
        log(f"  {path.name}: {status}")
        out.append((path.name, status, text))
    if quick:
        for f in HERE.glob("results_*.md"):
            if f in saved:
                f.write_bytes(saved[f])
            else:
                f.unlink()
    return out


def _earlier(script: Path) -> str:
    """A stopped script's report from an earlier run (bench_X.py writes results_X.md), said so
    with the commit that last changed it; "" where there is none."""
    f = HERE / ("results_" + script.stem.removeprefix("bench_") + ".md")
    if not f.exists():
        return ""
    commit = subprocess.run(["git", "-C", str(ROOT), "log", "-1", "--format=%h, %cs", "--", str(f)],
                            capture_output=True, text=True).stdout.strip() or "not committed"
    return (f"*Not measured in this run: the script was stopped. Its report from an earlier run "
            f"({f.name}, commit {commit}) follows.*\n\n" + _demote(f.read_text(encoding="utf-8")))


def _demote(md_text: str) -> str:
    """Headings three levels down, so that a script's report nests under its own heading."""
    return "\n".join("###" + ln if ln.startswith("#") else ln for ln in md_text.splitlines())


# --- the whole run ---


MIN_SHARE = 240.0  # seconds every other bench_*.py script gets at least (full run)

CONFIG = {
    "full": {"n": 720, "repeats": 5, "n_stiff": 360, "chain": [1, 2, 5, 10, 20, 40], "chain_poses": 100,
             "budget": 900.0, "api_lengths": (100_000, 3_600, 360), "api_repeats": 7, "cli_runs": 2},
    "quick": {"n": 72, "repeats": 3, "n_stiff": 72, "chain": [1, 4, 10], "chain_poses": 30,
              "budget": 120.0, "api_lengths": (3_600, 360), "api_repeats": 3, "cli_runs": 1},
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a smoke run: fewer poses, sizes and repeats")
    ap.add_argument("--no-install", action="store_true", help="do not pip-install missing peers")
    ap.add_argument("--out", default=str(HERE), help="folder for RESULTS.md and the PNGs")
    ap.add_argument("--no-others", action="store_true", help="skip the other bench_*.py scripts")
    ap.add_argument("--only", choices=("stability", "growth"),
                    help="run this section alone and print its tables (RESULTS.md is not written)")
    args = ap.parse_args(argv)
    cfg = CONFIG["quick" if args.quick else "full"]
    if args.only:
        return run_only(args, cfg)
    # fresh compiled-code cache: setup times then include compiling, not loading old builds
    os.environ["KINCAS_CACHE"] = tempfile.mkdtemp(prefix="kincas-bench-")
    os.environ.setdefault("MPLBACKEND", "Agg")
    t_start = time.perf_counter()
    log = lambda s: print(s, file=sys.stderr, flush=True)
    log("installing peers ...")
    installs = install_requirements(args.no_install)
    log("0. what users call: kincas.sweep and kincas solve against peers at 360 to 100,000 poses ...")
    from peers.api import study_api
    api = study_api(cfg, log)
    log("1-2. error against time, throughput against peers ...")
    main_res = study_main(cfg, log)
    log("3. stability ...")
    stab = study_stability(cfg, log)
    log("4. growth ...")
    growth = study_growth(cfg, log)
    deadline = t_start + cfg["budget"]  # the other scripts share what is left of it
    others = [] if args.no_others else other_benchmarks(args.quick, deadline, log)
    from peers.report import write_report
    out = Path(args.out)
    write_report(out, quick=args.quick, cfg=cfg, installs=installs, machine=machine(), api=api, main=main_res,
                 stability=stab, growth=growth, others=others, seconds=time.perf_counter() - t_start)
    log(f"wrote {out / 'RESULTS.md'} in {time.perf_counter() - t_start:.0f} s")
    return 0


def run_only(args, cfg) -> int:
    """One section, its tables printed as markdown (the peers installed as for a full run)."""
    os.environ["KINCAS_CACHE"] = tempfile.mkdtemp(prefix="kincas-bench-")
    log = lambda s: print(s, file=sys.stderr, flush=True)
    t0 = time.perf_counter()
    install_requirements(args.no_install)
    from peers import report
    if args.only == "stability":
        lines = report.stability_tables(study_stability(cfg, log))
    else:
        lines = report.growth_table(study_growth(cfg, log))
    print("\n".join(lines))
    log(f"{args.only}: {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
