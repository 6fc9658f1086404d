"""The tuning problem of the automatic QFT design: objective, constraints, and the tuner.

Everything the tuning evaluates is precomputed on the design and analysis grids
(:class:`TuningProblem`); :func:`tune` explores with Powell on exterior penalties, polishes
with SLSQP to KKT points, and keeps the best candidate by a total order (feasible first, then
the smaller objective), so the design does not jump when the data move by round-off.

Units: ω in rad/s, wind speeds in m/s, DEL and damage reductions in % (positive = less),
bound margins and safety margins in dB, decay rates in 1/s; the parameter vector x is
:mod:`specdesign.qft.structure`'s.
"""
from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import control as ct
import numpy as np
from numpy.typing import ArrayLike

from .. import spectral
from ..closedloop import closed_map, plant_responses, siso_response
from ..spec import SLSQP_OPTIONS
from .structure import controller_polys, vector_bounds

if TYPE_CHECKING:
    from ..spec import Baseline
    from ..turbine import TurbineModel

__all__ = ["TuningProblem", "tune", "FEASIBLE_TOL", "STABILITY_SAFETY_DB", "PERFORMANCE_SAFETY_DB", "DC_SAFETY_DB"]

#: Safety margins (dB) on the bounds while tuning: the stability specs, the performance specs
#: above 0.05 rad/s, and below it (where the specs meet ROSCO's loop at DC).
STABILITY_SAFETY_DB = 0.1
PERFORMANCE_SAFETY_DB = 0.02
DC_SAFETY_DB = 0.005


class TuningProblem:
    """Everything the tuning evaluates, precomputed on the design and analysis grids.

    The plant cases are the linear models at ``speeds``; the specifications are, per case,
    |T_{Ω,w}| ≤ |T^ROSCO_{Ω,w}|·10^(speed_relax_db/20), |T_{MyT,w}| ≤ |T^ROSCO_{MyT,w}|·|tower_shaping|
    and |1/(1 + L)| ≤ ``max_sensitivity`` on each loop with the other closed and at the actuator.
    The performance (DEL, damage, standard deviations) is the nominal case's on the baseline's
    grid ``base.omega`` with its wind PSD.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine (linearised at every speed of ``speeds``).
    v : float
        Nominal wind speed, m/s.
    speeds : sequence of float
        Wind speeds of the plant cases (templates), m/s, including ``v``.
    nominal : int
        Index of the nominal case in ``speeds``.
    design_omega : array_like
        Design frequencies, rad/s.
    tower_shaping : callable
        Maps ω (rad/s) to the complex shaping of ROSCO's T_{MyT,w} (notches × relaxation), e.g. the
        tower :class:`specdesign.spec.Specification`'s ``shaping``.
    speed_relax_db : float
        Relaxation of the generator-speed specification, dB.
    max_sensitivity : float
        Bound on |1/(1 + L)| (-, > 1).
    base : specdesign.spec.Baseline
        ROSCO's nominal loop (grid ``omega`` in rad/s, ``wind_psd`` in (m/s)² per rad/s,
        Wöhler exponent ``m`` and damage method).
    speed_shaping : callable, optional
        ω → W_Ω(jω)/T^ROSCO_{Ω,w}(jω) of the nominal case, applied to every case in place of
        the constant relaxation ``speed_relax_db`` (a given generator-speed specification).
    response_method : {"python-control", "batched"}
        How the plant cases are evaluated (:func:`specdesign.closedloop.plant_responses`); the
        fixed-structure design keeps python-control's round-off, the certificate design the
        fast batched solve.
    controller_bound : tuple, optional
        (ω → allowed |C_β(jω)| in rad per rad/s, (low, high) band in rad/s): the high-frequency
        gain bound the pitch controller must meet (:func:`specdesign.feasibility.hf_gain_bound`),
        checked on the dense grid with the loops' specifications; None: none.

    Attributes
    ----------
    plants, rosco : list
        Linear plant and ROSCO controller per case.
    wd : numpy.ndarray
        Current design frequencies, rad/s (:meth:`set_design`).
    WO, WM : numpy.ndarray
        |W_Ω| and |W_MyT| on ``wd``, shape (n_omega, n_cases).
    d0 : float
        ROSCO's nominal tower-base damage rate, 1/s.
    sd0 : dict
        ROSCO's nominal standard deviations: ``gen_speed`` (rad/s), ``pitch`` (rad),
        ``pitch_rate`` (rad/s).

    Raises
    ------
    ValueError
        If a plant has a direct feedthrough from the pitch command to a measurement, or a
        speed is outside ``model.wind_range``.

    Examples
    --------
    >>> from specdesign import spec, turbine
    >>> from specdesign.qft import DEFAULT_DESIGN_OMEGA
    >>> from specdesign.qft.structure import rosco_start
    >>> model = turbine.iea15mw()  # doctest: +SKIP
    >>> d = spec.design_specifications(model, 19.0, speed_relax_db=3.0)  # doctest: +SKIP
    >>> prob = TuningProblem(model, 19.0, (18.0, 19.0, 20.0), 1, DEFAULT_DESIGN_OMEGA,
    ...                      d.tower.shaping, 3.0, 1.9, d.base)  # doctest: +SKIP
    >>> prob.margins(rosco_start(prob.rosco[1])).shape  # doctest: +SKIP
    (5, 47, 3)
    """

    def __init__(self, model: TurbineModel, v: float, speeds: Sequence[float], nominal: int, design_omega: ArrayLike,
                 tower_shaping: Callable[[np.ndarray], np.ndarray], speed_relax_db: float, max_sensitivity: float,
                 base: Baseline, speed_shaping: Callable[[np.ndarray], np.ndarray] | None = None,
                 response_method: str = "python-control", controller_bound: tuple | None = None) -> None:
        from ..spec import baseline_controllers

        self.v, self.speeds, self.nom = v, speeds, nominal
        self.response_method = response_method  # plant_responses' method, for every evaluation of the plants
        self.plants = [model.linearize(s) for s in speeds]
        self.rosco = baseline_controllers(model, speeds)
        self.tower_shaping = tower_shaping  # callable ω → complex shaping (notches × relaxation)
        self.speed_gain = 10 ** (speed_relax_db / 20)
        self.speed_shaping = speed_shaping  # callable ω → W_Ω/T^ROSCO_{Ω,w} (nominal), or None: speed_gain
        self.ms = max_sensitivity
        self.controller_bound = controller_bound
        self.base = base
        self.wf, self.S = base.omega, base.wind_psd
        self.Rf = plant_responses(self.plants, self.wf, method=response_method)
        self.pss = []
        for P in self.plants:
            p = ct.ss(P)[["gen_speed", "tower_top_vel"], "pitch_cmd"]
            if np.any(np.asarray(p.D) != 0):
                raise ValueError("the plant has a direct feedthrough pitch → measurement; not supported")
            self.pss.append((np.asarray(p.A), np.asarray(p.B), np.asarray(p.C)))
        c0 = siso_response(self.rosco[nominal], self.wf)[:, None]
        T0 = {y: self._t(self.Rf, c0, 0.0, y)[:, nominal] for y in ("tower_base_my", "gen_speed", "pitch")}
        self.d0 = float(spectral.damage_rate(self.wf, np.abs(T0["tower_base_my"]) ** 2 * self.S, base.m, method=base.method))
        self.sd0 = {"gen_speed": self._sd(T0["gen_speed"]), "pitch": self._sd(T0["pitch"]),
                    "pitch_rate": self._sd(T0["pitch"] * 1j * self.wf)}
        self.set_design(design_omega)

    # closed-loop maps from responses (every case at once)
    @staticmethod
    def _t(R, c, k, y):
        return closed_map(R, c, k, y)

    def _sd(self, t):
        return float(np.sqrt(np.trapezoid(np.abs(t) ** 2 * self.S, self.wf)))

    def weights(self, omega: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(W_Ω, W_MyT), each (n_omega, n_cases) magnitudes at ω (rad/s).

        Parameters
        ----------
        omega : array_like
            Frequencies, rad/s.

        Returns
        -------
        w_speed : numpy.ndarray
            |W_Ω| = |T^ROSCO_{Ω,w}|·10^(speed_relax_db/20) per case, rad/s per m/s.
        w_tower : numpy.ndarray
            |W_MyT| = |T^ROSCO_{MyT,w}|·|tower_shaping| per case, N·m per m/s.
        """
        R = plant_responses(self.plants, omega, ("gen_speed", "tower_base_my", "tower_top_vel"), method=self.response_method)
        c = np.stack([siso_response(r, omega) for r in self.rosco], axis=1)
        gain = self.speed_gain if self.speed_shaping is None else np.abs(self.speed_shaping(omega))[:, None]
        w_speed = np.abs(self._t(R, c, 0.0, "gen_speed")) * gain
        w_tower = np.abs(self._t(R, c, 0.0, "tower_base_my")) * np.abs(self.tower_shaping(omega))[:, None]
        return w_speed, w_tower

    def set_design(self, omega: ArrayLike) -> None:
        """Set the design frequencies and precompute the plant responses and weights on them.

        Parameters
        ----------
        omega : array_like
            New design frequencies, rad/s (replaces ``wd``, ``Rd``, ``WO``, ``WM``).
        """
        self.wd = np.asarray(omega, float)
        # the controller's high-frequency gain bound on wd (rad per rad/s; inf outside its band)
        self._gain_bound = None if self.controller_bound is None else self.controller_bound[0](self.wd)
        self.Rd = plant_responses(self.plants, self.wd, ("gen_speed", "tower_base_my", "tower_top_vel"),
                                  method=self.response_method)
        self.WO, self.WM = self.weights(self.wd)

    def margins(self, x: ArrayLike) -> np.ndarray:
        """Per-spec margins in dB on the design grid, (n_specs, n_omega, n_cases).

        Parameters
        ----------
        x : array_like
            Parameter vector (:mod:`specdesign.qft.structure`).

        Returns
        -------
        numpy.ndarray
            20·log10(bound/|map|), dB (≥ 0 where met), shape (5, n_omega, n_cases), in the
            order: generator speed, tower load, pitch-loop margin (ATD closed), ATD-loop
            margin (pitch loop closed), margin at the actuator; with ``controller_bound`` a
            sixth row, 20·log10(bound/|C_β|) (the same for every case; 100 dB outside its band).
        """
        nb, db, na, da = controller_polys(x)
        s = 1j * self.wd[:, None]
        c = np.polyval(nb, s) / np.polyval(db, s)
        k = np.polyval(na, s) / np.polyval(da, s)
        R = self.Rd
        to = self._t(R, c, k, "gen_speed")
        tm = self._t(R, c, k, "tower_base_my")
        ob, zb = R[("gen_speed", "pitch_cmd")], R[("tower_top_vel", "pitch_cmd")]
        d = 1 + c * ob + k * zb
        with np.errstate(divide="ignore"):
            rows = [
                20 * np.log10(self.WO / np.abs(to)),
                20 * np.log10(self.WM / np.abs(tm)),
                20 * np.log10(self.ms * np.abs(d) / np.abs(1 + k * zb)),  # pitch loop, ATD closed
                20 * np.log10(self.ms * np.abs(d) / np.abs(1 + c * ob)),  # ATD loop, pitch closed
                20 * np.log10(self.ms * np.abs(d)),  # at the actuator
            ]
            if self._gain_bound is not None:  # finite outside the band too: the SLSQP constraints are numbers
                gain = np.minimum(20 * np.log10(self._gain_bound[:, None] / np.abs(c)), 100.0)
                rows.append(np.broadcast_to(gain, to.shape))
            return np.stack(rows)

    def max_real(self, x: ArrayLike) -> np.ndarray:
        """Largest closed-loop pole real part (1/s) per case, full interconnection.

        Parameters
        ----------
        x : array_like
            Parameter vector (:mod:`specdesign.qft.structure`).

        Returns
        -------
        numpy.ndarray
            Largest Re p of the plant with both loops closed, 1/s, one per case (< −``min_decay``
            is required).
        """
        from scipy.signal import tf2ss

        nb, db, na, da = controller_polys(x)
        A1, B1, C1, D1 = tf2ss(nb, db)
        A2, B2, C2, D2 = tf2ss(na, da)
        n1, n2 = A1.shape[0], A2.shape[0]
        out = []
        for A, B, C in self.pss:
            n = A.shape[0]
            M = np.zeros((n + n1 + n2,) * 2)
            M[:n, :n] = A - B @ (D1 @ C[0:1] + D2 @ C[1:2])
            M[:n, n:n + n1] = -B @ C1
            M[:n, n + n1:] = -B @ C2
            M[n:n + n1, :n] = B1 @ C[0:1]
            M[n:n + n1, n:n + n1] = A1
            M[n + n1:, :n] = B2 @ C[1:2]
            M[n + n1:, n + n1:] = A2
            out.append(np.linalg.eigvals(M).real.max())
        return np.array(out)

    def performance(self, x: ArrayLike) -> tuple[float, float, float, float, float]:
        """(DEL reduction %, damage reduction %, SD ratios gen speed, pitch, pitch rate) nominal.

        Dirlik (the baseline's damage method) on |T_{MyT,w}|² S_W of the nominal case, against
        ROSCO's; the last result is cached (the objective and the constraints ask for the same x).

        Parameters
        ----------
        x : array_like
            Parameter vector (:mod:`specdesign.qft.structure`).

        Returns
        -------
        tuple of float
            Tower-base DEL reduction (%), damage reduction (%), and the ratios σ/σ_ROSCO (-) of
            generator speed, pitch and pitch rate.
        """
        key = np.asarray(x, float).tobytes()
        if getattr(self, "_perf_key", None) == key:  # the objective and the constraints ask for the same x
            return self._perf
        nb, db, na, da = controller_polys(x)
        s = 1j * self.wf[:, None]
        c = np.polyval(nb, s) / np.polyval(db, s)
        k = np.polyval(na, s) / np.polyval(da, s)
        self._perf_key, self._perf = key, self.performance_of(c, k)
        return self._perf

    def performance_of(self, c: np.ndarray, k: np.ndarray) -> tuple[float, float, float, float, float]:
        """:meth:`performance` of any controllers, given their responses on the baseline's grid.

        Parameters
        ----------
        c, k : numpy.ndarray
            C_β (rad per rad/s) and C_atd (rad per m/s) at jω for ω = ``base.omega``, shape
            (n_omega, 1) (or broadcasting to it).

        Returns
        -------
        tuple of float
            As :meth:`performance`.
        """
        tm = self._t(self.Rf, c, k, "tower_base_my")[:, self.nom]
        tp = self._t(self.Rf, c, k, "pitch")[:, self.nom]
        to = self._t(self.Rf, c, k, "gen_speed")[:, self.nom]
        d = float(spectral.damage_rate(self.wf, np.abs(tm) ** 2 * self.S, self.base.m, method=self.base.method))
        ratio = d / self.d0
        return (100 * (1 - ratio ** (1 / self.base.m)), 100 * (1 - ratio), self._sd(to) / self.sd0["gen_speed"],
                self._sd(tp) / self.sd0["pitch"], self._sd(tp * 1j * self.wf) / self.sd0["pitch_rate"])

    def objective(self, x: ArrayLike) -> float:
        """The tuning objective: (σ_β̇/σ_β̇,ROSCO)² + 0.1·(σ_Ω/σ_Ω,ROSCO)², nominal case.

        Parameters
        ----------
        x : array_like
            Parameter vector (:mod:`specdesign.qft.structure`).

        Returns
        -------
        float
            The objective (-); 1.1 for ROSCO's own standard deviations.
        """
        _, _, gs, _, rate = self.performance(x)
        return float(rate**2 + 0.1 * gs**2)

    def _safety(self):
        # the performance specs touch their weights at ω → 0 (integral action: every design
        # reaches the same DC response), so only the margin specs get a full safety margin
        return np.where(self.wd >= 0.05, PERFORMANCE_SAFETY_DB, DC_SAFETY_DB)[None, :, None]

    def constraints(self, x: ArrayLike, target: float, min_decay: float) -> np.ndarray:
        """Every requirement as one vector that is ≥ 0 when met.

        Bound margins (dB) less their safety margin per spec, frequency and case; DEL reduction
        − target (pp); decay margin −(max Re p + min_decay) per case (1/s).

        Parameters
        ----------
        x : array_like
            Parameter vector (:mod:`specdesign.qft.structure`).
        target : float or None
            Required tower-base DEL reduction, %; None when a given specification carries it
            (no DEL constraint).
        min_decay : float
            Required decay rate, 1/s (poles left of −``min_decay``).

        Returns
        -------
        numpy.ndarray
            1-D: the 5·n_omega·n_cases bound margins (6· with ``controller_bound``; dB, less :data:`PERFORMANCE_SAFETY_DB` /
            :data:`DC_SAFETY_DB` on the performance specs and :data:`STABILITY_SAFETY_DB` on the
            margin specs), the DEL margin (pp) and the n_cases decay margins (1/s).
        """
        g = self.margins(x)
        del_margin = [] if target is None else [self.performance(x)[0] - target]
        return np.r_[(g[:2] - self._safety()).ravel(), (g[2:] - STABILITY_SAFETY_DB).ravel(), del_margin,
                     -(self.max_real(x) + min_decay)]

    def cost(self, x: ArrayLike, target: float, min_decay: float, weight: float = 1e3) -> float:
        """Exterior-penalty cost of the exploration.

        objective + 10·(target − reduction)₊² + weight·Σ(bound violation, dB)²; a barrier
        (≥ 1e10) for decay-rate violations.

        Parameters
        ----------
        x : array_like
            Parameter vector (:mod:`specdesign.qft.structure`).
        target : float or None
            Required tower-base DEL reduction, %; None for no DEL penalty.
        min_decay : float
            Required decay rate, 1/s.
        weight : float
            Penalty weight per dB² of bound violation (after the safety margins).

        Returns
        -------
        float
            The cost (-); 1e12 when x cannot be evaluated (non-finite responses, a failed
            eigenvalue computation), 1e10·(1 + Σ excess) when a pole is right of −``min_decay``.
        """
        try:
            g = self.margins(x)
            red = self.performance(x)[0]
            mr = self.max_real(x)
        except (ValueError, np.linalg.LinAlgError, FloatingPointError):
            return 1e12
        if not (np.all(np.isfinite(g)) and np.isfinite(red) and np.all(np.isfinite(mr))):
            return 1e12
        viol = np.sum(np.minimum(g[:2] - self._safety(), 0.0) ** 2) + np.sum(np.minimum(g[2:] - STABILITY_SAFETY_DB, 0.0) ** 2)
        excess = np.sum(np.maximum(mr + min_decay, 0.0))
        if excess > 0:  # a barrier: never trade stability for anything
            return float(1e10 * (1 + excess))
        shortfall = 0.0 if target is None else max(target - red, 0.0)
        return float(self.objective(x) + 10 * shortfall ** 2 + weight * viol)


#: Largest constraint violation a polished candidate may keep and still count as feasible
#: (dB for bounds, pp for the DEL target, 1/s for the decay rate): SLSQP's own tolerance.
FEASIBLE_TOL = 1e-6


def tune(prob: TuningProblem, x0: ArrayLike, target: float | None, min_decay: float, maxfev: int) -> tuple[np.ndarray, bool]:
    """Tune from ``x0``: explore, polish, and keep the best candidate by a total order.

    Powell on the penalty cost explores (a derivative-free search that gets past the kinks of
    the bounds from an infeasible start) but stops wherever its line searches happen to end,
    so its end point moves with round-off. Each candidate is therefore polished by SLSQP on the
    constrained problem (objective subject to :meth:`TuningProblem.constraints` ≥ 0) to a KKT point,
    which moves continuously with the data. Candidates: the polished Powell end point, the
    polished start, and the unpolished Powell end point. The order that picks one is total:
    feasible (every constraint ≥ −1e-6) before infeasible; among feasible ones the smaller
    objective; among infeasible ones the smaller penalty cost; ties by candidate order.

    Parameters
    ----------
    prob : TuningProblem
        The precomputed problem.
    x0 : array_like
        Start parameter vector, e.g. :func:`specdesign.qft.structure.rosco_start`.
    target : float or None
        Required tower-base DEL reduction, %; None: no DEL constraint (a given specification
        carries the target).
    min_decay : float
        Required closed-loop decay rate, 1/s.
    maxfev : int
        Function evaluations per Powell run (three runs: penalty weights 1e3, 1e5, 1e7).

    Returns
    -------
    x : numpy.ndarray
        The chosen parameter vector, inside :func:`specdesign.qft.structure.vector_bounds`.
    feasible : bool
        Whether ``x`` meets every constraint (each ≥ −:data:`FEASIBLE_TOL`).

    Examples
    --------
    >>> from specdesign.qft.structure import from_vector, rosco_start
    >>> # prob: a TuningProblem (see its example)
    >>> x, feasible = tune(prob, rosco_start(prob.rosco[1]), 25.0, 0.02, 3000)  # doctest: +SKIP
    >>> from_vector(x)["k"] < 0  # doctest: +SKIP
    True
    """
    from scipy.optimize import minimize

    lo, hi = vector_bounds()
    box = list(zip(lo, hi))
    x = x0
    # exterior penalty method: the bound violations cost more and more (continuation)
    for weight in (1e3, 1e5, 1e7):
        with np.errstate(all="ignore"):
            res = minimize(prob.cost, x, args=(target, min_decay, weight), method="Powell", bounds=box,
                           options={"maxfev": int(maxfev), "xtol": 1e-4, "ftol": 1e-8})
        if np.all(np.isfinite(res.x)) and res.fun <= prob.cost(x, target, min_decay, weight):
            x = np.clip(res.x, lo, hi)

    def polish(start):
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                r = minimize(prob.objective, start, method="SLSQP", bounds=box,
                             constraints=[{"type": "ineq", "fun": prob.constraints, "args": (target, min_decay)}],
                             options=dict(SLSQP_OPTIONS))
            except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                return None
        return np.clip(r.x, lo, hi) if np.all(np.isfinite(r.x)) else None

    candidates = [c for c in (polish(x), polish(np.asarray(x0, float)), x) if c is not None]

    def key(c):
        with np.errstate(all="ignore"):
            try:
                g = prob.constraints(c, target, min_decay)
                if np.all(np.isfinite(g)) and g.min() >= -FEASIBLE_TOL:
                    return (0, prob.objective(c))
                return (1, prob.cost(c, target, min_decay, 1e7))
            except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                return (2, 0.0)

    keys = [key(c) for c in candidates]
    best = min(range(len(candidates)), key=lambda i: (keys[i], i))
    return candidates[best], keys[best][0] == 0
