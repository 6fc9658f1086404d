"""Collet et al.'s methods as their paper defines them, adapted to collective pitch: the
parametrised quadratic MPC with wind preview (its Eqs. 10-12), ρ chosen by its Eq. 13, and the
behavioural clone of the long-horizon *preview* optimum (Eqs. 14-22).

The paper's stage is individual pitch: outputs ỹ = [M_yaw, M_tilt, θ_yaw, θ_tilt] (the yaw and
tilt blade-root moments and pitch angles), Q(ρ) = diag(ρI₂, I₂), R = εI₂ with
ε = min(ρ, 1)·10⁻³ (Eq. 12), T_s = 0.1 s, N_MPC = 20, the future wind known, unconstrained
(Eq. 11), the collective loop (which regulates the rotor speed) left as it is. The reduced
model here has one collective pitch and one collective blade moment, and that pitch is also
the loop that regulates the rotor speed, so the collective version (:func:`collet_qp`) is::

    J = Σ_{k=1..N} [ ρ (δM_k/M̄)² + δβ_k² + q_Ω (δΩ_k/Ω_rated)² ] + ε Σ_{k=0..N−1} u_k²

δM the blade-root flapwise moment (N·m) about its trim M̄, δβ the pitch (rad), δΩ the rotor
speed (rad/s), u the pitch setpoint (rad), all deviations from the design point's trim. The
speed term is the one addition (fixed q_Ω = 100, the project's quadratic MPC's speed weight):
without it nothing holds the rotor at rated. Moments are in units of M̄ so that ρ is a pure
number (the paper's kN·m and its ρ = 5 × 10⁻² do not carry over to a 15 MW rotor).

Setting (the paper's): one design point (its 12 m/s, here ``design_speed``), the plant's
linearisation there known exactly and the wind known over the horizon (a perfect LiDAR). The
controllers do not read the run's wind speed: their operating point is the design point they
are built for (``operating_point="design point"`` of
:class:`~specdesign.mpc.sampled.SampledController`).

Eq. 13: ρ = argmin E[J_fat(ρ, x₀, v)] over winds, J_fat = Σ_i π_i D(y_i) (Eq. 1) the rainflow
Miner damage of the closed loop's outputs (:func:`fatigue_cost`), the components those of the
paper's Table 1 that exist here, the blade-root moment (m = 10) and the pitch (m = 4), priced
as :func:`~specdesign.mpc.fit_fatigue_terms` prices them (π_i = 1/D_ref,i) so that the same
prices serve the expert's surrogate (Eq. 4) and Eq. 1. :func:`tune_rho` evaluates it on a grid
of ρ (the paper: 100 winds).

The clone (:func:`preview_demonstrations`, :class:`PreviewClone`): the expert is the open-loop
optimum of the surrogate over the whole wind record from the trim (Eq. 14,
:func:`~specdesign.mpc.economic_open_loop`, with the same speed term and no move penalty); its
features are the last M_x samples of the outputs, setpoints and wind (Eq. 15) and the wind
over the next N_MPC steps (Eq. 16), its target the optimal setpoint (Eq. 17), sampled along the
optimal trajectories (no DAgger: the paper's procedure); the regressor is the paper's linear
stage plus gradient-boosted trees (:class:`~specdesign.mpc.CloningRegressor`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .._checks import positive_scalar
from .._docs import docstring_of
from ..fatigue import rainflow
from ..simulate import simulate
from .base import (
    MEASURED,
    DiscreteTurbine,
    discretize_turbine,
    prediction_matrices,
    steps_per_sample,
    within_limits,
)
from .cloning import CloningRegressor, Demonstrations
from .economic import economic_open_loop, economic_problem
from .quadratic import QuadraticMPC, preview_matrix
from .sampled import SampledController

__all__ = ["COLLET_OUTPUTS", "collet_qp", "ColletMPC", "fatigue_cost", "RhoTuning", "tune_rho",
           "preview_features", "preview_demonstrations", "PreviewClone"]

#: Outputs of the collective quadratic MPC's cost: blade-root moment (N·m), pitch (rad),
#: generator speed (rad/s) (module docstring).
COLLET_OUTPUTS = ("blade_root_my", "pitch", "gen_speed")


def collet_qp(dm: DiscreteTurbine, horizon: int, rho: float, *, speed_weight: float, rated_speed: float) -> dict:
    """The unconstrained preview QP of the collective Collet MPC (module docstring) at one design point.

    Parameters
    ----------
    dm : DiscreteTurbine
        The discrete model (its trim moment is M̄).
    horizon : int
        N steps (the paper's 20).
    rho : float
        ρ > 0, the weight of the blade moment.
    speed_weight : float
        q_Ω ≥ 0.
    rated_speed : float
        Ω_rated (rad/s).

    Returns
    -------
    dict
        ``H`` (N, N) and ``G`` (N, n + N) with J = ½uᵀHu + (G p)ᵀu + const for p = [x; d₀..d_{N−1}],
        ``K`` = −H⁻¹G (the minimiser u* = K p) and ``epsilon`` (ε of Eq. 12).

    Raises
    ------
    ValueError
        For ρ ≤ 0 or a negative speed weight.
    """
    rho = positive_scalar(rho, "rho")
    if not (np.isfinite(speed_weight) and speed_weight >= 0):
        raise ValueError(f"speed_weight={speed_weight!r} must be finite and >= 0")
    N = int(horizon)
    Phi, Gam, _ = prediction_matrices(dm, COLLET_OUTPUTS, N)
    Psi = preview_matrix(dm, COLLET_OUTPUTS, N)
    moment = abs(float(dm.y0[dm.rows(["blade_root_my"])[0]]))
    wz = np.tile([np.sqrt(rho) / positive_scalar(moment, "trim blade moment"), 1.0,
                  np.sqrt(speed_weight) / rated_speed], N)
    eps = min(rho, 1.0) * 1e-3
    Wg = wz[:, None] * Gam
    H = 2.0 * (Wg.T @ Wg + eps * np.eye(N))
    G = 2.0 * np.hstack([Wg.T @ (wz[:, None] * Phi), Wg.T @ (wz[:, None] * Psi)])
    return {"H": H, "G": G, "K": -np.linalg.solve(H, G), "epsilon": eps}


class ColletMPC(QuadraticMPC):
    """Collet et al.'s parametrised quadratic MPC, collective, with wind preview (module docstring).

    Unconstrained (the paper's Eq. 11): its first move is the minimiser's, then cut to the pitch
    rate and position limits (the actuator's; counted in ``saturated``).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    design_speed : float
        Wind speed of the design point (m/s): the linearisation it predicts with.
    preview : tuple
        ``(wind, wind_dt)`` as :class:`~specdesign.mpc.QuadraticMPC`'s: the runs' absolute wind
        (m/s) every ``wind_dt`` s from t = 0.
    rho : float, default 0.05
        ρ (choose it by :func:`tune_rho`; 0.05 is the paper's value, in its units).
    ts : float, default 0.1
        Sample time (s), the paper's.
    horizon : int, default 20
        N_MPC, the paper's.
    speed_weight : float, default 100
        q_Ω (module docstring).
    measured : sequence of str, optional
        Outputs the Kalman filter reads.
    name : str, default "Collet quadratic MPC"
        Label.

    Attributes
    ----------
    saturated : int
        First moves the actuator's limits cut since the last start.
    """

    def __init__(self, model, design_speed: float, preview, rho: float = 0.05, ts: float = 0.1, horizon: int = 20, *,
                 speed_weight: float = 100.0, measured=MEASURED, name: str = "Collet quadratic MPC"):
        if preview is None:
            raise TypeError("preview must be a tuple (wind array in m/s, wind_dt in s): the paper's MPC knows the wind")
        self.rho = positive_scalar(rho, "rho")
        self.speed_weight = float(speed_weight)
        self.saturated = 0
        super().__init__(model, ts, horizon, preview=preview, measured=measured, name=name,
                         operating_point="design point", design_speed=design_speed)

    @docstring_of(SampledController, note='Here the QP of :func:`collet_qp` at the design point, under ``"qp"``.')
    def build(self, dm: DiscreteTurbine) -> dict:
        return {"qp": collet_qp(dm, self.horizon, self.rho, speed_weight=self.speed_weight,
                                rated_speed=float(self.model.rated_rotor_speed))}

    @docstring_of(SampledController)
    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        # QuadraticMPC.start checks the preview's runs; the count of commands cut at the limits restarts
        self.saturated = 0
        super().start(dt, wind, pitch, torque)

    @docstring_of(SampledController)
    def policy(self, pt: dict, xhat: np.ndarray, uprev: np.ndarray) -> np.ndarray:
        # the unconstrained minimiser's first move, within the actuator's limits
        t0 = time.process_time()
        dw = self._horizon_wind(pt["model"], xhat)
        u = np.einsum("j,gj->g", pt["qp"]["K"][0], np.hstack([xhat[:, :-1], dw]))
        out = within_limits(self.model, self.ts, u, uprev, pt["model"].pitch0)
        self.saturated += int(np.count_nonzero(out != u))
        self.solve_times.extend([(time.process_time() - t0) / max(uprev.size, 1)] * uprev.size)
        return out


def fatigue_cost(terms, series: dict) -> np.ndarray:
    """J_fat of Collet et al.'s Eq. 1: Σ_i π_i D(y_i), D the rainflow Miner damage of each history.

    D is the damage :func:`~specdesign.fatigue.fit_variance_damage` fits (half cycles 0.5, the
    range-based curve N = (L_ult/S)^m), so J_fat and the surrogate J̃_fat (Eq. 4) share units.

    Parameters
    ----------
    terms : sequence of FatigueTerm
        Priced components (output, m, L_ult, π).
    series : dict
        Output → (..., n) histories (load units).

    Returns
    -------
    numpy.ndarray
        (...) cost (currency).

    Raises
    ------
    ValueError
        For a term whose output is not in ``series``.

    Examples
    --------
    >>> from specdesign.fatigue import VarianceDamageFit
    >>> from specdesign.mpc import FatigueTerm
    >>> t = FatigueTerm("pitch", VarianceDamageFit(2.0, 0.0, 4.0, 2.0, 0.0), 3.0, 1.0)
    >>> float(fatigue_cost([t], {"pitch": np.array([0.0, 2.0, 0.0])}))   # one cycle of range 2: 3·(2/2)⁴
    3.0
    """
    missing = [t.output for t in terms if t.output not in series]
    if missing:
        raise ValueError(f"series has no history of the priced outputs {missing}")
    out = 0.0
    for t in terms:
        y = np.asarray(series[t.output], float)
        flat = y.reshape(-1, y.shape[-1])
        d = np.empty(flat.shape[0])
        for i, rec in enumerate(flat):
            c = rainflow(rec)
            d[i] = float(np.sum(c.counts * (c.ranges / t.fit.ultimate) ** t.fit.m))
        out = out + t.price * d.reshape(y.shape[:-1])
    return np.asarray(out)


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class RhoTuning:
    """Eq. 13 on a grid: the mean closed-loop J_fat of each ρ.

    Parameters
    ----------
    rhos : numpy.ndarray
        (K,) the ρ tried.
    costs : numpy.ndarray
        (K, W) J_fat (Eq. 1) of each ρ on each tuning wind.
    rho : float
        The minimiser of the mean cost over the grid.
    """

    rhos: np.ndarray
    costs: np.ndarray
    rho: float


def tune_rho(model, design_speed: float, terms, wind, wind_dt: float, rhos, *, duration: float,
             transient: float = 0.0, linear: bool = True, **kw) -> RhoTuning:
    """ρ of Collet et al.'s Eq. 13: min_ρ E[J_fat(ρ, x₀, v)], on a grid of ρ and given winds.

    Each ρ's :class:`ColletMPC` runs in closed loop (``simulate``, the linearised turbine at
    ``design_speed`` by default: the paper's model-equal-plant setting) on every wind; J_fat is
    :func:`fatigue_cost` of the recorded outputs; E is the mean over the winds.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    design_speed : float
        Design and mean wind speed (m/s).
    terms : sequence of FatigueTerm
        The priced components of J_fat.
    wind : numpy.ndarray
        (W, n_w) tuning winds (m/s) every ``wind_dt`` s.
    wind_dt : float
        Their sample spacing (s).
    rhos : array_like
        Grid of ρ > 0.
    duration, transient : float
        Recorded time and discarded start of each run (s).
    linear : bool, default True
        The linearised plant (the paper's), or the reduced nonlinear model.
    **kw
        Other options of :class:`ColletMPC`.

    Returns
    -------
    RhoTuning
        The grid, its costs and the minimiser.

    Raises
    ------
    ValueError
        For an empty grid or a non-positive ρ.
    """
    rhos = np.atleast_1d(np.asarray(rhos, float))
    if rhos.size < 1 or np.any(~np.isfinite(rhos)) or np.any(rhos <= 0):
        raise ValueError(f"rhos={rhos!r} must be a non-empty grid of finite ρ > 0")
    w = np.atleast_2d(np.asarray(wind, float))
    costs = np.empty((rhos.size, w.shape[0]))
    for i, rho in enumerate(rhos):
        ctrl = ColletMPC(model, design_speed, (w, wind_dt), rho=float(rho), **kw)
        r = simulate(model, ctrl, [design_speed], wind=w[None], wind_dt=wind_dt, duration=duration,
                     transient=transient, linear=linear)
        costs[i] = fatigue_cost(terms, {t.output: r[t.output][0] for t in terms})
    return RhoTuning(rhos, costs, float(rhos[int(np.argmin(costs.mean(axis=1)))]))


def preview_features(outputs: np.ndarray, commands: np.ndarray, wind: np.ndarray, k: int, *, history: int,
                     horizon: int) -> np.ndarray:
    """Features (X_{k−1}, V_k) of Collet et al.'s Eqs. 15-16 at sample k.

    Parameters
    ----------
    outputs : numpy.ndarray
        (T, q) output deviations at samples 0..T−1 (SI).
    commands : numpy.ndarray
        (T,) setpoint deviations (rad); command j is applied over sample j.
    wind : numpy.ndarray
        (≥ k + horizon + 1,) wind deviations (m/s) per sample.
    k : int
        The sample whose command is wanted (k ≥ ``history``).
    history : int
        M_x: the outputs measured at the starts of samples k−M_x+1..k (the last one is the
        measurement the command is computed from), the commands and wind of samples k−M_x..k−1.
    horizon : int
        N_MPC: the wind of samples k..k+N_MPC.

    Returns
    -------
    numpy.ndarray
        (history·(q + 2) + horizon + 1,) [outputs, commands, wind of the past M_x samples; the
        wind of the next N_MPC + 1]; the last past command is at index ``history·q + history − 1``.
    """
    past = slice(k - history, k)
    return np.concatenate([outputs[k - history + 1:k + 1].ravel(), commands[past], wind[past],
                           wind[k:k + horizon + 1]])


def preview_demonstrations(model, design_speed: float, terms, wind, wind_dt: float, *, ts: float = 0.1,
                           history: int = 10, horizon: int = 20, samples: int = 300, speed_weight: float = 100.0,
                           seed: int = 0) -> Demonstrations:
    """The expert's demonstrations: open-loop optima over whole records, sampled (Eqs. 14-18).

    Parameters
    ----------
    model, design_speed : TurbineModel, float
        The turbine and its design (and mean) wind speed, m/s, about whose trim the expert optimises.
    terms : sequence of FatigueTerm
        The surrogate's priced components (Eq. 4).
    wind : numpy.ndarray
        (W, n_w) wind records (m/s) every ``wind_dt`` s; the whole record is the expert's horizon.
    wind_dt : float
        Their spacing (s); ``ts`` a whole multiple of it.
    ts : float, default 0.1
        Sample time (s).
    history, horizon : int
        M_x and N_MPC of :func:`preview_features`.
    samples : int, default 300
        Instants drawn per optimal trajectory (the paper's 300).
    speed_weight : float, default 100
        q_Ω of the expert's speed term (module docstring).
    seed : int, default 0
        Seed of the drawn instants.

    Returns
    -------
    Demonstrations
        Features of :func:`preview_features`, targets the optimal setpoint deviations (rad),
        ``seeds`` the record's index, ``cpu_time`` one entry per optimum.
    """
    rng = np.random.default_rng(seed)
    dm = discretize_turbine(model, design_speed, ts)
    every = int(round(ts / wind_dt))
    rows = dm.rows(COLLET_OUTPUTS)
    wind = np.atleast_2d(np.asarray(wind, float))
    # every record has the same length, so one compiled problem serves them all
    problem = economic_problem(dm, terms, wind[0, ::every].size - 1, speed_weight=speed_weight, activity_weight=0.0,
                               rated_speed=float(model.rated_rotor_speed), rate_limit=float(model.pitch_rate_limit),
                               pitch_limits=(float(model.pitch_min), float(model.pitch_max)))
    feats, targs, which, cpu = [], [], [], []
    for i, w in enumerate(wind):
        res = economic_open_loop(model, design_speed, w, wind_dt, terms, ts=ts, speed_weight=speed_weight,
                                 activity_weight=0.0, dm=dm, problem=problem)
        cpu.append(res.cpu_time)
        N = res.pitch_cmd.size
        # outputs after command j are those seen at the start of sample j + 1
        y = np.vstack([np.zeros(len(rows)), np.column_stack([res.outputs[n] for n in COLLET_OUTPUTS])
                       - dm.y0[rows]])[:N]
        u = res.pitch_cmd - dm.pitch0
        d = w[::every] - design_speed
        last = N - horizon - 1
        ks = rng.choice(np.arange(history, last), size=min(samples, last - history), replace=False)  # Eq. 18's draws
        for k in ks:
            feats.append(preview_features(y, u, d, int(k), history=history, horizon=horizon))
            targs.append(u[k])
            which.append(i)
    return Demonstrations(np.array(feats), np.array(targs), np.array(which), ts, np.array(cpu))


class PreviewClone:
    """The clone of the preview optimum as a controller of ``simulate`` (module docstring).

    Keeps the last M_x samples of the measured outputs, its setpoints and the wind, reads the
    next N_MPC + 1 wind samples from the preview, and applies the regressor's setpoint within
    the pitch rate and position limits (``saturated`` counts the cuts).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    design_speed : float
        Design wind speed (m/s): deviations are about its trim.
    regressor : CloningRegressor
        Fitted on :func:`preview_demonstrations` (``uprev_column`` the last past command).
    preview : tuple
        ``(wind, wind_dt)`` as :class:`ColletMPC`'s.
    ts : float, default 0.1
        Sample time (s).
    history, horizon : int
        M_x and N_MPC of the features.
    name : str, default "clone of the preview optimum"
        Label.

    Attributes
    ----------
    solve_times : list of float
        CPU time (s) per sample and run.
    saturated : int
        Setpoints the actuator's limits cut since the last start.
    """

    def __init__(self, model, design_speed: float, regressor: CloningRegressor, preview, ts: float = 0.1,
                 history: int = 10, horizon: int = 20, name: str = "clone of the preview optimum"):
        if not isinstance(regressor, CloningRegressor) or regressor.linear is None:
            raise TypeError("regressor must be a fitted CloningRegressor")
        self.model, self.regressor = model, regressor
        self.ts, self.history, self.horizon = positive_scalar(ts, "ts"), int(history), int(horizon)
        w, wdt = preview
        self.wind = np.atleast_2d(np.asarray(w, float).reshape(-1, np.shape(w)[-1]))
        self.wind_dt = positive_scalar(wdt, "preview wind_dt")
        self.dm = discretize_turbine(model, float(design_speed), self.ts)
        self.design_speed = float(design_speed)
        self.__name__ = self.name = str(name)
        self.solve_times, self.saturated = [], 0

    def start(self, dt: float, wind, pitch, torque) -> None:
        """Reset the buffers (called by the simulator).

        Parameters
        ----------
        dt : float
            Simulation step (s); ``ts`` a whole multiple of it.
        wind, pitch, torque : array_like
            (R,) per run at t = 0.

        Raises
        ------
        ValueError
            For another number of runs than the preview's, or ``ts`` not a multiple of ``dt``.
        """
        R = np.size(pitch)
        if R != self.wind.shape[0]:
            raise ValueError(f"preview has {self.wind.shape[0]} runs but the simulation has {R}")
        self._every = steps_per_sample(self.ts, dt)
        M, q = self.history, len(COLLET_OUTPUTS)
        self._k = 0
        self._y = np.zeros((R, M, q))
        self._u = np.zeros((R, M))
        self._cmd = np.asarray(pitch, float).copy()
        self.saturated = 0

    def __call__(self, t: float, y: dict) -> np.ndarray:
        """(R,) absolute pitch setpoints (rad) of every run at time ``t`` (s), held between samples: the
        simulator's callable contract, as :meth:`specdesign.mpc.sampled.SampledController.__call__`."""
        k = self._k
        self._k += 1
        if k % self._every:
            return self._cmd
        t0 = time.process_time()
        dm, M, N = self.dm, self.history, self.horizon
        rows = dm.rows(COLLET_OUTPUTS)
        yk = np.column_stack([np.asarray(y[n], float) for n in COLLET_OUTPUTS]) - dm.y0[rows]
        grid = np.arange(self.wind.shape[1]) * self.wind_dt
        times = t + self.ts * np.arange(-M, N + 1)
        d = np.stack([np.interp(times, grid, w) for w in self.wind]) - self.design_speed
        # X_{k−1}: the outputs seen at the starts of samples k−M+1..k stand for those after
        # commands k−M..k−1 (as in the demonstrations); the wind past and to come
        self._y = np.concatenate([self._y[:, 1:], yk[:, None]], axis=1)
        X = np.hstack([self._y.reshape(len(yk), -1), self._u, d])
        u = self.regressor.predict(X)
        out = within_limits(self.model, self.ts, u, self._cmd - dm.pitch0, dm.pitch0)
        self.saturated += int(np.count_nonzero(out != u))
        self._u = np.concatenate([self._u[:, 1:], out[:, None]], axis=1)
        self._cmd = dm.pitch0 + out
        self.solve_times.extend([(time.process_time() - t0) / len(out)] * len(out))
        return self._cmd
