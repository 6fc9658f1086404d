"""The second baseline of docs/comparison.md: ROSCO with its tower damper on.

ROSCO's fore-aft tower damper (``TD_Mode = 1``: pitch += FA_KI·∫HPF(tower-top acceleration))
with its gain set by ``rosco.tune_tower_damper`` (the smallest FA_KI giving the first tower
fore-aft mode a damping ratio of 0.2 at every whole m/s of 12-25 m/s on the linear model with
ROSCO's PI), run by ``rosco_scheduled(model, tower_damper=...)`` on the same speeds, paired seeds
and durations as ``benchmarks/comparison.py``, beside ROSCO as shipped (tower damping off), QFT,
H∞ and (unless ``--no-mpc``) the quadratic MPC (also reading the generator speed and pitch only,
without the tower-top acceleration the baselines lack), the excursion MPC
(``HealthMPC(health_weight=10)``) and the health-aware MPC (``health_aware_mpc(stress_weight=30)``). Every change is given against
both baselines, with the paired-seed jackknife SE (``validate.paired_change``). Every controller
reads the plant through the same sensors as in ``comparison.py`` (``IEA15MW_SENSORS`` by default,
``--noise none`` for the exact outputs), the same noise on the same (wind speed, seed).

Writes its tables between the markers ``<!-- tower_damper.py results: start/end -->`` of
docs/comparison.md (written once after the LTI controllers, again after the MPCs).

``--sweep Z1 Z2 ...``: instead, ROSCO + TD for each target damping ratio, printed (not written):
the damper gain's trade-off between tower DEL and pitch activity.

Run: python benchmarks/tower_damper.py [--no-mpc] [--quick --out /tmp/td.md] [--sweep 0.2 0.3 0.4 0.5]
     [--speeds 15 19 23 --seeds 8 --duration 600 --noise {iea15mw,none}]
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from comparison import (
    INDS,
    LABELS,
    ROOT,
    SPEEDS,
    actuator_table,
    fmt,
    qft_schedule,
    splice,
)

START, END = "<!-- tower_damper.py results: start -->", "<!-- tower_damper.py results: end -->"


def table(camps, baseline):
    """Rows "controller | Δ% ± SE per indicator (mean over speeds)" vs ``baseline``."""
    from specdesign.validate import paired_change

    b = camps[baseline]
    lines = ["| controller | " + " | ".join(f"{LABELS[k]} Δ% ± SE" for k in INDS) + " |",
             "|---" * (len(INDS) + 1) + "|"]
    per = {}
    for name, c in camps.items():
        if name == baseline:
            continue
        cells = []
        for k in INDS:
            ch = paired_change(c.values[k][0], b.values[k][0], k, m=c.m, wind_speeds=c.wind_speeds)
            per[(name, k)] = ch
            cells.append(fmt(float(np.mean(ch.change)), float(np.sqrt(np.sum(ch.se**2))) / ch.change.size))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines, per


def sweep(model, speeds, seeds, duration, ratios, noise=None):
    """Print ROSCO + TD against ROSCO (TD off) for each target damping ratio of the rule."""
    from specdesign.rosco import rosco_scheduled, tune_tower_damper
    from specdesign.validate import run_campaign

    kw = {"model": model, "duration": duration, "transient": 30.0, "predict": False, "progress": False,
          "noise": noise}
    camps = {"ROSCO (TD off)": run_campaign({"R": rosco_scheduled(model)}, list(speeds), seeds, **kw)}
    for z in ratios:
        td = tune_tower_damper(model, z)
        name = f"ROSCO + TD, ζ = {z:g} (FA_KI = {td.gain:.5f} rad·s/m)"
        camps[name] = run_campaign({"TD": rosco_scheduled(model, tower_damper=td)}, list(speeds), seeds, **kw)
    print("\n".join(table(camps, "ROSCO (TD off)")[0]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smoke test: 2 speeds, 2 seeds, 60 s")
    ap.add_argument("--no-mpc", action="store_true", help="LTI controllers only (seconds instead of minutes)")
    ap.add_argument("--damping-ratio", type=float, default=0.2)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "comparison.md"))
    ap.add_argument("--sweep", type=float, nargs="+", help="target damping ratios: print ROSCO + TD vs ROSCO for each")
    ap.add_argument("--speeds", type=float, nargs="+", default=list(SPEEDS))
    ap.add_argument("--seeds", type=int, default=20)
    ap.add_argument("--duration", type=float, default=600.0)
    ap.add_argument("--noise", choices=("iea15mw", "none"), default="iea15mw",
                    help="the sensors every controller reads: IEA15MW_SENSORS (docs/sensors.md) or the exact outputs")
    a = ap.parse_args()
    import control as ct

    from specdesign import hinf, mpc, turbine
    from specdesign.controller.noise import IEA15MW_SENSORS
    from specdesign.rosco import rosco_scheduled, tower_mode_damping, tune_tower_damper
    from specdesign.simulate import scheduled
    from specdesign.validate import run_campaign

    speeds, seeds, duration = ((17.0, 21.0), [0, 1], 60.0) if a.quick else (tuple(a.speeds), list(range(a.seeds)),
                                                                           a.duration)
    noise = IEA15MW_SENSORS if a.noise == "iea15mw" else None
    sensors = "IEA15MW_SENSORS" if noise is not None else "exact"
    load, t_all = os.getloadavg(), time.perf_counter()
    model = turbine.iea15mw()
    if a.sweep:
        sweep(model, speeds, seeds, duration, a.sweep, noise)
        return
    td = tune_tower_damper(model, a.damping_ratio)
    zeta = {v: (tower_mode_damping(model, v, None), tower_mode_damping(model, v, td)) for v in speeds}
    ctrls = {"ROSCO (TD off)": rosco_scheduled(model),
             "ROSCO + TD": rosco_scheduled(model, tower_damper=td, name="ROSCO + TD")}
    designs, qft_targets = qft_schedule(model, speeds)
    ctrls["QFT"] = scheduled(model, {d.wind_speed: d.pitch_controller for d in designs},
                             atd={d.wind_speed: d.atd_controller for d in designs}, name="QFT")
    hd = {v: hinf.design_hinf(model, v) for v in speeds}
    ctrls["H∞"] = scheduled(model, {v: ct.ss(d.pitch_controller) for v, d in hd.items()},
                            atd={v: ct.ss(d.atd_controller) for v, d in hd.items() if d.atd_controller is not None}
                            or None, name="H∞")
    # the quadratic MPC also without the tower-top acceleration the baselines lack (speed and pitch
    # only); every MPC's Kalman filter assumes the campaign's sensor noise (mpc.base.filter_noise)
    mpcs = {} if a.no_mpc else {
        "quadratic MPC": mpc.QuadraticMPC(model, sensors=noise),
        "quadratic MPC (speed, pitch only)": mpc.QuadraticMPC(model, measured=("gen_speed", "pitch"), sensors=noise,
                                                              name="quadratic MPC (speed, pitch only)"),
        "excursion MPC": mpc.HealthMPC(model, health_weight=10.0, sensors=noise),
        "health-aware MPC": mpc.health_aware_mpc(model, stress_weight=30.0, sensors=noise)}
    camps, wall = {}, {}

    def run(group):
        for name, c in group.items():
            t0 = time.perf_counter()
            camps[name] = run_campaign({name: c}, list(speeds), seeds, model=model, duration=duration, transient=30.0,
                                       predict=False, progress=False, noise=noise)
            wall[name] = time.perf_counter() - t0
            print(f"{name}: {wall[name]:.0f} s wall", flush=True)

    def write(mpc_done):
        cmd = "python benchmarks/tower_damper.py" + (" --quick" if a.quick else (
            f" --speeds {' '.join(f'{v:g}' for v in speeds)} --seeds {len(seeds)} --duration {duration:g}"
            f" --noise {a.noise}")) + (" --no-mpc" if a.no_mpc else "")
        head = [f"Command: `{cmd}`; {len(speeds)} speeds ({', '.join(f'{v:g}' for v in speeds)} m/s) × {len(seeds)} "
                f"paired seeds × {duration:g} s (after 30 s of transient), the same winds as `comparison.py`; "
                f"sensors: **{sensors}** for every controller (the same noise on the same (wind speed, seed)); "
                "QFT's DEL targets " + ", ".join(f"{t:g} % at {v:g} m/s" for v, t in zip(speeds, qft_targets)) + ". "
                f"Took {time.perf_counter() - t_all:.0f} s wall; load average {load[0]:.1f} at the start, "
                f"{os.getloadavg()[0]:.1f} at the end (2 cores, shared). Campaign wall times: "
                + ", ".join(f"{n} {t:.0f} s" for n, t in wall.items()) + "."
                + ("" if mpc_done or a.no_mpc else " The MPC rows are NOT YET RUN (written before their campaigns)."),
                "",
                f"Tower damper: FA_KI = {td.gain:.5f} rad·s/m, FA_HPFCornerFreq = {td.hpf_corner:g} rad/s "
                f"(`rosco.tune_tower_damper(model, {a.damping_ratio:g})`); FA_IntSat = {np.degrees(td.int_sat):g}° is "
                "not applied by the simulator (linear ATD path). Tower-mode damping ratio on the linear model with "
                "ROSCO's PI (`rosco.tower_mode_damping`), TD off → on: "
                + ", ".join(f"{v:g} m/s {z0:.3f} → {z1:.3f}" for v, (z0, z1) in zeta.items()) + ".", ""]
        l1, _ = table(camps, "ROSCO (TD off)")
        l2, per = table(camps, "ROSCO + TD")
        ps = ["", "Tower DEL per wind speed vs ROSCO + TD (%, ± paired-seed SE):", "",
              "| controller | " + " | ".join(f"{v:g} m/s" for v in speeds) + " |", "|---" * (len(speeds) + 1) + "|"]
        for name in camps:
            if (name, "tower_del") in per:
                ch = per[(name, "tower_del")]
                ps.append(f"| {name} | " + " | ".join(fmt(c, s) for c, s in zip(ch.change, ch.se)) + " |")
        text = "\n".join(head + ["Change vs ROSCO as shipped (tower damping off):", ""] + l1
                         + ["", "Change vs ROSCO with its tower damper (TD_Mode = 1):", ""] + l2 + ps
                         + ["", "The pitch actuator's cost (absolute; mean over the speeds and seeds):", ""]
                         + actuator_table(camps))
        print(text, flush=True)
        splice(a.out, text, START, END, append=True)

    run(ctrls)
    write(False)
    if mpcs:
        run(mpcs)
        write(True)


if __name__ == "__main__":
    main()
