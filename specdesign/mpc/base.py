"""What every controller of :mod:`specdesign.mpc` shares: the linearised turbine discretised at
the controller's sample time, a steady-state Kalman filter that estimates its states and the
rotor-effective wind from the measured outputs, and the sampled loop that runs them as a
callable controller of :func:`specdesign.simulate.simulate` (the loop is
:class:`specdesign.mpc.sampled.SampledController`; this module holds its parts).

Discrete model (deviations from the trim at the run's mean wind speed v, zero-order hold of
both the pitch command u and the wind deviation d over the sample time T_s)::

    x_{k+1} = A x_k + B_u u_k + B_w d_k,     y_k = C x_k + D_w d_k

with x the five states of :data:`specdesign.turbine.STATE_NAMES` (pitch actuator included).
A model whose pitch command reaches an output directly (a feedthrough D_u ≠ 0: OpenFAST's
linearisations, which have no pitch actuator, so the measured pitch is the command and the
tower-top acceleration answers it at once) gets one more state, the command held over the
last sample, s_{k+1} = u_k, and y_k = C x_k + D_u s_k + D_w d_k: what is measured at a sample
comes before the command computed from it (:func:`discretize_turbine`).

Observer: the state is augmented with the wind deviation as a random walk,
d_{k+1} = d_k + η_k, and a steady-state (time-invariant) Kalman filter in "current estimator"
form runs on the measured outputs (default generator speed, tower-top fore-aft acceleration
and pitch, the sensors a turbine has)::

    x̂_{k|k} = x̂_{k|k-1} + L (y_k − C_a x̂_{k|k-1}),     x̂_{k+1|k} = A_a x̂_{k|k} + B_a u_k

L from the discrete algebraic Riccati equation of (A_a, C_a) with process noise
Q = diag(q_x, q_w T_s) and measurement noise R = diag(σ²). The wind estimate d̂ is what the
controllers use in place of a wind measurement (no preview).

Operating point (``operating_point="estimated"``, the default): no controller is told the
run's mean wind. Each run's operating point is the controller's own estimate of the
rotor-effective wind, v̂, from the LPV Kalman filter of :mod:`specdesign.mpc.lpv` (the filter
above, on the linearisations of the model every 1 m/s, blended by α(v̂) and scheduled by its
own wind estimate: an extended-Kalman-like estimator of the kind ROSCO's wind-speed estimator
is, with the wind a random-walk state it infers from the generator speed, the pitch and the
tower-top acceleration through the model's aerodynamic tables). At every sample the policy
is evaluated at the two grid points v_i ≤ v̂ < v_{i+1} (each with its own discretised model,
filter states in deviations about its trim and compiled problem) and the absolute commands
are blended, β = Σ α_i(v̂) (β̄_i + u_i): a gain-scheduled controller whose internal linear
model follows the estimate. Both vertex commands respect the pitch rate and position limits,
and so does their convex blend. The filter starts at the steady state whose trim pitch is the
pitch measured at t = 0 (:func:`pitch_wind_estimate`, the trim table inverted), which is all
it reads at ``start``; the wind sample the simulator passes to ``start`` is not used.

``operating_point="initial pitch"`` keeps the former behaviour: one fixed linearisation per
run at the wind speed whose trim is the run's initial pitch (in this simulator, the run's mean
wind, :func:`operating_wind_speed`) and its time-invariant filter. It is the model-equal-plant
setting of Collet et al. (the system and its operating point known), kept for the
open-loop-vs-closed-loop comparison of ``benchmarks/mpc.py`` on the *linearised* turbine at
the mean wind, where that model is the plant. ``operating_point="design point"`` holds the
linearisation at a wind speed the user gives (``design_speed``), as a fixed-gain controller is
designed at one point: Collet et al.'s setting (:mod:`specdesign.mpc.collet`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import positive_scalar
from ..controller.noise import MEASURED as SENSOR_SIGNALS
from ..controller.noise import SensorNoise

__all__ = ["DiscreteTurbine", "discretize_turbine", "filter_noise", "kalman_gain", "operating_wind_speed", "pitch_wind_estimate",
           "prediction_matrices", "steps_per_sample", "within_limits", "MEASURED", "MEASUREMENT_STD", "OPERATING_POINTS"]

#: Values of ``operating_point``: the estimate scheduled online (default), the trim of the
#: run's initial pitch held, or a fixed design point given by the user (module docstring).
OPERATING_POINTS = ("estimated", "initial pitch", "design point")

#: Outputs the observer reads by default: generator speed (rad/s), tower-top fore-aft
#: acceleration (m/s², an accelerometer in the nacelle) and the pitch (rad).
MEASURED = ("gen_speed", "tower_top_acc", "pitch")

#: Measurement noise standard deviations the Kalman filter assumes (SI), per output name: the
#: filter's tuning (not a noise the simulator adds). Small against the signals' own spread at
#: rated (speed SD ~ 0.02 rad/s, acceleration SD ~ 0.1 m/s²), so the filter trusts the sensors.
MEASUREMENT_STD = {"gen_speed": 1e-3, "tower_top_acc": 1e-2, "tower_top_vel": 1e-3, "pitch": 1e-3,
                   "tower_base_my": 1e5, "power": 1e4}


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class DiscreteTurbine:
    """The linearised turbine at one wind speed, discretised by zero-order hold.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed of the trim (m/s).
    ts : float
        Sample time (s).
    A, Bu, Bw : numpy.ndarray
        (n, n), (n,), (n,) discrete state matrix and the pitch-command (per rad) and wind
        (per m/s) input columns.
    C, Dw : numpy.ndarray
        (p, n) and (p,) outputs of :attr:`output_names` (SI) and their wind feedthrough.
    output_names : tuple of str
        Output names, in the order of the rows of ``C``.
    pitch0, torque0 : float
        Trim pitch (rad) and generator torque (N·m).
    y0 : numpy.ndarray
        (p,) outputs at the trim (SI).
    x0 : numpy.ndarray, optional
        (n,) the states at the trim, absolute (SI; the held command's is ``pitch0``): what a
        filter in absolute values is about (:mod:`specdesign.mpc.lpv`). :func:`discretize_turbine`
        sets it; None (default) for a model built by hand, whose trim no filter reads.
    """

    wind_speed: float
    ts: float
    A: np.ndarray = field(repr=False)
    Bu: np.ndarray = field(repr=False)
    Bw: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    Dw: np.ndarray = field(repr=False)
    output_names: tuple
    pitch0: float
    torque0: float
    y0: np.ndarray = field(repr=False)
    x0: np.ndarray | None = field(default=None, repr=False)

    def rows(self, names) -> np.ndarray:
        """Indices of the outputs ``names`` in ``C``.

        Parameters
        ----------
        names : sequence of str
            Output names.

        Returns
        -------
        numpy.ndarray
            Integer row indices.

        Raises
        ------
        ValueError
            For a name that is not an output of the model.
        """
        out = []
        for n in names:
            if n not in self.output_names:
                raise ValueError(f"output {n!r} is not an output of the model; choose among {self.output_names}")
            out.append(self.output_names.index(n))
        return np.array(out, dtype=int)


def discretize_turbine(model, wind_speed: float, ts: float) -> DiscreteTurbine:
    """``model.linearize(wind_speed)`` discretised by zero-order hold at ``ts``.

    When the pitch command has a feedthrough to an output (D_u ≠ 0), the state is augmented
    with the command held over the previous sample (module docstring): a measurement at a
    sample instant reads the command held up to it, the zero-order hold's left limit.

    Parameters
    ----------
    model : TurbineModel or LinearTurbine
        The turbine (e.g. :func:`specdesign.turbine.iea15mw`), or OpenFAST's linearisations
        with their operating points' states and outputs
        (:class:`specdesign.openfast.LinearTurbine`).
    wind_speed : float
        Mean wind speed (m/s).
    ts : float
        Sample time (s).

    Returns
    -------
    DiscreteTurbine
        The discrete model and the trim it is about.

    Raises
    ------
    ValueError
        For a non-positive ``ts`` or a wind speed outside the model's range.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> d = discretize_turbine(iea15mw(), 19.0, 0.1)
    >>> d.A.shape, d.output_names[0]
    ((5, 5), 'gen_speed')
    """
    import scipy.signal

    ts = positive_scalar(ts, "ts")
    sys = model.linearize(float(wind_speed))
    names = tuple(sys.output_labels)
    iw, iu = list(sys.input_labels).index("wind"), list(sys.input_labels).index("pitch_cmd")
    A, B, C, D = (np.asarray(m, float) for m in (sys.A, sys.B, sys.C, sys.D))
    Ad, Bd, *_ = scipy.signal.cont2discrete((A, B[:, [iw, iu]], C, D[:, [iw, iu]]), ts, method="zoh")
    Bu, Bw = Bd[:, 1], Bd[:, 0]
    op = model.trim(float(wind_speed))
    x0 = np.asarray(op.x, float)
    if np.any(D[:, iu]):  # the held command as a state: s_{k+1} = u_k, y_k = C x_k + D_u s_k
        n = Ad.shape[0]
        Ad = np.block([[Ad, np.zeros((n, 1))], [np.zeros((1, n + 1))]])
        Bu, Bw = np.append(Bu, 1.0), np.append(Bw, 0.0)
        C = np.hstack([C, D[:, [iu]]])
        x0 = np.append(x0, op.pitch)
    y0 = np.asarray(model.evaluate_outputs(op.x, float(wind_speed), op.pitch, op.gen_torque), float)
    return DiscreteTurbine(float(wind_speed), ts, Ad, Bu.copy(), Bw.copy(), C, D[:, iw].copy(), names,
                           float(op.pitch), float(op.gen_torque), y0, x0)


def filter_noise(sensors: SensorNoise | None, dt: float | None = None) -> dict:
    """The measurement noise SDs a Kalman filter assumes for the sensors a run reads through.

    Parameters
    ----------
    sensors : SensorNoise or None
        The sensors the simulator applies (``simulate(..., noise=sensors)``,
        ``run_campaign(noise=...)``); None: the filter's own tuning, :data:`MEASUREMENT_STD`.
    dt : float, optional
        The step the noisy measurements are drawn at, s: the simulation step, at which a sampled
        controller reads them (default ``sensors.sample_time``, the simulator's default step).

    Returns
    -------
    dict
        Output name → SD in its SI unit: :data:`MEASUREMENT_STD`, with every signal the sensors
        perturb set to the SD of one noisy sample (:meth:`SensorNoise.sd` at ``dt``) and, for the
        generator speed, the 3P line's RMS (amplitude/√2) added in quadrature: the filter then
        weighs each sensor by the noise it carries. A signal the sensors leave exact keeps its
        tuning (a filter needs R > 0).

    Raises
    ------
    TypeError
        If ``sensors`` is neither None nor a SensorNoise.

    Examples
    --------
    >>> from specdesign.simulate import IEA15MW_SENSORS
    >>> round(filter_noise(IEA15MW_SENSORS)["gen_speed"], 6)  # 0.005 rad/s white, 4.9e-4 rad/s 3P line
    0.005012
    """
    std = dict(MEASUREMENT_STD)
    if sensors is None:
        return std
    if not isinstance(sensors, SensorNoise):
        raise TypeError(f"sensors must be a specdesign.simulate.SensorNoise or None, got {type(sensors).__name__}")
    step = sensors.sample_time if dt is None else positive_scalar(dt, "dt")
    for signal in SENSOR_SIGNALS:
        sd = sensors.sd(signal, step)
        if signal == "gen_speed":
            sd = float(np.hypot(sd, sensors.ripple_3p / np.sqrt(2.0)))
        if sd > 0:
            std[signal] = sd
    return std


def kalman_gain(dm: DiscreteTurbine, measured=MEASURED, *, wind_walk: float = 0.45, state_noise: float = 1e-8,
                measurement_std: dict | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Steady-state Kalman filter of the model augmented with the wind deviation (a random walk).

    Parameters
    ----------
    dm : DiscreteTurbine
        The discrete model.
    measured : sequence of str, optional
        Measured outputs (default :data:`MEASURED`).
    wind_walk : float, optional
        Variance rate of the wind random walk, (m/s)²/s: the increment over a sample has
        variance ``wind_walk·ts``. The default 0.45 is 2σ²/T for a rotor-effective wind of
        σ = 2 m/s and a correlation time T ≈ 18 s (L/U at 19 m/s).
    state_noise : float, optional
        Process noise variance on each model state per sample (state units²), small: the
        model is trusted, the wind carries the uncertainty.
    measurement_std : dict, optional
        Output name → noise standard deviation (SI); default :data:`MEASUREMENT_STD`.

    Returns
    -------
    Aa, Ba, Ca, L : numpy.ndarray
        Augmented (n+1, n+1) state matrix, (n+1,) pitch column, (q, n+1) measurement matrix
        of the q measured outputs and the (n+1, q) filter gain.

    Raises
    ------
    ValueError
        For an unknown or unmeasurable output, or non-positive noise levels.
    """
    import scipy.linalg

    rows = dm.rows(measured)
    std = dict(MEASUREMENT_STD if measurement_std is None else measurement_std)
    missing = [dm.output_names[r] for r in rows if dm.output_names[r] not in std]
    if missing:
        raise ValueError(f"measurement_std has no noise level for the measured outputs {missing}")
    sig = np.array([positive_scalar(std[dm.output_names[r]], f"measurement_std[{dm.output_names[r]!r}]")
                    for r in rows])
    wind_walk = positive_scalar(wind_walk, "wind_walk")
    state_noise = positive_scalar(state_noise, "state_noise")
    n = dm.A.shape[0]
    Aa = np.zeros((n + 1, n + 1))
    Aa[:n, :n], Aa[:n, n], Aa[n, n] = dm.A, dm.Bw, 1.0
    Ba = np.append(dm.Bu, 0.0)
    Ca = np.hstack([dm.C[rows], dm.Dw[rows, None]])
    Q = np.diag(np.append(np.full(n, state_noise), wind_walk * dm.ts))
    Rn = np.diag(sig**2)
    P = scipy.linalg.solve_discrete_are(Aa.T, Ca.T, Q, Rn)
    L = P @ Ca.T @ np.linalg.inv(Ca @ P @ Ca.T + Rn)
    return Aa, Ba, Ca, L


def prediction_matrices(dm: DiscreteTurbine, outputs, horizon: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Condensed prediction of ``outputs`` over ``horizon`` steps: z = Φ x₀ + Γ u + Ψ d.

    z stacks the outputs at steps 1..N (step-major: z[j·q + i] is output i at step j+1), u the
    N commands u₀..u_{N−1} (rad, deviations), d the wind deviation held over the horizon (m/s).

    Parameters
    ----------
    dm : DiscreteTurbine
        The discrete model.
    outputs : sequence of str
        Predicted outputs (q of them).
    horizon : int
        N ≥ 1 steps.

    Returns
    -------
    Phi, Gamma, Psi : numpy.ndarray
        (N·q, n), (N·q, N) and (N·q,) matrices.

    Raises
    ------
    ValueError
        For ``horizon`` < 1 or an unknown output.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> Phi, Gamma, Psi = prediction_matrices(discretize_turbine(iea15mw(), 19.0, 0.1), ["gen_speed"], 3)
    >>> Gamma.shape, float(Gamma[0, 1])
    ((3, 3), 0.0)
    """
    if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
        raise ValueError(f"horizon={horizon!r} must be an integer number of steps >= 1")
    rows = dm.rows(outputs)
    C, Dw = dm.C[rows], dm.Dw[rows]
    n, q, N = dm.A.shape[0], rows.size, int(horizon)
    Phi, Gamma, Psi = np.zeros((N * q, n)), np.zeros((N * q, N)), np.zeros(N * q)
    Ak = np.eye(n)
    xs_u = np.zeros((n, N))  # state response to the commands after j+1 steps, built recursively
    xw = np.zeros(n)
    for j in range(N):
        xs_u = dm.A @ xs_u
        xs_u[:, j] += dm.Bu
        xw = dm.A @ xw + dm.Bw
        Ak = dm.A @ Ak
        Phi[j * q:(j + 1) * q] = C @ Ak
        Gamma[j * q:(j + 1) * q] = C @ xs_u
        Psi[j * q:(j + 1) * q] = C @ xw + Dw
    return Phi, Gamma, Psi


def operating_wind_speed(model, pitch: float, wind: float) -> float:
    """Mean wind speed (m/s) whose trim pitch is ``pitch``: where the simulator started a run.

    Above rated the trim pitch grows with the wind speed, so it identifies the operating
    point; at the lower pitch limit (at or below rated) it does not, and the wind sample at
    t = 0 decides, rounded to 0.5 m/s within the model's range.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    pitch : float
        Initial pitch of the run (rad).
    wind : float
        Wind at t = 0 (m/s).

    Returns
    -------
    float
        The wind speed (m/s), rounded to 1 mm/s so runs at one speed share one model.

    Raises
    ------
    ValueError
        For a pitch above the trim pitch at the top of the model's range.
    """
    import scipy.optimize

    lo, hi = (float(x) for x in model.wind_range)
    p_lo, p_hi = model.trim(lo).pitch, model.trim(hi).pitch
    if pitch > p_hi + 1e-9:
        raise ValueError(f"initial pitch {pitch:.4f} rad is above the trim pitch {p_hi:.4f} rad at {hi:g} m/s: "
                         "the run does not start at a trim of this model")
    rated = model.pitch_min + 1e-4
    if pitch <= max(p_lo, rated):
        if p_lo > rated:
            return lo
        return float(min(max(round(2.0 * float(wind)) / 2.0, lo), float(model.rated_wind_speed)))
    v = scipy.optimize.brentq(lambda s: model.trim(s).pitch - pitch, lo, hi, xtol=1e-6)
    return round(float(v), 3)


def pitch_wind_estimate(model, pitch: float) -> float:
    """Steady-state wind speed (m/s) whose trim pitch is the measured ``pitch``.

    The trim table inverted: above rated the trim pitch grows with the wind speed. At or below
    the pitch of the lowest wind speed of ``model.wind_range`` the pitch carries no information
    and the lowest speed is returned (the filter then finds the wind from the speed and the
    tower); above the highest, the highest.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    pitch : float
        Measured pitch (rad).

    Returns
    -------
    float
        The wind speed (m/s), rounded to 1 mm/s.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> pitch_wind_estimate(m, m.trim(19.0).pitch)
    19.0
    """
    import scipy.optimize

    lo, hi = (float(x) for x in model.wind_range)
    p_lo, p_hi = model.trim(lo).pitch, model.trim(hi).pitch
    if pitch <= p_lo:
        return lo
    if pitch >= p_hi:
        return hi
    v = scipy.optimize.brentq(lambda s: model.trim(s).pitch - pitch, lo, hi, xtol=1e-6)
    return round(float(v), 3)


def steps_per_sample(ts: float, dt: float) -> int:
    """Simulation steps per controller sample: ``ts`` checked to be a whole multiple of ``dt``.

    Parameters
    ----------
    ts : float
        The controller's sample time (s).
    dt : float
        The simulation step (s).

    Returns
    -------
    int
        ts/dt, ≥ 1.

    Raises
    ------
    ValueError
        If ``ts`` is not a whole multiple of ``dt`` (to 1e-9 of ``ts``: the round-off of a
        step such as 0.02 s written in decimal).

    Examples
    --------
    >>> steps_per_sample(0.1, 0.02)
    5
    """
    every = int(round(ts / dt))
    if every < 1 or abs(every * dt - ts) > 1e-9 * ts:
        raise ValueError(f"ts={ts} s must be a whole multiple of the simulation step dt={dt} s")
    return every


def within_limits(model, ts: float, u: np.ndarray, uprev: np.ndarray, pitch0: float) -> np.ndarray:
    """Commands cut to the pitch actuator's rate and position limits over one sample.

    Parameters
    ----------
    model : TurbineModel
        The turbine (``pitch_rate_limit`` rad/s, ``pitch_min``, ``pitch_max`` rad).
    ts : float
        Sample time (s).
    u, uprev : numpy.ndarray
        (G,) wanted and previous commands (rad, deviations from ``pitch0``).
    pitch0 : float
        The trim pitch the deviations are about (rad).

    Returns
    -------
    numpy.ndarray
        (G,) the commands within |u − u_prev| ≤ β̇_max T_s and β_min ≤ pitch0 + u ≤ β_max.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> float(within_limits(m, 0.1, np.array([1.0]), np.array([0.0]), 0.3)[0]) == m.pitch_rate_limit * 0.1
    True
    """
    step = float(model.pitch_rate_limit) * ts
    lo = np.maximum(uprev - step, float(model.pitch_min) - pitch0)
    hi = np.minimum(uprev + step, float(model.pitch_max) - pitch0)
    return np.minimum(np.maximum(u, lo), hi)
