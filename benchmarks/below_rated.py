"""Below rated and the transition (issue 16, part 1): the numbers of docs/turbine.md and docs/validation.md.

Run: python benchmarks/below_rated.py
Prints (1) the IEA 15 MW trim under its torque law from cut-in to cut-out (region, rotor
speed, torque, pitch, power, slowest pole of the linearisation); (2) the compiled torque law
in the simulator against ROSCO's compiled DISCON (rosco package, libdiscon 2.10) on the same
wind, 4 seeds x 600 s at 5, 9, 11, 13 m/s, ROSCO's IEA 15 MW DISCON.IN with VS_ControlMode 1
(and 3) and PS_Mode 0: SD of rotor speed, generator torque and pitch, and the relative
differences (the issue's acceptance: within 2 %); (3) the cost of both, as a ratio; (4) near
rated, the default torque_control="auto" (torque held at rated above rated) against "rosco"
(the law in every run) with rosco_scheduled, 4 seeds x 600 s.
Needs the rosco package for (2) and (3) (pip install 'specdesign[rosco]').
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from specdesign.fatigue import del_rainflow
from specdesign.rosco import Discon, from_discon, rosco_scheduled, rosco_test_cases, torque_law_from_discon, write_discon
from specdesign.simulate import simulate
from specdesign.turbine import iea15mw

SPEEDS = [5.0, 9.0, 11.0, 13.0]
SEEDS = [1, 2, 3, 4]


def trim_table(model):
    print("## IEA 15 MW trim under its torque law (iea15mw().torque_control, VS_ControlMode 1)")
    law = model.torque_control
    print(f"K = {law.k_opt:.4g} N·m/(rad/s)², min speed {law.min_speed:.4f} rad/s, torque reference speed "
          f"{law.reference_speed:.4f} rad/s, Kp = {law.kp:.4g} N·m·s/rad, Ki = {law.ki:.4g} N·m/rad; "
          f"rated wind speed {model.rated_wind_speed():.3f} m/s")
    print("| v (m/s) | region | Ω (rad/s) | T (MN·m) | pitch (deg) | P (MW) | states | slowest pole (1/s) |")
    print("|---|---|---|---|---|---|---|---|")
    for v in [3.0, 5.0, 7.0, 8.0, 9.0, 10.0, 10.5, 11.0, 13.0, 15.0, 19.0, 25.0]:
        op = model.trim(v)
        sys = model.linearize(v)
        slow = float(np.max(np.linalg.eigvals(sys.A).real))
        print(f"| {v:g} | {op.region} | {op.rotor_speed:.4f} | {op.gen_torque / 1e6:.3f} | {np.degrees(op.pitch):.2f} "
              f"| {op.power / 1e6:.2f} | {sys.nstates} | {slow:.4f} |")


def sds(r, model):
    omega = r["gen_speed"]
    torque = r["power"] / (model.generator_efficiency * omega)
    return [x.std(axis=2).mean(axis=1) for x in (omega, torque, r["pitch"])]


def against_discon(model, mode, folder):
    deck = rosco_test_cases() / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile"
    path = write_discon(deck / "IEA-15-240-RWT-Monopile_DISCON.IN", folder / f"DISCON_{mode}.IN",
                        VS_ControlMode=mode, PS_Mode=0)
    kw = dict(seeds=SEEDS, duration=600.0)
    sched = rosco_scheduled(model, schedule=from_discon(path), scheduling_filter="rosco")
    law = torque_law_from_discon(path)
    simulate(model, sched, [9.0], seeds=[1], duration=10.0, torque_control=law)  # compile
    t0 = time.perf_counter()
    d = simulate(model, Discon(path), SPEEDS, **kw)
    t1 = time.perf_counter()
    s = simulate(model, sched, SPEEDS, torque_control=law, **kw)
    t2 = time.perf_counter()
    print(f"\n## VS_ControlMode {mode}: ROSCO DISCON vs the compiled law, {len(SEEDS)} seeds x 600 s, same wind")
    print("| v (m/s) | Ω SD DISCON (rad/s) | rel. diff | T SD DISCON (kN·m) | rel. diff | pitch SD DISCON (deg) | rel. diff |")
    print("|---|---|---|---|---|---|---|")
    a, b = sds(d, model), sds(s, model)
    for i, v in enumerate(SPEEDS):
        cells = []
        for k, scale in zip(range(3), (1.0, 1e-3, np.degrees(1.0))):
            rel = "held (SD ≈ 0)" if a[k][i] < 1e-9 or (k == 1 and a[k][i] < 1e3) else f"{100 * (b[k][i] / a[k][i] - 1):+.3f} %"
            cells += [f"{a[k][i] * scale:.4g}", rel]
        print(f"| {v:g} | " + " | ".join(cells) + " |")
    n = len(SPEEDS) * len(SEEDS)
    print(f"time for {n} runs: DISCON {t1 - t0:.2f} s, compiled {t2 - t1:.3f} s, ratio {(t1 - t0) / (t2 - t1):.0f}x")


def near_rated(model):
    print("\n## Near rated: torque held at rated above rated ('auto') or ROSCO's law in every run ('rosco')")
    print("| v (m/s) | torque_control | Ω SD (rad/s) | mean power (MW) | tower-base DEL (MN·m, m = 4) |")
    print("|---|---|---|---|---|")
    c = rosco_scheduled(model)
    vs = [11.0, 13.0, 15.0]
    for tc in ("auto", "rosco"):
        r = simulate(model, c, vs, seeds=SEEDS, duration=600.0, torque_control=tc)
        dels = np.array([[del_rainflow(x, 4.0, 600.0) for x in row] for row in r["tower_base_my"]]).mean(axis=1)
        for i, v in enumerate(vs):
            print(f"| {v:g} | {tc} | {r['gen_speed'][i].std(axis=1).mean():.4f} | {r['power'][i].mean() / 1e6:.2f} "
                  f"| {dels[i] / 1e6:.2f} |")


def main():
    model = iea15mw()
    trim_table(model)
    near_rated(model)
    try:
        rosco_test_cases()
    except ModuleNotFoundError as e:
        print(f"\n(no comparison with ROSCO's DISCON: {e})")
        return
    with tempfile.TemporaryDirectory() as tmp:
        for mode in (1, 3):
            against_discon(model, mode, Path(tmp))


if __name__ == "__main__":
    main()
