"""Turbine figures: the paper's Fig. 1 (open loop vs ROSCO) and Fig. 3 (where fatigue comes from).

Numbers in (from :func:`specdesign.closedloop.loop_maps` and :mod:`specdesign.spectral`),
axes out; magnitudes in dB only here.
"""
from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ..closedloop import LoopMaps

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..closedloop import LoopMaps

__all__ = ["plot_open_vs_baseline", "plot_fatigue_origin"]


def _axes(axes, n):
    if axes is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(n, 1, figsize=(6.4, 2.4 * n), sharex=True, constrained_layout=True)
    axes = np.atleast_1d(axes)
    if axes.size != n:
        raise ValueError(f"axes must hold {n} matplotlib Axes, got {axes.size}")
    return axes


def _db(x):
    return 20 * np.log10(np.maximum(np.abs(x), 1e-300))


def plot_open_vs_baseline(maps: LoopMaps, axes: Sequence[Axes] | None = None, *, label: str = "ROSCO") -> np.ndarray:
    """Fig. 1 analogue: |T_{Ω,w}|, |T_{MyT,w}| open loop vs closed loop, and |C_β|, in dB vs ω.

    Parameters
    ----------
    maps : specdesign.closedloop.LoopMaps
        The maps (:func:`specdesign.closedloop.loop_maps`): ω in rad/s, T_{Ω,w} in
        (rad/s)/(m/s), T_{MyT,w} in N·m/(m/s), C_β in rad/(rad/s).
    axes : sequence of matplotlib.axes.Axes, optional
        Three stacked axes; default a new figure.
    label : str
        Name of the controller in the legends.

    Returns
    -------
    numpy.ndarray
        The three Axes.

    Raises
    ------
    TypeError
        If ``maps`` is not a :class:`~specdesign.closedloop.LoopMaps`.
    ValueError
        If ``axes`` does not hold three axes.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import loop_maps
    >>> from specdesign.plots.turbine import plot_open_vs_baseline
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> maps = loop_maps(model.linearize(19.0), rosco_baseline(model, 19.0), np.logspace(-2, 1, 200))
    >>> plot_open_vs_baseline(maps).shape
    (3,)
    """
    if not isinstance(maps, LoopMaps):
        raise TypeError(f"maps must be a LoopMaps from specdesign.closedloop.loop_maps, got {type(maps).__name__}")
    ax = _axes(axes, 3)
    w = maps.omega
    ax[0].semilogx(w, _db(maps.gen_open), "k--", label="open loop")
    ax[0].semilogx(w, _db(maps.gen_closed), "C0", label=label)
    ax[0].set_ylabel("|T_Ω,w| (dB, rad/s per m/s)")
    ax[1].semilogx(w, _db(maps.tower_open), "k--", label="open loop")
    ax[1].semilogx(w, _db(maps.tower_closed), "C0", label=label)
    ax[1].set_ylabel("|T_MyT,w| (dB, N·m per m/s)")
    ax[2].semilogx(w, _db(maps.controller), "C1", label=f"{label} C_β")
    ax[2].set_ylabel("|C_β| (dB, rad per rad/s)")
    ax[2].set_xlabel("ω (rad/s)")
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend(loc="best", fontsize="small")
    return ax


def plot_fatigue_origin(omega: ArrayLike, t_tower: ArrayLike, psd: ArrayLike, delta_d: ArrayLike,
                        axes: Sequence[Axes] | None = None, *, m: float | None = None) -> np.ndarray:
    """Fig. 3 analogue: |T_{MyT,w}| (dB), S_MyT ((MN·m)² per rad/s, log) and ΔD%(ω).

    Parameters
    ----------
    omega : array_like
        Frequency grid, rad/s.
    t_tower : array_like
        Complex T_{MyT,w} on ``omega``, N·m per m/s.
    psd : array_like
        One-sided S_MyT on ``omega``, (N·m)² per rad/s (drawn in (MN·m)² per rad/s).
    delta_d : array_like
        ΔD% per grid point (:func:`specdesign.spectral.sensitivity`), %.
    axes : sequence of matplotlib.axes.Axes, optional
        Three stacked axes; default a new figure.
    m : float, optional
        Wöhler exponent (-), for the legend.

    Returns
    -------
    numpy.ndarray
        The three Axes.

    Raises
    ------
    ValueError
        If ``t_tower``, ``psd`` or ``delta_d`` does not have the shape of ``omega``, or
        ``axes`` does not hold three axes.

    Examples
    --------
    >>> from specdesign.plots.turbine import plot_fatigue_origin
    >>> from specdesign.spec import baseline_analysis
    >>> from specdesign.turbine import iea15mw
    >>> b = baseline_analysis(iea15mw(), 19.0)
    >>> plot_fatigue_origin(b.omega, b.t_response, b.psd, b.sensitivity, m=b.m).shape
    (3,)
    """
    w = np.asarray(omega, float)
    for name, arr in (("t_tower", t_tower), ("psd", psd), ("delta_d", delta_d)):
        if np.shape(arr) != w.shape:
            raise ValueError(f"{name} must have shape {w.shape} to match omega, got {np.shape(arr)}")
    ax = _axes(axes, 3)
    ax[0].semilogx(w, _db(t_tower), "C0", label="T_MyT,w")
    ax[0].set_ylabel("|T_MyT,w| (dB, N·m per m/s)")
    ax[1].loglog(w, np.maximum(np.asarray(psd) / 1e12, 1e-300), "C0", label="S_MyT")
    ax[1].set_ylabel("S_MyT ((MN·m)² per rad/s)")
    ax[2].semilogx(w, delta_d, "C3", label="ΔD%" + (f" (m = {m:g})" if m is not None else ""))
    ax[2].set_ylabel("ΔD% per grid point (%)")
    ax[2].set_xlabel("ω (rad/s)")
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
        a.legend(loc="best", fontsize="small")
    return ax
