"""The automatic QFT design at one operating point and over a schedule (see :mod:`specdesign.qft`).

Units: ω in rad/s, wind speeds in m/s, reductions and standard-deviation changes in %
(reductions positive = less, changes positive = more), relaxations and gain margins in dB,
phase margins in degrees, decay rates in 1/s; β = −C_β·Ω_g − C_atd·ẋ_top.
"""
from __future__ import annotations

import inspect
import warnings
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np
from tqdm.auto import tqdm

from loopshaping import qft as lqft

from .. import turbine
from .._checks import del_target, positive_scalar, spec_made_at
from ..closedloop import (
    DESIGN_MAX_SENSITIVITY,
    MIN_DECAY_RATE,
    case_speeds,
    closed_loop,
    lightly_damped,
    refine_grid,
)
from ..feasibility import (
    HF_END,
    MAX_HF_GAIN_RATIO,
    HF_OMEGA,
    TargetSpecification,
    hf_check_omega,
    hf_gain_bound,
    specification_for_target,
)
from ..feasibility.achievable import hf_ratio
from ..feasibility.target import TARGET_REDUCTION
from ..spec import KEEP_BELOW, SPEC_REDUCTION, TOWER_RELAX_DB, TOWER_RELAX_OMEGA
from .certificate import design_from_certificate
from .checks import fine_pitch_lift, loop_checks, spec_ratio, spec_roots
from .result import DEFAULT_DESIGN_OMEGA, QFTDesign, assemble_design
from .structure import controllers, from_vector, rosco_start
from .tuner import TuningProblem, tune

if TYPE_CHECKING:

    from ..turbine import TurbineModel

__all__ = ["design_qft", "design_schedule", "design_table", "format_table", "SPEED_RELAX_DB", "check_design_speed",
           "held_lift"]


#: Relaxations (dB) of the generator-speed spec the notch design (``spec="notch"``) tries in turn,
#: smallest first: ROSCO's T_{Ω,w} dips at the tower mode where a well-damped loop cannot follow
#: it, and 3 dB is the least that the IEA 15 MW designs met; hinf.spec_like_qft uses the same.
SPEED_RELAX_DB = (3.0, 4.5, 6.0, 8.0)


def _sharp_frequencies(prob, enabled=True, zeta_max=0.3, spread=(0.99, 1.0, 1.01)):
    """|p|·spread for lightly damped (ζ < zeta_max) poles and zeros of every case's ROSCO
    closed-loop maps wind → gen_speed and wind → tower_base_my, inside 0.005-20 rad/s."""

    if not enabled:
        return np.zeros(0)
    out = []
    with warnings.catch_warnings():  # python-control's notes on the interconnections (unused signals)
        warnings.filterwarnings("ignore", category=UserWarning, module=r"control\.")
        for P, c in zip(prob.plants, prob.rosco):
            cl = closed_loop(P, c, warn=False)
            for y in ("gen_speed", "tower_base_my"):
                sys = cl[y, "wind"]
                for r in lightly_damped(np.r_[ct.poles(sys), ct.zeros(sys)], zeta_max):
                    if r.imag > 0:
                        out.extend(abs(r) * np.asarray(spread))
    w = np.asarray(out)
    return np.unique(w[(w >= 0.005) & (w <= 20.0)])


def design_qft(model: TurbineModel, wind_speed: float, target_reduction: float = TARGET_REDUCTION, *,
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
        increasing sequence tried in turn (default :data:`SPEED_RELAX_DB`): the design with the
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
        max_sensitivity : float, default :data:`~specdesign.closedloop.DESIGN_MAX_SENSITIVITY`
            Bound on |1/(1+L)| for both loops and at the actuator (> 1).
        min_decay : float, default 0.02
            Required closed-loop decay rate, 1/s (poles left of −min_decay).
        keep_below : float, default 0.6
            Protected band of the notch specification, rad/s (power regulation).
        max_hf_gain_ratio : float or None, default :data:`~specdesign.feasibility.MAX_HF_GAIN_RATIO` (the measured κ, on)
            κ of the high-frequency gain bound, |C_β(jω)| ≤ κ·|C_ROSCO(jω)| on HF_OMEGA-HF_END
            (2-10 rad/s, 3P inside) with C_β strictly proper; None switches it off. With
            ``spec="target"`` the certificate is made under it
            (``specification_for_target(max_hf_gain_ratio=...)``, which refuses a target the bound
            makes infeasible, naming it) and the design meets it with its order margin; a
            TargetSpecification carries its own. The fixed structures are checked against it
            (dense check "hf_gain").
        held_below_rated : bool, default False
            Only with ``spec="target"``: the design is held below rated by a schedule (its
            lowest design speed): the certificate, and the controller reduced from it, lift the
            pitch off fine pitch for the torque law's speed deficit by at most its
            ``pitch_switch`` (``specification_for_target(held_below_rated=True)``;
            :func:`held_lift`). :func:`design_schedule` sets it for its lowest speed.
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
        ``spec="notch"`` or ``structure="fixed"``).
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

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.qft import design_qft
    >>> d = design_qft(turbine.iea15mw(), 19.0)  # doctest: +SKIP
    >>> print(d.summary())  # doctest: +SKIP
    >>> fixed = design_qft(turbine.iea15mw(), 19.0, spec="notch")  # doctest: +SKIP
    """
    ladder = _checked_options(model, wind_speed, speed_relax_db, spec, structure, kwargs)
    if isinstance(spec, str) and spec == "target":
        # the plant cases the pair is certified on are the ones the design must meet it on
        offsets = kwargs.pop("template_offsets") if structure != "fixed" and "template_offsets" in kwargs else None
        # the certificate meets the high-frequency gain bound, and so does the design reduced from it
        hf = {k: kwargs.pop(k) for k in ("max_hf_gain_ratio", "held_below_rated") if structure != "fixed" and k in kwargs}
        spec = specification_for_target(model, model.check_wind_speed(wind_speed), target_reduction,
                                        **({} if offsets is None else {"case_offsets": offsets}), **hf)
    elif isinstance(spec, str):  # "notch"
        spec = None
    if structure == "certificate" and not isinstance(spec, TargetSpecification):
        raise ValueError("structure='certificate' needs spec='target' or a feasibility.TargetSpecification (it carries "
                         "the certificate)")
    if isinstance(spec, TargetSpecification) and structure != "fixed":
        allowed = {"max_sensitivity", "min_decay", "design_omega", "dense_omega"}
        if "template_offsets" in kwargs:
            raise TypeError("design_qft(spec=TargetSpecification) meets the pair on the plant cases it was certified on "
                            "(spec.case_speeds): make the specification with specification_for_target(..., "
                            "case_offsets=...) instead of passing template_offsets=")
        for k in ("max_hf_gain_ratio", "held_below_rated"):
            if k in kwargs:
                raise TypeError(f"design_qft(spec=TargetSpecification) meets the {k} its certificate was made with "
                                f"(spec.max_hf_gain_ratio, spec.held_lift_limit): make the specification with "
                                f"specification_for_target(..., {k}=...) instead of passing it here")
        if set(kwargs) - allowed:
            raise TypeError(f"design_qft(structure='certificate') takes the options {sorted(allowed)}, "
                            f"got {sorted(set(kwargs) - allowed)}")
        spec_made_at(spec, model.check_wind_speed(wind_speed))
        return design_from_certificate(model, spec, **kwargs)
    if spec is not None:
        spec_made_at(spec, model.check_wind_speed(wind_speed))
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


def _checked_options(model, wind_speed, speed_relax_db, spec, structure, kwargs) -> np.ndarray:
    """:func:`design_qft`'s arguments checked at the door, in its order (unknown options, the
    model, the wind speed, ``spec``, options of the other design, the relaxation ladder,
    ``structure``): the ladder of speed relaxations (dB, increasing)."""
    options = [n for n, p in inspect.signature(_design_single).parameters.items() if p.kind is p.KEYWORD_ONLY]
    unknown = sorted(set(kwargs) - set(options) - {"speed_relax_db", "held_below_rated"})
    if unknown:  # named here, not as a TypeError of an internal function
        raise TypeError(f"design_qft got unknown option(s) {unknown}; its options are {sorted(options)}")
    if not (isinstance(model, turbine.TurbineModel) or callable(getattr(model, "baseline_controller", None))):
        raise TypeError(f"model must be a specdesign.turbine.TurbineModel (e.g. turbine.iea15mw()) or a "
                        f"specdesign.openfast.LinearTurbine, got {type(model).__name__}")
    check_design_speed(model, wind_speed)
    if isinstance(spec, str) and spec not in ("target", "notch"):
        raise ValueError(f"spec={spec!r} must be 'target', 'notch', a feasibility.TargetSpecification or a pair "
                         "(tower, speed)")
    fixed_only = set(kwargs) - {"max_sensitivity", "min_decay", "design_omega", "dense_omega", "template_offsets",
                                "max_hf_gain_ratio", "held_below_rated"}
    if isinstance(spec, str) and spec == "target" and structure != "fixed" and (fixed_only or speed_relax_db is not None):
        named = sorted(fixed_only | ({"speed_relax_db"} if speed_relax_db is not None else set()))
        raise TypeError(f"design_qft options {named} belong to the fixed-structure design: pass spec='notch' (the "
                        "notch specification and a DEL target) or structure='fixed'; the specification-driven default "
                        "takes max_sensitivity, min_decay, design_omega, dense_omega, template_offsets, "
                        "max_hf_gain_ratio")
    if "held_below_rated" in kwargs and not (isinstance(spec, str) and spec == "target" and structure != "fixed"):
        raise TypeError("design_qft's held_below_rated belongs to the specification-driven design (spec='target'): "
                        "the certificate is made to keep fine pitch below rated")
    if speed_relax_db is None:
        speed_relax_db = SPEED_RELAX_DB
    ladder = np.atleast_1d(np.asarray(speed_relax_db, float))
    if ladder.ndim != 1 or ladder.size == 0 or not np.all(np.isfinite(ladder)) or np.any(ladder < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB or a sequence of them")
    if np.any(np.diff(ladder) <= 0):  # the first that works is kept: a ladder out of order would skip a smaller one
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must increase (dB): the smallest relaxation that works is kept")
    if structure not in (None, "certificate", "fixed"):
        raise ValueError(f"structure={structure!r} must be 'certificate' or 'fixed'")
    return ladder


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


def _design_single(model, wind_speed, target_reduction=TARGET_REDUCTION, *, given=None, spec_reduction=SPEC_REDUCTION,
                   template_offsets=(-1.0, -0.5, 0.5, 1.0),
                   design_omega=None, dense_omega=None, speed_relax_db=3.0, tower_relax_db=TOWER_RELAX_DB,
                   tower_relax_omega=TOWER_RELAX_OMEGA,
                   max_sensitivity=DESIGN_MAX_SENSITIVITY, min_decay=MIN_DECAY_RATE, keep_below=KEEP_BELOW, refine=2, maxfev=3000,
                   max_hf_gain_ratio=MAX_HF_GAIN_RATIO) -> QFTDesign:
    """One design with a fixed speed-spec relaxation; see :func:`design_qft`."""
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

    kappa = hf_ratio(max_hf_gain_ratio)
    bound = None if kappa is None else (lambda w: hf_gain_bound(model, v, w, kappa), (HF_OMEGA, HF_END))
    if bound is not None:  # the bound's check includes its band's ends and 3P
        wdense = np.union1d(wdense, hf_check_omega(model, wdense))
    prob = TuningProblem(model, v, speeds, nom, wd, tower_shaping, speed_relax_db, max_sensitivity, base,
                         speed_shaping=speed_shaping, controller_bound=bound)
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
                                        min_decay=min_decay, refine_rounds=rounds, max_hf_gain_ratio=kappa),
                           checks=(pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs))


def design_schedule(model: TurbineModel, wind_speeds: Sequence[float] = (15, 17, 19, 21, 23, 25),
                    target_reduction: float | Sequence[float] = TARGET_REDUCTION, *, specification: str = "target",
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
        If ``wind_speeds`` is not a non-empty 1-D sequence, ``target_reduction`` is not one
        DEL reduction in (0, 100) % or one per wind speed (every one checked before the first
        design), ``specification`` is unknown, or :func:`design_qft` (or, with
        ``"target"``, :func:`specdesign.feasibility.specification_for_target`) raises.
    TypeError
        As :func:`design_qft`; for a bool or a string as a target.

    Warns
    -----
    RuntimeWarning
        As :func:`design_qft`, for each wind speed whose design does not meet every spec; and
        for a model with a torque law when the lowest design, which a schedule holds below
        rated, lifts the pitch off fine pitch for the speed deficit there
        (:func:`specdesign.qft.fine_pitch_lift` above the law's ``pitch_switch``). With
        ``"target"`` that design is made with ``held_below_rated=True`` (its certificate and
        its reduction keep the lift within ``pitch_switch``), so the warning is for the notch
        designs or a target that cannot be met so.

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
    if specification not in ("notch", "target"):
        raise ValueError(f"specification={specification!r} must be 'notch' or 'target'")
    for v in vs:  # before any design: a speed below the design range is refused with its reason
        check_design_speed(model, float(v))
    # every target too (a bool or a string is no target), before the first design
    per_speed = np.ndim(target_reduction) != 0
    if per_speed and np.shape(target_reduction) != vs.shape:
        raise ValueError(f"target_reduction has {np.size(target_reduction)} values for {vs.size} wind speeds; give "
                         "one number or one per wind speed")
    targets = np.array([del_target(x, f"target_reduction[{i}]" if per_speed else "target_reduction") for i, x in
                        enumerate(target_reduction if per_speed else [target_reduction] * vs.size)])

    out = []
    lowest = int(np.argmin(vs))
    held = specification == "target" and getattr(model, "torque_control", None) is not None
    for i, (v, tr) in enumerate(tqdm(list(zip(vs, targets)), desc=f"QFT designs ({specification} specification)",
                                     unit="speed", disable=not progress)):
        # the lowest design is held below rated: made to keep fine pitch for the speed deficit there
        extra = {"held_below_rated": True} if held and i == lowest else {}
        out.append(design_qft(model, float(v), float(tr), spec=specification, **kwargs, **extra))
    _warn_held_design(model, out[lowest])
    return tuple(out)


def held_lift(model, design) -> float | None:
    """How far ``design``, held below rated by a schedule, lifts the pitch off fine pitch (rad).

    The speed deficit is the torque law's pitch reference minus its minimum speed
    (:func:`fine_pitch_lift`); a lift above the law's ``pitch_switch`` leaves fine pitch and
    ROSCO's torque state machine goes to rated torque.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine (its ``torque_control``).
    design : QFTDesign
        A design (its ``pitch_controller``).

    Returns
    -------
    float or None
        The lift, rad; None for a model without a torque law.
    """
    law = getattr(model, "torque_control", None)
    if law is None:
        return None
    deficit = law.pitch_reference_speed - law.min_speed  # the model's gen_speed output is the rotor-shaft speed
    return fine_pitch_lift(design.pitch_controller, deficit)


def _warn_held_design(model, design):
    """Warn when a schedule's lowest design, held below rated, would lift the pitch off fine pitch."""
    lift = held_lift(model, design)
    if lift is None:
        return
    law = model.torque_control
    deficit = law.pitch_reference_speed - law.min_speed
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
