"""Time the batched nonlinear simulation and a full validation campaign.

Targets (issue 7, printed, not asserted): 48 runs (6 wind speeds × 4 seeds × 600 s × 2
controllers) in < 3 s, 1800 runs (6 × 100 seeds × 3 controllers) in < 60 s, on this 2-core
machine. numba compile time is excluded: every path is run once on a short case first
(warm-up), and the compiled kernels are cached on disk anyway.

The compiled loop's cost is also printed as CPU time per RK4 step and run (time.process_time
over the 48 runs, numba's threads included, divided by 48 × 33 000 steps): on a machine shared
with other processes it moves far less than the wall times, so it is the number to compare two
versions of the loop by (the same command on both).

Run: python benchmarks/bench_simulate.py [--quick]
(--quick: skips the 1800-run case.)
"""
from __future__ import annotations

import dataclasses
import sys
import time

import numpy as np

from specdesign import simulate as sm
from specdesign import turbine
from specdesign import validate as va

SPEEDS = [15.0, 17.0, 19.0, 21.0, 23.0, 25.0]


def _timed(f):
    t0 = time.perf_counter()
    out = f()
    return out, time.perf_counter() - t0


def main(quick=False):
    model = turbine.iea15mw()
    rosco = sm.rosco_scheduled(model)
    single = turbine.rosco_baseline(model, 19.0)
    import control

    atd = control.tf([-0.014187, -0.014187 * 4.357], [1, 0.3276])
    designed = dataclasses.replace(rosco, atd=tuple(atd for _ in rosco.pitch), name="ATD")  # same ROSCO form + ATD
    ctrls = {"ROSCO": rosco, "ATD": designed}
    dt, rdt, transient = 0.02, 0.1, 60.0

    # warm-up (compile or load from cache), excluded from timings
    va.run_campaign(ctrls, [19.0], [1], model=model, duration=20.0, transient=5.0, progress=False)

    # wind synthesised once; simulation alone, all 6 × 4 runs per controller in one batch
    wind, t_wind = _timed(lambda: sm.wind_series(model.rotor_radius, SPEEDS, [1, 2, 3, 4], 600.0 + transient + rdt, rdt))

    def sim48():
        for c in ctrls.values():
            sm.simulate(model, c, SPEEDS, wind=wind, wind_dt=rdt, duration=600.0, dt=dt, record_dt=rdt, transient=transient)

    _, t_sim = _timed(sim48)
    c0 = time.process_time()
    sim48()  # again: the loop checks and controller banks are kept from the call before, the loop is what is left
    cpu_step = (time.process_time() - c0) / (48 * round((600.0 + transient) / dt))
    _, t_one = _timed(lambda: sm.simulate(model, single, SPEEDS, wind=wind, wind_dt=rdt, duration=600.0, dt=dt,
                                          record_dt=rdt, transient=transient))
    _, t_camp = _timed(lambda: va.run_campaign(ctrls, SPEEDS, [1, 2, 3, 4], model=model, progress=False))
    sim_s = 48 * 660.0
    print(f"machine: {__import__('os').cpu_count()} cores; dt = {dt} s (RK4, Tustin controllers), outputs every {rdt} s, "
          f"{transient:g} s transient + 600 s recorded per run; compile time excluded")
    print(f"{'case':58s} {'time (s)':>9s} {'target':>8s} {'ratio':>7s}")
    print(f"{'wind synthesis, 6 speeds × 4 seeds':58s} {t_wind:9.2f}")
    print(f"{f'48 runs, scheduled ROSCO ({len(rosco.pitch)} local PI) + ROSCO+ATD, sim only':58s} {t_sim:9.2f} {3.0:8.1f} {t_sim / 3.0:7.2f}")
    print(f"{'24 runs, one LTI controller (no scheduling), sim only':58s} {t_one:9.2f}")
    print(f"{'48-run campaign: wind + sim + rainflow + Welch + linear pred':58s} {t_camp:9.2f} {3.0:8.1f} {t_camp / 3.0:7.2f}")
    print(f"{'simulated seconds per wall second (48 runs, sim only)':58s} {sim_s / t_sim:9.0f}")
    print(f"{'CPU per RK4 step and run (ns, 48 runs, all threads)':58s} {1e9 * cpu_step:9.0f}  "
          f"(load average {__import__('os').getloadavg()[0]:.1f})")
    # the slow path: a Python callable (numpy PI at 19 m/s, Tustin by hand) called every step
    cd = control.c2d(control.ss(single), dt, "tustin")
    A, B, C, D = (np.asarray(m_, float) for m_ in (cd.A, cd.B, cd.C, cd.D))
    b0 = model.trim(19.0).pitch

    class PythonPI:
        def __init__(self, n):
            self.x = np.zeros((n, A.shape[0]))

        def __call__(self, t, y):
            e = -(y["gen_speed"] - model.rated_rotor_speed)
            u = self.x @ C.ravel() + D.item() * e
            self.x = self.x @ A.T + np.outer(e, B.ravel())
            return b0 + u

    w19 = wind[2:3]
    _, t_call = _timed(lambda: sm.simulate(model, PythonPI(4), [19.0], wind=w19, wind_dt=rdt, duration=600.0, dt=dt,
                                           record_dt=rdt, transient=transient))
    _, t_fast = _timed(lambda: sm.simulate(model, single, [19.0], wind=w19, wind_dt=rdt, duration=600.0, dt=dt,
                                           record_dt=rdt, transient=transient))
    print(f"{'4 runs, Python callable controller (slow path)':58s} {t_call:9.2f}")
    print(f"{'4 runs, same controller compiled':58s} {t_fast:9.2f} {'':8s} {t_call / t_fast:6.0f}x")
    if not quick:
        ctrls3 = {"ROSCO": rosco, "ATD": designed, "PI19": single}
        seeds = list(range(1, 101))
        _, t_big = _timed(lambda: va.run_campaign(ctrls3, SPEEDS, seeds, model=model, progress=False, predict=False))
        print(f"{'1800-run campaign (6 × 100 seeds × 3 ctrl), no predictions':58s} {t_big:9.2f} {60.0:8.1f} {t_big / 60.0:7.2f}")


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
