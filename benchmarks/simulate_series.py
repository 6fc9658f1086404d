"""Series of seven simulator cases saved, or compared bit for bit with a saved set: the check that a
refactor of the compiled loop (e.g. its parameters grouped into records) changes no number.

Cases (60 s recorded after 10 s): ROSCO's LTI baseline at 15/19/23 m/s × 2 seeds, ROSCO's
gain-scheduled PI at 13 and 19 m/s and below rated at 8 and 10 m/s (torque law), the linearised
plant, an output-blended schedule with an ATD on every local, a 17 m/s baseline, and a callable
PI (the slow path).

Run: ``python benchmarks/simulate_series.py save before.npz`` on the old code,
``python benchmarks/simulate_series.py compare before.npz`` on the new (exit status 1 on any
difference). Run on the change that grouped ``_run_one``'s parameters: 63 series, none differs.
"""
from __future__ import annotations

import sys

import control
import numpy as np

from specdesign.simulate import ScheduledController, rosco_scheduled, simulate
from specdesign.turbine import iea15mw, rosco_baseline


class _CallablePI:
    """A PI on the generator speed as a Python callable (the simulator's slow path)."""

    def start(self, dt, wind, pitch, torque):
        self.b0, self.dt, self.i = pitch, dt, 0.0

    def __call__(self, t, y):
        e = y["gen_speed"] - 0.7917
        self.i = self.i + e * self.dt
        return self.b0 + 0.5 * e + 0.1 * self.i


def series() -> dict:
    """Case/output name → (W, S, n) array."""
    m = iea15mw()
    kw = dict(duration=60.0, transient=10.0)
    atd = control.tf([0.02], [1.0, 0.5])
    sc = ScheduledController(np.array([0.1, 0.3]), (rosco_baseline(m, 15.0), rosco_baseline(m, 21.0)), (atd, atd), name="o")
    runs = {
        "lti": simulate(m, rosco_baseline(m, 19.0), [15.0, 19.0, 23.0], seeds=[1, 2], **kw),
        "sched": simulate(m, rosco_scheduled(m), [13.0, 19.0], seeds=[3], **kw),
        "below": simulate(m, rosco_scheduled(m), [8.0, 10.0], seeds=[1], **kw),
        "linear": simulate(m, rosco_baseline(m, 19.0), [19.0], seeds=[1], linear=True, **kw),
        "atd": simulate(m, sc, [15.0, 21.0], seeds=[2], **kw),
        "lti17": simulate(m, rosco_baseline(m, 17.0), [17.0], seeds=[4], **kw),
        "callable": simulate(m, _CallablePI(), [19.0], seeds=[1], **kw),
    }
    return {f"{case}/{k}": v for case, r in runs.items() for k, v in r.outputs.items()}


def main() -> None:
    if len(sys.argv) != 3 or sys.argv[1] not in ("save", "compare"):
        raise SystemExit("usage: simulate_series.py save|compare FILE.npz")
    now = series()
    if sys.argv[1] == "save":
        np.savez(sys.argv[2], **now)
        print(f"saved {len(now)} series to {sys.argv[2]}")
        return
    old = np.load(sys.argv[2])
    differ = sorted(k for k in old.files if k not in now or not np.array_equal(old[k], now[k]))
    print(f"{len(old.files)} series compared, {len(differ)} differ" + (f": {differ}" if differ else ""))
    raise SystemExit(1 if differ else 0)


if __name__ == "__main__":
    main()
