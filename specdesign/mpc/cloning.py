"""Behavioural cloning of the long-horizon economic optimiser (Collet et al., behavioural cloning of a fatigue-oriented economic MPC, Section 4).

The expert is the economic problem of :func:`~specdesign.mpc.economic_problem` over a long
horizon (default 20 s; the paper's 10-100 s), solved open loop from a given state: its first
move is the expert's command there. A controller in closed loop knows the present only (the
simulator gives it no wind preview), so the expert is asked what a controller could ask:
from the Kalman estimate (x̂_k, d̂_k) of :mod:`specdesign.mpc.base`, with the wind deviation
held at d̂_k over the horizon, and the previous command u_{k−1}. Demonstrations pair::

    features  X_k = [x̂_k (5 states, deviations), d̂_k (m/s), u_{k−1} (rad), v (m/s)]
    target    Y_k = u*_k (rad, deviation from the trim pitch), the expert's first move

at the states a closed loop visits: rollouts of a behaviour controller on the nonlinear
turbine (:class:`~specdesign.mpc.QuadraticMPC` first), then, with ``rounds`` > 1, of the clone
itself (DAgger: the clone's own state distribution, labelled by the expert, is added and the
clone refitted). Each visited state is also labelled in ``perturbed`` copies moved by Gaussian
draws of the features' own spread: along a closed loop's trajectory the features are nearly
collinear, and fitted on the visited states alone the regressor's gains are not identified (a
clone with the operating point estimated took a tower-velocity gain of the wrong sign and
shook the tower; docs/mpc.md). Cloning the paper's perfect-preview open-loop optimum instead
(:func:`~specdesign.mpc.economic_open_loop`) gives a policy without enough speed feedback: its
demonstrations never leave the optimal trajectory, and the clone lets the rotor run away in
closed loop (docs/mpc.md). That optimum stays the reference the controllers are compared with.

The regressor is the paper's two-stage fit (Eqs. 19-22): a linear regression f_L, then
gradient-boosted trees f_NL (scikit-learn ``HistGradientBoostingRegressor``, depth ≤ 6, early
stopping on a validation split) on its residual. Both learn the move u*_k − u_{k−1} (the command
itself is dominated by u_{k−1}, which would make any fit look perfect); the predicted command
is u_{k−1} + f_L + f_NL. The clone's command is saturated at the pitch rate and position limits
(a safety layer the regressor cannot guarantee, counted in ``saturated``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from threadpoolctl import ThreadpoolController

from .._checks import positive_scalar
from .._docs import docstring_of
from ..simulate import SimulationDivergedError, simulate
from .base import MEASURED, discretize_turbine, steps_per_sample, within_limits
from .economic import economic_problem, solve_cone
from .quadratic import QuadraticMPC
from .sampled import SampledController

__all__ = ["Demonstrations", "demonstrations", "CloningRegressor", "ClonedController", "OpenLoopPlayback", "clone",
           "UPREV"]

#: Column of the previous command u_{k−1} in the features.
UPREV = 6


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Demonstrations:
    """Expert demonstrations: features, target commands and where they came from.

    Parameters
    ----------
    features : numpy.ndarray
        (n, 8) rows [x̂ (5 states), d̂ (m/s), u_prev (rad), v (m/s)] (module docstring).
    targets : numpy.ndarray
        (n,) expert commands u* (rad, deviations).
    seeds : numpy.ndarray
        (n,) seed of the wind record of each row.
    ts : float
        Sample time (s).
    cpu_time : numpy.ndarray
        CPU time of each expert solve (s).
    """

    features: np.ndarray
    targets: np.ndarray
    seeds: np.ndarray
    ts: float
    cpu_time: np.ndarray

    def join(self, other: Demonstrations) -> Demonstrations:
        """These rows and ``other``'s (DAgger aggregates the rounds).

        Parameters
        ----------
        other : Demonstrations
            More rows, at the same ``ts``.

        Returns
        -------
        Demonstrations
            All rows.

        Raises
        ------
        ValueError
            For another sample time.
        """
        if abs(other.ts - self.ts) > 1e-12:
            raise ValueError(f"cannot join demonstrations at ts={self.ts} and ts={other.ts} s")
        return Demonstrations(np.vstack([self.features, other.features]), np.concatenate([self.targets, other.targets]),
                              np.concatenate([self.seeds, other.seeds]), self.ts,
                              np.concatenate([self.cpu_time, other.cpu_time]))


def demonstrations(model, wind_speeds, seeds, terms, *, behaviour=None, horizon: float = 20.0, ts: float = 0.2,
                   duration: float = 100.0, every: float = 0.6, transient: float = 20.0,
                   speed_weight: float = 100.0, activity_weight: float = 1.0,
                   turbulence_class: str = "B", perturbed: int = 1, perturb_seed: int = 0) -> Demonstrations:
    """Roll out a behaviour controller, then label the states it visits, and perturbed copies, with the expert's move.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    wind_speeds : sequence of float
        Mean wind speeds (m/s).
    seeds : sequence of int
        Wind seeds of the rollouts (:func:`specdesign.wind.wind_series`).
    terms : sequence of FatigueTerm
        Priced loads (:func:`~specdesign.mpc.fit_fatigue_terms`).
    behaviour : SampledController, optional
        Controller of the rollouts (default :class:`~specdesign.mpc.QuadraticMPC` at ``ts``).
    horizon : float, default 20.0
        Expert's horizon (s).
    ts : float, default 0.2
        Sample time (s), the behaviour controller's.
    duration : float, default 100.0
        Recorded length of each rollout (s).
    every : float, default 0.6
        Spacing of the labelled states (s), a multiple of ``ts`` (consecutive samples carry
        little new information, and each label is one solve).
    transient : float, default 20.0
        Rollout time before the first labelled state (s).
    speed_weight, activity_weight : float
        The expert's q_Ω and q_Δ (:func:`~specdesign.mpc.economic_problem`).
    turbulence_class : str, default "B"
        IEC class of the wind.
    perturbed : int, default 1
        Perturbed copies of every visited state, labelled too: each of the features x̂, d̂ and
        u_prev moved by an independent Gaussian draw whose SD is that feature's SD over the
        visited states (the grid point v kept). Without them the features are nearly collinear
        (the pitch follows the command, the tower velocity follows the wind estimate along a
        closed loop's trajectory) and the regressor's gains on them are not identified: a clone
        fitted on the visited states alone took a tower-velocity gain of the wrong sign and
        shook the tower (docs/mpc.md, "The causal clone with the operating point estimated").
        0 labels the visited states only.
    perturb_seed : int, default 0
        Seed of the perturbations' generator.

    Returns
    -------
    Demonstrations
        One row per labelled state (the visited states first, then their perturbed copies).

    Raises
    ------
    ValueError
        For ``every`` not a whole multiple of ``ts``, a behaviour controller at another sample
        time, or ``perturbed`` not an integer >= 0.
    """
    horizon, ts, every = positive_scalar(horizon, "horizon"), positive_scalar(ts, "ts"), positive_scalar(every, "every")
    stride = int(round(every / ts))
    if stride < 1 or abs(stride * ts - every) > 1e-9 * every:
        raise ValueError(f"every={every} s must be a whole multiple of ts={ts} s")
    behaviour = QuadraticMPC(model, ts=ts) if behaviour is None else behaviour
    if not isinstance(behaviour, SampledController) or abs(behaviour.ts - ts) > 1e-12:
        raise ValueError(f"behaviour must be a SampledController (an MPC or a clone) at ts={ts} s")
    if isinstance(perturbed, bool) or not isinstance(perturbed, (int, np.integer)) or perturbed < 0:
        raise ValueError(f"perturbed={perturbed!r} must be an integer >= 0 (perturbed copies per visited state)")
    N = int(round(horizon / ts))
    seeds = list(seeds)
    behaviour.record(True)
    visited, seed_of = [], []  # feature rows [x̂, d̂, u_prev, v] of the visited states, their wind seeds
    try:
        for v in np.atleast_1d(np.asarray(wind_speeds, float)):
            try:
                simulate(model, behaviour, [float(v)], seeds=seeds, duration=duration, transient=transient)
            except SimulationDivergedError:
                pass  # an early clone may lose the rotor: the states it visited on the way are the lesson
            # every ``stride``-th sample after the transient (a sample may carry two records:
            # the two grid points of its wind estimate)
            trace = [rec for rec in behaviour.trace if rec[0] >= transient and int(round(rec[0] / ts)) % stride == 0]
            for _, vv, xhat, uprev, runs in trace:
                visited.extend(np.column_stack([xhat, uprev, np.full(uprev.size, vv)]))
                seed_of.extend(seeds[r % len(seeds)] for r in runs)
    finally:
        behaviour.record(False)
    rows, seed_of = np.array(visited).reshape(-1, UPREV + 2), np.array(seed_of, int)
    if perturbed and rows.shape[0] > 1:
        # every feature but the grid point v, spread by its own SD over the visited states
        spread = np.append(rows[:, :-1].std(axis=0), 0.0)
        rng = np.random.default_rng(perturb_seed)
        copies = np.repeat(rows, perturbed, axis=0)
        rows = np.vstack([rows, copies + rng.standard_normal(copies.shape) * spread])
        seed_of = np.concatenate([seed_of, np.repeat(seed_of, perturbed)])
    feats, targs, sd, cpu, experts = [], [], [], [], {}
    for f, s in zip(rows, seed_of):
        vv = float(f[-1])
        if vv not in experts:  # the expert at the row's operating point, compiled once
            experts[vv] = economic_problem(
                discretize_turbine(model, vv, ts), terms, N, speed_weight=speed_weight,
                activity_weight=activity_weight, rated_speed=float(model.rated_rotor_speed),
                rate_limit=float(model.pitch_rate_limit),
                pitch_limits=(float(model.pitch_min), float(model.pitch_max)))
        pb = experts[vv]
        t0 = time.process_time()
        pb["x0"].value, pb["d"].value = f[:UPREV - 1], np.full(N, f[UPREV - 1])
        pb["uprev"].value = f[UPREV:UPREV + 1]
        ok = solve_cone(pb["problem"])
        cpu.append(time.process_time() - t0)
        if not ok:
            continue  # an unlabelled state is left out, not guessed
        feats.append(f)
        targs.append(float(pb["v"].value[0]) * pb["step"])
        sd.append(int(s))
    return Demonstrations(np.array(feats).reshape(-1, UPREV + 2), np.array(targs), np.array(sd, int), ts,
                          np.array(cpu))


_POOLS = []


def _threadpools():
    """threadpoolctl's controller, built once (it scans the loaded libraries: milliseconds)."""
    if not _POOLS:
        _POOLS.append(ThreadpoolController())
    return _POOLS[0]


def clone(model, wind_speeds, seeds, terms, *, rounds: int = 2, ts: float = 0.2, **kw) -> tuple:
    """Behavioural cloning with DAgger: demonstrations, fit, then ``rounds − 1`` rounds of the clone's own states.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    wind_speeds : sequence of float
        Mean wind speeds (m/s) of the rollouts; one regressor is fitted per speed, and the
        clone runs at these speeds only (:class:`ClonedController`).
    seeds : sequence of int
        Wind seeds of the rollouts (use other seeds to evaluate the clone).
    terms : sequence of FatigueTerm
        Priced loads of the expert.
    rounds : int, default 2
        1: the behaviour controller's states only; each further round rolls out the current
        clone, labels its states and refits on everything.
    ts : float, default 0.2
        Sample time (s).
    **kw
        Options of :func:`demonstrations` (``horizon``, ``duration``, ``every``, ``transient``,
        the weights, ``turbulence_class``, ``perturbed``, ``perturb_seed``).

    Returns
    -------
    controller : ClonedController
        The clone.
    demos : Demonstrations
        Every demonstration it was fitted on.

    Raises
    ------
    ValueError
        For ``rounds`` < 1.
    """
    if isinstance(rounds, bool) or not isinstance(rounds, (int, np.integer)) or rounds < 1:
        raise ValueError(f"rounds={rounds!r} must be an integer >= 1")
    speeds = [float(v) for v in np.atleast_1d(np.asarray(wind_speeds, float))]
    # one regressor per operating point, as gains are scheduled: the expert's feedback gains
    # change with the wind speed more than one linear stage plus trees fit well
    demos = {v: demonstrations(model, [v], seeds, terms, ts=ts, **kw) for v in speeds}
    ctrl = ClonedController(model, {v: CloningRegressor().fit(d) for v, d in demos.items()}, ts)
    for _ in range(int(rounds) - 1):
        demos = {v: d.join(demonstrations(model, [v], seeds, terms, behaviour=ctrl, ts=ts, **kw))
                 for v, d in demos.items()}
        ctrl = ClonedController(model, {v: CloningRegressor().fit(d) for v, d in demos.items()}, ts)
    every = list(demos.values())
    joined = every[0]
    for d in every[1:]:
        joined = joined.join(d)
    return ctrl, joined


class CloningRegressor:
    """Linear regression plus gradient-boosted trees on its residual (Collet et al., Eqs. 19-22).

    Parameters
    ----------
    max_depth : int, default 6
        Depth of the trees (the paper's 6).
    max_iter : int, default 200
        Most boosting iterations; early stopping on a 10 % validation split ends sooner.
    random_state : int, default 0
        Seed of the validation split.
    uprev_column : int, default :data:`UPREV`
        Column of the features holding the previous command: the stages learn the move from it.
    """

    def __init__(self, max_depth: int = 6, max_iter: int = 200, random_state: int = 0, uprev_column: int = UPREV):
        self.max_depth, self.max_iter, self.random_state = int(max_depth), int(max_iter), int(random_state)
        self.uprev_column = int(uprev_column)
        self.linear = self.trees = None

    def fit(self, demos: Demonstrations) -> CloningRegressor:
        """Fit on demonstrations.

        Parameters
        ----------
        demos : Demonstrations
            Training rows.

        Returns
        -------
        CloningRegressor
            ``self``, fitted.

        Raises
        ------
        ImportError
            Without scikit-learn (``pip install "specdesign[mpc]"``).
        ValueError
            With fewer than 20 rows.
        """
        try:
            from sklearn.ensemble import HistGradientBoostingRegressor
            from sklearn.linear_model import LinearRegression
        except ImportError as e:  # pragma: no cover - the mpc extra installs it
            raise ImportError('behavioural cloning needs scikit-learn: pip install "specdesign[mpc]"') from e
        if demos.targets.size < 20:
            raise ValueError(f"demos has {demos.targets.size} rows; fit needs at least 20")
        move = demos.targets - demos.features[:, self.uprev_column]
        self.linear = LinearRegression().fit(demos.features, move)
        res = move - self.linear.predict(demos.features)
        self.trees = HistGradientBoostingRegressor(max_depth=self.max_depth, max_iter=self.max_iter,
                                                   early_stopping=True, validation_fraction=0.1,
                                                   random_state=self.random_state).fit(demos.features, res)
        return self

    def predict(self, features: np.ndarray) -> np.ndarray:
        """Commands (rad, deviations) for rows of features.

        Parameters
        ----------
        features : numpy.ndarray
            (n, 8) rows as in :class:`Demonstrations`.

        Returns
        -------
        numpy.ndarray
            (n,) predicted commands.

        Raises
        ------
        RuntimeError
            Before :meth:`fit`.
        """
        if self.linear is None:
            raise RuntimeError("CloningRegressor.fit(demos) must be called before predict")
        features = np.asarray(features, float)
        # one thread: for the few rows of a control step, OpenMP's thread start-up costs ~50×
        # the prediction itself (45 ms against 0.6 ms of CPU for 4 rows)
        with _threadpools().limit(limits=1, user_api="openmp"):
            return features[:, self.uprev_column] + self.linear.predict(features) + self.trees.predict(features)

    def score(self, demos: Demonstrations, *, moves: bool = True) -> float:
        """R² of the predictions on demonstrations (1 − SS_res/SS_tot).

        Parameters
        ----------
        demos : Demonstrations
            Rows to score (held out from the fit, for an honest figure).
        moves : bool, default True
            Score the moves u − u_prev (the demanding figure) rather than the commands u.

        Returns
        -------
        float
            The coefficient of determination.
        """
        y, p = demos.targets, self.predict(demos.features)
        if moves:
            y, p = y - demos.features[:, self.uprev_column], p - demos.features[:, self.uprev_column]
        return float(1.0 - np.sum((y - p) ** 2) / np.sum((y - y.mean()) ** 2))


class ClonedController(SampledController):
    """The cloned expert as a callable controller of :func:`~specdesign.simulate.simulate`.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    regressor : CloningRegressor or dict
        Fitted on :func:`demonstrations`: one for every operating point, or wind speed (m/s)
        → regressor, the nearest used at each run's wind speed (within ``max_gap``).
    ts : float, default 0.2
        Sample time (s), that of the demonstrations.
    measured : sequence of str, optional
        Outputs the Kalman filter reads.
    max_gap : float, default 5.0
        Largest distance (m/s) from an operating point of the schedule to the nearest trained
        speed: a clone knows only the operating points it was shown (a rollout at v visits
        the grid points its wind estimate crosses: in class-B turbulence at 19 m/s, 15-23 m/s).
    name : str, default "behavioural cloning"
        Label.
    operating_point, wind_speeds : str, array_like
        As :class:`~specdesign.mpc.sampled.SampledController` takes them.
    sensors : specdesign.simulate.SensorNoise, optional
        The sensors the runs read through, whose noise the Kalman filter assumes, as
        :class:`~specdesign.mpc.sampled.SampledController` takes them (default: none, the
        filter's own tuning).

    Attributes
    ----------
    saturated : int
        Commands the rate or position limits cut since the last :meth:`start`.
    solve_times : list of float
        CPU time (s) per sample and run (the runs of an operating point are predicted at once;
        their time is shared).
    """

    def __init__(self, model, regressor, ts: float = 0.2, measured=MEASURED, max_gap: float = 5.0,
                 name: str = "behavioural cloning", operating_point: str = "estimated", wind_speeds=None,
                 sensors=None):
        regs = regressor if isinstance(regressor, dict) else {None: regressor}
        if not regs or not all(isinstance(r, CloningRegressor) and r.linear is not None for r in regs.values()):
            raise TypeError("regressor must be a fitted CloningRegressor (CloningRegressor().fit(demos)) "
                            "or a dict wind speed → fitted CloningRegressor")
        self.regressors = {None if k is None else float(k): r for k, r in regs.items()}
        self.max_gap = positive_scalar(max_gap, "max_gap")
        self.saturated = 0
        super().__init__(model, ts, measured, name, operating_point=operating_point, wind_speeds=wind_speeds,
                         sensors=sensors)

    @docstring_of(SampledController, note=('Here the regressor trained nearest the operating point, under ``"regressor"``; '
                                           "a ValueError if none was trained within ``max_gap`` of its wind speed."))
    def build(self, dm) -> dict:
        if None in self.regressors:
            return {"regressor": self.regressors[None]}
        near = min(self.regressors, key=lambda v: abs(v - dm.wind_speed))
        if abs(near - dm.wind_speed) > self.max_gap:
            raise ValueError(f"{self.name}: no clone trained within {self.max_gap:g} m/s of {dm.wind_speed:g} m/s "
                             f"(trained at {sorted(self.regressors)}); clone at this wind speed too")
        return {"regressor": self.regressors[near]}

    @docstring_of(SampledController, note="The clone also sets its count of saturated commands (``saturated``) to zero.")
    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        self.saturated = 0
        super().start(dt, wind, pitch, torque)

    @docstring_of(SampledController)
    def policy(self, pt: dict, xhat: np.ndarray, uprev: np.ndarray) -> np.ndarray:
        # the regressor's command for every run, within the actuator limits
        t0 = time.process_time()
        dm = pt["model"]
        X = np.column_stack([xhat, uprev, np.full(uprev.size, dm.wind_speed)])
        u = pt["regressor"].predict(X)
        out = within_limits(self.model, self.ts, u, uprev, dm.pitch0)
        self.saturated += int(np.count_nonzero(out != u))
        self.solve_times.extend([(time.process_time() - t0) / max(uprev.size, 1)] * uprev.size)
        return out


class OpenLoopPlayback:
    """Replays fixed pitch-command sequences (e.g. open-loop optima) through ``simulate``.

    Parameters
    ----------
    commands : array_like
        (R, N) absolute pitch commands (rad), one row per run, each held for ``ts``; the last
        is held beyond.
    ts : float
        Sample time of the commands (s).
    name : str, default "open-loop optimum"
        Label.

    Examples
    --------
    >>> p = OpenLoopPlayback([[0.1, 0.2]], 0.2)
    >>> p.start(0.1, [19.0], [0.1], [1.0]); [float(p(t, {})[0]) for t in (0.0, 0.1, 0.2, 0.3, 0.4)]
    [0.1, 0.1, 0.2, 0.2, 0.2]
    """

    def __init__(self, commands, ts: float, name: str = "open-loop optimum"):
        self.commands = np.atleast_2d(np.asarray(commands, float))
        if not np.all(np.isfinite(self.commands)):
            raise ValueError("commands must be finite pitch angles (rad)")
        self.ts = positive_scalar(ts, "ts")
        self.__name__ = self.name = str(name)

    def start(self, dt: float, wind, pitch, torque) -> None:
        """Reset to the first command (called by the simulator).

        Parameters
        ----------
        dt : float
            Simulation step (s); ``ts`` must be a whole multiple of it.
        wind, pitch, torque : array_like
            (R,) per run (unused but for R).

        Raises
        ------
        ValueError
            If the number of runs is not the number of rows of ``commands``, or ``ts`` is not a
            whole multiple of ``dt``.
        """
        if np.size(pitch) != self.commands.shape[0]:
            raise ValueError(f"commands has {self.commands.shape[0]} rows but the simulation has {np.size(pitch)} runs")
        self._every = steps_per_sample(self.ts, dt)
        self._k = 0

    def __call__(self, t: float, y: dict) -> np.ndarray:
        """(R,) pitch commands (rad) of every run at time ``t`` (s), the measured outputs ``y`` unused (open
        loop): the simulator's callable contract, as :meth:`specdesign.mpc.sampled.SampledController.__call__`."""
        j = min(self._k // self._every, self.commands.shape[1] - 1)
        self._k += 1
        return self.commands[:, j].copy()
