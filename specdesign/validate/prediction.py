"""Linear prediction: the closed-loop map T_{y,w}(jω) of any controller the simulator runs,
and the output spectrum |T|²S_W with its DEL by a spectral method (Dirlik by default)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import spectral, wind
from ..wind import LOWEST_OMEGA, RECORD_LENGTH, record_window
from .._checks import positive_scalar
from ..closedloop import local_response, t_output_wind, unstable_message, unstable_poles
from ..closedloop.maps import state_space_response
from ..fatigue import TOWER_M
from ..simulate import turbine_plant
from ._loop import rotor_radius

__all__ = ["loop_plant", "closed_loop_response", "prediction_grid", "LinearPrediction", "linear_prediction"]


def loop_plant(model):
    """The plant whose linearised loop :mod:`specdesign.closedloop` analyses.

    A model that provides its own (``kernel_plant()``: a :class:`specdesign.openfast.LinearTurbine`)
    gives it; anything else goes through :func:`specdesign.simulate.turbine_plant`.

    Parameters
    ----------
    model : TurbineModel, KernelPlant, LinearTurbine or None
        The turbine (None: the embedded IEA 15 MW).

    Returns
    -------
    KernelPlant
        The plant.
    """
    own = getattr(model, "kernel_plant", None)
    return own() if callable(own) else turbine_plant(model)


def closed_loop_response(model, controller, wind_speed: float, omega, output: str = "tower_base_my") -> np.ndarray:
    """T_{y,w}(jω) from rotor-effective wind (m/s) to ``output`` (SI) in closed loop.

    The controller closes the linearisation at ``wind_speed`` through
    :func:`specdesign.closedloop.t_output_wind`, with β = −C_β·Ω_g − C_atd·ẋ_top as in the
    simulator; a scheduled controller is blended at the trim pitch of ``wind_speed``.

    Parameters
    ----------
    model : TurbineModel, KernelPlant or LinearTurbine
        The plant (:func:`loop_plant`).
    controller : LTI, Controller or ScheduledController
        Any controller with a linear form the simulator runs.
    wind_speed : float
        Operating point (m/s).
    omega : array_like
        Frequencies (rad/s), strictly increasing.
    output : str, default "tower_base_my"
        Output of the plant's linearisation.

    Returns
    -------
    numpy.ndarray
        Complex response (output SI unit per m/s), shaped like ``omega``.
    """
    w = np.asarray(omega, dtype=float)
    plant = loop_plant(model)
    lin = plant.linearize(wind_speed)
    # (ny, nu, nw), inputs wind, pitch_cmd, gen_torque
    G = np.moveaxis(state_space_response(lin.A, lin.B, lin.C, lin.D, w), 0, -1)
    names = list(plant.output_names)
    # by position: a user KernelPlant's linearisation need not carry signal names
    P = {(o, u): G[names.index(o), j] for o in {output, "gen_speed", "tower_top_vel"}
         for j, u in enumerate(("wind", "pitch_cmd"))}
    cb, ca = local_response(plant, controller, wind_speed, 1j * w)
    return t_output_wind(P, cb, w, output, atd_controller=ca, atd_measurement="tower_top_vel")


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class LinearPrediction:
    """Linear prediction at one wind speed (:func:`linear_prediction`).

    Parameters
    ----------
    omega : numpy.ndarray
        Frequency grid (rad/s).
    psd : numpy.ndarray
        One-sided PSD of the output, |T|²S_W (SI² per rad/s).
    del_ : float
        DEL of the output (a range, 1 Hz; Dirlik by default).
    sd : float
        Standard deviation of the output, √∫S dω (SI).
    """

    omega: np.ndarray
    psd: np.ndarray
    del_: float
    sd: float


def prediction_grid(duration: float = RECORD_LENGTH, omega_max: float = 30.0, n: int = 3000) -> np.ndarray:
    """Log-spaced frequency grid for a prediction over records of ``duration`` seconds.

    The grid starts at :data:`specdesign.wind.LOWEST_OMEGA` scaled to the record (a tenth of its
    fundamental 2π/duration): with :func:`specdesign.wind.record_window` weighting the wind
    spectrum, what lies below is negligible, so the prediction is converged in its lowest
    frequency as the specification's promise is, on the same band (a grid that started sharply
    at 2π/duration, unwindowed, left the prediction to where the grid happened to stop).

    Parameters
    ----------
    duration : float, default 600.0
        Record length (s) whose cycles the prediction counts.
    omega_max : float, default 30.0
        Highest frequency (rad/s).
    n : int, default 3000
        Number of points.

    Returns
    -------
    numpy.ndarray
        (n,) frequencies (rad/s).

    Raises
    ------
    ValueError
        A non-positive ``duration`` or ``omega_max``.

    Examples
    --------
    >>> w = prediction_grid(600.0, 30.0, 5)
    >>> float(w[0]), float(w[-1])
    (0.001, 30.0)
    """
    lo = LOWEST_OMEGA * RECORD_LENGTH / positive_scalar(duration, "duration")
    return np.geomspace(lo, positive_scalar(omega_max, "omega_max"), int(n))


def linear_prediction(model, controller, wind_speed: float, *, output: str = "tower_base_my", m: float = TOWER_M,
                      omega=None, turbulence_class: str = "B", method: str = "dirlik",
                      record_length: float = RECORD_LENGTH) -> LinearPrediction:
    """|T_{y,w}|²·S_W and its DEL by a spectral method (Dirlik by default) at one wind speed.

    Parameters
    ----------
    model : TurbineModel or LinearTurbine
        The turbine (its rotor radius sets the rotor-effective wind spectrum; the loop is
        that of :func:`loop_plant`).
    controller : LTI, Controller or ScheduledController
        Any controller with a linear form (:func:`closed_loop_response`).
    wind_speed : float
        Operating point (m/s).
    output : str, default "tower_base_my"
        Output whose spectrum and DEL are predicted.
    m : float, default 4.0
        Wöhler exponent of the DEL.
    omega : array_like, optional
        Frequency grid (rad/s); default :func:`prediction_grid` of ``record_length`` (to 30 rad/s).
    turbulence_class : {"A", "B", "C"}, default "B"
        IEC NTM class of S_W (:func:`specdesign.wind.rotor_effective_spectrum`).
    method : str, default "dirlik"
        Spectral DEL method of :func:`specdesign.spectral.del_spectral`.
    record_length : float, default 600.0
        Length (s) of the records whose cycles are predicted: S_W is weighted by
        :func:`specdesign.wind.record_window` (the variance about each record's mean, as the
        specification's promise and the rainflow count of each record see it).

    Returns
    -------
    LinearPrediction
        Grid, PSD, DEL (range, 1 Hz) and SD of the output.

    Raises
    ------
    ValueError
        The controller destabilises the loop (naming it and the unstable poles): |T|²S_W of
        an unstable loop is finite but describes no response.
    """
    bad = unstable_poles(loop_plant(model), controller, wind_speed)
    if bad.size:
        raise ValueError(unstable_message(controller, wind_speed, bad) + "; a linear prediction of an unstable loop is meaningless")
    w = prediction_grid(record_length) if omega is None else np.asarray(omega, dtype=float)
    radius = rotor_radius(model)
    sw = wind.rotor_effective_spectrum(w, wind_speed, radius, turbulence_class=turbulence_class) * record_window(w, record_length)
    t = closed_loop_response(model, controller, wind_speed, w, output)
    psd = np.abs(t) ** 2 * sw
    return LinearPrediction(omega=w, psd=psd, del_=float(spectral.del_spectral(w, psd, m, method=method)),
                            sd=float(np.sqrt(np.trapezoid(psd, w))))
