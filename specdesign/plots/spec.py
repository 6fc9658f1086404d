"""Specification figures and the interactive notch explorer (results in, axes out).

Magnitudes in dB re 1 SI unit of the output per m/s (:mod:`specdesign.plots.conventions`), ω in rad/s.
"""
from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from loopshaping.interactive import LiveArtists, readout_html

from ..spec import Baseline, Notch, promise_of
from .conventions import tf_magnitude_label

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..spec import Promise, Specification

__all__ = ["plot_specification", "NotchExplorer", "plot_frontier"]


def plot_specification(base: Baseline, specification: Specification | None = None, *, shaping: ArrayLike | None = None,
                       ax: Axes | None = None) -> Axes:
    """Bode magnitude of the baseline T_{y,w} and the specification W_y on the baseline grid.

    Magnitudes in dB re 1 SI unit of the output per m/s (for the tower-base moment, dB re
    1 N·m/(m/s), as every transfer-function figure of the workbench), ω in rad/s on a log axis.

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
    t_db = 20 * np.log10(np.abs(base.t_response))
    ax.semilogx(w, t_db, label="baseline $|T_{y,w}|$")
    if specification is not None:
        shaping = specification.response(w) / base.t_response
    if shaping is not None:
        ax.semilogx(w, t_db + 20 * np.log10(np.abs(shaping)), "--", label="specification $|W_y|$")
    ax.set_xlabel("frequency ω (rad/s)")
    ax.set_ylabel(tf_magnitude_label(base.output or "tower_base_my"))
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
    checker : specdesign.feasibility.PitchChecker, optional
        With a generator-speed specification fixed (:func:`specdesign.feasibility.pitch_checkers`),
        every update also says, in the title, whether ROSCO's map × the notch can be met
        through the pitch at all (:attr:`verdict`).
    bounds_checker : specdesign.qft.boundscheck.BoundsChecker, optional
        The pitch loop's QFT problem at the same speed (:func:`specdesign.qft.boundscheck.bounds_checker`):
        every update also says whether the QFT bounds of ROSCO's map × the notch are empty
        anywhere (:attr:`bounds_verdict`). The explorer calls its
        :meth:`~specdesign.qft.boundscheck.BoundsChecker.precompute` (about 1 s, once), so
        a move decides the verdict by comparisons instead of a bound computation (35-70 ms).
    live : bool, optional
        Redraw a move by blitting the line, marker, title and legend on a cached background
        (:class:`loopshaping.interactive.LiveArtists`); default: on ipympl's canvas
        (``%matplotlib widget``), where a full redraw of the two log axes takes 0.1-0.2 s.

    Attributes
    ----------
    notch : specdesign.spec.Notch
        The current notch.
    promise : specdesign.spec.Promise
        Its promise against ``base``, %.
    verdict : specdesign.feasibility.PitchFeasibility or None
        The feasibility verdict of the last update (with a ``checker``).
    bounds_verdict : specdesign.qft.boundscheck.BoundsVerdict or None
        The QFT bounds' verdict of the last update (with a ``bounds_checker``).
    fig : matplotlib.figure.Figure
        The figure.
    update_ms : float
        Wall time of the last :meth:`update` in the kernel (compute, artist data and the
        blit or the redraw request), ms: what a slider move costs before the browser shows it.
    readout : str
        What the last update says: the notch (ω_n, depth, width) and its promise and verdicts,
        one per line. The figure shows it in its title and legend, or, on a live figure shown
        by :meth:`widget`, a readout above the figure does (the figure's legend then names the
        specification only, and its title is drawn into saved figures only).

    Examples
    --------
    >>> from specdesign.plots.spec import NotchExplorer
    >>> from specdesign.spec import baseline_analysis
    >>> from specdesign.turbine import iea15mw
    >>> explorer = NotchExplorer(baseline_analysis(iea15mw(), 19.0))
    >>> p = explorer.update(1.0, 6.0, 0.2, redraw=False)
    >>> print(f"damage −{p.exact_damage:.1f} %")
    damage −28.1 %
    """

    def __init__(self, base: Baseline, notch: Notch | None = None, *, checker: Any = None,
                 bounds_checker: Any = None, live: bool | None = None):
        import matplotlib.pyplot as plt

        self.base = base
        self.checker = checker
        self.verdict = None
        self.bounds_checker = bounds_checker if bounds_checker is None else bounds_checker.precompute()
        self.bounds_verdict = None
        self.notch = notch or Notch(1.05, 6.0, 0.2)
        # not shown by pyplot at the end of the cell: widget() shows it once, with the sliders
        with plt.ioff():
            self.fig, (self.ax_mag, self.ax_sens) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
        plot_specification(base, shaping=self.notch.response(base.omega), ax=self.ax_mag)
        self.line = self.ax_mag.get_lines()[-1]
        self.ax_mag.set_xlabel("")  # the axes share ω: its label once, under the lower one
        self._t_db = 20 * np.log10(np.abs(base.t_response))
        self.ax_sens.semilogx(base.omega, base.sensitivity, color="C2", label="ΔD%(ω) per 1 % of $S_y$")
        self.marker = self.ax_sens.axvline(self.notch.omega_n, color="C1", ls=":", label="notch ω_n")
        self.ax_sens.set_xlabel("frequency ω (rad/s)")
        self.ax_sens.set_ylabel("ΔD% (%)")
        self.ax_sens.grid(True, which="both", alpha=0.3)
        self.ax_sens.legend()
        # one legend, its entry for the notch relabelled by every move (a new legend per move
        # would be a new artist to draw in full)
        self._legend = self.ax_mag.legend(fontsize=8, loc="lower left")
        self._legend_text = self._legend.get_texts()[self.ax_mag.get_legend_handles_labels()[0].index(self.line)]
        self.promise = None
        self._out = None  # the ipywidgets Output a static (non-ipympl) figure is shown in
        self._sliders, self._sent, self._quiet = None, {}, False  # the widget's sliders, once built
        self.readout = ""
        self._readout_widget = None  # the ipywidgets.HTML above a live figure showing the readout
        if hasattr(self.fig.canvas, "header_visible"):  # ipympl: no "Figure n" label above the plot
            self.fig.canvas.header_visible = False
            self.fig.canvas.toolbar_position = "right"  # beside the figure, not over its labels
        self._redraw = LiveArtists(self.fig, [self.line, self.marker, self.ax_mag.title, self._legend], live)
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
            Show the move: blit the changed artists on ipympl's canvas, else ask for a full
            redraw (``draw_idle``).

        Returns
        -------
        specdesign.spec.Promise
            The notch's promise against the baseline, %.

        Raises
        ------
        ValueError
            If the notch parameters are invalid (:class:`specdesign.spec.Notch`).
        """
        t0 = time.perf_counter()
        self.notch = Notch(float(omega_n), float(depth_db), float(width))
        at = f"notch at {self.notch.omega_n:.3g} rad/s, {self.notch.depth_db:.3g} dB, ζ_p = {self.notch.width:.3g}"
        if self._readout_widget is None:  # the figure says it (the readout widget does beside a live one)
            self.line.set_label(f"specification $|W_y|$: {at}")
            self._legend_text.set_text(self.line.get_label())
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
        if self.bounds_checker is not None:
            b = self.bounds_checker
            self.bounds_verdict = b.check(b.rosco_nominal * self.notch.response(b.template.omega))
            title += "\n" + self.bounds_verdict.summary()
        self.readout = f"{at}\n{title}"
        if self._readout_widget is None:
            self.ax_mag.set_title(title, fontsize=9)
        else:  # drawn into a saved figure only, which says where the notch is in its title then
            self.ax_mag.set_title(self.readout, fontsize=9)
            self._readout_widget.value = readout_html(self.readout)
        if self._sliders is not None:  # a call from code: the sliders follow (not a move)
            self._quiet = True
            try:
                for k, sl in self._sliders.items():
                    v = getattr(self.notch, k)
                    if sl.value != v:
                        sl.value = v
                        self._sent[k].append(sl.value)  # as clamped to the slider's range
            finally:
                self._quiet = False
        if redraw:
            self._redraw.redraw()
            if self._out is not None:
                self._show()
        self.update_ms = 1e3 * (time.perf_counter() - t0)
        return self.promise

    @classmethod
    def from_session(cls, session: Any, name: str | None = None, *, checker: Any = None) -> "NotchExplorer":
        """An explorer starting from a saved design session's specification.

        The baseline is recomputed from the session's model at the specification's wind speed
        (:meth:`specdesign.session.Session.baseline`), the notch is the specification's first.

        Parameters
        ----------
        session : specdesign.session.Session or str or os.PathLike
            A session record, or the path of a session file (:func:`specdesign.session.load_session`).
        name : str, optional
            Which specification (default: the only one, or the first saved).
        checker : specdesign.feasibility.PitchChecker, optional
            As for the constructor.

        Returns
        -------
        NotchExplorer
            The explorer, its notch and promise those of the saved specification.

        Raises
        ------
        ValueError
            If the session holds no specification, ``name`` is not one of them, or the
            specification has no notch.
        """
        from ..session import Session, load_session

        if not isinstance(session, Session):
            session = load_session(session)
        name = session.specification_name(name)
        notches = [e for e in session.specifications[name].elements if isinstance(e, Notch)]
        if not notches:
            raise ValueError(f"specification {name!r} of the session has no notch for the explorer to move")
        return cls(session.baseline(name), notches[0], checker=checker)

    def _show(self):
        from IPython.display import clear_output, display

        with self._out:
            clear_output(wait=True)
            display(self.fig)

    def widget(self) -> Any:
        """Sliders for ω_n, depth and width wired to :meth:`update`, above the figure (shown once).

        The starting notch is kept exactly: the browser rounds a slider's value to its step and
        sends it back (possibly after later cells ran), and an event within half a step of a value
        Python set since the last move is taken for that echo, not for a move. :meth:`update`
        called from code moves the sliders too.

        Returns
        -------
        ipywidgets.VBox
            The sliders and the figure (needs ipywidgets; with ``%matplotlib widget`` the
            figure is the live canvas, under a readout of :attr:`readout`, otherwise a static
            image re-shown on every move).
        """
        import ipywidgets as widgets

        w = self.base.omega
        n = self.notch
        sliders = dict(
            omega_n=widgets.FloatLogSlider(value=n.omega_n, base=10, min=np.log10(max(w[0], 0.05)), max=np.log10(w[-1]),
                                           step=0.005, description="ω_n (rad/s)", readout_format=".4g"),
            depth_db=widgets.FloatSlider(value=n.depth_db, min=0.0, max=30.0, step=0.1, description="depth (dB)",
                                         readout_format=".3g"),
            width=widgets.FloatSlider(value=n.width, min=0.02, max=1.0, step=0.01, description="width ζ_p",
                                      readout_format=".3g"),
        )

        self._sliders, self._sent = sliders, {k: [getattr(n, k)] for k in sliders}

        def moved(change, name):
            if self._quiet:
                return
            new = change["new"]
            # The browser rounds each value set from Python to the slider's step and sends it
            # back, possibly after later cells have set others: within half a step of a value
            # Python set since the last move, it is such an echo, not a move.
            gap = (lambda a, b: abs(np.log10(a / b))) if name == "omega_n" else (lambda a, b: abs(a - b))
            if min(gap(new, v) for v in self._sent[name]) < 0.5 * sliders[name].step:
                # an echo: not a move, but the slider now shows it; put back the value the figure
                # draws (notebook 03 showed 2.80 dB over a 12 dB notch after Run All), unless the
                # echo is that value rounded to the step (then it already says the same)
                current = getattr(self.notch, name)
                if gap(new, current) >= 0.5 * sliders[name].step:
                    self._quiet = True
                    try:
                        sliders[name].value = current
                        self._sent[name].append(sliders[name].value)
                    finally:
                        self._quiet = False
                return
            self._sent[name] = [new]
            vals = dict(omega_n=self.notch.omega_n, depth_db=self.notch.depth_db, width=self.notch.width)
            vals[name] = new
            self.update(**vals)

        for name, sl in sliders.items():
            sl.observe(lambda change, name=name: moved(change, name), names="value")
        canvas = self.fig.canvas
        readout = []
        if isinstance(canvas, widgets.DOMWidget):
            fig_box = canvas
            if self._redraw.live and self._readout_widget is None:
                # the changing lines leave the live canvas for a readout above it: drawn at every
                # move they were most of a redraw (text costs about 0.1 ms a glyph, a new mathtext
                # legend label a parse, and their pixels go to the browser)
                self._readout_widget = widgets.HTML()
                self.line.set_label("specification $|W_y|$ with the notch")
                self._legend_text.set_text(self.line.get_label())
                self._redraw.settle(self._legend)
                self._redraw.print_only(self.ax_mag.title)
                self.update(self.notch.omega_n, self.notch.depth_db, self.notch.width, redraw=False)
            readout = [self._readout_widget] if self._readout_widget is not None else []
        else:
            fig_box = self._out = widgets.Output()
            self._show()
        return widgets.VBox([widgets.VBox(list(sliders.values())), *readout, fig_box])


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
