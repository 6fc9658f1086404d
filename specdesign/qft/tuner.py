"""The tuning problem of the automatic QFT design: objective, constraints, and the tuner.

Everything the tuning evaluates is precomputed on the design and analysis grids
(:class:`TuningProblem`); :func:`tune` reaches a feasible point by a phase one (least uniform
violation), polishes with SLSQP and refines to the KKT point by Newton's method
(:func:`kkt_refine`): local methods from a start that moves continuously with the data, and no
decision by a hair, so the design does not jump when the data move by round-off.

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
from .._kkt import kkt_point
from ..closedloop import closed_map, plant_responses, siso_response
from .structure import controller_polys, vector_bounds

if TYPE_CHECKING:
    from ..spec import Baseline
    from ..turbine import TurbineModel

__all__ = ["TuningProblem", "tune", "kkt_refine", "tied_objective", "FEASIBLE_TOL", "ACTIVE_TOL", "TIE_BREAK",
           "PHASE1_ROOM", "STEP_TOL", "STABILITY_SAFETY_DB", "PERFORMANCE_SAFETY_DB", "DC_SAFETY_DB"]

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
    measurement_filter : (numpy.ndarray, numpy.ndarray), optional
        A fixed filter on both measurements, part of both controllers in every evaluation
        (:func:`specdesign.qft.structure.controller_polys`); None: none.

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
                 response_method: str = "python-control", controller_bound: tuple | None = None,
                 measurement_filter: tuple | None = None) -> None:
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
        self.measurement_filter = measurement_filter  # (num, den) of a fixed filter in both controllers, or None
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
        nb, db, na, da = controller_polys(x, self.measurement_filter)
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

        nb, db, na, da = controller_polys(x, self.measurement_filter)
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
        nb, db, na, da = controller_polys(x, self.measurement_filter)
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


#: Largest constraint violation a polished candidate may keep and still count as feasible
#: (dB for bounds, pp for the DEL target, 1/s for the decay rate): SLSQP's own tolerance.
FEASIBLE_TOL = 1e-6


#: Constraint values (dB, pp, 1/s) under which a constraint counts as active at a polished point.
ACTIVE_TOL = 1e-6
#: Weight of the tie-break TIE_BREAK·|x − x_start|² that the polish and :func:`kkt_refine` add to
#: the objective (x in log-scale and damping-ratio units): along a direction the objective hardly
#: bends in (the ATD's pole and gain together, curvature ≈ 1e-6 where a finite-difference gradient
#: is known to ≈ 1e-10) the optimum is otherwise known only to ≈ 1e-4, and round-off picks.
TIE_BREAK = 1e-4
#: Phase one of :func:`tune` stops once every constraint has this much room (dB, pp, 1/s), and
#: counts as feasible only with half of it: a start that is feasible by a hair is not decided by it.
PHASE1_ROOM = 0.01
#: Newton's steps end when no parameter moves by more than this (log-scale and damping-ratio units).
STEP_TOL = 1e-6
#: SLSQP's options in :func:`tune` (its ``maxfev`` sets the iterations): a tolerance that lets it
#: converge, with central-difference gradients (accurate to ≈ 1e-10, where forward differences
#: stop a polish 1e-5 from where another round-off would).
POLISH_OPTIONS = {"ftol": 1e-14}


def tied_objective(prob: TuningProblem, x: ArrayLike, anchor: ArrayLike) -> float:
    """The tuner's objective with the tie-break: ``prob.objective(x)`` + :data:`TIE_BREAK`·|x − anchor|².

    Parameters
    ----------
    prob : TuningProblem
        The precomputed problem.
    x : array_like
        Parameter vector (:mod:`specdesign.qft.structure`).
    anchor : array_like
        The tie-break's anchor, the tuner's start.

    Returns
    -------
    float
        The objective with the tie-break (-).
    """
    d = np.asarray(x, float) - np.asarray(anchor, float)
    return float(prob.objective(x) + TIE_BREAK * (d @ d))


def kkt_refine(prob: TuningProblem, x: ArrayLike, target: float | None, min_decay: float, anchor: ArrayLike,
               iterations: int = 15) -> tuple[np.ndarray, dict]:
    """Newton's method on the KKT conditions of the constraints active at ``x`` (``specdesign._kkt.kkt_point``).

    A polish ends where its line search or its tolerance stops it, which moves with round-off
    along a shallow valley of the objective (1e-5 relative in the parameters). From that point,
    with the active constraints (value < :data:`ACTIVE_TOL`) as equalities and the parameters on
    (within 1e-5 of) their box limits fixed, Newton's method on ∇f = Jᵀλ, g_A = 0 (f the objective
    with the tie-break, :func:`tied_objective`; the objective's gradient by central differences with
    a 1e-4 step, the tie-break's exactly, the Lagrangian's Hessian by central differences of its
    gradient) converges to the KKT point itself, to the gradients' round-off (≈ 1e-8 in the
    parameters where the active set is not near-degenerate). It is kept only if it converges (at
    least three steps, the last below :data:`STEP_TOL`), every multiplier is ≥ 0 and every
    constraint stays met; else ``x`` is returned unchanged.

    Parameters
    ----------
    prob : TuningProblem
        The precomputed problem.
    x : array_like
        A feasible polished parameter vector.
    target : float or None
        Required DEL reduction, %, as for :meth:`TuningProblem.constraints`.
    min_decay : float
        Required decay rate, 1/s.
    anchor : array_like
        The tie-break's anchor (:func:`tied_objective`), the tuner's start.
    iterations : int
        Newton steps at most.

    Returns
    -------
    x : numpy.ndarray
        The refined vector (or ``x``).
    info : dict
        ``converged`` (bool), ``steps``, ``active`` (number of active constraints), ``free``
        (parameters not on a limit), ``kkt_residual`` (|∇f − Jᵀλ|, at the end) and ``reason``.
    """
    lo, hi = vector_bounds()
    return kkt_point(prob.objective, lambda z: prob.constraints(z, target, min_decay), np.asarray(x, float), lo, hi,
                     active_tol=ACTIVE_TOL, feasible_tol=FEASIBLE_TOL, step_tol=STEP_TOL, iterations=iterations,
                     tie_break=(TIE_BREAK, anchor))


def tune(prob: TuningProblem, x0: ArrayLike, target: float | None, min_decay: float, maxfev: int) -> tuple[np.ndarray, bool]:
    """Tune from ``x0``: every step a local method whose end moves continuously with the data.

    1. Phase one, unless ``x0`` meets every constraint with :data:`PHASE1_ROOM`/2 of room (ROSCO's
       start never does): SLSQP on min t subject to constraints + t ≥ 0 (the least uniform
       violation, t in dB / pp / 1/s) from ``x0``, stopped at t = −:data:`PHASE1_ROOM`; it counts
       as feasible only with t ≤ −:data:`PHASE1_ROOM`/2 (room, so no hair decides), else ``tune``
       returns its end as infeasible. SLSQP on the objective straight from an infeasible start
       ended feasible or not by round-off.
    2. Polish: SLSQP on the constrained problem (the objective plus the tie-break
       :data:`TIE_BREAK`·|x − x0|², subject to :meth:`TuningProblem.constraints` ≥ 0) from there.
    3. A feasible polish is refined to its KKT point (:func:`kkt_refine`).

    No derivative-free exploration and no choice among candidates by a strict order: those
    (Powell's end point, the smaller of two nearly equal objectives) moved with round-off, and
    with them the design (1e-3 relative in the parameters under a 1e-9 m/s nudge, another
    local optimum on OpenFAST's 25 m/s linearisation).

    Parameters
    ----------
    prob : TuningProblem
        The precomputed problem.
    x0 : array_like
        Start parameter vector, e.g. :func:`specdesign.qft.structure.rosco_start`; also the
        tie-break's anchor.
    target : float or None
        Required tower-base DEL reduction, %; None: no DEL constraint (a given specification
        carries the target).
    min_decay : float
        Required closed-loop decay rate, 1/s.
    maxfev : int
        Iterations at most of each SLSQP run.

    Returns
    -------
    x : numpy.ndarray
        The parameter vector, inside :func:`specdesign.qft.structure.vector_bounds`.
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
    x0 = np.clip(np.asarray(x0, float), lo, hi)
    options = {**POLISH_OPTIONS, "maxiter": int(maxfev)}

    def run(fun, start, constraints, bounds):
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                r = minimize(fun, start, method="SLSQP", bounds=bounds, jac="3-point",
                             constraints=constraints, options=options)
            except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                return None
        return r.x if np.all(np.isfinite(r.x)) else None

    def polish(start):
        x = run(lambda y: tied_objective(prob, y, x0), start,
                [{"type": "ineq", "fun": prob.constraints, "args": (target, min_decay)}], box)
        return None if x is None else np.clip(x, lo, hi)

    def violation(x):
        with np.errstate(all="ignore"):
            try:
                g = prob.constraints(x, target, min_decay)
            except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                return np.inf
        return float(-g.min()) if np.all(np.isfinite(g)) else np.inf

    start = x0
    t0 = violation(x0)
    if not np.isfinite(t0):
        return x0, False
    if t0 > -PHASE1_ROOM / 2:  # SLSQP from an infeasible start ends where round-off sends it: phase one first
        z = run(lambda z: z[-1], np.r_[x0, t0],
                [{"type": "ineq", "fun": lambda z: prob.constraints(z[:-1], target, min_decay) + z[-1]}],
                box + [(-PHASE1_ROOM, max(t0, 0.0) + 1.0)])
        if z is None:
            return x0, False
        start = np.clip(z[:-1], lo, hi)
        if violation(start) > -PHASE1_ROOM / 2:
            return start, False
    x = polish(start)
    if x is None or violation(x) > FEASIBLE_TOL:
        return (start if x is None else x), False
    return kkt_refine(prob, x, target, min_decay, x0)[0], True
