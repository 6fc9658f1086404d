"""Validation figures: Welch vs linear prediction (paper Fig. 8), time series (Fig. 9),
predicted vs rainflow DEL reduction (Fig. 10). Results in, axes out; no plt.show()."""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .conventions import SI_UNITS, TIME_SERIES, show_se

__all__ = ["plot_spectra", "plot_time_series", "plot_reductions", "plot_lifetime_damage", "plot_comparison",
           "save_validation_figures"]

_NAMES = {"gen_speed": "Generator speed", "tower_base_my": "Tower-base fore-aft moment", "blade_root_my": "Blade-root flapwise moment"}

#: Upper end of the spectra drawn (rad/s): the band of the specifications and the design checks;
#: above it the spectra only roll off (towards the record's Nyquist frequency) and would squeeze
#: the band where the loads are.
SPECTRA_MAX_OMEGA = 10.0


def _axes(ax, **kw):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(**kw)
    return ax


def plot_spectra(campaign, wind_speed: float, output: str = "tower_base_my", *, controllers=None, ax=None):
    """Fig. 8: seed-averaged Welch PSD (solid) and linear prediction |T|²S_W (dashed).

    Log-log axes, ω in rad/s up to :data:`SPECTRA_MAX_OMEGA`, PSD in SI units² per rad/s,
    the magnitude axis spanning what the curves hold in that band.

    Parameters
    ----------
    campaign : specdesign.validate.Campaign
        The campaign.
    wind_speed : float
        One of its wind speeds (m/s).
    output : {"tower_base_my", "gen_speed"}, default "tower_base_my"
        Output whose spectra are drawn.
    controllers : sequence of str, optional
        Controllers to draw (default all).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new pyplot figure).

    Returns
    -------
    matplotlib.axes.Axes
        The axes.

    Raises
    ------
    ValueError
        A wind speed or output that the campaign does not hold.
    """
    ax = _axes(ax)
    i = int(np.argmin(np.abs(campaign.wind_speeds - float(wind_speed))))
    if abs(campaign.wind_speeds[i] - float(wind_speed)) > 1e-9:
        raise ValueError(f"wind_speed={wind_speed} m/s is not in the campaign {campaign.wind_speeds.tolist()}")
    if output not in campaign.welch:
        raise ValueError(f"output={output!r} must be one of {sorted(campaign.welch)}")
    names = campaign.controllers if controllers is None else controllers
    w = campaign.omega
    sel = (w > 0) & (w <= SPECTRA_MAX_OMEGA)
    drawn = []
    for k, name in enumerate(names):
        c = campaign.index(name)
        color = f"C{k}"
        ax.loglog(w[sel], campaign.welch[output][c, i][sel], color=color, label=f"{name} simulation (Welch)")
        drawn.append(campaign.welch[output][c, i][sel])
        pred = campaign.predicted_psd[output][c, i][sel]
        if np.any(np.isfinite(pred)):
            ax.loglog(w[sel], pred, color=color, ls="--", label=f"{name} linear |T|²S_W")
            drawn.append(pred)
    values = np.concatenate(drawn)
    values = values[np.isfinite(values) & (values > 0)]
    if values.size:  # the range the curves span in the band drawn, with a margin
        ax.set_ylim(values.min() / 3.0, values.max() * 3.0)
    unit = SI_UNITS.get(output)
    ax.set_xlabel("ω (rad/s)")
    ax.set_ylabel(f"PSD ({unit})²/(rad/s)" if unit else "PSD (SI units)²/(rad/s)")
    ax.set_title(f"{_NAMES.get(output, output)}, {campaign.wind_speeds[i]:g} m/s")
    ax.legend(fontsize="small")
    ax.grid(True, which="both", alpha=0.3)
    return ax


def plot_time_series(series, wind_speed: float, *, seed_index: int = 0, controllers=None, axes=None):
    """Fig. 9: generator speed (rpm), tower-base moment (MN·m), power (MW) and pitch (deg).

    One seed at one wind speed, for each controller.

    Parameters
    ----------
    series : dict
        Controller → :class:`~specdesign.simulate.SimulationResult` (e.g. ``Campaign.series``).
    wind_speed : float
        A simulated wind speed (m/s).
    seed_index : int, default 0
        Index of the seed among the kept ones.
    controllers : sequence of str, optional
        Controllers to draw (default all of ``series``).
    axes : sequence of matplotlib.axes.Axes, optional
        Four stacked axes (default a new pyplot figure).

    Returns
    -------
    numpy.ndarray
        The four axes.

    Raises
    ------
    ValueError
        Not four axes, or a wind speed that was not simulated.
    """
    if axes is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(4, 1, figsize=(8, 8), sharex=True)
    axes = np.asarray(axes).ravel()
    if axes.size != 4:
        raise ValueError(f"axes must hold 4 axes (speed, moment, power, pitch), got {axes.size}")
    names = list(series) if controllers is None else controllers
    panels = [(key, *TIME_SERIES[key]) for key in ("gen_speed", "tower_base_my", "power", "pitch")]
    titles = {"gen_speed": "Gen. speed", "tower_base_my": "Tower-base My", "power": "Power", "pitch": "Pitch"}
    panels = [(key, scale, f"{titles[key]} ({unit})") for key, scale, unit in panels]
    for k, name in enumerate(names):
        r = series[name]
        i = int(np.argmin(np.abs(r.wind_speeds - float(wind_speed))))
        if abs(r.wind_speeds[i] - float(wind_speed)) > 1e-9:
            raise ValueError(f"wind_speed={wind_speed} m/s was not simulated for {name}")
        for ax, (key, scale, ylabel) in zip(axes, panels):
            ax.plot(r.time, r[key][i, seed_index] * scale, color=f"C{k}", lw=0.8, label=name)
            ax.set_ylabel(ylabel)
    axes[-1].set_xlabel("time (s)")
    axes[0].legend(fontsize="small", loc="upper right")
    axes[0].set_title(f"{float(wind_speed):g} m/s, seed index {seed_index}")
    return axes


#: One style per series of Fig. 10 (colour, line style, marker all fixed, none shared), so a
#: series added later with the default colour cycle cannot take a drawn series' look.
_REDUCTION_STYLES = {
    "predicted": dict(color="C0", ls="--", marker="o"),
    "rainflow": dict(color="C1", ls="-", marker="s"),
    "rainflow_linear": dict(color="C4", ls=":", marker="v"),
    "volterra": dict(color="C3", ls="-.", marker="d"),
    "promised": dict(color="C2", ls=":", marker="^"),
    "target": dict(color="0.5", ls="-.", marker=""),
}


def plot_reductions(acc, *, promised=None, target: float | None = None, ax=None):
    """Fig. 10: tower-base DEL reduction (%) vs mean wind speed (m/s).

    Linear prediction and rainflow evaluation with ±1 standard error bars (paired seeds),
    plus rainflow on the linearised model when the campaign had a linear twin (the gap between
    the two rainflow curves is the plant nonlinearity's part) and the Volterra prediction when
    the campaign had one (``run_campaign(volterra=k)``). Every series has its own colour, line
    style and marker.

    Parameters
    ----------
    acc : specdesign.validate.Acceptance
        The acceptance of a design (:func:`~specdesign.validate.acceptance`).
    promised : dict of float to float, optional
        Wind speed (m/s) → the specification's promised DEL reduction (%), drawn as its own
        series.
    target : float, optional
        The design target (DEL reduction, %), drawn as a horizontal line.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new pyplot figure).

    Returns
    -------
    matplotlib.axes.Axes
        The axes.

    Raises
    ------
    TypeError
        If ``promised`` is not a mapping of wind speed to reduction.
    """
    if promised is not None and not hasattr(promised, "items"):
        raise TypeError(f"promised must be a dict of wind speed (m/s) → DEL reduction (%), got {type(promised).__name__}")
    st = _REDUCTION_STYLES
    ax = _axes(ax)
    se = show_se(acc.n_seeds)  # with fewer seeds the bars would claim a spread not estimated
    ax.plot(acc.wind_speeds, acc.predicted, **st["predicted"], label="linear prediction (Dirlik on |T|²S_W)")
    ax.errorbar(acc.wind_speeds, acc.rainflow, yerr=acc.se if se else None, capsize=3, **st["rainflow"],
                label=f"rainflow, nonlinear model ({acc.n_seeds} paired seeds{', ±1 SE' if se else ', too few for an SE'})")
    if np.all(np.isfinite(acc.rainflow_linear)):
        ax.errorbar(acc.wind_speeds, acc.rainflow_linear, yerr=acc.se_spectral if se else None, capsize=3,
                    **st["rainflow_linear"], label=f"rainflow, linearised model (same seeds{', ±1 SE' if se else ''})")
    if acc.volterra_order and np.all(np.isfinite(acc.volterra)):
        ax.plot(acc.wind_speeds, acc.volterra, **st["volterra"],
                label=f"Volterra prediction, order {acc.volterra_order} (rainflow, same seeds)")
    if promised:
        v = sorted(promised)
        ax.plot(v, [promised[k] for k in v], **st["promised"], label="specification's promise")
    if target is not None:
        ax.axhline(float(target), lw=0.8, **st["target"], label=f"design target ({float(target):g} %)")
    # reductions are read against zero (no reduction): an axis cut just around the curves
    # would make a 2 pp spread look like a factor of two
    top = max(ax.get_ylim()[1], 0.0)
    ax.set_ylim(min(ax.get_ylim()[0], 0.0), top)
    ax.set_xlabel("mean wind speed (m/s)")
    ax.set_ylabel("tower-base DEL reduction (%), positive: lower than the baseline")
    ax.legend(fontsize="small")
    ax.grid(True, alpha=0.3)
    return ax


def plot_lifetime_damage(life, channel: str = "tower_base_my", *, ax=None):
    """Damage contribution per wind bin for each controller (grouped bars).

    Each bar is p_b·mean_s DEL_{b,s}^m of one controller in one bin as a percentage of the
    baseline controller's lifetime damage over the covered bins (the baseline's bars sum to
    100 %, a controller's bars sum to (1 + change/100)^m · 100 %). Bins of the wind climate
    the campaign did not simulate are named in the title with their probability.

    Parameters
    ----------
    life : specdesign.validate.LifetimeDEL
        The lifetime result (:func:`~specdesign.validate.lifetime`).
    channel : str, default "tower_base_my"
        One of ``life.channels``.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on (default a new pyplot figure).

    Returns
    -------
    matplotlib.axes.Axes
        The axes.

    Raises
    ------
    ValueError
        A channel that ``life`` does not hold.
    """
    if channel not in life.channels:
        raise ValueError(f"channel={channel!r} must be one of {life.channels}")
    j = life.channels.index(channel)
    ax = _axes(ax)
    v = np.asarray(life.wind_speeds, dtype=float)
    n = len(life.controllers)
    step = float(np.min(np.diff(np.sort(v)))) if v.size > 1 else 1.0
    width = 0.8 * step / n
    for i, name in enumerate(life.controllers):
        label = f"{name} (lifetime DEL {life.del_life[i, j] / 1e6:.4g} MN·m"
        label += ")" if name == life.baseline else f", {life.change[i, j]:+.1f} ± {life.change_se[i, j]:.1f} %)"
        ax.bar(v + (i - (n - 1) / 2) * width, 100.0 * life.damage_share[i, j], width=width, color=f"C{i}",
               label=label)
    ax.set_xlabel("wind-speed bin centre (m/s)")
    ax.set_ylabel(f"share of {life.baseline}'s damage over the simulated bins (%)")
    title = f"{_NAMES.get(channel, channel)}, m = {life.m:g}"
    if life.missing_speeds.size:
        title += (f"\nbins not simulated: {', '.join(f'{x:g}' for x in life.missing_speeds.tolist())} m/s "
                  f"(p = {float(life.missing_probability.sum()):.3g})")
    ax.set_title(title, fontsize="small")
    ax.legend(fontsize="small")
    ax.grid(True, axis="y", alpha=0.3)
    return ax


def plot_comparison(changes, indicators=("tower_del", "blade_del"), *, axes=None):
    """DEL change vs the baseline per controller and wind speed, with standard-error bars.

    The wind speeds are categories on the horizontal axis (one group per speed, labelled in
    m/s), the controllers side by side within a group: a controller's position in its group
    is not a wind speed. Standard-error bars only from
    :data:`~specdesign.plots.conventions.MIN_SEEDS_FOR_SE` paired seeds on.

    Parameters
    ----------
    changes : mapping
        Controller name → {indicator → :class:`~specdesign.validate.PairedChange`} (the
        changes of ``benchmarks/comparison.py``); each change's ``wind_speeds`` (m/s) name
        its groups, so a controller run on fewer speeds shows fewer points.
    indicators : sequence of str, default ("tower_del", "blade_del")
        One panel per indicator (:data:`~specdesign.validate.INDICATORS`).
    axes : sequence of matplotlib.axes.Axes, optional
        One per indicator; new axes side by side if omitted.

    Returns
    -------
    numpy.ndarray
        The panels' axes (change in %, wind speed in m/s, one series per controller, legend).

    Raises
    ------
    ValueError
        No controllers, or an ``axes`` of another length than ``indicators``.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.validate import paired_change
    >>> ch = {"A": {"tower_del": paired_change([[9.0, 10.0]], [[10.0, 11.0]], wind_speeds=[19.0])}}
    >>> ax = plot_comparison(ch, ("tower_del",))
    >>> ax[0].get_ylabel()
    'tower-base DEL change vs baseline (%), negative: lower'
    """
    names = list(changes)
    if not names:
        raise ValueError("changes is empty: give controller name → {indicator → PairedChange}")
    inds = tuple(indicators)
    if axes is None:
        import matplotlib.pyplot as plt

        _, axes = plt.subplots(1, len(inds), figsize=(5.5 * len(inds), 4.0), squeeze=False)
        axes = axes[0]
    axes = np.atleast_1d(np.asarray(axes, dtype=object))
    if axes.size != len(inds):
        raise ValueError(f"axes has {axes.size} entries; give one per indicator ({len(inds)})")
    labels = {"tower_del": "tower-base DEL", "blade_del": "blade-root DEL", "gen_speed_sd": "generator-speed SD",
              "mean_power": "mean power", "pitch_sd": "pitch SD", "pitch_rate_sd": "pitch-rate SD"}
    width = 0.8 / len(names)
    speeds = np.unique(np.concatenate([np.asarray(changes[n][ind].wind_speeds, dtype=float)
                                       for n in names for ind in inds]))
    for ax, ind in zip(axes, inds):
        for i, n in enumerate(names):
            ch = changes[n][ind]
            group = np.searchsorted(speeds, np.asarray(ch.wind_speeds, dtype=float))
            x = group + (i - (len(names) - 1) / 2) * width
            se = show_se(ch.n_seeds)
            ax.errorbar(x, ch.change, yerr=ch.se if se else None, fmt="o", capsize=3,
                        label=n if se else f"{n} ({ch.n_seeds} seeds: no SE)")
        ax.axhline(0.0, color="0.5", lw=0.8)
        ax.set_xticks(np.arange(speeds.size), [f"{v:g}" for v in speeds])
        ax.set_xlabel("mean wind speed (m/s; controllers side by side)")
        ax.set_ylabel(f"{labels.get(ind, ind)} change vs baseline (%), negative: lower")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    return axes


def save_validation_figures(campaign, folder: str | os.PathLike, acc=None, *, promised=None) -> list[Path]:
    """Figs. 8-10 of a campaign as PNG files: the demo's step 4 and ``specdesign validate`` both.

    One file per figure and wind speed, so the demo and a validation written into the same
    folder keep one copy of each: ``fig8_<v>mps.png`` (:func:`plot_spectra`, generator speed
    and tower-base moment), ``fig9_<v>mps.png`` (:func:`plot_time_series`, the first kept
    seed; only when the campaign kept series) and, with ``acc``, ``fig10.png``
    (:func:`plot_reductions`, with the promise). Drawn on :class:`matplotlib.figure.Figure`:
    no pyplot, no backend needed. ``<v>`` is the wind speed in m/s as ``f"{v:g}"``.

    Parameters
    ----------
    campaign : specdesign.validate.Campaign
        The campaign (:func:`specdesign.validate.run_campaign`).
    folder : str or os.PathLike
        An existing folder to write into (files of the same names are replaced).
    acc : specdesign.validate.Acceptance, optional
        The design's acceptance against its baseline (:func:`specdesign.validate.acceptance`);
        without it no fig10.
    promised : dict of float to float, optional
        Wind speed (m/s) → the specification's promised DEL reduction (%), drawn on fig10.

    Returns
    -------
    list of pathlib.Path
        The files written, in the order above.
    """
    from matplotlib.figure import Figure  # figures only: matplotlib is never loaded by a computation

    out = Path(folder)
    written = []
    for v in campaign.wind_speeds:
        fig = Figure(figsize=(7, 6))
        axes = fig.subplots(2, 1, sharex=True)
        plot_spectra(campaign, v, "gen_speed", ax=axes[0])
        plot_spectra(campaign, v, "tower_base_my", ax=axes[1])
        fig.tight_layout()
        written.append(out / f"fig8_{v:g}mps.png")
        fig.savefig(written[-1], dpi=120)
        if campaign.series:
            fig = Figure(figsize=(8, 8))
            plot_time_series(campaign.series, v, seed_index=0, axes=fig.subplots(4, 1, sharex=True))
            written.append(out / f"fig9_{v:g}mps.png")
            fig.savefig(written[-1], dpi=120)
    if acc is not None:
        fig = Figure()
        plot_reductions(acc, promised=promised, ax=fig.subplots())
        written.append(out / "fig10.png")
        fig.savefig(written[-1], dpi=120)
    return written
