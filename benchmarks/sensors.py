"""What the documented sensors (:data:`specdesign.controller.noise.IEA15MW_SENSORS`) change: the
numbers of docs/sensors.md.

1. The achievable design's promise (``feasibility.achievable_pitch``, speed specification relaxed
   1 dB, pitch-rate SD at most ROSCO's, κ = 1) without noise, with the white generator-speed
   noise, and with the noise and the 3P ripple, at 15, 19 and 23 m/s.
2. ROSCO (``rosco_scheduled``) and the QFT design at 19 m/s (``qft.design_qft``, 25 % target)
   simulated on the reduced model with and without the sensors (``run_campaign(noise=...)``): the
   same winds, so paired; tower DEL, speed SD, pitch-rate SD, pitch travel and time at the rate
   limit.

Run: ``nice -n 10 python benchmarks/sensors.py [--seeds 4] [--duration 600]`` (a few minutes).
"""
from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from specdesign.controller.noise import IEA15MW_SENSORS
from specdesign.feasibility import achievable_pitch
from specdesign.qft import design_qft
from specdesign.rosco import rosco_scheduled
from specdesign.spec import baseline_analysis
from specdesign.turbine import iea15mw
from specdesign.validate import pool, run_campaign

SPEEDS = (15.0, 19.0, 23.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--duration", type=float, default=600.0)
    args = ap.parse_args()
    model = iea15mw()
    white = dataclasses.replace(IEA15MW_SENSORS, ripple_3p=0.0)
    print(f"Sensors: {IEA15MW_SENSORS}\n")
    print("| wind speed | promise, no noise | white speed noise | noise + 3P |")
    print("|---|---|---|---|")
    for v in SPEEDS:
        base = baseline_analysis(model, v)
        r = [achievable_pitch(model, v, 1.0, base=base, noise=n).del_reduction for n in (None, white, IEA15MW_SENSORS)]
        print(f"| {v:g} m/s | {r[0]:.2f} % | {r[1]:.2f} % | {r[2]:.2f} % |")
    seeds = list(range(args.seeds))
    kw = dict(model=model, duration=args.duration, predict=False, progress=False)
    rosco = rosco_scheduled(model)
    qft19 = design_qft(model, 19.0, target_reduction=25.0).pitch_controller
    print(f"\nOn the reduced model, {args.seeds} paired seeds × {args.duration:g} s, without → with the sensors "
          "(seeds pooled: DEL by damage, SDs by variance, the rest by mean):\n")
    print("| controller | wind speed | tower DEL (MN·m) | speed SD (rpm) | pitch-rate SD (deg/s) | pitch travel (deg/h) | "
          "time at the rate limit (%) |")
    print("|---|---|---|---|---|---|---|")
    conv = {"tower_del": 1e-6, "gen_speed_sd": 30 / np.pi, "pitch_rate_sd": 180 / np.pi, "pitch_travel": 180 / np.pi,
            "rate_limit_time": 100.0}
    for name, c, speeds in (("ROSCO", rosco, SPEEDS), ("QFT (19 m/s design)", qft19, (19.0,))):
        clean, noisy = (run_campaign({name: c}, list(speeds), seeds, noise=n, **kw) for n in (None, IEA15MW_SENSORS))
        for i, v in enumerate(speeds):
            cells = []
            for k, f in conv.items():
                a, b = (f * float(pool(k, x.values[k][0, i], x.m)) for x in (clean, noisy))  # seeds pooled as they add up
                cells.append(f"{a:.3g} → {b:.3g}")
            print(f"| {name} | {v:g} m/s | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
