"""Collet et al.'s quadratic MPC and clone of the preview optimum, as the paper defines them
(collective; ``specdesign.mpc.collet``), on the paper's setting: one design point, its
linearisation as the plant (``simulate(linear=True)``), the wind known over the horizon.

Steps (IEA 15 MW at ``--speed``, records of ``--record`` s at T_s = 0.1 s):

1. the surrogate's (a, b) for the blade-root moment (m = 10) and the pitch (m = 4), fitted on
   ROSCO's loads in windows of the record length (``fit_fatigue_terms``, relative prices);
2. ρ by Eq. 13 (``tune_rho``) on a log grid, ``--tune`` winds (seeds 400+);
3. the expert: the open-loop optimum over each whole record (Eq. 14) on ``--train`` winds
   (seeds 500+), ``--samples`` instants drawn per record; features Eqs. 15-16 (M_x = 10,
   N_MPC = 20), the two-stage regressor;
4. closed loop on ``--valid`` other winds (seeds 600+): J_fat (Eq. 1, rainflow) of the quadratic
   MPC (ρ of step 2) and of the clone; the paper's statistics of J_clone/J_QMPC; the same two
   controllers on the reduced nonlinear model (model ≠ plant) on the same winds.

Turbulence classes cycle A, B, C over the seeds (the paper varies the intensity).
Writes its table between the markers of docs/mpc.md (``--out``).

Run: python benchmarks/collet.py [--record 60 --tune 6 --train 16 --valid 8 --samples 300]
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from comparison import splice

from specdesign import mpc, turbine
from specdesign.simulate import SimulationDivergedError, simulate
from specdesign.wind import wind_series

START, END = "<!-- collet.py results: start -->", "<!-- collet.py results: end -->"


def winds(model, v, seeds, duration, dt):
    """(W, n) wind records, the turbulence class cycling A, B, C."""
    return np.vstack([wind_series(model.rotor_radius, [v], [s], duration, dt, turbulence_class="ABC"[i % 3])[0]
                      for i, s in enumerate(seeds)])


def jfat(model, ctrl, v, w, terms, duration, linear):
    """J_fat (Eq. 1) per wind of a closed loop (NaN where the run diverges)."""
    try:
        r = simulate(model, ctrl, [v], wind=w[None], wind_dt=0.1, duration=duration, transient=0.0, linear=linear)
    except SimulationDivergedError:
        return np.full(w.shape[0], np.nan), None
    return mpc.fatigue_cost(terms, {t.output: r[t.output][0] for t in terms}), r


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--speed", type=float, default=19.0)
    ap.add_argument("--record", type=float, default=60.0)
    ap.add_argument("--tune", type=int, default=6)
    ap.add_argument("--train", type=int, default=16)
    ap.add_argument("--valid", type=int, default=8)
    ap.add_argument("--samples", type=int, default=300)
    ap.add_argument("--out", default="docs/mpc.md")
    a = ap.parse_args()
    model, v, T, dt = turbine.iea15mw(), a.speed, a.record, 0.1
    t_all, load = time.perf_counter(), os.getloadavg()
    terms = mpc.fit_fatigue_terms(model, v, T, seeds=(1, 2), duration=max(600.0, 2 * T),
                                  outputs=("blade_root_my", "pitch"))
    rhos = np.geomspace(0.1, 1000.0, 9)
    tune = mpc.tune_rho(model, v, terms, winds(model, v, range(400, 400 + a.tune), T + 1.0, dt), dt, rhos,
                        duration=T, transient=0.0)
    print("Eq. 13:", dict(zip(rhos.round(3), tune.costs.mean(axis=1).round(4))), "→ ρ =", tune.rho)
    wt = winds(model, v, range(500, 500 + a.train), T + 0.1, dt)
    demos = mpc.preview_demonstrations(model, v, terms, wt, dt, samples=a.samples, history=10, horizon=20)
    reg = mpc.CloningRegressor(uprev_column=10 * len(mpc.COLLET_OUTPUTS) + 9).fit(demos)
    print(f"demonstrations: {demos.targets.size} rows, expert {np.mean(demos.cpu_time):.1f} s CPU per record")
    wv = winds(model, v, range(600, 600 + a.valid), T + 3.0, dt)
    rows = {}
    for linear in (True, False):
        q = mpc.ColletMPC(model, v, (wv, dt), rho=tune.rho)
        c = mpc.PreviewClone(model, v, reg, (wv, dt))
        jq, rq = jfat(model, q, v, wv, terms, T, linear)
        jc, rc = jfat(model, c, v, wv, terms, T, linear)
        ratio = jc / jq
        rows[linear] = dict(jq=jq, jc=jc, ratio=ratio, cpu_clone=1e3 * np.mean(c.solve_times) if c.solve_times else np.nan,
                            sd_q=np.nan if rq is None else float(rq["gen_speed"].std(axis=-1).mean()),
                            sd_c=np.nan if rc is None else float(rc["gen_speed"].std(axis=-1).mean()),
                            sat_c=c.saturated)
        print("linear" if linear else "nonlinear", "J_QMPC", jq.round(3), "J_clone", jc.round(3))
    # the expert's own cost on the validation winds (the open-loop optimum, the bound)
    exp = np.array([mpc.fatigue_cost(terms, {t.output: res.outputs[t.output] for t in terms})
                    for res in (mpc.economic_open_loop(model, v, w[:int(T / dt) + 1], dt, terms, ts=dt,
                                                       speed_weight=100.0, activity_weight=0.0) for w in wv)])
    took = time.perf_counter() - t_all
    lines = [(f"Command: `python benchmarks/collet.py --record {T:g} --tune {a.tune} --train {a.train} --valid "
              f"{a.valid} --samples {a.samples}`; design point {v:g} m/s; records of {T:g} s at T_s = 0.1 s (the "
              f"paper: 200 s); turbulence classes A/B/C cycled over the seeds. Took {took:.0f} s wall (load "
              f"average {load[0]:.1f} at the start, 2 shared cores)."), "",
             (f"Eq. 13 (mean J_fat over {a.tune} tuning winds, linearised plant): "
              + ", ".join(f"ρ = {r:.3g}: {c:.3f}" for r, c in zip(rhos, tune.costs.mean(axis=1)))
              + f"; ρ = {tune.rho:.3g} chosen."), "",
             ("Surrogate fits: " + ", ".join(f"{t.output} a = {t.fit.a:.2f}, b = {t.fit.b:.2f} (m = {t.fit.m:g})"
                                            for t in terms)
              + f". Clone: {demos.targets.size} demonstrations from {a.train} open-loop optima "
              f"({np.mean(demos.cpu_time):.1f} s CPU per optimum), {reg.score(demos):.3f} R² of the moves on its "
              "training rows."), "",
             ("| plant | J_fat QMPC (mean) | J_fat clone (mean) | J_clone/J_QMPC mean | median | share ≤ 1 | ratio of means "
              "| speed SD QMPC / clone (rad/s) | clone CPU/step (ms) | clone setpoints cut |"),
             "|---|---|---|---|---|---|---|---|---|---|"]
    for linear, r in rows.items():
        ok = np.isfinite(r["ratio"])
        lines.append(f"| {'linearised (the paper’s)' if linear else 'reduced nonlinear'} | {np.nanmean(r['jq']):.3f} | "
                     f"{np.nanmean(r['jc']):.3f} | {np.mean(r['ratio'][ok]):.2f} | {np.median(r['ratio'][ok]):.2f} | "
                     f"{np.mean(r['ratio'][ok] <= 1):.0%} ({ok.sum()} runs) | "
                     f"{np.nanmean(r['jc']) / np.nanmean(r['jq']):.2f} | {r['sd_q']:.4f} / {r['sd_c']:.4f} | "
                     f"{r['cpu_clone']:.2f} | {r['sat_c']} |")
    lines += ["", (f"The expert (open-loop optimum, whole record known) on the validation winds: mean J_fat "
                   f"{np.mean(exp):.3f} (its ratio to the QMPC's on the linearised plant "
                   f"{np.mean(exp / rows[True]['jq']):.2f}).")]
    text = "\n".join(lines)
    print(text)
    splice(a.out, text, START, END, append=True)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
