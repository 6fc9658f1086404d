"""QuadraticMPC in OpenFAST through the forwarding DISCON library, beside ROSCO: one short
campaign run at 19 m/s (issue 31, item 3), through run_campaign(..., plant=deck).

Run: python benchmarks/openfast_forward.py [--duration 60] [--transient 20] [--store DIR] [--sensors]
                                           [--activity-weight W] [--speed-filter]
One TurbSim field (seed 0, NTM B), the shipped IEA 15 MW monopile deck, one OpenFAST process at
a time (niced): ROSCO's libdiscon.so with the deck's DISCON.IN, and QuadraticMPC (ts = 0.1 s,
its operating point estimated online, the turbine's pitch-rate limit in the library, ROSCO's
torque law of the reduced model) forwarded at DLL_DT = 0.02 s; with --sensors also QuadraticMPC
whose Kalman filter assumes the documented sensor noise (IEA15MW_SENSORS) instead of trusting
the sensors. With --activity-weight W also QuadraticMPC with the pitch-activity weight
q_Δ = W (default of the class 0.1): the variant that takes it off the rate limit (docs/openfast.md,
"Why the MPC rides the rate limit"); with --speed-filter also QuadraticMPC reading the generator
speed through the deck's ROSCO speed filter (forwarded(..., measurement_filters=...): second-order
low-pass, 1.0081 rad/s, damping 0.7, F_LPFCornerFreq of its DISCON.IN), which does not. The store
resumes: runs already there are read back. Prints the campaign's indicators
of both and the wall time of each run. Not the comparison issue 31 asks for (2 speeds × 4 seeds ×
600 s): one seed, a short record, to show the route works and what it costs.
"""
from __future__ import annotations

import argparse
import time

from specdesign import validate
from specdesign.export import forwarded
from specdesign.mpc import QuadraticMPC
from specdesign.openfast import iea15mw_monopile
from specdesign.simulate import IEA15MW_SENSORS
from specdesign.turbine import iea15mw

#: The deck's ROSCO generator-speed filter (its DISCON.IN: F_LPFType 2, F_LPFCornerFreq 1.0081 rad/s,
#: F_LPFDamping 0.7): (corner rad/s, damping).
ROSCO_SPEED_FILTER = (1.0081, 0.7)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=60.0)
    ap.add_argument("--transient", type=float, default=20.0)
    ap.add_argument("--store", default="/tmp/specdesign_openfast_forward")
    ap.add_argument("--sensors", action="store_true", help="also the MPC with a noise-aware Kalman filter")
    ap.add_argument("--activity-weight", type=float, default=None,
                    help="also the MPC with this pitch-activity weight q_Δ (the class default is 0.1)")
    ap.add_argument("--speed-filter", action="store_true",
                    help="also the MPC reading the speed through the deck's ROSCO low-pass (1.0081 rad/s, 0.7)")
    args = ap.parse_args()
    model = iea15mw()
    deck = iea15mw_monopile()
    mpc = QuadraticMPC(model, ts=0.1)
    controllers = {"ROSCO": deck.fst.with_name(deck.name + "_DISCON.IN"),
                   "QuadraticMPC": forwarded(mpc, dt=0.02, model=model, pitch_rate_limit=model.pitch_rate_limit)}
    if args.sensors:
        noisy = QuadraticMPC(model, ts=0.1, sensors=IEA15MW_SENSORS, name="quadratic MPC, sensor noise")
        controllers["QuadraticMPC_noiseKF"] = forwarded(noisy, dt=0.02, model=model,
                                                        pitch_rate_limit=model.pitch_rate_limit)
    if args.activity_weight is not None:
        calm = QuadraticMPC(model, ts=0.1, activity_weight=args.activity_weight,
                            name=f"quadratic MPC, q_Δ = {args.activity_weight:g}")
        controllers[f"QuadraticMPC_qD{args.activity_weight:g}"] = forwarded(
            calm, dt=0.02, model=model, pitch_rate_limit=model.pitch_rate_limit)
    if args.speed_filter:
        controllers["QuadraticMPC_speedLPF"] = forwarded(
            QuadraticMPC(model, ts=0.1), dt=0.02, model=model, pitch_rate_limit=model.pitch_rate_limit,
            measurement_filters={"gen_speed": ROSCO_SPEED_FILTER}, name="quadratic MPC, ROSCO's speed filter")
    t0 = time.perf_counter()
    camp = validate.run_campaign(controllers, [19.0], [0], plant=deck, duration=args.duration,
                                 transient=args.transient, store=args.store, openfast={"processes": 1, "nice": 10})
    wall = time.perf_counter() - t0
    print(f"{args.duration:g} s recorded after {args.transient:g} s, 19 m/s, seed 0; store {args.store}; "
          f"campaign wall time {wall:.0f} s (every run, one at a time, TurbSim included; stored runs read back)")
    print(f"{'':16s}" + "".join(f"{n:>24s}" for n in camp.controllers))
    for k in ("tower_del", "blade_del", "gen_speed_sd", "mean_power", "pitch_sd", "pitch_rate_sd", "pitch_travel",
              "rate_limit_time"):
        print(f"{k:16s}" + "".join(f"{camp.values[k][i, 0, 0]:24.4g}" for i in range(len(camp.controllers))))
    print("failed (unstable):", {n: bool(camp.unstable[i, 0]) for i, n in enumerate(camp.controllers)})


if __name__ == "__main__":
    main()
