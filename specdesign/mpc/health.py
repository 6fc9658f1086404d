"""Health-aware LPV MPC of the pitch (after Boutrous, Nejjari and Puig, *Health-aware LPV model predictive control of wind turbines*), trading speed (power) tracking against the
growth of the blades' accumulated fatigue damage.

Seed 002 (Boutrous, Nejjari, Puig) augments an LPV turbine model with the accumulated
blade-root moment M_acc(k+1) = M_acc(k) + M_b(k) (its Eq. 16) and adds Ψ_mb·M_acc to the
tracking cost (its Eqs. 12, 18), solved as a QP with the scheduling frozen over the horizon at
its current estimate. Mapped onto this workbench's reduced model:

- **Plant and scheduling**: the LPV prediction of :mod:`specdesign.mpc.lpv` (vertices are the
  linearisations of the simulated equations every 1 m/s, blended by the estimated wind v̂),
  instead of the seed's Euler-discretised polytope. The state and the wind come from the
  Kalman filter of :mod:`specdesign.mpc.base` made LPV on the same vertices
  (:class:`~specdesign.mpc.lpv.LPVObserver`; the seed assumes them measured).
- **Blade load**: the seed's regression M_b = a₀ + a₁T_gω_r + a₂w becomes this model's
  ``blade_root_my`` (the quasi-static flapwise moment r_T(β)·T/3 of
  :mod:`specdesign.turbine.kernel`), predicted through the same LPV model.
- **Health terms** (the predicted blade moments M_1..M_N over the horizon, M̄ the running
  mean of the measured moment, an exponential average over ``mean_time`` seconds started at
  the trim moment, M_s the blade moment at the run's trim):

  * the seed's accumulated-stress term, ``stress_weight`` · Σ_j M_j /(N M_s): linear, it
    derates (more pitch, less thrust and less power), as in the seed's Table 2;
  * the growth of the accumulated *fatigue* damage, ``health_weight`` · Σ_j ((M_j − M̄)/M_s)²
    (the predicted M_j shifted by the measured moment's difference from the model's moment
    now, so that the linear model's bias is not taken for an excursion):
    for a Gaussian load the damage rate grows as σ_M^m (narrow band, range-based S-N curve),
    so the moment's excursions about its mean are what the blade pays for; penalising their
    predicted squares is the convex proxy that keeps the problem a QP. (Penalising the
    increments M_j − M_{j−1} instead does the opposite of what is wanted: with the wind held
    over the horizon the increments are the pitch's own doing: the controller stops pitching
    against gusts and the blade DEL rises instead of falling.)

  The health weight can follow the blades' measured health: with ``del_budget`` (a 1 Hz DEL
  the blade may accumulate, N·m), the online rainflow + Miner damage D(k) of the measured
  moment (:class:`specdesign.fatigue_online.StreamingDamage`, S-N exponent ``blade_m``, S_ref =
  ``del_budget``) scales it by DEL(k)/``del_budget`` = ((D(k) + τ)/(t + τ))^{1/m}, with a prior
  of τ = ``budget_prior`` seconds at the budget: a blade that has accumulated damage faster
  than its budget gets a larger weight.

At every sample the QP, in the pitch commands U (absolute, N of them, zero-order hold over T_s),
is::

    min  q_Ω Σ_j ((Ω_j − Ω_rated)/Ω_rated)² + q_T Σ_j ẋ_top,j² + q_Δ Σ_j ((U_j − U_{j−1})/(β̇_max T_s))²
         + ψ(k) Σ_j ((M_j − M̄)/M_s)² + ψ_acc Σ_j M_j/(N M_s)
    s.t. (Ω, M, ẋ_top) = LPV prediction at v̂,   β_min ≤ U_j ≤ β_max,   |U_j − U_{j−1}| ≤ β̇_max T_s

written as ‖S w − s‖² + cᵀw in w = (U − β_ref)/(β̇_max T_s) (O(1) numbers). Its unconstrained
minimiser (the normal equations) is its solution whenever it is feasible (the QP is strictly
convex), so the solver runs only when a constraint is active: a cvxpy problem whose data S, s,
c and bounds are Parameters, compiled once (DPP) and solved by OSQP.
"""
from __future__ import annotations

import time

import numpy as np

from .._checks import bad_measurements, positive_scalar
from .._docs import docstring_of
from ..fatigue import BLADE_M, SNCurve
from ..fatigue_online import StreamingDamage
from .base import MEASURED
from .lpv import LPVTurbine, lpv_turbine
from .sampled import SampledController

__all__ = ["HealthMPC", "health_aware_mpc", "health_qp", "health_move", "health_scale", "HEALTH_OSQP", "REF_MARGIN"]

#: OSQP settings of the constrained QP (tight tolerances, polishing for exact active sets).
HEALTH_OSQP = {"eps_abs": 1e-9, "eps_rel": 1e-9, "polishing": True, "max_iter": 20000}

#: Largest raise of the speed reference by the integral correction, as a fraction of rated.
REF_MARGIN = 0.05


def health_qp(n_rows: int, horizon: int) -> dict:
    """The compiled cvxpy QP min ‖S w − s‖² + cᵀw, lower ≤ w ≤ upper, |Δw| ≤ 1 (w₋₁ given).

    Parameters
    ----------
    n_rows : int
        Rows of S.
    horizon : int
        N, the number of commands.

    Returns
    -------
    dict
        ``problem`` and its Parameters ``S`` (n_rows, N), ``s`` (n_rows,), ``c`` (N,),
        ``lower``, ``upper`` (N,), ``wprev`` (1,), and the Variable ``w`` (N,).

    Examples
    --------
    >>> qp = health_qp(2, 1)
    >>> qp["S"].value, qp["s"].value = np.eye(2, 1), np.array([3.0, 0.0])
    >>> qp["c"].value, qp["lower"].value, qp["upper"].value = np.zeros(1), -np.ones(1), np.ones(1)
    >>> qp["wprev"].value = np.zeros(1)
    >>> _ = qp["problem"].solve(solver="OSQP", **HEALTH_OSQP)
    >>> round(float(qp["w"].value[0]), 6)    # wants 3, one move allows 1
    1.0
    """
    import cvxpy as cp

    N = int(horizon)
    S, s = cp.Parameter((int(n_rows), N), name="S"), cp.Parameter(int(n_rows), name="s")
    c, lower, upper = cp.Parameter(N, name="c"), cp.Parameter(N, name="lower"), cp.Parameter(N, name="upper")
    wprev = cp.Parameter(1, name="wprev")
    w = cp.Variable(N, name="w")
    dw = cp.hstack([w[:1] - wprev, w[1:] - w[:-1]]) if N > 1 else w - wprev
    problem = cp.Problem(cp.Minimize(cp.sum_squares(S @ w - s) + c @ w), [w >= lower, w <= upper, cp.abs(dw) <= 1.0])
    return {"problem": problem, "S": S, "s": s, "c": c, "lower": lower, "upper": upper, "wprev": wprev, "w": w}


def health_move(lpv: LPVTurbine, x: np.ndarray, wind: float, pitch_ref: float, uprev: float, moment: float, *,
                weights: tuple, rated_speed: float, step: float, pitch_limits: tuple, moment_scale: float,
                speed_ref: float | None = None, measured_moment: float | None = None, qp: dict | None = None,
                solver: str = "OSQP") -> np.ndarray:
    """Optimal pitch commands of the health-aware QP (module docstring) at one sample.

    Parameters
    ----------
    lpv : LPVTurbine
        Prediction model; its outputs must include ``gen_speed``, ``blade_root_my`` and
        ``tower_top_vel``.
    x : numpy.ndarray
        (n,) absolute state estimate (SI).
    wind : float
        Wind estimate v̂ (m/s).
    pitch_ref : float
        β_ref (rad): the commands are optimised as w = (U − β_ref)/step.
    uprev : float
        Previous command (rad, absolute).
    moment : float
        Mean blade-root moment M̄ the excursions are measured from (N·m).
    weights : tuple of float
        (q_Ω, q_T, q_Δ, ψ, ψ_acc) ≥ 0 (dimensionless); q_Δ > 0.
    rated_speed : float
        Ω_rated (rad/s), the speed scale (and the reference unless ``speed_ref`` is given).
    step : float
        Largest move β̇_max T_s (rad).
    pitch_limits : tuple of float
        (β_min, β_max) (rad).
    moment_scale : float
        M_s (N·m).
    speed_ref : float, optional
        Speed reference (rad/s); default ``rated_speed``.
    measured_moment : float, optional
        The blade moment measured now (N·m): the predicted moments are shifted by its difference
        from the model's moment now (offset-free: the linear model's bias does not count as an
        excursion). Default: no shift.
    qp : dict, optional
        :func:`health_qp` of matching size; built here when a constraint is active and none is
        given.
    solver : str, optional
        cvxpy solver.

    Returns
    -------
    numpy.ndarray
        (N,) absolute pitch commands (rad); the first is applied.

    Raises
    ------
    RuntimeError
        If the solver does not find an optimal solution.
    """
    qo, qt, qd, psi, psi_acc = (float(v) for v in weights)
    N, names = lpv.horizon, lpv.output_names
    q = len(names)
    iw, im, iv = names.index("gen_speed"), names.index("blade_root_my"), names.index("tower_top_vel")
    z0, G = lpv.affine(np.asarray(x, float), float(wind), float(pitch_ref))
    zr, Gr = z0.reshape(N, q), (G * step).reshape(N, q, N)
    if measured_moment is not None:
        zr = zr.copy()
        zr[:, im] += float(measured_moment) - lpv.current(np.asarray(x, float), float(wind))[im]
    Dm = np.eye(N) - np.eye(N, k=-1)
    e1 = np.zeros(N)
    e1[0] = 1.0
    wprev = (float(uprev) - pitch_ref) / step
    a, b, sd, h = np.sqrt(qo) / rated_speed, np.sqrt(qt), np.sqrt(qd), np.sqrt(psi) / moment_scale
    S = np.vstack([a * Gr[:, iw, :], b * Gr[:, iv, :], sd * Dm, h * Gr[:, im, :]])
    ref = rated_speed if speed_ref is None else float(speed_ref)
    s = np.concatenate([-a * (zr[:, iw] - ref), -b * zr[:, iv], sd * e1 * wprev, -h * (zr[:, im] - float(moment))])
    c = psi_acc / (N * moment_scale) * Gr[:, im, :].sum(axis=0)
    lower = np.full(N, (pitch_limits[0] - pitch_ref) / step)
    upper = np.full(N, (pitch_limits[1] - pitch_ref) / step)
    w = np.linalg.solve(S.T @ S, S.T @ s - 0.5 * c)
    tol = 1e-9
    if np.any(w < lower - tol) or np.any(w > upper + tol) or np.any(np.abs(np.diff(np.concatenate([[wprev], w]))) > 1 + tol):
        qp = health_qp(S.shape[0], N) if qp is None else qp
        qp["S"].value, qp["s"].value, qp["c"].value = S, s, c
        qp["lower"].value, qp["upper"].value, qp["wprev"].value = lower, upper, np.array([wprev])
        qp["problem"].solve(solver=solver, warm_start=True, **(HEALTH_OSQP if solver == "OSQP" else {}))
        if qp["problem"].status not in ("optimal", "optimal_inaccurate"):
            raise RuntimeError(f"the health-aware QP is {qp['problem'].status}")
        w = np.asarray(qp["w"].value, float)
        # the applied move must respect the actuator's limits exactly (solver tolerance)
        w[0] = min(max(w[0], wprev - 1.0, lower[0]), wprev + 1.0, upper[0])
    return pitch_ref + step * w


def health_scale(damage: float, t: float, m: float, prior: float) -> float:
    """Health factor DEL(k)/DEL_budget = ((D + τ)/(t + τ))^{1/m} of the weight ψ.

    Parameters
    ----------
    damage : float
        D(k), Miner damage so far on an S-N curve whose S_ref is the DEL budget (so the budget
        accrues damage 1 per second at 1 Hz).
    t : float
        Time since the start (s).
    m : float
        Wöhler exponent.
    prior : float
        τ (s): the factor starts at 1, as if τ seconds at the budget had passed.

    Returns
    -------
    float
        The factor (> 0); 1 when the blade is exactly on budget.

    Examples
    --------
    >>> round(health_scale(2.0**10 * 100.0, 100.0, 10.0, 1e-9), 6)   # DEL twice the budget
    2.0
    """
    return float(((damage + prior) / (t + prior)) ** (1.0 / m))


class HealthMPC(SampledController):
    """Health-aware LPV MPC (after Boutrous et al.), a callable controller for ``simulate`` and ``run_campaign``.

    See the module docstring for the problem; the observer and sampling are those of
    :class:`specdesign.mpc.sampled.SampledController`. The generator torque stays at its trim.

    Parameters
    ----------
    model : TurbineModel
        The turbine (with the ``blade_root_my`` output).
    ts : float, default 0.2
        Sample time (s), a whole multiple of the simulation step.
    horizon : int, default 30
        Prediction horizon N (steps): 6 s at 0.2 s, about the tower's period.
    speed_weight, tower_weight, activity_weight : float
        q_Ω, q_T, q_Δ (dimensionless, ≥ 0; q_Δ > 0). Defaults 100, 100, 0.1 (those of
        :class:`specdesign.mpc.QuadraticMPC`).
    health_weight : float, default 0
        ψ, the weight of the blade moment's excursions about its mean (the damage-growth proxy).
    stress_weight : float, default 0
        ψ_acc, Boutrous et al.'s weight of the accumulated blade moment (derating).
    blade_m : float, default 10
        Wöhler exponent of the blade's online damage D(k).
    del_budget : float, optional
        1 Hz blade DEL budget (N·m); with it ψ follows the measured damage (module docstring).
    budget_prior : float, default 60
        τ (s) of :func:`health_scale`.
    mean_time : float, default 60
        Averaging time (s) of the running mean blade moment M̄.
    speed_integral_time : float or None, default 30
        T_I (s): the speed reference is corrected by the integral of the speed error,
        Ω_ref ← Ω_ref − (T_s/T_I)(Ω − Ω_rated), so the *mean* speed (and with the constant
        torque the mean power) stays at rated in turbulence, where the aerodynamics' asymmetry
        would otherwise shift it as the health weight loosens the speed regulation. The
        reference stays ≤ (1 + :data:`REF_MARGIN`)·Ω_rated (anti-windup: with a large health
        weight the speed follows it only loosely), and with ``stress_weight`` > 0 ≤ Ω_rated, so
        the correction does not undo the derating asked for. None: off.
    lpv : bool, default True
        Schedule the prediction and the observer on the estimated wind (LPV,
        :class:`~specdesign.mpc.lpv.LPVObserver`); False: the linearisation at the run's
        starting operating point (``operating_point``) and its fixed Kalman filter only.
    wind_speeds : array_like, optional
        LPV vertices (m/s); default every 1 m/s over the model's range.
    measured : sequence of str, optional
        Outputs the Kalman filter reads.
    solver : str, default "OSQP"
        cvxpy solver when a constraint is active.
    name : str, default "excursion MPC"
        Label (the default names the excursion penalty, this workbench's term; Boutrous et
        al.'s controller is :func:`health_aware_mpc`, "health-aware MPC").
    operating_point : {"estimated", "initial pitch"}, default "estimated"
        Start the observer at the trim of the pitch measured at t = 0 (default; from then on
        the LPV observer schedules on its own wind estimate), or at the trim of the run's
        mean wind (:class:`~specdesign.mpc.sampled.SampledController`).
    sensors : specdesign.simulate.SensorNoise, optional
        The sensors the runs read through, whose noise the Kalman filter assumes, as
        :class:`~specdesign.mpc.sampled.SampledController` takes them (default: none, the
        filter's own tuning).

    Attributes
    ----------
    solve_times : list of float
        CPU time (s) of every QP (one per run per sample) since the last pickle.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> from specdesign.simulate import simulate
    >>> m = iea15mw()
    >>> mpc = HealthMPC(m, health_weight=10.0, wind_speeds=[17.0, 19.0, 21.0])
    >>> r = simulate(m, mpc, [19.0], seeds=[1], duration=4.0, transient=1.0)
    >>> r["blade_root_my"].shape, mpc.blade_damage.shape
    ((1, 1, 40), (1,))
    """

    def __init__(self, model, ts: float = 0.2, horizon: int = 30, *, speed_weight: float = 100.0,
                 tower_weight: float = 100.0, activity_weight: float = 0.1, health_weight: float = 0.0,
                 stress_weight: float = 0.0, blade_m: float = BLADE_M, del_budget: float | None = None,
                 budget_prior: float = 60.0, mean_time: float = 60.0, speed_integral_time: float | None = 30.0,
                 lpv: bool = True, wind_speeds=None, measured=MEASURED,
                 solver: str = "OSQP", name: str = "excursion MPC", operating_point: str = "estimated", sensors=None):
        if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
            raise ValueError(f"horizon={horizon!r} must be an integer number of steps >= 1")
        self.horizon = int(horizon)
        w = (speed_weight, tower_weight, activity_weight, health_weight, stress_weight)
        self.weights = tuple(float(v) for v in w)
        if not np.all(np.isfinite(self.weights)) or min(self.weights) < 0:
            raise ValueError("speed_weight, tower_weight, activity_weight, health_weight, stress_weight must be "
                             f"finite and >= 0, got {self.weights}")
        if self.weights[2] == 0:
            raise ValueError("activity_weight must be > 0 (it keeps the QP strictly convex)")
        self.blade_m = positive_scalar(blade_m, "blade_m")
        self.del_budget = None if del_budget is None else positive_scalar(del_budget, "del_budget")
        self.budget_prior = positive_scalar(budget_prior, "budget_prior")
        self.mean_time = positive_scalar(mean_time, "mean_time")
        self.speed_integral_time = (None if speed_integral_time is None
                                    else positive_scalar(speed_integral_time, "speed_integral_time"))
        self.lpv = bool(lpv)
        self.solver = str(solver)
        super().__init__(model, ts, measured, name, operating_point=operating_point, wind_speeds=wind_speeds,
                         sensors=sensors)
        positive_scalar(model.pitch_rate_limit, "model.pitch_rate_limit")

    def _reset_caches(self):
        super()._reset_caches()
        self._lpv = None
        self._qp = None

    def __getstate__(self):
        state = super().__getstate__()
        for k in ("_lpv", "_qp"):
            state.pop(k, None)
        return state

    @docstring_of(SampledController, note=("Here the trim state ``x_trim`` (n,: the discrete model's ``x0``), the moment scale ``moment_scale`` (N·m) "
                                           "and the prediction model ``lpv`` (:class:`LPVTurbine`), at the run's mean "
                                           "wind speed."))
    def build(self, dm) -> dict:
        if self.lpv:
            if self._lpv is None:
                self._lpv = lpv_turbine(self.model, self.ts, self.horizon, wind_speeds=self.wind_speeds)
            lpv = self._lpv
        else:
            lpv = lpv_turbine(self.model, self.ts, self.horizon, wind_speeds=[dm.wind_speed])
        scale = float(abs(dm.y0[dm.rows(["blade_root_my"])[0]]))
        # the discrete model's trim state: the plant's, plus the held command when the pitch feeds
        # through to an output (OpenFAST's linearisations: BldPitch1), as the LPV vertices have it
        return {"x_trim": np.asarray(dm.x0, float), "moment_scale": positive_scalar(scale, "trim blade moment"),
                "lpv": lpv}

    @docstring_of(SampledController, note="Each run's online blade damage starts at zero (its S-N curve: ``blade_m``, "
                                          "``del_budget``), its mean blade moment and speed reference at its trim.")
    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        super().start(dt, wind, pitch, torque)
        sn = SNCurve(m=self.blade_m, s_ref=self.del_budget if self.del_budget is not None else 1e6)
        self._run["damage"] = [StreamingDamage(sn) for _ in range(np.asarray(pitch).size)]
        self._run["dt"] = float(dt)
        mean = np.empty(np.asarray(pitch).size)
        for v, idx in self._run["groups"].items():
            mean[idx] = self._run["points"][v]["moment_scale"]
        self._run["mean_moment"] = mean
        self._run["speed_ref"] = np.full(mean.size, float(self.model.rated_rotor_speed))
        if self.lpv:
            z = np.empty((mean.size, self.observer().z_trim.shape[1]))
            for v, idx in self._run["groups"].items():
                z[idx] = np.append(self._run["points"][v]["x_trim"], v)
            self._run["zprior"] = z

    @property
    def blade_damage(self) -> np.ndarray:
        """(R,) online Miner damage D(k) of each run's blade moment since the simulation started
        (the discarded transient included; closed cycles; S_ref = ``del_budget``, or 1 MN·m
        without one)."""
        run = getattr(self, "_run", None)
        return np.array([] if run is None else [d.damage for d in run["damage"]])

    @docstring_of(SampledController, note="``y`` needs ``blade_root_my`` and ``gen_speed`` besides the measured "
                                          "outputs; a run with a NaN or inf in one of them also holds its damage count, "
                                          "mean moment and speed reference.")
    def __call__(self, t: float, y: dict) -> np.ndarray:
        run = getattr(self, "_run", None)
        if run is None:
            raise RuntimeError("HealthMPC.start(dt, wind, pitch, torque) must be called first "
                               "(specdesign.simulate.simulate does it)")
        k = run["k"]
        run["k"] = k + 1
        if k % run["every"]:
            return run["cmd"]
        # a run with a NaN/inf sample holds its command, damage count, mean moment, speed
        # reference and estimate (bad_measurements: the convention of every controller)
        signals = tuple(dict.fromkeys((*self.measured, "blade_root_my", "gen_speed")))
        ok = ~bad_measurements(y, signals, t, run["warned"], self.name)
        moment = np.asarray(y["blade_root_my"], float)
        for r, sd in enumerate(run["damage"]):
            if ok[r]:
                sd.update(moment[r])
        run["mean_moment"] += np.where(ok, min(self.ts / self.mean_time, 1.0) * (moment - run["mean_moment"]), 0.0)
        if self.speed_integral_time is not None:
            rated = float(self.model.rated_rotor_speed)
            ref = run["speed_ref"] - self.ts / self.speed_integral_time * (np.asarray(y["gen_speed"], float) - rated)
            # anti-windup at 5 % above rated; with a derating term never above rated: it must not
            # undo the derating asked for
            ref = np.minimum(ref, rated if self.weights[4] > 0 else (1.0 + REF_MARGIN) * rated)
            run["speed_ref"] = np.where(ok, ref, run["speed_ref"])
        elapsed = k * run["dt"]
        ym = np.stack([np.asarray(y[n], float) for n in self.measured], axis=1)
        model = self.model
        step = float(model.pitch_rate_limit) * self.ts
        limits = (float(model.pitch_min), float(model.pitch_max))
        for v, idx in run["groups"].items():
            idx = idx[ok[idx]]
            if not idx.size:
                continue
            pt = run["points"][v]
            Aa, Ba, Ca, L = pt["kf"]
            if self.lpv:  # the LPV observer, absolute (states, wind)
                zf = np.stack([self.observer().update(run["zprior"][r], ym[r]) for r in idx])
                xs, winds = zf[:, :-1], zf[:, -1]
            else:  # the fixed-point filter of SampledController, deviations from the run's trim
                xf = run["xprior"][idx] + (ym[idx] - run["y0"][v] - run["xprior"][idx] @ Ca.T) @ L.T
                xs, winds = pt["x_trim"] + xf[:, :-1], v + xf[:, -1]
            u = np.empty(idx.size)
            for g, r in enumerate(idx):
                t0 = time.process_time()
                psi = self.weights[3]
                if self.del_budget is not None and psi > 0:
                    psi *= health_scale(run["damage"][r].damage, elapsed, self.blade_m, self.budget_prior)
                if self._qp is None:
                    self._qp = health_qp(4 * self.horizon, self.horizon)
                beta0 = pt["model"].pitch0
                cmds = health_move(pt["lpv"], xs[g], winds[g], beta0, beta0 + run["u"][r], run["mean_moment"][r],
                                   weights=self.weights[:3] + (psi, self.weights[4]),
                                   rated_speed=float(model.rated_rotor_speed), step=step, pitch_limits=limits,
                                   moment_scale=pt["moment_scale"], speed_ref=run["speed_ref"][r],
                                   measured_moment=moment[r], qp=self._qp, solver=self.solver)
                u[g] = cmds[0] - beta0
                self.solve_times.append(time.process_time() - t0)
            run["u"][idx] = u
            if self.lpv:
                for g, r in enumerate(idx):
                    run["zprior"][r] = self.observer().predict(zf[g], pt["model"].pitch0 + u[g])
            else:
                run["xprior"][idx] = xf @ Aa.T + u[:, None] * Ba
        run["cmd"] = run["beta0"] + run["u"]
        return run["cmd"]


def health_aware_mpc(model, stress_weight: float = 30.0, **kw) -> HealthMPC:
    """Boutrous et al.'s health-aware LPV MPC: the accumulated-blade-moment term alone.

    The linear cost ψ_acc·Σ_j M_j/(N M_s) on the predicted blade moment (their Ψ_mb·M_b,acc,
    Eqs. 16-18) with the excursion penalty off (``health_weight`` = 0): the controller pitches
    more and derates, trading power for accumulated blade stress as the paper's Table 2 does
    (docs/health_mpc.md).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    stress_weight : float, default 30
        ψ_acc (dimensionless, > 0); 30 at 13 m/s derates 15.00 → 14.54 MW (docs/health_mpc.md).
    **kw
        Other options of :class:`HealthMPC` (not ``health_weight``).

    Returns
    -------
    HealthMPC
        Named "health-aware MPC" unless ``name`` is given.

    Raises
    ------
    ValueError
        For a ``stress_weight`` that is not > 0, or a ``health_weight`` given.
    """
    if "health_weight" in kw:
        raise ValueError("health_aware_mpc has no excursion penalty: use HealthMPC(health_weight=...) for it")
    stress_weight = positive_scalar(stress_weight, "stress_weight")
    kw.setdefault("name", "health-aware MPC")
    return HealthMPC(model, stress_weight=stress_weight, **kw)
