"""Volterra prediction: the closed-loop response of the nonlinear turbine to a periodic wind
record as a perturbation series about the trim (the aerodynamic loads' Taylor terms to third
order fed back through the linear loop), in the frequency domain, and the DEL it predicts."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._checks import positive_scalar
from ..closedloop import local_response, t_output_wind
from ..fatigue import TOWER_M, del_rainflow
from ..simulate import wind_series
from ..turbine import OUTPUT_NAMES
from ..wind import RECORD_LENGTH
from ._loop import has_linear_form, rotor_radius
from .stats import pool, seeds_from

__all__ = ["volterra_response", "VolterraPrediction", "volterra_prediction"]

_AERO_OUTPUTS = ("gen_speed", "tower_top_vel", "pitch")  # rotor speed (gearbox ratio 1), ẋ_top, β


def volterra_response(model, controller, wind_speed: float, wind, dt: float, *, order: int = 3,
                      outputs=("tower_base_my",)) -> dict[str, np.ndarray]:
    """Closed-loop response to a periodic wind record as a Volterra series, to ``order``.

    The loop is the linearisation at ``wind_speed`` closed by ``controller`` (a scheduled one
    frozen at the trim, as in :func:`~specdesign.validate.linear_prediction`); the
    aerodynamic loads carry their Taylor expansion to third order
    (:meth:`~specdesign.turbine.TurbineModel.aero_expansion`) in z = (rotor speed, wind − ẋ_top,
    pitch). Term 1 is the linear response y₁ = T_w·w. Term 2 is the loop's response (through
    the ``aero_torque`` and ``thrust`` inputs) to ½ z₁ᵀ H z₁, the quadratic loads along the
    linear trajectory z₁. Term 3 is its response to z₁ᵀ H z₂ + D³[z₁, z₁, z₁]/6, z₂ the
    second-order trajectory. Each product is formed in the time domain and filtered by FFT,
    so ``wind`` must be periodic over its record (as :func:`specdesign.wind.gaussian_series`
    makes it); no time stepping. With the aerodynamic nonlinearity of class-B turbulence the
    series to third order matches the tower-base DEL of the nonlinear simulation within a few
    tenths of a percent (docs/nonlinearity.md, section (i)).

    Parameters
    ----------
    model : TurbineModel
        The turbine (:class:`~specdesign.turbine.TurbineModel`, with ``aero_expansion``).
    controller : LTI, Controller or ScheduledController
        A controller with a linear form (not a callable).
    wind_speed : float
        Operating point (m/s).
    wind : array_like
        (..., n) rotor-effective wind (m/s, mean included), n ≥ 16, periodic over the record.
    dt : float
        Sample spacing of ``wind`` (s).
    order : {1, 2, 3}, default 3
        Order of the series.
    outputs : str or sequence of str, default ("tower_base_my",)
        Names from :data:`specdesign.turbine.OUTPUT_NAMES`.

    Returns
    -------
    dict
        Output → array (order, ..., n): term k of the series at index k − 1, SI deviation from
        the trim (sum over axis 0 for the prediction).

    Raises
    ------
    TypeError
        A model without ``aero_expansion`` or a controller without a linear form.
    ValueError
        An order outside 1-3, an unknown output, a non-finite or too short wind record, or a
        non-positive ``dt``.
    """
    if not hasattr(model, "aero_expansion"):
        raise TypeError(f"model must be a turbine.TurbineModel (with aero_expansion), got {type(model).__name__}")
    if order not in (1, 2, 3):
        raise ValueError(f"order={order!r} must be 1, 2 or 3")
    outs = (outputs,) if isinstance(outputs, str) else tuple(outputs)
    bad = [o for o in outs if o not in OUTPUT_NAMES]
    if bad or not outs:
        raise ValueError(f"outputs={outputs!r}: choose from {OUTPUT_NAMES}")
    if not has_linear_form(controller):
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
    cb, ca = local_response(model, controller, v, 1j * om)
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
    """Volterra prediction at one wind speed (:func:`volterra_prediction`).

    Parameters
    ----------
    del_ : float
        Damage-pooled DEL of the records (N·m for the tower-base moment; range, 1 Hz).
    dels : numpy.ndarray
        (S,) DEL per record.
    sd : float
        Pooled standard deviation of the output (SI).
    order : int
        Order of the series (1-3).
    seeds : numpy.ndarray
        (S,) wind seeds.
    duration : float
        Record length (s).
    """

    del_: float
    dels: np.ndarray
    sd: float
    order: int
    seeds: np.ndarray
    duration: float


def volterra_prediction(model, controller, wind_speed: float, *, seeds=range(1000, 1200), duration: float = RECORD_LENGTH,
                        dt: float = 0.1, order: int = 3, m: float = TOWER_M, output: str = "tower_base_my",
                        turbulence_class: str = "B", chunk: int = 50) -> VolterraPrediction:
    """DEL of ``output`` predicted by the Volterra series over synthetic periodic wind records.

    The nonlinear counterpart of :func:`~specdesign.validate.linear_prediction`
    (:func:`volterra_response` on each record), made before any time-domain simulation
    (FFT-fast: a few ms per record, ``benchmarks/volterra.py``).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    controller : LTI, Controller or ScheduledController
        A controller with a linear form.
    wind_speed : float
        Operating point (m/s).
    seeds : int or sequence of int, default range(1000, 1200)
        Wind seeds (:func:`~specdesign.validate.seeds_from`): records from
        :func:`specdesign.simulate.wind_series`, periodic over ``duration``, so no transient is
        needed. The DEL's sampling error falls as 1/√S; two controllers given the same seeds
        are compared paired.
    duration : float, default 600.0
        Record length (s).
    dt : float, default 0.1
        Sample spacing (s).
    order : {1, 2, 3}, default 3
        Order of the series.
    m : float, default 4.0
        Wöhler exponent of the DEL.
    output : str, default "tower_base_my"
        Output whose DEL is predicted.
    turbulence_class : {"A", "B", "C"}, default "B"
        IEC NTM class of the wind.
    chunk : int, default 50
        Records per FFT batch (memory).

    Returns
    -------
    VolterraPrediction
        Pooled and per-record DELs and the pooled SD.

    Raises
    ------
    ValueError
        Invalid seeds, a non-positive ``duration``, ``dt`` or ``m``, or an error of
        :func:`volterra_response`.
    TypeError
        See :func:`volterra_response`.
    """
    seeds = seeds_from(seeds)
    duration, dt, m = positive_scalar(duration, "duration"), positive_scalar(dt, "dt"), positive_scalar(m, "m")
    dels, sq = [], []
    for lo in range(0, seeds.size, max(int(chunk), 1)):
        part = seeds[lo:lo + max(int(chunk), 1)]
        wind = wind_series(rotor_radius(model), [wind_speed], part, duration, dt, turbulence_class)[0]
        y = volterra_response(model, controller, wind_speed, wind, dt, order=order, outputs=(output,))[output].sum(axis=0)
        dels += [del_rainflow(row, m, duration) for row in y]
        sq.append(y.var(axis=-1))
    dels = np.asarray(dels)
    return VolterraPrediction(del_=float(pool("tower_del", dels, m)), dels=dels, sd=float(np.sqrt(np.mean(np.concatenate(sq)))),
                              order=int(order), seeds=seeds, duration=duration)
