"""Specification figures and the interactive notch explorer (results in, axes out)."""
from __future__ import annotations

import numpy as np

from ..spec import Baseline, Notch, evaluate

__all__ = ["plot_specification", "NotchExplorer"]


def plot_specification(base: Baseline, specification=None, *, shaping=None, ax=None, scale=1e-3, unit="kN·m/(m/s)"):
    """Bode magnitude of the baseline T_{y,w} and the specification W_y on the baseline grid.

    ``specification`` is a :class:`specdesign.spec.Specification`, or pass ``shaping`` (the
    complex or real |W/T| on ``base.omega``). Magnitudes in dB of ``scale`` × (output/wind),
    ω in rad/s on a log axis.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 3.5))
    w = base.omega
    t_db = 20 * np.log10(np.abs(base.t_response) * scale)
    ax.semilogx(w, t_db, label="baseline $|T_{y,w}|$")
    if specification is not None:
        shaping = specification.response(w) / base.t_response
    if shaping is not None:
        ax.semilogx(w, t_db + 20 * np.log10(np.abs(shaping)), "--", label="specification $|W_y|$")
    ax.set_xlabel("frequency ω (rad/s)")
    ax.set_ylabel(f"magnitude (dB re 1 {unit})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax


class NotchExplorer:
    """One notch on the baseline, live: sliders for ω_n (rad/s), depth (dB) and width (ζ_p).

    ``update(omega_n, depth_db, width)`` recomputes the specification's magnitude and its
    promise (Eq. 10 and exact Dirlik) and refreshes the figure's line and title; it is the
    slider callback, and is timed in ``benchmarks/bench_spec.py``. ``widget()`` returns the
    ipywidgets box (needs ipywidgets; ``%matplotlib widget`` for live redraw in Jupyter).
    """

    def __init__(self, base: Baseline, notch: Notch | None = None, *, scale=1e-3):
        import matplotlib.pyplot as plt

        self.base = base
        self.notch = notch or Notch(1.05, 6.0, 0.2)
        self.fig, (self.ax_mag, self.ax_sens) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
        plot_specification(base, shaping=self.notch.response(base.omega), ax=self.ax_mag, scale=scale)
        self.line = self.ax_mag.get_lines()[-1]
        self._t_db = 20 * np.log10(np.abs(base.t_response) * scale)
        self.ax_sens.semilogx(base.omega, base.sensitivity, color="C2", label="ΔD%(ω) per 1 % of $S_y$")
        self.marker = self.ax_sens.axvline(self.notch.omega_n, color="C1", ls=":", label="notch ω_n")
        self.ax_sens.set_xlabel("frequency ω (rad/s)")
        self.ax_sens.set_ylabel("ΔD% (%)")
        self.ax_sens.grid(True, which="both", alpha=0.3)
        self.ax_sens.legend()
        self.promise = None
        self.update(self.notch.omega_n, self.notch.depth_db, self.notch.width)

    def update(self, omega_n, depth_db, width, *, redraw=True):
        self.notch = Notch(float(omega_n), float(depth_db), float(width))
        shaping = self.notch.response(self.base.omega)
        self.promise = evaluate(shaping, self.base)
        self.line.set_ydata(self._t_db + 20 * np.log10(np.abs(shaping)))
        self.marker.set_xdata([omega_n, omega_n])
        p = self.promise
        self.ax_mag.set_title(
            f"damage −{p.exact_damage:.1f} % (Eq. 10: −{p.predicted_damage:.1f} %), DEL −{p.exact_del:.2f} %"
        )
        if redraw:
            self.fig.canvas.draw_idle()
        return self.promise

    def widget(self):
        import ipywidgets as widgets

        w = self.base.omega
        sliders = dict(
            omega_n=widgets.FloatLogSlider(value=self.notch.omega_n, base=10, min=np.log10(max(w[0], 0.05)), max=np.log10(w[-1]), step=0.005, description="ω_n (rad/s)"),
            depth_db=widgets.FloatSlider(value=self.notch.depth_db, min=0.0, max=30.0, step=0.1, description="depth (dB)"),
            width=widgets.FloatSlider(value=self.notch.width, min=0.02, max=1.0, step=0.01, description="width ζ_p"),
        )
        out = widgets.interactive(self.update, **sliders)
        return out
