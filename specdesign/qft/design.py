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
    merge_frequencies,
    refine_grid,
)
from ..feasibility import (
    HF_END,
    MAX_HF_GAIN_RATIO,
    HF_OMEGA,
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
from .specs import SPEED_RELAX_DB, QFTSpecification, spec_from_certified
from .structure import controllers, filter_polys, from_vector, rosco_start
from .tuner import TuningProblem, tune

if TYPE_CHECKING:

    from ..turbine import TurbineModel

__all__ = ["design_qft", "design_schedule", "design_table", "format_table", "check_design_speed", "held_lift"]


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
    return merge_frequencies(w[(w >= 0.005) & (w <= 20.0)])


def design_qft(model: TurbineModel, wind_speed: float, target_reduction: float = TARGET_REDUCTION, *,
               spec: QFTSpecification | None = None, structure: str | None = None, **kwargs: Any) -> QFTDesign:
    """QFT design at ``wind_speed`` (m/s) that meets a fatigue-based specification pair.

    By default specification-driven (the method's centre, seed paper Sect. 3-4): the feasible
    specification pair for ``target_reduction`` first
    (:func:`specdesign.feasibility.specification_for_target`, certified over the plant cases),
    then the controller that meets it at every plant case on the dense check (its certificate
    reduced to the lowest order that does, 2-5 s). ``spec=spec_notch(target)`` is the earlier
    automatic procedure: fixed structures (PI + notch + low-pass and an ATD) started from
    ROSCO, tuned against the bounds of every plant case with a DEL-target penalty (5-60 s).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel or specdesign.openfast.LinearTurbine
        The turbine, e.g. ``turbine.iea15mw()``.
    wind_speed : float
        Operating point, m/s (above rated, inside ``model.wind_range``).
    target_reduction : float
        Tower-base DEL reduction (1 Hz, m = 4) vs ROSCO, % (0-100): without ``spec``, the
        promise of the specification that is made and met. Not used with a ``spec`` (it
        carries its own).
    spec : QFTSpecification, optional
        The specification to meet. Default: the certified pair
        ``specification_for_target(model, wind_speed, target_reduction)``, as with
        :func:`spec_from_certified`. Made from other sources by :func:`spec_from_certified`
        (a :class:`specdesign.feasibility.TargetSpecification` made beforehand),
        :func:`spec_from_pair` (W_MyT, W_Ω: each plant case gets ROSCO's map at its speed
        times the nominal ratio W/T^ROSCO; no DEL penalty, ``target_reduction`` is set to the
        pair's promise) or :func:`spec_notch` (the notch specification made here, a DEL target
        and a ladder of speed relaxations: the design with the smallest relaxation that meets
        every spec is returned, else the last attempt, with a warning). ``success`` means:
        every bound met, the dense check passed for every case, every loop stable (and with
        :func:`spec_notch` the DEL target reached).
    structure : {"certificate", "fixed"}, optional
        The controller designed. ``"fixed"``: the tuned fixed structures (PI + notch + low-pass
        and a first-order ATD). ``"certificate"`` (only with a certified pair, the default's
        or :func:`spec_from_certified`'s; their default): the specification's certificate
        reduced to the lowest order that meets it over the plant cases
        (:func:`specdesign.qft.certificate.design_from_certificate`; options
        ``max_sensitivity``, ``min_decay``, ``design_omega``, ``dense_omega``, and without
        ``spec`` ``template_offsets``, ``max_hf_gain_ratio`` and ``held_below_rated``, with
        which the pair is made).
    **kwargs
        Options of each design attempt (keyword only; the certificate takes only the four
        named above, the fixed structures all of these):

        spec_reduction : float, default 15.0
            Damage reduction (%) the notch-shaped tower specification promises
            (:func:`specdesign.spec.shape_to_target`, notches above ``keep_below`` rad/s).
        template_offsets : sequence of float, default (-1, -0.5, 0.5, 1)
            Wind-speed offsets (m/s) of the neighbouring operating points (clipped to
            ``model.wind_range``). Without ``spec`` the plant cases the specification is
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
            (2-10 rad/s, 3P inside) with C_β strictly proper; None switches it off. Without
            ``spec`` the certificate is made under it
            (``specification_for_target(max_hf_gain_ratio=...)``, which refuses a target the bound
            makes infeasible, naming it) and the design meets it with its order margin; a
            certified pair carries its own. The fixed structures are checked against it
            (dense check "hf_gain").
        held_below_rated : bool, default False
            Only without ``spec``: the design is held below rated by a schedule (its
            lowest design speed): the certificate, and the controller reduced from it, lift the
            pitch off fine pitch for the torque law's speed deficit by at most its
            ``pitch_switch`` (``specification_for_target(held_below_rated=True)``;
            :func:`held_lift`). :func:`design_schedule` sets it for its lowest speed.
        measurement_filter : control.TransferFunction, optional
            A fixed filter on both measurements (generator speed and tower-top velocity),
            e.g. :func:`three_p_notch`: both structures are tuned with it and returned with it
            (SISO, proper, stable, finite nonzero gain at 0). In OpenFAST it keeps 3P out of the
            pitch, which the linear model does not show (docs/openfast.md).
        refine : int, default 2
            Rounds adding the dense check's failing frequencies to the design set.
        maxfev : int, default 3000
            Iterations at most of each SLSQP run of the tuning (phase one and polish).

    Returns
    -------
    QFTDesign
        The design; ``success`` is False (with a message, and a RuntimeWarning) when the
        target, a bound, the dense check or stability (of the loops or of the controller
        itself) is not met.

    Raises
    ------
    TypeError
        If ``model`` is not a :class:`specdesign.turbine.TurbineModel`, ``spec`` is not a
        :class:`QFTSpecification` (the message names the functions that make one), an option
        is unknown (or belongs to the other design: the tuner's options need
        :func:`spec_notch`, :func:`spec_from_pair` or ``structure="fixed"``).
    ValueError
        If ``wind_speed`` is outside ``model.wind_range``; ``target_reduction`` is not
        strictly between 0 and 100 %; no certified specification reaches it ("infeasible
        because ...", from :func:`specdesign.feasibility.specification_for_target`); ``spec``
        was made at another wind speed; ``structure="certificate"`` is asked of a spec without
        a certificate; a relaxation is negative or not finite; ``tower_relax_omega`` or
        ``min_decay`` is not positive; ``max_sensitivity`` ≤ 1; ``template_offsets`` is not a
        1-D array of finite offsets; or a frequency grid is invalid.

    Warns
    -----
    RuntimeWarning
        When no relaxation of a :func:`spec_notch` ladder gives a design that meets every
        specification (the last attempt is returned, ``success`` False).

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.qft import design_qft, spec_notch
    >>> d = design_qft(turbine.iea15mw(), 19.0)  # doctest: +SKIP
    >>> print(d.summary())  # doctest: +SKIP
    >>> fixed = design_qft(turbine.iea15mw(), 19.0, spec=spec_notch(25.0))  # doctest: +SKIP
    """
    _checked_options(model, wind_speed, spec, structure, kwargs)
    v = model.check_wind_speed(wind_speed)
    if spec is None:
        spec = _spec_for_target(model, v, target_reduction, structure, kwargs)
    spec_made_at(spec.target if spec.target is not None else spec, v)
    if structure == "certificate" and spec.kind != "certified":
        raise ValueError(f"structure='certificate' needs a certified specification (no spec, or "
                         f"qft.spec_from_certified(a feasibility.TargetSpecification): it carries the certificate), "
                         f"got a {spec.kind!r} specification")
    if spec.kind == "notch":
        return _design_notch(model, wind_speed, spec, kwargs)
    if spec.kind == "certified" and structure != "fixed":
        return design_from_certificate(model, spec.target, **_certificate_options(kwargs))
    return _design_single(model, wind_speed, None, speed_relax_db=float(SPEED_RELAX_DB[0]), given=(spec.tower, spec.speed),
                          **kwargs)


def _spec_for_target(model, v, target_reduction, structure, kwargs) -> QFTSpecification:
    """:func:`design_qft`'s default specification: the certified pair for ``target_reduction``
    at ``v`` (m/s), made with the options of ``kwargs`` that make it (taken out of them)."""
    made = {}
    if structure != "fixed":
        # the plant cases the pair is certified on are the ones the design must meet it on
        if "template_offsets" in kwargs:
            made["case_offsets"] = kwargs.pop("template_offsets")
        # the certificate meets the high-frequency gain bound, and so does the design reduced from it
        made.update({k: kwargs.pop(k) for k in ("max_hf_gain_ratio", "held_below_rated") if k in kwargs})
    return spec_from_certified(specification_for_target(model, v, target_reduction, **made))


def _certificate_options(kwargs) -> dict:
    """``kwargs`` checked to be options of :func:`design_from_certificate` (a certified pair's)."""
    allowed = {"max_sensitivity", "min_decay", "design_omega", "dense_omega"}
    if "template_offsets" in kwargs:
        raise TypeError("design_qft(spec=spec_from_certified(...)) meets the pair on the plant cases it was certified "
                        "on (spec.target.case_speeds): make the specification with specification_for_target(..., "
                        "case_offsets=...) instead of passing template_offsets=")
    for k in ("max_hf_gain_ratio", "held_below_rated"):
        if k in kwargs:
            raise TypeError(f"design_qft(spec=spec_from_certified(...)) meets the {k} its certificate was made with "
                            f"(max_hf_gain_ratio, held_lift_limit of the TargetSpecification): make the specification "
                            f"with specification_for_target(..., {k}=...) instead of passing it here")
    if set(kwargs) - allowed:
        raise TypeError(f"design_qft(structure='certificate') takes the options {sorted(allowed)}, "
                        f"got {sorted(set(kwargs) - allowed)}")
    return kwargs


def _design_notch(model, wind_speed, spec, kwargs) -> QFTDesign:
    """:func:`design_qft` with :func:`spec_notch`: the fixed structures against the notch
    specification for each speed relaxation in turn, the first that meets every spec kept."""
    design = None
    for relax in spec.speed_relax_db:
        # each attempt's warnings (an unstable plant case, a weak tower mode) are said of the design
        # returned only: a rung passed over is not the result; its miss (RuntimeWarning) is said below
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            design = _design_single(model, wind_speed, spec.target_reduction, speed_relax_db=relax, **kwargs)
        if design.success:
            break
    for w in said:
        if not issubclass(w.category, RuntimeWarning):
            warnings.warn(w.message, w.category, stacklevel=3)
    if not design.success:
        warnings.warn(f"design_qft at {design.wind_speed:g} m/s (speed spec relaxed up to {spec.speed_relax_db[-1]:g} dB): "
                      f"{design.message}", RuntimeWarning, stacklevel=3)
    return design


def _checked_options(model, wind_speed, spec, structure, kwargs) -> None:
    """:func:`design_qft`'s arguments checked at the door, in its order (unknown options, the
    model, the wind speed, ``spec``, options of the other design, ``structure``)."""
    options = [n for n, p in inspect.signature(_design_single).parameters.items()
               if p.kind is p.KEYWORD_ONLY and n not in ("given", "speed_relax_db")]
    unknown = sorted(set(kwargs) - set(options) - {"held_below_rated"})
    if unknown:  # named here, not as a TypeError of an internal function
        ladder = (" (speed_relax_db is the notch specification's: spec=qft.spec_notch(target_reduction, "
                  "speed_relax_db=...))" if "speed_relax_db" in unknown else "")
        raise TypeError(f"design_qft got unknown option(s) {unknown}; its options are {sorted(options)}{ladder}")
    if not (isinstance(model, turbine.TurbineModel) or callable(getattr(model, "baseline_controller", None))):
        raise TypeError(f"model must be a specdesign.turbine.TurbineModel (e.g. turbine.iea15mw()) or a "
                        f"specdesign.openfast.LinearTurbine, got {type(model).__name__}")
    check_design_speed(model, wind_speed)
    if spec is not None and not isinstance(spec, QFTSpecification):
        raise TypeError(f"spec must be a qft.QFTSpecification, got {spec!r}: make it with qft.spec_from_certified "
                        "(a feasibility.TargetSpecification), qft.spec_from_pair (W_MyT, W_Ω) or qft.spec_notch (the "
                        "notch specification and a DEL target); without spec the certified pair for target_reduction "
                        "is made")
    fixed_only = set(kwargs) - {"max_sensitivity", "min_decay", "design_omega", "dense_omega", "template_offsets",
                                "max_hf_gain_ratio", "held_below_rated"}
    if spec is None and structure != "fixed" and fixed_only:
        raise TypeError(f"design_qft options {sorted(fixed_only)} belong to the fixed-structure design: pass "
                        "spec=qft.spec_notch(target_reduction) (the notch specification and a DEL target) or "
                        "structure='fixed'; the specification-driven default takes max_sensitivity, min_decay, "
                        "design_omega, dense_omega, template_offsets, max_hf_gain_ratio, held_below_rated")
    if "held_below_rated" in kwargs and not (spec is None and structure != "fixed"):
        raise TypeError("design_qft's held_below_rated belongs to the specification-driven default (no spec): "
                        "the certificate is made to keep fine pitch below rated")
    if structure not in (None, "certificate", "fixed"):
        raise ValueError(f"structure={structure!r} must be 'certificate' or 'fixed'")


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


def _design_single(model, wind_speed, target_reduction=TARGET_REDUCTION, *, given=None, spec_reduction=SPEC_REDUCTION,
                   template_offsets=(-1.0, -0.5, 0.5, 1.0),
                   design_omega=None, dense_omega=None, speed_relax_db=3.0, tower_relax_db=TOWER_RELAX_DB,
                   tower_relax_omega=TOWER_RELAX_OMEGA,
                   max_sensitivity=DESIGN_MAX_SENSITIVITY, min_decay=MIN_DECAY_RATE, keep_below=KEEP_BELOW, refine=2, maxfev=3000,
                   max_hf_gain_ratio=MAX_HF_GAIN_RATIO, measurement_filter=None) -> QFTDesign:
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
    filt = filter_polys(measurement_filter)
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
        wdense = merge_frequencies(wdense, hf_check_omega(model, wdense))
    prob = TuningProblem(model, v, speeds, nom, wd, tower_shaping, speed_relax_db, max_sensitivity, base,
                         speed_shaping=speed_shaping, controller_bound=bound, measurement_filter=filt)
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
        sharp = merge_frequencies(sharp, np.abs(light[light.imag > 0]))
        sharp = sharp[(sharp >= 0.005) & (sharp <= 20.0)]
        wdense = refine_grid(wdense, light)
    if sharp.size:
        prob.set_design(merge_frequencies(prob.wd, sharp))
        wdense = merge_frequencies(wdense, sharp[(sharp >= wdense[0]) & (sharp <= wdense[-1])])
    x = rosco_start(prob.rosco[nom])
    rounds = 0
    while True:
        x, feasible = tune(prob, x, None if given is not None else t, min_decay, maxfev)
        cb, ca = controllers(x, v, filt)
        pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs = loop_checks(prob, cb, ca, wdense)
        bad = [w for chk in (pitch_check, atd_check) for name in chk.names for w in [chk.worst(name)] if w[1] < 0]
        # more design frequencies cannot rescue a design that already fails on the ones it has
        if not bad or not feasible or rounds >= refine:
            break
        new = merge_frequencies(prob.wd, [w[0] for w in bad])
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
                                        min_decay=min_decay, refine_rounds=rounds, max_hf_gain_ratio=kappa,
                                        measurement_filter=None if filt is None else tuple(map(tuple, filt))),
                           checks=(pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs))


def design_schedule(model: TurbineModel, wind_speeds: Sequence[float] = (15, 17, 19, 21, 23, 25),
                    target_reduction: float | Sequence[float] | None = None, *,
                    spec: QFTSpecification | Sequence[QFTSpecification] | None = None, progress: bool = True,
                    **kwargs: Any) -> tuple[QFTDesign, ...]:
    """:func:`design_qft` at every wind speed (m/s); returns a tuple of :class:`QFTDesign`.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine.
    wind_speeds : sequence of float
        Operating points, m/s.
    target_reduction : float or sequence of float, optional
        Without ``spec``: the tower-base DEL reduction to reach, %: one number, or one value per
        wind speed (default :data:`specdesign.feasibility.target.TARGET_REDUCTION`). With
        ``spec`` it is not given: a notch specification carries its own target.
    spec : QFTSpecification or sequence of QFTSpecification, optional
        None (default): specification-driven, at each speed the certified pair for the target
        first (:func:`specdesign.feasibility.specification_for_target`), then the design that
        meets it (:func:`design_qft`'s default). A :func:`spec_notch` specification (it does not
        depend on the speed): the fixed-structure design against the notch specification made at
        each speed, with its DEL target and relaxation ladder; or one per wind speed. A certified
        pair or a given pair is made at one speed: design it with :func:`design_qft`.
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
        design), ``spec`` is a sequence of another length than ``wind_speeds``, or
        :func:`design_qft` (or, without ``spec``,
        :func:`specdesign.feasibility.specification_for_target`) raises.
    TypeError
        As :func:`design_qft`; for a bool or a string as a target; for a ``spec`` that is not a
        :func:`spec_notch` specification, or one given with ``target_reduction``.

    Warns
    -----
    RuntimeWarning
        As :func:`design_qft`, for each wind speed whose design does not meet every spec; and
        for a model with a torque law when the lowest design, which a schedule holds below
        rated, lifts the pitch off fine pitch for the speed deficit there
        (:func:`specdesign.qft.fine_pitch_lift` above the law's ``pitch_switch``). Without
        ``spec`` that design is made with ``held_below_rated=True`` (its certificate and
        its reduction keep the lift within ``pitch_switch``), so the warning is for the notch
        designs or a target that cannot be met so.

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.qft import design_schedule, design_table, format_table
    >>> designs = design_schedule(turbine.iea15mw(), (15, 19, 23))  # doctest: +SKIP
    >>> print(format_table(design_table(designs)))  # doctest: +SKIP
    >>> from specdesign.qft import spec_notch
    >>> notch = design_schedule(turbine.iea15mw(), (15, 19, 23), spec=spec_notch(25.0))  # doctest: +SKIP
    """
    vs = np.atleast_1d(np.asarray(wind_speeds, float))
    if vs.ndim != 1 or vs.size == 0:
        raise ValueError("wind_speeds must be a non-empty 1-D sequence of wind speeds in m/s")
    specs = _schedule_specs(spec, target_reduction, vs.size)
    for v in vs:  # before any design: a speed below the design range is refused with its reason
        check_design_speed(model, float(v))
    if specs is not None:  # each notch specification carries its target (design_qft does not read the argument)
        target_reduction = [x.target_reduction for x in specs]
    elif target_reduction is None:
        target_reduction = TARGET_REDUCTION
    # every target too (a bool or a string is no target), before the first design
    per_speed = np.ndim(target_reduction) != 0
    if per_speed and np.shape(target_reduction) != vs.shape:
        raise ValueError(f"target_reduction has {np.size(target_reduction)} values for {vs.size} wind speeds; give "
                         "one number or one per wind speed")
    targets = np.array([del_target(x, f"target_reduction[{i}]" if per_speed else "target_reduction") for i, x in
                        enumerate(target_reduction if per_speed else [target_reduction] * vs.size)])

    out = []
    lowest = int(np.argmin(vs))
    held = specs is None and getattr(model, "torque_control", None) is not None
    kind = "target" if specs is None else "notch"
    for i, (v, tr) in enumerate(tqdm(list(zip(vs, targets)), desc=f"QFT designs ({kind} specification)",
                                     unit="speed", disable=not progress)):
        # the lowest design is held below rated: made to keep fine pitch for the speed deficit there
        extra = {"held_below_rated": True} if held and i == lowest else {}
        out.append(design_qft(model, float(v), float(tr), spec=None if specs is None else specs[i], **kwargs, **extra))
    _warn_held_design(model, out[lowest])
    return tuple(out)


def _schedule_specs(spec, target_reduction, n) -> tuple[QFTSpecification, ...] | None:
    """:func:`design_schedule`'s ``spec`` as one notch specification per wind speed (None without
    one), refusing the kinds made at one speed and a target given beside a specification."""
    if spec is None:
        return None
    many = isinstance(spec, Sequence) and not isinstance(spec, str)
    specs = tuple(spec) if many else (spec,) * n
    for s in specs:
        if not isinstance(s, QFTSpecification) or s.kind != "notch":
            got = f"a {s.kind!r} specification" if isinstance(s, QFTSpecification) else repr(s)
            raise TypeError(f"design_schedule's spec must be qft.spec_notch(target_reduction) (applied at every wind "
                            f"speed) or one per wind speed, got {got}: a qft.spec_from_certified or qft.spec_from_pair "
                            "specification is made at one speed (design it with qft.design_qft); without spec each "
                            "speed gets the certified pair for target_reduction")
    if len(specs) != n:
        raise ValueError(f"spec has {len(specs)} specifications for {n} wind speeds; give one or one per wind speed")
    if target_reduction is not None:
        raise TypeError("design_schedule: give target_reduction or spec, not both: a notch specification carries its "
                        "DEL target (qft.spec_notch(target_reduction))")
    return specs


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
    """Markdown table of :func:`design_table` rows (reductions and changes in %, margins in dB/deg,
    the tower mode's damping ratio of the design and of ROSCO).

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
            "| tower ζ (ROSCO) | bounds | dense check | stable | states |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        lines.append(
            f"| {r['wind_speed']:g} | {r['notch_promise_del_pct']:.1f} | {r['promised_del_pct']:.1f} | {r['predicted_del_pct']:.1f} | {r['predicted_damage_pct']:.1f} "
            f"| {r['gen_speed_sd_change_pct']:+.1f} | {r['pitch_sd_change_pct']:+.1f} | {r['pitch_rate_sd_change_pct']:+.1f} "
            f"| {r['gain_margin_db']:.1f} | {r['phase_margin_deg']:.1f} | {r['atd_gain_margin_db']:.1f} "
            f"| {r['atd_phase_margin_deg']:.1f} | {r['tower_damping_ratio']:.3f} ({r['baseline_tower_damping_ratio']:.3f}) "
            f"| {'yes' if r['bounds_met'] else 'NO'} | {'pass' if r['dense_check_passed'] else 'FAIL'} "
            f"| {'yes' if r['all_stable'] else 'NO'} | {r['n_states']} |")
    return "\n".join(lines)
