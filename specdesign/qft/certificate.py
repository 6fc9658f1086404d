"""The QFT step on a target specification: the certificate's controller, reduced, checked as any QFT design.

A :class:`specdesign.feasibility.TargetSpecification` carries a certificate: a stabilising
pitch controller that meets its pair (W_MyT, W_Ω) at every plant case. The fixed structure
of :mod:`specdesign.qft.design` (PI + notch + low-pass, first-order ATD) cannot follow the
shape of such a specification (a ≥ 25 % promise asks for T_{MyT,w} reduced over the whole
wind band); the certificate can. :func:`design_from_certificate` balances-and-truncates it
to the lowest order (from ``min_order`` up) whose loop meets every specification on the
dense grid over every plant case, then runs the same checks and records the same
:class:`~specdesign.qft.result.QFTDesign` as the fixed-structure design (exact bounds at the
design frequencies, dense checks of both loops, stability of every case). No ATD (pitch
only), no tuning, no DEL penalty: the specification carries the target.

Units: ω in rad/s, wind speeds in m/s, reductions in %, relaxations in dB.
"""
from __future__ import annotations

import warnings
from typing import Any

import control as ct
import numpy as np

from loopshaping import qft as lqft
from loopshaping import reduction

from ..closedloop import (
    DESIGN_MAX_SENSITIVITY,
    MIN_DECAY_RATE,
    closed_loop,
    closed_map,
    fine_pitch_lift,
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
from .checks import spec_ratio, spec_roots
from .result import DEFAULT_DESIGN_OMEGA, assemble_design
from .tuner import TuningProblem

__all__ = ["ORDER_AXIS_TOL", "ORDER_MARGIN_DB", "design_from_certificate"]

#: A pole p of the certificate counts as stable, and is balanced-truncated, only if
#: Re p < −ORDER_AXIS_TOL·max(1, |p|); the rest (the integrator S(0) = 0 puts at ±1e-16 rad/s)
#: is kept exactly (:func:`loopshaping.reduction.reduce`). Deciding by the sign of a pole at
#: ±1e-16 (python-control's ``balred``) truncated the integrator at one speed and kept it at
#: the speed 1e-9 m/s away: order 19 at 23 m/s, 12 at 23 + 1e-9 m/s.
ORDER_AXIS_TOL = 1e-6
#: Margin (dB) by which a reduced controller must meet every specification and the M_s bound
#: on the dense grid over every plant case to be chosen, and relative margin on the decay
#: rate: the lowest order that meets them by less is not chosen, so that an order that meets
#: them by a hair at one operating point and misses by a hair 1e-9 m/s away does not decide.
ORDER_MARGIN_DB = 0.01


def design_from_certificate(model, target, *, max_sensitivity: float = DESIGN_MAX_SENSITIVITY, min_decay: float = MIN_DECAY_RATE,
                            min_order: int = 4, design_omega=None, dense_omega=None) -> Any:
    """QFT design at a target specification's operating point from its certificate.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine the specification was made on.
    target : specdesign.feasibility.TargetSpecification
        The specification pair, its plant cases and its certificate.
    max_sensitivity : float
        Bound on |1/(1+L)| of the pitch loop and at the actuator (> 1).
    min_decay : float
        Required closed-loop decay rate of every case, 1/s.
    min_order : int
        Lowest controller order tried (states, ≥ 1).
    design_omega : array_like, optional
        QFT design frequencies, rad/s (default
        :data:`specdesign.qft.result.DEFAULT_DESIGN_OMEGA` plus the specification's sharp features).
    dense_omega : array_like, optional
        Grid of the final check, rad/s (default 600 points, 0.005-20 rad/s, refined around the
        lightly damped roots of the specification).

    Returns
    -------
    specdesign.qft.result.QFTDesign
        The design (``atd_controller`` zero; ``parameters`` holds the order), ``success`` when
        every check passes; ``promise`` is the specification's and ``target_reduction`` its
        exact DEL promise. Every plant case meets its own W_i = T^ROSCO_i·W/T^ROSCO (the
        specification at that case's speed); ``options["strict_excess_db"]`` gives the largest
        excess of any case over the nominal W_MyT and W_Ω themselves (dB, the pair read strictly:
        > 0 where a case exceeds the W the user sees). With the high-frequency gain bound of
        ``target.max_hf_gain_ratio`` the controller also meets |C_β| ≤ κ·|C_ROSCO| on
        HF_OMEGA-HF_END (the dense grid's points there and 3P) with the order margin and is
        strictly proper (its certificate is, and balanced truncation keeps D = 0); the check
        "hf_gain" of ``pitch_check`` says so, and ``options["max_hf_gain_ratio"]`` records κ.

    Raises
    ------
    TypeError
        If ``target`` is not a TargetSpecification.
    ValueError
        If ``max_sensitivity`` ≤ 1, ``min_decay`` ≤ 0 or ``min_order`` < 1.
    """
    from .. import spec as sp

    if not isinstance(target, TargetSpecification):
        raise TypeError(f"target must be a feasibility.TargetSpecification, got {type(target).__name__}")
    if not max_sensitivity > 1:
        raise ValueError(f"max_sensitivity={max_sensitivity!r} must be > 1 (|1/(1+L)| bound)")
    if not min_decay > 0:
        raise ValueError(f"min_decay={min_decay!r} must be a decay rate > 0 (1/s)")
    if int(min_order) != min_order or min_order < 1:
        raise ValueError(f"min_order={min_order!r} must be an order ≥ 1 (states)")
    v = target.design.wind_speed
    speeds = tuple(target.case_speeds) or (v,)
    nom = speeds.index(v)
    base = sp.baseline_analysis(model, v)
    wd = DEFAULT_DESIGN_OMEGA.copy() if design_omega is None else lqft.check_grid(design_omega, "design_omega")
    wdense = (np.logspace(np.log10(0.005), np.log10(20.0), 600) if dense_omega is None
              else lqft.check_grid(dense_omega, "dense_omega"))
    tower_shaping = spec_ratio(target.tower, base.system)
    speed_shaping = spec_ratio(target.speed, sp.speed_specification(model, v).baseline)
    kappa = target.max_hf_gain_ratio
    bound = None if kappa is None else (lambda w: hf_gain_bound(model, v, w, kappa), (HF_OMEGA, HF_END))
    prob = TuningProblem(model, v, speeds, nom, wd, tower_shaping, 0.0, max_sensitivity, base,
                         speed_shaping=speed_shaping, response_method="batched", controller_bound=bound)
    roots = lightly_damped(np.concatenate([spec_roots(target.tower), spec_roots(target.speed)]))
    sharp = np.abs(roots[roots.imag > 0])
    sharp = sharp[(sharp >= wdense[0]) & (sharp <= wdense[-1])]
    if sharp.size:
        prob.set_design(np.unique(np.r_[prob.wd, sharp]))
    wdense = refine_grid(wdense, roots)
    if kappa is not None:  # the bound's check includes its band's ends and 3P (hf_check_omega)
        wdense = np.union1d(wdense, hf_check_omega(model, wdense))
    full = ct.ss(target.design.controller(model))
    strict = (np.abs(np.asarray(target.speed.response(wdense))), np.abs(np.asarray(target.tower.response(wdense))))
    cb, order, strict_excess = _lowest_order(prob, full, wdense, int(min_order), max_sensitivity, min_decay, strict,
                                             target.held_lift_limit)
    ca = ct.tf([0.0], [1.0])
    c = siso_response(cb, base.omega)[:, None]
    performance = prob.performance_of(c, np.zeros_like(c))
    promise = target.promise
    shaping = sp.ShapingResult((), promise, float("nan"), "del", True, "target specification", target.tower)
    return assemble_design(model, prob, cb, ca, wdense, float(promise.exact_del), performance, base=base,
                           tower_spec=target.tower, speed_spec=target.speed, shaping=shaping, promise=promise,
                           parameters={"order": float(order)},
                           options=dict(structure="certificate", template_offsets=target.template_offsets,
                                        speed_relax_db=target.speed_relax_db, tower_slack_db=target.slack_db,
                                        strict_excess_db=strict_excess, max_hf_gain_ratio=kappa,
                                        held_lift_limit=target.held_lift_limit,
                                        max_sensitivity=max_sensitivity, min_decay=min_decay))


def _lowest_order(prob, full, omega, min_order, ms, min_decay, strict, held=None):
    """The lowest-order balanced truncation of ``full`` (its stable part; poles within
    :data:`ORDER_AXIS_TOL` of the axis kept) that meets every specification on ``omega`` at every
    plant case, keeps |S| ≤ ``ms``, meets ``prob.controller_bound`` (if any) strictly proper, keeps
    its fine-pitch lift within ``held`` = (deficit rad/s, limit rad) if given, and is stable with
    decay ≥ ``min_decay``, each with the margin :data:`ORDER_MARGIN_DB`; else ``full``. Each case meets its own W_i (ROSCO's map at its speed
    times the nominal ratio). Returns (controller, order, (largest excess over the nominal W_MyT,
    over the nominal W_Ω) dB at any case: the pair read strictly, ``strict`` = (|W_Ω|, |W_MyT|) on
    ``omega``, reported beside it))."""
    R = plant_responses(prob.plants, omega, ("gen_speed", "tower_base_my", "tower_top_vel"), method="batched")
    w_speed, w_tower = prob.weights(omega)
    ob = R[("gen_speed", "pitch_cmd")]
    shrink = 10 ** (-ORDER_MARGIN_DB / 20)
    hf = None if prob.controller_bound is None else prob.controller_bound[0](omega)
    for n in range(min_order, full.nstates + 1):
        if n < full.nstates:
            try:
                cand = reduction.reduce(full, n, axis_tol=ORDER_AXIS_TOL).controller
            except (ValueError, np.linalg.LinAlgError, ct.ControlArgument):
                continue  # e.g. n below the kept (marginal or unstable) part's order
        else:
            cand = full
        c = siso_response(cand, omega)[:, None]
        if (np.any(np.abs(closed_map(R, c, 0.0, "tower_base_my")) > shrink * w_tower)
                or np.any(np.abs(closed_map(R, c, 0.0, "gen_speed")) > shrink * w_speed)
                or np.any(np.abs(1 / (1 + c * ob)) > shrink * ms)
                or (hf is not None and (np.any(np.abs(c[:, 0]) > shrink * hf) or np.any(np.asarray(ct.ss(cand).D) != 0)))):
            continue
        with warnings.catch_warnings():  # python-control's notes on the interconnections (unused signals)
            warnings.filterwarnings("ignore", category=UserWarning, module=r"control\.")
            decay = min(-np.max(np.real(closed_loop(p, cand, warn=False).poles())) for p in prob.plants)
        if decay >= min_decay / shrink and (held is None or fine_pitch_lift(cand, held[0]) <= held[1]):
            return cand, n, _strict_excess(R, cand, omega, strict)
    return full, full.nstates, _strict_excess(R, full, omega, strict)


def _strict_excess(R, controller, omega, strict):
    """(largest |T_MyT,w|/|W_MyT|, largest |T_Ω,w|/|W_Ω|) over the plant cases, dB, against the nominal W."""
    c = siso_response(controller, omega)[:, None]
    return (float(20 * np.log10(np.max(np.abs(closed_map(R, c, 0.0, "tower_base_my")) / strict[1][:, None]))),
            float(20 * np.log10(np.max(np.abs(closed_map(R, c, 0.0, "gen_speed")) / strict[0][:, None]))))
