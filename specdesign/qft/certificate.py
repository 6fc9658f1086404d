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

from ..closedloop import (
    DESIGN_MAX_SENSITIVITY,
    closed_loop,
    closed_map,
    lightly_damped,
    plant_responses,
    refine_grid,
    siso_response,
)
from ..feasibility import TargetSpecification
from .checks import spec_ratio, spec_roots
from .result import DEFAULT_DESIGN_OMEGA, assemble_design
from .tuner import TuningProblem

__all__ = ["design_from_certificate"]


def design_from_certificate(model, target, *, max_sensitivity: float = DESIGN_MAX_SENSITIVITY, min_decay: float = 0.02,
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
        exact DEL promise.

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
    prob = TuningProblem(model, v, speeds, nom, wd, tower_shaping, 0.0, max_sensitivity, base,
                         speed_shaping=speed_shaping, response_method="batched")
    roots = lightly_damped(np.concatenate([spec_roots(target.tower), spec_roots(target.speed)]))
    sharp = np.abs(roots[roots.imag > 0])
    sharp = sharp[(sharp >= wdense[0]) & (sharp <= wdense[-1])]
    if sharp.size:
        prob.set_design(np.unique(np.r_[prob.wd, sharp]))
    wdense = refine_grid(wdense, roots)
    full = ct.ss(target.design.controller(model))
    cb, order = _lowest_order(prob, full, wdense, int(min_order), max_sensitivity, min_decay)
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
                                        max_sensitivity=max_sensitivity, min_decay=min_decay))


def _lowest_order(prob, full, omega, min_order, ms, min_decay):
    """The lowest-order balanced truncation of ``full`` that meets every specification on ``omega``
    at every plant case, is stable with decay ≥ ``min_decay`` and keeps |S| ≤ ``ms``; else ``full``."""
    R = plant_responses(prob.plants, omega, ("gen_speed", "tower_base_my", "tower_top_vel"), method="batched")
    w_speed, w_tower = prob.weights(omega)
    ob = R[("gen_speed", "pitch_cmd")]
    for n in range(min_order, full.nstates + 1):
        if n < full.nstates:
            try:
                with warnings.catch_warnings():  # python-control's and SLICOT's notes on the reduction
                    warnings.filterwarnings("ignore", category=UserWarning, module=r"(control|slycot)\.")
                    cand = ct.balred(full, n, method="truncate")
            except (ValueError, np.linalg.LinAlgError, ct.ControlArgument):
                continue
        else:
            cand = full
        c = siso_response(cand, omega)[:, None]
        if (np.any(np.abs(closed_map(R, c, 0.0, "tower_base_my")) > w_tower)
                or np.any(np.abs(closed_map(R, c, 0.0, "gen_speed")) > w_speed)
                or np.any(np.abs(1 / (1 + c * ob)) > ms)):
            continue
        with warnings.catch_warnings():  # python-control's notes on the interconnections (unused signals)
            warnings.filterwarnings("ignore", category=UserWarning, module=r"control\.")
            decay = min(-np.max(np.real(closed_loop(p, cand, warn=False).poles())) for p in prob.plants)
        if decay >= min_decay:
            return cand, n
    return full, full.nstates
