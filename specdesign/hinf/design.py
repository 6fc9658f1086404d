"""H∞ design of the pitch (and ATD) controller at one operating point on the fatigue-based
specifications, with reduction, discretisation and an assessment on a refined grid."""
from __future__ import annotations

import warnings
from dataclasses import dataclass, replace

import control as ct
import numpy as np

from loopshaping import hinf as lhinf

from ..closedloop import closed_loop_mimo, refine_grid
from .plant import DEFAULT_INTEGRAL_CORNER, generalized_plant
from .weights import DEFAULT_MIN_DAMPING, siso_weight

__all__ = ['HinfDesign', 'QFT_SPEED_RELAX_DB', 'DEFAULT_DECAY_RATE', 'TOWER_BAND', 'design_hinf', 'qft_specifications']

#: α (1/s) of the α-shifted synthesis in :func:`design_hinf`.
DEFAULT_DECAY_RATE = 0.02
#: Half-width of the tower-mode band (relative) over which ``tower_excess_db`` is the maximum.
TOWER_BAND = 0.1


@dataclass(frozen=True)
class HinfDesign:
    """Outcome of :func:`design_hinf` at one operating point (units: rad/s, N·m, rad, %).

    ``pitch_controller`` C_β (gen_speed → pitch) and ``atd_controller`` C_atd (or None), in the
    workbench sign β = −C_β·Ω_g − C_atd·v, as minimal SISO systems for frequency-domain use
    (implement the 1×2 ``controller`` itself: see :func:`specdesign.closedloop.closed_loop_mimo`);
    ``controller`` the reduced K (u = K·y) and
    ``full_controller`` the synthesised one; ``gamma`` of the full-order design; ``reduction``
    (:class:`loopshaping.hinf.ReductionResult`); ``w_tower``, ``w_speed`` the specifications;
    ``promised_del_reduction`` (the specification's exact Dirlik promise, %) and
    ``predicted_del_reduction`` (Dirlik on the reduced controller's closed loop, %);
    ``speed_excess_db`` max over the grid of 20·log10(|T_Ω,w|/|W_Ω|) (≤ 0 means met);
    ``tower_excess_db`` the same for MyT at ``tower_mode`` (rad/s) and
    ``tower_band_excess_db`` its max over ``tower_mode``·(1 ± :data:`TOWER_BAND`);
    ``zeta_min`` the least damping ratio of the reduced loop's oscillatory poles, at
    ``zeta_min_frequency`` (|p|, rad/s), ``max_pole_real`` its largest Re p (1/s);
    ``peak_sensitivity`` max |1/(1 + L_u)| at the actuator, L_u = Σ C_i·P_{y_i,β};
    ``decay_rate`` the α of the synthesis;
    ``discrete_controller`` K sampled at ``dt`` (Tustin prewarped at the tower mode) or None;
    ``pitch_std``/``pitch_std_baseline`` pitch-command standard deviation (rad) from the
    linear model; ``omega`` the assessment grid (:func:`specdesign.closedloop.refine_grid`) on which every
    frequency-domain number here is computed, DELs included; ``check`` the :func:`loopshaping.check.check` of the
    reduced pitch controller against both specifications in QFT's general form (specs
    "tower" and "speed", margins in dB, stability, gain/phase margins; None with ATD, whose
    1×2 loop that SISO check does not cover); ``notes``;
    ``specs`` which specifications were the weights ("qft", "qft_design", "rosco", "custom")
    and ``speed_relax_db`` the relaxation of ROSCO's T_{Ω,w} in the speed spec (dB; nan for
    custom specs); ``notch_spec`` the unrelaxed notch specification (ROSCO × notches of
    :func:`specdesign.spec.shape_to_target`; ``w_tower`` for custom specs),
    ``notch_promised_del_reduction`` its promise (%), ``tower_notch_excess_db`` the tower
    excess against it at ``tower_mode`` (stricter than ``tower_excess_db`` when ``w_tower``
    is relaxed); ``speed_excess_baseline_db`` max 20·log10(|T_Ω,w|/|T^ROSCO_Ω,w|), the speed
    excess over ROSCO's unrelaxed response (what a relaxed speed spec gives away).
    """

    pitch_controller: ct.StateSpace
    atd_controller: object
    controller: ct.StateSpace
    full_controller: ct.StateSpace
    gamma: float
    reduction: object
    w_tower: object
    w_speed: object
    promised_del_reduction: float
    predicted_del_reduction: float
    speed_excess_db: float
    tower_excess_db: float
    tower_mode: float
    pitch_std: float
    pitch_std_baseline: float
    omega: np.ndarray
    check: object
    discrete_controller: object
    notes: tuple
    zeta_min: float
    zeta_min_frequency: float
    peak_sensitivity: float
    max_pole_real: float
    decay_rate: float
    tower_band_excess_db: float
    specs: str = "custom"
    speed_relax_db: float = float("nan")
    notch_spec: object = None
    notch_promised_del_reduction: float = float("nan")
    tower_notch_excess_db: float = float("nan")
    speed_excess_baseline_db: float = float("nan")


def _qft_check(plant, pitch_controller, w_tower, w_speed, omega):
    """Re-check a SISO pitch controller with :mod:`loopshaping.check`: the tower spec in
    the general form |(A + B·C)/(1 + D·C)| ≤ |W_MyT| with A = P_{MyT,w},
    B = P_{MyT,w}P_{Ω,β} − P_{MyT,β}P_{Ω,w}, D = P_{Ω,β}; the speed spec with A = P_{Ω,w}, B = 0."""
    from loopshaping import check, qft

    def resp(o, i):
        sub = plant[o, i]
        return lambda w: np.asarray(ct.frequency_response(sub, np.asarray(w, float)).complex).reshape(-1, 1)

    p_mw, p_mb = resp("tower_base_my", "wind"), resp("tower_base_my", "pitch_cmd")
    p_ow, p_ob = resp("gen_speed", "wind"), resp("gen_speed", "pitch_cmd")
    tower = qft.Spec("general", weight=siso_weight(w_tower, "w_tower"), name="tower", kind_args=dict(
        A=p_mw, B=lambda w: p_mw(w) * p_ob(w) - p_mb(w) * p_ow(w), C=1.0, D=p_ob))
    speed = qft.Spec("general", weight=siso_weight(w_speed, "w_speed"), name="speed",
                     kind_args=dict(A=p_ow, B=0.0, C=1.0, D=p_ob))
    return check.check([plant["gen_speed", "pitch_cmd"]], pitch_controller, [tower, speed], omega)


def _tower_mode(plant):
    """Frequency (rad/s) of the least-damped complex open-loop pole pair: the tower mode."""
    p = np.asarray(plant.poles())
    p = p[p.imag > 1e-6]
    if p.size == 0:
        raise ValueError("plant has no oscillatory pole: cannot locate the tower mode")
    zeta = -p.real / np.abs(p)
    return float(np.abs(p[np.argmin(zeta)]))


def _is_design(obj) -> bool:
    """A design record carrying the specifications it met (e.g. :class:`specdesign.qft.QFTDesign`)."""
    return all(hasattr(obj, k) for k in ("tower_spec", "speed_spec", "shaping", "options"))


def qft_specifications(model, wind_speed, *, speed_relax_db=4.5, spec_reduction=15.0, tower_relax_db=6.0,
                       tower_relax_omega=1.3, keep_below=0.6, m=4.0, omega=None):
    """The specifications :func:`specdesign.qft.design_qft` designs against, built the same way.

    Tower load: W_MyT = T^ROSCO_{MyT,w} × the notches of :func:`specdesign.spec.shape_to_target`
    (``spec_reduction`` % damage, notches above ``keep_below`` rad/s) × two leads
    (1 + s/ω_r)/(1 + s/(ω_r·10^(tower_relax_db/40))), ω_r = ``tower_relax_omega`` (rad/s): the
    spec is relaxed by ``tower_relax_db`` at high frequency, where ΔD% is negligible (the
    leads already lift it by ≈ 1.9 dB at the tower mode, 1.06 rad/s, with the defaults).
    Generator speed: W_Ω = T^ROSCO_{Ω,w}·10^(speed_relax_db/20), ROSCO's dip at the tower
    mode (a ζ = 0.01 zero pair) kept.

    Returns
    -------
    (Specification, Specification, Specification)
        ``(tower_spec, speed_spec, notch_spec)``: the two specs QFT is given and the
        unrelaxed notch spec whose promise :func:`specdesign.spec.shape_to_target` reports.
    """
    from .. import spec

    d = spec.design_specifications(model, wind_speed, speed_relax_db=speed_relax_db, spec_reduction=spec_reduction,
                                   tower_relax_db=tower_relax_db, tower_relax_omega=tower_relax_omega,
                                   keep_below=keep_below, m=m, omega=omega)
    if not d.shaping.success:
        raise ValueError(f"no tower specification at {float(wind_speed):g} m/s: {d.shaping.message}")
    return d.tower, d.speed, d.shaping.specification


#: Relaxations (dB) of the generator-speed spec tried in turn by ``design_hinf(specs="qft")``:
#: the ladder of :func:`specdesign.qft.design_qft`.
QFT_SPEED_RELAX_DB = (3.0, 4.5, 6.0, 8.0)


def design_hinf(
    model,
    wind_speed,
    *,
    specs="qft",
    target_reduction=15.0,
    measurements=("gen_speed", "tower_top_vel"),
    order=8,
    w_tower=None,
    w_speed=None,
    w_pitch=None,
    speed_relax_db=QFT_SPEED_RELAX_DB,
    tower_relax_db=6.0,
    tower_relax_omega=1.3,
    m=4.0,
    omega=None,
    suboptimality=0.05,
    reduction_method="balanced",
    dt=None,
    min_damping=DEFAULT_MIN_DAMPING,
    decay_rate=DEFAULT_DECAY_RATE,
    integral_corner=None,
    **plant_options,
):
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
        m/s, above rated.
    specs : "qft", "rosco" or specdesign.qft.QFTDesign
        Which specifications are the weights (``w_tower``/``w_speed``, when given, override).
        ``"qft"`` (default): those of :func:`specdesign.qft.design_qft`
        (:func:`qft_specifications`): the notch spec relaxed by ``tower_relax_db`` above
        ≈ ``tower_relax_omega`` and ROSCO's T_{Ω,w} relaxed by ``speed_relax_db``; given a
        sequence (default :data:`QFT_SPEED_RELAX_DB`, QFT's ladder) the relaxations are tried
        in turn and the smallest whose reduced design meets both specs on the refined grid
        (speed everywhere, tower over the tower-mode band) is kept, as QFT does.
        A ``QFTDesign``: its own ``tower_spec`` and ``speed_spec``, for a comparison on
        exactly the specs that design met. ``"rosco"``: the unrelaxed notch spec and ROSCO's
        T_{Ω,w} (this function's default before; its ζ = 0.01 dip at the tower mode is then
        a spec no well-damped loop can follow, docs/hinf.md).
    target_reduction : float
        % of tower-base damage the automatic notch specification
        (:func:`specdesign.spec.shape_to_target`) must promise (QFT's ``spec_reduction``).
    measurements : tuple of str
        ``("gen_speed", "tower_top_vel")`` (default: 1×2 controller, pitch + active tower
        damping) or ``("gen_speed",)`` (pitch only).
    order : int
        States of the reduced controller.
    w_tower, w_speed : Specification or SISO LTI, optional
        Explicit specifications (override ``specs``).
    w_pitch : optional
        Pitch-activity weight, see :func:`generalized_plant`.
    speed_relax_db, tower_relax_db, tower_relax_omega : float (dB, dB, rad/s)
        See ``specs="qft"``.
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
        α (1/s) of an α-shifted synthesis (:func:`loopshaping.hinf.synthesize`) on the
        turbine's states and the integrator F (weights, in series, unshifted): every pole of
        the loop with the full-order controller has Re < −α (reduction may move them; the
        reduced loop's poles are reported in ``zeta_min`` and ``max_pole_real``).
    integral_corner : float, optional
        ω_i (rad/s) of the integrator F(s) = (1 + s/ω_i)/s built into the plant
        (:func:`generalized_plant`). Default: 0.1 rad/s when ``decay_rate`` > 0 (without it
        the shift would move the controller's integral action to −α), none otherwise.
    **plant_options
        ``noise``, ``noise_band``, ``rolloff``, ``shift`` for :func:`generalized_plant`.
    """
    from .. import spec

    v = float(wind_speed)
    base = spec.baseline_analysis(model, v, m=m, omega=omega)
    notch_spec, ladder, label = None, [None], "custom"
    if _is_design(specs):
        label = "qft_design"
        w_tower = specs.tower_spec if w_tower is None else w_tower
        w_speed = specs.speed_spec if w_speed is None else w_speed
        notch_spec = specs.shaping.specification
        ladder = [float(specs.options.get("speed_relax_db", np.nan))]
    elif isinstance(specs, str) and specs in ("qft", "rosco"):
        label = specs
        if specs == "qft":
            ladder = np.atleast_1d(np.asarray(speed_relax_db, float))
            if ladder.ndim != 1 or ladder.size == 0 or not np.all(np.isfinite(ladder)) or np.any(ladder < 0):
                raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB or a sequence of them")
            ladder = [float(x) for x in ladder] if w_speed is None else [float(ladder[0])]
        else:
            ladder = [0.0]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            shaped = spec.shape_to_target(base, target_reduction)
        if not shaped.success:
            raise ValueError(f"no tower specification at {v:g} m/s: {shaped.message}")
        notch_spec = shaped.specification
    else:
        raise ValueError(f"specs={specs!r} must be 'qft', 'rosco' or a specdesign.qft.QFTDesign")
    if w_tower is not None and w_speed is not None and label in ("qft", "rosco"):
        label, ladder, notch_spec = "custom", [None], None
    design = None
    for k, relax in enumerate(ladder):
        wt, ws = w_tower, w_speed
        if label == "qft":
            t_q, s_q, _ = qft_specifications(model, v, speed_relax_db=relax, spec_reduction=target_reduction,
                                             tower_relax_db=tower_relax_db, tower_relax_omega=tower_relax_omega,
                                             m=m, omega=omega)
            wt = t_q if wt is None else wt
            ws = s_q if ws is None else ws
        elif label == "rosco":
            wt = notch_spec if wt is None else wt
            ws = spec.speed_specification(model, v) if ws is None else ws
        last = k == len(ladder) - 1
        try:
            design = _design_once(model, v, base, wt, ws, notch_spec, label, relax, measurements=measurements,
                                  order=order, w_pitch=w_pitch, m=m, suboptimality=suboptimality,
                                  reduction_method=reduction_method, dt=dt, min_damping=min_damping,
                                  decay_rate=decay_rate, integral_corner=integral_corner, **plant_options)
        except RuntimeError:
            if last:
                raise
            continue
        if last or (design.speed_excess_db <= 0 and design.tower_band_excess_db <= 0):
            break
    if label == "qft" and len(ladder) > 1:
        met = design.speed_excess_db <= 0 and design.tower_band_excess_db <= 0
        design = replace(design, notes=design.notes + (
            f"specs='qft': speed spec relaxed by {design.speed_relax_db:g} dB, the smallest of {tuple(ladder)} "
            "with both specs met on the refined grid" if met else
            f"specs='qft': no relaxation of {tuple(ladder)} met both specs; the last is returned",))
    return design


def _design_once(model, v, base, w_tower, w_speed, notch_spec, label, relax, *, measurements, order, w_pitch, m,
                 suboptimality, reduction_method, dt, min_damping, decay_rate, integral_corner, **plant_options):
    """One synthesis, reduction and assessment of :func:`design_hinf` on fixed specifications."""
    from .. import closedloop, spec, spectral, turbine, wind

    plant = model.linearize(v)
    Wt, Ws = siso_weight(w_tower, "w_tower"), siso_weight(w_speed, "w_speed")
    wt_resp = np.asarray(ct.frequency_response(Wt, base.omega).complex).reshape(-1)
    promise = spec.promise_of(wt_resp / base.t_response, base)
    Wn = Wt if notch_spec is None else siso_weight(notch_spec, "notch_spec")
    wn_resp = np.asarray(ct.frequency_response(Wn, base.omega).complex).reshape(-1)
    notch_promise = spec.promise_of(wn_resp / base.t_response, base)

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
    res = lhinf.synthesize(gp.system, gp.n_meas, gp.n_ctrl, suboptimality=suboptimality,
                           decay_rate=decay_rate, decay_states=np.arange(gp.system.nstates) < n_p)
    K_full = res.controller
    if gp.input_filter is not None:
        f = gp.input_filter
        K_full = ct.series(ct.ss(K_full.A, K_full.B, K_full.C, K_full.D), ct.ss(f.A, f.B, f.C, f.D))
    red = lhinf.reduce(K_full, order, method=reduction_method)
    K = red.controller
    cl = closed_loop_mimo(plant, K, measurements)
    if not closedloop.check_stability(cl, "H∞ closed loop (reduced controller)"):
        raise RuntimeError(
            f"the {order}-state reduced controller does not stabilise the turbine at {v:g} m/s "
            f"(reduction error {red.error_hinf:.3g}); raise order"
        )
    rosco = turbine.rosco_baseline(model, v)
    cl0 = closedloop.closed_loop(plant, rosco, warn=False)
    cl_full = closed_loop_mimo(plant, K_full, measurements)
    omega = refine_grid(base.omega, [
        cl.poles(), cl_full.poles(), cl0["gen_speed", "wind"], cl0["tower_base_my", "wind"], Wt, Ws, Wn,
    ])
    # β = −C·y: the workbench's controllers are −K, one SISO part per measurement.
    parts = [ct.minreal(ct.ss(K.A, K.B[:, [i]], -K.C, -K.D[:, [i]]), verbose=False)
             for i in range(len(measurements))]
    t_tower = closedloop.frequency_response(cl, omega, "tower_base_my")
    t_speed = closedloop.frequency_response(cl, omega, "gen_speed")
    t_pitch = closedloop.frequency_response(cl, omega, "pitch_cmd")
    ws_resp = np.asarray(ct.frequency_response(Ws, omega).complex).reshape(-1)
    wt_resp = np.asarray(ct.frequency_response(Wt, omega).complex).reshape(-1)
    speed_excess = float(np.max(20 * np.log10(np.abs(t_speed) / np.abs(ws_resp))))
    wt_mode = _tower_mode(plant)
    band = np.abs(omega / wt_mode - 1) <= TOWER_BAND
    tower_band_excess = float(np.max(20 * np.log10(np.abs(t_tower[band]) / np.abs(wt_resp[band]))))
    at_mode = np.abs(closedloop.frequency_response(cl, [wt_mode, 2 * wt_mode], "tower_base_my"))[0]
    tower_excess = float(20 * np.log10(at_mode / np.abs(np.asarray(Wt(1j * wt_mode)))))
    notch_excess = float(20 * np.log10(at_mode / np.abs(np.asarray(Wn(1j * wt_mode)))))
    t_speed0 = closedloop.frequency_response(cl0, omega, "gen_speed")
    speed_excess0 = float(np.max(20 * np.log10(np.abs(t_speed) / np.abs(t_speed0))))
    wind_psd = wind.rotor_effective_spectrum(omega, v, model.rotor_radius)
    t_tower0 = closedloop.frequency_response(cl0, omega, "tower_base_my")
    del0 = float(spectral.del_spectral(omega, np.abs(t_tower0) ** 2 * wind_psd, m))
    del1 = float(spectral.del_spectral(omega, np.abs(t_tower) ** 2 * wind_psd, m))
    t_pitch0 = closedloop.frequency_response(cl0, omega, "pitch_cmd")
    std = lambda t: float(np.sqrt(np.trapezoid(np.abs(t) ** 2 * wind_psd, omega)))  # noqa: E731
    # Loop at the actuator, L_u = Σ C_i·P_{y_i,β}; its peak sensitivity max |1/(1 + L_u)|.
    Kj = np.asarray(ct.frequency_response(K, omega).complex).reshape(1, len(measurements), -1)[0]
    L_u = -sum(Kj[i] * closedloop.frequency_response(plant, omega, y, "pitch_cmd")
               for i, y in enumerate(measurements))
    p = np.asarray(cl.poles())
    osc = p[np.abs(p.imag) > 1e-6]
    zeta = -osc.real / np.abs(osc)
    return HinfDesign(
        pitch_controller=parts[0], atd_controller=parts[1] if len(parts) > 1 else None, controller=K, full_controller=K_full,
        gamma=res.gamma, reduction=red, w_tower=w_tower, w_speed=w_speed,
        promised_del_reduction=float(promise.exact_del),
        predicted_del_reduction=100.0 * (1.0 - del1 / del0),
        speed_excess_db=speed_excess, tower_excess_db=tower_excess, tower_mode=wt_mode,
        pitch_std=std(t_pitch), pitch_std_baseline=std(t_pitch0), omega=omega,
        check=_qft_check(plant, parts[0], w_tower, w_speed, omega) if len(parts) == 1 else None,
        discrete_controller=None if dt is None else lhinf.discretize(K, dt, prewarp_frequency=wt_mode),
        notes=gp.notes + res.notes,
        zeta_min=float(zeta.min()) if zeta.size else 1.0,
        zeta_min_frequency=float(np.abs(osc[np.argmin(zeta)])) if zeta.size else float("nan"),
        peak_sensitivity=float(np.max(np.abs(1.0 / (1.0 + L_u)))),
        max_pole_real=float(p.real.max()),
        decay_rate=float(decay_rate),
        tower_band_excess_db=tower_band_excess,
        specs=label, speed_relax_db=float("nan") if relax is None else float(relax),
        notch_spec=notch_spec if notch_spec is not None else w_tower,
        notch_promised_del_reduction=float(notch_promise.exact_del),
        tower_notch_excess_db=notch_excess, speed_excess_baseline_db=speed_excess0,
    )
