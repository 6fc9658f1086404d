"""Per-run indicators: tower-base DEL (m = 4 by default) and blade-root DEL (m = 10) by
rainflow, generator-speed SD, mean power, pitch and pitch-rate SD, and the actuator's cost
(pitch travel per hour, time at the pitch-rate limit), from arrays (a simulation's outputs or
:func:`specdesign.openfast.series_from_openfast`)."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .._checks import positive_scalar
from ..fatigue import BLADE_M, TOWER_M, del_rainflow

__all__ = ["INDICATORS", "ACTUATOR_INDICATORS", "RATE_LIMIT_MARGIN", "Indicators", "indicators"]

#: Names of the indicators, in the order of :meth:`Indicators.as_dict` and of the output files.
INDICATORS = ("tower_del", "gen_speed_sd", "mean_power", "pitch_sd", "pitch_rate_sd", "blade_del", "pitch_travel",
              "rate_limit_time")
#: The actuator's indicators (with ``pitch_rate_sd``): what a pitch controller costs the bearings and drives.
ACTUATOR_INDICATORS = ("pitch_travel", "pitch_rate_sd", "rate_limit_time")
#: Relative margin below the rate limit at which a sample interval counts as at the limit: the
#: recorded pitch of a rate-saturated interval differs by |Δβ|/Δt = limit up to the rounding of
#: the recorded samples and of the actuator's clip (1e-3 would do on the reduced model; 1 %
#: leaves room for an OpenFAST controller's own rate clip, which acts on its command).
RATE_LIMIT_MARGIN = 0.01


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Indicators:
    """Per-run indicators, each an array shaped like the runs (e.g. (W, S)).

    Parameters
    ----------
    tower_del : numpy.ndarray
        Tower-base damage-equivalent load (N·m, a range, 1 Hz convention).
    gen_speed_sd : numpy.ndarray
        Standard deviation of the generator speed (rad/s).
    mean_power : numpy.ndarray
        Mean electrical power (W).
    pitch_sd : numpy.ndarray
        Standard deviation of the blade pitch (rad).
    pitch_rate_sd : numpy.ndarray
        Standard deviation of the pitch rate (rad/s).
    blade_del : numpy.ndarray
        Blade-root flapwise DEL (N·m, a range, 1 Hz convention, Wöhler exponent
        :data:`BLADE_M` = 10) of the output ``blade_root_my``; NaN where the series has no
        such output (e.g. an OpenFAST file without it).
    pitch_travel : numpy.ndarray
        Pitch travel per hour, Σ|Δβ| over the recorded samples × 3600 s / duration (rad/h; tables
        show deg/h). Sampled at the record's spacing: motion faster than its Nyquist
        frequency is not counted.
    rate_limit_time : numpy.ndarray
        Fraction of the record (-) spent at the pitch-rate limit: of the sample intervals, those
        with |Δβ|/Δt ≥ (1 − :data:`RATE_LIMIT_MARGIN`)·limit; NaN where no limit was given.
    m : float
        Wöhler exponent of the tower-base DEL.
    duration : float
        Record length used for the equivalent cycle count N_eq (s).

    See Also
    --------
    indicators : Computes them from time series.
    """

    tower_del: np.ndarray
    gen_speed_sd: np.ndarray
    mean_power: np.ndarray
    pitch_sd: np.ndarray
    pitch_rate_sd: np.ndarray
    blade_del: np.ndarray
    pitch_travel: np.ndarray
    rate_limit_time: np.ndarray
    m: float
    duration: float

    def as_dict(self) -> dict[str, np.ndarray]:
        """The indicators by name (:data:`INDICATORS`), without ``m`` and ``duration``.

        Returns
        -------
        dict
            Indicator name → array.
        """
        return {k: getattr(self, k) for k in INDICATORS}


def indicators(series: Mapping, dt: float, m: float = TOWER_M, *, pitch_rate_limit: float | None = None) -> Indicators:
    """Compute the indicators of every run in ``series``.

    Parameters
    ----------
    series : mapping
        ``tower_base_my`` (N·m), ``gen_speed`` (rad/s), ``power`` (W) and ``pitch`` (rad),
        each shaped (..., n) (a :class:`~specdesign.simulate.SimulationResult` qualifies, as
        does the first result of :func:`specdesign.openfast.series_from_openfast`); optionally
        ``blade_root_my`` (N·m, same shape) for ``blade_del`` (NaN without it).
    dt : float
        Sample spacing (s).
    m : float, default 4.0
        Wöhler exponent of the tower-base DEL (S-N curve with S the range); the blade-root
        DEL always uses :data:`BLADE_M`.
    pitch_rate_limit : float, optional
        The actuator's pitch-rate limit, rad/s (e.g. ``TurbineModel.pitch_rate_limit``, or
        ROSCO's ``PC_MaxRat``), for ``rate_limit_time``; None: that indicator is NaN.

    Returns
    -------
    Indicators
        Arrays shaped (...,): one value per run.

    Raises
    ------
    ValueError
        A series is missing, the arrays differ in shape or hold fewer than 2 samples, or
        ``dt``/``m`` is not a positive number.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(600) * 0.1
    >>> s = {"tower_base_my": np.sin(t), "gen_speed": 0.8 + 0.01 * np.sin(t),
    ...      "power": np.full(600, 15e6), "pitch": np.zeros(600)}
    >>> float(indicators(s, 0.1).mean_power)
    15000000.0
    """
    dt = positive_scalar(dt, "dt")
    m = positive_scalar(m, "m")
    rate_limit = None if pitch_rate_limit is None else positive_scalar(pitch_rate_limit, "pitch_rate_limit")
    get = series.__getitem__
    try:
        my, om, pw, pb = (np.asarray(get(k), dtype=float) for k in ("tower_base_my", "gen_speed", "power", "pitch"))
    except KeyError as e:
        raise ValueError(f"series lacks {e}; it needs tower_base_my, gen_speed, power and pitch") from None
    if not (my.shape == om.shape == pw.shape == pb.shape) or my.shape[-1] < 2:
        raise ValueError(f"series arrays must share a shape (..., n ≥ 2); got {my.shape}, {om.shape}, {pw.shape}, {pb.shape}")
    n = my.shape[-1]
    duration = n * dt
    flat = my.reshape(-1, n)
    dels = np.array([del_rainflow(row, m, duration) for row in flat]).reshape(my.shape[:-1])
    blade = np.full(my.shape[:-1], np.nan)
    try:
        bm = np.asarray(get("blade_root_my"), dtype=float)
    except KeyError:  # e.g. an OpenFAST file without the channel: the indicator is NaN, not a guess
        bm = None
    if bm is not None:
        if bm.shape != my.shape:
            raise ValueError(f"series['blade_root_my'] must have the shape {my.shape} of the other series; got {bm.shape}")
        blade = np.array([del_rainflow(row, BLADE_M, duration) for row in bm.reshape(-1, n)]).reshape(my.shape[:-1])
    step = np.abs(np.diff(pb, axis=-1))
    at_limit = (np.full(my.shape[:-1], np.nan) if rate_limit is None
                else np.mean(step >= (1.0 - RATE_LIMIT_MARGIN) * rate_limit * dt, axis=-1))
    return Indicators(
        tower_del=dels,
        gen_speed_sd=om.std(axis=-1),
        mean_power=pw.mean(axis=-1),
        pitch_sd=pb.std(axis=-1),
        pitch_rate_sd=(np.diff(pb, axis=-1) / dt).std(axis=-1),
        blade_del=blade,
        pitch_travel=step.sum(axis=-1) * 3600.0 / duration,
        rate_limit_time=at_limit,
        m=m,
        duration=duration,
    )
