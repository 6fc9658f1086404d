"""A QFT design's record: :class:`QFTDesign`, assembled by :func:`assemble_design` from the tuned
controllers, and the default design frequencies :data:`DEFAULT_DESIGN_OMEGA`.

Both designs stand on it: :func:`specdesign.qft.design_qft` (the fixed structure tuned on the
notch specification) and :func:`specdesign.qft.certificate.design_from_certificate` (the
certificate's controller reduced); see :mod:`specdesign.qft.design` for the units.
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np

from loopshaping import qft as lqft
from loopshaping.freqresp import is_zero

from ..closedloop import (
    UNSTABLE_CONTROLLER_RATE,
    check_stability,
    closed_loop,
    plant_responses,
    siso_response,
)
from ..closedloop.modes import TowerDampingWarning, tower_damping, tower_damping_message
from .checks import bounds_met, loop_checks

if TYPE_CHECKING:
    from loopshaping.bounds import Bounds
    from loopshaping.check import CheckResult
    from loopshaping.templates import Template

    from ..spec import Baseline, Promise, ShapingResult, Specification

__all__ = ["DEFAULT_DESIGN_OMEGA", "QFTDesign", "assemble_design"]


#: Default QFT design frequencies, rad/s: the wind band, the tower mode (~1.06 rad/s) and
#: the actuator band.
DEFAULT_DESIGN_OMEGA = np.unique(np.r_[0.005, 0.007, np.logspace(-2, 1, 37), 0.9, 0.95, 1.0, 1.03, 1.05, 1.07, 1.1, 1.15, 1.2])


# ----------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class QFTDesign:
    """One operating point's QFT design (frozen), made by :func:`design_qft`.

    All changes are designed vs ROSCO (ATD off), in %, positive = increase; reductions are
    positive = less. The controllers are in the workbench sign β_cmd = −C_β·Ω_g − C_atd·ẋ_top.

    Parameters
    ----------
    wind_speed : float
        Operating point, m/s.
    pitch_controller : control.TransferFunction
        C_β, generator speed (rad/s) → pitch command (rad).
    atd_controller : control.TransferFunction
        C_atd, tower-top fore-aft velocity ẋ_top (m/s) → pitch command (rad).
    baseline_controller : control.TransferFunction
        ROSCO's PI (with its speed filter) at the same speed, rad/s → rad.
    template_speeds : tuple of float
        Wind speeds of the plant cases, m/s; nominal at ``wind_speed``.
    design_omega : numpy.ndarray
        QFT design frequencies, rad/s (the final set, refinements included).
    dense_omega : numpy.ndarray
        Grid of the dense check, rad/s.
    tower_spec : specdesign.spec.Specification
        The (relaxed) tower-load specification W_MyT, N·m per m/s.
    speed_spec : specdesign.spec.Specification
        The generator-speed specification W_Ω (ROSCO's T_{Ω,w} relaxed by the
        ``speed_relax_db`` that worked), rad/s per m/s.
    shaping : specdesign.spec.ShapingResult
        The notches of :func:`specdesign.spec.shape_to_target` and the unrelaxed notch
        specification's promise (``shaping.promise``, what the paper's Table 3 lists).
    promise : specdesign.spec.Promise
        Promise of the (relaxed) tower specification, %.
    pitch_template : loopshaping.qft.Template
        Template of P'_{Ω,β} (ATD closed) on ``design_omega``.
    atd_template : loopshaping.qft.Template
        Template of P''_{z,β} (pitch loop closed) on ``design_omega``.
    pitch_bounds : loopshaping.qft.Bounds
        Bounds on L0 = C_β·P'_{Ω,β} (ATD closed), exact for the final controllers.
    atd_bounds : loopshaping.qft.Bounds
        Bounds on L0 = C_atd·P''_{z,β} (pitch loop closed).
    pitch_check : loopshaping.check.CheckResult
        Dense check of the pitch loop on ``dense_omega``, every case.
    atd_check : loopshaping.check.CheckResult
        Dense check of the ATD loop on ``dense_omega``, every case.
    closed_loop : control.StateSpace
        Nominal plant with both loops closed (:func:`specdesign.closedloop.closed_loop`).
    baseline : specdesign.spec.Baseline
        ROSCO's nominal loop as seen by the tower-base moment (T_{MyT,w}, S_W, ΔD%).
    bounds_met : bool
        Every bound met at every design frequency (nominal loop, exact).
    all_stable : bool
        The full interconnection is stable for every plant case.
    del_reduction : float
        Predicted tower-base DEL reduction (1 Hz, m = 4), Dirlik on |T|²S_W, nominal case, %.
    damage_reduction : float
        Predicted tower-base damage reduction, same method, %.
    gen_speed_sd_change : float
        Change of the generator-speed standard deviation, %.
    pitch_sd_change : float
        Change of the pitch standard deviation, %.
    pitch_rate_sd_change : float
        Change of the pitch-rate standard deviation, %.
    pitch_rate_sd : float
        Pitch-rate standard deviation of the design, rad/s (linear, nominal case).
    gain_margin_db : float
        Gain margin of the nominal pitch loop C_β·P'_{Ω,β} (ATD closed), dB.
    phase_margin_deg : float
        Phase margin of the same loop, degrees.
    atd_gain_margin_db : float
        Gain margin of the nominal ATD loop C_atd·P''_{z,β} (pitch loop closed), dB.
    atd_phase_margin_deg : float
        Phase margin of the same loop, degrees.
    actuator_peak_sensitivity : float
        Maximum over ω and cases of |1/(1 + C_β P_{Ω,β} + C_atd P_{z,β})| (-).
    tower_damping_ratio : float
        Damping ratio (-) of the first tower fore-aft mode with both loops closed, nominal case
        (:func:`specdesign.closedloop.tower_damping`); below
        :data:`~specdesign.closedloop.MIN_TOWER_DAMPING_FRACTION` of ROSCO's the design warns
        (:class:`~specdesign.closedloop.TowerDampingWarning`): the promise does not see what else
        drives the mode on a real turbine.
    baseline_tower_damping_ratio : float
        The same with ROSCO's PI (-).
    target_reduction : float
        The requested tower-base DEL reduction, %.
    success : bool
        Every specification met: target (within 0.5 pp), bounds, dense checks, stability of
        every closed loop and of the controller itself (no pole growing faster than
        :data:`specdesign.closedloop.UNSTABLE_CONTROLLER_RATE`: a saturated pitch opens the loop).
    message : str
        ``"all specifications met"`` or what failed.
    parameters : dict of str to float
        The tuned parameters (:func:`specdesign.qft.structure.from_vector`).
    options : dict
        The options the design was made with (``spec_reduction``, ``template_offsets``,
        ``speed_relax_db``, ``tower_relax_db``, ``tower_relax_omega``, ``max_sensitivity``,
        ``min_decay``) and ``refine_rounds``; a design from a target specification's certificate
        also ``strict_excess_db``: (largest |T_MyT,w|/|W_MyT|, largest |T_Ω,w|/|W_Ω|) at any plant
        case against the nominal W itself, dB, on the dense grid (the cases meet their own W_i =
        T^ROSCO_i·W/T^ROSCO; this is the pair read strictly, reported beside it).

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.qft import design_qft
    >>> d = design_qft(turbine.iea15mw(), 19.0)  # doctest: +SKIP
    >>> d.success, d.n_states, d.is_proper  # doctest: +SKIP
    (True, 6, True)
    """

    wind_speed: float
    pitch_controller: ct.TransferFunction
    atd_controller: ct.TransferFunction
    baseline_controller: ct.TransferFunction
    template_speeds: tuple[float, ...]
    design_omega: np.ndarray
    dense_omega: np.ndarray
    tower_spec: Specification
    speed_spec: Specification
    shaping: ShapingResult
    promise: Promise
    pitch_template: Template
    atd_template: Template
    pitch_bounds: Bounds
    atd_bounds: Bounds
    pitch_check: CheckResult
    atd_check: CheckResult
    closed_loop: ct.StateSpace
    baseline: Baseline
    bounds_met: bool
    all_stable: bool
    del_reduction: float
    damage_reduction: float
    gen_speed_sd_change: float
    pitch_sd_change: float
    pitch_rate_sd_change: float
    pitch_rate_sd: float
    gain_margin_db: float
    phase_margin_deg: float
    atd_gain_margin_db: float
    atd_phase_margin_deg: float
    actuator_peak_sensitivity: float
    tower_damping_ratio: float
    baseline_tower_damping_ratio: float
    target_reduction: float
    success: bool
    message: str
    parameters: dict[str, float] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def n_states(self) -> int:
        """Total controller order (pitch + ATD states)."""
        return int(ct.ss(self.pitch_controller).nstates + ct.ss(self.atd_controller).nstates)

    @property
    def is_proper(self) -> bool:
        """Both controllers are proper (numerator degree ≤ denominator degree)."""

        def proper(tf):
            return len(np.trim_zeros(tf.num[0][0], "f")) <= len(np.trim_zeros(tf.den[0][0], "f"))

        return proper(self.pitch_controller) and proper(self.atd_controller)

    def row(self) -> dict[str, Any]:
        """One row of :func:`design_table`.

        Returns
        -------
        dict
            ``wind_speed`` (m/s); the promises of the notch and of the relaxed specification
            (``notch_promise_del_pct``, ``notch_promise_damage_pct``, ``promised_del_pct``,
            ``promised_damage_pct``) and the predicted reductions (``predicted_del_pct``,
            ``predicted_damage_pct``), %; the SD changes (``*_sd_change_pct``), %; the margins
            (``gain_margin_db``, ``phase_margin_deg``, ``atd_gain_margin_db``,
            ``atd_phase_margin_deg``); the tower mode's damping ratios of the design and of
            ROSCO (``tower_damping_ratio``, ``baseline_tower_damping_ratio``, -); ``bounds_met``, ``dense_check_passed``, ``all_stable``
            (bool) and ``n_states``.
        """
        return {
            "wind_speed": self.wind_speed,
            "notch_promise_del_pct": self.shaping.promise.exact_del,
            "notch_promise_damage_pct": self.shaping.promise.exact_damage,
            "promised_del_pct": self.promise.exact_del,
            "promised_damage_pct": self.promise.exact_damage,
            "predicted_del_pct": self.del_reduction,
            "predicted_damage_pct": self.damage_reduction,
            "gen_speed_sd_change_pct": self.gen_speed_sd_change,
            "pitch_sd_change_pct": self.pitch_sd_change,
            "pitch_rate_sd_change_pct": self.pitch_rate_sd_change,
            "gain_margin_db": self.gain_margin_db,
            "phase_margin_deg": self.phase_margin_deg,
            "atd_gain_margin_db": self.atd_gain_margin_db,
            "atd_phase_margin_deg": self.atd_phase_margin_deg,
            "tower_damping_ratio": self.tower_damping_ratio,
            "baseline_tower_damping_ratio": self.baseline_tower_damping_ratio,
            "bounds_met": self.bounds_met,
            "dense_check_passed": bool(self.pitch_check.passed and self.atd_check.passed),
            "all_stable": self.all_stable,
            "n_states": self.n_states,
        }

    def summary(self) -> str:
        """One-paragraph summary: reductions, SD changes, margins, checks and the message.

        Returns
        -------
        str
            The summary (reductions and changes in %, margins in dB and degrees).
        """
        r = self.row()
        if self.options.get("structure") == "certificate":
            return (f"QFT design at {self.wind_speed:g} m/s meeting the target specification: tower DEL reduced "
                    f"{r['predicted_del_pct']:.1f} % (the specification promises {r['promised_del_pct']:.1f} %), "
                    f"{r['n_states']}-state pitch controller, no ATD; gen-speed SD {r['gen_speed_sd_change_pct']:+.1f} %, "
                    f"pitch SD {r['pitch_sd_change_pct']:+.1f} %, pitch-rate SD {r['pitch_rate_sd_change_pct']:+.1f} %; "
                    f"pitch loop GM {r['gain_margin_db']:.1f} dB PM {r['phase_margin_deg']:.1f}°; {self._tower_text()}; "
                    f"bounds met: {self.bounds_met}, dense check: {r['dense_check_passed']}, all {len(self.template_speeds)} cases "
                    f"stable: {self.all_stable}; {self.message}")
        return (f"QFT design at {self.wind_speed:g} m/s: tower DEL reduced {r['predicted_del_pct']:.1f} % "
                f"(notch spec promises {r['notch_promise_del_pct']:.1f} %, relaxed spec {r['promised_del_pct']:.1f} %), "
                f"gen-speed SD {r['gen_speed_sd_change_pct']:+.1f} %, "
                f"pitch SD {r['pitch_sd_change_pct']:+.1f} %, pitch-rate SD {r['pitch_rate_sd_change_pct']:+.1f} %; "
                f"pitch loop GM {r['gain_margin_db']:.1f} dB PM {r['phase_margin_deg']:.1f}°, ATD loop GM "
                f"{r['atd_gain_margin_db']:.1f} dB PM {r['atd_phase_margin_deg']:.1f}°; {self._tower_text()}; "
                f"bounds met: {self.bounds_met}, "
                f"dense check: {r['dense_check_passed']}, all {len(self.template_speeds)} cases stable: {self.all_stable}; "
                f"{self.message}")

    def _tower_text(self) -> str:
        return f"tower mode ζ {self.tower_damping_ratio:.3f} (ROSCO {self.baseline_tower_damping_ratio:.3f})"


def assemble_design(model, prob, cb, ca, wdense, t, performance, *, base, tower_spec, speed_spec, shaping, promise,
                    parameters, options, checks=None) -> QFTDesign:
    """Check a pair of controllers against a tuning problem's specifications and record the design.

    The exact bounds at the design frequencies, the dense checks of both loops over every
    plant case, closed-loop stability of every case, and the nominal performance.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine (kept for the record's provenance).
    prob : specdesign.qft.tuner.TuningProblem
        Plant cases, weights, design frequencies, ``max_sensitivity``.
    cb, ca : control.LTI
        Pitch controller C_β (rad per rad/s) and ATD controller C_atd (rad per m/s).
    wdense : numpy.ndarray
        Grid of the dense check, rad/s.
    t : float
        The DEL reduction the design must reach, % (0.5 pp tolerance).
    performance : tuple of float
        (DEL reduction %, damage reduction %, σ ratios of gen speed, pitch, pitch rate) nominal.
    base : specdesign.spec.Baseline
        ROSCO's baseline at the nominal speed.
    tower_spec, speed_spec : object
        The specifications met (recorded).
    shaping : specdesign.spec.ShapingResult
        The shaping the tower specification came from (recorded).
    promise : specdesign.spec.Promise
        The promise of the tower specification (recorded).
    parameters : dict
        Controller parameters (recorded).
    options : dict
        Options of the design (recorded).
    checks : tuple, optional
        :func:`specdesign.qft.checks.loop_checks`'s result for these controllers, if computed.

    Returns
    -------
    QFTDesign
        The design; ``success`` False with a message (and a RuntimeWarning) when a check fails.
    """
    v, nom, speeds = prob.v, prob.nom, prob.speeds
    if checks is None:
        checks = loop_checks(prob, cb, ca, wdense)
    pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs = checks
    # exact bounds on the final design frequencies, for the Nichols charts and the bound check
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lqft.BoundsWarning)
        pitch_bounds = lqft.intersect(*[lqft.bounds(pitch_t, s_) for s_ in pitch_specs])
        atd_bounds = lqft.intersect(*[lqft.bounds(atd_t, s_) for s_ in atd_specs])
    met = bounds_met(pitch_bounds, cb, pitch_t, prob.wd) and bounds_met(atd_bounds, ca, atd_t, prob.wd)


    with warnings.catch_warnings():  # python-control's notes on the interconnections (unused signals)
        warnings.filterwarnings("ignore", category=UserWarning, module=r"control\.")
        stable = [check_stability(closed_loop(P, cb, ca, warn=False), tol=0.0) for P in prob.plants]
        cl = closed_loop(prob.plants[nom], cb, ca, warn=False)
        zeta = tower_damping(prob.plants[nom], cl)[1]
        zeta_rosco = tower_damping(prob.plants[nom], closed_loop(prob.plants[nom], prob.rosco[nom], warn=False))[1]
    all_stable = bool(np.all(stable))
    red, dred, gs, ps, rate = performance
    Rdense = plant_responses(prob.plants, wdense, ("gen_speed", "tower_top_vel"), method=prob.response_method)
    cdn, kdn = siso_response(cb, wdense)[:, None], siso_response(ca, wdense)[:, None]
    peak_in = float(np.max(1 / np.abs(1 + cdn * Rdense[("gen_speed", "pitch_cmd")] + kdn * Rdense[("tower_top_vel", "pitch_cmd")])))
    nomp = pitch_t.nominal
    problems = []
    if red < t - 0.5:
        problems.append(f"DEL reduction {red:.1f} % below the target {t:g} %")
    if not met:
        problems.append("a bound is violated at a design frequency")
    if not pitch_check.passed:
        problems.append("dense check of the pitch loop failed: " + pitch_check.summary().replace("\n", "; "))
    if not atd_check.passed:
        problems.append("dense check of the ATD loop failed: " + atd_check.summary().replace("\n", "; "))
    if not all_stable:
        problems.append(f"unstable closed loops at {[speeds[i] for i, s_ in enumerate(stable) if not s_]} m/s")
    if prob.controller_bound is not None and np.any(np.asarray(ct.ss(cb).D) != 0):
        problems.append(f"the pitch controller has a direct term ({float(np.asarray(ct.ss(cb).D).ravel()[0]):.3g} rad per "
                        "rad/s): under the high-frequency gain bound it must be strictly proper (roll off)")
    rhp = np.concatenate([ct.poles(cb), ct.poles(ca)])
    rhp = rhp[rhp.real > UNSTABLE_CONTROLLER_RATE]
    if rhp.size:
        problems.append(f"the controller itself is unstable (poles {np.array2string(rhp, precision=4)} 1/s): wherever the "
                        "pitch saturates (at fine pitch in the lulls near rated, at its rate limit) the loop opens and "
                        "these modes grow (docs/below_rated.md)")
    success = not problems
    message = "all specifications met" if success else "; ".join(problems)
    if not success:
        warnings.warn(f"design_qft at {v:g} m/s: {message}", RuntimeWarning, stacklevel=3)
    weak = tower_damping_message("design_qft", v, zeta, zeta_rosco, tower_damper=not is_zero(ca))
    if weak is not None:
        warnings.warn(weak, TowerDampingWarning, stacklevel=3)
    return QFTDesign(
        wind_speed=v, pitch_controller=cb, atd_controller=ca, baseline_controller=prob.rosco[nom],
        template_speeds=speeds, design_omega=prob.wd.copy(), dense_omega=wdense, tower_spec=tower_spec,
        speed_spec=speed_spec, shaping=shaping, promise=promise, pitch_template=pitch_t, atd_template=atd_t,
        pitch_bounds=pitch_bounds, atd_bounds=atd_bounds, pitch_check=pitch_check, atd_check=atd_check, closed_loop=cl,
        baseline=base, bounds_met=bool(met), all_stable=all_stable, del_reduction=float(red),
        damage_reduction=float(dred), gen_speed_sd_change=100 * (gs - 1), pitch_sd_change=100 * (ps - 1),
        pitch_rate_sd_change=100 * (rate - 1), pitch_rate_sd=float(rate * prob.sd0["pitch_rate"]),
        gain_margin_db=float(pitch_check.gain_margin_db[nomp]), phase_margin_deg=float(pitch_check.phase_margin_deg[nomp]),
        atd_gain_margin_db=float(atd_check.gain_margin_db[nomp]), atd_phase_margin_deg=float(atd_check.phase_margin_deg[nomp]),
        actuator_peak_sensitivity=peak_in, tower_damping_ratio=zeta, baseline_tower_damping_ratio=zeta_rosco,
        target_reduction=t, success=success, message=message, parameters=parameters,
        options=options,
    )
