"""Quadratic MPC, economic fatigue MPC and behavioural cloning against ROSCO (docs/mpc.md).

(a) Campaign (nonlinear IEA 15 MW, ``run_campaign``): ROSCO's scheduled PI, the quadratic
    MPC, the receding-horizon economic MPC and its behavioural clone at 15 and 19 m/s on the
    same paired seeds: tower-base DEL (m = 4) and blade-root DEL (m = 10, when the model has
    that output) change vs ROSCO with the paired-seed SE, generator-speed SD, pitch SD, mean
    power, and CPU time per policy evaluation (the controllers' own ``solve_times``: one per run
    and grid point, two per control sample with the operating point estimated; ROSCO's PI is
    compiled into the simulator and has none).
(b) Open loop vs closed loop (the *linearised* turbine at 19 m/s, ``simulate(linear=True)``,
    every run from the trim, the wind held over each 0.2 s sample as the optimiser assumes):
    the fatigue surrogate J̃ (Collet et al., Eq. 4) and the tower DEL over a 100 s record of the
    perfect-preview open-loop optimum (``economic_open_loop``, replayed), the quadratic MPC,
    the economic MPC and the clone, relative to ROSCO's, on the same records.

The surrogate's a, b are fitted on ROSCO's loads at 19 m/s over windows of the horizon
(``fit_fatigue_terms``; components priced relative to ROSCO's damage). The clone is trained by
``clone`` (2 DAgger rounds, each visited state also labelled in one perturbed copy) on seeds
100-103 at both speeds, never on the evaluation seeds; its held-out R² is on visited states only.

Also printed: the command, wall time and load average, each controller's sensors, and the
economic MPC's objective term shares at its optima in the campaign (Eq. 4, speed and move terms).

Run: python benchmarks/mpc.py [--seeds 3] [--duration 200] (22 minutes niced on 2 shared cores at a
load average of 3-6).
"""
from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

from specdesign import mpc, turbine
from specdesign.fatigue import del_rainflow
from specdesign.rosco import rosco_scheduled
from specdesign.simulate import simulate
from specdesign.validate import paired_change, run_campaign
from specdesign.wind import wind_series

SPEEDS = (15.0, 19.0)
TS = 0.2


def _blade_del(camp, name, m=10.0):
    """(W, S) blade-root DEL of the kept series of one controller (N·m)."""
    r = camp.series[name]
    x = r["blade_root_my"]
    return np.array([[del_rainflow(x[i, j], m, r.duration) for j in range(x.shape[1])] for i in range(x.shape[0])])


def campaign_table(model, terms, bc, seeds, duration):
    """Part (a): the campaign table, printed."""
    ctrls = {"ROSCO": rosco_scheduled(model), "quadratic MPC": mpc.QuadraticMPC(model),
             "economic MPC": mpc.EconomicMPC(model, terms, ts=TS), "behavioural cloning": bc}
    for c in ctrls.values():
        if hasattr(c, "solve_times"):
            c.solve_times.clear()
    t0 = time.perf_counter()
    camp = run_campaign(ctrls, list(SPEEDS), seeds, model=model, duration=duration, transient=30.0, predict=False,
                        keep_series=True)
    print(f"(a) campaign: {len(SPEEDS)} speeds × {len(seeds)} paired seeds × {duration:g} s, "
          f"{time.perf_counter() - t0:.0f} s wall")
    print("sensors (noise-free; the MPCs' Kalman filter and operating point estimated online): "
          + "; ".join(f"{n}: {sensors(c)}" for n, c in ctrls.items()))
    blade = "blade_root_my" in model.output_names
    head = "| controller | v (m/s) | tower DEL Δ% ± SE |" + (" blade DEL Δ% ± SE |" if blade else "")
    print(head + " speed SD (rpm) | pitch SD (deg) | mean power (MW) | CPU/evaluation (ms) |")
    print("|" + "---|" * (head.count("|") + 3))
    bdel = {n: _blade_del(camp, n) for n in ctrls} if blade else {}
    for n, c in ctrls.items():
        i = camp.index(n)
        ch = camp.change(n, "ROSCO", "tower_del")
        chb = paired_change(bdel[n], bdel["ROSCO"], "tower_del", m=10.0) if blade else None
        cpu = 1e3 * np.mean(c.solve_times) if getattr(c, "solve_times", None) else float("nan")
        for w, v in enumerate(SPEEDS):
            sd = np.sqrt(np.mean(camp.values["gen_speed_sd"][i, w] ** 2)) * 60 / (2 * np.pi)
            psd = np.degrees(np.sqrt(np.mean(camp.values["pitch_sd"][i, w] ** 2)))
            pw = np.mean(camp.values["mean_power"][i, w]) / 1e6
            row = f"| {n} | {v:g} | {ch.change[w]:+.1f} ± {ch.se[w]:.1f} |"
            if blade:
                row += f" {chb.change[w]:+.1f} ± {chb.se[w]:.1f} |"
            cpu_s = "–" if np.isnan(cpu) else f"{cpu:.2f}"
            print(row + f" {sd:.3f} | {psd:.3f} | {pw:.3f} | {cpu_s} |")
    print(term_shares(ctrls["economic MPC"].term_values))


def sensors(c):
    """What controller ``c`` reads, in words: the MPCs' ``measured`` outputs, else ROSCO's PI's."""
    if hasattr(c, "measured"):
        return ", ".join(c.measured) + f" (operating point: {c.operating_point})"
    # rosco_scheduled / rosco_baseline: the PI on the filtered generator speed, its gains
    # scheduled on its own filtered pitch command (not a sensor)
    return "gen_speed"


def term_shares(values):
    """Line of the economic MPC's objective term shares at its optima, per speed and overall.

    ``values`` are ``EconomicMPC.term_values`` after the campaign: ``run_campaign`` without an
    executor runs the speeds one after the other in ``SPEEDS`` order with the same seeds, so
    the solves split into ``len(SPEEDS)`` equal consecutive blocks, one per speed.
    """
    if not values:
        return "economic MPC objective: no term values recorded (the controller ran in another process)"
    p = np.array(values)
    frac = p / p.sum(axis=1, keepdims=True)
    parts = [("all", frac)]
    if len(frac) % len(SPEEDS) == 0:
        parts += [(f"{v:g} m/s", b) for v, b in zip(SPEEDS, np.split(frac, len(SPEEDS)))]
    return ("economic MPC objective at its optima (mean shares, Eq. 4 / speed / move term): "
            + "; ".join(f"{k} {100 * b[:, 0].mean():.0f} / {100 * b[:, 1].mean():.0f} / "
                        f"{100 * b[:, 2].mean():.0f} % ({len(b)} solves)" for k, b in parts))


def open_loop_table(model, terms, terms_mpc, bc, seeds, horizon=100.0, v=19.0):
    """Part (b): open-loop optimum vs the closed loops on the linearised turbine, printed."""
    n = int(round(horizon / TS))
    w = wind_series(model.rotor_radius, [v], seeds, (n + 1) * TS, TS)[0]
    t0 = time.process_time()
    dm = mpc.discretize_turbine(model, v, TS)
    opt = [mpc.economic_open_loop(model, v, w[j], TS, terms, ts=TS, dm=dm) for j in range(len(seeds))]
    cpu_ol = (time.process_time() - t0) / len(seeds)
    # the wind held over each sample, at the simulation step: the optimiser's zero-order hold
    dt = 0.02
    held = np.repeat(w[:, :n], int(round(TS / dt)), axis=1)
    held = np.concatenate([held, held[:, -1:]], axis=1)[None]
    kw = dict(wind=held, wind_dt=dt, duration=horizon, transient=0.0, linear=True, dt=dt, record_dt=0.1)
    # the plant here is the linearisation at v, which the open-loop optimum also knows: the
    # closed loops get the same model and operating point (operating_point="initial pitch"),
    # so the comparison is of the controllers, not of their model error
    known = dict(operating_point="initial pitch")
    ctrls = {"ROSCO": turbine.rosco_baseline(model, v), "open-loop optimum (preview)":
             mpc.OpenLoopPlayback(np.stack([o.pitch_cmd for o in opt]), TS),
             "quadratic MPC": mpc.QuadraticMPC(model, **known),
             "quadratic MPC (preview)": mpc.QuadraticMPC(model, preview=(held, dt), **known),
             "economic MPC": mpc.EconomicMPC(model, terms_mpc, ts=TS, **known),
             "behavioural cloning": mpc.ClonedController(model, bc.regressors, TS, **known)}
    print("sensors: " + "; ".join(f"{n}: {'none (replays its record)' if n.startswith('open-loop') else sensors(c)}"
                                  for n, c in ctrls.items()))
    res = {}
    for name, c in ctrls.items():
        r = simulate(model, c, [v], **kw)
        series = {t.output: r[t.output][0] for t in terms}
        j = mpc.surrogate_cost(terms, series)
        d = np.array([del_rainflow(x, 4.0, horizon) for x in r["tower_base_my"][0]])
        res[name] = (j, d, r["gen_speed"][0].std(axis=-1))
    print(f"\n(b) linearised turbine at {v:g} m/s, {len(seeds)} records of {horizon:g} s from the trim "
          f"(open-loop solve: {cpu_ol:.1f} s CPU per record)")
    print("| controller | J̃ / J̃_ROSCO (mean ± SE) | tower DEL Δ% (mean ± SE) | speed SD (rpm) |")
    print("|---|---|---|---|")
    j0, d0, _ = res["ROSCO"]
    for name, (j, d, s) in res.items():
        rj, rd = j / j0, 100 * (d / d0 - 1)
        se = (lambda x: x.std(ddof=1) / np.sqrt(x.size) if x.size > 1 else float("nan"))
        print(f"| {name} | {rj.mean():.3f} ± {se(rj):.3f} | {rd.mean():+.1f} ± {se(rd):.1f} | "
              f"{np.sqrt(np.mean(s ** 2)) * 60 / (2 * np.pi):.3f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--duration", type=float, default=200.0)
    a = ap.parse_args()
    model = turbine.iea15mw()
    t0 = time.perf_counter()
    load0 = os.getloadavg()
    print(f"command: python {' '.join(sys.argv)}; load average {load0[0]:.1f} / {load0[1]:.1f} / {load0[2]:.1f} "
          f"(1/5/15 min) at the start, {os.cpu_count()} cores")
    terms = mpc.fit_fatigue_terms(model, 19.0, 10.0, seeds=(1, 2))
    print("surrogate fits (window 10 s = the MPC's horizon): "
          + ", ".join(f"{t.output}: m={t.fit.m:g} a={t.fit.a:.2f} b={t.fit.b:.1f}" for t in terms))
    bc, demos = mpc.clone(model, list(SPEEDS), [100, 101, 102, 103], terms, rounds=2, horizon=10.0, duration=60.0)
    held = mpc.demonstrations(model, [19.0], [300], terms, horizon=10.0, duration=60.0, perturbed=0)  # visited states
    print(f"clone: {demos.targets.size} demonstrations, expert {1e3 * np.mean(demos.cpu_time):.1f} ms CPU per solve; "
          f"held-out R² of the moves at 19 m/s {bc.regressors[19.0].score(held):.3f} ({time.perf_counter() - t0:.0f} s)")
    campaign_table(model, terms, bc, list(range(a.seeds)), a.duration)
    terms100 = mpc.fit_fatigue_terms(model, 19.0, 100.0, seeds=(1, 2))
    open_loop_table(model, terms100, terms, bc, list(range(50, 50 + a.seeds)))
    q = mpc.QuadraticMPC(model, shortcut=False)
    simulate(model, q, [19.0], seeds=[1], duration=30.0, transient=0.0)
    print(f"\nquadratic MPC with the QP solved at every step (cvxpy + OSQP, no shortcut): "
          f"{1e3 * np.mean(q.solve_times):.2f} ms CPU per evaluation (median {1e3 * np.median(q.solve_times):.2f})")
    load1 = os.getloadavg()
    print(f"took {time.perf_counter() - t0:.0f} s wall; load average {load1[0]:.1f} / {load1[1]:.1f} / "
          f"{load1[2]:.1f} at the end")


if __name__ == "__main__":
    main()
