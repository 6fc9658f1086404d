"""Fatigue-oriented economic MPC (after Collet et al.): the variance-damage surrogate cost of Eq. (4),

    J̃_fat(y) = Σ_i π_i e^{b_i} / L_ult,i^{m_i} · Var(y_i)^{a_i},

with (a_i, b_i) fitted by :func:`specdesign.fatigue.fit_variance_damage` on load histories of
this turbine (:func:`fit_fatigue_terms`), minimised over the pitch commands of the linearised
turbine, open loop over a long horizon with the wind known (:func:`economic_open_loop`, the
"expert" of the paper) or receding-horizon with the wind estimated (:class:`EconomicMPC`).

Convexity: over the horizon the outputs are affine in the commands, y_i = c_i + G_i u, so
Var(y_i) = (1/N)‖P(c_i + G_i u)‖² (P removes the mean, Eq. 2) is a convex quadratic, ≥ 0;
t ↦ t^a is convex and nondecreasing on t ≥ 0 for a ≥ 1, so Var^a is convex (the composition
rule) and the problem is a convex cone program (cvxpy: ``power(·, a)`` as a power cone,
solved by Clarabel). For a < 1, t^a is concave and the composition is not convex in general:
the seed paper's exponents are ≥ 1 (2.19 at m = 4, 4.86 at m = 10; Gaussian loads give
a ≈ m/2), and a fitted a < 1 is refused (ValueError) rather than approximated.

The fatigue cost alone does not regulate the rotor (a constant offset has no variance), so
the objective adds the production side as the paper's tuning does, in the same normalised
units as :class:`~specdesign.mpc.QuadraticMPC`::

    J = J̃_fat(y) / J̃_ref + q_Ω · mean_j (Ω_j / Ω_rated)² + q_Δ · mean_j ((u_j − u_{j−1}) / (β̇_max T_s))²

J̃_ref is J̃_fat at the fitting records' mean variances (a constant: the argmin is that of
J̃_fat + J̃_ref·(…)), and the pitch position and rate limits are constraints.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .._checks import positive_scalar
from .._docs import docstring_of
from ..fatigue import (
    BLADE_M,
    TOWER_M,
    VarianceDamageFit,
    economic_cost,
    fit_variance_damage,
)
from ..simulate import simulate
from ..turbine import rosco_baseline
from ..wind import RECORD_LENGTH
from .base import MEASURED, DiscreteTurbine, discretize_turbine
from .sampled import SampledController

__all__ = ["solve_cone", "FatigueTerm", "fit_fatigue_terms", "fatigue_terms_from_records", "surrogate_cost", "economic_problem",
           "economic_open_loop", "OpenLoopResult", "EconomicMPC", "WOHLER"]

#: Wöhler exponents of the priced components: steel tower, glass-fibre blade root, and the
#: pitch angle (the pitch actuator's fatigue, m = 4 in Collet et al.'s Table 1).
WOHLER = {"tower_base_my": TOWER_M, "blade_root_my": BLADE_M, "pitch": 4.0}


def solve_cone(problem) -> bool:
    """Solve a compiled cvxpy cone problem by Clarabel, SCS if Clarabel fails numerically.

    Parameters
    ----------
    problem : cvxpy.Problem
        The problem, parameters set.

    Returns
    -------
    bool
        Whether an optimal (or optimal-inaccurate) solution was found.
    """
    import cvxpy as cp

    for solver, opts in (("CLARABEL", {}), ("SCS", {"eps_abs": 1e-7, "eps_rel": 1e-7, "max_iters": 20000})):
        try:
            # the SciPy canonicalisation backend: cvxpy 1.9's COO backend, which it picks for
            # long horizons (the open-loop optimum over a whole record), fails on a Parameter divided by a constant
            problem.solve(solver=solver, canon_backend="SCIPY", **opts)
        except cp.error.SolverError:
            continue  # Clarabel's rare numerical breakdowns on a far-off state: the first-order solver still converges
        if problem.status in ("optimal", "optimal_inaccurate"):
            return True
    return False


@dataclass(frozen=True)
class FatigueTerm:
    """One component of Eq. (4): output, price and its variance-damage fit.

    Parameters
    ----------
    output : str
        Model output (a load, SI).
    fit : VarianceDamageFit
        ln(L_ult^m D) = a ln Var + b, with m and L_ult.
    price : float
        π_i, currency per unit Miner damage (≥ 0).
    reference_variance : float
        Mean variance of the fitting records (load units²): the scale of the solver's variables.
    """

    output: str
    fit: VarianceDamageFit
    price: float
    reference_variance: float


def fit_fatigue_terms(model, wind_speed: float, window: float, *, seeds=(1, 2, 3), prices: dict | None = None,
                      ultimate: dict | None = None, classes=("A", "B", "C"), duration: float = RECORD_LENGTH,
                      outputs=None) -> tuple:
    """Fit the variance-damage surrogate of each priced load on simulated histories of this turbine.

    ROSCO's PI (:func:`specdesign.turbine.rosco_baseline`) runs at ``wind_speed`` on the IEC
    turbulence ``classes`` × ``seeds``; every record is cut into windows of ``window`` seconds
    (the horizon the cost is applied over: D is a damage per window) and
    :func:`specdesign.fatigue.fit_variance_damage` fits ln(L_ult^m D) = a ln Var + b on them
    (:func:`fatigue_terms_from_records`, which takes records made elsewhere, e.g. OpenFAST's).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    wind_speed : float
        Mean wind speed (m/s).
    window : float
        Record length of the fit (s), that of the optimisation horizon.
    seeds : sequence of int, optional
        Turbulence seeds per class.
    prices : dict, optional
        Output → π, currency per unit damage. Default: the tower base and, when the model has
        that output, the blade root, each priced 1/D_ref (D_ref its predicted damage at the
        fitting records' mean variance), so J̃_fat = Σ D_i/D_ref,i weighs each component's
        damage relative to ROSCO's and needs no ultimate loads. Each output needs a Wöhler
        exponent in :data:`WOHLER`.
    ultimate : dict, optional
        Output → L_ult (load units; default 1.0: only the ratios π_i/L_ult,i^{m_i} between
        priced components matter).
    classes : sequence of str, optional
        IEC turbulence classes (spread of variances for the fit).
    duration : float, optional
        Simulated time per run (s).
    outputs : sequence of str, optional
        The outputs to price relatively (π = 1/D_ref each) when ``prices`` is not given; default
        the tower base and the blade root.

    Returns
    -------
    tuple of FatigueTerm
        One per priced output.

    Raises
    ------
    ValueError
        For an output the model does not have, one without a Wöhler exponent, a window
        longer than half of ``duration`` or not a whole number of the records' samples.
    """
    window = positive_scalar(window, "window")
    duration = positive_scalar(duration, "duration")
    if window > duration / 2:
        raise ValueError(f"window={window} s must be at most half of duration={duration} s (two records per run)")
    names = tuple(model.output_names)
    if prices is not None:
        priced = list(prices)
    else:
        priced = [o for o in ("tower_base_my", "blade_root_my") if o in names] if outputs is None else list(outputs)
    for out in priced:
        if out not in names:
            raise ValueError(f"priced output {out!r} is not an output of the model {names}")
    _check_wohler(priced)
    runs = [simulate(model, rosco_baseline(model, wind_speed), [wind_speed], seeds=list(seeds), duration=duration,
                     turbulence_class=c) for c in classes]
    records = {out: [r[out][0, s] for r in runs for s in range(len(seeds))] for out in priced}
    return fatigue_terms_from_records(records, runs[0].dt, window, prices=prices, ultimate=ultimate)


def _check_wohler(names) -> None:
    for out in names:
        if out not in WOHLER:
            raise ValueError(f"priced output {out!r} has no Wöhler exponent; known: {WOHLER}")


def fatigue_terms_from_records(records, dt: float, window: float, *, prices: dict | None = None,
                               ultimate: dict | None = None) -> tuple:
    """Fit the variance-damage surrogate of each priced load on given load histories.

    Every record is cut into consecutive windows of ``window`` seconds (a remainder shorter
    than a window is left out) and :func:`specdesign.fatigue.fit_variance_damage` fits
    ln(L_ult^m D) = a ln Var + b on the windows. :func:`fit_fatigue_terms` makes its records by
    simulating ROSCO on the reduced model; this takes any, e.g. ROSCO's records in OpenFAST.

    Parameters
    ----------
    records : dict
        Output → sequence of 1-D load histories (load units, SI) sampled every ``dt``; the
        outputs priced. Each output needs a Wöhler exponent in :data:`WOHLER`.
    dt : float
        Sample interval of the records (s).
    window : float
        Window of the fit (s), that of the optimisation horizon; a whole number of samples
        (to 1e-9 relative).
    prices : dict, optional
        Output → π, currency per unit damage, for every output of ``records``. Default: each
        priced 1/D_ref (D_ref its predicted damage at the windows' mean variance), so J̃_fat =
        Σ D_i/D_ref,i weighs each component's damage relative to the records'.
    ultimate : dict, optional
        Output → L_ult (load units; default 1.0).

    Returns
    -------
    tuple of FatigueTerm
        One per output of ``records``, in its order.

    Raises
    ------
    ValueError
        Empty ``records``, an output without a Wöhler exponent, a record that is not 1-D and
        finite, ``prices`` not naming exactly the recorded outputs, a window that is not a whole
        number of samples, fewer than two windows, or a fitted exponent a < 1 (Var^a not
        convex: module docstring).
    """
    dt, window = positive_scalar(dt, "dt"), positive_scalar(window, "window")
    records = dict(records)
    if not records:
        raise ValueError("records is empty: pass {output: [load history, ...]} for the outputs to price")
    _check_wohler(records)
    if prices is not None and set(prices) != set(records):
        raise ValueError(f"prices names {sorted(prices)}, records {sorted(records)}: price exactly the recorded outputs")
    n = round(window / dt)
    if n < 2 or abs(n * dt - window) > 1e-9 * window:
        raise ValueError(f"window={window} s is not a whole number (>= 2) of samples of dt={dt} s")
    ultimate = {} if ultimate is None else dict(ultimate)
    terms = []
    for out, histories in records.items():
        recs = []
        for k, x in enumerate(histories):
            x = np.asarray(x, float)
            if x.ndim != 1 or not np.all(np.isfinite(x)):
                raise ValueError(f"records[{out!r}][{k}] must be a 1-D finite history, got shape {x.shape}")
            recs += [x[i:i + n] for i in range(0, x.size - n + 1, n)]
        if len(recs) < 2:
            raise ValueError(f"records[{out!r}] holds {len(recs)} window(s) of {window} s: at least two are needed")
        fit = fit_variance_damage(recs, WOHLER[out], ultimate=float(ultimate.get(out, 1.0)))
        if fit.a < 1:
            raise ValueError(f"the fitted exponent a={fit.a:.3f} of {out!r} is below 1: Var^a is not convex "
                             "(module docstring); fit on more varied records or another window")
        ref = float(np.mean([np.var(x) for x in recs]))
        terms.append(FatigueTerm(out, fit, 1.0 / float(fit.predict(ref)) if prices is None else float(prices[out]), ref))
    return tuple(terms)


def surrogate_cost(terms, series: dict) -> np.ndarray:
    """J̃_fat of Eq. (4) for load histories: Σ_i π_i e^{b_i}/L_ult^{m_i} · Var(y_i)^{a_i}.

    Parameters
    ----------
    terms : sequence of FatigueTerm
        The priced components.
    series : dict
        Output → (..., n) histories (load units); the variance is over the last axis (Eq. 2).

    Returns
    -------
    numpy.ndarray
        (...) cost, currency (:func:`specdesign.fatigue.economic_cost` of the predicted damages).

    Raises
    ------
    ValueError
        For a term whose output is not in ``series``.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.fatigue import VarianceDamageFit
    >>> t = FatigueTerm("tower_base_my", VarianceDamageFit(2.0, 1.0, 4.0, 1.0, 0.0), 3.0, 1.0)
    >>> y = np.array([0.0, 2.0, 0.0, 2.0])  # variance 1
    >>> float(surrogate_cost([t], {"tower_base_my": y}))  # 3 e^1 · 1^2
    8.154845485377136
    """
    missing = [t.output for t in terms if t.output not in series]
    if missing:
        raise ValueError(f"series has no history of the priced outputs {missing}")
    damages = np.stack([t.fit.predict(np.var(np.asarray(series[t.output], float), axis=-1)) for t in terms], axis=-1)
    return economic_cost(damages, [t.price for t in terms])


def economic_problem(dm: DiscreteTurbine, terms, horizon: int, *, speed_weight: float, activity_weight: float,
                     rated_speed: float, rate_limit: float, pitch_limits: tuple[float, float]) -> dict:
    """The convex problem of the module docstring over ``horizon`` steps, compiled once (cvxpy, DPP).

    Parameters
    ----------
    dm : DiscreteTurbine
        The discrete model.
    terms : sequence of FatigueTerm
        Priced loads (outputs of ``dm``).
    horizon : int
        N steps.
    speed_weight, activity_weight : float
        q_Ω and q_Δ (≥ 0).
    rated_speed : float
        Ω_rated (rad/s).
    rate_limit : float
        β̇_max (rad/s).
    pitch_limits : tuple of float
        (β_min, β_max) absolute pitch (rad).

    Returns
    -------
    dict
        ``problem``; parameters ``x0`` (n,), ``d`` (N,) wind deviations (m/s) and ``uprev``
        (1,); variables ``v`` (N,) commands in units of the largest move ``step`` (rad) and ``x``
        (n, N+1) states; ``scale`` (J̃_ref) and ``step``; ``parts`` the objective's three terms
        (``"fatigue"`` J̃_fat/J̃_ref, ``"speed"``, ``"activity"``: cvxpy expressions whose values
        after a solve are the terms' shares, ``EconomicMPC.term_values``).

    Raises
    ------
    ValueError
        For a negative weight, a term with a < 1 or an output ``dm`` does not have.
    """
    import cvxpy as cp

    if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 2:
        raise ValueError(f"horizon={horizon!r} must be an integer number of steps >= 2 (a variance needs two)")
    if not (speed_weight >= 0 and activity_weight >= 0):
        raise ValueError(f"speed_weight={speed_weight!r} and activity_weight={activity_weight!r} must be >= 0")
    N, n = int(horizon), dm.A.shape[0]
    step = float(rate_limit) * dm.ts
    x0, d, uprev = cp.Parameter(n, name="x0"), cp.Parameter(N, name="d"), cp.Parameter(1, name="uprev")
    v = cp.Variable(N, name="v")
    # states in units of their typical deviations (O(1) numbers for the interior-point solver)
    sx = np.abs(np.array([0.01 * rated_speed, 0.1, 0.1, 0.02, 0.02] if n == 5 else np.ones(n)))
    A, Bu, Bw = dm.A * (1 / sx)[:, None] * sx, dm.Bu * step / sx, dm.Bw / sx
    xi = cp.Variable((n, N + 1), name="xi")
    x = cp.multiply(sx[:, None], xi)
    cons = [xi[:, 0] == cp.multiply(1 / sx, x0),
            xi[:, 1:] == A @ xi[:, :-1] + Bu[:, None] @ cp.reshape(v, (1, N), order="C")
            + Bw[:, None] @ cp.reshape(d, (1, N), order="C")]
    dv = cp.hstack([v[:1] - uprev / step, cp.diff(v)])
    cons += [v >= (pitch_limits[0] - dm.pitch0) / step, v <= (pitch_limits[1] - dm.pitch0) / step, cp.abs(dv) <= 1.0]
    scale = float(sum(t.price * t.fit.predict(t.reference_variance) for t in terms))
    fatigue = 0
    for t in terms:
        if t.fit.a < 1:
            raise ValueError(f"term {t.output!r} has a={t.fit.a:.3f} < 1: Var^a is not convex (module docstring)")
        r = dm.rows([t.output])[0]
        y = (dm.C[r] @ x[:, 1:] + dm.Dw[r] * d) / np.sqrt(t.reference_variance)  # O(1) numbers
        # a (1,) vector: cvxpy's exact power cone refuses a scalar argument (shape mismatch)
        var = cp.reshape(cp.sum_squares(y - cp.sum(y) / N) / N, (1,), order="C")  # Var(y) / Var_ref (Eq. 2)
        # π e^b Var^a / L^m = (π D(Var_ref)) · (Var/Var_ref)^a, divided by J̃_ref
        weight = t.price * float(t.fit.predict(t.reference_variance)) / scale
        fatigue = fatigue + weight * cp.sum(cp.power(var, t.fit.a, approx=False))
    w = dm.rows(["gen_speed"])[0]
    speed = cp.sum_squares((dm.C[w] @ x[:, 1:]) / rated_speed) / N
    parts = {"fatigue": fatigue, "speed": float(speed_weight) * speed,
             "activity": float(activity_weight) * cp.sum_squares(dv) / N}
    problem = cp.Problem(cp.Minimize(parts["fatigue"] + parts["speed"] + parts["activity"]), cons)
    return {"problem": problem, "x0": x0, "d": d, "uprev": uprev, "v": v, "x": x, "scale": scale, "step": step,
            "parts": parts}


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class OpenLoopResult:
    """The long-horizon optimum on the linear model (the expert of Collet et al.'s behavioural cloning).

    Parameters
    ----------
    time : numpy.ndarray
        (N,) sample times (s).
    wind : numpy.ndarray
        (N,) wind held over each sample (m/s).
    pitch_cmd : numpy.ndarray
        (N,) optimal absolute pitch commands (rad).
    states : numpy.ndarray
        (N+1, n) linear-model states (deviations; row k before command k).
    outputs : dict
        Output name → (N,) absolute outputs after each command (SI): the trim plus the linear
        model's deviations.
    cost : float
        Optimal objective (normalised, module docstring).
    surrogate : float
        J̃_fat of the optimal outputs (Eq. 4, currency).
    cpu_time : float
        CPU time of the solve (s), compilation included.
    """

    time: np.ndarray
    wind: np.ndarray
    pitch_cmd: np.ndarray
    states: np.ndarray
    outputs: dict
    cost: float
    surrogate: float
    cpu_time: float


def economic_open_loop(model, wind_speed: float, wind, wind_dt: float, terms, *, ts: float = 0.2,
                       speed_weight: float = 100.0, activity_weight: float = 1.0, dm: DiscreteTurbine | None = None,
                       problem: dict | None = None) -> OpenLoopResult:
    """Minimise the economic cost over the whole wind record, open loop, wind known (Collet et al., Eq. 14).

    Starts at the trim of ``wind_speed``; the wind is sampled at ``ts`` and held over each
    sample (zero-order hold, as the discrete model assumes).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    wind_speed : float
        Mean wind speed of the trim (m/s).
    wind : array_like
        (n_w,) rotor-effective wind (m/s) every ``wind_dt``; its length sets the horizon.
    wind_dt : float
        Wind sample spacing (s); ``ts`` must be a whole multiple of it.
    terms : sequence of FatigueTerm
        Priced loads (:func:`fit_fatigue_terms`).
    ts : float, default 0.2
        Sample time (s).
    speed_weight, activity_weight : float
        q_Ω and q_Δ of the module docstring (defaults 100 and 1).
    dm : DiscreteTurbine, optional
        The discrete model, if already built (:func:`~specdesign.mpc.discretize_turbine`).
    problem : dict, optional
        A compiled :func:`economic_problem` of the same horizon, to re-solve on another wind
        without recompiling.

    Returns
    -------
    OpenLoopResult
        The optimal commands and trajectories.

    Raises
    ------
    ValueError
        For a ``ts`` that is not a whole multiple of ``wind_dt``, or a wind record of fewer
        than two samples at ``ts``.
    RuntimeError
        If the solver does not find the optimum.
    """
    t0 = time.process_time()
    ts, wind_dt = positive_scalar(ts, "ts"), positive_scalar(wind_dt, "wind_dt")
    every = int(round(ts / wind_dt))
    if every < 1 or abs(every * wind_dt - ts) > 1e-9 * ts:
        raise ValueError(f"ts={ts} s must be a whole multiple of wind_dt={wind_dt} s")
    w = np.asarray(wind, float)
    if w.ndim != 1 or not np.all(np.isfinite(w)):
        raise ValueError("wind must be a finite 1-D record (m/s)")
    w = w[::every]
    N = w.size - 1  # the state after the last command is the record's last sample
    if N < 2:
        raise ValueError(f"wind covers {N} samples at ts={ts} s; a horizon needs at least 2")
    dm = discretize_turbine(model, wind_speed, ts) if dm is None else dm
    if problem is None:
        problem = economic_problem(dm, terms, N, speed_weight=speed_weight, activity_weight=activity_weight,
                                   rated_speed=float(model.rated_rotor_speed), rate_limit=float(model.pitch_rate_limit),
                                   pitch_limits=(float(model.pitch_min), float(model.pitch_max)))
    problem["x0"].value = np.zeros(dm.A.shape[0])
    problem["d"].value = w[:N] - dm.wind_speed
    problem["uprev"].value = np.zeros(1)
    if not solve_cone(problem["problem"]):
        raise RuntimeError(f"the economic open-loop problem is {problem['problem'].status}")
    u = np.asarray(problem["v"].value, float) * problem["step"]
    X = np.asarray(problem["x"].value, float).T
    Y = X[1:] @ dm.C.T + np.outer(w[:N] - dm.wind_speed, dm.Dw) + dm.y0
    outs = {name: Y[:, i] for i, name in enumerate(dm.output_names)}
    return OpenLoopResult(np.arange(N) * ts, w[:N], dm.pitch0 + u, X, outs, float(problem["problem"].value),
                          float(surrogate_cost(terms, outs)), time.process_time() - t0)


class EconomicMPC(SampledController):
    """Receding-horizon economic fatigue MPC: the problem of :func:`economic_problem` every sample.

    The wind over the horizon is the Kalman estimate d̂ held constant (no preview), the start
    the estimated state; the first move is applied. One cone program per run per sample
    (Clarabel): slower than :class:`~specdesign.mpc.QuadraticMPC` (see ``solve_times``).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    terms : sequence of FatigueTerm
        Priced loads (:func:`fit_fatigue_terms`).
    ts : float, default 0.2
        Sample time (s).
    horizon : int, default 50
        N steps (10 s at 0.2 s, the short end of the paper's 10-100 s).
    speed_weight, activity_weight : float
        q_Ω and q_Δ (defaults 100 and 1, as :func:`economic_open_loop`).
    measured : sequence of str, optional
        Outputs the Kalman filter reads.
    name : str, default "economic MPC"
        Label.
    operating_point, wind_speeds : str, array_like
        As :class:`~specdesign.mpc.sampled.SampledController` takes them.
    sensors : specdesign.simulate.SensorNoise, optional
        The sensors the runs read through, whose noise the Kalman filter assumes, as
        :class:`~specdesign.mpc.sampled.SampledController` takes them (default: none, the
        filter's own tuning).

    Attributes
    ----------
    solve_times : list of float
        CPU time (s) per solve.
    term_values : list of tuple
        (fatigue, speed, activity) values of the objective's terms at every solve's optimum
        (module docstring), since the last pickle: how much of the objective is Eq. 4's term.
    """

    def __init__(self, model, terms, ts: float = 0.2, horizon: int = 50, *, speed_weight: float = 100.0,
                 activity_weight: float = 1.0, measured=MEASURED, name: str = "economic MPC",
                 operating_point: str = "estimated", wind_speeds=None, sensors=None):
        self.terms = tuple(terms)
        if not self.terms or not all(isinstance(t, FatigueTerm) for t in self.terms):
            raise TypeError("terms must be a non-empty sequence of FatigueTerm (fit_fatigue_terms)")
        if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 2:
            raise ValueError(f"horizon={horizon!r} must be an integer number of steps >= 2")
        self.horizon = int(horizon)
        self.speed_weight, self.activity_weight = float(speed_weight), float(activity_weight)
        super().__init__(model, ts, measured, name, operating_point=operating_point, wind_speeds=wind_speeds,
                         sensors=sensors)

    def _reset_caches(self):
        super()._reset_caches()
        self.term_values = []

    def __getstate__(self):
        state = super().__getstate__()
        state.pop("term_values", None)
        return state

    @docstring_of(SampledController, note='Here the compiled problem of :func:`economic_problem`, under ``"problem"``.')
    def build(self, dm: DiscreteTurbine) -> dict:
        return {"problem": economic_problem(dm, self.terms, self.horizon, speed_weight=self.speed_weight,
                                            activity_weight=self.activity_weight,
                                            rated_speed=float(self.model.rated_rotor_speed),
                                            rate_limit=float(self.model.pitch_rate_limit),
                                            pitch_limits=(float(self.model.pitch_min), float(self.model.pitch_max)))}

    @docstring_of(SampledController)
    def policy(self, pt: dict, xhat: np.ndarray, uprev: np.ndarray) -> np.ndarray:
        # the first move of the economic problem of every run (RuntimeError if the solver fails)
        pb = pt["problem"]
        out = np.empty(uprev.size)
        for g in range(uprev.size):
            t0 = time.process_time()
            pb["x0"].value = xhat[g, :-1]
            pb["d"].value = np.full(self.horizon, xhat[g, -1])
            pb["uprev"].value = np.array([uprev[g]])
            if not solve_cone(pb["problem"]):
                raise RuntimeError(f"{self.name}: the economic problem is {pb['problem'].status}")
            step = pb["step"]
            # the interior-point solution sits a hair inside the bounds; the applied move is
            # the first one, within the actuator's limits to rounding
            out[g] = min(max(float(pb["v"].value[0]) * step, uprev[g] - step), uprev[g] + step)
            self.solve_times.append(time.process_time() - t0)
            self.term_values.append(tuple(float(pb["parts"][k].value) for k in ("fatigue", "speed", "activity")))
        return out
