"""Are the QFT bounds of a tower specification feasible? Checked live, while the specification is shaped.

The pitch loop's QFT problem at one operating point: the template of P_{Ω,β} over the plant
cases (v + ``template_offsets``, no tower damping loop), and at each design frequency the
bounds of the tower-load spec |T_{MyT,w}| ≤ |W_MyT,i|, the generator-speed spec and the
stability margin |1/(1+L)| ≤ M_s, each case's W_i being ROSCO's map at its speed times the
nominal ratio W/T^ROSCO (as :func:`specdesign.qft.design_qft` uses them). An *empty* bound
(no loop value L₀(jω) meets all of them for every case) means no controller of any structure
closing this loop meets the specifications there: the designer sees it before loop shaping.

:func:`bounds_checker` precomputes everything but the tower weight; :meth:`BoundsChecker.check`
then costs one exact bound computation (35-70 ms on 47 frequencies). For a slider,
:meth:`BoundsChecker.precompute` brackets, per design frequency, the ratio W/W^ROSCO at which the
bound turns empty (the allowed set only grows with W), so a check is a comparison, with the exact
computation only for a ratio inside a bracket.

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
        n = template.omega.size
        # per design frequency: the largest ratio W/W^ROSCO computed empty, the smallest computed
        # not empty (nothing known until precompute())
        self._empty_up_to, self._feasible_from = np.full(n, -np.inf), np.full(n, np.inf)

    def _empty(self, ratio):
        """Empty flags of the intersected bounds with the tower weight ROSCO's map × ``ratio`` per frequency."""
        weight = self.rosco_tower * ratio[:, None]
        a, b, c, d = self.coefficients
        spec = lqft.Spec("general", weight, name="tower", kind_args={"A": a, "B": b, "C": c, "D": d})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", lqft.BoundsWarning)
            both = lqft.intersect(self.fixed, lqft.bounds(self.template, spec))
        return np.asarray(both.empty, bool)

    @property
    def precomputed(self) -> bool:
        """True once :meth:`precompute` has bracketed some frequency (checks then compare)."""
        return bool(np.isfinite(self._empty_up_to).any() or np.isfinite(self._feasible_from).any())

    def precompute(self, lowest: float = 1e-3, highest: float = 10.0, halvings: int = 14) -> BoundsChecker:
        """Bracket the ratio W/W^ROSCO where each frequency's bound turns empty, for fast checks.

        The tower spec |T_{MyT,w}| ≤ W allows a set of loop values that only grows with W, so at
        each design frequency the intersected bound is empty below some ratio r* of W to ROSCO's
        map and not above it. This brackets r* between a ratio computed empty and one computed
        not empty: seeds at every decade from ``lowest`` to ``highest``, then ``halvings`` halvings
        of the bracket's log width (2⁻¹⁴ decade: a bracket 0.014 % wide), every frequency in
        one bound computation per step (19 in all, about 1 s). Afterwards :meth:`check` decides each
        frequency by comparison and runs the exact computation only when a ratio falls inside a
        bracket or outside the seeded range; the verdict is the exact one either way. A frequency
        whose seeds are not monotone in the ratio keeps no bracket (always computed exactly).

        Parameters
        ----------
        lowest, highest : float
            Ratio range seeded, W/W^ROSCO (-, 0 < lowest < highest); a notch of 0-30 dB spans
            0.03-1.
        halvings : int
            Bisection steps of each bracket (≥ 0).

        Returns
        -------
        BoundsChecker
            This checker (brackets stored).

        Raises
        ------
        ValueError
            If the range or ``halvings`` is invalid.
        """
        if not 0 < lowest < highest or not np.isfinite(highest):
            raise ValueError(f"need 0 < lowest < highest < inf; got lowest={lowest!r}, highest={highest!r}")
        if int(halvings) != halvings or halvings < 0:
            raise ValueError(f"halvings={halvings!r} must be an integer ≥ 0")
        n = self.template.omega.size
        seeds = np.geomspace(lowest, highest, max(2, round(np.log10(highest / lowest)) + 1))
        empty = np.stack([self._empty(np.full(n, r)) for r in seeds])  # (n_seeds, n)
        # monotone: empty at the low seeds, not empty from some seed on
        monotone = np.all(empty[1:] <= empty[:-1], axis=0)
        k = empty.sum(axis=0)  # seeds computed empty at each frequency: the first k
        lo = np.where(k > 0, seeds[np.maximum(k - 1, 0)], -np.inf)
        hi = np.where(k < seeds.size, seeds[np.minimum(k, seeds.size - 1)], np.inf)
        inner = monotone & np.isfinite(lo) & np.isfinite(hi)
        for _ in range(int(halvings)):
            if not inner.any():
                break
            mid = np.where(inner, np.sqrt(np.where(inner, lo * hi, 1.0)), 1.0)
            e = self._empty(mid)
            lo, hi = np.where(inner & e, mid, lo), np.where(inner & ~e, mid, hi)
        self._empty_up_to = np.where(monotone, lo, -np.inf)
        self._feasible_from = np.where(monotone, hi, np.inf)
        return self

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
        ratio = np.abs(vals) / np.abs(self.rosco_nominal)
        empty = ratio <= self._empty_up_to
        if not np.all(empty | (ratio >= self._feasible_from)):  # inside a bracket, or none: exact
            empty = self._empty(ratio)
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
