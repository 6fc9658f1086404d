"""Are the QFT bounds of a tower specification feasible? Checked live, while the specification is shaped.

The pitch loop's QFT problem at one operating point: the template of P_{Ω,β} over the plant
cases (v + ``template_offsets``, no tower damping loop), and at each design frequency the
bounds of the tower-load spec |T_{MyT,w}| ≤ |W_MyT,i|, the generator-speed spec and the
stability margin |1/(1+L)| ≤ M_s, each case's W_i being ROSCO's map at its speed times the
nominal ratio W/T^ROSCO (as :func:`specdesign.qft.design_qft` uses them). An *empty* bound
(no loop value L₀(jω) meets all of them for every case) means no controller of any structure
closing this loop meets the specifications there: the designer sees it before loop shaping.

:func:`bounds_checker` precomputes everything but the tower weight; :meth:`BoundsChecker.check`
then costs one exact bound computation (a few ms), fast enough for a slider.

Units: ω in rad/s, magnitudes linear (N·m per m/s for the tower weight).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from loopshaping import qft as lqft

from ..closedloop import (
    DESIGN_MAX_SENSITIVITY,
    case_speeds,
    closed_map,
    general_coefficients,
    plant_responses,
    siso_response,
)
from .result import DEFAULT_DESIGN_OMEGA

__all__ = ["BoundsVerdict", "BoundsChecker", "bounds_checker"]


@dataclass(frozen=True)
class BoundsVerdict:
    """The QFT bounds' feasibility of a specification pair.

    Parameters
    ----------
    omega : numpy.ndarray
        Design frequencies, rad/s.
    empty : numpy.ndarray
        Boolean per frequency: the intersected bound is empty there.
    feasible : bool
        No bound is empty.
    """

    omega: np.ndarray
    empty: np.ndarray
    feasible: bool

    def summary(self) -> str:
        """One line: feasible, or the frequencies where the bounds are empty.

        Returns
        -------
        str
            The verdict.
        """
        if self.feasible:
            return f"QFT bounds feasible at all {self.omega.size} design frequencies"
        return "QFT bounds empty at " + ", ".join(f"{w:.3g}" for w in self.omega[self.empty]) + " rad/s"


class BoundsChecker:
    """Precomputed pitch-loop template, speed and margin bounds of one operating point.

    Made by :func:`bounds_checker`; :meth:`check` takes the tower specification.

    Parameters
    ----------
    template : loopshaping.templates.Template
        The pitch loop's template P_{Ω,β} over the plant cases.
    fixed : loopshaping.bounds.Bounds
        The intersected speed and margin bounds.
    coefficients : tuple of numpy.ndarray
        (A, B, C, D) of T_{MyT,w} in QFT's general form per case, on the design frequencies.
    rosco_tower : numpy.ndarray
        |T^ROSCO_{MyT,w}| per case (n_omega, n_cases), N·m per m/s.
    rosco_nominal : numpy.ndarray
        ROSCO's nominal T_{MyT,w} (complex, n_omega), the reference of the tower ratio.
    """

    def __init__(self, template, fixed, coefficients, rosco_tower, rosco_nominal):
        self.template, self.fixed = template, fixed
        self.coefficients, self.rosco_tower, self.rosco_nominal = coefficients, rosco_tower, rosco_nominal

    def check(self, tower_spec) -> BoundsVerdict:
        """The bounds' feasibility with this tower specification.

        Parameters
        ----------
        tower_spec : object with ``response(omega)`` or array_like
            W_MyT at the nominal speed: a :class:`specdesign.spec.Specification` (or any object
            with ``response``), or its complex values on ``template.omega``.

        Returns
        -------
        BoundsVerdict
            Empty frequencies and the verdict.

        Raises
        ------
        ValueError
            If an array of the wrong length is given.
        """
        w = self.template.omega
        vals = (np.asarray(tower_spec.response(w)) if hasattr(tower_spec, "response")
                else np.asarray(tower_spec, complex))
        if vals.shape != w.shape:
            raise ValueError(f"tower_spec has {vals.shape} values, expected {w.shape} (one per design frequency)")
        weight = self.rosco_tower * (np.abs(vals) / np.abs(self.rosco_nominal))[:, None]
        a, b, c, d = self.coefficients
        spec = lqft.Spec("general", weight, name="tower", kind_args={"A": a, "B": b, "C": c, "D": d})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", lqft.BoundsWarning)
            both = lqft.intersect(self.fixed, lqft.bounds(self.template, spec))
        empty = np.asarray(both.empty, bool)
        return BoundsVerdict(w.copy(), empty, not bool(empty.any()))


def bounds_checker(model, wind_speed, speed_spec=None, *, max_sensitivity=DESIGN_MAX_SENSITIVITY,
                   template_offsets=(-1.0, -0.5, 0.5, 1.0), design_omega=None) -> BoundsChecker:
    """Precompute the pitch loop's QFT problem at ``wind_speed`` for live tower-spec checks.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speed : float
        Operating point, m/s.
    speed_spec : object with ``response(omega)``, optional
        W_Ω at the nominal speed (default ROSCO's T_{Ω,w} relaxed by 3 dB, design_qft's first rung).
    max_sensitivity : float
        M_s of the margin bound (> 1).
    template_offsets : sequence of float
        Wind-speed offsets of the plant cases, m/s (clipped to ``model.wind_range``).
    design_omega : array_like, optional
        Design frequencies, rad/s (default :data:`specdesign.qft.result.DEFAULT_DESIGN_OMEGA`).

    Returns
    -------
    BoundsChecker
        Call ``.check(tower_spec)``.

    Raises
    ------
    ValueError
        If ``max_sensitivity`` ≤ 1 or a grid is invalid.

    Examples
    --------
    >>> from specdesign.qft.boundscheck import bounds_checker
    >>> from specdesign.spec import design_specifications
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> checker = bounds_checker(model, 19.0)
    >>> checker.check(design_specifications(model, 19.0).tower).feasible
    True
    """
    from .. import spec as sp
    from ..spec import baseline_controllers

    if not max_sensitivity > 1:
        raise ValueError(f"max_sensitivity={max_sensitivity!r} must be > 1 (|1/(1+L)| bound)")
    v = model.check_wind_speed(wind_speed)
    speeds, nom = case_speeds(v, template_offsets, model.wind_range, name="template_offsets")
    w = DEFAULT_DESIGN_OMEGA.copy() if design_omega is None else lqft.check_grid(design_omega, "design_omega")
    plants = [model.linearize(s) for s in speeds]
    R = plant_responses(plants, w, ("gen_speed", "tower_base_my", "tower_top_vel"), method="batched")
    c = np.stack([siso_response(c, w) for c in baseline_controllers(model, speeds)], axis=1)
    t_tower, t_speed = closed_map(R, c, 0.0, "tower_base_my"), closed_map(R, c, 0.0, "gen_speed")
    if speed_spec is None:
        speed_spec = sp.speed_specification(model, v, margin_db=3.0)
    speed_ratio = np.abs(np.asarray(speed_spec.response(w))) / np.abs(t_speed[:, nom])
    template = lqft.Template.from_responses(w, R[("gen_speed", "pitch_cmd")], nom)
    sa, sb, sc, sd = general_coefficients(R, "gen_speed", "gen_speed")
    speed = lqft.Spec("general", np.abs(t_speed) * speed_ratio[:, None], name="speed",
                      kind_args={"A": sa, "B": sb, "C": sc, "D": sd})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lqft.BoundsWarning)
        fixed = lqft.intersect(lqft.bounds(template, speed),
                               lqft.bounds(template, lqft.Spec("sensitivity", max_sensitivity, name="margin")))
    return BoundsChecker(template, fixed, general_coefficients(R, "tower_base_my", "gen_speed"), np.abs(t_tower),
                         t_tower[:, nom])
