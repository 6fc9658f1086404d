"""A certified specification pair at every plant case: the explicit check, and the multi-model H∞ step.

A :class:`specdesign.feasibility.TargetSpecification` is certified over plant cases (the
nominal speed and its neighbours): at case i the specifications are
W_i = T^ROSCO_i·(W/T^ROSCO at the nominal speed), and a pitch controller meets the pair when
|T_{MyT,w,i}(jω)| ≤ |W_MyT,i(jω)| and |T_{Ω,w,i}(jω)| ≤ |W_Ω,i(jω)| at every case and ω, with
T = [P_{y,w} + C(P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w})]/(1 + C·P_{Ω,β}) (the check of
:mod:`specdesign.qft.certificate`). :func:`check_pair` evaluates that explicitly;
:func:`refine_on_cases` is the multi-model H∞ step of :func:`specdesign.hinf.design_hinf`.

Why a multi-model step: the Riccati synthesis bounds the root-sum-square of the weighted
outputs of the nominal plant, with the weights' narrow zeros capped, while the pair is a box
(each ratio ≤ 1) at every case. The step takes the reduced H∞ controller and adjusts its
poles, residues and feedthrough (its order, and its integrator, kept) until
max over cases and channels of ‖W_i⁻¹T_i‖∞ ≤ 10^(−margin/20) on the check grid, the loop's
poles have Re ≤ −``decay_rate`` at every case and |1/(1 + C·P_{Ω,β})| ≤ ``max_sensitivity``,
then lowers the worst ratio further (a smooth minimax):
the per-channel, multi-model H∞ constraint of structured H∞ synthesis (Apkarian & Noll 2006,
MATLAB's ``hinfstruct``/``systune``), here an exterior penalty minimised by L-BFGS-B with
analytic gradients.

Units: ω in rad/s, wind speeds in m/s, excesses and margins in dB, decay rates in 1/s; the
pitch controller C_β in the workbench sign β = −C_β·Ω_g (rad per rad/s).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import control as ct
import numpy as np
from numpy.typing import ArrayLike
from scipy import linalg, optimize

from .._blas import one_blas_thread
from ..closedloop import (
    DESIGN_MAX_SENSITIVITY,
    MIN_DECAY_RATE,
    closed_map,
    lightly_damped,
    plant_responses,
    refine_grid,
    siso_response,
)
from ..feasibility import (
    HF_END,
    HF_OMEGA,
    TargetSpecification,
    hf_check_omega,
    hf_gain_bound,
)
from .modal import (
    modal_bounds,
    modal_matrices,
    modal_matrices_jacobian,
    modal_parameters,
    modal_response,
)

__all__ = ["CHECK_OMEGA", "CONTINUATION_DB", "CaseCheck", "check_pair", "refine_on_cases"]

#: Base grid of the dense check, rad/s (refined around the specification's and the loop's
#: lightly damped roots): the certificate's (:mod:`specdesign.qft.certificate`).
CHECK_OMEGA = np.geomspace(0.005, 20.0, 600)
#: Margins (dB) of the continuation in :func:`refine_on_cases`: from a start that misses by
#: several dB (7.6 dB at 25 m/s) one step to the final margin ends in an unstable loop, the
#: ladder does not.
CONTINUATION_DB = (-6.0, -3.0, -1.5, -0.5, 0.0)
#: Temperature of the smooth maximum in the last stage of :func:`refine_on_cases`, dB.
_SMOOTH_DB = 0.1
#: Relative spacing of the optimisation grid around the specifications' lightly damped roots
#: (:func:`specdesign.closedloop.refine_grid`'s ``rel_step``): 10× the dense check's, ≥ 20
#: points across a ζ = 0.01 peak; the margin covers the rest and the dense check judges.
_COARSE_STEP = 1e-3
#: Weight of the closed-loop poles' exterior penalty Σ max(0, Re p + decay)², (dB·s)². 10⁴
#: let the ratios' sum over the cases and the grid outweigh an unstable pole at 24 m/s (a pole
#: crossing between the optimisation grid's points is not seen in the ratios): the step ended
#: with Re p = +0.05 1/s; 10⁶ keeps every case stable at 15-25 m/s.
_POLE_WEIGHT = 1e6
#: Largest |Re λ| and Im λ of the adjusted controller's poles, rad/s (or the start's, if larger):
#: 50× the check grid's top, so the grid cannot tell a faster pole from a constant.
_MAX_RATE = 1e3
#: Frequencies above the check grid (rad/s) where the adjusted controller's gain is bounded, and
#: by how much it may exceed the start's there (dB).
_HF_OMEGA = np.geomspace(20.0, 400.0, 60)
_HF_ROOM_DB = 6.0
#: Objective value of a controller whose poles overflowed (a step far outside the model).
_WALL = 1e30
#: dB per neper: 20·log10|z| = _DB·Re log z.
_DB = 20 / np.log(10)


@dataclass(frozen=True)
class CaseCheck:
    """A pitch controller checked against a certified pair at every plant case (:func:`check_pair`).

    Parameters
    ----------
    case_speeds : tuple of float
        Wind speeds of the plant cases, m/s.
    tower_excess_db, speed_excess_db : tuple of float
        Per case, max over ω of 20·log10(|T|/|W_i|), dB (≤ 0 means met).
    tower_omega, speed_omega : tuple of float
        Where each maximum is, rad/s.
    max_sensitivity : float
        max over cases and ω of |1/(1 + C·P_{Ω,β})| (-).
    decay_rate : float
        min over cases of −max Re p of the closed loop's poles, 1/s (> 0: every case stable).
    omega : numpy.ndarray
        The check grid, rad/s.
    hf_excess_db : float
        Largest 20·log10(|C_β|/(κ·|C_ROSCO|)) on the pair's high-frequency band
        (HF_OMEGA-HF_END rad/s, the grid's points there and 3P), dB, with κ the pair's
        ``max_hf_gain_ratio``; −inf without a bound.
    proper : bool
        C_β strictly proper (no direct term), as the bound requires; True without one.
    """

    case_speeds: tuple
    tower_excess_db: tuple
    speed_excess_db: tuple
    tower_omega: tuple
    speed_omega: tuple
    max_sensitivity: float
    decay_rate: float
    omega: np.ndarray
    hf_excess_db: float = -np.inf
    proper: bool = True

    @property
    def met(self) -> bool:
        """Every case stable, both specifications met at every case (excess ≤ 0 dB) and the
        high-frequency gain bound met by a strictly proper controller.

        Returns
        -------
        bool
        """
        return bool(self.decay_rate > 0 and max(self.tower_excess_db) <= 0 and max(self.speed_excess_db) <= 0
                    and self.hf_excess_db <= 0 and self.proper)


class _Cases:
    """Plant cases, their pair weights and pitch-loop state spaces on one grid."""

    def __init__(self, model, target, omega, rel_step=1e-4):
        from .. import spec as sp
        from ..qft.checks import spec_ratio, spec_roots

        v = target.design.wind_speed
        self.speeds = tuple(target.case_speeds) or (v,)
        plants = [model.linearize(s) for s in self.speeds]
        self.loops = []
        for P in plants:
            p = ct.ss(P)["gen_speed", "pitch_cmd"]
            self.loops.append((np.asarray(p.A), np.asarray(p.B), np.asarray(p.C), np.asarray(p.D)))
        base = CHECK_OMEGA if omega is None else np.asarray(omega, float)
        roots = lightly_damped(np.concatenate([spec_roots(target.tower), spec_roots(target.speed)]))
        self.roots = roots
        self.base = base
        self.omega = refine_grid(base, roots, rel_step=rel_step)
        self.plants = plants
        kappa = target.max_hf_gain_ratio
        # the high-frequency gain bound of the pair's certificate: its band's points of the base
        # grid, its ends and 3P (refined around each checked controller's poles by _check)
        self.model = model
        self.hf_base = hf_check_omega(model, base)
        self._hf_bound = None if kappa is None else (lambda w: 20 * np.log10(hf_gain_bound(model, v, w, kappa)))
        self.hf = None
        self.regrid_hf(self.hf_base)
        self._rosco = sp.baseline_controllers(model, self.speeds)
        self._tower_ratio = spec_ratio(target.tower, sp.baseline_analysis(model, v).system)
        self._speed_ratio = spec_ratio(target.speed, sp.speed_specification(model, v).baseline)
        self.regrid(self.omega)

    def regrid(self, omega):
        """Evaluate the plants and the pair's weights at every case on ``omega`` (rad/s)."""
        self.R = plant_responses(self.plants, omega, ("gen_speed", "tower_base_my"), method="batched")
        c0 = np.stack([siso_response(r, omega) for r in self._rosco], axis=1)
        # W_i = T^ROSCO_i·(W/T^ROSCO_nom): the pair's convention at the non-nominal cases
        self.w_tower = np.abs(closed_map(self.R, c0, None, "tower_base_my")) * np.abs(self._tower_ratio(omega))[:, None]
        self.w_speed = np.abs(closed_map(self.R, c0, None, "gen_speed")) * np.abs(self._speed_ratio(omega))[:, None]
        self.ob = self.R[("gen_speed", "pitch_cmd")]

    def regrid_hf(self, omega):
        """The high-frequency gain bound's grid (rad/s, inside HF_OMEGA-HF_END) and its bound in dB."""
        if self._hf_bound is not None:
            w = np.asarray(omega, float)
            w = w[(w >= HF_OMEGA) & (w <= HF_END)]
            self.hf = (1j * w, self._hf_bound(w))

    def ratios(self, c):
        """(tower dB, speed dB, |S|), each (n_omega, n_cases), for C_β's response c on the grid."""
        c = np.asarray(c)[:, None]
        rt = 20 * np.log10(np.abs(closed_map(self.R, c, None, "tower_base_my")) / self.w_tower)
        rs = 20 * np.log10(np.abs(closed_map(self.R, c, None, "gen_speed")) / self.w_speed)
        return rt, rs, np.abs(1 / (1 + c * self.ob))

    def poles(self, a, b, c, d):
        """Closed-loop poles of every case with C_β = (a, b, c, d), β = −C_β·Ω_g."""
        out = []
        for A, B, C, D in self.loops:
            if np.any(D):  # pragma: no cover - the turbine models have none
                raise ValueError("the plant has a feedthrough pitch → generator speed; not supported")
            top = np.hstack([A - B @ d @ C, -B @ c])
            out.append(np.linalg.eigvals(np.vstack([top, np.hstack([b @ C, a])])))
        return np.concatenate(out)


def check_pair(model, target, pitch_controller: ct.LTI, *, omega: ArrayLike | None = None) -> CaseCheck:
    """The explicit check of a pitch controller against a certified pair at every plant case.

    The grid is ``omega`` (default :data:`CHECK_OMEGA`, 0.005-20 rad/s) refined around the
    lightly damped roots of both specifications and of every case's closed loop
    (:func:`specdesign.closedloop.refine_grid`), so no narrow feature falls between points.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine the pair was made on.
    target : specdesign.feasibility.TargetSpecification
        The pair and its plant cases.
    pitch_controller : control.LTI
        C_β (rad per rad/s), workbench sign β = −C_β·Ω_g.
    omega : array_like, optional
        Base grid, rad/s.

    Returns
    -------
    CaseCheck
        Per-case excesses (dB) and where, the peak sensitivity and the decay rate.

    Raises
    ------
    TypeError
        If ``target`` is not a TargetSpecification or ``pitch_controller`` not an LTI system.

    Examples
    --------
    >>> from specdesign import feasibility, turbine
    >>> from specdesign.hinf import check_pair
    >>> model = turbine.iea15mw()
    >>> ts = feasibility.specification_for_target(model, 19.0, 25.0)  # doctest: +SKIP
    >>> check_pair(model, ts, ts.design.controller(model)).met  # doctest: +SKIP
    True
    """
    _require(target, pitch_controller)
    return _check(_Cases(model, target, omega), ct.ss(pitch_controller))


def _check(cases, k):
    """:func:`check_pair` on plant cases already built (regridded to the dense check grid)."""
    a, b, c, d = (np.asarray(x, float) for x in (k.A, k.B, k.C, k.D))
    poles = cases.poles(a, b, c, d)
    grid = refine_grid(refine_grid(cases.base, cases.roots), poles)
    if grid.size != cases.omega.size or np.any(grid != cases.omega):
        cases.omega = grid
        cases.regrid(grid)
    rt, rs, sens = cases.ratios(siso_response(k, grid))
    hf, proper = -np.inf, True
    if cases.hf is not None:
        hf_grid = hf_check_omega(cases.model, cases.base, np.linalg.eigvals(a) if a.size else ())
        if hf_grid.size != cases.hf[0].size or np.any(hf_grid != cases.hf[0].imag):
            cases.regrid_hf(hf_grid)
        s_hf, log_bound = cases.hf
        hf = float(np.max(20 * np.log10(np.abs(siso_response(k, s_hf.imag))) - log_bound))
        proper = not np.any(d)
    return CaseCheck(case_speeds=cases.speeds, tower_excess_db=tuple(float(x) for x in rt.max(0)),
                     speed_excess_db=tuple(float(x) for x in rs.max(0)),
                     tower_omega=tuple(float(grid[i]) for i in rt.argmax(0)),
                     speed_omega=tuple(float(grid[i]) for i in rs.argmax(0)),
                     max_sensitivity=float(sens.max()), decay_rate=float(-poles.real.max()), omega=grid,
                     hf_excess_db=hf, proper=bool(proper))


def _require(target, controller):
    if not isinstance(target, TargetSpecification):
        raise TypeError(f"target must be a feasibility.TargetSpecification, got {type(target).__name__}")
    if not isinstance(controller, ct.LTI):
        raise TypeError(f"the pitch controller must be a control.LTI system, got {type(controller).__name__}")


class _Objective:
    """The exterior penalty of :func:`refine_on_cases` and its smooth-maximum stage, with analytic
    gradients: every ratio is 20·log10|T(C(jω))| with T rational in C, so
    d(dB)/dx = (20/ln 10)·Re((dT/dC)/T · dC/dx), dC/dx closed-form (:func:`modal_response`);
    a closed-loop pole moves by dλ = wᴴ·dA_cl·v/(wᴴv) (left/right eigenvectors)."""

    def __init__(self, cases, kinds, decay_rate, max_sensitivity, x0):
        self.cases, self.kinds, self.decay_rate = cases, kinds, decay_rate
        self.log_ms = 20 * np.log10(max_sensitivity)
        self.s = 1j * cases.omega
        # above the check grid nothing judges the loop: C may not rise there by more than
        # _HF_ROOM_DB over the start (unbounded, a pair at 21 rad/s lifted |C| 20 dB and the loop
        # sampled at 0.02 s was unstable)
        self.s_hf = 1j * _HF_OMEGA
        self.log_cap = _DB * np.log(np.abs(modal_response(kinds, x0, self.s_hf))) + _HF_ROOM_DB
        R = cases.R
        self.yw, self.ow, self.ob = R[("tower_base_my", "wind")], R[("gen_speed", "wind")], cases.ob
        # T_MyT = (P_yw + C·X)/(1 + C·P_Ωβ), X = P_yw·P_Ωβ − P_yβ·P_Ωw: dT/dC = −P_yβ·P_Ωw/(1 + C·P_Ωβ)²
        self.x_tower = self.yw * self.ob - R[("tower_base_my", "pitch_cmd")] * self.ow
        self.g_tower = -R[("tower_base_my", "pitch_cmd")] * self.ow
        self.log_wt, self.log_ws = 20 * np.log10(cases.w_tower), 20 * np.log10(cases.w_speed)

    def _maps(self, x):
        c, jac = modal_response(self.kinds, x, self.s, jacobian=True)
        c = c[:, None]
        num, den = self.yw + c * self.x_tower, 1 + c * self.ob
        rt = _DB * np.log(np.abs(num / den)) - self.log_wt
        rs = _DB * np.log(np.abs(self.ow / den)) - self.log_ws
        sens = -_DB * np.log(np.abs(den))
        # d log T/dC: tower −P_yβ·P_Ωw/(num·den); speed and sensitivity −P_Ωβ/den (both ∝ 1/den)
        return rt, rs, sens, self.g_tower / (num * den), -self.ob / den, jac

    def _poles(self, x):
        """Penalty :data:`_POLE_WEIGHT`·Σ max(0, Re p + decay)² over every case's closed-loop poles, and its gradient."""
        a, b, c, d = modal_matrices(self.kinds, x)
        f, grad, dmats = 0.0, np.zeros(x.size), None
        if not np.all(np.isfinite(a)):  # a pole pushed to overflow: a wall the line search backs off from
            return _WALL, grad
        for A, B, C, D in self.cases.loops:
            M = np.block([[A - B @ d @ C, -B @ c], [b @ C, a]])
            lam = np.linalg.eigvals(M)
            h = np.maximum(lam.real + self.decay_rate, 0.0)
            if not np.any(h > 0):
                continue
            f += _POLE_WEIGHT * float(np.sum(h ** 2))
            if dmats is None:
                dmats = modal_matrices_jacobian(self.kinds, x)
            lam, wl, vr = linalg.eig(M, left=True, right=True)
            act = np.flatnonzero(lam.real + self.decay_rate > 0)
            wl, vr = wl[:, act], vr[:, act]
            scale = 2 * _POLE_WEIGHT * (lam.real[act] + self.decay_rate) / np.einsum("ij,ij->j", wl.conj(), vr)
            for k, (da, db, dc, dd) in enumerate(dmats):
                dM = np.block([[-B @ dd @ C, -B @ dc], [db @ C, da]])
                grad[k] += float(np.sum((scale * np.einsum("ij,ik,kj->j", wl.conj(), dM, vr)).real))
        return f, grad

    def penalty(self, x, margin):
        """Exterior penalty at ``margin`` (dB) and its gradient."""
        fp, gp = self._poles(x)
        if fp >= _WALL:
            return fp, gp
        rt, rs, sens, gt, gs, jac = self._maps(x)
        ht, hs, hS = (np.maximum(r, 0.0) for r in (rt + margin, rs + margin, sens - self.log_ms))
        w = np.sum(2 * (ht * gt + (hs + hS) * gs), axis=1)
        c, jc = modal_response(self.kinds, x, self.s_hf, jacobian=True)
        hc = np.maximum(_DB * np.log(np.abs(c)) - self.log_cap, 0.0)
        f = float(np.sum(ht ** 2) + np.sum(hs ** 2) + np.sum(hS ** 2) + np.sum(hc ** 2)) + fp
        g = _DB * (w @ jac).real + _DB * ((2 * hc / c) @ jc).real + gp
        if self.cases.hf is not None:  # the pair's high-frequency gain bound, with the margin
            s_b, log_bound = self.cases.hf
            cb, jb = modal_response(self.kinds, x, s_b, jacobian=True)
            hb = np.maximum(_DB * np.log(np.abs(cb)) - log_bound + margin, 0.0)
            f += float(np.sum(hb ** 2))
            g = g + _DB * ((2 * hb / cb) @ jb).real
        return f, g

    def worst(self, x, margin):
        """Smooth maximum (log-sum-exp, :data:`_SMOOTH_DB`) of every ratio plus the penalty at
        ``margin``, and its gradient: the multi-model H∞ objective itself."""
        f, g = self.penalty(x, margin)
        if f >= _WALL:
            return f, g
        rt, rs, _, gt, gs, jac = self._maps(x)
        top = max(rt.max(), rs.max())
        et, es = np.exp((rt - top) / _SMOOTH_DB), np.exp((rs - top) / _SMOOTH_DB)
        total = et.sum() + es.sum()
        w = np.sum(et * gt + es * gs, axis=1) / total
        return float(top + _SMOOTH_DB * np.log(total)) + f, _DB * (w @ jac).real + g


def refine_on_cases(model, target, pitch_controller: ct.LTI, *, margin_db: float = 0.15, decay_rate: float = MIN_DECAY_RATE,
                    max_sensitivity: float = DESIGN_MAX_SENSITIVITY, margins_db: tuple = CONTINUATION_DB, omega: ArrayLike | None = None,
                    max_iterations: int = 5000) -> tuple[ct.StateSpace, CaseCheck]:
    """The multi-model H∞ step: adjust a pitch controller until it meets a certified pair at every case.

    The poles, residues and feedthrough of ``pitch_controller`` (same order; an integrator, a
    pole with |λ| < 1e-6 rad/s, stays at s = 0; stable poles stay stable, no pole faster than 10³ rad/s;
    :mod:`specdesign.hinf.modal`) minimise the exterior penalty
    Σ max(0, 20·log10(|T_i|/|W_i|) + margin)² over both channels, every plant case and the
    optimisation grid, plus Σ max(0, 20·log10(|S_i|/``max_sensitivity``))² and
    10⁶·Σ max(0, Re p + ``decay_rate``)² over the closed-loop poles of every case, plus
    Σ max(0, 20·log10(|C(jω)|/|C_start(jω)|) − 6)² at 20-400 rad/s, above the grid, where
    nothing else holds the controller's gain (a sampled implementation needs it), and, for a pair
    made under the high-frequency gain bound (``target.max_hf_gain_ratio`` = κ),
    Σ max(0, 20·log10(|C(jω)|/(κ·|C_ROSCO(jω)|)) + margin)² on HF_OMEGA-HF_END (3P included)
    with the feedthrough held at 0 (C strictly proper) (L-BFGS-B
    with the analytic gradient: every ratio is rational in C(jω), which is linear in the
    residues and feedthrough; BLAS on one thread; deterministic). The penalty is zero exactly when
    max_i ‖W_i⁻¹T_i‖∞ ≤ 10^(−margin/20) per channel with the loop's decay and margin.
    ``margins_db`` are tightened in turn before ``margin_db`` (a continuation from a far start).
    A last stage minimises the smooth maximum (log-sum-exp, 0.1 dB) of every ratio over the
    cases, channels and grid plus that penalty: min γ of the multi-model problem, so the result
    is not merely the first feasible point the penalty stage reached (which moved the predicted
    reduction by 4 pp between 19 and 19 + 1e-9 m/s). The optimisation grid is ``omega``
    refined around the pair's lightly damped roots with 10× the dense check's spacing (≥ 20
    points across a ζ = 0.01 peak); the result is checked by :func:`check_pair` on the
    dense grid, and when that finds a miss the last stage is repeated on the dense grid.

    Parameters
    ----------
    model, target
        The turbine and the certified pair, as :func:`check_pair` takes them.
    pitch_controller : control.LTI
        Starting C_β (rad per rad/s, β = −C_β·Ω_g), e.g. the reduced H∞ controller.
    margin_db : float
        Required distance below each specification on the grid, dB (≥ 0): room for the
        final check's finer grid.
    decay_rate : float
        Required decay of every case's closed loop, 1/s (> 0).
    max_sensitivity : float
        Bound on |1/(1 + C·P_{Ω,β})| (> 1).
    margins_db : tuple of float
        Looser margins (dB, may be negative) tried first, in order (default
        :data:`CONTINUATION_DB`); each is skipped when already met.
    omega : array_like, optional
        Base grid, rad/s (default :data:`CHECK_OMEGA`).
    max_iterations : int
        Cap on the L-BFGS-B iterations of each stage: a guard, not the stopping rule (each
        stage converges in at most ≈ 1500 iterations at 15-25 m/s on the IEA 15 MW model); a
        stage stopped by it is warned about, since where it stops would depend on round-off.

    Returns
    -------
    controller : control.StateSpace
        The adjusted C_β (or ``pitch_controller`` unchanged when its A is defective and its
        poles cannot be parametrised).
    check : CaseCheck
        :func:`check_pair` of the returned controller.

    Raises
    ------
    TypeError
        If ``target`` is not a TargetSpecification or ``pitch_controller`` not an LTI system.
    ValueError
        If ``margin_db`` < 0, ``decay_rate`` ≤ 0 or ``max_sensitivity`` ≤ 1.

    Examples
    --------
    >>> from specdesign import feasibility, turbine
    >>> from specdesign.hinf import design_hinf, refine_on_cases, spec_from_certified
    >>> model = turbine.iea15mw()
    >>> ts = feasibility.specification_for_target(model, 19.0, 25.0)  # doctest: +SKIP
    >>> start = -design_hinf(model, 19.0, spec=spec_from_certified(ts)).reduction.controller  # the Riccati controller  # doctest: +SKIP
    >>> c, chk = refine_on_cases(model, ts, start)  # doctest: +SKIP
    >>> chk.met  # doctest: +SKIP
    True
    """
    _require(target, pitch_controller)
    if not (np.isfinite(margin_db) and margin_db >= 0):
        raise ValueError(f"margin_db={margin_db!r} must be a margin ≥ 0 dB")
    if not (np.isfinite(decay_rate) and decay_rate > 0):
        raise ValueError(f"decay_rate={decay_rate!r} must be a decay rate > 0 (1/s)")
    if not max_sensitivity > 1:
        raise ValueError(f"max_sensitivity={max_sensitivity!r} must be > 1 (|1/(1+L)| bound)")
    k = ct.ss(pitch_controller)
    modal = modal_parameters(k)
    if modal is None:
        return k, check_pair(model, target, k, omega=omega)
    kinds, x = modal
    cases = _Cases(model, target, omega, rel_step=_COARSE_STEP)
    capped, bounds = [], modal_bounds(kinds, x, _MAX_RATE)
    if cases.hf is not None:  # strictly proper under the high-frequency gain bound: D (the last parameter) = 0
        x = np.r_[x[:-1], 0.0]
        bounds[-1] = (0.0, 0.0)
    x0 = x

    def run(fun, x, margin):
        res = optimize.minimize(fun, x, args=(margin,), jac=True, method="L-BFGS-B", bounds=bounds,
                                options={"maxiter": int(max_iterations)})
        if res.nit >= max_iterations:
            capped.append(f"{fun.__name__} at {margin:g} dB")
        return res.x

    with warnings.catch_warnings(), one_blas_thread():
        warnings.simplefilter("ignore", RuntimeWarning)
        obj = _Objective(cases, kinds, decay_rate, max_sensitivity, x0)
        for margin in (*margins_db, margin_db):
            if obj.penalty(x, margin)[0] > 0:
                x = run(obj.penalty, x, margin)
        # the smooth maximum of every ratio: every zero-penalty point is feasible, and minimising
        # the worst ratio picks one point of that set, so the design does not depend on where
        # the penalty stage stopped
        x = run(obj.worst, x, margin_db)
        out = ct.ss(*modal_matrices(kinds, x))
        check = _check(cases, out)
        if not check.met:  # a feature the coarse grid did not resolve: again on the dense check grid,
            # where _check has just regridded the cases
            x = run(_Objective(cases, kinds, decay_rate, max_sensitivity, x0).worst, x, margin_db)
            out = ct.ss(*modal_matrices(kinds, x))
            check = _check(cases, out)
    if capped:
        warnings.warn(f"refine_on_cases: L-BFGS-B stopped at max_iterations={max_iterations} ({', '.join(capped)}), "
                      "not converged: raise max_iterations", RuntimeWarning, stacklevel=2)
    return out, check
