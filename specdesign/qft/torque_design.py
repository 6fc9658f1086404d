"""The design loop below rated: a generator-torque loop stiffness for a tower-load target.

Below rated ROSCO's pitch PI sits at fine pitch and the only loop is the generator-torque law
(``TurbineModel.linearize`` closes it in the plant). A torque controller G added to the law,
τ_add = −G·Ω_g (Ω_g the rotor-shaft speed deviation, rad/s), gives the tower-base moment's wind
map in QFT's general form

    T_MyT,w = (A + B·G)/(C + D·G),  A = P_MyT,w,  B = P_MyT,w·P_Ω,τ − P_MyT,τ·P_Ω,w,  C = 1,
    D = P_Ω,τ,

with the limit G → ∞ (rotor speed held) K∞ = B/D. :func:`design_torque` takes the proportional
family G = −k (τ_add = k·δΩ, k ≥ 0 N·m per rad/s: a stiffer law) and picks the smallest k whose
promised tower-base DEL reduction (exact Dirlik on |T|²S_W against the baseline of
:func:`specdesign.spec.baseline_analysis`, torque law closed, pitch loop open) reaches the
target, with its costs from the same linear maps: rotor-speed, torque and power SD and the
mean aerodynamic power change, second order, ½·tr(H_P·Σ) (H_P the Hessian of P = Q·Ω in
(Ω, wind − ẋ_top) from ``model.aero_expansion``, Σ their covariance).

Nonlinear, :meth:`TorqueDesign.torque_law` turns the design into ROSCO's TSR-tracking torque PI
(``VS_ControlMode`` 3) whose proportional gain is the law's own stiffness plus k, integral gain
in ROSCO's ratio, and a slow speed reference (the reference must not follow the wind over the
tower band, or the PI holds nothing there). ``model.linearize`` treats mode 3 as the K·Ω² curve
it tracks and leaves ROSCO's speed filter out; :func:`torque_law_response` linearises a law as
the simulator runs it (filter, PI, moving reference) and :func:`law_promise` recomputes the
promise with it: at 8 m/s it moves the 20 % design's promise by 0.6 pp, so the gap to the
nonlinear runs (−15.0 ± 1.7 % over 20 seeds) is not the linearisation of the law but the torque
ceiling and the minimum-speed region the turbulent rotor visits (docs/below_rated.md, section 3;
``benchmarks/below_rated_design.py --part torque_gap``).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import control
import numpy as np
from scipy.optimize import brentq

from ..fatigue import TOWER_M
from ..spec import baseline_analysis
from ..spectral import del_spectral

__all__ = ["DEFAULT_TORQUE_OMEGA", "TORQUE_DESIGN_REGIONS", "TorqueDesign", "design_torque", "law_promise",
           "torque_general_form", "torque_law_response"]

#: Torque regions (:data:`specdesign.rosco.TORQUE_REGIONS`) where the torque loop is the only
#: loop; in "2.5s" (setpoint smoothing) and "3" the pitch loop acts.
TORQUE_DESIGN_REGIONS = ("1.5", "2", "2.5")
#: The design frequency grid, rad/s.
DEFAULT_TORQUE_OMEGA = np.logspace(-3.0, 1.0, 800)
#: The gain search spans k = 0 and this range in units of the law's own stiffness (-).
_GAIN_SPAN = np.logspace(-2.0, 2.0, 81)
#: Real part (rad/s) from which a closed-loop pole of :func:`law_promise` counts as unstable: the
#: cancelled integrator mode sits at |s| ~ 1e-12, the slowest physical pole (the reference
#: filter, 0.02 rad/s) far above.
_MARGINAL = 1e-8
_OUTPUTS = ("tower_base_my", "gen_speed", "tower_top_vel", "power")


@dataclass(frozen=True)
class TorqueDesign:
    """A torque-loop design below rated (:func:`design_torque`).

    Parameters
    ----------
    wind_speed : float
        Operating point, m/s.
    region : str
        Torque region of the trim (:data:`TORQUE_DESIGN_REGIONS`).
    gain : float
        k, the added proportional torque gain, N·m per rad/s of rotor-shaft speed
        (τ_add = k·δΩ; G = −k in the general form).
    law_stiffness : float
        The torque law's own dτ/dΩ at the trim, N·m per rad/s (region 2: 2KΩ; regions 1.5 and
        2.5: −kp of its PI).
    target_reduction : float
        Requested tower-base DEL reduction, %.
    promise : float
        Predicted tower-base DEL reduction with the design, % (Dirlik, linear).
    limit_promise : float
        The same for G → ∞ (rotor speed held), %: the most any torque controller on Ω gives.
    baseline_del, design_del : float
        Tower-base DEL (range, N·m at 1 Hz) of the baseline and the design.
    speed_sd, baseline_speed_sd : float
        Rotor-speed SD, rad/s.
    torque_sd, baseline_torque_sd : float
        Generator-torque SD (law + added), N·m.
    power_sd, baseline_power_sd : float
        Electrical-power SD, W.
    power_change_pct : float
        Mean aerodynamic power change against the baseline, % (second-order estimate; < 0 a loss).
    m : float
        Wöhler exponent (-).
    omega : numpy.ndarray
        Frequency grid, rad/s.
    t_response : numpy.ndarray
        T_MyT,w(jω) with the design, N·m per m/s.
    wind_psd : numpy.ndarray
        S_W(ω), one-sided, (m/s)² per rad/s.
    """

    wind_speed: float
    region: str
    gain: float
    law_stiffness: float
    target_reduction: float
    promise: float
    limit_promise: float
    baseline_del: float
    design_del: float
    speed_sd: float
    baseline_speed_sd: float
    torque_sd: float
    baseline_torque_sd: float
    power_sd: float
    baseline_power_sd: float
    power_change_pct: float
    m: float
    omega: np.ndarray = dataclasses.field(repr=False)
    t_response: np.ndarray = dataclasses.field(repr=False)
    wind_psd: np.ndarray = dataclasses.field(repr=False)

    def torque_law(self, law, reference_corner: float = 0.02):
        """The design as ROSCO's TSR-tracking torque PI, for ``simulate(..., torque_control=law)``.

        Parameters
        ----------
        law : specdesign.rosco.TorqueLaw
            The turbine's torque law (``model.torque_control``), kept but for mode and gains.
        reference_corner : float, optional
            ``F_VSRefSpdCornerFreq`` (rad/s) of the speed reference: well below the tower band
            (≈ 1 rad/s) so the PI holds the speed there; ROSCO's 0.209 lets the reference follow
            the wind and the stiffer loop does nothing for the tower.

        Returns
        -------
        specdesign.rosco.TorqueLaw
            ``mode=3``, ``kp = −(law_stiffness + gain)`` (ROSCO's sign), ``ki`` in the ratio
            ki/kp of ``law``.

        Raises
        ------
        ValueError
            For a non-positive or non-finite ``reference_corner`` or a ``law`` without a PI.

        Examples
        --------
        >>> from specdesign.turbine import iea15mw
        >>> m = iea15mw()
        >>> d = design_torque(m, 8.0, target_reduction=15.0)
        >>> d.torque_law(m.torque_control).mode
        3
        """
        if not (math.isfinite(reference_corner) and reference_corner > 0):
            raise ValueError(f"reference_corner={reference_corner!r} must be a positive frequency in rad/s (e.g. 0.02)")
        if not (law.kp < 0 and law.ki <= 0):
            raise ValueError(f"law has kp={law.kp!r}, ki={law.ki!r}: the torque PI gains must be negative (ROSCO's sign)")
        kp = -(self.law_stiffness + self.gain)
        return dataclasses.replace(law, mode=3, kp=kp, ki=kp * law.ki / law.kp, reference_corner=reference_corner,
                                   name=f"torque loop k={self.gain:.4g} N·m/(rad/s) @ {self.wind_speed:g} m/s")


def torque_general_form(model, wind_speed: float, omega) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A, B, C, D of T_MyT,w = (A + B·G)/(C + D·G) for a torque controller G on the rotor speed.

    τ_add = −G·Ω_g is added to the torque law closed in ``model.linearize(wind_speed)``.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        Turbine with a torque law.
    wind_speed : float
        Operating point below rated, m/s.
    omega : array_like
        Frequencies, rad/s.

    Returns
    -------
    tuple of numpy.ndarray
        Complex A (N·m per m/s), B (N·m per m/s · rad/s per N·m), C (-), D (rad/s per N·m).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> A, B, C, D = torque_general_form(iea15mw(), 8.0, [1.0])
    >>> bool(abs(D[0]) > 0)
    True
    """
    return _form(_responses(model.linearize(wind_speed), np.asarray(omega, dtype=float)))


def torque_law_response(model, law, wind_speed: float, omega) -> np.ndarray:
    """δτ/δΩ of a torque law as the simulator runs it (:func:`specdesign.rosco.torque_step`), linearised at the trim.

    The law acts on the rotor speed low-passed by ROSCO's filter F (``filter_type``,
    ``filter_corner``, ``filter_damping``). Mode 1: region 2, K·Ω_f², gives 2KΩ·F; regions 1.5 and
    2.5, the PI C = kp + ki/s on a constant reference, −C·F. Modes 3 and 4 (region 2): one PI on
    e = r − Ω_f with the reference r low-passed, R = a/(s + a), a = ``reference_corner``, from
    (P/(ηK))^{1/3} (mode 3, P = η·τ·Ω: δr_raw = δΩ/3 + δτ/(3KΩ)) or (τ/K)^{1/2} (mode 4:
    δτ/(2KΩ)); solving δτ = C·(R·δr_raw − F·δΩ) for δτ gives C·(a_Ω·R − F)/(1 − C·R·a_τ), which is
    2KΩ at s = 0 (the curve) and the PI on the filtered speed above a. In regions 1.5 and 2.5 the
    reference is clamped at a speed limit: −C·F. Torque and rate limits, the state machine and the
    controller's sampling are left out (small-amplitude response).

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        Turbine; its trim (``model.trim``) gives Ω (rad/s) and the region (the law tracks the
        same K·Ω² curve, as :meth:`TorqueDesign.torque_law`'s does).
    law : specdesign.rosco.TorqueLaw
        The law as simulated (``simulate(..., torque_control=law)``).
    wind_speed : float
        Operating point, m/s (torque regions :data:`TORQUE_DESIGN_REGIONS`).
    omega : array_like
        Frequencies, rad/s.

    Returns
    -------
    numpy.ndarray
        Complex δτ/δΩ, N·m per rad/s (τ the generator torque, Ω the rotor-shaft speed).

    Raises
    ------
    ValueError
        Outside :data:`TORQUE_DESIGN_REGIONS`.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> L = torque_law_response(m, m.torque_control, 8.0, [1e-6])
    >>> bool(abs(L[0] / (2 * m.torque_control.k_opt * m.trim(8.0).rotor_speed) - 1) < 1e-3)
    True
    """
    return control.frequency_response(_law_tf(model, law, wind_speed), np.asarray(omega, dtype=float)).complex.ravel()


def _law_tf(model, law, wind_speed):
    op = model.trim(wind_speed)
    if op.region not in TORQUE_DESIGN_REGIONS:
        raise ValueError(f"wind_speed={wind_speed!r} m/s is in torque region {op.region!r}; the torque law's "
                         f"response is linearised in regions {TORQUE_DESIGN_REGIONS}")
    s = control.tf("s")
    wc = law.filter_corner
    f = wc**2 / (s**2 + 2 * law.filter_damping * wc * s + wc**2) if law.filter_type == 2 else wc / (s + wc)
    pi = law.kp + law.ki / s
    stiff = 2.0 * law.k_opt * op.rotor_speed
    if op.region != "2":
        return -pi * f
    if law.mode == 1:
        return stiff * f
    r = law.reference_corner / (s + law.reference_corner) if law.reference_corner > 0 else 1
    a_om, a_tq = (1.0 / 3.0, 2.0 / (3.0 * stiff)) if law.mode == 3 else (0.0, 1.0 / stiff)  # 1/(3KΩ), 1/(2KΩ)
    return control.minreal(pi * (a_om * r - f) / (1 - pi * r * a_tq), verbose=False)


def law_promise(model, design: TorqueDesign, law=None) -> float:
    """The design's promise recomputed with the torque laws linearised as the simulator runs them.

    Baseline: ``model.torque_control`` (ROSCO's law, its speed filter included); design: ``law``
    (default ``design.torque_law(model.torque_control)``), both by :func:`torque_law_response`,
    each entered in the general form as G = L_lin − L (L_lin the law ``model.linearize`` closes:
    2KΩ in region 2, the PI on the raw speed in 1.5 and 2.5). Exact Dirlik on |T|²S_W on the
    design's grid, spectrum and Wöhler exponent.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine the design was made on.
    design : TorqueDesign
        The design (:func:`design_torque`).
    law : specdesign.rosco.TorqueLaw, optional
        The design's law as simulated.

    Returns
    -------
    float
        Tower-base DEL reduction against the baseline, %.

    Raises
    ------
    ValueError
        If either loop is unstable with its law closed (the promise would be meaningless).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> d = design_torque(m, 8.0, target_reduction=20.0)
    >>> bool(abs(law_promise(m, d) - d.promise) < 1.0)
    True
    """
    v, w = design.wind_speed, design.omega
    law = design.torque_law(model.torque_control) if law is None else law
    P = model.linearize(v)
    A, B, _, D = _form(_responses(P, w))
    op = model.trim(v)
    base = model.torque_control
    lin = 2.0 * base.k_opt * op.rotor_speed if op.region == "2" else -(base.kp + base.ki / control.tf("s"))
    loop = P["gen_speed", "gen_torque"]
    dels = []
    for name, tl in (("baseline", base), ("design", law)):
        g = lin - _law_tf(model, tl, v)
        # τ_add = −G·Ω. In regions 1.5 and 2.5 the linearised law's PI state and G's integrator
        # both integrate Ω: their difference is a mode at s = 0 that nothing excites or sees
        # (it cancels in L = L_lin − G), left by feedback at |s| ~ 1e-12 rad/s: not counted
        poles = control.feedback(loop, g).poles()
        if np.max(poles.real) >= _MARGINAL:
            raise ValueError(f"the {name} torque law {tl.name!r} closed on the linearised turbine at {v:g} m/s is "
                             f"unstable (pole {poles[np.argmax(poles.real)]:.3g})")
        G = control.frequency_response(g, w).complex.ravel()
        dels.append(float(del_spectral(w, np.abs((A + B * G) / (1.0 + D * G)) ** 2 * design.wind_psd, design.m)))
    return 100.0 * (1.0 - dels[1] / dels[0])


def _form(R):
    yw, yt, nw, nt = R["tower_base_my"][0], R["tower_base_my"][1], R["gen_speed"][0], R["gen_speed"][1]
    return yw, yw * nt - yt * nw, np.ones_like(yw), nt


def _responses(P, w):
    """{output: (P_y,wind, P_y,gen_torque)} at the frequencies ``w``."""
    return {y: tuple(control.frequency_response(P[y, u], w).complex.ravel() for u in ("wind", "gen_torque"))
            for y in _OUTPUTS}


def _check(model, wind_speed, target_reduction, max_power_loss_pct, m):
    if getattr(model, "torque_control", None) is None:
        raise TypeError("model must be a TurbineModel with a torque law (model.torque_control), e.g. iea15mw()")
    for name, x in (("wind_speed", wind_speed), ("target_reduction", target_reduction),
                    ("max_power_loss_pct", max_power_loss_pct), ("m", m)):
        if isinstance(x, bool) or not isinstance(x, (int, float, np.floating, np.integer)) or not math.isfinite(x):
            raise ValueError(f"{name}={x!r} must be a finite number")
    if not 0 < target_reduction < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a tower-base DEL reduction in % within (0, 100)")
    if max_power_loss_pct < 0:
        raise ValueError(f"max_power_loss_pct={max_power_loss_pct!r} must be >= 0 (a loss of mean power, %)")
    if m <= 0:
        raise ValueError(f"m={m!r} must be a positive Wöhler exponent")
    op = model.trim(wind_speed)
    if op.region not in TORQUE_DESIGN_REGIONS:
        raise ValueError(f"wind_speed={wind_speed!r} m/s is in torque region {op.region!r}: the pitch loop acts there "
                         f"(rated at {model.rated_wind_speed():.2f} m/s); design the pitch controller (qft.design_qft) "
                         f"instead, the torque design is for regions {TORQUE_DESIGN_REGIONS}")
    return op


def design_torque(model, wind_speed: float, target_reduction: float = 15.0, max_power_loss_pct: float = 1.0, *,
                  m: float = TOWER_M, turbulence_class: str = "B", omega=None) -> TorqueDesign:
    """The smallest added torque-loop stiffness that cuts the tower-base DEL by ``target_reduction`` %.

    The gain is the first crossing of the target on a log grid of 81 gains, 0.01-100 times the
    law's own stiffness, refined by Brent's method between the grid neighbours (the DEL falls
    monotonically with k on the IEA 15 MW at 7-10 m/s; a non-monotone plant could hide a smaller
    root between grid points). The closed loop with the gain is checked stable.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        Turbine with a torque law (``model.torque_control``).
    wind_speed : float
        Operating point below rated, m/s (torque regions :data:`TORQUE_DESIGN_REGIONS`).
    target_reduction : float
        Tower-base DEL reduction to reach, % (linear, exact Dirlik on |T|²S_W vs the baseline).
    max_power_loss_pct : float
        Largest acceptable mean aerodynamic power loss, % (second-order estimate).
    m : float
        Wöhler exponent (-), range-based S-N curve.
    turbulence_class : str
        IEC turbulence class of the rotor-effective wind spectrum.
    omega : array_like, optional
        Frequency grid, rad/s (default :data:`DEFAULT_TORQUE_OMEGA`, 0.001-10: the rotor speed
        and the mean power have variance below 0.01 rad/s, the pitch designs' lower end).

    Returns
    -------
    TorqueDesign
        The gain k (N·m per rad/s), its promise and costs; :meth:`TorqueDesign.torque_law`
        gives the nonlinear law.

    Raises
    ------
    ValueError
        Above rated (the pitch region), for bad inputs (named), when no gain reaches the
        target (the limit G → ∞ is reported) or when the power loss at the smallest gain that
        does exceeds ``max_power_loss_pct``.
    TypeError
        For a model without a torque law.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> d = design_torque(iea15mw(), 8.0, target_reduction=15.0)
    >>> bool(d.promise >= 15.0 - 1e-6) and d.gain > 0
    True
    """
    op = _check(model, wind_speed, target_reduction, max_power_loss_pct, m)
    w = DEFAULT_TORQUE_OMEGA if omega is None else np.asarray(omega, dtype=float)
    if w.ndim != 1 or w.size < 2 or not np.all(np.isfinite(w)) or np.any(w <= 0) or np.any(np.diff(w) <= 0):
        raise ValueError("omega must be an increasing 1-D grid of positive frequencies in rad/s")
    base = baseline_analysis(model, wind_speed, m=m, turbulence_class=turbulence_class, omega=w)
    s_w = base.wind_psd
    R = _responses(model.linearize(wind_speed), w)
    law = model.torque_control
    stiff = 2.0 * law.k_opt * op.rotor_speed if op.region == "2" else -law.kp
    eta_om, eta_tq = model.generator_efficiency * op.rotor_speed, op.power / op.rotor_speed
    e = model.aero_expansion(wind_speed)
    om0, gq, hq = e.point[0], e.gradient[0], e.hessian[0]
    hp = np.array([[om0 * hq[0, 0] + 2 * gq[0], om0 * hq[0, 1] + gq[1]], [om0 * hq[0, 1] + gq[1], om0 * hq[1, 1]]])
    p_aero = e.loads[0] * om0

    def maps(k):
        d = 1.0 - k * R["gen_speed"][1]  # 1 + G·D with G = −k
        T = {y: R[y][0] + k * R[y][1] * R["gen_speed"][0] / d for y in _OUTPUTS}
        T["torque"] = (T["power"] - eta_tq * T["gen_speed"]) / eta_om  # P = η·τ·Ω linearised
        return T

    def var(x):
        return float(np.trapezoid(np.abs(x) ** 2 * s_w, w))

    def dlt(k):
        return float(del_spectral(w, np.abs(maps(k)["tower_base_my"]) ** 2 * s_w, m))

    def mean_power(T):
        z = (T["gen_speed"], 1.0 - T["tower_top_vel"])  # the rotor sees wind − ẋ_top
        cov = np.array([[np.trapezoid(np.real(a * np.conj(b)) * s_w, w) for b in z] for a in z])
        return 0.5 * float(np.sum(hp * cov))

    d0 = dlt(0.0)  # = the baseline's: A is baseline_analysis's T_MyT,w (same plant, same grid)
    _, B, _, D = _form(R)
    limit = 100.0 * (1.0 - float(del_spectral(w, np.abs(B / D) ** 2 * s_w, m)) / d0)
    ks = stiff * _GAIN_SPAN
    red = np.array([100.0 * (1.0 - dlt(k) / d0) for k in ks])
    hit = np.flatnonzero(red >= target_reduction)
    if hit.size == 0:
        raise ValueError(f"no torque gain reaches target_reduction={target_reduction:g} % at {wind_speed:g} m/s: the limit "
                         f"G -> inf (rotor speed held) gives {limit:.1f} %, k = {ks[-1]:.3g} N·m/(rad/s) "
                         f"(100 x the law's stiffness) gives {red[-1]:.1f} %")
    i = int(hit[0])
    lo = 0.0 if i == 0 else ks[i - 1]
    k = ks[i] if red[i] == target_reduction else float(
        brentq(lambda x: 100.0 * (1.0 - dlt(x) / d0) - target_reduction, lo, ks[i], xtol=1e-12 * ks[i], rtol=1e-12))
    P = model.linearize(wind_speed)
    io, it = P.output_labels.index("gen_speed"), P.input_labels.index("gen_torque")
    poles = np.linalg.eigvals(np.asarray(P.A) + k * np.asarray(P.B)[:, it:it + 1] @ np.asarray(P.C)[io:io + 1])
    if np.max(poles.real) >= 0:
        raise ValueError(f"the torque loop with k = {k:.4g} N·m/(rad/s) is unstable at {wind_speed:g} m/s "
                         f"(pole {poles[np.argmax(poles.real)]:.3g})")
    T0, T = maps(0.0), maps(k)
    dp = 100.0 * (mean_power(T) - mean_power(T0)) / p_aero
    if -dp > max_power_loss_pct:
        raise ValueError(f"the power loss {-dp:.2f} % exceeds max_power_loss_pct={max_power_loss_pct:g} at "
                         f"k = {k:.4g} N·m/(rad/s), the smallest gain reaching target_reduction={target_reduction:g} % "
                         f"at {wind_speed:g} m/s")
    return TorqueDesign(
        wind_speed=float(wind_speed), region=op.region, gain=float(k), law_stiffness=float(stiff),
        target_reduction=float(target_reduction), promise=100.0 * (1.0 - dlt(k) / d0), limit_promise=limit,
        baseline_del=d0, design_del=dlt(k), speed_sd=math.sqrt(var(T["gen_speed"])),
        baseline_speed_sd=math.sqrt(var(T0["gen_speed"])), torque_sd=math.sqrt(var(T["torque"])),
        baseline_torque_sd=math.sqrt(var(T0["torque"])), power_sd=math.sqrt(var(T["power"])),
        baseline_power_sd=math.sqrt(var(T0["power"])), power_change_pct=dp, m=float(m), omega=w,
        t_response=T["tower_base_my"], wind_psd=s_w)
