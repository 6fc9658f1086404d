"""Offline validation: indicators, spectra, paired-seed statistics and the paper's Tables 2-3.

Works on arrays, so the same post-processing serves :func:`specdesign.simulate.simulate` runs
and the user's OpenFAST outputs (:func:`series_from_openfast`).

Indicators per run (the paper's four, plus pitch rate): tower-base DEL by rainflow (a range,
N·m, 1 Hz convention, Wöhler exponent m = 4 by default), generator-speed SD (rad/s), mean
electrical power (W), pitch SD (rad) and pitch-rate SD (rad/s).

Per wind speed, seeds are pooled the way fatigue adds up: DEL over S seeds of equal length
is (mean_s DEL_s^m)^{1/m} (the DEL of the concatenated damage), SDs are pooled as
√(mean_s var_s), the power is the plain mean. A *relative change* designed vs baseline is
100·(X_designed/X_baseline − 1) %; a *reduction* is minus that. Both controllers see the same
seeds (paired), and standard errors come from the jackknife over paired seeds (delete one
seed from both controllers), or a seeded paired bootstrap.

Weibull mean (Table 2's "Mean" column): Σ w_i c_i with w_i = f(v_i)/Σ_j f(v_j), f the Weibull
pdf with k = 2.2, A = 11.29 m/s evaluated at the operating points. This reproduces the means
printed in the paper's Table 2 from its per-speed values (tested).
"""
from __future__ import annotations

import csv
import dataclasses
import json
import math
import sys
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._checks import positive_scalar
from .closedloop import closed_loop_poles, unstable_message, unstable_poles

__all__ = [
    "WEIBULL_K",
    "WEIBULL_A",
    "OPENFAST_CHANNELS",
    "weibull_weights",
    "welch_psd",
    "Indicators",
    "indicators",
    "series_from_openfast",
    "closed_loop_response",
    "LinearPrediction",
    "linear_prediction",
    "volterra_response",
    "VolterraPrediction",
    "volterra_prediction",
    "PairedChange",
    "paired_change",
    "Campaign",
    "run_campaign",
    "Table",
    "table2",
    "table3",
    "Acceptance",
    "acceptance",
    "load_controller",
    "run_config",
]

WEIBULL_K = 2.2
WEIBULL_A = 11.29
#: OpenFAST channel → workbench output name.
OPENFAST_CHANNELS = {"GenSpeed": "gen_speed", "TwrBsMyt": "tower_base_my", "BldPitch1": "pitch", "GenPwr": "power"}
#: SI unit each workbench series must arrive in (read_outputs converts rpm, deg, kN·m, kW, …)
_SERIES_UNITS = {"gen_speed": "rad/s", "tower_base_my": "N·m", "pitch": "rad", "power": "W"}
_INDICATORS = ("tower_del", "gen_speed_sd", "mean_power", "pitch_sd", "pitch_rate_sd")
_LABELS = {
    "gen_speed_sd": "Generator speed SD",
    "mean_power": "Mean power",
    "tower_del": "Tower base DEL",
    "pitch_sd": "Pitch activity (SD)",
    "pitch_rate_sd": "Pitch rate SD",
}


# ----------------------------------------------------------------------------- basics
def weibull_weights(wind_speeds, k: float = WEIBULL_K, scale: float = WEIBULL_A) -> np.ndarray:
    """Weights of the operating points: Weibull pdf at each wind speed, normalised to sum 1.

    f(v) = (k/A)(v/A)^{k−1} exp(−(v/A)^k), w_i = f(v_i)/Σ f(v_j); v and A in m/s.
    """
    v = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    if v.ndim != 1 or v.size == 0 or np.any(~np.isfinite(v)) or np.any(v <= 0):
        raise ValueError(f"wind_speeds must be positive mean wind speeds in m/s, got {wind_speeds!r}")
    k = positive_scalar(k, "k")
    a = positive_scalar(scale, "scale")
    f = (k / a) * (v / a) ** (k - 1) * np.exp(-((v / a) ** k))
    return f / f.sum()


def welch_psd(x, dt, nperseg: int | None = None, axis: int = -1):
    """One-sided Welch PSD per rad/s of ``x`` sampled every ``dt`` s.

    scipy's ``welch`` with ``fs = 1/dt`` returns f (Hz) and P(f) per Hz, one-sided. With
    ω = 2πf the density per rad/s is S(ω) = P(f)/(2π), so that ∫ S dω = ∫ P df = variance.
    Default segment: 2^k samples closest to 1/6 of the record (≈ 100 s for 600 s), Hann window,
    50 % overlap, mean removed per segment.

    Returns (omega rad/s, psd) with psd shaped like x with ``axis`` replaced by frequency.
    """
    from scipy.signal import welch

    x = np.asarray(x, dtype=float)
    dt = positive_scalar(dt, "dt")
    n = x.shape[axis]
    if nperseg is None:
        nperseg = int(2 ** max(4, round(math.log2(max(n / 6, 16)))))
    nperseg = min(int(nperseg), n)
    f, p = welch(x, fs=1.0 / dt, nperseg=nperseg, axis=axis)
    return 2.0 * np.pi * f, p / (2.0 * np.pi)


# ----------------------------------------------------------------------------- indicators
@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Indicators:
    """Per-run indicators, each an array shaped like the runs (e.g. (W, S)).

    tower_del : tower-base DEL (N·m, a range, 1 Hz), m : its Wöhler exponent.
    gen_speed_sd (rad/s), mean_power (W), pitch_sd (rad), pitch_rate_sd (rad/s).
    duration : record length used for N_eq (s).
    """

    tower_del: np.ndarray
    gen_speed_sd: np.ndarray
    mean_power: np.ndarray
    pitch_sd: np.ndarray
    pitch_rate_sd: np.ndarray
    m: float
    duration: float

    def as_dict(self) -> dict:
        return {k: getattr(self, k) for k in _INDICATORS}


def indicators(series, dt, m: float = 4.0) -> Indicators:
    """Indicators of every run in ``series``.

    series : dict with ``tower_base_my`` (N·m), ``gen_speed`` (rad/s), ``power`` (W) and
        ``pitch`` (rad), each shaped (..., n) (a :class:`~specdesign.simulate.SimulationResult`
        qualifies, as does :func:`series_from_openfast`).
    dt : sample spacing (s). m : Wöhler exponent of the tower-base DEL (S-N with S the range).
    """
    from .fatigue import del_rainflow

    dt = positive_scalar(dt, "dt")
    m = positive_scalar(m, "m")
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
    return Indicators(
        tower_del=dels,
        gen_speed_sd=om.std(axis=-1),
        mean_power=pw.mean(axis=-1),
        pitch_sd=pb.std(axis=-1),
        pitch_rate_sd=(np.diff(pb, axis=-1) / dt).std(axis=-1),
        m=m,
        duration=duration,
    )


def series_from_openfast(outputs, channels=OPENFAST_CHANNELS):
    """Stack OpenFAST outputs (from :func:`specdesign.openfast.read_outputs`) into workbench series.

    Returns (series dict name → (n_files, n) SI arrays, dt s). All files must share dt and
    length (cut them to a common length first if needed).
    """
    from .openfast import OpenFASTOutput

    outs = [outputs] if isinstance(outputs, OpenFASTOutput) else list(outputs)
    if not outs:
        raise ValueError("outputs is empty; pass one or more OpenFASTOutput objects")
    dts = [o.dt for o in outs]
    lens = [o.time.size for o in outs]
    if max(dts) - min(dts) > 1e-9 * max(dts) or len(set(lens)) != 1:
        raise ValueError(f"outputs must share dt and length; got dt {sorted(set(dts))} s and lengths {sorted(set(lens))}")
    series = {}
    for ch, name in channels.items():
        for o in outs:
            if ch not in o.channels:
                raise ValueError(f"{o.path}: channel {ch!r} was not read; pass channels={list(channels)} to read_outputs")
            want = _SERIES_UNITS.get(name)
            if want is not None and o.units[ch] != want:
                raise ValueError(f"{o.path}: channel {ch!r} is in {o.original_units[ch]!r}, which does not convert to "
                                 f"{want} (the unit {name!r} needs); a unit the reader does not know is not guessed")
        series[name] = np.stack([o.channels[ch] for o in outs])
    return series, dts[0]


# ----------------------------------------------------------------------------- linear prediction
def _local_response(controller, model, wind_speed, s):
    """(C_β(s), C_atd(s)) of a controller at a wind speed, blended as the simulator blends.
    An integrator evaluated at s = 0 gives inf (or nan) silently: the closed-loop formulas take
    the limit there."""
    import warnings

    with warnings.catch_warnings(), np.errstate(divide="ignore", invalid="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        return _local_response_unchecked(controller, model, wind_speed, s)


def _local_response_unchecked(controller, model, wind_speed, s):
    from .simulate import ScheduledController, _as_lti, turbine_plant

    if isinstance(controller, ScheduledController):
        b0 = turbine_plant(model).trim(wind_speed)[1]
        K = controller.schedule_pitch.size
        w = np.array([np.interp(b0, controller.schedule_pitch, np.eye(K)[q]) for q in range(K)])
        cb = sum(w[q] * np.asarray(controller.pitch[q](s)) for q in range(K) if w[q] != 0)
        ca = 0.0 if controller.atd is None else sum(w[q] * np.asarray(controller.atd[q](s)) for q in range(K) if w[q] != 0)
        return np.asarray(cb, complex), np.asarray(ca, complex) * np.ones_like(s)
    c = _as_lti(controller, "controller")
    return np.asarray(c(s), complex), np.zeros_like(s)


def closed_loop_response(model, controller, wind_speed, omega, output="tower_base_my"):
    """T_{y,w}(jω) from rotor-effective wind (m/s) to ``output`` (SI) in closed loop.

    The controller (any kind the simulator runs; a scheduled one blended at the trim pitch of
    ``wind_speed``) closes the linearisation at ``wind_speed`` through
    :func:`specdesign.closedloop.t_output_wind`, with β = −C_β·Ω_g − C_atd·ẋ_top as in the
    simulator. omega in rad/s, strictly increasing; returns a complex array shaped like omega.
    """
    from .closedloop import t_output_wind
    from .simulate import turbine_plant

    w = np.asarray(omega, dtype=float)
    plant = turbine_plant(model)
    G = np.asarray(plant.linearize(wind_speed)(1j * w))  # (ny, nu, nw), inputs wind, pitch_cmd, gen_torque
    names = list(plant.output_names)
    # by position: a user KernelPlant's linearisation need not carry signal names
    P = {(o, u): G[names.index(o), j] for o in {output, "gen_speed", "tower_top_vel"}
         for j, u in enumerate(("wind", "pitch_cmd"))}
    cb, ca = _local_response(controller, model, wind_speed, 1j * w)
    return t_output_wind(P, cb, w, output, atd_controller=ca, atd_measurement="tower_top_vel")


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class LinearPrediction:
    """Linear prediction at one wind speed: omega (rad/s), psd of the output (SI² per rad/s,
    = |T|²S_W), del_ (DEL, Dirlik by default, 1 Hz, range) and sd (√∫S dω)."""

    omega: np.ndarray
    psd: np.ndarray
    del_: float
    sd: float


def prediction_grid(duration: float = 600.0, omega_max: float = 30.0, n: int = 3000) -> np.ndarray:
    """Log-spaced ω grid (rad/s) from 2π/duration (the longest period a record resolves) to omega_max."""
    return np.geomspace(2 * np.pi / positive_scalar(duration, "duration"), positive_scalar(omega_max, "omega_max"), int(n))


def linear_prediction(model, controller, wind_speed, *, output="tower_base_my", m=4.0, omega=None,
                      turbulence_class="B", method="dirlik") -> LinearPrediction:
    """|T_{y,w}|²·S_W and its DEL by a spectral method (Dirlik by default) at one wind speed.

    S_W is :func:`specdesign.wind.rotor_effective_spectrum` (NTM class ``turbulence_class``).
    omega defaults to :func:`prediction_grid` (600 s, 30 rad/s).

    Raises ValueError when the controller destabilises the loop (naming it and the unstable
    poles): |T|²S_W of an unstable loop is finite but describes no response.
    """
    from . import spectral, wind

    bad = unstable_poles(model, controller, wind_speed)
    if bad.size:
        raise ValueError(unstable_message(controller, wind_speed, bad) + "; a linear prediction of an unstable loop is meaningless")
    w = prediction_grid() if omega is None else np.asarray(omega, dtype=float)
    radius = _rotor_radius(model)
    sw = wind.rotor_effective_spectrum(w, wind_speed, radius, turbulence_class=turbulence_class)
    t = closed_loop_response(model, controller, wind_speed, w, output)
    psd = np.abs(t) ** 2 * sw
    return LinearPrediction(omega=w, psd=psd, del_=float(spectral.del_spectral(w, psd, m, method=method)),
                            sd=float(np.sqrt(np.trapezoid(psd, w))))


_AERO_OUTPUTS = ("gen_speed", "tower_top_vel", "pitch")  # rotor speed (gearbox ratio 1), ẋ_top, β


def volterra_response(model, controller, wind_speed, wind, dt, *, order=3, outputs=("tower_base_my",)) -> dict:
    """Closed-loop response of the nonlinear turbine to a periodic wind record as a Volterra
    (perturbation) series about the trim, to ``order`` in the turbulence: frequency domain,
    no time stepping.

    The loop is the linearisation at ``wind_speed`` closed by ``controller`` (any kind with a
    linear form; a scheduled one frozen at the trim, as in :func:`linear_prediction`); the
    aerodynamic loads carry their Taylor expansion to third order
    (:meth:`~specdesign.turbine.TurbineModel.aero_expansion`) in z = (rotor speed, wind − ẋ_top,
    pitch). Term 1 is the linear response y₁ = T_w·w. Term 2 is the loop's response (through
    the ``aero_torque`` and ``thrust`` inputs) to ½ z₁ᵀ H z₁, the quadratic loads along the
    linear trajectory z₁. Term 3 is its response to z₁ᵀ H z₂ + D³[z₁, z₁, z₁]/6, z₂ the
    second-order trajectory. Each product is formed in the time domain and filtered by FFT,
    so ``wind`` must be periodic over its record (as :func:`specdesign.wind.synthesize`
    makes it). With the aerodynamic nonlinearity of class-B turbulence the series to third
    order matches the tower-base DEL of the nonlinear simulation within a few tenths of a
    percent (docs/nonlinearity.md, section (i)).

    model : :class:`~specdesign.turbine.TurbineModel`. wind_speed : operating point (m/s).
    wind : (..., n) rotor-effective wind (m/s, mean included) sampled every ``dt`` s.
    order : 1, 2 or 3. outputs : names from :data:`specdesign.turbine.OUTPUT_NAMES`.
    Returns dict output → array (order, ..., n): term k of the series at index k − 1, SI
    deviation from the trim (sum over axis 0 for the prediction).
    """
    from .closedloop import t_output_wind
    from .turbine import OUTPUT_NAMES

    if not hasattr(model, "aero_expansion"):
        raise TypeError(f"model must be a turbine.TurbineModel (with aero_expansion), got {type(model).__name__}")
    if order not in (1, 2, 3):
        raise ValueError(f"order={order!r} must be 1, 2 or 3")
    outs = (outputs,) if isinstance(outputs, str) else tuple(outputs)
    bad = [o for o in outs if o not in OUTPUT_NAMES]
    if bad or not outs:
        raise ValueError(f"outputs={outputs!r}: choose from {OUTPUT_NAMES}")
    if not _has_linear_form(controller):
        raise TypeError(f"controller {getattr(controller, '__name__', type(controller).__name__)} has no linear "
                        "form (a callable): the Volterra series needs the loop's frequency response")
    dt = positive_scalar(dt, "dt")
    v = float(wind_speed)
    w = np.asarray(wind, dtype=float)
    if w.ndim < 1 or w.shape[-1] < 16 or not np.all(np.isfinite(w)):
        raise ValueError(f"wind must be a finite (..., n ≥ 16) record in m/s, got shape {w.shape}")
    n = w.shape[-1]
    om = 2 * np.pi * np.fft.rfftfreq(n, dt)
    exp = model.aero_expansion(v)
    plant = model.linearize(v, load_inputs=True)
    G = np.asarray(plant(1j * om, squeeze=False))
    names, ins = list(plant.output_labels), list(plant.input_labels)
    cb, ca = _local_response(controller, model, v, 1j * om)
    need = tuple(dict.fromkeys(_AERO_OUTPUTS + outs))

    def loop(u):  # closed-loop responses of ``need`` to input u, on the rfft grid
        P = {(o, k): G[names.index(o), ins.index(src)] for o in need for k, src in (("wind", u), ("pitch_cmd", "pitch_cmd"))}
        return {o: t_output_wind(P, cb, om, o, atd_controller=ca) for o in need}

    T = {u: loop(u) for u in ("wind", "aero_torque", "thrust")}

    def spec(x):
        return np.fft.rfft(x, axis=-1)

    def response(F, direct):  # F: {input: spectrum}; direct: the wind itself in z's relative wind
        y = {o: np.fft.irfft(sum(T[u][o] * X for u, X in F.items()), n=n, axis=-1) for o in need}
        z = np.stack([y["gen_speed"], direct - y["tower_top_vel"], y["pitch"]])
        return y, z

    W = spec(w - v)
    y1, z1 = response({"wind": W}, w - v)
    terms = {o: [y1[o]] for o in outs}
    if order >= 2:
        q2 = 0.5 * np.einsum("kij,i...,j...->k...", exp.hessian, z1, z1)
        y2, z2 = response({"aero_torque": spec(q2[0]), "thrust": spec(q2[1])}, 0.0)
        for o in outs:
            terms[o].append(y2[o])
    if order == 3:
        q3 = (np.einsum("kij,i...,j...->k...", exp.hessian, z1, z2)
              + np.einsum("kijl,i...,j...,l...->k...", exp.third, z1, z1, z1) / 6.0)
        y3, _ = response({"aero_torque": spec(q3[0]), "thrust": spec(q3[1])}, 0.0)
        for o in outs:
            terms[o].append(y3[o])
    return {o: np.stack(t) for o, t in terms.items()}


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class VolterraPrediction:
    """Volterra prediction at one wind speed (:func:`volterra_prediction`): per-record
    ``dels`` (S,) and their damage-pooled ``del_`` (N·m, range, 1 Hz), ``sd`` the pooled
    standard deviation of the output (SI), ``order``, ``seeds`` (S,) and ``duration`` (s)."""

    del_: float
    dels: np.ndarray
    sd: float
    order: int
    seeds: np.ndarray
    duration: float


def volterra_prediction(model, controller, wind_speed, *, seeds=range(1000, 1200), duration=600.0, dt=0.1,
                        order=3, m=4.0, output="tower_base_my", turbulence_class="B", chunk=50) -> VolterraPrediction:
    """DEL of ``output`` predicted by the Volterra series (:func:`volterra_response`) over
    synthetic periodic wind records: the nonlinear counterpart of :func:`linear_prediction`,
    made before any time-domain simulation (FFT-fast: a few ms per record, `benchmarks/volterra.py`).

    seeds : wind seeds (records from :func:`specdesign.simulate.wind_series`, periodic over
        ``duration`` s, so no transient is needed); the DEL's sampling error falls as 1/√S,
        and two controllers given the same seeds are compared paired. dt : sample spacing (s).
    order : 1-3. m : Wöhler exponent. chunk : records per FFT batch (memory).
    """
    from .fatigue import del_rainflow
    from .simulate import wind_series

    seeds = seeds_from(seeds)
    duration, dt, m = positive_scalar(duration, "duration"), positive_scalar(dt, "dt"), positive_scalar(m, "m")
    dels, sq = [], []
    for lo in range(0, seeds.size, max(int(chunk), 1)):
        part = seeds[lo:lo + max(int(chunk), 1)]
        wind = wind_series(_rotor_radius(model), [wind_speed], part, duration, dt, turbulence_class)[0]
        y = volterra_response(model, controller, wind_speed, wind, dt, order=order, outputs=(output,))[output].sum(axis=0)
        dels += [del_rainflow(row, m, duration) for row in y]
        sq.append(y.var(axis=-1))
    dels = np.asarray(dels)
    return VolterraPrediction(del_=float(_pool("tower_del", dels, m)), dels=dels, sd=float(np.sqrt(np.mean(np.concatenate(sq)))),
                              order=int(order), seeds=seeds, duration=duration)


def _rotor_radius(model):
    if model is None or not hasattr(model, "rotor_radius"):
        from . import turbine

        return turbine.iea15mw().rotor_radius
    return model.rotor_radius


# ----------------------------------------------------------------------------- statistics
def _pool(name, x, m, axis=-1):
    if name == "tower_del":
        return np.mean(x**m, axis=axis) ** (1.0 / m)
    if name == "mean_power":
        return np.mean(x, axis=axis)
    return np.sqrt(np.mean(x**2, axis=axis))


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class PairedChange:
    """Relative change (%) designed vs baseline per wind speed, with its standard error.

    change : (W,) 100·(X_des/X_base − 1) of the seed-pooled indicator; se : (W,) standard
    error over paired seeds; method : "jackknife" or "bootstrap"; n_seeds : S.
    """

    indicator: str
    wind_speeds: np.ndarray
    change: np.ndarray
    se: np.ndarray
    method: str
    n_seeds: int


def paired_change(designed, baseline, indicator="tower_del", *, m=4.0, wind_speeds=None, method="jackknife",
                  n_boot=2000, seed=0) -> PairedChange:
    """Paired-seed relative change of an indicator, with jackknife (default) or bootstrap SE.

    designed, baseline : (W, S) per-run values on the same seeds (seed j of both columns saw
    the same wind). Seeds are pooled per :mod:`specdesign.validate` (DEL by damage, SDs by
    variance). Jackknife: θ_(i) from all seeds but i, SE = √((S−1)/S Σ(θ_(i) − θ̄)²).
    Bootstrap: resample seed indices (the same for both controllers) ``n_boot`` times with
    ``np.random.default_rng(seed)``; SE = SD of the replicates.
    """
    a = np.atleast_2d(np.asarray(designed, dtype=float))
    b = np.atleast_2d(np.asarray(baseline, dtype=float))
    if a.shape != b.shape:
        raise ValueError(f"designed {a.shape} and baseline {b.shape} must have the same (W, S) shape: paired seeds")
    if indicator not in _INDICATORS:
        raise ValueError(f"indicator={indicator!r} must be one of {_INDICATORS}")
    W, S = a.shape
    vs = np.arange(W, dtype=float) if wind_speeds is None else np.asarray(wind_speeds, dtype=float)

    def theta(ia, ib):
        return 100.0 * (_pool(indicator, ia, m) / _pool(indicator, ib, m) - 1.0)

    est = theta(a, b)
    se = _resampled_se(lambda idx: theta(a[:, idx], b[:, idx]), S, W, method, n_boot, seed)
    return PairedChange(indicator=indicator, wind_speeds=vs, change=est, se=se, method=method, n_seeds=S)


def _resampled_se(theta, S, W, method, n_boot=2000, seed=0):
    """SE over paired seeds of a statistic ``theta(seed_indices) → (W,)``: jackknife
    (leave one seed out) or bootstrap (the same resampled seeds for every array)."""
    if method not in ("jackknife", "bootstrap"):
        raise ValueError(f"method={method!r} must be 'jackknife' or 'bootstrap'")
    if S < 2:
        return np.full(W, np.nan)
    if method == "jackknife":
        keep = np.arange(S)
        reps = np.stack([theta(np.delete(keep, i)) for i in range(S)], axis=-1)
        return np.sqrt((S - 1) / S * np.sum((reps - reps.mean(axis=-1, keepdims=True)) ** 2, axis=-1))
    rng = np.random.default_rng(seed)
    reps = np.stack([theta(i) for i in rng.integers(0, S, size=(int(n_boot), S))], axis=-1)
    return reps.std(axis=-1, ddof=1)


# ----------------------------------------------------------------------------- campaign
@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Campaign:
    """Results of controllers × wind speeds × seeds (paired: every controller saw the same seeds).

    controllers : names, in order. wind_speeds : (W,) m/s. seeds : (S,). duration, dt : record
    length and sample spacing (s). m : Wöhler exponent.
    values : dict indicator → (C, W, S) per-run values (see :class:`Indicators` for units).
    predicted_del : (C, W) linear prediction of the tower-base DEL (Dirlik on |T|²S_W, N·m);
        NaN for controllers without a linear form (callables).
    omega : (nω,) Welch grid (rad/s). welch : dict output → (C, W, nω) seed-averaged Welch PSD
    per rad/s. predicted_psd : dict output → (C, W, nω) |T|²S_W on the same grid.
    series : dict controller → SimulationResult (W, k, n) of the first k seeds kept
        (``keep_series``), else {}.
    linear_values : like ``values`` from the same seeds run through the *linearised* model
        (``run_campaign(linear_twin=True)``; NaN for controllers without a linear form), else
        {}. It splits the prediction error into the spectral method's part and the plant's
        nonlinearity (:func:`acceptance`).
    volterra_values : like ``values`` from the Volterra series of order ``volterra_order``
        (:func:`volterra_response`) on the same wind (``run_campaign(volterra=k)``; NaN for
        controllers without a linear form), else {}: a prediction that includes the
        aerodynamic nonlinearity, still made from the linear loop.
    unstable : (C, W) bool: the controller destabilises the linearised loop or its simulation
        diverged at that wind speed; its values and predictions there are NaN (with a
        warning when the campaign ran), and the tables print "unstable".
    """

    controllers: tuple
    wind_speeds: np.ndarray
    seeds: np.ndarray
    duration: float
    dt: float
    m: float
    values: dict = field(repr=False)
    predicted_del: np.ndarray = field(repr=False)
    omega: np.ndarray = field(repr=False)
    welch: dict = field(repr=False)
    predicted_psd: dict = field(repr=False)
    series: dict = field(default_factory=dict, repr=False)
    linear_values: dict = field(default_factory=dict, repr=False)
    volterra_values: dict = field(default_factory=dict, repr=False)
    volterra_order: int = 0
    unstable: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.unstable is None:
            object.__setattr__(self, "unstable", np.zeros((len(self.controllers), np.size(self.wind_speeds)), bool))

    def index(self, controller: str) -> int:
        if controller not in self.controllers:
            raise ValueError(f"controller {controller!r} not in the campaign {self.controllers}")
        return self.controllers.index(controller)

    def change(self, designed, baseline, indicator="tower_del", **kw) -> PairedChange:
        """:func:`paired_change` of ``indicator`` between two controllers of the campaign."""
        i, j = self.index(designed), self.index(baseline)
        return paired_change(self.values[indicator][i], self.values[indicator][j], indicator, m=self.m,
                             wind_speeds=self.wind_speeds, **kw)


_SPECTRA = ("gen_speed", "tower_base_my")


def _campaign_point(model, controllers, v, seeds, duration, dt, record_dt, transient, m, predict,
                    turbulence_class, keep_series, nperseg, linear_twin=False, volterra=0):
    """One wind speed, every controller, the same seeds: indicators, spectra, predictions."""
    from . import wind as wmod
    from .closedloop import ClosedLoopUnstableWarning
    from .simulate import SimulationDivergedError, SimulationResult, simulate, wind_series

    n_keep = len(seeds) if keep_series is True else int(keep_series)
    radius = _rotor_radius(model)
    wdt = record_dt
    wind = wind_series(radius, [v], seeds, transient + duration + wdt, wdt, turbulence_class)
    out = {"values": {}, "linear": {}, "volterra": {}, "pred": [], "welch": {k: [] for k in _SPECTRA}, "ppsd": {k: [] for k in _SPECTRA},
           "series": {}, "unstable": []}
    omega = welch_psd(np.zeros((1, int(round(duration / record_dt)))), record_dt, nperseg)[0]
    nan_ind = {k: np.full((1, len(seeds)), np.nan) for k in _INDICATORS}
    for name, c in controllers.items():
        bad = unstable_poles(model, c, v) if _has_linear_form(c) else np.zeros(0)
        if bad.size:
            warnings.warn(unstable_message(c, v, bad) + f"; campaign results of {name!r} at {v:g} m/s are NaN",
                          ClosedLoopUnstableWarning, stacklevel=3)
        r = None
        if not bad.size:  # an unstable loop is not simulated: nothing of it would be a result
            try:
                r = simulate(model, c, [v], seeds=seeds, wind=wind, wind_dt=wdt, duration=duration, dt=dt,
                             record_dt=record_dt, transient=transient)
            except SimulationDivergedError as err:
                warnings.warn(f"{err}; campaign results of {name!r} at {v:g} m/s are NaN", ClosedLoopUnstableWarning,
                              stacklevel=3)
                bad = np.array([np.nan])
        out["unstable"].append(bool(bad.size))
        if r is None:  # every entry NaN
            for k in _INDICATORS:
                out["values"].setdefault(k, []).append(nan_ind[k][0])
                if linear_twin:
                    out["linear"].setdefault(k, []).append(nan_ind[k][0])
                if volterra:
                    out["volterra"].setdefault(k, []).append(nan_ind[k][0])
            out["pred"].append(np.nan)
            for k in _SPECTRA:
                out["welch"][k].append(np.full(omega.size, np.nan))
                out["ppsd"][k].append(np.full(omega.size, np.nan))
            continue
        ind = indicators(r.outputs, r.dt, m)
        for k, val in ind.as_dict().items():
            out["values"].setdefault(k, []).append(val[0])
        if linear_twin:
            lin = {k: np.full((1, len(seeds)), np.nan) for k in _INDICATORS}
            if _has_linear_form(c):
                try:
                    rl = simulate(model, c, [v], seeds=seeds, wind=wind, wind_dt=wdt, duration=duration, dt=dt,
                                  record_dt=record_dt, transient=transient, linear=True)
                    lin = indicators(rl.outputs, rl.dt, m).as_dict()
                except SimulationDivergedError as err:  # keep the nonlinear results: only the twin is NaN
                    warnings.warn(f"{err}; the linear twin of {name!r} at {v:g} m/s is NaN", ClosedLoopUnstableWarning,
                                  stacklevel=3)
            for k, val in lin.items():
                out["linear"].setdefault(k, []).append(val[0])
        if volterra:
            if _has_linear_form(c):
                vol = _volterra_indicators(model, c, v, wind[0], wdt, volterra, transient, r, m)
            else:
                vol = {k: np.full((1, len(seeds)), np.nan) for k in _INDICATORS}
            for k, val in vol.items():
                out["volterra"].setdefault(k, []).append(val[0])
        for k in _SPECTRA:
            omega, p = welch_psd(r[k][0], r.dt, nperseg)
            out["welch"][k].append(p.mean(axis=0))
        if predict and _has_linear_form(c):
            pr = linear_prediction(model, c, v, m=m, omega=prediction_grid(duration), turbulence_class=turbulence_class)
            out["pred"].append(pr.del_)
            sw = wmod.rotor_effective_spectrum(omega, v, radius, turbulence_class=turbulence_class)
            pos = omega > 0  # an integrating controller makes T singular at ω = 0: leave DC out
            for k in _SPECTRA:
                pp = np.full(omega.size, np.nan)
                pp[pos] = np.abs(closed_loop_response(model, c, v, omega[pos], k)) ** 2 * sw[pos]
                out["ppsd"][k].append(pp)
        else:
            out["pred"].append(np.nan)
            for k in _SPECTRA:
                out["ppsd"][k].append(np.full(omega.size, np.nan))
        if n_keep:
            outs = {k: a[:, :n_keep] for k, a in r.outputs.items()}
            out["series"][name] = SimulationResult(time=r.time, wind_speeds=r.wind_speeds, seeds=seeds[:n_keep],
                                                   outputs=outs, dt=r.dt, sim_dt=r.sim_dt, controller=name)
    out["omega"] = omega
    return out


def _volterra_indicators(model, controller, v, wind, wdt, order, transient, sim, m):
    """Indicators of the Volterra prediction over the records of the simulation ``sim``
    (same wind, same window: the wind sample at ``transient`` is the first record sample)."""
    outs = ("tower_base_my", "gen_speed", "power", "pitch")
    terms = volterra_response(model, controller, v, wind, wdt, order=order, outputs=outs)
    op = model.trim(v)
    y0 = dict(zip(model.output_names, model.evaluate_outputs(op.x, v, op.pitch, op.gen_torque)))
    i0, n = int(round(transient / wdt)), sim.outputs["tower_base_my"].shape[-1]
    series = {o: (y0[o] + terms[o].sum(axis=0)[..., i0:i0 + n])[None] for o in outs}
    return indicators(series, sim.dt, m).as_dict()


def _has_linear_form(c) -> bool:
    from .simulate import ScheduledController, _is_lti_like

    return isinstance(c, ScheduledController) or _is_lti_like(c)


def _check_campaign_step(model, controllers, vs, dt):
    """Up front, before the first simulation: a step too large for the plant, or for any
    controller where its loop is stable (:func:`specdesign.simulate.simulate` would refuse it
    at that wind speed only after the earlier speeds had run)."""
    from ._checks import positive_scalar
    from .simulate import _check_loop_step, _check_step, turbine_plant

    dt = positive_scalar(dt, "dt")
    plant = turbine_plant(model)
    if plant.linearize is None:
        return
    _check_step(plant, vs, dt)
    for name, c in controllers.items():
        if not _has_linear_form(c):
            continue
        for v in vs:
            if not unstable_poles(plant, c, float(v)).size:  # an unstable loop is reported by the campaign
                try:
                    _check_loop_step(plant, c, float(v), dt)
                except ValueError as err:
                    raise ValueError(f"campaign controller {name!r}: {err}") from None


def run_campaign(controllers, wind_speeds, seeds, *, model=None, duration=600.0, dt=0.02, record_dt=0.1,
                 transient=60.0, m=4.0, predict=True, turbulence_class="B", keep_series=False,
                 linear_twin=False, volterra=0, executor=None, progress=None, nperseg=None) -> Campaign:
    """Run every controller at every wind speed on the same seeds and post-process.

    controllers : dict name → controller (LTI, Controller, ScheduledController or callable;
        see :mod:`specdesign.simulate`). wind_speeds (m/s), seeds: distinct integers, or an
        integer n for the seeds 0..n−1 (:func:`seeds_from`, as in campaign files); every controller
        sees the same wind series per (wind speed, seed) (:func:`specdesign.simulate.seed_for`).
    model : TurbineModel (default ``turbine.iea15mw()``). duration, dt, record_dt, transient:
        as in :func:`specdesign.simulate.simulate` (s). m : Wöhler exponent of the DEL.
    predict : compute the linear predictions (|T|²S_W, Dirlik DEL) for LTI-like controllers.
    keep_series : keep time series in ``Campaign.series``: True for every seed, an int k for
        the first k seeds (enough for Fig. 9), False for none (memory: C·W·k·n·8 bytes per
        output).
    linear_twin : also run every LTI-like controller through the linearised model on the
        same wind (twice the simulation time): ``Campaign.linear_values``, and
        :func:`acceptance` then splits the deviation into the spectral method's part
        (linear-model rainflow − prediction) and the plant nonlinearity's part (nonlinear −
        linear-model rainflow).
    volterra : 0 (none), or 1-3: also evaluate every LTI-like controller's Volterra series of
        that order (:func:`volterra_response`) on the same wind and window, FFT-fast (well
        under a second per controller and wind speed): ``Campaign.volterra_values``, and
        :func:`acceptance` compares rainflow with it too.
    executor : optional ``concurrent.futures.Executor`` (a dask.distributed Client qualifies);
        wind speeds are submitted as separate tasks. Default: run locally, the compiled
        simulator already using every core. For a local process pool use a "spawn" context,
        ``ProcessPoolExecutor(mp_context=multiprocessing.get_context("spawn"))``: numba's
        OpenMP threads make fork() unsafe.
    progress : show a tqdm bar over wind speeds; None → only when stderr is a terminal.
    """
    if not isinstance(controllers, dict) or not controllers:
        raise TypeError("controllers must be a non-empty dict {name: controller}")
    if model is None:
        from . import turbine

        model = turbine.iea15mw()
    vs = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    seeds = seeds_from(seeds)
    if volterra not in (0, 1, 2, 3) or isinstance(volterra, bool):
        raise ValueError(f"volterra={volterra!r} must be 0 (none) or an order 1, 2 or 3")
    if volterra and not hasattr(model, "aero_expansion"):
        raise TypeError(f"volterra={volterra} needs a turbine.TurbineModel, got {type(model).__name__}")
    _check_campaign_step(model, controllers, vs, dt)
    args = [(model, controllers, float(v), seeds, duration, dt, record_dt, transient, m, predict, turbulence_class,
             keep_series, nperseg, bool(linear_twin), int(volterra)) for v in vs]
    show = (sys.stderr.isatty()) if progress is None else bool(progress)
    from tqdm.auto import tqdm

    bar = tqdm(total=len(args), desc="validation", unit="wind speed", disable=not show)
    try:
        if executor is None:
            points = []
            for a in args:
                points.append(_campaign_point(*a))
                bar.update()
        else:
            futs = [executor.submit(_campaign_point, *a) for a in args]
            points = []
            for f in futs:
                points.append(f.result())
                bar.update()
    finally:
        bar.close()
    names = tuple(controllers)
    values = {k: np.stack([np.stack(p["values"][k]) for p in points], axis=1) for k in _INDICATORS}
    series = {}
    if keep_series:
        from .simulate import SimulationResult

        for name in names:
            rs = [p["series"].get(name) for p in points]
            ok = next((r for r in rs if r is not None), None)
            if ok is None:  # unstable or diverged at every speed (warned): no series to keep
                continue
            # where it was unstable or diverged (warned), NaN series: the other speeds are kept
            outs = {k: np.concatenate([(r.outputs[k] if r is not None else np.full_like(ok.outputs[k], np.nan))
                                       for r in rs], axis=0) for k in ok.outputs}
            series[name] = SimulationResult(time=ok.time, wind_speeds=vs, seeds=ok.seeds, outputs=outs, dt=ok.dt,
                                            sim_dt=ok.sim_dt, controller=name)
    return Campaign(
        controllers=names, wind_speeds=vs, seeds=seeds, duration=float(duration), dt=float(record_dt), m=float(m),
        values=values,
        predicted_del=np.array([p["pred"] for p in points]).T,
        omega=points[0]["omega"],
        welch={k: np.stack([np.stack(p["welch"][k]) for p in points], axis=1) for k in _SPECTRA},
        predicted_psd={k: np.stack([np.stack(p["ppsd"][k]) for p in points], axis=1) for k in _SPECTRA},
        series=series,
        linear_values={k: np.stack([np.stack(p["linear"][k]) for p in points], axis=1) for k in _INDICATORS}
        if linear_twin else {},
        volterra_values={k: np.stack([np.stack(p["volterra"][k]) for p in points], axis=1) for k in _INDICATORS}
        if volterra else {},
        volterra_order=int(volterra),
        unstable=np.array([p["unstable"] for p in points]).T,
    )


def concat_campaigns(campaigns) -> Campaign:
    """One :class:`Campaign` from campaigns over different wind speeds (e.g. one per operating
    point, each with that point's designed controllers under the same names). They must share
    controller names, seeds, duration, sampling, m and Welch grid; wind speeds are stacked in
    the given order."""
    camps = list(campaigns)
    if not camps or not all(isinstance(c, Campaign) for c in camps):
        raise TypeError("campaigns must be a non-empty sequence of validate.Campaign")
    c0 = camps[0]
    for k, c in enumerate(camps[1:], 1):
        same = (c.controllers == c0.controllers and np.array_equal(c.seeds, c0.seeds) and c.duration == c0.duration
                and c.dt == c0.dt and c.m == c0.m and np.array_equal(c.omega, c0.omega)
                and bool(c.linear_values) == bool(c0.linear_values) and bool(c.series) == bool(c0.series)
                and c.volterra_order == c0.volterra_order)
        if not same:
            raise ValueError(f"campaigns[{k}] differs from campaigns[0] in controllers, seeds, duration, dt, m, Welch "
                             "grid, linear twin, Volterra order or kept series: run them with the same settings")
    vs = np.concatenate([c.wind_speeds for c in camps])
    if len(set(vs.tolist())) != vs.size:
        raise ValueError(f"campaigns repeat a wind speed ({vs.tolist()} m/s)")

    def cat(dicts, axis=1):
        return {k: np.concatenate([d[k] for d in dicts], axis=axis) for k in dicts[0]} if dicts[0] else {}

    series = {}
    for name in c0.series:
        rs = [c.series[name] for c in camps]
        series[name] = dataclasses.replace(rs[0], wind_speeds=np.concatenate([r.wind_speeds for r in rs]),
                                           outputs=cat([r.outputs for r in rs], axis=0))
    return dataclasses.replace(
        c0, wind_speeds=vs, values=cat([c.values for c in camps]),
        predicted_del=np.concatenate([c.predicted_del for c in camps], axis=1),
        welch=cat([c.welch for c in camps]), predicted_psd=cat([c.predicted_psd for c in camps]), series=series,
        linear_values=cat([c.linear_values for c in camps]), volterra_values=cat([c.volterra_values for c in camps]),
        unstable=np.concatenate([c.unstable for c in camps], axis=1))


# ----------------------------------------------------------------------------- tables
@dataclass(frozen=True)
class Table:
    """A plain table: ``columns`` (header strings) and ``rows`` (label, values), values as
    floats (NaN shown empty). ``fmt`` formats the values; ``title`` and ``note`` are text.
    ``marks``: per value column, a word shown in place of NaN (e.g. "unstable")."""

    title: str
    columns: tuple
    rows: tuple
    fmt: str = "{:.2f} %"
    note: str = ""
    row_fmt: tuple = ()  # (label, fmt) pairs overriding ``fmt`` for those rows (e.g. pp)
    marks: tuple = ()

    def _cell(self, v, fmt=None, mark=""):
        return mark if v is None or (isinstance(v, float) and math.isnan(v)) else (fmt or self.fmt).format(v)

    def to_markdown(self) -> str:
        head = "| " + " | ".join(self.columns) + " |"
        sep = "|" + "|".join("---" for _ in self.columns) + "|"
        fmts = dict(self.row_fmt)
        marks = tuple(self.marks) + ("",) * (len(self.columns) - 1 - len(self.marks))
        body = ["| " + " | ".join([label] + [self._cell(float(v), fmts.get(label), mk) for v, mk in zip(vals, marks)]) + " |"
                for label, vals in self.rows]
        text = [f"**{self.title}**", "", head, sep, *body]
        if self.note:
            text += ["", self.note]
        return "\n".join(text) + "\n"

    _repr_markdown_ = to_markdown

    def to_csv(self, path) -> Path:
        """Write the table (values as plain numbers, NaN empty) to ``path``; returns the path."""
        path = Path(path)
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(self.columns)
            for label, vals in self.rows:
                w.writerow([label] + ["" if math.isnan(float(v)) else repr(float(v)) for v in vals])
        return path

    def values(self) -> np.ndarray:
        """(n_rows, n_columns − 1) float array of the table body."""
        return np.array([[float(v) for v in vals] for _, vals in self.rows])


def _speed_columns(vs):
    return tuple(["Indicator"] + [f"{v:g} m/s" for v in vs] + ["Mean"])


def _unstable_marks(campaign, *names):
    """Per speed column (+ Mean): "unstable" where any of the controllers is (the Mean too
    when any speed is: its NaN is theirs, not a missing number)."""
    bad = np.any(campaign.unstable[[campaign.index(n) for n in names]], axis=0)
    return tuple("unstable" if b else "" for b in bad) + ("unstable" if np.any(bad) else "",)


def table2(campaign: Campaign, designed: str, baseline: str, *, k=WEIBULL_K, scale=WEIBULL_A) -> Table:
    """The paper's Table 2: relative change (%) of each indicator, designed vs baseline, per
    wind speed, and the Weibull-weighted mean (weights: :func:`weibull_weights`)."""
    w = weibull_weights(campaign.wind_speeds, k, scale)
    rows = []
    for ind in ("gen_speed_sd", "mean_power", "tower_del", "pitch_sd", "pitch_rate_sd"):
        ch = campaign.change(designed, baseline, ind).change
        rows.append((_LABELS[ind], tuple(ch) + (float(w @ ch),)))
    return Table(
        title=f"Table 2: change of the indicators, {designed} vs {baseline}",
        columns=_speed_columns(campaign.wind_speeds), rows=tuple(rows),
        note=f"Relative change 100·(X_{designed}/X_{baseline} − 1) over {campaign.seeds.size} paired seeds of "
             f"{campaign.duration:g} s; DEL with m = {campaign.m:g}, 1 Hz. Mean: weighted by the Weibull pdf "
             f"(k = {k}, A = {scale} m/s) at the operating points, normalised.",
        marks=_unstable_marks(campaign, designed, baseline),
    )


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Acceptance:
    """Linear prediction vs rainflow of the tower-base DEL reduction, per wind speed (%).

    predicted : 100·(1 − DEL_pred,des/DEL_pred,base) from Dirlik on |T|²S_W.
    rainflow : 100·(1 − DEL_rf,des/DEL_rf,base), seeds pooled by damage, paired.
    deviation : rainflow − predicted (percentage points); se : its standard error over paired
    seeds (the prediction has no sampling error). n_seeds : S. method : SE method.

    With a linear twin (``run_campaign(linear_twin=True)``), the deviation splits exactly into
    spectral_deviation = rainflow_linear − predicted (the spectral method against rainflow on
    the linearised model, same seeds; SE se_spectral) and nonlinear_deviation = rainflow −
    rainflow_linear (the plant's nonlinearity; SE se_nonlinear, small because both runs saw
    the same wind). All NaN without a linear twin.

    With a Volterra prediction (``run_campaign(volterra=k)``): volterra = the reduction by
    rainflow on the order-``volterra_order`` Volterra series over the same wind (%),
    volterra_deviation = rainflow − volterra (pp) and se_volterra its SE over paired seeds.
    NaN (order 0) without one.
    """

    wind_speeds: np.ndarray
    predicted: np.ndarray
    rainflow: np.ndarray
    deviation: np.ndarray
    se: np.ndarray
    n_seeds: int
    method: str
    rainflow_linear: np.ndarray
    spectral_deviation: np.ndarray
    se_spectral: np.ndarray
    nonlinear_deviation: np.ndarray
    se_nonlinear: np.ndarray
    volterra: np.ndarray
    volterra_deviation: np.ndarray
    se_volterra: np.ndarray
    volterra_order: int = 0

    def passes(self, tolerance_pp: float = 1.0, against: str = "linear") -> np.ndarray:
        """True where |rainflow − prediction| ≤ tolerance (percentage points); ``against`` =
        "linear" (Dirlik on |T|²S_W) or "volterra" (the Volterra series, same seeds)."""
        if against not in ("linear", "volterra"):
            raise ValueError(f"against={against!r} must be 'linear' or 'volterra'")
        if against == "volterra" and not self.volterra_order:
            raise ValueError("against='volterra' needs a campaign run with run_campaign(volterra=k)")
        dev = self.deviation if against == "linear" else self.volterra_deviation
        return np.abs(dev) <= tolerance_pp


def _paired_gap(values, twin, i, j, m, method):
    """(reduction on ``twin`` − reduction on ``values``, pp, and its SE): the rainflow
    reduction of controller i vs j on two evaluations of the same seeds."""
    a, b, al, bl = values[i], values[j], twin[i], twin[j]

    def gap(idx):
        return 100.0 * (_pool("tower_del", al[:, idx], m) / _pool("tower_del", bl[:, idx], m)
                        - _pool("tower_del", a[:, idx], m) / _pool("tower_del", b[:, idx], m))

    return gap(slice(None)), _resampled_se(gap, a.shape[1], a.shape[0], method)


def acceptance(campaign: Campaign, designed: str, baseline: str, *, method="jackknife") -> Acceptance:
    """Per wind speed: linear-prediction vs rainflow reduction of the tower-base DEL, their
    deviation (pp) and its standard error over paired seeds; split into the spectral and the
    nonlinear part when the campaign has a linear twin, and compared with the Volterra
    prediction when it has one."""
    i, j = campaign.index(designed), campaign.index(baseline)
    pred = 100.0 * (1.0 - campaign.predicted_del[i] / campaign.predicted_del[j])
    ch = campaign.change(designed, baseline, "tower_del", method=method)
    rf = -ch.change
    nan = np.full(rf.shape, np.nan)
    rfl, dsp, sesp, dnl, senl = nan, nan, nan, nan, nan
    vol, dvol, sevol = nan, nan, nan
    values = campaign.values["tower_del"]
    if campaign.linear_values:
        lin = paired_change(campaign.linear_values["tower_del"][i], campaign.linear_values["tower_del"][j], "tower_del",
                            m=campaign.m, wind_speeds=campaign.wind_speeds, method=method)
        rfl, sesp = -lin.change, lin.se
        dsp = rfl - pred
        dnl, senl = _paired_gap(values, campaign.linear_values["tower_del"], i, j, campaign.m, method)
    if campaign.volterra_values:
        vc = paired_change(campaign.volterra_values["tower_del"][i], campaign.volterra_values["tower_del"][j],
                           "tower_del", m=campaign.m, wind_speeds=campaign.wind_speeds, method=method)
        vol = -vc.change
        dvol, sevol = _paired_gap(values, campaign.volterra_values["tower_del"], i, j, campaign.m, method)
    return Acceptance(wind_speeds=campaign.wind_speeds, predicted=pred, rainflow=rf, deviation=rf - pred, se=ch.se,
                      n_seeds=ch.n_seeds, method=method, rainflow_linear=rfl, spectral_deviation=dsp, se_spectral=sesp,
                      nonlinear_deviation=dnl, se_nonlinear=senl, volterra=vol, volterra_deviation=dvol,
                      se_volterra=sevol, volterra_order=campaign.volterra_order)


def table3(campaign: Campaign, designed: str, baseline: str, *, promised=None, method="jackknife") -> Table:
    """The paper's Table 3: tower-base DEL reduction promised by the specification (optional
    dict wind speed → %), linear prediction, rainflow evaluation, |deviation| and its SE.
    Mean column: plain mean of the |deviation| (as in the paper)."""
    acc = acceptance(campaign, designed, baseline, method=method)
    nan = float("nan")
    rows = []
    if promised is not None:
        prom = {float(k): float(v) for k, v in promised.items()}
        rows.append(("Specification", tuple(prom.get(float(v), nan) for v in acc.wind_speeds) + (nan,)))
    dev = np.abs(acc.deviation)
    rows += [
        ("Linear prediction", tuple(acc.predicted) + (nan,)),
        ("Rainflow evaluation", tuple(acc.rainflow) + (nan,)),
        ("Estimation deviation", tuple(dev) + (float(np.mean(dev)),)),
        (f"Standard error ({method}, paired seeds)", tuple(acc.se) + (nan,)),
    ]
    pp = [("Estimation deviation", "{:.2f} pp"), (f"Standard error ({method}, paired seeds)", "{:.2f} pp")]
    extra = []  # (row label, per-speed values, format or None for the table's default)
    if campaign.linear_values:  # the split of the signed deviation: spectral method + plant nonlinearity
        extra += [
            ("Rainflow evaluation, linearised model", acc.rainflow_linear, None),
            ("Spectral-method part (linearised − prediction)", acc.spectral_deviation, "{:+.2f} pp"),
            ("Spectral-method part: standard error", acc.se_spectral, "{:.2f} pp"),
            ("Nonlinear part (rainflow − linearised)", acc.nonlinear_deviation, "{:+.2f} pp"),
            ("Nonlinear part: standard error", acc.se_nonlinear, "{:.2f} pp"),
        ]
    if campaign.volterra_values:  # the prediction that includes the aerodynamic nonlinearity
        extra += [
            (f"Volterra prediction (order {acc.volterra_order}, rainflow, same seeds)", acc.volterra, None),
            ("Deviation from the Volterra prediction", acc.volterra_deviation, "{:+.2f} pp"),
            ("Deviation from the Volterra prediction: standard error", acc.se_volterra, "{:.2f} pp"),
        ]
    for name, vals, fmt in extra:
        rows.append((name, tuple(vals) + (nan,)))
        if fmt:
            pp.append((name, fmt))
    return Table(
        title=f"Table 3: tower-base fatigue (DEL) reduction, {designed} vs {baseline}",
        columns=_speed_columns(campaign.wind_speeds), rows=tuple(rows),
        note=f"{acc.n_seeds} paired seeds of {campaign.duration:g} s; DEL with m = {campaign.m:g} at 1 Hz; "
             "linear prediction by Dirlik on |T|²S_W; deviation in percentage points.",
        row_fmt=tuple(pp),
        marks=_unstable_marks(campaign, designed, baseline),
    )


# ----------------------------------------------------------------------------- configuration
# One schema for campaign files: key → (check, what it must be). Every key of the file is
# checked, at every level, before the first simulation: a typo or a wrong type is an error
# naming the file and the key, not a traceback after minutes of simulation.
_TOP_KEYS = ("turbine", "wind_speeds", "seeds", "duration", "dt", "record_dt", "transient", "wohler_exponent",
             "turbulence_class", "controllers", "baseline", "designed", "promised", "output", "linear_twin", "volterra")
_CONTROLLER_KEYS = {"rosco": {"kind", "wind_speeds", "name"}, "file": {"kind", "file", "name"}}


class ConfigError(ValueError):
    """A campaign or controller file that does not follow the schema (docs/validation.md)."""


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _need(ok, path, key, what):
    if not ok:
        raise ConfigError(f"{path}: {key} must be {what}")


def _number(cfg, key, path, default, *, positive=True):
    v = cfg.get(key, default)
    _need(_number_ok(v, positive), path, key, "a positive number" if positive else "a number ≥ 0")
    return float(v)


def _number_ok(v, positive):
    return _is_number(v) and (v > 0 if positive else v >= 0)


def seeds_from(seeds) -> np.ndarray:
    """The seeds of a campaign: an integer n means the n seeds 0, 1, …, n − 1 (in a campaign
    file and in :func:`run_campaign` alike); a sequence lists distinct integer seeds."""
    if isinstance(seeds, (int, np.integer)) and not isinstance(seeds, bool):
        if seeds < 1:
            raise ValueError(f"seeds={seeds!r}: an integer n means the seeds 0..n−1 and must be ≥ 1")
        return np.arange(int(seeds), dtype=np.int64)
    items = list(np.atleast_1d(np.asarray(seeds, dtype=object)))
    if not items or not all(isinstance(s, (int, np.integer)) and not isinstance(s, bool) for s in items):
        raise ValueError(f"seeds must be an integer n (the seeds 0..n−1) or a non-empty list of integers, got {seeds!r}")
    out = np.asarray(items, dtype=np.int64)
    if len(set(out.tolist())) != out.size:
        raise ValueError(f"seeds must be distinct, got {out.tolist()}")
    return out


def _coefficients(v, path, where):
    ok = isinstance(v, list) and len(v) > 0 and all(_is_number(x) for x in v)
    _need(ok, path, where, "a non-empty list of finite numbers (descending powers of s)")
    return np.asarray(v, float)


def load_controller(spec: dict, base: Path, model, *, config=None, name="controller"):
    """A controller from a campaign-file entry (``docs/validation.md``: kind "rosco" or
    "file"); every key of the entry and of the controller file is checked, and every error
    is a :class:`ConfigError` (or FileNotFoundError/OSError) naming the file and the key."""
    import control

    from .simulate import ScheduledController, rosco_scheduled, scheduled

    where = f"controllers.{name}"
    base = Path(base)
    src = config if config is not None else base
    if not isinstance(spec, dict):
        raise ConfigError(f"{src}: {where} must be a table with 'kind' = \"rosco\" or 'file' = \"<controller.json>\"")
    kind = spec.get("kind", "file")
    if not isinstance(kind, str) or kind not in _CONTROLLER_KEYS:
        raise ConfigError(f"{src}: {where}.kind={kind!r} must be \"rosco\" or \"file\"")
    extra = set(spec) - _CONTROLLER_KEYS[kind]
    if extra:
        raise ConfigError(f"{src}: unknown key(s) {sorted(extra)} in {where}; allowed for kind \"{kind}\": "
                          f"{sorted(_CONTROLLER_KEYS[kind])}")
    label = spec.get("name", name)
    _need(isinstance(label, str) and label, src, f"{where}.name", "a non-empty string (the controller's label)")
    if kind == "rosco":
        vs = spec.get("wind_speeds")
        if vs is not None:
            vs = _wind_speeds(vs, model, src, f"{where}.wind_speeds")
        try:
            return rosco_scheduled(model, vs, name=label)
        except ValueError as e:
            raise ConfigError(f"{src}: {where}.wind_speeds: {e}") from None
    _need(isinstance(spec.get("file"), str) and spec["file"], src, f"{where}.file", "the path of a controller JSON file")
    path = (base / spec["file"]).resolve()
    if not path.exists():
        raise FileNotFoundError(f"{src}: {where}.file: controller file {path} does not exist")
    if not path.is_file():
        raise ConfigError(f"{src}: {where}.file: {path} is not a file; give the path of a controller JSON file")
    try:
        text = path.read_bytes()
    except OSError as e:
        raise type(e)(f"{src}: {where}.file: cannot read {path} ({e.strerror or e})") from None
    data = _load_json(text, path, "a controller file")

    def tf(d, key):
        if isinstance(d, dict) and "elements" in d:
            from loopshaping.controller import Controller

            try:
                num, den = Controller.from_dict(d).polys()
            except (TypeError, ValueError) as e:
                raise ConfigError(f"{path}: {key}: {e}") from None
        elif isinstance(d, dict) and set(d) == {"num", "den"}:
            num, den = _coefficients(d["num"], path, f"{key}.num"), _coefficients(d["den"], path, f"{key}.den")
            _need(den[0] != 0, path, f"{key}.den", "a list whose leading coefficient is non-zero")
        else:
            raise ConfigError(f"{path}: {key} must hold exactly 'num' and 'den' coefficient lists (descending powers "
                              f"of s) or a loopshaping Controller ('elements', from Controller.to_dict); got {d!r:.80}")
        _need(np.any(num != 0), path, key, "a non-zero controller (num is all zeros; leave an unused loop out)")
        _need(np.trim_zeros(num, "f").size <= den.size, path, key, "proper (no more zeros than poles)")
        return control.tf(num, den)

    def per_speed(items, key, n):
        _need(isinstance(items, list) and len(items) == n, path, key, f"a list of one controller per wind speed ({n})")
        return [tf(c, f"{key}[{i}]") for i, c in enumerate(items)]

    if not isinstance(data, dict):
        raise ConfigError(f"{path}: a controller file holds a JSON object, got {type(data).__name__}")
    keys = set(data)
    if keys & {"num", "den", "elements", "version"}:  # one controller
        return tf(data, "the file")
    if "wind_speeds" in keys:
        extra = keys - {"wind_speeds", "pitch", "atd"}
        if extra:
            raise ConfigError(f"{path}: unknown key(s) {sorted(extra)}; a scheduled controller has 'wind_speeds', "
                              "'pitch' and optionally 'atd'")
        vs = _wind_speeds(data["wind_speeds"], model, path, "wind_speeds")
        _need("pitch" in keys, path, "pitch", f"a list of one controller per wind speed ({len(vs)})")
        pitch = per_speed(data["pitch"], "pitch", len(vs))
        atd = None if data.get("atd") is None else per_speed(data["atd"], "atd", len(vs))
        try:
            return scheduled(model, dict(zip(vs, pitch)), None if atd is None else dict(zip(vs, atd)), name=label)
        except (TypeError, ValueError) as e:
            raise ConfigError(f"{path}: {e}") from None
    if "pitch" in keys:
        extra = keys - {"pitch", "atd"}
        if extra:
            raise ConfigError(f"{path}: unknown key(s) {sorted(extra)}; a pitch + ATD controller has 'pitch' and 'atd'")
        c = tf(data["pitch"], "pitch")
        if data.get("atd") is not None:
            return ScheduledController(np.zeros(1), (c,), (tf(data["atd"], "atd"),), name=label)
        return c
    raise ConfigError(f"{path}: unknown key(s) {sorted(keys)}; a controller file holds {{'num', 'den'}}, "
                      "{'elements'} (Controller.to_dict), {'pitch', 'atd'} or {'wind_speeds', 'pitch', 'atd'} "
                      "(docs/validation.md)")


def _wind_speeds(vs, model, path, key) -> list:
    """Distinct wind speeds (m/s) inside the model's range, or ConfigError naming ``key``."""
    _need(isinstance(vs, list) and vs and all(_is_number(v) for v in vs), path, key,
          "a non-empty list of wind speeds in m/s")
    _need(len({float(v) for v in vs}) == len(vs), path, key, f"a list of distinct wind speeds, got {vs}")
    for v in vs:
        try:
            model._check_wind(v)
        except ValueError as e:
            raise ConfigError(f"{path}: {key}: {e}") from None
    return [float(v) for v in vs]


def _load_json(text: bytes, path: Path, what: str):
    """JSON with every object's keys distinct (a repeated key would silently keep the last)."""
    def pairs(items):
        out = {}
        for k, v in items:
            if k in out:
                raise ConfigError(f"{path}: key {k!r} appears twice in one object; keep one")
            out[k] = v
        return out

    try:
        return json.loads(text, object_pairs_hook=pairs)
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise ConfigError(f"{path}: {what} must be valid UTF-8 JSON ({e})") from None


def _read_config(path: Path) -> dict:
    try:
        text = path.read_bytes()
    except OSError as e:
        raise type(e)(f"{path}: cannot read the campaign file ({e.strerror or e})") from None
    if path.suffix.lower() == ".toml":
        import tomllib

        try:
            return tomllib.loads(text.decode())
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
            raise ConfigError(f"{path}: invalid TOML ({e})") from None
    if path.suffix.lower() != ".json":
        raise ConfigError(f"{path}: a campaign file is a .toml or .json file (by its extension)")
    return _load_json(text, path, "a .json campaign file")


#: a run longer than a day (transient or recorded) is a typo, not a fatigue campaign
_MAX_DURATION = 86400.0
#: seeds are non-negative and below 2**32 (numpy's SeedSequence takes them as given)
_MAX_SEED = 2**32


def _checked_seeds(seeds, path) -> np.ndarray:
    """The campaign's seeds (:func:`seeds_from`: an int n → 0..n−1), each 0 ≤ s < 2**32."""
    items = seeds if isinstance(seeds, list) else [seeds]
    ok = all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < _MAX_SEED for s in items)
    _need(ok, path, "seeds", "an integer n ≥ 1 (the seeds 0..n−1) or a non-empty list of distinct integers "
          f"0 ≤ seed < 2**32, got {seeds!r:.80}")
    try:
        return seeds_from(seeds)
    except ValueError as e:
        raise ConfigError(f"{path}: {e}") from None


def _output_folder(folder: Path, path: Path, key: str) -> Path:
    """Create ``folder`` and check that a file can be written there, before anything runs."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".specdesign_write_test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise type(e)(f"{path}: {key}: the output folder {folder} cannot be created or written "
                      f"({e.strerror or e}); choose a writable folder") from None
    return folder


def read_config(path, out=None) -> dict:
    """Read and check a campaign file completely (schema: ``docs/validation.md``).

    Returns the arguments of the campaign: ``controllers`` (loaded), ``wind_speeds``,
    ``seeds``, ``kwargs`` for :func:`run_campaign`, ``baseline``, ``designed``, ``promised``
    and ``out`` (created and checked writable). Raises :class:`ConfigError` (a ValueError)
    naming the file and the key, FileNotFoundError, or another OSError (an output folder that
    cannot be written, naming it), before anything runs.
    """
    from . import turbine
    from .simulate import _check_step, turbine_plant

    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"config file {path} does not exist")
    if not path.is_file():
        raise ConfigError(f"{path}: not a file; give a .toml or .json campaign file")
    cfg = _read_config(path)
    if not isinstance(cfg, dict):
        raise ConfigError(f"{path}: a campaign file holds a table (TOML) or an object (JSON)")
    unknown = set(cfg) - set(_TOP_KEYS)
    if unknown:
        raise ConfigError(f"{path}: unknown key(s) {sorted(unknown)}; allowed: {sorted(_TOP_KEYS)}")
    for key in ("wind_speeds", "seeds", "controllers"):
        if key not in cfg:
            raise ConfigError(f"{path}: missing required key {key!r}")
    _need(cfg.get("turbine", "iea15mw") == "iea15mw", path, "turbine", "\"iea15mw\" (the only embedded model)")
    model = turbine.iea15mw()
    vs = _wind_speeds(cfg["wind_speeds"], model, path, "wind_speeds")
    seeds = _checked_seeds(cfg["seeds"], path)
    kw = dict(duration=_number(cfg, "duration", path, 600.0), dt=_number(cfg, "dt", path, 0.02),
              record_dt=_number(cfg, "record_dt", path, 0.1), transient=_number(cfg, "transient", path, 60.0, positive=False),
              m=_number(cfg, "wohler_exponent", path, 4.0))
    for key in ("duration", "transient"):
        _need(kw[key] <= _MAX_DURATION, path, key, f"at most {_MAX_DURATION:g} s (one day) per run, got {kw[key]:g} s")
    rec = kw["record_dt"] / kw["dt"]
    _need(abs(rec - round(rec)) <= 1e-9 * rec and round(rec) >= 1, path, "record_dt", f"a whole multiple of dt={kw['dt']:g} s")
    _need(kw["duration"] >= 10 * kw["record_dt"], path, "duration",
          f"at least 10 output samples, ≥ {10 * kw['record_dt']:g} s at record_dt={kw['record_dt']:g} s")
    try:
        _check_step(turbine_plant(model), np.asarray(vs, float), kw["dt"])
    except ValueError as e:
        raise ConfigError(f"{path}: {e}") from None
    tc = cfg.get("turbulence_class", "B")
    _need(tc in ("A", "B", "C"), path, "turbulence_class", "\"A\", \"B\" or \"C\" (IEC 61400-1 NTM)")
    twin = cfg.get("linear_twin", False)
    _need(isinstance(twin, bool), path, "linear_twin", "true or false (a TOML/JSON boolean, not a string)")
    vol = cfg.get("volterra", 0)
    _need(isinstance(vol, int) and not isinstance(vol, bool) and vol in (0, 1, 2, 3), path, "volterra",
          "0 (none) or an order 1, 2 or 3 (an integer)")
    ctrl = cfg["controllers"]
    _need(isinstance(ctrl, dict) and ctrl, path, "controllers", "a table of named controllers ([controllers.NAME])")
    controllers = {str(n): load_controller(spec, path.parent, model, config=path, name=str(n)) for n, spec in ctrl.items()}
    names = list(controllers)
    baseline, designed = cfg.get("baseline", names[0]), cfg.get("designed", names[-1])
    for key, val in (("baseline", baseline), ("designed", designed)):
        _need(isinstance(val, str) and val in controllers, path, key, f"one of the controllers {names}")
    _need(len(names) < 2 or baseline != designed, path, "designed",
          f"another controller than baseline={baseline!r} (Tables 2-3 compare the two)")
    try:  # the step each controller's sampled loop needs, as run_campaign checks it, but naming the file
        _check_campaign_step(model, controllers, np.asarray(vs, float), kw["dt"])
    except ValueError as e:
        raise ConfigError(f"{path}: dt: {e}") from None
    promised = cfg.get("promised")
    if "promised" in cfg:  # a JSON null is not "no promise": leave the key out for that
        _need(isinstance(promised, dict), path, "promised", "a table wind speed (m/s) → promised DEL reduction (%)")
        out_p = {}
        for k, val in promised.items():
            try:
                v = float(k)
            except ValueError:
                raise ConfigError(f"{path}: promised: key {k!r} must be a wind speed in m/s") from None
            if isinstance(val, dict):  # TOML reads 19.5 = … as the dotted key 19 → 5
                raise ConfigError(f"{path}: promised.{k} must be a promised reduction in %, got a table; "
                                  f"quote a decimal wind speed in TOML: \"{k}.{next(iter(val), '5')}\" = …")
            _need(any(abs(v - w) < 1e-9 for w in vs), path, f"promised.{k}", f"at one of the wind_speeds {vs}")
            _need(_is_number(val) and val < 100, path, f"promised.{k}", "a promised reduction in % (a number < 100)")
            _need(v not in out_p, path, f"promised.{k}", f"given once (the wind speed {v:g} m/s appears twice)")
            out_p[v] = float(val)
        promised = out_p
    output = cfg.get("output", "validation_output")
    _need(isinstance(output, str) and output, path, "output", "a folder name")
    if out is not None:
        folder = _output_folder(Path(out), path, "--out")
    else:
        folder = _output_folder(path.parent / output, path, "output")
    kw.update(turbulence_class=tc, linear_twin=twin, volterra=int(vol), model=model)
    return dict(controllers=controllers, wind_speeds=vs, seeds=seeds, kwargs=kw, baseline=baseline,
                designed=designed, promised=promised, out=folder)


def run_config(path, out=None) -> Campaign:
    """Run the campaign described by a TOML/JSON file and write tables and figures.

    The whole file is checked first (:func:`read_config`). Writes into ``out`` (default: the
    file's ``output`` key, else ``validation_output`` beside the file): ``table2.md/.csv``,
    ``table3.md/.csv``, ``indicators.csv``, ``fig8_<v>mps.png``, ``fig9_<v>mps.png``,
    ``fig10.png``. Schema: ``docs/validation.md``.
    """
    c = read_config(path, out)
    camp = run_campaign(c["controllers"], c["wind_speeds"], c["seeds"], keep_series=1, **c["kwargs"])
    folder, baseline, designed = c["out"], c["baseline"], c["designed"]
    _write_indicators(camp, folder / "indicators.csv")
    if len(camp.controllers) >= 2:
        t2, t3 = table2(camp, designed, baseline), table3(camp, designed, baseline, promised=c["promised"])
        for t, stem in ((t2, "table2"), (t3, "table3")):
            (folder / f"{stem}.md").write_text(t.to_markdown())
            t.to_csv(folder / f"{stem}.csv")
    _write_figures(camp, folder, designed, baseline if len(camp.controllers) >= 2 else None)
    return camp


def _write_indicators(camp: Campaign, path: Path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["controller", "wind_speed_m_s", "seed", "tower_del_Nm", "gen_speed_sd_rad_s", "mean_power_W",
                    "pitch_sd_rad", "pitch_rate_sd_rad_s"])
        for c, name in enumerate(camp.controllers):
            for i, v in enumerate(camp.wind_speeds):
                for s, seed in enumerate(camp.seeds):
                    w.writerow([name, v, int(seed)] + [repr(float(camp.values[k][c, i, s])) for k in _INDICATORS])


def _write_figures(camp: Campaign, out: Path, designed, baseline):
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    from .plots import validation as pv

    for v in camp.wind_speeds:
        fig, axes = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
        pv.plot_spectra(camp, v, "gen_speed", ax=axes[0])
        pv.plot_spectra(camp, v, "tower_base_my", ax=axes[1])
        fig.tight_layout()
        fig.savefig(out / f"fig8_{v:g}mps.png", dpi=120)
        plt.close(fig)
        if camp.series:
            axes = pv.plot_time_series(camp.series, v, seed_index=0)
            axes[0].figure.savefig(out / f"fig9_{v:g}mps.png", dpi=120)
            plt.close(axes[0].figure)
    if baseline is not None:
        ax = pv.plot_reductions(acceptance(camp, designed, baseline))
        ax.figure.savefig(out / "fig10.png", dpi=120)
        plt.close(ax.figure)
