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
MATLAB's ``hinfstruct``/``systune``), here an exterior penalty minimised by L-BFGS-B.

Units: ω in rad/s, wind speeds in m/s, excesses and margins in dB, decay rates in 1/s; the
pitch controller C_β in the workbench sign β = −C_β·Ω_g (rad per rad/s).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import control as ct
import numpy as np
from numpy.typing import ArrayLike
from scipy import optimize

from ..closedloop import closed_map, lightly_damped, plant_responses, refine_grid, siso_response

__all__ = ["CaseCheck", "check_pair", "refine_on_cases", "CHECK_OMEGA", "CONTINUATION_DB"]

#: Base grid of the dense check, rad/s (refined around the specification's and the loop's
#: lightly damped roots): the certificate's (:mod:`specdesign.qft.certificate`).
CHECK_OMEGA = np.geomspace(0.005, 20.0, 600)
#: Margins (dB) of the continuation in :func:`refine_on_cases`: from a start that misses by
#: several dB (7.6 dB at 25 m/s) one step to the final margin ends in an unstable loop, the
#: ladder does not.
CONTINUATION_DB = (-6.0, -3.0, -1.5, -0.5, 0.0)
#: Temperature of the smooth maximum in the last stage of :func:`refine_on_cases`, dB.
_SMOOTH_DB = 0.1
#: Below this |λ| (rad/s) a controller pole is its integrator, kept at s = 0 exactly.
_INTEGRATOR_TOL = 1e-6


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
    """

    case_speeds: tuple
    tower_excess_db: tuple
    speed_excess_db: tuple
    tower_omega: tuple
    speed_omega: tuple
    max_sensitivity: float
    decay_rate: float
    omega: np.ndarray

    @property
    def met(self) -> bool:
        """Every case stable and both specifications met at every case (excess ≤ 0 dB).

        Returns
        -------
        bool
        """
        return bool(self.decay_rate > 0 and max(self.tower_excess_db) <= 0 and max(self.speed_excess_db) <= 0)


class _Cases:
    """Plant cases, their pair weights and pitch-loop state spaces on one grid."""

    def __init__(self, model, target, omega):
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
        self.omega = refine_grid(base, roots)
        self.plants = plants
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
    k = ct.ss(pitch_controller)
    a, b, c, d = (np.asarray(x, float) for x in (k.A, k.B, k.C, k.D))
    cases = _Cases(model, target, omega)
    poles = cases.poles(a, b, c, d)
    grid = refine_grid(cases.omega, poles)
    if grid.size != cases.omega.size:
        cases.regrid(grid)
    rt, rs, sens = cases.ratios(siso_response(k, grid))
    return CaseCheck(case_speeds=cases.speeds, tower_excess_db=tuple(float(x) for x in rt.max(0)),
                     speed_excess_db=tuple(float(x) for x in rs.max(0)),
                     tower_omega=tuple(float(grid[i]) for i in rt.argmax(0)),
                     speed_omega=tuple(float(grid[i]) for i in rs.argmax(0)),
                     max_sensitivity=float(sens.max()), decay_rate=float(-poles.real.max()), omega=grid)


def _require(target, controller):
    from ..feasibility import TargetSpecification

    if not isinstance(target, TargetSpecification):
        raise TypeError(f"target must be a feasibility.TargetSpecification, got {type(target).__name__}")
    if not isinstance(controller, ct.LTI):
        raise TypeError(f"the pitch controller must be a control.LTI system, got {type(controller).__name__}")


def _modal(k):
    """C_β as (kinds, x): an integrator ('i': residue), real poles ('r': log(−λ), residue) and
    complex pairs ('c': log(−Re λ), log(Im λ), residue re/im), then D; a pole with Re λ ≥ 0
    (H∞ controllers may have one) is 'ru'/'cu', its real part a parameter as it is (a log would
    keep it unstable). None when A is defective."""
    lam, vec = np.linalg.eig(np.asarray(k.A, float))
    if np.linalg.cond(vec) > 1e8:
        return None
    res = (np.asarray(k.C, float) @ vec).ravel() * np.linalg.solve(vec, np.asarray(k.B, float)).ravel()
    idx = np.argsort(np.abs(lam) + 1e-12 * lam.imag, kind="stable")
    kinds, x, used = [], [], set()
    for i in idx:
        if i in used:
            continue
        used.add(i)
        lam_i, r = lam[i], res[i]
        if abs(lam_i) < _INTEGRATOR_TOL:
            kinds.append("i")
            x.append(r.real)
        elif abs(lam_i.imag) <= 1e-9 * abs(lam_i):
            kinds.append("r" if lam_i.real < 0 else "ru")
            x += [np.log(-lam_i.real) if lam_i.real < 0 else lam_i.real, r.real]
        else:
            j = min((j for j in idx if j not in used), key=lambda j: abs(lam[j] - np.conj(lam_i)))
            used.add(j)
            if lam_i.imag < 0:
                lam_i, r = np.conj(lam_i), np.conj(r)
            kinds.append("c" if lam_i.real < 0 else "cu")
            x += [np.log(-lam_i.real) if lam_i.real < 0 else lam_i.real, np.log(lam_i.imag), r.real, r.imag]
    return tuple(kinds), np.array(x + [float(np.asarray(k.D).ravel()[0])])


def _real_part(kind, value):
    return value if kind.endswith("u") else -np.exp(value)


def _response(kinds, x, s):
    out, p = np.zeros_like(s), 0
    for kind in kinds:
        if kind == "i":
            out, p = out + x[p] / s, p + 1
        elif kind in ("r", "ru"):
            out, p = out + x[p + 1] / (s - _real_part(kind, x[p])), p + 2
        else:
            lam, r = _real_part(kind, x[p]) + 1j * np.exp(x[p + 1]), x[p + 2] + 1j * x[p + 3]
            out, p = out + r / (s - lam) + np.conj(r) / (s - np.conj(lam)), p + 4
    return out + x[p]


def _matrices(kinds, x):
    """Real block-diagonal (A, B, C, D) of the modal parameters."""
    blocks, bs, cs, p = [], [], [], 0
    for kind in kinds:
        if kind == "i":
            blocks.append([[0.0]]), bs.append([1.0]), cs.append([x[p]])
            p += 1
        elif kind in ("r", "ru"):
            blocks.append([[_real_part(kind, x[p])]]), bs.append([1.0]), cs.append([x[p + 1]])
            p += 2
        else:
            sg, om, rr, ri = _real_part(kind, x[p]), np.exp(x[p + 1]), x[p + 2], x[p + 3]
            # r/(s − λ) + c.c. = (2·rr·s − 2(rr·σ + ri·ω))/((s − σ)² + ω²): the block [[σ, ω], [−ω, σ]]
            blocks.append([[sg, om], [-om, sg]]), bs.append([0.0, 1.0]), cs.append([-2 * ri, 2 * rr])
            p += 4
    from scipy.linalg import block_diag

    a = block_diag(*[np.asarray(b, float) for b in blocks]) if blocks else np.zeros((0, 0))
    b = np.concatenate(bs)[:, None] if bs else np.zeros((0, 1))
    c = np.concatenate(cs)[None, :] if cs else np.zeros((1, 0))
    return a, b, c, np.array([[x[p]]])


def refine_on_cases(model, target, pitch_controller: ct.LTI, *, margin_db: float = 0.15, decay_rate: float = 0.02,
                    max_sensitivity: float = 1.9, margins_db: tuple = CONTINUATION_DB, omega: ArrayLike | None = None,
                    max_iterations: int = 500) -> tuple[ct.StateSpace, CaseCheck]:
    """The multi-model H∞ step: adjust a pitch controller until it meets a certified pair at every case.

    The poles, residues and feedthrough of ``pitch_controller`` (same order; an integrator, a
    pole with |λ| < 1e-6 rad/s, stays at s = 0; stable poles stay stable) minimise the exterior penalty
    Σ max(0, 20·log10(|T_i|/|W_i|) + margin)² over both channels, every plant case and the
    check grid, plus Σ max(0, 20·log10(|S_i|/``max_sensitivity``))² and
    10⁴·Σ max(0, Re p + ``decay_rate``)² over the closed-loop poles of every case (L-BFGS-B,
    finite-difference gradient; deterministic). The penalty is zero exactly when
    max_i ‖W_i⁻¹T_i‖∞ ≤ 10^(−margin/20) per channel with the loop's decay and margin.
    ``margins_db`` are tightened in turn before ``margin_db`` (a continuation from a far start).
    A last stage minimises the smooth maximum (log-sum-exp, 0.1 dB) of every ratio over the
    cases, channels and grid plus that penalty: min γ of the multi-model problem, so the result
    is not merely the first feasible point the penalty stage reached (which moved the predicted
    reduction by 4 pp between 19 and 19 + 1e-9 m/s). The result is then checked by
    :func:`check_pair` on its own refined grid.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine the pair was made on.
    target : specdesign.feasibility.TargetSpecification
        The pair and its plant cases.
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
        L-BFGS-B iterations per margin.

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
    >>> from specdesign.hinf import design_hinf, refine_on_cases
    >>> model = turbine.iea15mw()
    >>> ts = feasibility.specification_for_target(model, 19.0, 25.0)  # doctest: +SKIP
    >>> c, chk = refine_on_cases(model, ts, design_hinf(model, 19.0, specs=ts).pitch_controller)  # doctest: +SKIP
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
    modal = _modal(k)
    if modal is None:
        return k, check_pair(model, target, k, omega=omega)
    kinds, x = modal
    cases = _Cases(model, target, omega)
    s = 1j * cases.omega
    log_ms = 20 * np.log10(max_sensitivity)

    def penalty(x, margin):
        rt, rs, sens = cases.ratios(_response(kinds, x, s))
        g = np.concatenate([(rt + margin).ravel(), (rs + margin).ravel(), (20 * np.log10(sens) - log_ms).ravel()])
        st = np.maximum(cases.poles(*_matrices(kinds, x)).real + decay_rate, 0.0)
        return float(np.sum(np.maximum(g, 0.0) ** 2) + 1e4 * np.sum(st ** 2))

    def worst(x):
        # smooth max (log-sum-exp, 0.1 dB) of every ratio: the multi-model H∞ objective itself.
        # Every zero-penalty point is feasible; minimising the worst ratio picks one point of that
        # set, so the design does not depend on where the penalty stage stopped.
        rt, rs, _ = cases.ratios(_response(kinds, x, s))
        g = np.concatenate([rt.ravel(), rs.ravel()]) / _SMOOTH_DB
        top = g.max()
        return float(_SMOOTH_DB * (top + np.log(np.sum(np.exp(g - top))))) + penalty(x, margin_db)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        for margin in (*margins_db, margin_db):
            if penalty(x, margin) > 0:
                x = optimize.minimize(penalty, x, args=(margin,), method="L-BFGS-B",
                                      options=dict(maxiter=int(max_iterations))).x
        x = optimize.minimize(worst, x, method="L-BFGS-B", options=dict(maxiter=int(max_iterations))).x
    a, b, c, d = _matrices(kinds, x)
    out = ct.ss(a, b, c, d)
    return out, check_pair(model, target, out, omega=omega)
