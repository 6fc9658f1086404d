"""Nichols charts: bounds, the nominal loop, templates and M-contours (dB vs degrees).

Numbers first (:func:`loop_nichols`, :func:`m_contour`), drawing second (:func:`draw`,
:func:`plot_templates`); matplotlib is imported only inside the drawing functions.
Bounds are drawn the way QFT Toolbox users read them: one colour per design frequency,
solid = lower bound (the loop must pass above), dashed = upper bound (must pass below).
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from ._deprecation import renamed_keywords
from .bounds import Bounds
from .controller import Controller
from .freqresp import check_grid, evaluate
from .templates import Template

__all__ = ["draw", "loop_nichols", "m_contour", "plot_templates", "template_nichols"]


@renamed_keywords(omegas="omega")
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
    import matplotlib.pyplot as plt

    cmap = plt.get_cmap("tab10" if n <= 10 else "viridis")
    return [cmap(i if n <= 10 else i / max(n - 1, 1)) for i in range(n)]


def draw(bounds: Bounds | None, loop: object = None, ax: "matplotlib.axes.Axes | None" = None,
         omega: ArrayLike | None = None, m_contours_db: ArrayLike | None = None, xlim: tuple = (-360.0, 0.0),
         ylim: tuple | None = None, legend: bool = True) -> "matplotlib.axes.Axes":
    """Nichols chart of ``bounds`` and the nominal open loop ``loop`` = L0 = P0·G.

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
        Phase axis limits, degrees.
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
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7, 5))
    if bounds is not None and not isinstance(bounds, Bounds):
        raise TypeError(f"bounds must be a loopshaping.qft.Bounds or None; got {type(bounds).__name__}")
    design = bounds.omega if bounds is not None else np.array([])
    colours = _colours(len(design))
    if bounds is not None:
        lower, upper = bounds.edges()
        ph = bounds.phases_deg
        for i, w in enumerate(design):
            # One artist per frequency and style (curves joined by NaN breaks): fast redraws.
            lab = f"ω = {w:.4g} rad/s"
            for edge, style in ((lower, "-"), (upper, "--")):
                curves = edge[i].T[np.any(np.isfinite(edge[i].T), axis=1)]
                if curves.size:
                    xs = np.concatenate([np.r_[ph, np.nan] for _ in curves])
                    ys = np.concatenate([np.r_[c, np.nan] for c in curves])
                    ax.plot(xs, ys, style, color=colours[i], lw=1.5, label=lab)
                    lab = None
            if bounds.empty[i]:
                ax.plot([], [], " ", label=f"ω = {w:.4g} rad/s: EMPTY bound")
    for m in () if m_contours_db is None else np.atleast_1d(m_contours_db):
        ph, mag = m_contour(float(m))
        ax.plot(ph, mag, ":", color="0.5", lw=0.8)
        j = np.nanargmin(np.abs(ph + 180 + 40))
        ax.annotate(f"M = {m:.3g} dB", (ph[j], mag[j]), color="0.4", fontsize=7)
    if loop is not None:
        if omega is None:
            lo = design.min() / 100 if design.size else 1e-2
            hi = design.max() * 100 if design.size else 1e3
            omega = np.logspace(np.log10(lo), np.log10(hi), 2000)
        grid = check_grid(omega, "omega")
        if isinstance(loop, np.ndarray):
            L = loop  # markers go to the nearest grid points
        else:
            # Add the design frequencies so the markers sit exactly on the curve.
            grid = np.unique(np.concatenate([grid, design]))
            L = loop.response(grid) if isinstance(loop, Controller) else evaluate(loop, grid, "loop")
        ph, mag = loop_nichols(L, grid, xlim)
        ax.plot(ph, mag, "k-", lw=1.5, label="nominal loop L0")
        for i, w in enumerate(design):
            j = int(np.argmin(np.abs(grid - w)))
            ax.plot(ph[j], mag[j], "o", color=colours[i], mec="k", ms=7)
    ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.set_xticks(np.arange(xlim[0], xlim[1] + 1, 45))
    ax.set_xlabel("Open-loop phase [deg]")
    ax.set_ylabel("Open-loop magnitude [dB]")
    ax.grid(True, lw=0.3)
    if legend and (bounds is not None or loop is not None):
        ax.legend(fontsize=8, loc="best")
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
        ax.plot(ph[i], mag[i], ".", color=colours[i], label=f"ω = {w:.4g} rad/s")
        ax.plot(ph[i, template.nominal], mag[i, template.nominal], "s", mfc="none", mec="k", ms=8)
    ax.plot([], [], "s", mfc="none", mec="k", label="nominal case")
    ax.set_xlabel("Plant phase [deg]")
    ax.set_ylabel("Plant magnitude [dB]")
    ax.grid(True, lw=0.3)
    if legend:
        ax.legend(fontsize=8, loc="best")
    return ax
