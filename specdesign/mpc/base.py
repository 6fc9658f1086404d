"""What every controller of :mod:`specdesign.mpc` shares: the linearised turbine discretised at
the controller's sample time, a steady-state Kalman filter that estimates its states and the
rotor-effective wind from the measured outputs, and the sampled loop that runs them as a
callable controller of :func:`specdesign.simulate.simulate`.

Discrete model (deviations from the trim at the run's mean wind speed v, zero-order hold of
both the pitch command u and the wind deviation d over the sample time T_s)::

    x_{k+1} = A x_k + B_u u_k + B_w d_k,     y_k = C x_k + D_w d_k

with x the five states of :data:`specdesign.turbine.STATE_NAMES` (pitch actuator included).

Observer: the state is augmented with the wind deviation as a random walk,
d_{k+1} = d_k + η_k, and a steady-state (time-invariant) Kalman filter in "current estimator"
form runs on the measured outputs (default generator speed, tower-top fore-aft acceleration
and pitch, the sensors a turbine has)::

    x̂_{k|k} = x̂_{k|k-1} + L (y_k − C_a x̂_{k|k-1}),     x̂_{k+1|k} = A_a x̂_{k|k} + B_a u_k

L from the discrete algebraic Riccati equation of (A_a, C_a) with process noise
Q = diag(q_x, q_w T_s) and measurement noise R = diag(σ²). The wind estimate d̂ is what the
controllers use in place of a wind measurement (no preview).

The operating point of each run is found at ``start`` from its initial pitch (the simulator
starts every run at the trim of its mean wind speed, and the trim pitch is monotone in the wind
speed above rated), so one controller object serves every wind speed of a campaign.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import bad_measurements, positive_scalar

__all__ = ["DiscreteTurbine", "discretize_turbine", "kalman_gain", "operating_wind_speed", "prediction_matrices",
           "SampledController", "MEASURED", "MEASUREMENT_STD"]

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

    Parameters
    ----------
    model : TurbineModel
        The turbine (e.g. :func:`specdesign.turbine.iea15mw`).
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
    op = model.trim(float(wind_speed))
    y0 = np.asarray(model.evaluate_outputs(op.x, float(wind_speed), op.pitch, op.gen_torque), float)
    return DiscreteTurbine(float(wind_speed), ts, Ad, Bd[:, 1].copy(), Bd[:, 0].copy(), C, D[:, iw].copy(), names,
                           float(op.pitch), float(op.gen_torque), y0)


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


class SampledController:
    """A discrete controller on the estimated state, run as a callable of :func:`~specdesign.simulate.simulate`.

    Base of :class:`~specdesign.mpc.QuadraticMPC`, :class:`~specdesign.mpc.EconomicMPC` and
    :class:`~specdesign.mpc.ClonedController`: every ``ts`` it updates the Kalman filter of
    :func:`kalman_gain` with the measurements, asks the subclass's ``policy`` for the command
    deviation of each run, and holds the command until the next sample (zero-order hold, as the
    discrete model assumes). Picklable: the per-operating-point caches and timings are rebuilt,
    not pickled.

    Parameters
    ----------
    model : TurbineModel
        The turbine the controller is designed on (and runs on).
    ts : float
        Sample time (s), a whole multiple of the simulation step.
    measured : sequence of str, optional
        Outputs the observer reads (default :data:`MEASURED`).
    name : str, optional
        Label in campaign tables.

    Attributes
    ----------
    solve_times : list of float
        CPU time (s) of the policy per run and sample, since construction or unpickling.
    trace : list or None
        What the policy saw at every sample of the last run, after :meth:`record`.
    """

    def __init__(self, model, ts: float, measured=MEASURED, name: str = "controller"):
        self.model = model
        self.ts = positive_scalar(ts, "ts")
        self.measured = tuple(measured)
        if not self.measured or not all(isinstance(m, str) for m in self.measured):
            raise TypeError(f"measured must be a non-empty sequence of output names, got {measured!r}")
        self.__name__ = self.name = str(name)
        self._reset_caches()

    def _reset_caches(self):
        self._points = {}
        self.solve_times = []
        self.trace = None

    def record(self, on: bool = True) -> None:
        """Record, from the next :meth:`start`, what the policy sees at every sample.

        Parameters
        ----------
        on : bool, default True
            Record (True) or stop (False).

        Notes
        -----
        The record is :attr:`trace`: a list of ``(t, v, xhat, uprev)`` per sample and
        operating point, ``xhat`` (G, n+1) the filtered states and wind estimate and ``uprev``
        (G,) the previous command deviations; behavioural cloning labels these states.
        """
        self._recording = bool(on)

    def __getstate__(self):
        state = dict(self.__dict__)
        for k in ("_points", "solve_times", "_run", "trace", "_recording"):
            state.pop(k, None)
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._reset_caches()

    def point(self, wind_speed: float) -> dict:
        """The per-operating-point data at ``wind_speed`` (built once, then cached).

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s).

        Returns
        -------
        dict
            ``"model"`` (:class:`DiscreteTurbine`), ``"kf"`` (:func:`kalman_gain`'s tuple) and
            whatever the subclass's ``build`` adds.
        """
        key = round(float(wind_speed), 3)
        if key not in self._points:
            dm = discretize_turbine(self.model, key, self.ts)
            pt = {"model": dm, "kf": kalman_gain(dm, self.measured)}
            pt.update(self.build(dm))
            self._points[key] = pt
        return self._points[key]

    def build(self, dm: DiscreteTurbine) -> dict:
        """Subclass hook: what ``policy`` needs at one operating point.

        Parameters
        ----------
        dm : DiscreteTurbine
            The discrete model there.

        Returns
        -------
        dict
            Extra entries of :meth:`point` (none here).
        """
        return {}

    def policy(self, pt: dict, xhat: np.ndarray, uprev: np.ndarray) -> np.ndarray:
        """Subclass hook: command deviations (rad) of the runs at one operating point.

        Each controller defines it (the QP's first move, the economic problem's first move, the
        regressor's command within the actuator limits); they share this docstring.

        Parameters
        ----------
        pt : dict
            :meth:`point` of their operating point.
        xhat : numpy.ndarray
            (G, n+1) filtered states and wind deviation (last column, m/s).
        uprev : numpy.ndarray
            (G,) previous command deviations (rad).

        Returns
        -------
        numpy.ndarray
            (G,) new command deviations (rad).

        Raises
        ------
        RuntimeError
            If the controller's solver fails.
        """
        raise NotImplementedError

    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        """Initialise every run at its trim (called by the simulator before the first step).

        Parameters
        ----------
        dt : float
            Simulation step (s); ``ts`` must be a whole multiple of it.
        wind : numpy.ndarray
            (R,) wind at t = 0 (m/s).
        pitch : numpy.ndarray
            (R,) initial pitch (rad): the trim pitch of each run's mean wind speed.
        torque : numpy.ndarray
            (R,) generator torque (N·m).

        Raises
        ------
        ValueError
            If ``ts`` is not a whole multiple of ``dt``.
        """
        every = int(round(self.ts / dt))
        if every < 1 or abs(every * dt - self.ts) > 1e-9 * self.ts:
            raise ValueError(f"ts={self.ts} s must be a whole multiple of the simulation step dt={dt} s")
        pitch = np.asarray(pitch, float)
        speeds = np.array([operating_wind_speed(self.model, float(b), float(w)) for b, w in zip(pitch, wind)])
        groups = {}
        for r, v in enumerate(speeds):
            groups.setdefault(float(v), []).append(r)
        groups = {v: np.array(idx) for v, idx in groups.items()}
        pts = {v: self.point(v) for v in groups}
        n1 = next(iter(pts.values()))["kf"][0].shape[0]
        beta0 = np.empty(pitch.size)
        y0 = {}
        for v, idx in groups.items():
            beta0[idx] = pts[v]["model"].pitch0
            y0[v] = pts[v]["model"].y0[pts[v]["model"].rows(self.measured)]
        self.trace = [] if getattr(self, "_recording", False) else None
        self._run = {"every": every, "k": 0, "groups": groups, "points": pts, "beta0": beta0, "y0": y0,
                     "xprior": np.zeros((pitch.size, n1)), "u": pitch - beta0, "cmd": pitch.copy(), "warned": set()}

    def __call__(self, t: float, y: dict) -> np.ndarray:
        """Pitch command of every run at time ``t`` (the simulator's callable contract).

        Parameters
        ----------
        t : float
            Time (s).
        y : dict
            Output name → (R,) measured outputs (SI).

        Returns
        -------
        numpy.ndarray
            (R,) absolute pitch command (rad), held between samples.

        Raises
        ------
        RuntimeError
            If called before :meth:`start`.

        Warns
        -----
        RuntimeWarning
            Once per signal, for a NaN or inf measurement: that run holds its last command and
            its state estimate until the signal is finite again
            (:func:`specdesign._checks.bad_measurements`, the convention of every controller).
        """
        run = getattr(self, "_run", None)
        if run is None:
            raise RuntimeError(f"{type(self).__name__}.start(dt, wind, pitch, torque) must be called first "
                               "(specdesign.simulate.simulate does it)")
        k = run["k"]
        run["k"] = k + 1
        if k % run["every"]:
            return run["cmd"]
        # a run with a NaN/inf sample holds its command and its estimate (bad_measurements)
        bad = bad_measurements(y, self.measured, t, run["warned"], self.name)
        ym = np.stack([np.asarray(y[n], float) for n in self.measured], axis=1)
        for v, idx in run["groups"].items():
            idx = idx[~bad[idx]]
            if not idx.size:
                continue
            pt = run["points"][v]
            Aa, Ba, Ca, L = pt["kf"]
            xp = run["xprior"][idx]
            xf = xp + (ym[idx] - run["y0"][v] - xp @ Ca.T) @ L.T
            if self.trace is not None:
                self.trace.append((t, v, xf.copy(), run["u"][idx].copy()))
            run["now"] = (t, idx)  # for a policy that reads per-run data (a wind preview)
            u = np.asarray(self.policy(pt, xf, run["u"][idx]), float)
            run["u"][idx] = u
            run["xprior"][idx] = xf @ Aa.T + u[:, None] * Ba
        run["cmd"] = run["beta0"] + run["u"]
        return run["cmd"]
