"""Validation campaigns timed against their targets, and how their cost scales (issue 16).

Run:
    python benchmarks/bench_campaign.py              # campaign timings (48 runs, 1800 runs, store, dask)
    python benchmarks/bench_campaign.py --quick      # without the 1800-run campaign
    python benchmarks/bench_campaign.py --scale      # + scale curves: docs/figures/campaign_scaling.png
                                                     #   and the Markdown table of docs/campaigns.md
    python benchmarks/bench_campaign.py --scale --budget 300   # let a curve point take up to 300 s
    python benchmarks/bench_campaign.py --only-scale           # the scale curves alone
    python benchmarks/bench_campaign.py --profile    # where the CPU time of the 48-run campaign
                                                     #   (no predictions) goes: cProfile, CPU time

The lifetime campaign runs the three controllers at the 12 bin centres 3-25 m/s of
``validate.weibull_bins()`` with ROSCO's torque law in every run (``torque_control="rosco"``,
as ``specdesign demo --lifetime`` runs them).

Every campaign is ``validate.run_campaign`` with the scheduled controllers of
benchmarks/bench_simulate.py (ROSCO's gain-scheduled PI on 6 local PIs, the same with an ATD
notch, and a single PI at 19 m/s for the third controller), 600 s recorded after a 60 s
transient, dt = 0.02 s, records every 0.1 s, unless said otherwise. Wall times are
time.perf_counter over one call (best of 3 for the sub-10 s ones), numba compile time
excluded (one short warm-up campaign first; the kernels are cached on disk anyway). The
machine's load average is printed: other processes on its 2 cores inflate every time. The CPU
time of the best repeat (time.process_time: every thread of the process, numba's included) is
printed beside it: on a shared machine it moves far less than the wall time, so two versions of
the code are best compared by it (the wall time is what the targets are about).

Scale curves: time vs number of runs N (one controller, 6 wind speeds × N/6 seeds, 600 s,
no linear predictions: their cost does not grow with the seeds; N = 1 is one speed, one
seed) and vs record length (48 runs). A line t = a + b·x fitted on the relative error gives
the fixed cost a and the cost per run or per simulated second b; "linear" means t/x
settles to b. A curve stops at the first point whose
predicted time (from the line so far) exceeds the budget (default 120 s), and says so.
"""
from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from specdesign import simulate as sm
from specdesign import turbine
from specdesign import validate as va
from specdesign import wind

SPEEDS = [15.0, 17.0, 19.0, 21.0, 23.0, 25.0]
ROOT = Path(__file__).resolve().parents[1]
FIGURE = ROOT / "docs" / "figures" / "campaign_scaling.png"


def _timed(f, repeat=1):
    """(best wall time, CPU time of that call) of ``repeat`` calls of ``f(model, ctrls)``, each on
    a fresh model and fresh controllers (built untimed): the per-model trims and per-loop checks
    the workbench keeps for the objects in use are not carried from one repeat to the next, nor
    the rotor-disc coherence cache (cleared), so every call is a cold campaign."""
    best = (np.inf, np.inf)
    for _ in range(repeat):
        model = turbine.iea15mw()
        ctrls = controllers(model)
        wind.disc_coherence.cache_clear()
        t0, c0 = time.perf_counter(), time.process_time()
        f(model, ctrls)
        best = min(best, (time.perf_counter() - t0, time.process_time() - c0))
    return best


def controllers(model):
    import control

    rosco = sm.rosco_scheduled(model)
    atd = control.tf([-0.014187, -0.014187 * 4.357], [1, 0.3276])
    designed = dataclasses.replace(rosco, atd=tuple(atd for _ in rosco.pitch), name="ATD")
    return {"ROSCO": rosco, "ATD": designed, "PI19": turbine.rosco_baseline(model, 19.0)}


def row(label, tc, target=None, note=""):
    t, cpu = tc
    tgt = f"{target:8.1f} {target / t:7.2f}x" if target else f"{'':8s} {'':8s}"
    print(f"  {label:<62s} {t:9.2f} {cpu:8.2f} {tgt}  {note}", flush=True)


def two_of(ctrls):
    return {k: ctrls[k] for k in ("ROSCO", "ATD")}


def timings(model, ctrls, quick):
    print(f"\nCampaigns (load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; ratio = target / ours)")
    print(f"  {'case':<62s} {'time (s)':>9s} {'CPU (s)':>8s} {'target':>8s} {'ratio':>8s}")
    run48 = dict(progress=False)
    row("48 runs (6 speeds × 4 seeds × 2 scheduled ctrl), full campaign",
        _timed(lambda m, c: va.run_campaign(two_of(c), SPEEDS, [1, 2, 3, 4], model=m, **run48), 3), 0.5,
        "wind + sim + rainflow + Welch + linear predictions")
    row("48 runs, no linear predictions",
        _timed(lambda m, c: va.run_campaign(two_of(c), SPEEDS, [1, 2, 3, 4], model=m, predict=False, **run48), 3), 0.5)
    with tempfile.TemporaryDirectory() as tmp:
        # the same controller objects for both calls: a store compares pickles, and two
        # python-control systems built alike in one process get different automatic names
        row("48 runs, no predictions, every run stored (store=)",
            _timed(lambda m, c: va.run_campaign(two_of(ctrls), SPEEDS, [1, 2, 3, 4], model=model, predict=False,
                                                store=Path(tmp) / "s", **run48)),
            None, "48 NetCDF cells written")
        row("  the same rerun: all 48 cells read back, nothing simulated",
            _timed(lambda m, c: va.run_campaign(two_of(ctrls), SPEEDS, [1, 2, 3, 4], model=model, predict=False,
                                                store=Path(tmp) / "s", **run48), 3))
    try:
        import distributed
    except ImportError:
        print("  (dask.distributed not installed: pip install -e '.[cluster]' for the cluster row)")
    else:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster, \
                distributed.Client(cluster) as client:
            # warm-up: each worker loads the compiled kernels (excluded, as locally)
            client.run(lambda: va.run_campaign(two_of(ctrls), [19.0], [1], model=model, duration=20.0, transient=5.0,
                                               progress=False))
            row("48 runs, no predictions, dask LocalCluster 2 workers × 1 thread",
                _timed(lambda m, c: va.run_campaign(two_of(c), SPEEDS, [1, 2, 3, 4], model=m, predict=False,
                                                    executor=client, **run48), 3),
                0.5, "one task per wind speed; CPU: this process's only, not the workers'")
    lifetime_bins = va.weibull_bins().centres  # 3, 5, ..., 25 m/s: cut-in to cut-out, 2 m/s bins
    row("lifetime: 12 bins × 6 seeds × 3 ctrl (216 runs), no predictions",
        _timed(lambda m, c: va.run_campaign(c, lifetime_bins, 6, model=m, predict=False, torque_control="rosco",
                                            **run48), 3),
        10.0, "ROSCO's torque law in every run")
    if not quick:
        seeds = list(range(1, 101))
        row("1800 runs (6 speeds × 100 seeds × 3 ctrl), no predictions",
            _timed(lambda m, c: va.run_campaign(c, SPEEDS, seeds, model=m, predict=False, **run48)), 15.0)


def _fit(x, t):
    """t = a + b·x by least squares on the relative error (each point weighs 1/t: the small
    points matter as much as the large ones on the log-log plot)."""
    x, t = np.asarray(x, float), np.asarray(t, float)
    a, b = np.linalg.lstsq(np.c_[np.ones(x.size), x] / t[:, None], np.ones(x.size), rcond=None)[0]
    return a, b


def curve(label, xs, run, budget):
    """Time run(x) for growing x until the line so far predicts more than ``budget`` seconds."""
    done, times = [], []
    for x in xs:
        if len(done) >= 2:
            a, b = _fit(done, times)
            guess = a + b * x
            if guess > budget:
                print(f"  {label}: stopped before {x:g} (the line so far predicts {guess:.0f} s > budget "
                      f"{budget:g} s; --budget raises it)", flush=True)
                break
        t = _timed(lambda m, c: run(x, m, c))[0]
        done.append(x)
        times.append(t)
        print(f"  {label} = {x:>6g}: {t:8.2f} s  ({1e3 * t / x:8.2f} ms per unit; load average now "
              f"{os.getloadavg()[0]:.1f})", flush=True)
    return np.array(done, float), np.array(times)


def scale(model, ctrls, budget):
    print(f"\nScale curves (load average {os.getloadavg()[0]:.1f}; no linear predictions)", flush=True)

    def runs(n, m, c):  # n runs: 6 speeds × n/6 seeds (1 speed for n < 6)
        speeds = SPEEDS if n >= 6 else [19.0]
        return va.run_campaign({"ROSCO": c["ROSCO"]}, speeds, list(range(1, n // len(speeds) + 1)), model=m,
                               predict=False, progress=False)

    t1 = _timed(lambda m, c: runs(1, m, c))[0]
    print(f"  runs = {1:>6d}: {t1:8.2f} s  (one wind speed, one seed: one task)", flush=True)
    # from 6 runs on, 6 wind speeds: 6 tasks, each with its wind synthesis and checks
    xr, tr = curve("runs", [6, 12, 30, 60, 120, 300, 600, 1200, 3000, 6000, 10002], runs, budget)
    lengths = [75.0, 150.0, 300.0, 600.0, 1200.0, 2400.0]

    def records(d, m, c):
        return va.run_campaign(two_of(c), SPEEDS, [1, 2, 3, 4], model=m, predict=False, duration=d, progress=False)

    xl, tl = curve("record length (s), 48 runs", lengths, records, budget)
    sim_s = 48 * (xl + 60.0)  # simulated seconds, transient included
    ar, br = _fit(xr, tr)
    al, bl = _fit(sim_s, tl)
    print("\nMarkdown table (docs/campaigns.md):\n")
    print("| runs (600 s each) | time (s) | ms per run |")
    print("|---:|---:|---:|")
    print(f"| 1 (one wind speed) | {t1:.2f} | {1e3 * t1:.1f} |")
    for x, t in zip(xr, tr):
        print(f"| {x:g} | {t:.2f} | {1e3 * t / x:.1f} |")
    print(f"\nLine t = a + b·N (6 wind speeds): a = {ar:.2f} s, b = {1e3 * br:.2f} ms per run.\n")
    print("| record length (s), 48 runs | simulated s | time (s) | µs per simulated s |")
    print("|---:|---:|---:|---:|")
    for x, s, t in zip(xl, sim_s, tl):
        print(f"| {x:g} | {s:g} | {t:.2f} | {1e6 * t / s:.1f} |")
    print(f"\nLine t = a + b·T: a = {al:.2f} s, b = {1e6 * bl:.2f} µs per simulated second.")
    figure(xr, tr, (ar, br), sim_s, tl, (al, bl))


def figure(xr, tr, fr, xs, ts, fs):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9.0, 3.6), layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    for ax, x, t, (a, b), xlabel in ((ax1, xr, tr, fr, "runs N (600 s each)"),
                                     (ax2, xs, ts, fs, "simulated seconds (48 runs × (60 s + record))")):
        ax.loglog(x, t, "o", label="measured")
        xx = np.geomspace(x.min(), x.max(), 100)
        ax.loglog(xx, a + b * xx, "-", lw=1, label=f"a + b·x (a = {a:.2f} s, b = {b:.2g} s)")
        ax.loglog(xx, b * xx, ":", lw=1, color="grey", label="b·x (linear)")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("wall time (s)")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=8)
    ax1.set_title("time vs number of runs", fontsize=10)
    ax2.set_title("time vs record length", fontsize=10)
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    print(f"\nfigure: {FIGURE.relative_to(ROOT)}")


def profile():
    """cProfile of one cold 48-run campaign without predictions, on CPU time (time.process_time:
    the compiled loop's line is the CPU of numba's threads, twice its wall time on 2 idle cores)."""
    import cProfile
    import pstats

    model = turbine.iea15mw()
    ctrls = controllers(model)
    prof = cProfile.Profile(time.process_time)
    prof.enable()
    va.run_campaign(two_of(ctrls), SPEEDS, [1, 2, 3, 4], model=model, predict=False, progress=False)
    prof.disable()
    print(f"\nCPU profile of the 48-run campaign, no predictions (load average {os.getloadavg()[0]:.1f})")
    pstats.Stats(prof).sort_stats("cumulative").print_stats(30)


def main(argv):
    model = turbine.iea15mw()
    ctrls = controllers(model)
    # warm-up (compile or load from cache), excluded from timings
    va.run_campaign(ctrls, [19.0], [1], model=model, duration=20.0, transient=5.0, progress=False)
    if "--profile" in argv:
        profile()
        return
    if "--only-scale" not in argv:
        timings(model, ctrls, quick="--quick" in argv)
    if "--scale" in argv or "--only-scale" in argv:
        budget = float(argv[argv.index("--budget") + 1]) if "--budget" in argv else 120.0
        scale(model, ctrls, budget)


if __name__ == "__main__":
    main(sys.argv[1:])
