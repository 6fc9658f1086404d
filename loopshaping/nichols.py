"""Nichols charts: bounds, the nominal loop, templates and M-contours (dB vs degrees).

Numbers first (:func:`loop_nichols`, :func:`m_contour`), drawing second (:func:`draw`,
:func:`plot_templates`); matplotlib is imported only inside the drawing functions.
Bounds are drawn the way QFT Toolbox users read them: one colour per design frequency,
solid = lower bound (the loop must pass above), dashed = upper bound (must pass below); the
legend says so. Bounds repeat every 360°, so the loop is wrapped into the chart's phase window
(:func:`wrap_phase`) and broken where it wraps: a loop whose phase runs past −360° stays on
the chart, each design-frequency marker where the bounds are.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .bounds import Bounds
from .controller import Controller
from .freqresp import check_grid, evaluate
from .templates import Template

if TYPE_CHECKING:  # annotations only
    import matplotlib

__all__ = ["draw", "loop_nichols", "m_contour", "plot_templates", "template_nichols", "wrap_phase"]


def loop_nichols(loop: object, omega: ArrayLike, phase_window: tuple = (-360.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Phase (degrees, unwrapped) and magnitude (dB) of a loop on the grid ``omega``.

    Parameters
    ----------
    loop : control LTI or Controller or array_like
        A SISO LTI, a :class:`~loopshaping.controller.Controller` or a complex response on
        ``omega``.
    omega : array_like
        Frequencies, rad/s, strictly increasing.
    phase_window : tuple of float
        ``(low, high)`` degrees: the unwrapped phase is shifted by a multiple of 360° so
        that its first point lies in it.

    Returns
    -------
    phase_deg : numpy.ndarray
        Unwrapped phase, degrees.
    magnitude_db : numpy.ndarray
        Magnitude, dB.

    Raises
    ------
    ValueError
        For a bad grid or a response of another shape.

    Examples
    --------
    >>> import control as ct
    >>> ph, mag = loop_nichols(ct.tf([1], [1, 0]), [1.0])
    >>> float(ph[0]), float(mag[0])
    (-90.0, 0.0)
    """
    w = check_grid(omega, "omega")
    if isinstance(loop, Controller):
        L = loop.response(w)
    elif isinstance(loop, np.ndarray) or isinstance(loop, (list, tuple)):
        L = np.asarray(loop, complex)
        if L.shape != w.shape:
            raise ValueError(f"loop response must have the shape of omega {w.shape}")
    else:
        L = evaluate(loop, w, "loop")
    phase = np.degrees(np.unwrap(np.angle(L)))
    lo, hi = phase_window
    phase = phase - 360.0 * np.floor((phase[0] - lo) / 360.0)
    if phase[0] > hi:
        phase -= 360.0
    with np.errstate(divide="ignore"):
        return phase, 20 * np.log10(np.abs(L))


def wrap_phase(phase_deg: ArrayLike, magnitude_db: ArrayLike, window: tuple = (-360.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """A Nichols curve wrapped into one 360° phase window, broken where it wraps.

    Bounds and M-contours repeat every 360°, so a loop point at φ − 360° belongs on the chart
    at φ. Each point is moved by a multiple of 360° into ``[low, low + 360)``; where the curve
    leaves the window it is drawn to the edge (magnitude interpolated linearly in phase), a NaN
    breaks the line, and it re-enters from the opposite edge: no line is drawn across the chart.

    Parameters
    ----------
    phase_deg : array_like
        1-D unwrapped phases of the curve, degrees (e.g. from :func:`loop_nichols`).
    magnitude_db : array_like
        Magnitudes, dB, the shape of ``phase_deg``.
    window : tuple of float
        ``(low, high)`` degrees, ``high > low``; points are wrapped into ``[low, low + 360)``.

    Returns
    -------
    phase_deg : numpy.ndarray
        Wrapped phases, degrees, with edge points and NaN breaks inserted at each wrap.
    magnitude_db : numpy.ndarray
        Magnitudes, dB, aligned with the returned phases.

    Raises
    ------
    ValueError
        If the arrays are not 1-D of one shape, or ``window`` is not finite and increasing.

    Examples
    --------
    >>> ph, mag = wrap_phase([-300.0, -420.0], [0.0, -12.0])
    >>> ph.tolist()
    [-300.0, -360.0, nan, 0.0, -60.0]
    >>> mag.tolist()
    [0.0, -6.0, nan, -6.0, -12.0]
    """
    ph = np.asarray(phase_deg, dtype=float)
    mag = np.asarray(magnitude_db, dtype=float)
    if ph.ndim != 1 or mag.shape != ph.shape:
        raise ValueError(f"phase_deg and magnitude_db must be 1-D of one shape; got {ph.shape} and {mag.shape}")
    lo, hi = _check_window(window)
    k = np.floor((ph - lo) / 360.0)
    wrapped = ph - 360.0 * k
    dk = np.diff(k)
    cuts = np.flatnonzero(np.isfinite(dk) & (dk != 0))
    if cuts.size == 0:
        return wrapped, mag.copy()
    ph_parts, mag_parts, start = [], [], 0
    for i in cuts:
        ph_parts.append(wrapped[start:i + 1])
        mag_parts.append(mag[start:i + 1])
        if abs(dk[i]) == 1:
            # the crossing of the window edge, so the curve reaches the edge on both sides
            edge = lo + 360.0 * max(k[i], k[i + 1])
            t = (edge - ph[i]) / (ph[i + 1] - ph[i])
            m = mag[i] + t * (mag[i + 1] - mag[i])
            ph_parts.append(np.array([edge - 360.0 * k[i], np.nan, edge - 360.0 * k[i + 1]]))
            mag_parts.append(np.array([m, np.nan, m]))
        else:  # more than a turn between two grid points: nothing sensible to join
            ph_parts.append(np.array([np.nan]))
            mag_parts.append(np.array([np.nan]))
        start = i + 1
    ph_parts.append(wrapped[start:])
    mag_parts.append(mag[start:])
    return np.concatenate(ph_parts), np.concatenate(mag_parts)


def _check_window(window):
    try:
        lo, hi = (float(x) for x in window)
    except (TypeError, ValueError):
        raise ValueError(f"window={window!r} must be a (low, high) pair of phases in degrees") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and hi > lo):
        raise ValueError(f"window={window!r} must be finite with high > low (degrees), e.g. (-360, 0)")
    return lo, hi


def _omega_label(w):
    """ω in rad/s to 3 significant figures, without exponent notation (0.04642 → 0.0464)."""
    return "ω = " + np.format_float_positional(float(w), precision=3, unique=True, fractional=False, trim="-") + " rad/s"


def m_contour(m_db: float, phases_deg: ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Nichols curve of constant closed-loop gain |L/(1+L)| = M.

    For each phase φ the open-loop magnitude y solves y²(1 − M²) − 2M²cos(φ)·y − M² = 0
    (closed form).

    Parameters
    ----------
    m_db : float
        M, dB.
    phases_deg : array_like, optional
        Open-loop phases, degrees; default −359.5…−0.5 in 0.5° steps.

    Returns
    -------
    phase_deg : numpy.ndarray
        Phases, degrees, the two branches separated by NaN.
    magnitude_db : numpy.ndarray
        Open-loop magnitudes, dB (NaN where M is not reached).
    """
    phases = np.linspace(-359.5, -0.5, 719) if phases_deg is None else np.asarray(phases_deg, float)
    M2 = 10 ** (m_db / 10)
    a, b, c = 1 - M2, -2 * M2 * np.cos(np.deg2rad(phases)), -M2 * np.ones_like(phases)
    with np.errstate(invalid="ignore", divide="ignore"):
        if abs(a) < 1e-12:
            roots = np.stack([-c / b, np.full_like(phases, np.nan)])
        else:
            disc = np.sqrt(b * b - 4 * a * c)
            roots = np.stack([(-b + disc) / (2 * a), (-b - disc) / (2 * a)])
        roots = np.where(roots > 0, roots, np.nan)
        mags = 20 * np.log10(roots)
    ph = np.concatenate([phases, [np.nan], phases[::-1]])
    return ph, np.concatenate([mags[0], [np.nan], mags[1][::-1]])


def _colours(n):
    from matplotlib import colormaps

    cmap = colormaps["tab10" if n <= 10 else "viridis"]
    return [cmap(i if n <= 10 else i / max(n - 1, 1)) for i in range(n)]


def _tiles(phases, lo, hi):
    """Shifts (multiples of 360°) that bring a periodic curve on ``phases`` into [lo, hi]."""
    k = np.arange(np.floor((lo - phases.max()) / 360.0), np.ceil((hi - phases.min()) / 360.0) + 1)
    s = 360.0 * k
    return s[(phases.max() + s > lo) & (phases.min() + s < hi)]


def _draw_bounds(ax, bounds, lo, hi, colours):
    """The lower (solid) and upper (dashed) bounds of every design frequency, tiled over the
    window [lo, hi] degrees, with the legend entries (or a colour key) and the styles' meaning."""
    design = bounds.omega
    lower, upper = bounds.edges()
    ph = bounds.phases_deg
    shifts = _tiles(ph, lo, hi)
    styles = set()
    for i, w in enumerate(design):
        lab = _omega_label(w) + (": EMPTY bound" if bounds.empty[i] else "")
        # One artist per frequency and style (curves joined by NaN breaks): fast redraws.
        for edge, style in ((lower, "-"), (upper, "--")):
            curves = edge[i].T[np.any(np.isfinite(edge[i].T), axis=1)]
            if curves.size:
                xs = np.concatenate([np.r_[ph + d, np.nan] for d in shifts for _ in curves])
                ys = np.concatenate([np.r_[c, np.nan] for _ in shifts for c in curves])
                ax.plot(xs, ys, style, color=colours[i], lw=1.5, label=lab)
                styles.add(style)
                lab = None
        if lab is not None:  # no curve to carry the frequency's legend entry
            ax.plot([], [], "-", color=colours[i], lw=1.5, label=lab)
    if len(design) > 10:
        # dozens of frequencies share a continuous colour map: a colour key says which
        # colour is which frequency (a legend of dozens of entries would say nothing)
        from matplotlib import colormaps
        from matplotlib.cm import ScalarMappable
        from matplotlib.colors import LogNorm

        key = ScalarMappable(norm=LogNorm(design.min(), design.max()), cmap=colormaps["viridis"])
        ax.figure.colorbar(key, ax=ax, pad=0.01, fraction=0.05, label="bound frequency ω (rad/s)")
    # Legend-only entries (no data) saying what the line styles mean, in a neutral grey.
    meaning = {"-": "solid: lower bound, L0 must pass above", "--": "dashed: upper bound, L0 must pass below"}
    for style in ("-", "--"):
        if style in styles:
            ax.plot([], [], style, color="0.5", lw=1.5, label=meaning[style])


def _draw_loop(ax, loop, omega, design, lo, hi, colours):
    """The nominal loop wrapped into [lo, lo + 360) degrees (black), with markers at the design
    frequencies ``design`` (rad/s) in the bounds' colours."""
    if omega is None:
        w_lo = design.min() / 100 if design.size else 1e-2
        w_hi = design.max() * 100 if design.size else 1e3
        omega = np.logspace(np.log10(w_lo), np.log10(w_hi), 2000)
    grid = check_grid(omega, "omega")
    if isinstance(loop, np.ndarray):
        L = loop  # markers go to the nearest grid points
    else:
        # Add the design frequencies so the markers sit exactly on the curve.
        grid = np.unique(np.concatenate([grid, design]))
        L = loop.response(grid) if isinstance(loop, Controller) else evaluate(loop, grid, "loop")
    ph, mag = loop_nichols(L, grid, (lo, hi))
    ax.plot(*wrap_phase(ph, mag, (lo, hi)), "k-", lw=1.5, label="nominal loop L0")
    for i, w in enumerate(design):
        j = int(np.argmin(np.abs(grid - w)))
        ax.plot(lo + np.mod(ph[j] - lo, 360.0), mag[j], "o", color=colours[i], mec="k", ms=7)


def draw(bounds: Bounds | None, loop: object = None, ax: "matplotlib.axes.Axes | None" = None,
         omega: ArrayLike | None = None, m_contours_db: ArrayLike | None = None, xlim: tuple = (-360.0, 0.0),
         ylim: tuple | None = None, legend: bool = True) -> "matplotlib.axes.Axes":
    """Nichols chart (dB vs degrees) of ``bounds`` and the nominal open loop ``loop`` = L0 = P0·G.

    The loop is wrapped into the phase window ``xlim`` (:func:`wrap_phase`; bounds repeat
    every 360°, so a loop point past −360° is drawn where its bound is) and broken where it
    wraps; the bounds and M-contours are repeated over the window when it is not
    ``bounds.phases_deg``'s. The legend names every design frequency (3 significant
    figures, rad/s) and what the line styles mean.

    Parameters
    ----------
    bounds : Bounds or None
        The bounds (one colour per design frequency; solid lower, dashed upper bounds).
    loop : control LTI or Controller or numpy.ndarray, optional
        SISO LTI, controller-shaped loop or complex response (then ``omega`` is its grid);
        drawn black, with markers at the design frequencies in the bound colours.
    ax : matplotlib.axes.Axes, optional
        Axes to draw in; default a new figure.
    omega : array_like, optional
        Loop grid, rad/s (default: 2000 points spanning the design frequencies ×/÷ 100).
    m_contours_db : sequence of float, optional
        Closed-loop magnitudes (dB) of M-contours to draw, e.g. (1.58, 6).
    xlim : tuple of float
        Phase window, degrees (``high > low``): the axis limits, and the loop is wrapped into
        ``[low, low + 360)``.
    ylim : tuple of float, optional
        Magnitude axis limits, dB.
    legend : bool
        Draw a legend.

    Returns
    -------
    matplotlib.axes.Axes
        The axes.

    Raises
    ------
    TypeError
        If ``bounds`` is neither a Bounds nor None.
    ValueError
        If ``xlim`` is not an increasing pair of finite phases.
    """
    if bounds is not None and not isinstance(bounds, Bounds):
        raise TypeError(f"bounds must be a loopshaping.qft.Bounds or None; got {type(bounds).__name__}")
    lo, hi = _check_window(xlim)
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7, 5))
    design = bounds.omega if bounds is not None else np.array([])
    colours = _colours(len(design))
    if bounds is not None:
        _draw_bounds(ax, bounds, lo, hi, colours)
    for n, m in enumerate(() if m_contours_db is None else np.atleast_1d(m_contours_db)):
        ph, mag = m_contour(float(m), np.arange(lo + 0.25, hi, 0.5))
        ax.plot(ph, mag, ":", color="0.5", lw=0.8, label=None if n else "M-contours: closed-loop |L0/(1+L0)|")
        j = np.nanargmin(np.abs(ph - (lo + np.mod(-220.0 - lo, 360.0))))
        ax.annotate(f"M = {m:.3g} dB", (ph[j], mag[j]), color="0.4", fontsize=7)
    if loop is not None:
        _draw_loop(ax, loop, omega, design, lo, hi, colours)
    # the critical point (−180° + k·360°, 0 dB) in every period the window shows: the loop's
    # distance to it is the stability margin a reader looks for first
    crit = [p for p in -180.0 + 360.0 * np.arange(np.floor((lo + 180.0) / 360.0), np.ceil((hi + 180.0) / 360.0) + 1)
            if lo <= p <= hi]
    if crit:
        ax.plot(crit, np.zeros(len(crit)), "+", color="r", ms=12, mew=2, zorder=5, label="critical point (−180°, 0 dB)")
    ax.set_xlim(lo, hi)
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.set_xticks(np.arange(lo, hi + 1, 45))
    ax.set_xlabel("Open-loop phase [deg]")
    ax.set_ylabel("Open-loop magnitude [dB]")
    ax.grid(True, lw=0.3)
    n_entries = len(ax.get_legend_handles_labels()[1])
    if legend and n_entries:
        ax.legend(fontsize=8, loc="best", ncol=2 if n_entries > 8 else 1)
    return ax


def template_nichols(template: Template) -> tuple[np.ndarray, np.ndarray]:
    """Phase and magnitude of every case of a template.

    Phases are taken relative to the nominal case (within ±180° of it), so a template that
    straddles a ±180° wrap is drawn in one piece.

    Parameters
    ----------
    template : Template
        The plant cases.

    Returns
    -------
    phase_deg : numpy.ndarray
        (n_omega, n_cases) phases, degrees.
    magnitude_db : numpy.ndarray
        (n_omega, n_cases) magnitudes, dB.
    """
    P = template.responses
    p0 = template.nominal_response[:, None]
    ph0 = np.degrees(np.angle(p0))
    ph0 = np.where(ph0 > 0, ph0 - 360, ph0)
    return ph0 + np.degrees(np.angle(P / p0)), 20 * np.log10(np.abs(P))


def plot_templates(template: Template, ax: "matplotlib.axes.Axes | None" = None,
                   legend: bool = True) -> "matplotlib.axes.Axes":
    """Templates on the Nichols plane: one colour per design frequency, nominal case boxed.

    Parameters
    ----------
    template : Template
        The plant cases.
    ax : matplotlib.axes.Axes, optional
        Axes to draw in; default a new figure.
    legend : bool
        Draw a legend.

    Returns
    -------
    matplotlib.axes.Axes
        The axes.

    Raises
    ------
    TypeError
        If ``template`` is not a Template.
    """
    import matplotlib.pyplot as plt

    if not isinstance(template, Template):
        raise TypeError(f"template must be a loopshaping.qft.Template; got {type(template).__name__}")
    if ax is None:
        _, ax = plt.subplots(figsize=(7, 5))
    ph, mag = template_nichols(template)
    colours = _colours(len(template.omega))
    for i, w in enumerate(template.omega):
        ax.plot(ph[i], mag[i], ".", color=colours[i], label=_omega_label(w))
        ax.plot(ph[i, template.nominal], mag[i, template.nominal], "s", mfc="none", mec="k", ms=8)
    ax.plot([], [], "s", mfc="none", mec="k", label="nominal case")
    ax.set_xlabel("Plant phase [deg]")
    ax.set_ylabel("Plant magnitude [dB]")
    ax.grid(True, lw=0.3)
    if legend:
        ax.legend(fontsize=8, loc="best")
    return ax
