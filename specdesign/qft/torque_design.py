"""The design loop below rated: a generator-torque loop stiffness for a tower-load target.

Below rated ROSCO's pitch PI sits at fine pitch and the only loop is the generator-torque law
(``TurbineModel.linearize`` closes it in the plant). A torque controller G added to the law,
τ_add = −G·Ω_g (Ω_g the rotor-shaft speed deviation, rad/s), gives the tower-base moment's wind
map in QFT's general form

    T_MyT,w = (A + B·G)/(C + D·G),  A = P_MyT,w,  B = P_MyT,w·P_Ω,τ − P_MyT,τ·P_Ω,w,  C = 1,
    D = P_Ω,τ,

with the limit G → ∞ (rotor speed held) K∞ = B/D. :func:`design_torque` designs the law the
simulator runs: ROSCO's TSR-tracking torque PI (``VS_ControlMode`` 3, :meth:`TorqueDesign.torque_law`)
with proportional gain −(s_law + k) (s_law the law's own stiffness at the trim, k ≥ 0 N·m per
rad/s the added stiffness), integral gain in ROSCO's ratio and a slow speed reference (the
reference must not follow the wind over the tower band, or the PI holds nothing there). It picks
the smallest k whose promised tower-base DEL reduction reaches the target, with its costs from
the same linear maps: rotor-speed, torque and power SD and the mean aerodynamic power change,
second order, ½·tr(H_P·Σ) (H_P the Hessian of P = Q·Ω in (Ω, wind − ẋ_top) from
``model.aero_expansion``, Σ their covariance).

The promise follows the simulated laws: ``model.linearize`` closes the K·Ω² curve on the raw
speed (what modes 1, 3 and 4 track in steady state), while the simulator's laws act on ROSCO's
filtered speed (corner 1 rad/s, at the tower mode) and mode 3's PI tracks a moving reference.
:func:`torque_law_response` linearises a law as simulated (checked against the nonlinear loop's
small-amplitude response, tests/test_torque_design.py), and both the baseline (the model's own
law) and the design enter the general form as G = L_lin − L (exact Dirlik on |T|²S_W, the pitch
loop open). The filter's lag caps what the mode-3 family gives (22.7 % at 8 m/s, against 41 %
for G → ∞). Nonlinear, at 8 m/s, the rest of the gap to rainflow is the torque ceiling (rated
torque) the stiffer law reaches in gusts and the minimum-speed region (1.5) the turbulent rotor
visits (docs/below_rated.md, section 3; ``benchmarks/below_rated_design.py --part torque_gap``).
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

__all__ = ["DEFAULT_REFERENCE_CORNER", "DEFAULT_TORQUE_OMEGA", "TORQUE_DESIGN_REGIONS", "TorqueDesign", "design_torque", "law_promise",
           "torque_general_form", "torque_law_response"]

#: Torque regions (:data:`specdesign.rosco.TORQUE_REGIONS`) where the torque loop is the only
#: loop; in "2.5s" (setpoint smoothing) and "3" the pitch loop acts.
TORQUE_DESIGN_REGIONS = ("1.5", "2", "2.5")
#: The design frequency grid, rad/s.
DEFAULT_TORQUE_OMEGA = np.logspace(-3.0, 1.0, 800)
#: The gain search spans k = 0 and this range in units of the law's own stiffness (-).
_GAIN_SPAN = np.logspace(-2.0, 2.0, 81)
#: Real part (rad/s) from which a closed-loop pole counts as unstable: in regions 1.5 and 2.5 the
#: linearised law's PI state and G's integrator both integrate Ω, and their difference is a mode
#: at s = 0 that nothing excites or sees (it cancels in L = L_lin − G), left by ``feedback`` at
#: |s| ~ 1e-12 rad/s; the slowest physical pole (the reference filter, 0.02 rad/s) is far above.
_MARGINAL = 1e-8
#: The design's speed-reference corner by default, rad/s (``F_VSRefSpdCornerFreq``).
DEFAULT_REFERENCE_CORNER = 0.02
_OUTPUTS = ("tower_base_my", "gen_speed", "tower_top_vel", "power")


@dataclass(frozen=True)
class TorqueDesign:
    """A torque-loop design below rated (:func:`design_torque`).

    Every linear figure is computed with the laws as simulated (:func:`torque_law_response`):
    the baseline is the model's own law, the design :meth:`torque_law` of it.

    Parameters
    ----------
    wind_speed : float
        Operating point, m/s.
    region : str
        Torque region of the trim (:data:`TORQUE_DESIGN_REGIONS`).
    gain : float
        k, the added proportional torque gain, N·m per rad/s of rotor-shaft speed (the mode-3
        PI's kp = −(law_stiffness + k)).
    law_stiffness : float
        The torque law's own dτ/dΩ at the trim, N·m per rad/s (region 2: 2KΩ; regions 1.5 and
        2.5: −kp of its PI).
    reference_corner : float
        The design law's speed-reference corner ``F_VSRefSpdCornerFreq``, rad/s.
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
    reference_corner: float
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

    def torque_law(self, law):
        """The design as ROSCO's TSR-tracking torque PI, for ``simulate(..., torque_control=law)``.

        Parameters
        ----------
        law : specdesign.rosco.TorqueLaw
            The turbine's torque law (``model.torque_control``, the law the promise was made
            with), kept but for mode, gains and reference corner.

        Returns
        -------
        specdesign.rosco.TorqueLaw
            ``mode=3``, ``kp = −(law_stiffness + gain)`` (ROSCO's sign), ``ki`` in the ratio
            ki/kp of ``law``, ``reference_corner`` the design's.

        Raises
        ------
        ValueError
            For a ``law`` without a PI.

        Examples
        --------
        >>> from specdesign.turbine import iea15mw
        >>> m = iea15mw()
        >>> d = design_torque(m, 8.0, target_reduction=15.0)
        >>> d.torque_law(m.torque_control).mode
        3
        """
        return _design_law(law, self.law_stiffness, self.gain, self.reference_corner, self.wind_speed)


def _design_law(law, stiff, k, corner, wind_speed):
    """The mode-3 PI with kp = −(stiff + k), ki in ``law``'s ratio, reference corner ``corner`` rad/s."""
    if not (law.kp < 0 and law.ki <= 0):
        raise ValueError(f"law has kp={law.kp!r}, ki={law.ki!r}: the torque PI gains must be negative (ROSCO's sign)")
    kp = -(stiff + k)
    return dataclasses.replace(law, mode=3, kp=kp, ki=kp * law.ki / law.kp, reference_corner=corner,
                               name=f"torque loop k={k:.4g} N·m/(rad/s) @ {wind_speed:g} m/s")


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


class _LawMaps:
    """The linear maps at ``wind_speed`` with a torque law as simulated closed in place of the linearised one."""

    def __init__(self, model, wind_speed, w):
        P = model.linearize(wind_speed)
        self.model, self.v, self.w = model, wind_speed, w
        self.R = _responses(P, w)
        self.loop = P["gen_speed", "gen_torque"]
        base, op = model.torque_control, model.trim(wind_speed)
        # the law model.linearize closes (controller.torque.close_torque_loop): 2KΩ or the PI on the raw speed
        self.lin = 2.0 * base.k_opt * op.rotor_speed if op.region == "2" else -(base.kp + base.ki / control.tf("s"))

    def g(self, law):
        """G(jω) = L_lin − L of ``law`` and whether the loop with it is stable."""
        g = self.lin - _law_tf(self.model, law, self.v)
        poles = control.feedback(self.loop, g).poles()  # τ_add = −G·Ω
        return control.frequency_response(g, self.w).complex.ravel(), bool(np.max(poles.real) < _MARGINAL)

    def maps(self, G):
        """{output: T_y,w(jω)} with τ_add = −G·Ω_g."""
        R = self.R
        d = 1.0 + G * R["gen_speed"][1]
        return {y: R[y][0] - G * R[y][1] * R["gen_speed"][0] / d for y in _OUTPUTS}


def law_promise(model, design: TorqueDesign, law=None) -> float:
    """The design's promise recomputed for another design law (e.g. a variant of ``design.torque_law``).

    Baseline: ``model.torque_control``; design: ``law`` (default ``design.torque_law(model.torque_control)``,
    which gives ``design.promise`` back), both linearised as simulated (:func:`torque_law_response`) and entered
    in the general form as G = L_lin − L. Exact Dirlik on |T|²S_W on the design's grid, spectrum and Wöhler
    exponent.

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
    >>> import dataclasses
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> d = design_torque(m, 8.0, target_reduction=20.0)
    >>> law = dataclasses.replace(d.torque_law(m.torque_control), filter_corner=30.0)  # ROSCO's filter's part
    >>> bool(law_promise(m, d, law) > d.promise)
    True
    """
    lm = _LawMaps(model, design.wind_speed, design.omega)
    law = design.torque_law(model.torque_control) if law is None else law
    dels = []
    for name, tl in (("baseline", model.torque_control), ("design", law)):
        G, ok = lm.g(tl)
        if not ok:
            raise ValueError(f"the {name} torque law {tl.name!r} closed on the linearised turbine at {design.wind_speed:g} "
                             "m/s is unstable")
        dels.append(float(del_spectral(design.omega, np.abs(lm.maps(G)["tower_base_my"]) ** 2 * design.wind_psd,
                                       design.m)))
    return 100.0 * (1.0 - dels[1] / dels[0])


def _form(R):
    yw, yt, nw, nt = R["tower_base_my"][0], R["tower_base_my"][1], R["gen_speed"][0], R["gen_speed"][1]
    return yw, yw * nt - yt * nw, np.ones_like(yw), nt


def _responses(P, w):
    """{output: (P_y,wind, P_y,gen_torque)} at the frequencies ``w``."""
    return {y: tuple(control.frequency_response(P[y, u], w).complex.ravel() for u in ("wind", "gen_torque"))
            for y in _OUTPUTS}


def _check(model, wind_speed, target_reduction, max_power_loss_pct, m, reference_corner):
    if getattr(model, "torque_control", None) is None:
        raise TypeError("model must be a TurbineModel with a torque law (model.torque_control), e.g. iea15mw()")
    for name, x in (("wind_speed", wind_speed), ("target_reduction", target_reduction),
                    ("max_power_loss_pct", max_power_loss_pct), ("m", m), ("reference_corner", reference_corner)):
        if isinstance(x, bool) or not isinstance(x, (int, float, np.floating, np.integer)) or not math.isfinite(x):
            raise ValueError(f"{name}={x!r} must be a finite number")
    if not 0 < target_reduction < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a tower-base DEL reduction in % within (0, 100)")
    if max_power_loss_pct < 0:
        raise ValueError(f"max_power_loss_pct={max_power_loss_pct!r} must be >= 0 (a loss of mean power, %)")
    if m <= 0:
        raise ValueError(f"m={m!r} must be a positive Wöhler exponent")
    if reference_corner <= 0:
        raise ValueError(f"reference_corner={reference_corner!r} must be a positive frequency in rad/s (e.g. 0.02)")
    op = model.trim(wind_speed)
    if op.region not in TORQUE_DESIGN_REGIONS:
        raise ValueError(f"wind_speed={wind_speed!r} m/s is in torque region {op.region!r}: the pitch loop acts there "
                         f"(rated at {model.rated_wind_speed():.2f} m/s); design the pitch controller (qft.design_qft) "
                         f"instead, the torque design is for regions {TORQUE_DESIGN_REGIONS}")
    return op


def design_torque(model, wind_speed: float, target_reduction: float = 15.0, max_power_loss_pct: float = 1.0, *,
                  m: float = TOWER_M, turbulence_class: str = "B", omega=None,
                  reference_corner: float = DEFAULT_REFERENCE_CORNER) -> TorqueDesign:
    """The smallest added torque-loop stiffness that cuts the tower-base DEL by ``target_reduction`` %.

    The design is ROSCO's mode-3 torque PI with kp = −(law stiffness + k) (:meth:`TorqueDesign.torque_law`);
    its promise and the baseline's DEL (the model's own law) are computed with both laws
    linearised as the simulator runs them (:func:`torque_law_response`). k = 0 if the mode-3 PI
    with the law's own stiffness already reaches the target; otherwise the first crossing of the
    target on a log grid of 81 gains, 0.01-100 times the law's stiffness, refined by Brent's
    method between the grid neighbours (a non-monotone promise could hide a smaller root between
    grid points). The closed loop with the gain is checked stable; grid gains whose loop is not
    are skipped.

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
    reference_corner : float, optional
        The design law's ``F_VSRefSpdCornerFreq``, rad/s: well below the tower band (≈ 1 rad/s)
        so the PI holds the speed there; ROSCO's 0.209 lets the reference follow the wind.

    Returns
    -------
    TorqueDesign
        The gain k (N·m per rad/s), its promise and costs; :meth:`TorqueDesign.torque_law`
        gives the nonlinear law.

    Raises
    ------
    ValueError
        Above rated (the pitch region), for bad inputs (named), when no gain reaches the
        target (the family's best and the limit G → ∞ are reported) or when the power loss at
        the smallest gain that does exceeds ``max_power_loss_pct``.
    TypeError
        For a model without a torque law.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> d = design_torque(iea15mw(), 8.0, target_reduction=18.0)
    >>> bool(d.promise >= 18.0 - 1e-6) and d.gain > 0
    True
    """
    op = _check(model, wind_speed, target_reduction, max_power_loss_pct, m, reference_corner)
    w = DEFAULT_TORQUE_OMEGA if omega is None else np.asarray(omega, dtype=float)
    if w.ndim != 1 or w.size < 2 or not np.all(np.isfinite(w)) or np.any(w <= 0) or np.any(np.diff(w) <= 0):
        raise ValueError("omega must be an increasing 1-D grid of positive frequencies in rad/s")
    s_w = baseline_analysis(model, wind_speed, m=m, turbulence_class=turbulence_class, omega=w).wind_psd
    lm = _LawMaps(model, wind_speed, w)
    law = model.torque_control
    stiff = 2.0 * law.k_opt * op.rotor_speed if op.region == "2" else -law.kp
    eta_om, eta_tq = model.generator_efficiency * op.rotor_speed, op.power / op.rotor_speed
    e = model.aero_expansion(wind_speed)
    om0, gq, hq = e.point[0], e.gradient[0], e.hessian[0]
    hp = np.array([[om0 * hq[0, 0] + 2 * gq[0], om0 * hq[0, 1] + gq[1]], [om0 * hq[0, 1] + gq[1], om0 * hq[1, 1]]])
    p_aero = e.loads[0] * om0

    def maps(G):
        T = lm.maps(G)
        T["torque"] = (T["power"] - eta_tq * T["gen_speed"]) / eta_om  # P = η·τ·Ω linearised
        return T

    def var(x):
        return float(np.trapezoid(np.abs(x) ** 2 * s_w, w))

    def dlt(G):
        return float(del_spectral(w, np.abs(lm.maps(G)["tower_base_my"]) ** 2 * s_w, m))

    def mean_power(T):
        z = (T["gen_speed"], 1.0 - T["tower_top_vel"])  # the rotor sees wind − ẋ_top
        cov = np.array([[np.trapezoid(np.real(a * np.conj(b)) * s_w, w) for b in z] for a in z])
        return 0.5 * float(np.sum(hp * cov))

    G0, ok = lm.g(law)
    if not ok:
        raise ValueError(f"the torque law {law.name!r} closed on the linearised turbine at {wind_speed:g} m/s is unstable")
    d0 = dlt(G0)
    _, B, _, D = _form(lm.R)
    limit = 100.0 * (1.0 - float(del_spectral(w, np.abs(B / D) ** 2 * s_w, m)) / d0)

    def design(k):
        """G of the design law with gain k, its promise (%, NaN if its loop is unstable)."""
        G, stable = lm.g(_design_law(law, stiff, k, reference_corner, wind_speed))
        return G, (100.0 * (1.0 - dlt(G) / d0) if stable else math.nan)

    ks = np.concatenate([[0.0], stiff * _GAIN_SPAN])
    red = np.array([design(k)[1] for k in ks])
    hit = np.flatnonzero(red >= target_reduction)  # NaN (unstable) compares False
    if hit.size == 0:
        best = int(np.nanargmax(red))
        raise ValueError(f"no torque gain reaches target_reduction={target_reduction:g} % at {wind_speed:g} m/s: the "
                         f"mode-3 torque PI on ROSCO's filtered speed reaches at most {red[best]:.1f} % (k = "
                         f"{ks[best]:.3g} N·m/(rad/s), {ks[best] / stiff:.3g} x the law's stiffness); the limit "
                         f"G -> inf (rotor speed held) gives {limit:.1f} %")
    i = int(hit[0])
    if i == 0 or red[i] == target_reduction or not math.isfinite(red[i - 1]):
        k = ks[i]  # k = 0 already reaches it, or the grid point is the root, or its neighbour's loop is unstable
    else:
        k = float(brentq(lambda x: design(x)[1] - target_reduction, ks[i - 1], ks[i], xtol=1e-12 * ks[i], rtol=1e-12))
    G, promise = design(k)
    if not math.isfinite(promise):
        raise ValueError(f"the torque loop with k = {k:.4g} N·m/(rad/s) is unstable at {wind_speed:g} m/s")
    T0, T = maps(G0), maps(G)
    dp = 100.0 * (mean_power(T) - mean_power(T0)) / p_aero
    if -dp > max_power_loss_pct:
        raise ValueError(f"the power loss {-dp:.2f} % exceeds max_power_loss_pct={max_power_loss_pct:g} at "
                         f"k = {k:.4g} N·m/(rad/s), the smallest gain reaching target_reduction={target_reduction:g} % "
                         f"at {wind_speed:g} m/s")
    return TorqueDesign(
        wind_speed=float(wind_speed), region=op.region, gain=float(k), law_stiffness=float(stiff),
        reference_corner=float(reference_corner), target_reduction=float(target_reduction), promise=promise,
        limit_promise=limit, baseline_del=d0, design_del=dlt(G), speed_sd=math.sqrt(var(T["gen_speed"])),
        baseline_speed_sd=math.sqrt(var(T0["gen_speed"])), torque_sd=math.sqrt(var(T["torque"])),
        baseline_torque_sd=math.sqrt(var(T0["torque"])), power_sd=math.sqrt(var(T["power"])),
        baseline_power_sd=math.sqrt(var(T0["power"])), power_change_pct=dp, m=float(m), omega=w,
        t_response=T["tower_base_my"], wind_psd=s_w)
