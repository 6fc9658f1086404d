"""The automatic QFT design at one operating point and over a schedule (see :mod:`specdesign.qft`).

Units: ω in rad/s, wind speeds in m/s, reductions and standard-deviation changes in %
(reductions positive = less, changes positive = more), relaxations and gain margins in dB,
phase margins in degrees, decay rates in 1/s; β = −C_β·Ω_g − C_atd·ẋ_top.
"""
from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np

from .._checks import del_target, positive_scalar
from ..closedloop import (case_speeds, check_stability, closed_loop, lightly_damped, plant_responses, refine_grid,
                          siso_response)
from .checks import bounds_met, loop_checks, spec_ratio, spec_roots
from .structure import controllers, from_vector, rosco_start
from .tuner import TuningProblem, tune

if TYPE_CHECKING:
    from loopshaping.bounds import Bounds
    from loopshaping.check import CheckResult
    from loopshaping.templates import Template

    from ..spec import Baseline, Promise, ShapingResult, Specification
    from ..turbine import TurbineModel

__all__ = ["QFTDesign", "design_qft", "assemble_design", "design_schedule", "design_table", "format_table",
           "DEFAULT_DESIGN_OMEGA", "check_design_speed", "UNSTABLE_CONTROLLER_RATE"]


#: Default QFT design frequencies, rad/s: the wind band, the tower mode (~1.06 rad/s) and
#: the actuator band.
DEFAULT_DESIGN_OMEGA = np.unique(np.r_[0.005, 0.007, np.logspace(-2, 1, 37), 0.9, 0.95, 1.0, 1.03, 1.05, 1.07, 1.1, 1.15, 1.2])


#: Growth rate (1/s) above which a controller pole counts as unstable in :func:`design_qft`'s
#: checks: slower modes grow less than e-fold over a 10-minute record.
UNSTABLE_CONTROLLER_RATE = 1e-3


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
    target_reduction : float
        The requested tower-base DEL reduction, %.
    success : bool
        Every specification met: target (within 0.5 pp), bounds, dense checks, stability of
        every closed loop and of the controller itself (no pole growing faster than
        :data:`UNSTABLE_CONTROLLER_RATE`: a saturated pitch opens the loop).
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
    target_reduction: float
    success: bool
    message: str
    parameters: dict[str, float] = field(default_factory=dict)
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def design_omegas(self) -> np.ndarray:
        """Deprecated name of :attr:`design_omega`.

        Warns
        -----
        DeprecationWarning
            Always: use :attr:`design_omega`.
        """
        warnings.warn("QFTDesign.design_omegas is deprecated, use QFTDesign.design_omega", DeprecationWarning, stacklevel=2)
        return self.design_omega

    @property
    def dense_omegas(self) -> np.ndarray:
        """Deprecated name of :attr:`dense_omega`.

        Warns
        -----
        DeprecationWarning
            Always: use :attr:`dense_omega`.
        """
        warnings.warn("QFTDesign.dense_omegas is deprecated, use QFTDesign.dense_omega", DeprecationWarning, stacklevel=2)
        return self.dense_omega

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
            ``atd_phase_margin_deg``); ``bounds_met``, ``dense_check_passed``, ``all_stable``
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
                    f"pitch loop GM {r['gain_margin_db']:.1f} dB PM {r['phase_margin_deg']:.1f}°; bounds met: "
                    f"{self.bounds_met}, dense check: {r['dense_check_passed']}, all {len(self.template_speeds)} cases "
                    f"stable: {self.all_stable}; {self.message}")
        return (f"QFT design at {self.wind_speed:g} m/s: tower DEL reduced {r['predicted_del_pct']:.1f} % "
                f"(notch spec promises {r['notch_promise_del_pct']:.1f} %, relaxed spec {r['promised_del_pct']:.1f} %), "
                f"gen-speed SD {r['gen_speed_sd_change_pct']:+.1f} %, "
                f"pitch SD {r['pitch_sd_change_pct']:+.1f} %, pitch-rate SD {r['pitch_rate_sd_change_pct']:+.1f} %; "
                f"pitch loop GM {r['gain_margin_db']:.1f} dB PM {r['phase_margin_deg']:.1f}°, ATD loop GM "
                f"{r['atd_gain_margin_db']:.1f} dB PM {r['atd_phase_margin_deg']:.1f}°; bounds met: {self.bounds_met}, "
                f"dense check: {r['dense_check_passed']}, all {len(self.template_speeds)} cases stable: {self.all_stable}; "
                f"{self.message}")


def _sharp_frequencies(prob, enabled=True, zeta_max=0.3, spread=(0.99, 1.0, 1.01)):
    """|p|·spread for lightly damped (ζ < zeta_max) poles and zeros of every case's ROSCO
    closed-loop maps wind → gen_speed and wind → tower_base_my, inside 0.005-20 rad/s."""

    if not enabled:
        return np.zeros(0)
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for P, c in zip(prob.plants, prob.rosco):
            cl = closed_loop(P, c, warn=False)
            for y in ("gen_speed", "tower_base_my"):
                sys = cl[y, "wind"]
                for r in lightly_damped(np.r_[ct.poles(sys), ct.zeros(sys)], zeta_max):
                    if r.imag > 0:
                        out.extend(abs(r) * np.asarray(spread))
    w = np.asarray(out)
    return np.unique(w[(w >= 0.005) & (w <= 20.0)])


def design_qft(model: TurbineModel, wind_speed: float, target_reduction: float = 25.0, *,
               speed_relax_db: float | Sequence[float] | None = None, spec: Any = "target",
               structure: str | None = None, **kwargs: Any) -> QFTDesign:
    """QFT design at ``wind_speed`` (m/s) that meets a fatigue-based specification pair.

    By default specification-driven (the method's centre, seed paper Sect. 3-4): the feasible
    specification pair for ``target_reduction`` first
    (:func:`specdesign.feasibility.specification_for_target`, certified over the plant cases),
    then the controller that meets it at every plant case on the dense check (its certificate
    reduced to the lowest order that does, 2-5 s). ``spec="notch"`` is the earlier automatic
    procedure: fixed structures (PI + notch + low-pass and an ATD) started from ROSCO, tuned
    against the bounds of every plant case with a DEL-target penalty (5-60 s).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel or specdesign.openfast.LinearTurbine
        The turbine, e.g. ``turbine.iea15mw()``.
    wind_speed : float
        Operating point, m/s (above rated, inside ``model.wind_range``).
    target_reduction : float
        Tower-base DEL reduction (1 Hz, m = 4) vs ROSCO, % (0-100): with ``spec="target"`` the
        promise of the specification that is made and met; with ``spec="notch"`` the predicted
        reduction the tuner must reach. Not used with a given specification.
    speed_relax_db : float or sequence of float, optional
        Only with ``spec="notch"``: relaxation of the generator-speed spec in dB (≥ 0), or an
        increasing sequence tried in turn (default 3, 4.5, 6, 8 dB): the design with the
        smallest relaxation that meets every spec is returned (else the last attempt, with a
        warning). With a specification-driven design the certificate sets it.
    spec : "target", "notch", TargetSpecification or (tower, speed)
        ``"target"`` (default): ``specification_for_target(model, wind_speed,
        target_reduction)``, then as for a TargetSpecification. ``"notch"``: the
        fixed-structure design against the notch specification and the DEL target.
        Otherwise the specification pair to meet:
        a :class:`specdesign.feasibility.TargetSpecification`, or two objects with a
        ``response(omega)`` (e.g. :class:`specdesign.spec.Specification`), W_MyT and W_Ω of
        the nominal case. Each plant case gets ROSCO's map at its speed times the nominal
        ratio W/T^ROSCO; no DEL penalty is used (the specification carries the target, and
        ``target_reduction`` is set to its promise). ``success`` then means: every bound met,
        the dense check passed for every case, every loop stable.
    structure : {"certificate", "fixed"}, optional
        The controller designed. ``"fixed"``: the tuned fixed structures (PI + notch + low-pass
        and a first-order ATD). ``"certificate"`` (only with ``"target"`` or a
        TargetSpecification; their default): the specification's certificate reduced to the
        lowest order that meets it over the plant cases
        (:func:`specdesign.qft.certificate.design_from_certificate`; options
        ``max_sensitivity``, ``min_decay``, ``design_omega``, ``dense_omega``, and with
        ``spec="target"`` ``template_offsets``, the plant cases the pair is certified on).
    **kwargs
        Options of each design attempt (keyword only; the certificate takes only the four
        named above, the fixed structures all of these):

        spec_reduction : float, default 15.0
            Damage reduction (%) the notch-shaped tower specification promises
            (:func:`specdesign.spec.shape_to_target`, notches above ``keep_below`` rad/s).
        template_offsets : sequence of float, default (-1, -0.5, 0.5, 1)
            Wind-speed offsets (m/s) of the neighbouring operating points (clipped to
            ``model.wind_range``). With ``spec="target"`` the plant cases the specification is
            certified on and met on (``specification_for_target(case_offsets=...)``).
        design_omega : array_like, optional
            QFT design frequencies, rad/s (default :data:`DEFAULT_DESIGN_OMEGA` plus the
            tower-mode features of ROSCO's loops).
        dense_omega : array_like, optional
            Grid of the final check, rad/s (default 600 points, 0.005-20 rad/s).
        tower_relax_db, tower_relax_omega : float, default 6.0 dB, 1.3 rad/s
            The tower spec is relaxed by this many dB above about this frequency (rad/s),
            where ΔD% is negligible (0 dB to disable).
        max_sensitivity : float, default 1.9
            Bound on |1/(1+L)| for both loops and at the actuator (> 1).
        min_decay : float, default 0.02
            Required closed-loop decay rate, 1/s (poles left of −min_decay).
        keep_below : float, default 0.6
            Protected band of the notch specification, rad/s (power regulation).
        refine : int, default 2
            Rounds adding the dense check's failing frequencies to the design set.
        maxfev : int, default 3000
            Function evaluations per tuning round.

    Returns
    -------
    QFTDesign
        The design; ``success`` is False (with a message, and a RuntimeWarning) when the
        target, a bound, the dense check or stability (of the loops or of the controller
        itself) is not met.

    Raises
    ------
    TypeError
        If ``model`` is not a :class:`specdesign.turbine.TurbineModel`, an option is unknown
        (or belongs to the other design: ``speed_relax_db`` and the tuner's options need
        ``spec="notch"`` or ``structure="fixed"``), or both a deprecated and a current keyword (``design_omegas=``/``design_omega=``,
        ``dense_omegas=``/``dense_omega=``) are given.
    ValueError
        If ``wind_speed`` is outside ``model.wind_range``; ``target_reduction`` is not
        strictly between 0 and 100 %; no certified specification reaches it ("infeasible
        because ...", from :func:`specdesign.feasibility.specification_for_target`);
        ``spec`` is an unknown string; a relaxation is negative or not finite;
        ``tower_relax_omega`` or ``min_decay`` is not positive; ``max_sensitivity`` ≤ 1;
        ``template_offsets`` is not a 1-D array of finite offsets; or a frequency grid is
        invalid.

    Warns
    -----
    RuntimeWarning
        When no relaxation of ``speed_relax_db`` gives a design that meets every
        specification (the last attempt is returned, ``success`` False).
    DeprecationWarning
        For the old keywords ``design_omegas=`` and ``dense_omegas=``.

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.qft import design_qft
    >>> d = design_qft(turbine.iea15mw(), 19.0)  # doctest: +SKIP
    >>> print(d.summary())  # doctest: +SKIP
    >>> fixed = design_qft(turbine.iea15mw(), 19.0, spec="notch")  # doctest: +SKIP
    """
    for old_name in ("design_omegas", "dense_omegas"):  # renamed: one name for frequency grids, omega
        if old_name in kwargs:
            new_name = old_name[:-1]
            warnings.warn(f"design_qft({old_name}=...) is deprecated, use {new_name}=", DeprecationWarning, stacklevel=2)
            if new_name in kwargs:
                raise TypeError(f"design_qft got both {old_name}= and {new_name}=")
            kwargs[new_name] = kwargs.pop(old_name)
    import inspect

    options = [n for n, p in inspect.signature(_design_single).parameters.items() if p.kind is p.KEYWORD_ONLY]
    unknown = sorted(set(kwargs) - set(options) - {"speed_relax_db"})
    if unknown:  # named here, not as a TypeError of an internal function
        raise TypeError(f"design_qft got unknown option(s) {unknown}; its options are {sorted(options)}")
    from .. import turbine

    if not (isinstance(model, turbine.TurbineModel) or callable(getattr(model, "baseline_controller", None))):
        raise TypeError(f"model must be a specdesign.turbine.TurbineModel (e.g. turbine.iea15mw()) or a "
                        f"specdesign.openfast.LinearTurbine, got {type(model).__name__}")
    check_design_speed(model, wind_speed)
    if isinstance(spec, str) and spec not in ("target", "notch"):
        raise ValueError(f"spec={spec!r} must be 'target', 'notch', a feasibility.TargetSpecification or a pair "
                         "(tower, speed)")
    fixed_only = set(kwargs) - {"max_sensitivity", "min_decay", "design_omega", "dense_omega", "template_offsets"}
    if isinstance(spec, str) and spec == "target" and structure != "fixed" and (fixed_only or speed_relax_db is not None):
        named = sorted(fixed_only | ({"speed_relax_db"} if speed_relax_db is not None else set()))
        raise TypeError(f"design_qft options {named} belong to the fixed-structure design: pass spec='notch' (the "
                        "notch specification and a DEL target) or structure='fixed'; the specification-driven default "
                        "takes max_sensitivity, min_decay, design_omega, dense_omega, template_offsets")
    if speed_relax_db is None:
        speed_relax_db = (3.0, 4.5, 6.0, 8.0)
    ladder = np.atleast_1d(np.asarray(speed_relax_db, float))
    if ladder.ndim != 1 or ladder.size == 0 or not np.all(np.isfinite(ladder)) or np.any(ladder < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB or a sequence of them")
    if np.any(np.diff(ladder) <= 0):  # the first that works is kept: a ladder out of order would skip a smaller one
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must increase (dB): the smallest relaxation that works is kept")
    from ..feasibility import TargetSpecification

    if structure not in (None, "certificate", "fixed"):
        raise ValueError(f"structure={structure!r} must be 'certificate' or 'fixed'")
    if isinstance(spec, str) and spec == "target":
        from ..feasibility import specification_for_target

        # the plant cases the pair is certified on are the ones the design must meet it on
        offsets = kwargs.pop("template_offsets") if structure != "fixed" and "template_offsets" in kwargs else None
        spec = specification_for_target(model, model.check_wind_speed(wind_speed), target_reduction,
                                        **({} if offsets is None else {"case_offsets": offsets}))
    elif isinstance(spec, str):  # "notch"
        spec = None
    if structure == "certificate" and not isinstance(spec, TargetSpecification):
        raise ValueError("structure='certificate' needs spec='target' or a feasibility.TargetSpecification (it carries "
                         "the certificate)")
    if isinstance(spec, TargetSpecification) and structure != "fixed":
        from .certificate import design_from_certificate

        allowed = {"max_sensitivity", "min_decay", "design_omega", "dense_omega"}
        if "template_offsets" in kwargs:
            raise TypeError("design_qft(spec=TargetSpecification) meets the pair on the plant cases it was certified on "
                            "(spec.case_speeds): make the specification with specification_for_target(..., "
                            "case_offsets=...) instead of passing template_offsets=")
        if set(kwargs) - allowed:
            raise TypeError(f"design_qft(structure='certificate') takes the options {sorted(allowed)}, "
                            f"got {sorted(set(kwargs) - allowed)}")
        if model.check_wind_speed(wind_speed) != spec.design.wind_speed:
            raise ValueError(f"spec was made at {spec.design.wind_speed:g} m/s, not at wind_speed={wind_speed!r}")
        return design_from_certificate(model, spec, **kwargs)
    if spec is not None:
        return _design_single(model, wind_speed, None, speed_relax_db=float(ladder[0]), given=_given_spec(spec), **kwargs)
    design = None
    for relax in ladder:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            design = _design_single(model, wind_speed, target_reduction, speed_relax_db=float(relax), **kwargs)
        if design.success:
            return design
    warnings.warn(f"design_qft at {design.wind_speed:g} m/s (speed spec relaxed up to {ladder[-1]:g} dB): {design.message}",
                  RuntimeWarning, stacklevel=2)
    return design


def check_design_speed(model, wind_speed: float) -> float:
    """``wind_speed`` checked to be one where a pitch controller can be designed (``model.wind_range``).

    Below it the reason is named: below rated ROSCO's pitch sits at fine pitch (the pitch
    loop open, its linearisation zero, :func:`specdesign.rosco.rosco_baseline`) and the tower
    load is the generator-torque loop's; docs/below_rated.md measures what a stiffer torque
    loop buys for the tower there and what it costs in power.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel or specdesign.openfast.LinearTurbine
        The turbine.
    wind_speed : float
        Operating point, m/s.

    Returns
    -------
    float
        The wind speed, m/s.

    Raises
    ------
    ValueError
        Outside ``model.wind_range``; below rated (a model with a ``torque_control``) with the
        reason: no pitch loop to design there.

    Examples
    --------
    >>> from specdesign.qft import check_design_speed
    >>> from specdesign.turbine import iea15mw
    >>> check_design_speed(iea15mw(), 11)
    11.0
    """
    wind_speed = positive_scalar(wind_speed, "wind_speed")
    law = getattr(model, "torque_control", None)
    lo = model.wind_range[0]
    if law is not None and model.operating_range[0] <= wind_speed < lo:
        rated = model.rated_wind_speed()
        where = (f"below rated ({rated:.2f} m/s): ROSCO's pitch sits at fine pitch there (the pitch loop is open, "
                 "its linearisation zero), so there is no pitch loop to shape; the tower load below rated is the "
                 "generator-torque loop's (ROSCO's torque law, closed in model.linearize). A stiffer torque loop "
                 "lowers the tower DEL there at a cost in power: docs/below_rated.md"
                 if wind_speed < rated else
                 f"between rated ({rated:.2f} m/s) and the lowest design speed: in the lulls the pitch saturates at "
                 "fine pitch and the plant changes fastest there (docs/below_rated.md)")
        raise ValueError(f"wind_speed={wind_speed!r} m/s is {where}; pitch designs start at {lo:g} m/s "
                         f"(model.wind_range), and a schedule holds its lowest design down to rated")
    return model.check_wind_speed(wind_speed)


def _given_spec(spec):
    """(tower, speed) of a TargetSpecification or a pair, each with ``response(omega)``."""
    from ..spec import specification_pair

    pair = specification_pair(spec)
    if pair is None or not all(hasattr(x, "response") for x in pair):
        raise TypeError("spec must be a feasibility.TargetSpecification or a pair (tower, speed) of specifications with "
                        f"response(omega), got {type(spec).__name__}")
    return pair


def _design_single(model, wind_speed, target_reduction=25.0, *, given=None, spec_reduction=15.0,
                   template_offsets=(-1.0, -0.5, 0.5, 1.0),
                   design_omega=None, dense_omega=None, speed_relax_db=3.0, tower_relax_db=6.0, tower_relax_omega=1.3,
                   max_sensitivity=1.9, min_decay=0.02, keep_below=0.6, refine=2, maxfev=3000) -> QFTDesign:
    """One design with a fixed speed-spec relaxation; see :func:`design_qft`."""
    from loopshaping import qft as lqft

    from .. import spec as sp

    v = model.check_wind_speed(wind_speed)  # the model's type is checked by design_qft
    t = None if given is not None else del_target(target_reduction)
    for name, val in (("speed_relax_db", speed_relax_db), ("tower_relax_db", tower_relax_db)):
        if not (np.isfinite(val) and val >= 0):
            raise ValueError(f"{name}={val!r} must be a finite relaxation ≥ 0 dB")
    positive_scalar(tower_relax_omega, "tower_relax_omega")
    if not max_sensitivity > 1:
        raise ValueError(f"max_sensitivity={max_sensitivity!r} must be > 1 (|1/(1+L)| bound)")
    positive_scalar(min_decay, "min_decay")
    offsets = np.atleast_1d(np.asarray(template_offsets, float))
    wd = DEFAULT_DESIGN_OMEGA.copy() if design_omega is None else lqft.check_grid(design_omega, "design_omega")
    wdense = np.logspace(np.log10(0.005), np.log10(20.0), 600) if dense_omega is None else lqft.check_grid(dense_omega, "dense_omega")

    speeds, nom = case_speeds(v, offsets, model.wind_range, name="template_offsets")
    specs = sp.design_specifications(model, v, speed_relax_db=speed_relax_db, spec_reduction=spec_reduction,
                                     tower_relax_db=tower_relax_db, tower_relax_omega=tower_relax_omega,
                                     keep_below=keep_below)
    base, shaping, tower_spec, speed_spec = specs.base, specs.shaping, specs.tower, specs.speed
    tower_shaping, speed_shaping = tower_spec.shaping, None
    if given is not None:
        # a given pair: each case gets ROSCO's map times the nominal ratio W/T^ROSCO
        tower_spec, speed_spec = given
        t_ref, s_ref = base.system, sp.speed_specification(model, v).baseline
        tower_shaping = spec_ratio(tower_spec, t_ref)
        speed_shaping = spec_ratio(speed_spec, s_ref)
        shaping = sp.ShapingResult((), sp.promise_of(tower_shaping(base.omega), base), float("nan"), "del", True,
                                   "given specification",
                                   tower_spec if isinstance(tower_spec, sp.Specification) else None)
    promise = sp.promise_of(tower_spec, base) if given is None else shaping.promise
    if t is None:
        t = float(promise.exact_del)  # the target the specification carries

    prob = TuningProblem(model, v, speeds, nom, wd, tower_shaping, speed_relax_db, max_sensitivity, base,
                         speed_shaping=speed_shaping)
    # Sharp features of the specs (the lightly damped tower-mode poles and zeros of every case's
    # ROSCO loop) are design frequencies and dense-check points too: a bound that holds on
    # both sides of a narrow dip of W can still fail inside it.
    sharp = _sharp_frequencies(prob, design_omega is None)
    if given is not None:
        # a given specification's own narrow features (a lightly damped pole or zero of W, e.g.
        # a near-axis zero of a designed closed loop) are design frequencies, and the dense
        # check is refined around them as H∞'s assessment is: a dip between grid points hid a
        # 1.3 dB violation
        roots = np.concatenate([spec_roots(x_) for x_ in given])
        light = lightly_damped(roots)
        sharp = np.unique(np.r_[sharp, np.abs(light[light.imag > 0])])
        sharp = sharp[(sharp >= 0.005) & (sharp <= 20.0)]
        wdense = refine_grid(wdense, light)
    if sharp.size:
        prob.set_design(np.unique(np.r_[prob.wd, sharp]))
        wdense = np.unique(np.r_[wdense, sharp[(sharp >= wdense[0]) & (sharp <= wdense[-1])]])
    x = rosco_start(prob.rosco[nom])
    rounds = 0
    while True:
        x, feasible = tune(prob, x, None if given is not None else t, min_decay, maxfev)
        cb, ca = controllers(x, v)
        pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs = loop_checks(prob, cb, ca, wdense)
        bad = [w for chk in (pitch_check, atd_check) for name in chk.names for w in [chk.worst(name)] if w[1] < 0]
        # more design frequencies cannot rescue a design that already fails on the ones it has
        if not bad or not feasible or rounds >= refine:
            break
        new = np.unique(np.r_[prob.wd, [w[0] for w in bad]])
        if new.size == prob.wd.size:
            break
        prob.set_design(new)
        rounds += 1

    red, dred, gs, ps, rate = prob.performance(x)
    return assemble_design(model, prob, cb, ca, wdense, t, (red, dred, gs, ps, rate), base=base, tower_spec=tower_spec,
                           speed_spec=speed_spec, shaping=shaping, promise=promise, parameters=from_vector(x),
                           options=dict(spec_reduction=spec_reduction, template_offsets=tuple(offsets),
                                        speed_relax_db=speed_relax_db, tower_relax_db=tower_relax_db,
                                        tower_relax_omega=tower_relax_omega, max_sensitivity=max_sensitivity,
                                        min_decay=min_decay, refine_rounds=rounds),
                           checks=(pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs))


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
    from loopshaping import qft as lqft

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


    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stable = [check_stability(closed_loop(P, cb, ca, warn=False), tol=0.0) for P in prob.plants]
        cl = closed_loop(prob.plants[nom], cb, ca, warn=False)
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
        actuator_peak_sensitivity=peak_in, target_reduction=t, success=success, message=message, parameters=parameters,
        options=options,
    )


def design_schedule(model: TurbineModel, wind_speeds: Sequence[float] = (15, 17, 19, 21, 23, 25),
                    target_reduction: float | Sequence[float] = 25.0, *, specification: str = "target",
                    progress: bool = True, **kwargs: Any) -> tuple[QFTDesign, ...]:
    """:func:`design_qft` at every wind speed (m/s); returns a tuple of :class:`QFTDesign`.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speeds : sequence of float
        Operating points, m/s.
    target_reduction : float or sequence of float
        Tower-base DEL reduction to reach, %: one number, or one value per wind speed.
    specification : {"target", "notch"}
        ``"target"`` (default): specification-driven, the specification for the target first
        (:func:`specdesign.feasibility.specification_for_target`), then the design that meets
        it (:func:`design_qft`'s default). ``"notch"``: the fixed-structure design against the
        notch specification and a DEL target (``design_qft(spec="notch")``).
    progress : bool
        Show a progress bar over the wind speeds (tqdm.auto: a widget in Jupyter).
    **kwargs
        Other keywords go to :func:`design_qft`.

    Returns
    -------
    tuple of QFTDesign
        One design per wind speed, in the order of ``wind_speeds``.

    Raises
    ------
    ValueError
        If ``wind_speeds`` is not a non-empty 1-D sequence, ``target_reduction`` does not
        broadcast to it, ``specification`` is unknown, or :func:`design_qft` (or, with
        ``"target"``, :func:`specdesign.feasibility.specification_for_target`) raises.
    TypeError
        As :func:`design_qft`.

    Warns
    -----
    RuntimeWarning
        As :func:`design_qft`, for each wind speed whose design does not meet every spec; and
        for a model with a torque law when the lowest design, which a schedule holds below
        rated, lifts the pitch off fine pitch for the speed deficit there
        (:func:`specdesign.qft.fine_pitch_lift` above the law's ``pitch_switch``).

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.qft import design_schedule, design_table, format_table
    >>> designs = design_schedule(turbine.iea15mw(), (15, 19, 23))  # doctest: +SKIP
    >>> print(format_table(design_table(designs)))  # doctest: +SKIP
    """
    vs = np.atleast_1d(np.asarray(wind_speeds, float))
    if vs.ndim != 1 or vs.size == 0:
        raise ValueError("wind_speeds must be a non-empty 1-D sequence of wind speeds in m/s")
    targets = np.broadcast_to(np.asarray(target_reduction, float), vs.shape)
    if specification not in ("notch", "target"):
        raise ValueError(f"specification={specification!r} must be 'notch' or 'target'")
    for v in vs:  # before any design: a speed below the design range is refused with its reason
        check_design_speed(model, float(v))
    from tqdm.auto import tqdm

    out = []
    for v, tr in tqdm(list(zip(vs, targets)), desc=f"QFT designs ({specification} specification)", unit="speed",
                      disable=not progress):
        out.append(design_qft(model, float(v), float(tr), spec=specification, **kwargs))
    _warn_held_design(model, out[int(np.argmin(vs))])
    return tuple(out)


def _warn_held_design(model, design):
    """Warn when a schedule's lowest design, held below rated, would lift the pitch off fine pitch."""
    from .checks import fine_pitch_lift

    law = getattr(model, "torque_control", None)
    if law is None:
        return
    deficit = law.pitch_reference_speed - law.min_speed  # the model's gen_speed output is the rotor-shaft speed
    lift = fine_pitch_lift(design.pitch_controller, deficit)
    if lift > law.pitch_switch:
        warnings.warn(f"design_schedule: the lowest design ({design.wind_speed:g} m/s), which a schedule holds down to "
                      f"rated and below, answers the speed deficit below rated ({deficit:.3f} rad/s) by lifting the pitch "
                      f"{np.degrees(lift):.1f}° off fine pitch (qft.fine_pitch_lift): below rated it leaves fine pitch and "
                      "ROSCO's torque state machine goes to rated torque (docs/below_rated.md)", RuntimeWarning, stacklevel=3)


def design_table(designs: Iterable[QFTDesign]) -> list[dict[str, Any]]:
    """Rows (dicts) of the per-wind-speed table: promised vs predicted reduction, SD changes, margins.

    Parameters
    ----------
    designs : iterable of QFTDesign
        Designs, e.g. from :func:`design_schedule`.

    Returns
    -------
    list of dict
        :meth:`QFTDesign.row` of each design (reductions and changes in %, margins in dB and
        degrees, wind speed in m/s).

    Raises
    ------
    TypeError
        If an element is not a :class:`QFTDesign`.

    Examples
    --------
    >>> from specdesign.qft import design_table
    >>> design_table([])
    []
    """
    designs = list(designs)
    if not all(isinstance(d, QFTDesign) for d in designs):
        raise TypeError("designs must be QFTDesign objects (from design_qft / design_schedule)")
    return [d.row() for d in designs]


def format_table(rows: Iterable[dict[str, Any]]) -> str:
    """Markdown table of :func:`design_table` rows (reductions and changes in %, margins in dB/deg).

    Parameters
    ----------
    rows : iterable of dict
        Rows of :func:`design_table` (:meth:`QFTDesign.row`).

    Returns
    -------
    str
        A Markdown table, one line per row after the header and the separator.

    Raises
    ------
    KeyError
        If a row lacks a key of :meth:`QFTDesign.row`.

    Examples
    --------
    >>> from specdesign.qft import format_table
    >>> table = format_table([])  # the header and the separator line
    >>> len(table.splitlines()), table.splitlines()[0].split(" | ")[:2]
    (2, ['| v [m/s]', 'notch-spec promise DEL [%]'])
    """
    head = ("| v [m/s] | notch-spec promise DEL [%] | relaxed-spec promise DEL [%] | predicted DEL red. [%] | predicted damage red. [%] | gen-speed SD [%] "
            "| pitch SD [%] | pitch-rate SD [%] | GM pitch [dB] | PM pitch [deg] | GM ATD [dB] | PM ATD [deg] "
            "| bounds | dense check | stable | states |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        lines.append(
            f"| {r['wind_speed']:g} | {r['notch_promise_del_pct']:.1f} | {r['promised_del_pct']:.1f} | {r['predicted_del_pct']:.1f} | {r['predicted_damage_pct']:.1f} "
            f"| {r['gen_speed_sd_change_pct']:+.1f} | {r['pitch_sd_change_pct']:+.1f} | {r['pitch_rate_sd_change_pct']:+.1f} "
            f"| {r['gain_margin_db']:.1f} | {r['phase_margin_deg']:.1f} | {r['atd_gain_margin_db']:.1f} "
            f"| {r['atd_phase_margin_deg']:.1f} | {'yes' if r['bounds_met'] else 'NO'} | {'pass' if r['dense_check_passed'] else 'FAIL'} "
            f"| {'yes' if r['all_stable'] else 'NO'} | {r['n_states']} |")
    return "\n".join(lines)


def __getattr__(name):
    if name == "DEFAULT_DESIGN_OMEGAS":  # renamed: one name for frequency grids, omega
        warnings.warn("DEFAULT_DESIGN_OMEGAS is deprecated, use DEFAULT_DESIGN_OMEGA", DeprecationWarning, stacklevel=2)
        return DEFAULT_DESIGN_OMEGA
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
