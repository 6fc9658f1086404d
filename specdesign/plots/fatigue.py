"""Fatigue figures: rainflow range histogram against Dirlik's range PDF, and ΔD%(ω)."""
from __future__ import annotations

import numpy as np

from ..fatigue import Cycles
from ..spectral import dirlik_range_pdf

__all__ = ["plot_range_histogram", "plot_sensitivity"]


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def plot_range_histogram(cycles: Cycles, omega, psd, ax=None, *, bins: int = 60, unit: str = "load units"):
    """Density histogram of rainflow ranges (half cycles weighted 0.5) with Dirlik's range PDF over it.

    Parameters
    ----------
    cycles : Cycles
        From :func:`specdesign.fatigue.rainflow` (ranges in load units).
    omega, psd : array_like
        Grid (rad/s) and one 1-D one-sided PSD per rad/s of the same signal.
    ax : matplotlib Axes, optional
    bins : int
        Number of histogram bins.
    unit : str
        Load unit for the axis label.

    Returns
    -------
    matplotlib Axes
    """
    if not isinstance(cycles, Cycles):
        raise TypeError(f"cycles must be a Cycles result of rainflow(), got {type(cycles).__name__}")
    if np.ndim(psd) != 1:
        raise ValueError(f"psd must be one 1-D spectrum for one histogram, got shape {np.shape(psd)}")
    ax = _axes(ax)
    top = float(cycles.ranges.max()) if len(cycles) else 1.0
    edges = np.linspace(0.0, top, bins + 1)
    ax.hist(cycles.ranges, bins=edges, weights=cycles.counts, density=True, alpha=0.5, label="rainflow (time series)")
    s = np.linspace(0.0, top, 400)
    ax.plot(s, dirlik_range_pdf(omega, psd, s), "k-", lw=1.5, label="Dirlik range PDF (spectrum)")
    ax.set_xlabel(f"cycle range S [{unit}]")
    ax.set_ylabel(f"probability density [1/{unit}]")
    ax.legend()
    return ax


def plot_sensitivity(omega, dd, ax=None, *, label: str = "ΔD%(ω)"):
    """Damage sensitivity ΔD%(ω) (Eq. 7: % damage change for a 1 % PSD reduction) on a log ω axis.

    Parameters
    ----------
    omega : array_like
        Frequency grid, rad/s.
    dd : array_like
        ΔD%(ω) in % (:func:`specdesign.spectral.sensitivity`), shape (n,) or (k, n): one line
        per row.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    label : str
        Legend label (suffixed by the row index when ``dd`` has several rows).

    Returns
    -------
    matplotlib Axes
        The axes drawn on.
    """
    w = np.asarray(omega, dtype=float)
    d = np.atleast_2d(np.asarray(dd, dtype=float))
    if d.shape[-1] != w.size:
        raise ValueError(f"dd must have shape (..., {w.size}) to match omega, got {np.shape(dd)}")
    ax = _axes(ax)
    for i, row in enumerate(d):
        # past the 10 colours of the cycle the line style changes, so no two rows look alike
        ax.semilogx(w, row, color=f"C{i % 10}", ls=("-", "--", "-.", ":")[(i // 10) % 4],
                    label=label if d.shape[0] == 1 else f"{label} [{i}]")
    ax.set_xlabel("frequency ω [rad/s]")
    ax.set_ylabel("ΔD% per 1 % PSD reduction [%]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return ax
