"""Specification figures and the interactive notch explorer (results in, axes out).

Magnitudes in dB (of the output per m/s, times a display ``scale``), ω in rad/s.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from ..spec import Baseline, Notch, promise_of

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..spec import Promise, Specification

__all__ = ["plot_specification", "NotchExplorer", "plot_frontier"]


def plot_specification(base: Baseline, specification: Specification | None = None, *, shaping: ArrayLike | None = None,
                       ax: Axes | None = None, scale: float = 1e-3, unit: str = "kN·m/(m/s)") -> Axes:
    """Bode magnitude of the baseline T_{y,w} and the specification W_y on the baseline grid.

    Magnitudes in dB of ``scale`` × (output/wind), ω in rad/s on a log axis.

    Parameters
    ----------
    base : specdesign.spec.Baseline
        The baseline (:func:`specdesign.spec.baseline_analysis`): its grid and T_{y,w}.
    specification : specdesign.spec.Specification, optional
        The specification W_y to draw over the baseline.
    shaping : array_like, optional
        Instead of ``specification``: the complex or real shaping W/T on ``base.omega`` (-).
        Ignored when ``specification`` is given.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new pyplot figure).
    scale : float
        Display factor of the magnitudes (1e-3: N·m → kN·m).
    unit : str
        Unit of ``scale`` × output per m/s, for the axis label.

    Returns
    -------
    matplotlib.axes.Axes
        The axes.

    Examples
    --------
    >>> from specdesign.plots.spec import plot_specification
    >>> from specdesign.spec import baseline_analysis, shape_to_target
    >>> from specdesign.turbine import iea15mw
    >>> base = baseline_analysis(iea15mw(), 19.0)
    >>> ax = plot_specification(base, shape_to_target(base, 15.0).specification)
    >>> len(ax.get_lines())
    2
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
    The figure has two axes: the magnitudes (:func:`plot_specification`) and ΔD%(ω).

    Parameters
    ----------
    base : specdesign.spec.Baseline
        The baseline (:func:`specdesign.spec.baseline_analysis`).
    notch : specdesign.spec.Notch, optional
        Initial notch (default 6 dB deep, width 0.2, at 1.05 rad/s).
    scale : float
        Display factor of the magnitudes (1e-3: N·m → kN·m).
    checker : specdesign.feasibility.PitchChecker, optional
        With a generator-speed specification fixed (:func:`specdesign.feasibility.pitch_checkers`),
        every update also says, in the title, whether ROSCO's map × the notch can be met
        through the pitch at all (:attr:`verdict`).

    Attributes
    ----------
    notch : specdesign.spec.Notch
        The current notch.
    promise : specdesign.spec.Promise
        Its promise against ``base``, %.
    verdict : specdesign.feasibility.PitchFeasibility or None
        The feasibility verdict of the last update (with a ``checker``).
    fig : matplotlib.figure.Figure
        The figure.

    Examples
    --------
    >>> from specdesign.plots.spec import NotchExplorer
    >>> from specdesign.spec import baseline_analysis
    >>> from specdesign.turbine import iea15mw
    >>> explorer = NotchExplorer(baseline_analysis(iea15mw(), 19.0))
    >>> p = explorer.update(1.0, 6.0, 0.2, redraw=False)
    >>> print(f"damage −{p.exact_damage:.1f} %")
    damage −28.4 %
    """

    def __init__(self, base: Baseline, notch: Notch | None = None, *, scale: float = 1e-3, checker: Any = None):
        import matplotlib.pyplot as plt

        self.base = base
        self.checker = checker
        self.verdict = None
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

    def update(self, omega_n: float, depth_db: float, width: float, *, redraw: bool = True) -> Promise:
        """Move the notch: recompute its promise and refresh the line, marker and title.

        Parameters
        ----------
        omega_n : float
            Centre frequency, rad/s.
        depth_db : float
            Depth, dB (> 0 attenuates).
        width : float
            Pole damping ratio ζ_p (-, 0 < width ≤ 2).
        redraw : bool
            Ask the canvas to redraw (``draw_idle``).

        Returns
        -------
        specdesign.spec.Promise
            The notch's promise against the baseline, %.

        Raises
        ------
        ValueError
            If the notch parameters are invalid (:class:`specdesign.spec.Notch`).
        """
        self.notch = Notch(float(omega_n), float(depth_db), float(width))
        shaping = self.notch.response(self.base.omega)
        self.promise = promise_of(shaping, self.base)
        self.line.set_ydata(self._t_db + 20 * np.log10(np.abs(shaping)))
        self.marker.set_xdata([omega_n, omega_n])
        p = self.promise
        title = f"damage −{p.exact_damage:.1f} % (Eq. 10: −{p.predicted_damage:.1f} %), DEL −{p.exact_del:.2f} %"
        if self.checker is not None:
            c = self.checker
            self.verdict = c.check(c.t_rosco * np.abs(self.notch.response(c.omega)))
            if self.verdict.feasible:
                title += "\npitch: feasible (necessary conditions)"
            else:
                bad = c.omega[np.array(self.verdict.binding) != ""]
                where = f"{bad.min():.3g}-{bad.max():.3g} rad/s" if bad.size else "the RHP zero"
                title += f"\npitch: INFEASIBLE at {where}"
        self.ax_mag.set_title(title, fontsize=9)
        if redraw:
            self.fig.canvas.draw_idle()
        return self.promise

    def widget(self) -> Any:
        """Sliders for ω_n, depth and width wired to :meth:`update`.

        Returns
        -------
        ipywidgets.interactive
            The widget box (needs ipywidgets; ``%matplotlib widget`` for live redraw in Jupyter).
        """
        import ipywidgets as widgets

        w = self.base.omega
        sliders = dict(
            omega_n=widgets.FloatLogSlider(value=self.notch.omega_n, base=10, min=np.log10(max(w[0], 0.05)), max=np.log10(w[-1]), step=0.005, description="ω_n (rad/s)"),
            depth_db=widgets.FloatSlider(value=self.notch.depth_db, min=0.0, max=30.0, step=0.1, description="depth (dB)"),
            width=widgets.FloatSlider(value=self.notch.width, min=0.02, max=1.0, step=0.01, description="width ζ_p"),
        )
        out = widgets.interactive(self.update, **sliders)
        return out


def plot_frontier(frontiers: dict, ax: Axes | None = None) -> Axes:
    """The pitch-control frontier: promised DEL reduction vs allowed generator-speed degradation.

    Parameters
    ----------
    frontiers : dict
        Wind speed (m/s) → the result of :func:`specdesign.feasibility.pitch_frontier` at that
        speed. Solid lines with markers: the achievable promise (a stabilising design meets
        it); dashed, same colour: the pointwise upper bound no controller beats.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).

    Returns
    -------
    matplotlib Axes
        The axes drawn on.
    """
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6.4, 4.2))
    for k, (v, f) in enumerate(sorted(frontiers.items())):
        color = f"C{k}"
        ax.plot(f["speed_relax_db"], f["achievable"], "o-", color=color, label=f"{v:g} m/s achievable")
        ax.plot(f["speed_relax_db"], f["bound"], "--", color=color, lw=1, label=f"{v:g} m/s upper bound")
    ax.set_xlabel("generator-speed specification relaxed over ROSCO's [dB]")
    ax.set_ylabel("tower-base DEL reduction vs ROSCO [%]")
    ax.set_title("Pitch control only: what a specification can promise")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="center right")
    return ax
