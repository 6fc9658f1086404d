"""H∞ design of the pitch (and ATD) controller at one operating point on the fatigue-based
specifications, with reduction, discretisation and an assessment on a refined grid.

Units: ω in rad/s, wind speed in m/s, pitch in rad, generator speed in rad/s, tower-base
moment in N·m, reductions in %, relaxations and excesses in dB, decay rates in 1/s. Sign
convention of the workbench: β = −C_β·Ω_g − C_atd·ẋ_top; the synthesis closes u = K·y, so
[C_β, C_atd] = −K.
"""
from __future__ import annotations

import warnings
from collections.abc import Sequence
from itertools import pairwise
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np
from numpy.typing import ArrayLike

from loopshaping import check, qft
from loopshaping import hinf as lhinf

from .. import closedloop, spectral, wind
from .. import spec as sp
from .._blas import one_blas_thread
from .._checks import finite_system, spec_made_at
from ..closedloop import MIN_DECAY_RATE, closed_loop_mimo, refine_grid
from ..closedloop.maps import state_space_response
from ..fatigue import TOWER_M
from ..feasibility import HF_END, HF_OMEGA, MAX_HF_GAIN_RATIO, hf_check_omega, hf_gain_bound
from ..feasibility.achievable import hf_ratio
from .cases import CaseCheck, refine_on_cases
from .plant import DEFAULT_INTEGRAL_CORNER, generalized_plant
from ..feasibility.target import TARGET_REDUCTION
from .specs import HinfSpecification, spec_for_target
from .weights import DEFAULT_MIN_DAMPING, siso_weight

if TYPE_CHECKING:
    from loopshaping.check import CheckResult
    from loopshaping.reduction import ReductionResult

    from ..spec import Specification
    from ..turbine import TurbineModel

__all__ = ['HinfDesign', 'DEFAULT_DECAY_RATE', 'ORDERS', 'ORDER_ROOM_DB', 'TOWER_BAND', 'design_hinf']

#: α (1/s) of the α-shifted synthesis in :func:`design_hinf`: the least decay rate of a designed
#: loop, :data:`specdesign.closedloop.MIN_DECAY_RATE`.
DEFAULT_DECAY_RATE = MIN_DECAY_RATE
#: Half-width of the tower-mode band (relative) over which ``tower_excess_db`` is the maximum.
TOWER_BAND = 0.1
#: States of the reduced controller tried in turn by :func:`design_hinf` (``order``): with a
#: certified pair the lowest whose multi-model step meets it at every plant case (with
#: :data:`ORDER_ROOM_DB` to spare; else the lowest that meets it) is kept. Under
#: the high-frequency gain bound the 25 % pairs at 19 and 25 m/s on the IEA 15 MW need 10 states
#: (8: 0.02 and 0.29 dB over W_MyT at a case, 2.6 dB over the bound at 25 m/s).
ORDERS = (8, 10, 12)
#: Room (dB) by which a reduced controller below the highest of ``order`` must meet its certified
#: pair at every plant case (both channels and the high-frequency gain bound) to be kept: the
#: choice of order is made with this room, not at 0 dB, where a rounding error could flip it. The
#: multi-model step aims 0.15 dB below the pair (:func:`specdesign.hinf.refine_on_cases`) and ends
#: 0.12-0.39 dB below when it succeeds; at 19 m/s on the IEA 15 MW 8 states end 0.027 dB above it,
#: which without the room left the order 0.027 dB from flipping, and with it 0.077 dB.
ORDER_ROOM_DB = 0.05
#: The multi-model step's least decay rate of every case's loop, 1/s (``decay_rate``, at least
#: this), and the fraction of it a lower order's design must keep to be chosen: ``case_check.met``
#: asks only > 0, and at 21 m/s a 10-state design met it with a pole at −1.5e-15 1/s, a rounding error.
_STEP_MIN_DECAY, _STEP_DECAY_ROOM = 1e-3, 0.5


@dataclass(frozen=True)
class HinfDesign:
    """Outcome of :func:`design_hinf` at one operating point (units: rad/s, N·m, rad, %).

    Every frequency-domain number is computed on ``omega``, the assessment grid
    (:func:`specdesign.closedloop.refine_grid`), DELs included.

    Parameters
    ----------
    pitch_controller : control.StateSpace
        C_β, generator speed (rad/s) → pitch (rad), in the workbench sign
        β = −C_β·Ω_g − C_atd·v, as a minimal SISO system for frequency-domain use (implement
        the 1×2 ``controller`` itself: see :func:`specdesign.closedloop.closed_loop_mimo`).
    atd_controller : control.StateSpace or None
        C_atd, tower-top velocity (m/s) → pitch (rad), same sign and use; None without ATD.
    controller : control.StateSpace
        The reduced K (u = K·y, y the measurements), ``order`` states.
    full_controller : control.StateSpace
        The synthesised full-order K (times the integrator F when one is built in).
    gamma : float
        The γ of the full-order design (-): the H∞ norm of the weighted closed loop
        (see :mod:`specdesign.hinf`).
    reduction : loopshaping.hinf.ReductionResult
        The controller reduction (reduced K, its H∞ error and bound, Hankel singular values).
    w_tower : specdesign.spec.Specification or control.LTI
        The tower-load specification W_MyT used as the weight, N·m per m/s.
    w_speed : specdesign.spec.Specification or control.LTI
        The generator-speed specification W_Ω used as the weight, rad/s per m/s.
    promised_del_reduction : float
        The tower specification's exact (Dirlik) promise, % (a TargetSpecification's own
        ``promise``: by default, without ``spec``, the promise of the pair met).
    predicted_del_reduction : float
        Dirlik on the reduced controller's closed loop vs ROSCO's, tower-base DEL, %.
    speed_excess_db : float
        Maximum over the grid of 20·log10(|T_Ω,w|/|W_Ω|), dB (≤ 0 means met).
    tower_excess_db : float
        The same for MyT at ``tower_mode``, dB.
    tower_mode : float
        Frequency of the tower mode (the open-loop pole pair with the highest wind → tower-base
        moment resonance, :func:`specdesign.closedloop.tower_pole`), rad/s.
    pitch_std : float
        Pitch-command standard deviation from the linear model, rad.
    pitch_std_baseline : float
        The same with ROSCO, rad.
    omega : numpy.ndarray
        The assessment grid, rad/s.
    check : loopshaping.check.CheckResult or None
        :func:`loopshaping.check.check` of the reduced pitch controller against both
        specifications in QFT's general form (specs "tower" and "speed", margins in dB,
        stability, gain/phase margins); None with ATD, whose 1×2 loop that SISO check does
        not cover.
    discrete_controller : control.StateSpace or None
        K sampled at ``dt`` (Tustin prewarped at the tower mode), or None.
    notes : tuple of str
        Notes of the weights, the synthesis and the relaxation ladder.
    zeta_min : float
        The least damping ratio of the reduced loop's oscillatory poles (-; 1 when none).
    zeta_min_frequency : float
        Its |p|, rad/s (nan when none).
    tower_damping_ratio : float
        Damping ratio (-) of the first tower fore-aft mode in the reduced loop
        (:func:`specdesign.closedloop.tower_damping`); below
        :data:`~specdesign.closedloop.MIN_TOWER_DAMPING_FRACTION` of ROSCO's the design warns
        (:class:`~specdesign.closedloop.TowerDampingWarning`); nan when the loop has moved the
        mode out of :func:`~specdesign.closedloop.tower_pole`'s span (``notes`` says so).
    baseline_tower_damping_ratio : float
        The same with ROSCO's PI (-).
    peak_sensitivity : float
        Peak |1/(1 + L_u)| at the actuator, L_u = Σ C_i·P_{y_i,β} (-).
    max_pole_real : float
        The reduced loop's largest pole real part Re p, 1/s.
    decay_rate : float
        The α of the synthesis, 1/s.
    tower_band_excess_db : float
        Maximum of the tower excess over ``tower_mode``·(1 ± :data:`TOWER_BAND`), dB.
    specs : str
        Which specifications were the weights, the ``kind`` of the
        :class:`~specdesign.hinf.HinfSpecification`: "target" (the certified pair of
        ``target_reduction``, the default), "given" (a pair or TargetSpecification handed
        over), "qft", "qft_design" or "rosco" ("custom", the field's default, for a record built directly).
    speed_relax_db : float
        The relaxation of ROSCO's T_{Ω,w} in the speed spec, dB (nan for custom specs).
    notch_spec : specdesign.spec.Specification or control.LTI
        The unrelaxed notch specification (ROSCO × notches of
        :func:`specdesign.spec.shape_to_target`; ``w_tower`` for custom specs).
    notch_promised_del_reduction : float
        Its promise, %.
    tower_notch_excess_db : float
        The tower excess against it at ``tower_mode``, dB (stricter than
        ``tower_excess_db`` when ``w_tower`` is relaxed).
    speed_excess_baseline_db : float
        Maximum of 20·log10(|T_Ω,w|/|T^ROSCO_Ω,w|), dB: the speed excess over ROSCO's unrelaxed
        response (what a relaxed speed spec gives away).
    case_check : specdesign.hinf.CaseCheck or None
        With a certified pair (a TargetSpecification) and pitch only: the explicit check of
        ``pitch_controller`` at every plant case the pair was certified on
        (:func:`specdesign.hinf.check_pair`); None otherwise.
    hf_excess_db : float
        Maximum of 20·log10(|C_β|/(κ·|C_ROSCO|)) on HF_OMEGA-HF_END (the grid's points there, the
        band's ends and 3P; :func:`specdesign.feasibility.hf_gain_bound`) at the nominal plant,
        dB (≤ 0 means the high-frequency gain bound is met; +inf with a direct term, −inf
        without a bound, κ = None).
    controller_unstable_poles : numpy.ndarray
        The reduced K's poles with Re > 0, 1/s (empty for a stable controller). The closed
        loop may be stable all the same (a conditionally stable loop): saturation, a rate limit or
        a start-up transient can then make it diverge.
    speed_integral_sign : int
        Sign of Re(C_β/C_ROSCO) at the grid's lowest frequency: +1 when the generator-speed channel
        regulates the speed with ROSCO's sign, −1 when it is reversed (the loop then holds the
        speed through another channel, e.g. an integrated tower-top velocity).

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.hinf import design_hinf
    >>> d = design_hinf(turbine.iea15mw(), 19.0)  # doctest: +SKIP
    >>> d.specs, d.controller.nstates, round(d.promised_del_reduction, 2)  # doctest: +SKIP
    ('target', 8, 25.05)
    """

    pitch_controller: ct.StateSpace
    atd_controller: ct.StateSpace | None
    controller: ct.StateSpace
    full_controller: ct.StateSpace
    gamma: float
    reduction: ReductionResult
    w_tower: Specification | ct.LTI
    w_speed: Specification | ct.LTI
    promised_del_reduction: float
    predicted_del_reduction: float
    speed_excess_db: float
    tower_excess_db: float
    tower_mode: float
    pitch_std: float
    pitch_std_baseline: float
    omega: np.ndarray
    check: CheckResult | None
    discrete_controller: ct.StateSpace | None
    notes: tuple[str, ...]
    zeta_min: float
    zeta_min_frequency: float
    tower_damping_ratio: float
    baseline_tower_damping_ratio: float
    peak_sensitivity: float
    max_pole_real: float
    decay_rate: float
    tower_band_excess_db: float
    specs: str = "custom"
    speed_relax_db: float = float("nan")
    notch_spec: Specification | ct.LTI | None = None
    notch_promised_del_reduction: float = float("nan")
    tower_notch_excess_db: float = float("nan")
    speed_excess_baseline_db: float = float("nan")
    case_check: CaseCheck | None = None
    hf_excess_db: float = -np.inf
    controller_unstable_poles: np.ndarray = field(default_factory=lambda: np.zeros(0, complex))
    speed_integral_sign: int = 1


def _qft_check(plant, pitch_controller, w_tower, w_speed, omega):
    """Re-check a SISO pitch controller with :mod:`loopshaping.check`: the tower spec in
    the general form |(A + B·C)/(1 + D·C)| ≤ |W_MyT| with A = P_{MyT,w},
    B = P_{MyT,w}P_{Ω,β} − P_{MyT,β}P_{Ω,w}, D = P_{Ω,β}; the speed spec with A = P_{Ω,w}, B = 0."""
    def resp(o, i):
        sub = plant[o, i]
        return lambda w: _response(sub, w).reshape(-1, 1)

    p_mw, p_mb = resp("tower_base_my", "wind"), resp("tower_base_my", "pitch_cmd")
    p_ow, p_ob = resp("gen_speed", "wind"), resp("gen_speed", "pitch_cmd")
    tower = qft.Spec("general", weight=siso_weight(w_tower, "w_tower"), name="tower", kind_args=dict(
        A=p_mw, B=lambda w: p_mw(w) * p_ob(w) - p_mb(w) * p_ow(w), C=1.0, D=p_ob))
    speed = qft.Spec("general", weight=siso_weight(w_speed, "w_speed"), name="speed",
                     kind_args=dict(A=p_ow, B=0.0, C=1.0, D=p_ob))
    return check.check([plant["gen_speed", "pitch_cmd"]], pitch_controller, [tower, speed], omega)


def _response(sys, omega, output=None, input="wind"):
    """sys[output, input] (or a SISO ``sys``) at s = jω, all ω (rad/s) at once: python-control
    solves one frequency at a time, minutes on the refined grids of a certified pair."""
    s = ct.ss(sys if output is None else sys[output, input])
    return state_space_response(s.A, s.B, s.C, s.D, np.asarray(omega, float).reshape(-1))[:, 0, 0]


def design_hinf(
    model: TurbineModel,
    wind_speed: float,
    target_reduction: float = TARGET_REDUCTION,
    *,
    spec: HinfSpecification | None = None,
    measurements: Sequence[str] | None = None,
    order: int | Sequence[int] = ORDERS,
    w_pitch: ct.LTI | float | None = None,
    m: float = TOWER_M,
    omega: ArrayLike | None = None,
    suboptimality: float = 0.05,
    reduction_method: str = "balanced",
    dt: float | None = None,
    min_damping: float = DEFAULT_MIN_DAMPING,
    decay_rate: float = DEFAULT_DECAY_RATE,
    integral_corner: float | None = None,
    max_hf_gain_ratio: float | None = MAX_HF_GAIN_RATIO,
    **plant_options: Any,
) -> HinfDesign:
    """Design, reduce and assess an H∞ pitch (and optional ATD) controller at one wind speed.

    Every frequency-domain number is computed on :func:`specdesign.closedloop.refine_grid`: ``omega`` refined
    around the lightly damped poles of the closed loop (full and reduced controller), and the
    poles and zeros of ROSCO's closed loop and of both specifications, so a narrow peak
    cannot fall between grid points.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        E.g. :func:`specdesign.turbine.iea15mw`.
    wind_speed : float
        Operating point, m/s, above rated.
    target_reduction : float
        Tower-base DEL reduction (1 Hz, m = ``m``) vs ROSCO, % (0-100), as in
        :func:`specdesign.qft.design_qft`: without ``spec``, the promise of the specification
        that is made and met. Not used with a ``spec``.
    spec : HinfSpecification, optional
        The specifications that are the weights and that the design is assessed against.
        Default: ``spec_for_target(model, wind_speed, target_reduction, m=m)``, the feasible
        pair of the DEL target certified over plant cases around ``wind_speed`` (as
        :func:`specdesign.qft.design_qft` does). Made from other sources by
        :func:`spec_from_certified` (a TargetSpecification made beforehand),
        :func:`spec_from_pair` (W_MyT, W_Ω), :func:`spec_from_qft` (exactly the specs a QFT
        design met), :func:`spec_like_qft` (QFT's notch specs, a ladder of speed relaxations
        tried in turn, the smallest whose reduced design meets both specs on the refined grid
        kept) or :func:`spec_from_rosco` (the unrelaxed notch spec and ROSCO's T_{Ω,w}, whose
        ζ = 0.01 dip at the tower mode no well-damped loop can follow, docs/hinf.md). A
        certified pair with pitch only (the default measurement then) adds the multi-model H∞
        step :func:`specdesign.hinf.refine_on_cases`: the reduced controller is adjusted until
        the pair holds at every plant case it was certified on, checked by
        :func:`specdesign.hinf.check_pair` (``case_check``; 5-15 s per speed).
    measurements : tuple of str, optional
        ``("gen_speed", "tower_top_vel")`` (1×2 controller, pitch + active tower damping) or
        ``("gen_speed",)`` (pitch only). Default: pitch only for a certified pair (its
        certificate's actuator), pitch + ATD otherwise.
    order : int or sequence of int
        States of the reduced controller, or several tried in increasing order (default
        :data:`ORDERS`): with a certified pair and pitch only the lowest whose multi-model step
        meets the pair at every plant case with :data:`ORDER_ROOM_DB` to spare is kept (else the
        lowest that meets it at all, else the highest, said as below); otherwise
        the first whose reduced controller stabilises the turbine.
    w_pitch : optional
        Pitch-activity weight, see :func:`generalized_plant`.
    m : float
        Wöhler exponent of the tower-base DEL (S-N curve on ranges).
    omega : array, optional
        Base grid in rad/s (default :func:`specdesign.spec.default_omega`), refined by
        :func:`specdesign.closedloop.refine_grid` for the assessment.
    suboptimality : float
        Passed to :func:`loopshaping.hinf.synthesize`.
    reduction_method : str
        Passed to :func:`loopshaping.hinf.reduce`.
    dt : float, optional
        Sample time (s): also return ``discrete_controller``, the reduced K by Tustin
        prewarped at the tower mode (exact there).
    min_damping : float
        Damping floor for the specifications' zeros in the weights (:func:`inverse_weight`):
        it caps W_Ω⁻¹ at ROSCO's narrow dip of T_{Ω,w} at the tower mode (ζ ≈ 0.01); the
        assessment uses the true specification, dip included.
        Without it (0) the synthesis copies the dip into a closed-loop pole pair of ζ ≈ 0.003.
    decay_rate : float
        The α (1/s) of an α-shifted synthesis (:func:`loopshaping.hinf.synthesize`) on the
        turbine's states and the integrator F (weights, in series, unshifted): every pole of
        the loop with the full-order controller has Re < −α (reduction may move them; the
        reduced loop's poles are reported in ``zeta_min`` and ``max_pole_real``).
    integral_corner : float, optional
        Corner ω_i (rad/s) of the integrator F(s) = (1 + s/ω_i)/s built into the plant
        (:func:`generalized_plant`). Default: 0.1 rad/s when ``decay_rate`` > 0 (without it
        the shift would move the controller's integral action to −α), none otherwise.
    max_hf_gain_ratio : float or None
        κ of the high-frequency gain bound, |C_β| ≤ κ·|C_ROSCO| on HF_OMEGA-HF_END (2-10 rad/s,
        3P included) with C_β strictly proper (``hf_excess_db``). Without ``spec`` the pair is
        made under it (``specification_for_target(max_hf_gain_ratio=...)``, which refuses a
        target it makes infeasible, naming it) and the multi-model step holds it at every plant
        case (``case_check``'s ``hf_excess_db`` and ``proper``); a TargetSpecification carries
        its own. On given specifications without the multi-model step (pitch + ATD, or a pair) the
        synthesis does not hold it: the design is measured against it and warns when it misses
        it (docs/hinf.md: raising the synthesis' sensor noise until it holds gives unstable,
        sign-reversed controllers). Default :data:`specdesign.feasibility.MAX_HF_GAIN_RATIO`, the
        measured κ (:data:`specdesign.feasibility.HF_GAIN_RATIO`); None switches it off.
    **plant_options
        ``noise``, ``noise_band``, ``rolloff``, ``shift`` for :func:`generalized_plant`.

    Returns
    -------
    HinfDesign
        The reduced design and its assessment; with a ladder of relaxations the smallest one
        met (else the last one, said in ``notes``).

    Raises
    ------
    TypeError
        If ``spec`` is not a :class:`HinfSpecification` (the message names the function that
        makes one), a weight is not an LTI system or a number, or ``plant_options`` has an
        unknown key.
    ValueError
        If ``spec`` was made at another wind speed (the same check as
        :func:`specdesign.qft.design_qft`'s); the plant at ``wind_speed`` has a NaN or inf
        entry; ``target_reduction`` is not in (0, 100) % without ``spec``; ``wind_speed`` is
        outside ``model.wind_range``; or a weight, the generalized plant, the synthesis or the
        reduction rejects its arguments (:func:`inverse_weight`, :func:`generalized_plant`,
        :func:`loopshaping.hinf.synthesize`, :func:`loopshaping.hinf.reduce`); an ill-posed
        synthesis names the wind speed.
    RuntimeError
        If the reduced controller of the last relaxation tried does not stabilise the
        turbine at any ``order`` (raise it).

    Warns
    -----
    specdesign.closedloop.ClosedLoopUnstableWarning
        When a reduced controller does not stabilise the turbine (before the RuntimeError, or
        before the next relaxation is tried).
    RuntimeWarning
        With a certified pair and pitch only: when the multi-model step leaves the pair
        missed at a plant case ("infeasible ... because": by how much, where, at which case;
        also in ``notes``). With a pair or with pitch + ATD (no multi-model step): when the
        reduced design does not meet it on the nominal plant's refined grid. The synthesis
        alone bounds the root-sum-square of the weighted outputs, not each ratio, and does
        not follow a certified pair's narrow tower-mode pattern; see docs/hinf.md.

    Examples
    --------
    >>> from specdesign import turbine
    >>> from specdesign.hinf import design_hinf, spec_like_qft
    >>> model = turbine.iea15mw()
    >>> d = design_hinf(model, 19.0)  # the certified pair for 25 %  # doctest: +SKIP
    >>> d.specs, d.case_check.met, d.predicted_del_reduction >= d.promised_del_reduction  # doctest: +SKIP
    ('target', True, True)
    >>> q = design_hinf(model, 19.0, spec=spec_like_qft(model, 19.0))  # QFT's notch specs, pitch + ATD  # doctest: +SKIP
    >>> q.speed_excess_db <= 0 and q.tower_band_excess_db <= 0  # doctest: +SKIP
    True
    """
    v = model.check_wind_speed(wind_speed)
    # a NaN plant: said here, naming the wind speed, before the specification search, the
    # baseline analysis or SLICOT meet it ("SVD did not converge")
    finite_system(model.linearize(v), f"the plant linearised at {v:g} m/s")
    if spec is None:  # design_qft's default: the feasible (certified) pair for the DEL target, then meet it
        spec = spec_for_target(model, v, target_reduction, m=m, max_hf_gain_ratio=max_hf_gain_ratio)
    elif not isinstance(spec, HinfSpecification):
        raise TypeError(f"spec must be a hinf.HinfSpecification, got {spec!r}: make it with hinf.spec_for_target, "
                        "spec_from_certified (a feasibility.TargetSpecification), spec_from_pair (W_MyT, W_Ω), "
                        "spec_from_qft (a QFTDesign), spec_like_qft (QFT's notch specs) or spec_from_rosco")
    # the same check as design_qft's: a record's promise holds at its own speed only
    spec_made_at(spec.target if spec.target is not None else spec, v)
    if measurements is None:
        measurements = ("gen_speed",) if spec.target is not None else ("gen_speed", "tower_top_vel")
    orders = _orders(order)
    kappa = spec.target.max_hf_gain_ratio if spec.target is not None else hf_ratio(max_hf_gain_ratio)
    base = sp.baseline_analysis(model, v, m=m, omega=omega)
    design = None
    for k, ((wt, ws), relax) in enumerate(zip(spec.pairs, spec.speed_relax_db)):
        last = k == len(spec.pairs) - 1
        try:
            design = _lowest_order(orders, lambda o, wt=wt, ws=ws, relax=relax: _design_once(
                model, v, base, wt, ws, spec.notch, spec.kind, relax, spec.target, measurements=measurements, order=o,
                w_pitch=w_pitch, m=m, suboptimality=suboptimality, reduction_method=reduction_method, dt=dt,
                min_damping=min_damping, decay_rate=decay_rate, integral_corner=integral_corner, kappa=kappa,
                **plant_options),
                min_decay=_STEP_DECAY_ROOM * max(decay_rate, _STEP_MIN_DECAY))
        except RuntimeError:
            if last:
                raise
            continue
        if last or (design.speed_excess_db <= 0 and design.tower_band_excess_db <= 0):
            break
    if len(spec.pairs) > 1:
        met = design.speed_excess_db <= 0 and design.tower_band_excess_db <= 0
        design = replace(design, notes=design.notes + (
            f"specs='{spec.kind}': speed spec relaxed by {design.speed_relax_db:g} dB, the smallest of "
            f"{spec.speed_relax_db} with both specs met on the refined grid" if met else
            f"specs='{spec.kind}': no relaxation of {spec.speed_relax_db} met both specs; the last is returned",))
        if not met:
            warnings.warn(f"design_hinf at {v:g} m/s: no relaxation of {spec.speed_relax_db} dB met both "
                          f"specifications; the last is returned, generator speed {design.speed_excess_db:+.2f} dB "
                          f"and tower load {design.tower_band_excess_db:+.2f} dB (tower-mode band) over them; "
                          "try pitch + ATD or a certified pair (the default)", RuntimeWarning,
                          stacklevel=2)
    # said of the design returned only (the orders and relaxations passed over are not the result)
    weak = closedloop.tower_damping_message("design_hinf", v, design.tower_damping_ratio,
                                            design.baseline_tower_damping_ratio,
                                            tower_damper=design.atd_controller is not None)
    if weak is not None:
        warnings.warn(weak, closedloop.TowerDampingWarning, stacklevel=2)
    for said in _carry_messages(design, v, kappa):
        warnings.warn(said, RuntimeWarning, stacklevel=2)
    return design


def _carry_messages(d, v, kappa):
    """What keeps the returned design off a real turbine: an unstable or sign-reversed controller, a
    high-frequency gain over the bound (the multi-model step's misses are said by it)."""
    out = []
    if d.controller_unstable_poles.size or d.speed_integral_sign < 0:
        poles = ", ".join(f"{p:.3g}" for p in d.controller_unstable_poles)
        what = [f"has unstable poles ({poles} 1/s): the loop is conditionally stable"] if poles else []
        if d.speed_integral_sign < 0:
            what.append("its generator-speed channel's integral action has the opposite sign of ROSCO's (with "
                        "pitch + ATD the speed is then held through the integrated tower-top velocity)")
        out.append(f"design_hinf at {v:g} m/s: the reduced controller {'; '.join(what)}. Saturation, the "
                   "pitch-rate limit or a start-up transient can make such a loop diverge: validate in OpenFAST "
                   "before use, or design on a certified pair with pitch only (the default)")
    if kappa is not None and d.case_check is None and d.hf_excess_db > 0:
        out.append(
            f"design_hinf at {v:g} m/s: C_β exceeds the high-frequency gain bound (κ = {kappa:g} × ROSCO's |C| on "
            f"{HF_OMEGA:g}-{HF_END:g} rad/s) by {d.hf_excess_db:.1f} dB: pitch-actuator wear and excited modes on a "
            "turbine with 3P and noise in the speed signal. The synthesis on given specifications does not hold the "
            "bound; the certified pair with pitch only (design_hinf's default) does")
    return out


def _orders(order):
    """``order`` as a tuple of increasing whole numbers ≥ 1 (states)."""
    orders = (order,) if isinstance(order, (int, np.integer)) and not isinstance(order, (bool, np.bool_)) else order
    try:
        out = tuple(int(o) for o in orders)
    except (TypeError, ValueError):
        raise TypeError(f"order={order!r} must be a whole number of states or a sequence of them") from None
    if not out or any(o < 1 or o != x or isinstance(x, (bool, np.bool_)) for o, x in zip(out, orders)) \
            or any(b <= a for a, b in pairwise(out)):
        raise ValueError(f"order={order!r} must be whole numbers of states ≥ 1, increasing")
    return out


def _lowest_order(orders, design_at, min_decay=0.0):
    """The design of the lowest of ``orders`` that meets its certified pair at every plant case
    with :data:`ORDER_ROOM_DB` to spare and every case's loop decaying at ≥ ``min_decay`` (1/s)
    (a design without the multi-model step: the first that stabilises); else the lowest that
    meets it at all; else the highest's."""
    # small dense algebra throughout: a second BLAS thread only synchronises (≈ 1.6× the CPU
    # time on the shared 2-core machine)
    met = None  # the lowest order that meets the pair without the room
    with one_blas_thread():
        for o in orders[:-1]:
            with warnings.catch_warnings():
                # this order may be passed over: its misses are not the result's (the last order's are said)
                warnings.filterwarnings("ignore", message="the certified pair is not met", category=RuntimeWarning)
                warnings.filterwarnings("ignore", message="refine_on_cases", category=RuntimeWarning)
                warnings.filterwarnings("ignore", category=closedloop.ClosedLoopUnstableWarning)
                try:
                    design = design_at(o)
                except RuntimeError:  # its reduced controller does not stabilise the turbine: the next order
                    continue
            if design.case_check is None or _met_with_room(design.case_check, min_decay):
                return design
            if met is None and design.case_check.met:
                met = design
        if met is None:
            return design_at(orders[-1])
        # a lower order met the pair, without the room: the highest is kept only if it meets it with
        # room (its warnings are then said), else that lower order is (the last order's misses are not the result's)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                last = design_at(orders[-1])
            except RuntimeError:
                return met
        if not _met_with_room(last.case_check, min_decay):
            return met
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return last


def _met_with_room(check, min_decay):
    """``check`` (a CaseCheck) met with :data:`ORDER_ROOM_DB` to spare and a decay rate ≥ ``min_decay`` (1/s)."""
    return (check.met and check.decay_rate >= min_decay
            and max(*check.tower_excess_db, *check.speed_excess_db, check.hf_excess_db) <= -ORDER_ROOM_DB)


def _design_once(model, v, base, w_tower, w_speed, notch_spec, label, relax, target, *, measurements, order, w_pitch, m,
                 suboptimality, reduction_method, dt, min_damping, decay_rate, integral_corner, kappa,
                 **plant_options):
    """One synthesis, reduction and assessment of :func:`design_hinf` on fixed specifications."""
    plant = model.linearize(v)
    Wt, Ws = siso_weight(w_tower, "w_tower"), siso_weight(w_speed, "w_speed")
    wt_resp = _response(Wt, base.omega)
    promise = sp.promise_of(wt_resp / base.t_response, base)
    Wn = Wt if notch_spec is None else siso_weight(notch_spec, "notch_spec")
    wn_resp = _response(Wn, base.omega)
    notch_promise = sp.promise_of(wn_resp / base.t_response, base)

    if integral_corner is None and decay_rate > 0:
        integral_corner = DEFAULT_INTEGRAL_CORNER
    gp = generalized_plant(plant, w_tower, w_speed, w_pitch, measurements, min_damping=min_damping,
                           integral_corner=integral_corner, **plant_options)
    n_p = gp.n_plant_states
    A_gp = np.asarray(gp.system.A)
    if not (np.allclose(A_gp[:plant.nstates, :plant.nstates], plant.A)
            and not np.any(A_gp[:n_p, n_p:])):  # pragma: no cover - interconnect's state order
        raise RuntimeError("generalized plant does not start with the turbine's states, "
                           "followed by weights in series: the α-shift would be wrong")
    try:
        res = lhinf.synthesize(gp.system, gp.n_meas, gp.n_ctrl, suboptimality=suboptimality,
                               decay_rate=decay_rate, decay_states=np.arange(gp.system.nstates) < n_p)
    except ValueError as e:  # an ill-posed problem: say at which operating point
        raise ValueError(f"H∞ design at {v:g} m/s: {e}") from e
    K_full = res.controller
    if gp.input_filter is not None:
        f = gp.input_filter
        K_full = ct.series(ct.ss(K_full.A, K_full.B, K_full.C, K_full.D), ct.ss(f.A, f.B, f.C, f.D))
    red = lhinf.reduce(K_full, order, method=reduction_method)
    K, case_check, notes = red.controller, None, gp.notes + res.notes
    if target is not None and len(measurements) == 1:
        # the synthesis bounds the nominal root-sum-square with capped weights; the pair is a
        # box at every plant case: the multi-model H∞ step (β = −C_β·Ω_g is −K)
        c_beta, case_check = refine_on_cases(model, target, -ct.ss(K), decay_rate=max(decay_rate, _STEP_MIN_DECAY))
        K = ct.ss(c_beta.A, c_beta.B, -c_beta.C, -c_beta.D)
        notes = notes + (f"multi-model H∞ step on the {len(case_check.case_speeds)} plant cases of the pair: "
                         f"worst tower excess {max(case_check.tower_excess_db):+.2f} dB, speed "
                         f"{max(case_check.speed_excess_db):+.2f} dB",)
    cl = closed_loop_mimo(plant, K, measurements)
    if not closedloop.check_stability(cl, "H∞ closed loop (reduced controller)"):
        raise RuntimeError(
            f"the {order}-state reduced controller does not stabilise the turbine at {v:g} m/s "
            f"(reduction error {red.error_hinf:.3g}); raise order"
        )
    rosco = sp.baseline_controller(model, v)
    cl0 = closedloop.closed_loop(plant, rosco, warn=False)
    cl_full = closed_loop_mimo(plant, K_full, measurements)
    omega = refine_grid(base.omega, [
        cl.poles(), cl_full.poles(), cl0["gen_speed", "wind"], cl0["tower_base_my", "wind"], Wt, Ws, Wn,
    ])
    # β = −C·y: the workbench's controllers are −K, one SISO part per measurement.
    parts = [ct.minreal(ct.ss(K.A, K.B[:, [i]], -K.C, -K.D[:, [i]]), verbose=False)
             for i in range(len(measurements))]
    if case_check is not None:  # exactly the controller check_pair judged (minreal may cancel near pairs)
        parts = [c_beta]
    t_tower = _response(cl, omega, "tower_base_my")
    t_speed = _response(cl, omega, "gen_speed")
    t_pitch = _response(cl, omega, "pitch_cmd")
    ws_resp, wt_resp = _response(Ws, omega), _response(Wt, omega)
    speed_ratio = 20 * np.log10(np.abs(t_speed) / np.abs(ws_resp))
    speed_excess = float(np.max(speed_ratio))
    wt_mode = abs(closedloop.tower_pole(plant))
    band = np.abs(omega / wt_mode - 1) <= TOWER_BAND
    tower_ratio = 20 * np.log10(np.abs(t_tower) / np.abs(wt_resp))
    tower_band_excess = float(np.max(tower_ratio[band]))
    at_mode = np.abs(closedloop.frequency_response(cl, [wt_mode, 2 * wt_mode], "tower_base_my"))[0]
    tower_excess = float(20 * np.log10(at_mode / np.abs(np.asarray(Wt(1j * wt_mode)))))
    notch_excess = float(20 * np.log10(at_mode / np.abs(np.asarray(Wn(1j * wt_mode)))))
    t_speed0 = _response(cl0, omega, "gen_speed")
    speed_excess0 = float(np.max(20 * np.log10(np.abs(t_speed) / np.abs(t_speed0))))
    # windowed as the baseline's (variance about each record's mean): the DELs converge in the grid's lowest ω
    wind_psd = wind.rotor_effective_spectrum(omega, v, model.rotor_radius) * wind.record_window(omega)
    t_tower0 = _response(cl0, omega, "tower_base_my")
    del0 = float(spectral.del_spectral(omega, np.abs(t_tower0) ** 2 * wind_psd, m))
    del1 = float(spectral.del_spectral(omega, np.abs(t_tower) ** 2 * wind_psd, m))
    t_pitch0 = _response(cl0, omega, "pitch_cmd")
    std = lambda t: float(np.sqrt(np.trapezoid(np.abs(t) ** 2 * wind_psd, omega)))  # noqa: E731
    # Loop at the actuator, L_u = Σ C_i·P_{y_i,β}; its peak sensitivity max |1/(1 + L_u)|.
    Kj = state_space_response(K.A, K.B, K.C, K.D, omega)[:, 0, :].T
    L_u = -sum(Kj[i] * _response(plant, omega, y, "pitch_cmd")
               for i, y in enumerate(measurements))
    if case_check is not None and not case_check.met:
        i, j = int(np.argmax(case_check.tower_excess_db)), int(np.argmax(case_check.speed_excess_db))
        missed = (f"the certified pair is not met at {v:g} m/s, infeasible for this H∞ design because the "
                  f"multi-model step found no {K.nstates}-state controller meeting it at every plant case: "
                  f"tower load by {case_check.tower_excess_db[i]:+.2f} dB at {case_check.tower_omega[i]:.3g} rad/s "
                  f"({case_check.case_speeds[i]:g} m/s), generator speed by {case_check.speed_excess_db[j]:+.2f} dB at "
                  f"{case_check.speed_omega[j]:.3g} rad/s ({case_check.case_speeds[j]:g} m/s), closed-loop decay "
                  f"{case_check.decay_rate:.3g} 1/s, high-frequency gain bound by {case_check.hf_excess_db:+.2f} dB"
                  f"{'' if case_check.proper else ' (not strictly proper)'}; raise order, or qft.design_qft(spec=...) "
                  "meets it")
        notes = notes + (missed,)
        warnings.warn(missed, RuntimeWarning, stacklevel=3)
    elif case_check is None and label in ("given", "target") and (speed_excess > 0 or tower_ratio.max() > 0):
        # a given pair is a promise to the user: say where the reduced design leaves it
        i, j = int(np.argmax(tower_ratio)), int(np.argmax(speed_ratio))
        missed = (f"the given specifications are not met at {v:g} m/s (nominal plant): tower load by "
                  f"{tower_ratio[i]:+.2f} dB at {omega[i]:.3g} rad/s, generator speed by {speed_excess:+.2f} dB at "
                  f"{omega[j]:.3g} rad/s; a pair made by specification_for_target is met by "
                  "qft.design_qft(spec=...), see docs/hinf.md")
        notes = notes + (missed,)
        warnings.warn(missed, RuntimeWarning, stacklevel=3)
    c_beta = parts[0]
    hf_excess = -np.inf
    if kappa is not None:  # the bound's band on the grid, its ends and 3P; a direct term breaks it above
        w_hf = hf_check_omega(model, omega, np.linalg.eigvals(np.asarray(c_beta.A, float)) if c_beta.nstates else ())
        hf_excess = np.inf if np.any(c_beta.D) else float(np.max(
            20 * np.log10(np.abs(_response(c_beta, w_hf)) / hf_gain_bound(model, v, w_hf, kappa))))
    kp = np.linalg.eigvals(np.asarray(K.A, float)) if K.nstates else np.zeros(0, complex)
    k_unstable = np.sort_complex(kp[kp.real > 1e-9])
    sign = 1 if np.real(_response(c_beta, omega[:1])[0] / _response(rosco, omega[:1])[0]) > 0 else -1
    zeta_rosco = closedloop.tower_damping(plant, cl0)[1]
    try:
        zeta_tower = closedloop.tower_damping(plant, cl)[1]
    except ValueError as e:  # the loop moved the mode out of tower_pole's span: say so, keep the design
        zeta_tower = float("nan")
        notes = notes + (f"tower mode's damping not located in the reduced loop ({e})",)
    p = np.asarray(cl.poles())
    osc = p[np.abs(p.imag) > 1e-6]
    zeta = -osc.real / np.abs(osc)
    return HinfDesign(
        pitch_controller=parts[0], atd_controller=parts[1] if len(parts) > 1 else None, controller=K, full_controller=K_full,
        gamma=res.gamma, reduction=red, w_tower=w_tower, w_speed=w_speed,
        promised_del_reduction=float((promise if target is None else target.promise).exact_del),
        predicted_del_reduction=100.0 * (1.0 - del1 / del0),
        speed_excess_db=speed_excess, tower_excess_db=tower_excess, tower_mode=wt_mode,
        pitch_std=std(t_pitch), pitch_std_baseline=std(t_pitch0), omega=omega,
        check=_qft_check(plant, parts[0], w_tower, w_speed, omega) if len(parts) == 1 else None,
        discrete_controller=None if dt is None else lhinf.discretize(K, dt, prewarp_frequency=wt_mode),
        notes=notes,
        zeta_min=float(zeta.min()) if zeta.size else 1.0,
        zeta_min_frequency=float(np.abs(osc[np.argmin(zeta)])) if zeta.size else float("nan"),
        tower_damping_ratio=zeta_tower, baseline_tower_damping_ratio=zeta_rosco,
        peak_sensitivity=float(np.max(np.abs(1.0 / (1.0 + L_u)))),
        max_pole_real=float(p.real.max()),
        decay_rate=float(decay_rate),
        tower_band_excess_db=tower_band_excess,
        specs=label, speed_relax_db=float("nan") if relax is None else float(relax),
        notch_spec=notch_spec if notch_spec is not None else w_tower,
        notch_promised_del_reduction=float(notch_promise.exact_del),
        tower_notch_excess_db=notch_excess, speed_excess_baseline_db=speed_excess0, case_check=case_check,
        hf_excess_db=hf_excess, controller_unstable_poles=k_unstable, speed_integral_sign=sign,
    )
