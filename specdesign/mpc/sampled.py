"""The sampled loop every controller of :mod:`specdesign.mpc` shares (:class:`SampledController`):
the Kalman filter of :mod:`specdesign.mpc.base` run on the measurements every sample, the
operating point estimated online (LPV observer of :mod:`specdesign.mpc.lpv`, the policy
scheduled on its wind estimate) or held at the initial trim, and the command held between
samples (see the module docstring of :mod:`specdesign.mpc.base`).
"""
from __future__ import annotations

import numpy as np

from .._checks import bad_measurements, positive_scalar
from .base import (
    MEASURED,
    OPERATING_POINTS,
    DiscreteTurbine,
    discretize_turbine,
    filter_noise,
    kalman_gain,
    operating_wind_speed,
    pitch_wind_estimate,
    steps_per_sample,
)
from .lpv import check_speeds, lpv_observer, vertex_pair

__all__ = ["SampledController"]


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
    operating_point : {"estimated", "initial pitch", "design point"}, default "estimated"
        Schedule the model on the run's own wind estimate (default), hold the linearisation at
        the trim of the run's initial pitch (the run's mean wind in the simulator: model and
        operating point known), or at ``design_speed`` (:mod:`specdesign.mpc.base`).
    wind_speeds : array_like, optional
        Grid of operating points (m/s) of the estimated schedule; default every 1 m/s over
        ``model.wind_range``.
    design_speed : float, optional
        The fixed operating point (m/s), with ``operating_point="design point"`` only.
    sensors : specdesign.simulate.SensorNoise, optional
        The sensors the runs read through: the Kalman filter assumes their noise
        (:func:`specdesign.mpc.base.filter_noise`, each sample's SD at the noise's
        ``sample_time``); None (default): its own tuning, :data:`~specdesign.mpc.base.MEASUREMENT_STD`, which trusts
        the sensors (a noise-free simulation).

    Attributes
    ----------
    solve_times : list of float
        CPU time (s) of the policy per run and sample, since construction or unpickling.
    trace : list or None
        What the policy saw at every sample of the last run, after :meth:`record`.
    """

    def __init__(self, model, ts: float, measured=MEASURED, name: str = "controller", *,
                 operating_point: str = "estimated", wind_speeds=None, design_speed: float | None = None,
                 sensors=None):
        self.model = model
        self.ts = positive_scalar(ts, "ts")
        self.measured = tuple(measured)
        if not self.measured or not all(isinstance(m, str) for m in self.measured):
            raise TypeError(f"measured must be a non-empty sequence of output names, got {measured!r}")
        if operating_point not in OPERATING_POINTS:
            raise ValueError(f"operating_point={operating_point!r} must be one of {OPERATING_POINTS}")
        self.operating_point = operating_point
        if (operating_point == "design point") != (design_speed is not None):
            raise ValueError('design_speed (m/s) must be given with operating_point="design point", and only then')
        self.design_speed = None if design_speed is None else positive_scalar(design_speed, "design_speed")
        self.wind_speeds = tuple(float(v) for v in check_speeds(model, wind_speeds))
        self.sensors = sensors
        self.measurement_std = filter_noise(sensors)
        self.__name__ = self.name = str(name)
        self._reset_caches()

    def _reset_caches(self):
        self._points = {}
        self._observer = None
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
        The record is :attr:`trace`: a list of ``(t, v, xhat, uprev, runs)`` per sample and
        operating point (grid point of the schedule), ``xhat`` (G, n+1) the filtered states and
        wind estimate and ``uprev`` (G,) the previous commands, in deviations from the trim at
        ``v``, and ``runs`` (G,) the runs' indices; behavioural cloning labels these states with
        the expert at ``v``.
        """
        self._recording = bool(on)

    def __getstate__(self):
        state = dict(self.__dict__)
        for k in ("_points", "_observer", "solve_times", "_run", "trace", "_recording"):
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
            pt = {"model": dm, "kf": kalman_gain(dm, self.measured, measurement_std=self.measurement_std)}
            pt.update(self.build(dm))
            self._points[key] = pt
        return self._points[key]

    def build(self, dm: DiscreteTurbine) -> dict:
        """What ``policy`` needs at one operating point (a subclass hook).

        Parameters
        ----------
        dm : DiscreteTurbine
            The discrete model there.

        Returns
        -------
        dict
            Extra entries of :meth:`point` (none in this base class).
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

    def observer(self):
        """The LPV Kalman filter of the estimated schedule (built once on :attr:`wind_speeds`).

        Returns
        -------
        LPVObserver
            :func:`specdesign.mpc.lpv.lpv_observer` of the model, the measured outputs and the grid.
        """
        if self._observer is None:
            self._observer = lpv_observer(self.model, self.ts, self.measured, wind_speeds=self.wind_speeds,
                                          measurement_std=self.measurement_std)
        return self._observer

    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        """Initialise every run (called by the simulator before the first step).

        Parameters
        ----------
        dt : float
            Simulation step (s); ``ts`` must be a whole multiple of it.
        wind : numpy.ndarray
            (R,) wind at t = 0 (m/s): read only with ``operating_point="initial pitch"`` below
            rated (:func:`~specdesign.mpc.base.operating_wind_speed`).
        pitch : numpy.ndarray
            (R,) measured initial pitch (rad).
        torque : numpy.ndarray
            (R,) generator torque (N·m).

        Raises
        ------
        ValueError
            If ``ts`` is not a whole multiple of ``dt``.
        """
        every = steps_per_sample(self.ts, dt)
        pitch = np.asarray(pitch, float)
        if self.operating_point == "estimated":
            # the trim table inverted at the measured pitch: the filter's starting point only
            speeds = np.array([pitch_wind_estimate(self.model, float(b)) for b in pitch])
        elif self.operating_point == "design point":
            speeds = np.full(pitch.size, self.design_speed)
        else:
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
        if self.operating_point == "estimated":
            self.observer()  # built before the first sample, not inside the timed policy
            z = np.empty((pitch.size, n1))
            for v, idx in groups.items():
                z[idx] = np.append(pts[v]["model"].x0, v)
            self._run["zprior"] = z

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
        if self.operating_point == "estimated":
            self._scheduled_step(t, ym, ~bad)
            return run["cmd"]
        for v, idx in run["groups"].items():
            idx = idx[~bad[idx]]
            if not idx.size:
                continue
            pt = run["points"][v]
            Aa, Ba, Ca, L = pt["kf"]
            xp = run["xprior"][idx]
            xf = xp + (ym[idx] - run["y0"][v] - xp @ Ca.T) @ L.T
            if self.trace is not None:
                self.trace.append((t, v, xf.copy(), run["u"][idx].copy(), idx.copy()))
            run["now"] = (t, idx)  # for a policy that reads per-run data (a wind preview)
            u = np.asarray(self.policy(pt, xf, run["u"][idx]), float)
            run["u"][idx] = u
            run["xprior"][idx] = xf @ Aa.T + u[:, None] * Ba
        run["cmd"] = run["beta0"] + run["u"]
        return run["cmd"]

    def _scheduled_step(self, t: float, ym: np.ndarray, ok: np.ndarray) -> None:
        """One sample of the estimated schedule: LPV filter, policy at the two grid points of v̂, blend."""
        run, obs = self._run, self.observer()
        rows = np.flatnonzero(ok)
        if not rows.size:
            return
        zf = np.stack([obs.update(run["zprior"][r], ym[r]) for r in rows])
        # the runs of each grid point with their weights α_i(v̂)
        share = {}
        for g, r in enumerate(rows):
            i, a = vertex_pair(obs.wind_speeds, zf[g, -1])
            for j, w in ((i, 1.0 - a), (min(i + 1, obs.wind_speeds.size - 1), a)):
                if w > 0.0:
                    share.setdefault(j, []).append((g, w))
        prev = run["cmd"][rows]
        new = np.zeros(rows.size)
        for j, gw in sorted(share.items()):
            g = np.array([x for x, _ in gw])
            w = np.array([x for _, x in gw])
            pt = self.point(float(obs.wind_speeds[j]))
            dm = pt["model"]
            xhat = zf[g] - obs.z_trim[j]  # deviations from this grid point's trim (states, wind)
            uprev = prev[g] - dm.pitch0
            if self.trace is not None:
                self.trace.append((t, dm.wind_speed, xhat.copy(), uprev.copy(), rows[g].copy()))
            run["now"] = (t, rows[g])  # for a policy that reads per-run data (a wind preview)
            u = np.asarray(self.policy(pt, xhat, uprev), float)
            new[g] += w * (dm.pitch0 + u)
        run["cmd"] = run["cmd"].copy()
        run["cmd"][rows] = new
        for g, r in enumerate(rows):
            run["zprior"][r] = obs.predict(zf[g], new[g])
