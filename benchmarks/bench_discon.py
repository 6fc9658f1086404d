"""ROSCO's compiled DISCON in the simulator: cost of one 600 s run (issue 15).

Run: python benchmarks/bench_discon.py
Target: ≤ 3 s per 600 s run (plus the 60 s transient) through the Python-callable path, one
ctypes call of ROSCO per step (dt = 0.02 s). The compiled rosco_scheduled (same DISCON.IN's
schedule, ROSCO's scheduling filter) is timed beside it: the fast path, as a ratio.
Needs the rosco package (pip install 'specdesign[rosco]').
"""
from __future__ import annotations

from timing import best_of

from specdesign.rosco import Discon, from_discon, rosco_scheduled, rosco_test_cases
from specdesign.simulate import simulate
from specdesign.turbine import iea15mw


def main():
    model = iea15mw()
    path = rosco_test_cases() / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile/IEA-15-240-RWT-Monopile_DISCON.IN"
    discon = Discon(path)
    sched = rosco_scheduled(model, schedule=from_discon(path), scheduling_filter="rosco")
    kw = dict(seeds=[1], duration=600.0, transient=60.0, dt=0.02)
    for c in (discon, sched):  # compile and warm up
        simulate(model, c, [19.0], **{**kw, "duration": 10.0})
    t_discon = best_of(lambda: simulate(model, discon, [19.0], **kw))
    t_sched = best_of(lambda: simulate(model, sched, [19.0], **kw))
    four = best_of(lambda: simulate(model, discon, [15.0, 23.0], seeds=[1, 2], duration=600.0), 1) / 4
    discon.close()
    print(f"DISCON (ctypes, one call per step), one 600 s run:   {t_discon:7.2f} s  (target <= 3 s)")
    print(f"DISCON, per run of a 4-run batch:                     {four:7.2f} s")
    print(f"rosco_scheduled (compiled), one 600 s run:           {t_sched:7.3f} s")
    print(f"ratio DISCON / compiled:                             {t_discon / t_sched:7.1f}x")


if __name__ == "__main__":
    main()
