"""Specification benchmarks: the interactive notch callback and the automatic shaper.

Run: python benchmarks/bench_spec.py
Target: the slider callback (notch response, Eq. 10, exact Dirlik, line update) < 100 ms.
"""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
from timing import best_of

from specdesign import spec  # noqa: E402
from specdesign.plots.spec import NotchExplorer  # noqa: E402
from specdesign.turbine import iea15mw  # noqa: E402


def main():
    model = iea15mw()
    base = spec.baseline_analysis(model, 19.0)
    explorer = NotchExplorer(base)
    rng = np.random.default_rng(0)

    def callback(redraw):
        explorer.update(rng.uniform(0.8, 1.4), rng.uniform(0, 20), rng.uniform(0.05, 0.8), redraw=redraw)

    t_cb = best_of(lambda: callback(False), 50)
    t_render = best_of(lambda: (callback(False), explorer.fig.canvas.draw()), 10)
    # as on ipympl's canvas: the line, marker, title and legend blitted on the cached background
    live = NotchExplorer(base, live=True)
    live.fig.canvas.draw()
    t_blit = best_of(lambda: live.update(rng.uniform(0.8, 1.4), rng.uniform(0, 20), rng.uniform(0.05, 0.8)), 10)
    t_compute = best_of(lambda: spec.promise_of(spec.Notch(1.05, 6.0, 0.2).response(base.omega), base), 200)
    t_base = best_of(lambda: spec.baseline_analysis(model, 19.0), 5)
    t_shape = best_of(lambda: spec.shape_to_target(base, 15.0), 5)
    print("specification benchmarks (best of N, 400-point grid)")
    print(f"  slider callback (compute + artist data): {t_cb * 1e3:8.2f} ms   target < 100 ms  -> {100e-3 / t_cb:6.0f}x under")
    print(f"  same + full Agg render of the figure:    {t_render * 1e3:8.2f} ms   (a full redraw: inline, static figures)")
    print(f"  same + blitted redraw (ipympl's path):   {t_blit * 1e3:8.2f} ms   (the browser shows the PNG diff after it)")
    print(f"    of which promise (Eq. 10 + Dirlik):     {t_compute * 1e3:8.3f} ms")
    print(f"  baseline analysis (linearise, loop, ΔD%): {t_base * 1e3:8.1f} ms")
    print(f"  shape_to_target 15 % at 19 m/s:           {t_shape * 1e3:8.1f} ms")


if __name__ == "__main__":
    main()
