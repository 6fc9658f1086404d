"""The Volterra prediction, order by order (docs/nonlinearity.md, section (i)).

(a) Convergence: ROSCO at 19 m/s on the same periodic wind records scaled to 1, ½ and ¼ ×
    class B: RMS of (nonlinear simulation − Volterra series to order k), relative to the
    signal's SD, and the DEL ratio series/nonlinear. A residual that falls by 2^k when the
    turbulence halves is the series converging.
(b) Order by order at 15-25 m/s: the QFT designs vs ROSCO (fixed controllers, as in
    benchmarks/acceptance.py, same seeds): the rainflow reduction on the nonlinear model, on
    the linearised model and on the Volterra series to order 1, 2, 3 (all on the same wind).
(c) Cost: one 660 s record through the Volterra series vs through the nonlinear simulator.

Run: python benchmarks/volterra.py [--seeds 100] [--speeds 15 17 19 21 23 25]
(about 3 minutes on 2 cores, most of it the QFT designs).
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from specdesign import simulate as sm
from specdesign import turbine
from specdesign import validate as va
from specdesign.fatigue import del_rainflow
from specdesign.qft import design_schedule, spec_notch

TRANSIENT, DURATION, WDT = 60.0, 600.0, 0.1


def pooled(y):
    return float(np.mean([del_rainflow(s, 4.0, DURATION) ** 4 for s in y]) ** 0.25)


def window(terms, n):
    i0 = int(round(TRANSIENT / WDT))
    return np.cumsum(terms, axis=0)[..., i0:i0 + n]


def convergence(model, seeds):
    v = 19.0
    rosco = turbine.rosco_baseline(model, v)
    wind = sm.wind_series(model.rotor_radius, [v], seeds, TRANSIENT + DURATION + WDT, WDT)
    op = model.trim(v)
    my0 = model.evaluate_outputs(op.x, v, op.pitch, op.gen_torque)[turbine.OUTPUT_NAMES.index("tower_base_my")]
    print(f"(a) ROSCO at {v:g} m/s, {len(seeds)} seeds: RMS(nonlinear − series to order k)/SD, DEL series/nonlinear")
    print("| turbulence (× class B) | order 1 (linear) | order 2 | order 3 | DEL ratio order 1 | order 2 | order 3 |")
    print("|---|---|---|---|---|---|---|")
    for a in (1.0, 0.5, 0.25):
        w = v + a * (wind - v)
        nl = sm.simulate(model, rosco, [v], wind=w, wind_dt=WDT)["tower_base_my"][0]
        part = my0 + window(va.volterra_response(model, rosco, v, w[0], WDT)["tower_base_my"], nl.shape[1])
        sd = np.std(nl)
        rms = [np.sqrt(np.mean((nl - part[k]) ** 2)) / sd for k in range(3)]
        ratio = [pooled(part[k]) / pooled(nl) for k in range(3)]
        print(f"| {a:g} | " + " | ".join(f"{x:.4f}" for x in rms) + " | " + " | ".join(f"{x:.4f}" for x in ratio) + " |")


def by_order(model, speeds, seeds):
    t0 = time.perf_counter()
    designs = design_schedule(model, speeds, spec=spec_notch())
    print(f"\n(b) QFT vs ROSCO, {len(seeds)} paired seeds × {DURATION:g} s (designs {time.perf_counter() - t0:.0f} s)")
    print("| wind speed (m/s) | linear prediction | rainflow, nonlinear | rainflow, linearised | Volterra order 1 "
          "| order 2 | order 3 | nonlinear part (pp) | order 2 part | order 3 part |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for d in designs:
        v = d.wind_speed
        ctrls = {"ROSCO": turbine.rosco_baseline(model, v),
                 "QFT": sm.scheduled(model, {v: d.pitch_controller}, atd={v: d.atd_controller}, name="QFT")}
        wind = sm.wind_series(model.rotor_radius, [v], seeds, TRANSIENT + DURATION + WDT, WDT)
        dels = {}
        for name, c in ctrls.items():
            nl = sm.simulate(model, c, [v], wind=wind, wind_dt=WDT)["tower_base_my"][0]
            li = sm.simulate(model, c, [v], wind=wind, wind_dt=WDT, linear=True)["tower_base_my"][0]
            part = window(va.volterra_response(model, c, v, wind[0], WDT)["tower_base_my"], nl.shape[1])
            dels[name] = [pooled(nl), pooled(li)] + [pooled(part[k]) for k in range(3)]
        red = [100 * (1 - q / r) for q, r in zip(dels["QFT"], dels["ROSCO"])]
        pred = 100 * (1 - va.linear_prediction(model, ctrls["QFT"], v).del_ / va.linear_prediction(model, ctrls["ROSCO"], v).del_)
        print(f"| {v:g} | {pred:.2f} | " + " | ".join(f"{x:.2f}" for x in red)
              + f" | {red[0] - red[1]:+.2f} | {red[3] - red[2]:+.2f} | {red[4] - red[2]:+.2f} |", flush=True)


def cost(model):
    v = 19.0
    rosco = turbine.rosco_baseline(model, v)
    seeds = np.arange(100)
    wind = sm.wind_series(model.rotor_radius, [v], seeds, TRANSIENT + DURATION + WDT, WDT)
    sm.simulate(model, rosco, [v], wind=wind[:, :2], wind_dt=WDT)  # compile
    t = time.perf_counter()
    sm.simulate(model, rosco, [v], wind=wind, wind_dt=WDT)
    t_sim = (time.perf_counter() - t) / seeds.size
    t = time.perf_counter()
    va.volterra_response(model, rosco, v, wind[0], WDT)
    t_vol = (time.perf_counter() - t) / seeds.size
    print(f"\n(c) per 660 s record at {v:g} m/s (100 records): nonlinear simulation {1e3 * t_sim:.1f} ms (RK4 at 0.02 s, "
          f"compiled, both cores), Volterra series to order 3 {1e3 * t_vol:.1f} ms (FFT, numpy)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=100)
    ap.add_argument("--speeds", type=float, nargs="+", default=[15, 17, 19, 21, 23, 25])
    args = ap.parse_args(argv)
    model = turbine.iea15mw()
    convergence(model, np.arange(min(args.seeds, 20)))
    by_order(model, args.speeds, np.arange(args.seeds))
    cost(model)


if __name__ == "__main__":
    main()
