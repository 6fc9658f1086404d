"""Lifetime damage: the per-bin DELs of a campaign combined over a wind climate.

IEC 61400-1 DLC 1.2 practice: the wind climate is cut into bins (2 m/s by default) from
cut-in to cut-out, each with the probability that the 10-min mean wind speed falls in it, and
the damage of every bin (seed-pooled by Wöhler exponent m) is weighted by that probability.
The lifetime DEL over the bins a campaign covers is

    DEL_life = (Σ_b p_b · mean_s DEL_{b,s}^m / Σ_b p_b)^{1/m},

the 1 Hz equivalent range of the operating time in those bins. Bins of the climate that the
campaign did not simulate are never dropped silently: :class:`LifetimeDEL` lists them with
their probability mass, and :meth:`LifetimeDEL.summary` says so. A campaign at every bin
centre from cut-in to cut-out (below rated under the model's torque law, e.g.
``run_campaign(..., weibull_bins().centres, ..., torque_control="rosco")``) covers the whole
climate; ``python -m specdesign demo --lifetime`` runs one.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import positive_scalar
from ..fatigue import TOWER_M
from .stats import resampled_se

__all__ = ["DEL_CHANNELS", "MAX_BINS", "WindClimate", "weibull_bins", "wind_climate", "LifetimeDEL", "lifetime"]

#: Channel of a campaign → the per-run DEL indicator it holds.
DEL_CHANNELS = {"tower_base_my": "tower_del"}
#: Most wind bins :func:`weibull_bins` makes: 1000 bins of 0.022 m/s between 3 and 25 m/s,
#: far finer than a campaign is ever run on (IEC 61400-1: 2 m/s).
MAX_BINS = 1000


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class WindClimate:
    """Wind-speed bins and the probability of each.

    Parameters
    ----------
    centres : numpy.ndarray
        (B,) bin centres (m/s), increasing.
    probabilities : numpy.ndarray
        (B,) probability of each bin (dimensionless), summing to at most 1 (the rest is the
        time below cut-in and above cut-out).
    description : str
        Where the probabilities come from.

    See Also
    --------
    weibull_bins, wind_climate : Make one.
    """

    centres: np.ndarray
    probabilities: np.ndarray
    description: str = "user-given"


def wind_climate(centres, probabilities, description: str = "user-given") -> WindClimate:
    """A user-given wind climate, validated.

    Parameters
    ----------
    centres : array_like
        (B,) distinct bin centres (m/s), positive and finite.
    probabilities : array_like
        (B,) probabilities (dimensionless), non-negative, finite, summing to ≤ 1 + 1e-9.
    description : str, default "user-given"
        Where they come from (printed by :meth:`LifetimeDEL.summary`).

    Returns
    -------
    WindClimate
        The bins sorted by centre.

    Raises
    ------
    ValueError
        Shapes that differ, a centre not positive and finite or repeated, a probability
        negative or not finite, or probabilities summing to more than 1.

    Examples
    --------
    >>> wind_climate([13.0, 15.0], [0.1, 0.05]).probabilities.tolist()
    [0.1, 0.05]
    """
    v = np.atleast_1d(np.asarray(centres, dtype=float))
    p = np.atleast_1d(np.asarray(probabilities, dtype=float))
    if v.ndim != 1 or v.size == 0 or np.any(~np.isfinite(v)) or np.any(v <= 0):
        raise ValueError(f"centres must be a 1-D non-empty array of positive wind speeds in m/s, got {centres!r}")
    if len(set(v.tolist())) != v.size:
        raise ValueError(f"centres must be distinct wind speeds (m/s), got {v.tolist()}")
    if p.shape != v.shape:
        raise ValueError(f"probabilities {p.shape} must have one entry per centre {v.shape}")
    if np.any(~np.isfinite(p)) or np.any(p < 0):
        raise ValueError(f"probabilities must be finite and ≥ 0, got {p.tolist()}")
    if p.sum() > 1 + 1e-9:
        raise ValueError(f"probabilities sum to {p.sum():.6g} > 1: pass the probability of each bin, not a pdf")
    order = np.argsort(v)
    return WindClimate(centres=v[order], probabilities=p[order], description=str(description))


def weibull_bins(k: float = 2.0, mean_speed: float | None = None, *, scale: float | None = None,
                 cut_in: float = 3.0, cut_out: float = 25.0, bin_width: float = 2.0) -> WindClimate:
    """Weibull wind climate in bins from cut-in to cut-out (IEC 61400-1 DLC 1.2 practice).

    Bin centres are cut_in, cut_in + bin_width, …, cut_out; bin b spans centre ± bin_width/2
    clipped to [cut_in, cut_out] (the first and last bins are half bins), and its probability
    is F(upper) − F(lower) with F(v) = 1 − exp(−(v/A)^k). The probabilities sum to
    F(cut_out) − F(cut_in) < 1: the time outside cut-in to cut-out carries no power-production
    damage. IEC 61400-1 class annual mean speeds at hub height: class I 10, class II 8.5,
    class III 7.5 m/s, with a Rayleigh distribution (k = 2), A = V_ave/Γ(1 + 1/k).

    Parameters
    ----------
    k : float, default 2.0
        Weibull shape (dimensionless); 2 is Rayleigh.
    mean_speed : float, optional
        Annual mean wind speed V_ave (m/s); default 10 m/s (class I) unless ``scale`` is given.
    scale : float, optional
        Weibull scale A (m/s), instead of ``mean_speed``.
    cut_in, cut_out : float, default 3.0, 25.0
        Cut-in and cut-out wind speeds (m/s).
    bin_width : float, default 2.0
        Bin width (m/s); (cut_out − cut_in)/bin_width must be a whole number, at most
        :data:`MAX_BINS`.

    Returns
    -------
    WindClimate
        Bin centres (m/s) and probabilities.

    Raises
    ------
    ValueError
        Both ``mean_speed`` and ``scale``, a non-positive parameter, cut_out ≤ cut_in, or a
        bin width that does not divide cut_out − cut_in.

    Examples
    --------
    >>> c = weibull_bins()
    >>> c.centres[[0, -1]].tolist(), round(float(c.probabilities.sum()), 4)
    ([3.0, 25.0], 0.9244)
    """
    if mean_speed is not None and scale is not None:
        raise ValueError("give mean_speed (V_ave, m/s) or scale (Weibull A, m/s), not both")
    k = positive_scalar(k, "k")
    if scale is not None:
        a = positive_scalar(scale, "scale")
        what = f"Weibull k = {k:g}, A = {a:g} m/s"
    else:
        v_ave = 10.0 if mean_speed is None else positive_scalar(mean_speed, "mean_speed")
        a = v_ave / math.gamma(1.0 + 1.0 / k)
        what = f"Weibull k = {k:g}, mean {v_ave:g} m/s (A = {a:.4g} m/s)"
    lo, hi, w = positive_scalar(cut_in, "cut_in"), positive_scalar(cut_out, "cut_out"), positive_scalar(bin_width, "bin_width")
    if hi <= lo:
        raise ValueError(f"cut_out={cut_out!r} must exceed cut_in={cut_in!r} (m/s)")
    n = (hi - lo) / w
    if n > MAX_BINS:  # else a width like 1e-9 m/s asks for 2e10 bins (and as many simulations)
        raise ValueError(f"bin_width={bin_width!r} m/s makes {n:.3g} bins from {lo:g} to {hi:g} m/s; at most "
                         f"{MAX_BINS} (a width ≥ {(hi - lo) / MAX_BINS:.3g} m/s; IEC 61400-1 uses 2 m/s)")
    if abs(n - round(n)) > 1e-9:
        raise ValueError(f"bin_width={bin_width!r} m/s must divide cut_out − cut_in = {hi - lo:g} m/s into whole bins")
    centres = lo + w * np.arange(round(n) + 1)
    lower = np.maximum(centres - w / 2, lo)
    upper = np.minimum(centres + w / 2, hi)

    def cdf(v):
        return -np.expm1(-((v / a) ** k))

    return WindClimate(centres=centres, probabilities=cdf(upper) - cdf(lower),
                       description=f"{what}, {w:g} m/s bins from {lo:g} to {hi:g} m/s")


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class LifetimeDEL:
    """Lifetime DEL per controller and channel over the bins a campaign covers.

    Parameters
    ----------
    controllers : tuple of str
        Controllers (C).
    channels : tuple of str
        Channels (K).
    baseline : str
        The controller the changes are relative to.
    m : float
        Wöhler exponent.
    availability : float
        Fraction of the time the turbine operates (dimensionless).
    wind_speeds : numpy.ndarray
        (B,) covered bin centres (m/s).
    probabilities : numpy.ndarray
        (B,) their probabilities.
    del_life : numpy.ndarray
        (C, K) lifetime DEL over the covered bins (N·m, 1 Hz convention); NaN where the
        controller was unstable in a covered bin.
    se : numpy.ndarray
        (C, K) its standard error over paired seeds (N·m).
    del_total : numpy.ndarray
        (C, K) DEL referred to the whole lifetime, (availability·Σ_b p_b mean_s DEL^m)^{1/m}
        (N·m): the same damage spread over every hour including idling, missing bins and
        downtime. Its relative change equals that of ``del_life``.
    change : numpy.ndarray
        (C, K) 100·(DEL_life/DEL_life,baseline − 1) (%).
    change_se : numpy.ndarray
        (C, K) its standard error over paired seeds (percentage points).
    damage_share : numpy.ndarray
        (C, K, B) p_b·mean_s DEL_{b,s}^m divided by the baseline's Σ_b: each bin's share of
        the baseline's lifetime damage (the baseline's shares sum to 1).
    missing_speeds : numpy.ndarray
        (M,) bin centres of the climate the campaign did not simulate (m/s).
    missing_probability : numpy.ndarray
        (M,) their probabilities.
    unstable : dict
        Controller → wind speeds (m/s) of covered bins where it was unstable (empty if none).
    n_seeds : int
        Paired seeds per bin.
    method : str
        "jackknife" or "bootstrap".
    climate : str
        Description of the wind climate.
    predicted_del_life : numpy.ndarray, optional
        (C, K) the same lifetime DEL from the campaign's linear predictions (Dirlik on
        |T|²S_W per bin, ``Campaign.predicted_del``, N·m): no seeds, no SE; NaN for a channel
        without predictions or a controller without a linear form.
    predicted_change : numpy.ndarray, optional
        (C, K) its change vs the baseline (%).

    See Also
    --------
    lifetime : Computes it.
    """

    controllers: tuple
    channels: tuple
    baseline: str
    m: float
    availability: float
    wind_speeds: np.ndarray
    probabilities: np.ndarray
    del_life: np.ndarray
    se: np.ndarray
    del_total: np.ndarray
    change: np.ndarray
    change_se: np.ndarray
    damage_share: np.ndarray
    missing_speeds: np.ndarray
    missing_probability: np.ndarray
    unstable: dict
    n_seeds: int
    method: str
    climate: str
    predicted_del_life: np.ndarray | None = None
    predicted_change: np.ndarray | None = None

    @property
    def covered_probability(self) -> float:
        """Probability mass of the covered bins (dimensionless).

        Returns
        -------
        float
            Σ_b p_b over the bins the campaign simulated.
        """
        return float(self.probabilities.sum())

    def summary(self) -> str:
        """Text summary: lifetime DEL ± SE and change ± SE per channel, the bins covered and missing.

        Returns
        -------
        str
            Several lines of text.
        """
        lines = [f"Lifetime DEL (m = {self.m:g}, {self.n_seeds} paired seeds, {self.method} SE), {self.climate}",
                 f"covered bins: {_speeds(self.wind_speeds)} m/s, probability {self.covered_probability:.4g}"]
        if self.missing_speeds.size:
            lines.append(f"MISSING bins (not in the campaign, excluded): {_speeds(self.missing_speeds)} m/s, "
                         f"probability {float(self.missing_probability.sum()):.4g}: the lifetime DEL covers only "
                         "the simulated bins")
        for name, speeds in self.unstable.items():
            if speeds:
                lines.append(f"UNSTABLE: {name} at {_speeds(np.asarray(speeds))} m/s: its lifetime DEL is NaN")
        for j, ch in enumerate(self.channels):
            lines.append(f"{ch}:")
            for i, name in enumerate(self.controllers):
                row = f"  {name:<16} DEL_life {self.del_life[i, j] / 1e6:10.4g} ± {self.se[i, j] / 1e6:.2g} MN·m"
                if name != self.baseline:
                    row += f"   change vs {self.baseline} {self.change[i, j]:+.2f} ± {self.change_se[i, j]:.2f} %"
                    if self.predicted_change is not None and np.isfinite(self.predicted_change[i, j]):
                        row += f" (linear prediction {self.predicted_change[i, j]:+.2f} %)"
                lines.append(row)
        return "\n".join(lines)


def _speeds(v) -> str:
    return ", ".join(f"{x:g}" for x in np.asarray(v).tolist())


def lifetime(campaign, wind_climate, *, controllers=None, channels=("tower_base_my",), m: float = TOWER_M,
             availability: float = 1.0, baseline: str | None = None, method: str = "jackknife",
             n_boot: int = 2000, seed: int = 0) -> LifetimeDEL:
    """Lifetime DEL of each controller and channel, with its SE and the change vs a baseline.

    DEL_life = (Σ_b p_b · mean_s DEL_{b,s}^m / Σ_b p_b)^{1/m} over the climate's bins the
    campaign simulated (a campaign wind speed must be a bin centre). Standard errors come from
    :func:`~specdesign.validate.resampled_se` over paired seeds: a seed index is deleted (or
    resampled) at every bin and for every controller at once. Bins of the climate without a
    campaign wind speed are reported in the result, never silently dropped.

    Parameters
    ----------
    campaign : Campaign
        Per-run DELs per controller, wind speed and seed (:class:`~specdesign.validate.Campaign`).
    wind_climate : WindClimate or tuple
        :func:`weibull_bins`, :func:`wind_climate`, or a (centres, probabilities) pair.
    controllers : sequence of str, optional
        Controllers to evaluate (default all of the campaign's).
    channels : sequence of str, default ("tower_base_my",)
        Load channels (keys of :data:`DEL_CHANNELS`).
    m : float, default 4.0
        Wöhler exponent; must be the one the campaign's DELs were computed with.
    availability : float, default 1.0
        Fraction of the time the turbine operates, in (0, 1]; scales ``del_total`` only.
    baseline : str, optional
        Controller the changes are relative to (default the first of ``controllers``).
    method : {"jackknife", "bootstrap"}, default "jackknife"
        Standard error over paired seeds.
    n_boot : int, default 2000
        Bootstrap replicates.
    seed : int, default 0
        Seed of the bootstrap.

    Returns
    -------
    LifetimeDEL
        The lifetime DELs, SEs, changes, damage per bin and the missing bins.

    Raises
    ------
    TypeError
        ``campaign`` is not a Campaign-like record.
    ValueError
        An unknown controller, channel or baseline; ``m`` unlike the campaign's; an
        availability outside (0, 1]; a campaign wind speed that is no bin centre; a climate
        without any covered bin; an invalid climate (:func:`wind_climate`).

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.validate import Campaign
    >>> d = np.array([[[1.0, 1.0]], [[0.5, 0.5]]])  # 2 controllers, 1 speed, 2 seeds (N·m)
    >>> c = Campaign(("a", "b"), np.array([15.0]), np.arange(2), 600.0, 0.1, 4.0, {"tower_del": d},
    ...              np.zeros((2, 1)), np.zeros(1), {}, {})
    >>> r = lifetime(c, wind_climate([13.0, 15.0], [0.2, 0.1]))
    >>> float(r.change[1, 0]), r.missing_speeds.tolist()
    (-50.0, [13.0])
    """
    if not all(hasattr(campaign, a) for a in ("controllers", "wind_speeds", "seeds", "values", "m")):
        raise TypeError(f"campaign must be a specdesign.validate.Campaign, got {type(campaign).__name__}")
    climate = wind_climate if isinstance(wind_climate, WindClimate) else _as_climate(wind_climate)
    names = tuple(campaign.controllers) if controllers is None else tuple(controllers)
    for n in names:
        if n not in campaign.controllers:
            raise ValueError(f"controllers: {n!r} is not in the campaign {tuple(campaign.controllers)}")
    if not names:
        raise ValueError("controllers must name at least one controller of the campaign")
    base = names[0] if baseline is None else baseline
    if base not in names:
        raise ValueError(f"baseline={base!r} must be one of controllers {names}")
    chans = (channels,) if isinstance(channels, str) else tuple(channels)
    if not chans or any(ch not in DEL_CHANNELS for ch in chans):
        raise ValueError(f"channels={channels!r} must be a non-empty sequence of {tuple(DEL_CHANNELS)}")
    m = positive_scalar(m, "m")
    if abs(m - float(campaign.m)) > 1e-12:
        raise ValueError(f"m={m:g} differs from the campaign's Wöhler exponent {campaign.m:g}: its DELs were "
                         f"computed with m={campaign.m:g}; pass m={campaign.m:g} or rerun run_campaign(m={m:g})")
    availability = positive_scalar(availability, "availability")
    if availability > 1:
        raise ValueError(f"availability={availability!r} must be a fraction of the time in (0, 1]")

    vs = np.asarray(campaign.wind_speeds, dtype=float)
    centres = climate.centres
    bin_of = np.array([int(np.argmin(np.abs(centres - v))) for v in vs])
    off = np.abs(centres[bin_of] - vs) > 1e-6
    if np.any(off):
        raise ValueError(f"campaign wind speeds {vs[off].tolist()} m/s are no bin centre of wind_climate "
                         f"({_speeds(centres)} m/s): use a climate whose bins are centred on the simulated speeds")
    if np.unique(bin_of).size != bin_of.size:  # would weight one bin twice
        raise ValueError(f"campaign wind speeds {vs.tolist()} m/s repeat a bin of wind_climate")
    covered = np.zeros(centres.size, bool)
    covered[bin_of] = True
    p = climate.probabilities[bin_of]
    if p.sum() <= 0:
        raise ValueError("wind_climate gives probability 0 to every bin the campaign simulated")
    ci = [campaign.index(n) if hasattr(campaign, "index") else campaign.controllers.index(n) for n in names]
    # (C, K, W, S) per-run DELs
    d = np.stack([np.asarray(campaign.values[DEL_CHANNELS[ch]], dtype=float)[ci] for ch in chans], axis=1)
    dm = d**m
    b = names.index(base)
    S = d.shape[-1]

    def energy(idx):  # Σ_b p_b mean_s DEL^m: (C, K)
        return np.einsum("w,ckw->ck", p, dm[..., idx].mean(axis=-1))

    def stats(idx):
        e = energy(idx)
        life = (e / p.sum()) ** (1.0 / m)
        return np.concatenate([life.ravel(), (100.0 * (life / life[b] - 1.0)).ravel()])

    est = stats(np.arange(S))
    se = resampled_se(stats, S, est.size, method, n_boot, seed)
    C, K = len(names), len(chans)
    e_bins = p * dm.mean(axis=-1)  # (C, K, W)
    unstable_all = np.asarray(getattr(campaign, "unstable", np.zeros((len(campaign.controllers), vs.size), bool)))
    # the linear predictions (tower-base DEL per controller and speed) combined the same way
    pred = np.full((C, K), np.nan)
    pd = getattr(campaign, "predicted_del", None)
    for k, ch in enumerate(chans):
        if ch == "tower_base_my" and pd is not None and np.shape(pd) == (len(campaign.controllers), vs.size):
            pred[:, k] = (p @ (np.asarray(pd, dtype=float)[ci].T ** m) / p.sum()) ** (1.0 / m)
    with np.errstate(invalid="ignore", divide="ignore"):  # no prediction (NaN, or 0 in a hand-made record)
        pred_change = 100.0 * (pred / pred[b] - 1.0)
    return LifetimeDEL(
        controllers=names, channels=chans, baseline=base, m=m, availability=availability, wind_speeds=vs.copy(),
        probabilities=p, del_life=est[:C * K].reshape(C, K), se=se[:C * K].reshape(C, K),
        del_total=(availability * energy(np.arange(S))) ** (1.0 / m),
        change=est[C * K:].reshape(C, K), change_se=se[C * K:].reshape(C, K),
        damage_share=e_bins / e_bins[b].sum(axis=-1)[None, :, None],
        missing_speeds=centres[~covered], missing_probability=climate.probabilities[~covered],
        unstable={n: vs[unstable_all[i]].tolist() for n, i in zip(names, ci)},
        n_seeds=S, method=method, climate=climate.description, predicted_del_life=pred,
        predicted_change=pred_change)


def _as_climate(wc) -> WindClimate:
    try:
        centres, probabilities = wc
    except (TypeError, ValueError):
        raise ValueError("wind_climate must be a WindClimate (weibull_bins, wind_climate) or a (centres, "
                         f"probabilities) pair, got {type(wc).__name__}") from None
    return wind_climate(centres, probabilities)
