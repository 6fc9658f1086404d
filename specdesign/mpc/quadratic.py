"""Quadratic (tracking) MPC on the linearised turbine: the "finely tuned quadratic MPC" baseline
of Collet et al.'s behavioural-cloning paper.

At every sample k, from the Kalman estimate (x̂, d̂) of :mod:`specdesign.mpc.base` and the
previous command u₋₁ (all deviations from the trim), solve over N steps::

    min_u  Σ_{j=1..N} [ q_Ω (Ω_j / Ω_rated)² + q_T (ẋ_top,j / 1 m/s)² ]
           + q_Δ Σ_{j=0..N−1} ((u_j − u_{j−1}) / (β̇_max T_s))²
    s.t.   z = Φ x̂ + Γ u + Ψ d̂                       (prediction, wind held at d̂)
           β_min − β₀ ≤ u_j ≤ β_max − β₀              (pitch position)
           |u_j − u_{j−1}| ≤ β̇_max T_s                (pitch rate)

and apply u₀ (receding horizon, zero-order hold over T_s). The speed error is made
dimensionless by Ω_rated, the tower-top velocity by 1 m/s and the pitch move by the largest
move the rate limit allows, so the weights q are comparable numbers.

The QP is a cvxpy problem with Parameters (x̂, d̂, u₋₁), compiled once per operating point
(DPP) and solved by OSQP (warm-started). The unconstrained minimiser is linear in the
parameters, u* = K [x̂; d̂; u₋₁]; when it satisfies every constraint it *is* the QP's solution
(the QP is strictly convex), so the controller uses it and calls the solver only when a
constraint is active (``shortcut=True``, exact; ``shortcut=False`` solves every step, for
timing the solver).
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from .._checks import positive_scalar
from .._docs import docstring_of
from ..closedloop.maps import state_space_response
from .base import MEASURED, DiscreteTurbine, discretize_turbine, prediction_matrices
from .sampled import SampledController

__all__ = ["QuadraticMPC", "quadratic_qp", "preview_matrix", "unconstrained_law", "loop_gain", "OSQP_OPTIONS"]

#: OSQP settings of the constrained QP: tolerances well under the 1e-6 relative accuracy the
#: first move needs, and solution polishing (an active-set refinement: exact active constraints).
OSQP_OPTIONS = {"eps_abs": 1e-9, "eps_rel": 1e-9, "polishing": True, "max_iter": 20000}


def preview_matrix(dm: DiscreteTurbine, outputs, horizon: int) -> np.ndarray:
    """Condensed response of ``outputs`` to a previewed wind sequence: z = … + Ψ [d₀ … d_{N−1}].

    The wind enters as the command does, through B_w (the same condensed matrix), plus the
    outputs' wind feedthrough D_w with the wind of the output's own step (the last held for
    the last step).

    Parameters
    ----------
    dm : DiscreteTurbine
        The discrete model.
    outputs : sequence of str
        The q outputs.
    horizon : int
        N steps.

    Returns
    -------
    numpy.ndarray
        (N·q, N) step-major as :func:`~specdesign.mpc.base.prediction_matrices`.
    """
    N = int(horizon)
    _, Psi, _ = prediction_matrices(dataclasses.replace(dm, Bu=dm.Bw), outputs, N)
    Dw, q = dm.Dw[dm.rows(outputs)], len(outputs)
    for j in range(N):  # feedthrough of the output at step j+1: the wind of that step
        Psi[j * q:(j + 1) * q, min(j + 1, N - 1)] += Dw
    return Psi


def quadratic_qp(dm: DiscreteTurbine, horizon: int, weights: tuple[float, float, float], rated_speed: float,
                 rate_limit: float, pitch_limits: tuple[float, float], preview: bool = False) -> dict:
    """The condensed QP of :class:`QuadraticMPC` at one operating point, as arrays and as cvxpy.

    Parameters
    ----------
    dm : DiscreteTurbine
        The discrete model.
    horizon : int
        N steps.
    weights : tuple of float
        (q_Ω, q_T, q_Δ) ≥ 0, dimensionless (module docstring).
    rated_speed : float
        Ω_rated (rad/s), the speed scale.
    rate_limit : float
        β̇_max (rad/s).
    pitch_limits : tuple of float
        (β_min, β_max) absolute pitch (rad).
    preview : bool, default False
        The wind deviation is a sequence d₀..d_{N−1} over the horizon (parameter ``d`` of
        shape (N,)) instead of one value held (shape (1,)); an output's wind feedthrough uses
        the wind of its step, the last held for the last step.

    Returns
    -------
    dict
        ``H`` (N, N) Hessian and ``G`` (N, n+n_d+1) with the cost ½uᵀHu + (G p)ᵀu for
        p = [x̂; d; u₋₁] (n_d = 1, or N with preview); ``K`` = −H⁻¹G (the unconstrained minimiser u* = K p); ``lower``,
        ``upper`` (N,) position bounds on u; ``step`` the largest move (rad); and the cvxpy
        ``problem`` with parameters ``x0``, ``d``, ``uprev`` and variable ``v`` = u/step.

    Raises
    ------
    ValueError
        For negative weights, or all of q_Δ zero with a singular Hessian.
    """
    import cvxpy as cp

    qw, qt, qd = (float(w) for w in weights)
    if min(qw, qt, qd) < 0 or not np.all(np.isfinite([qw, qt, qd])):
        raise ValueError(f"weights={weights!r} must be finite and >= 0 (speed, tower, pitch activity)")
    N = int(horizon)
    names = ("gen_speed", "tower_top_vel")
    Phi, Gam, Psi = prediction_matrices(dm, names, N)
    Psi = Psi[:, None]
    if preview:
        Psi = preview_matrix(dm, names, N)
    step = float(rate_limit) * dm.ts
    wz = np.tile([np.sqrt(qw) / rated_speed, np.sqrt(qt)], N)  # row scaling of z
    Dm = np.eye(N) - np.eye(N, k=-1)  # Δu = Dm u − e₁ u₋₁
    e1 = np.zeros(N)
    e1[0] = 1.0
    sd = np.sqrt(qd) / step
    # ½uᵀHu + (G p)ᵀu with p = [x0; d; uprev]
    Wg = wz[:, None] * Gam
    H = 2.0 * (Wg.T @ Wg + sd**2 * Dm.T @ Dm)
    G = 2.0 * np.hstack([Wg.T @ (wz[:, None] * Phi), Wg.T @ (wz[:, None] * Psi), -(sd**2) * (Dm.T @ e1)[:, None]])
    if np.linalg.cond(H) > 1e12:
        raise ValueError("the MPC Hessian is singular: give a positive pitch-activity weight")
    K = -np.linalg.solve(H, G)
    lower = np.full(N, pitch_limits[0] - dm.pitch0)
    upper = np.full(N, pitch_limits[1] - dm.pitch0)

    n = dm.A.shape[0]
    x0, d, uprev = cp.Parameter(n, name="x0"), cp.Parameter(Psi.shape[1], name="d"), cp.Parameter(1, name="uprev")
    # the variable is the command in units of the largest move (O(1) numbers: OSQP converges
    # in a few iterations; in radians the scaled cost spans 1e8 and it stalls)
    v = cp.Variable(N, name="v")
    z = Phi @ x0 + (Gam * step) @ v + Psi @ d
    dv = Dm @ v - e1[:, None] @ uprev / step
    cost = cp.sum_squares(cp.multiply(wz, z)) + qd * cp.sum_squares(dv)
    cons = [v >= lower / step, v <= upper / step, cp.abs(dv) <= 1.0]
    problem = cp.Problem(cp.Minimize(cost), cons)
    return {"H": H, "G": G, "K": K, "lower": lower, "upper": upper, "step": step, "problem": problem,
            "x0": x0, "d": d, "uprev": uprev, "v": v}


class QuadraticMPC(SampledController):
    """Quadratic MPC of the pitch on the linearised turbine, a callable controller for ``simulate``.

    See the module docstring for the problem, :mod:`specdesign.mpc.base` for the observer and
    the sampling. The generator torque stays at its trim (constant-torque region above rated).

    Parameters
    ----------
    model : TurbineModel
        The turbine (e.g. :func:`specdesign.turbine.iea15mw`).
    ts : float, default 0.1
        Sample time (s), a whole multiple of the simulation step.
    horizon : int, default 50
        Prediction horizon N (steps): 5 s at 0.1 s, close to the tower's period (5.9 s).
    speed_weight, tower_weight, activity_weight : float
        q_Ω, q_T, q_Δ of the module docstring (dimensionless, ≥ 0). Defaults (100, 100, 0.1) tuned on
        the IEA 15 MW at 19 m/s so the generator-speed SD is close to ROSCO's (docs/mpc.md).
    measured : sequence of str, optional
        Outputs the Kalman filter reads (default generator speed, tower-top acceleration, pitch).
    shortcut : bool, default True
        Use the unconstrained minimiser when it is feasible (exactly the QP's solution).
    solver : str, default "OSQP"
        cvxpy solver of the constrained QP.
    preview : tuple, optional
        ``(wind, wind_dt)``: rotor-effective wind known in advance (a perfect LiDAR, as seed
        000 assumes for its MPC): (R, n_w) or (W, S, n_w) absolute wind (m/s) of the runs
        every ``wind_dt`` s from the start of the simulation (the ``wind`` given to
        :func:`~specdesign.simulate.simulate`, transient included). The horizon's wind is
        then d_j = wind(t + j T_s) − v (linear interpolation, the last sample held past the
        record's end) instead of the estimate d̂ held. Default None: no preview.
    name : str, default "quadratic MPC"
        Label.
    operating_point, wind_speeds, design_speed : str, array_like, float
        Where the model is linearised, as :class:`~specdesign.mpc.sampled.SampledController`
        takes them (default: scheduled on the run's own wind estimate, every 1 m/s over
        ``model.wind_range``; or ``"initial pitch"``, or ``"design point"`` at ``design_speed``, m/s).
    sensors : specdesign.simulate.SensorNoise, optional
        The sensors the runs read through, whose noise the Kalman filter assumes, as
        :class:`~specdesign.mpc.sampled.SampledController` takes them (default: none, the
        filter's own tuning).

    Attributes
    ----------
    solve_times : list of float
        CPU time (s) of every policy evaluation (one per run per sample), since the last pickle.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> from specdesign.simulate import simulate
    >>> m = iea15mw()
    >>> r = simulate(m, QuadraticMPC(m), [19.0], seeds=[1], duration=5.0, transient=1.0)
    >>> r["pitch_cmd"].shape
    (1, 1, 50)
    """

    def __init__(self, model, ts: float = 0.1, horizon: int = 50, *, speed_weight: float = 100.0,
                 tower_weight: float = 100.0, activity_weight: float = 0.1, measured=MEASURED, shortcut: bool = True,
                 solver: str = "OSQP", preview=None, name: str = "quadratic MPC", operating_point: str = "estimated",
                 wind_speeds=None, design_speed: float | None = None, sensors=None):
        if isinstance(horizon, bool) or not isinstance(horizon, (int, np.integer)) or horizon < 1:
            raise ValueError(f"horizon={horizon!r} must be an integer number of steps >= 1")
        self.horizon = int(horizon)
        self.weights = (float(speed_weight), float(tower_weight), float(activity_weight))
        if min(self.weights) < 0 or not np.all(np.isfinite(self.weights)):
            raise ValueError(f"speed_weight, tower_weight, activity_weight must be finite and >= 0, got {self.weights}")
        if self.weights[2] == 0:
            raise ValueError("activity_weight must be > 0 (it keeps the QP strictly convex)")
        self.shortcut = bool(shortcut)
        self.solver = str(solver)
        self.preview = None
        if preview is not None:
            if not (isinstance(preview, tuple) and len(preview) == 2):
                raise TypeError("preview must be a tuple (wind array in m/s, wind_dt in s)")
            w = np.asarray(preview[0], float)
            w = w.reshape(-1, w.shape[-1]) if w.ndim == 3 else w
            if w.ndim != 2 or w.shape[1] < 2 or not np.all(np.isfinite(w)):
                raise ValueError(f"preview wind must be a finite (R, n_w) or (W, S, n_w) array in m/s, got shape "
                                 f"{np.shape(preview[0])}")
            self.preview = (w, positive_scalar(preview[1], "preview wind_dt"))
        super().__init__(model, ts, measured, name, operating_point=operating_point, wind_speeds=wind_speeds,
                         design_speed=design_speed, sensors=sensors)
        positive_scalar(model.pitch_rate_limit, "model.pitch_rate_limit")

    @docstring_of(SampledController, note='Here the QP of :func:`quadratic_qp`, under ``"qp"``.')
    def build(self, dm: DiscreteTurbine) -> dict:
        return {"qp": quadratic_qp(dm, self.horizon, self.weights, float(self.model.rated_rotor_speed),
                                   float(self.model.pitch_rate_limit),
                                   (float(self.model.pitch_min), float(self.model.pitch_max)),
                                   preview=self.preview is not None)}

    @docstring_of(SampledController, note="With a ``preview`` it is checked first: a ValueError if it has another "
                                          "number of runs or does not start with the simulation's wind.")
    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        if self.preview is not None:
            w = self.preview[0]
            if w.shape[0] != np.size(pitch):
                raise ValueError(f"preview has {w.shape[0]} runs but the simulation has {np.size(pitch)}")
            if not np.allclose(w[:, 0], np.asarray(wind, float), rtol=0, atol=1e-9):
                raise ValueError("preview wind does not start with the simulation's wind: pass the same records")
        super().start(dt, wind, pitch, torque)

    def _horizon_wind(self, dm: DiscreteTurbine, xhat: np.ndarray) -> np.ndarray:
        """(G, n_d) wind deviations over the horizon: the estimate held, or the preview."""
        if self.preview is None:
            return xhat[:, -1:]
        t, idx = self._run["now"]
        w, wdt = self.preview
        grid = np.arange(w.shape[1]) * wdt
        times = t + self.ts * np.arange(self.horizon)
        return np.stack([np.interp(times, grid, w[r]) for r in idx]) - dm.wind_speed

    def solve(self, qp: dict, x0: np.ndarray, d: float, uprev: float) -> np.ndarray:
        """The optimal command sequence for one run (the constrained QP, by cvxpy).

        Parameters
        ----------
        qp : dict
            :func:`quadratic_qp`'s result.
        x0 : numpy.ndarray
            (n,) state estimate (deviations, SI).
        d : float or numpy.ndarray
            Wind deviation (m/s): the estimate held, or the (N,) previewed sequence.
        uprev : float
            Previous command deviation (rad).

        Returns
        -------
        numpy.ndarray
            (N,) command deviations (rad).

        Raises
        ------
        RuntimeError
            If the solver does not return an optimal solution.
        """
        qp["x0"].value, qp["d"].value = np.asarray(x0, float), np.atleast_1d(np.asarray(d, float))
        qp["uprev"].value = np.array([uprev])
        opts = OSQP_OPTIONS if self.solver == "OSQP" else {}
        qp["problem"].solve(solver=self.solver, warm_start=True, **opts)
        if qp["problem"].status not in ("optimal", "optimal_inaccurate"):
            raise RuntimeError(f"{self.name}: the QP is {qp['problem'].status} (a start outside the rate limit?)")
        return np.asarray(qp["v"].value, float) * qp["step"]

    @docstring_of(SampledController)
    def policy(self, pt: dict, xhat: np.ndarray, uprev: np.ndarray) -> np.ndarray:
        # the first move of the QP of every run at this operating point
        qp = pt["qp"]
        out = np.empty(uprev.size)
        dw = self._horizon_wind(pt.get("model"), xhat)
        for g in range(uprev.size):
            t0 = time.process_time()
            p = np.concatenate([xhat[g, :-1], dw[g], [uprev[g]]])
            u = qp["K"] @ p if self.shortcut else None
            tol = 1e-9
            if u is None or np.any(u < qp["lower"] - tol) or np.any(u > qp["upper"] + tol) or \
                    np.any(np.abs(np.diff(np.concatenate([[uprev[g]], u]))) > qp["step"] + tol):
                u = self.solve(qp, xhat[g, :-1], dw[g], uprev[g])
                # OSQP's tolerance may leave a move a hair past the rate limit: the first move
                # is the only one applied, and it must respect the actuator's limits exactly
                u0 = min(max(u[0], uprev[g] - qp["step"], qp["lower"][0]), uprev[g] + qp["step"], qp["upper"][0])
            else:
                u0 = u[0]
            out[g] = u0
            self.solve_times.append(time.process_time() - t0)
        return out


def unconstrained_law(mpc: QuadraticMPC, wind_speed: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The MPC's linear law at one operating point when no constraint is active.

    Its Kalman filter at ``wind_speed`` (the vertex model, time-invariant) and the QP's
    unconstrained minimiser's first move, u_k = K_x x̂_{k|k} + K_u u_{k−1}, written as one
    discrete system at ``mpc.ts`` with state (x̂_{k|k−1}, u_{k−1}) from the measured outputs'
    deviations y_k (``mpc.measured``, SI) to the command deviation u_k (rad)::

        x̂_{k|k}   = F x̂_{k|k−1} + L y_k,   F = I − L C_a
        u_k       = K_x x̂_{k|k} + K_u u_{k−1}
        x̂_{k+1|k} = A_a x̂_{k|k} + B_a u_k

    Parameters
    ----------
    mpc : QuadraticMPC
        The controller (without preview: the law reads its wind estimate held).
    wind_speed : float
        The operating point (m/s), a speed its model linearises at.

    Returns
    -------
    A, B, C, D : numpy.ndarray
        (n+2, n+2), (n+2, q), (n+2,), (q,): u_k = C s_k + D y_k, s_{k+1} = A s_k + B y_k, with
        n+1 the filter's states (the model's and the wind) and q the measured outputs.

    Raises
    ------
    ValueError
        For an MPC with a wind preview.
    """
    if mpc.preview is not None:
        raise ValueError("mpc has a wind preview: its law reads the previewed wind, not a linear function of the "
                         "measurements; build the MPC without preview=")
    pt = mpc.point(wind_speed)
    Aa, Ba, Ca, L = pt["kf"]
    K = pt["qp"]["K"][0]
    n = Aa.shape[0]
    Kx, Ku = K[:n], K[n]
    F = np.eye(n) - L @ Ca
    A = np.zeros((n + 1, n + 1))
    A[:n, :n] = Aa @ F + np.outer(Ba, Kx @ F)
    A[:n, n] = Ba * Ku
    A[n, :n] = Kx @ F
    A[n, n] = Ku
    B = np.vstack([Aa @ L + np.outer(Ba, Kx @ L), (Kx @ L)[None, :]])
    return A, B, np.r_[Kx @ F, Ku], Kx @ L


def loop_gain(mpc: QuadraticMPC, wind_speed: float, omega, plant=None) -> np.ndarray:
    """The sampled loop's gain L(e^{jωT_s}) broken at the pitch command, MPC unconstrained.

    L = C(z)·P(z) with C the :func:`unconstrained_law` and P the plant from the command to
    the measured outputs, both discrete at ``mpc.ts`` (zero-order hold: exact at the sample
    instants). The loop is u = C P u, positive feedback, so the return difference is 1 − L and
    min_ω |1 − L| is the modulus margin (the distance of the Nyquist curve from +1; 0.5 is
    the usual robustness requirement, |S| ≤ 2).

    Parameters
    ----------
    mpc : QuadraticMPC
        The controller.
    wind_speed : float
        The operating point (m/s) of the law and of the plant.
    omega : array_like
        Frequencies (rad/s), up to the Nyquist frequency π/T_s.
    plant : TurbineModel or LinearTurbine, optional
        The plant the loop is closed on; default the MPC's own model (its internal model is the
        plant).

    Returns
    -------
    numpy.ndarray
        L at ``omega`` (complex, shaped as ``omega``).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> mpc = QuadraticMPC(iea15mw(), operating_point="initial pitch")
    >>> L = loop_gain(mpc, 19.0, np.linspace(0.01, np.pi / mpc.ts, 500))
    >>> round(float(np.abs(1 - L).min()), 2)  # the modulus margin on its own model
    0.5
    """
    A, B, C, D = unconstrained_law(mpc, wind_speed)
    dm = mpc.point(wind_speed)["model"] if plant is None else discretize_turbine(plant, wind_speed, mpc.ts)
    rows = dm.rows(mpc.measured)
    w = np.asarray(omega, float)
    p = state_space_response(dm.A, dm.Bu[:, None], dm.C[rows], np.zeros((rows.size, 1)), w.ravel(),
                             sample_time=mpc.ts)[:, :, 0]
    c = state_space_response(A, B, C[None, :], D[None, :], w.ravel(), sample_time=mpc.ts)[:, 0, :]
    return np.sum(c * p, axis=1).reshape(w.shape)
