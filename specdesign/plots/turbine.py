"""Turbine figures: the paper's Fig. 1 (open loop vs ROSCO) and Fig. 3 (where fatigue comes from).

Numbers in (from :func:`specdesign.closedloop.loop_maps` and :mod:`specdesign.spectral`),
axes out; magnitudes in dB only here.
"""
from __future__ import annotations

import numpy as np

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


def plot_open_vs_baseline(maps, axes=None, *, label="ROSCO"):
    """Fig. 1 analogue: |T_{Ω,w}|, |T_{MyT,w}| open loop vs closed loop, and |C_β|, in dB vs ω.

    maps: a :class:`specdesign.closedloop.LoopMaps`. axes: three matplotlib Axes or None.
    Returns the array of three Axes.
    """
    from ..closedloop import LoopMaps

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


def plot_fatigue_origin(omega, t_tower, psd, delta_d, axes=None, *, m=None):
    """Fig. 3 analogue: |T_{MyT,w}| (dB), S_MyT ((MN·m)² per rad/s, log) and ΔD%(ω).

    omega (rad/s); t_tower: complex T_{MyT,w} on omega (N·m per m/s); psd: S_MyT on omega
    ((N·m)² per rad/s); delta_d: ΔD% per grid point from :func:`specdesign.spectral.sensitivity`.
    m: Wöhler exponent for the legend. Returns the array of three Axes.
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
