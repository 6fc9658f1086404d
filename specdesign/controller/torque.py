"""ROSCO's generator-torque controller below rated: :class:`TorqueLaw`, its compiled step, its steady state.

ROSCO (``VariableSpeedControl``, ``ComputeVariablesSetpoints``, ``StateMachine`` and
``SetpointSmoother`` of ROSCO 2.10's Fortran source) runs, every controller step, on the
generator speed low-passed by the filter the pitch controller uses (``F_LPFType``):

* ``VS_ControlMode = 1``: K·Ω² in region 2, with a PI on the speed error in the transitions:
  region 1.5 holds the minimum speed ``VS_MinOMSpd`` (torque ≤ K·Ω_min²), region 2.5 holds
  ``VS_RefSpd`` (torque from K·Ω_ref² up to ``VS_ArSatTq``), region 3 (the pitch at least
  ``PC_Switch`` above its minimum) the rated torque. ROSCO's state machine picks the region
  from the previous step's two PI outputs and the measured pitch.
* ``VS_ControlMode = 3`` (power-based TSR tracking) and ``4`` (torque-based): one PI tracks the
  reference speed (P/η/K)^{1/3} or (T/K)^{1/2}, low-passed at ``F_VSRefSpdCornerFreq`` and held
  between ``VS_MinOMSpd`` and ``VS_RefSpd``; its output is limited to [``VS_MinTq``, ``VS_RtTq``].
  In steady state both track T = K·Ω² between the two speeds.
* ``VS_ConstPower = 1`` (``const_power``): above rated (state 5 of ROSCO's state machine) the
  torque holds the rated power, P_rated/(η·Ω_f) on the filtered speed Ω_f, instead of the
  rated torque, and every mode's torque ceiling is min(P_rated/(η·Ω_f), ``VS_MaxTq``) instead of
  ``VS_RtTq`` (``VariableSpeedControl`` of ``Controllers.f90``).
* ``VS_ControlMode = 2`` tracks the TSR from ROSCO's wind-speed estimator (an extended Kalman
  filter of the rotor) which the workbench does not model: :func:`torque_law_from_discon`
  refuses it unless told to read the file's gains as mode 3 (``mode=3``).

Setpoint smoothing (``SS_Mode = 1``) shifts the references apart so the two loops do not
fight near rated: ΔΩ = Ω_pc·[(β − β_min)/0.524·``SS_VSGain`` − (P_rated − P)/P_rated·``SS_PCGain``],
low-passed at ``F_SSCornerFreq``; a positive shift lowers the torque reference, a negative one
raises the pitch controller's. Torque is then limited to [``VS_MinTq``, min(``VS_MaxTq``,
``VS_RtTq``)] (with constant power min(``VS_MaxTq``, P_rated/(η·Ω_f))) and to the rate
``VS_MaxRat``. PIs are ROSCO's: forward Euler integrator
saturated at the output limits. Filters are ROSCO's Tustin forms, reset to their input on
the first call. Peak shaving (``PS_Mode``, a minimum pitch ``PS_BldPitchMin`` interpolated at
the wind speed estimated by ROSCO's extended Kalman filter) belongs to the pitch controller
(:mod:`specdesign.controller.peak_shaving`, run by :func:`specdesign.rosco.rosco_scheduled`); its
limit reaches this law as ``pitch_min`` of :func:`torque_step` (the smoother and the state
machine measure the pitch from it), the law's ``fine_pitch`` without it.

All quantities here are on the rotor (low-speed) shaft in SI: a DISCON.IN's generator-side
speeds are divided by its gearbox ratio N, torques multiplied by it (K by N³, PI gains by N²).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from .discon_file import read_discon

if TYPE_CHECKING:  # pragma: no cover
    from ..turbine import TurbineModel

__all__ = ["TORQUE_MODES", "TORQUE_PARAMS", "TORQUE_STATES", "TORQUE_REGIONS", "TRIM_TOL", "TorqueLaw", "torque_law",
           "torque_law_from_discon", "steady_state", "close_torque_loop", "torque_step", "rosco_lpf1", "rosco_lpf2"]

#: Regions of a trim (:attr:`specdesign.turbine.OperatingPoint.region`): "1.5" minimum speed held
#: by the PI, "2" K·Ω², "2.5" the torque controller's rated speed held by the PI, "2.5s" its PI
#: saturated at ``VS_ArSatTq`` with the speed between the two references, "3" pitch-regulated.
TORQUE_REGIONS = ("1.5", "2", "2.5", "2.5s", "3")

#: ROSCO torque-control modes this module runs (``VS_ControlMode``).
TORQUE_MODES = (1, 3, 4)

# Layout of the flat parameter array of torque_step (TorqueLaw.params()).
(T_MODE, T_K, T_KP, T_KI, T_MIN_SPEED, T_VS_REF, T_PC_REF, T_RATED_TQ, T_MAX_TQ, T_AR_SAT, T_MIN_TQ, T_MAX_RATE,
 T_RATED_POWER, T_GEN_EFF, T_FILT_TYPE, T_FILT_CORNER, T_FILT_DAMP, T_REF_CORNER, T_SS_MODE, T_SS_VS, T_SS_PC,
 T_SS_CORNER, T_PC_SWITCH, T_PITCH_MIN, T_CONST_POWER) = range(25)
#: Length of :meth:`TorqueLaw.params`.
TORQUE_PARAMS = 25
# Layout of the state array of torque_step.
(S_WF, S_WF2, S_U1, S_U2, S_REF, S_REF_U, S_SSF, S_SS_U, S_IAR, S_IBR, S_AR, S_BR, S_STATE, S_TQ, S_PLAST) = range(15)
#: Length of the state array of :func:`torque_step`.
TORQUE_STATES = 16
#: brentq's ``xtol`` and ``rtol`` for a trim's rotor speed (rad/s) and pitch (rad), here and in
#: :meth:`specdesign.turbine.TurbineModel.trim`: a few ulps of values near 1, so a trim is
#: converged to what float64 holds.
TRIM_TOL = 1e-14


@dataclass(frozen=True)
class TorqueLaw:
    """ROSCO's generator-torque controller, on the rotor shaft (see :mod:`specdesign.controller.torque`).

    Parameters
    ----------
    mode : int
        ``VS_ControlMode``: 1 (K·Ω² with PI transitions), 3 or 4 (TSR-tracking PI).
    k_opt : float
        Region-2 constant K (N·m per (rad/s)²): T = K·Ω².
    kp : float
        PI proportional gain in ROSCO's sign (N·m per rad/s; T = kp·e + ki∫e, e = reference −
        filtered speed, so both gains are negative).
    ki : float
        PI integral gain (N·m per rad).
    min_speed : float
        ``VS_MinOMSpd``, lowest rotor speed (rad/s).
    reference_speed : float
        ``VS_RefSpd``, the torque controller's rated speed (rad/s).
    pitch_reference_speed : float
        ``PC_RefSpd``, the pitch controller's reference (rad/s).
    rated_torque : float
        ``VS_RtTq`` (N·m).
    max_torque : float
        ``VS_MaxTq`` (N·m).
    transition_torque : float
        ``VS_ArSatTq``, upper limit of the region-2.5 PI (N·m).
    max_rate : float
        ``VS_MaxRat``, torque rate limit (N·m/s).
    rated_power : float
        ``VS_RtPwr`` (W).
    generator_efficiency : float
        ``VS_GenEff`` / 100 (-).
    min_torque : float, optional
        ``VS_MinTq`` (N·m).
    filter_type : int, optional
        ``F_LPFType`` of the generator-speed filter: 1 first order, 2 second order.
    filter_corner : float, optional
        ``F_LPFCornerFreq`` (rad/s).
    filter_damping : float, optional
        ``F_LPFDamping`` (-).
    reference_corner : float, optional
        ``F_VSRefSpdCornerFreq`` (rad/s), low-pass of the tracking reference (modes 3, 4); 0: none.
    setpoint_smoothing : bool, optional
        ``SS_Mode``.
    ss_vs_gain, ss_pc_gain : float, optional
        ``SS_VSGain``, ``SS_PCGain`` (-).
    ss_corner : float, optional
        ``F_SSCornerFreq`` (rad/s).
    pitch_switch : float, optional
        ``PC_Switch`` (rad): region 3 from the minimum pitch plus this.
    fine_pitch : float, optional
        ``PC_FinePit`` (rad), the pitch below rated.
    const_power : bool, optional
        ``VS_ConstPower``: above rated hold the rated power (torque P_rated/(η·Ω_f), N·m, capped
        at ``max_torque``) instead of the rated torque.
    name : str, optional
        Label.
    """

    mode: int
    k_opt: float
    kp: float
    ki: float
    min_speed: float
    reference_speed: float
    pitch_reference_speed: float
    rated_torque: float
    max_torque: float
    transition_torque: float
    max_rate: float
    rated_power: float
    generator_efficiency: float
    min_torque: float = 0.0
    filter_type: int = 2
    filter_corner: float = 1.0081
    filter_damping: float = 0.7
    reference_corner: float = 0.20944
    setpoint_smoothing: bool = True
    ss_vs_gain: float = 1.0
    ss_pc_gain: float = 0.05
    ss_corner: float = 0.6283
    pitch_switch: float = 0.01745
    fine_pitch: float = 0.0
    const_power: bool = False
    name: str = "ROSCO torque"

    def __post_init__(self):
        if self.mode not in TORQUE_MODES:
            raise ValueError(f"mode={self.mode!r} must be one of {TORQUE_MODES} (ROSCO VS_ControlMode; 2 needs ROSCO's "
                             "wind-speed estimator, which is not modelled: use 3, the same PI on the power-based reference)")
        for k in ("k_opt", "min_speed", "reference_speed", "pitch_reference_speed", "rated_torque", "max_torque",
                  "transition_torque", "max_rate", "rated_power", "generator_efficiency", "filter_corner"):
            if not (math.isfinite(getattr(self, k)) and getattr(self, k) > 0):
                raise ValueError(f"{k}={getattr(self, k)!r} must be a positive finite number (SI, rotor shaft)")
        if not self.min_speed < self.reference_speed:
            raise ValueError(f"min_speed={self.min_speed} must be below reference_speed={self.reference_speed} (rad/s)")
        if self.filter_type not in (1, 2):
            raise ValueError(f"filter_type={self.filter_type!r} must be 1 or 2 (ROSCO F_LPFType)")

    @property
    def min_speed_torque(self) -> float:
        """ROSCO's ``VS_MinOMTq`` = K·Ω_min², the torque at the start of region 2 (N·m)."""
        return self.k_opt * self.min_speed**2

    def params(self) -> np.ndarray:
        """Flat float64 parameter array of :func:`torque_step`.

        Returns
        -------
        numpy.ndarray
            (:data:`TORQUE_PARAMS`,) parameters (SI, rotor shaft).
        """
        p = np.zeros(TORQUE_PARAMS)
        p[[T_MODE, T_K, T_KP, T_KI, T_MIN_SPEED, T_VS_REF, T_PC_REF, T_RATED_TQ, T_MAX_TQ, T_AR_SAT, T_MIN_TQ,
           T_MAX_RATE, T_RATED_POWER, T_GEN_EFF, T_FILT_TYPE, T_FILT_CORNER, T_FILT_DAMP, T_REF_CORNER, T_SS_MODE,
           T_SS_VS, T_SS_PC, T_SS_CORNER, T_PC_SWITCH, T_PITCH_MIN, T_CONST_POWER]] = [
            self.mode, self.k_opt, self.kp, self.ki, self.min_speed, self.reference_speed, self.pitch_reference_speed,
            self.rated_torque, self.max_torque, self.transition_torque, self.min_torque, self.max_rate,
            self.rated_power, self.generator_efficiency, self.filter_type, self.filter_corner, self.filter_damping,
            self.reference_corner, float(self.setpoint_smoothing), self.ss_vs_gain, self.ss_pc_gain, self.ss_corner,
            self.pitch_switch, self.fine_pitch, float(self.const_power)]
        return p


def torque_law(model: TurbineModel, *, mode: int = 1, omega_vs: float = 0.12, zeta_vs: float = 0.85,
               min_speed: float, max_torque: float, max_rate: float, tsr: float | None = None) -> TorqueLaw:
    """ROSCO's torque law tuned on the reduced model, as ROSCO's toolbox tunes it.

    K = ½ρπR⁵·Cp(λ*, β_fine)/λ*³ with λ* the tip-speed ratio of maximum Cp at the minimum
    pitch (or ``tsr``); ``VS_RefSpd`` = min(λ*·v_rated/R, Ω_rated); the transition PI by pole
    placement on the rotor's first-order model at rated (``second_order_PI`` of ROSCO's
    toolbox): K_p = (2ζω + A)/B, K_i = ω²/B with A = (∂Q/∂Ω)/J, B = −1/J.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    mode : int, optional
        ``VS_ControlMode`` (1, 3 or 4).
    omega_vs : float, optional
        Natural frequency of the torque loop (rad/s) (the IEA 15 MW tuning: 0.12).
    zeta_vs : float, optional
        Its damping ratio (-) (0.85).
    min_speed : float
        Lowest rotor speed (rad/s).
    max_torque : float
        Largest generator torque (N·m).
    max_rate : float
        Torque rate limit (N·m/s).
    tsr : float, optional
        Tip-speed ratio to track (-) (default: that of maximum Cp at the minimum pitch).

    Returns
    -------
    TorqueLaw
        The law.
    """
    beta = float(model.pitch_min)
    if tsr is None:  # maximum Cp: a coarse grid, then refined around its best point
        from scipy.optimize import minimize_scalar

        grid = np.linspace(model.tsr_grid[0], model.tsr_grid[-1], 126)
        i = int(np.argmax(model.rotor_coefficients(grid, beta)[0]))
        lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
        tsr = float(minimize_scalar(lambda x: -float(model.rotor_coefficients(x, beta)[0]), bounds=(lo, hi),
                                    method="bounded", options={"xatol": 1e-6}).x)
    cp_opt = float(model.rotor_coefficients(tsr, beta)[0])
    R = model.rotor_radius
    k = 0.5 * model.air_density * np.pi * R**5 * cp_opt / tsr**3
    v_rated = model.rated_wind_speed()
    ref = min(tsr * v_rated / R, model.rated_rotor_speed)
    J, h = model.drivetrain_inertia, 1e-5
    x = np.array([ref, 0.0, 0.0, beta, 0.0])
    a = (model.derivatives(x + [h, 0, 0, 0, 0], v_rated, beta, 0.0)[0]
         - model.derivatives(x - [h, 0, 0, 0, 0], v_rated, beta, 0.0)[0]) / (2 * h)
    B = -1.0 / J
    return TorqueLaw(mode=mode, k_opt=float(k), kp=float((2 * zeta_vs * omega_vs + a) / B), ki=float(omega_vs**2 / B),
                     min_speed=float(min_speed), reference_speed=float(ref),
                     pitch_reference_speed=float(model.rated_rotor_speed), rated_torque=float(model.rated_generator_torque),
                     max_torque=float(max_torque), transition_torque=float(model.rated_generator_torque),
                     max_rate=float(max_rate), rated_power=float(model.rated_power),
                     generator_efficiency=float(model.generator_efficiency), fine_pitch=beta)


def _entry(path, entries, name, default=None):
    e = entries.get(name)
    if e is None:
        if default is not None:
            return default
        raise ValueError(f"{path}: key {name!r} is missing (a DISCON.IN written by ROSCO's toolbox has it)")
    try:
        return float(e.values[0])
    except (ValueError, IndexError):
        raise ValueError(f"{path}: line {e.line}: {name} = {' '.join(e.values)!r} is not numeric") from None


def torque_law_from_discon(path: str | Path, *, mode: int | None = None) -> TorqueLaw:
    """ROSCO's torque controller as a DISCON.IN file sets it, converted to the rotor shaft.

    Parameters
    ----------
    path : str or pathlib.Path
        The DISCON.IN file.
    mode : int, optional
        Run the file's gains in this ``VS_ControlMode`` instead of the file's (e.g. 3 for a
        file in mode 2, whose wind-speed estimator is not modelled).

    Returns
    -------
    TorqueLaw
        The law (``VS_KP``/``VS_KI``: the first entry).

    Raises
    ------
    ValueError
        For a missing or non-numeric key (file, line and key named), a mode outside
        :data:`TORQUE_MODES` (mode 2: pass ``mode=3``), ``VS_ConstPower`` not 0 or 1, or
        ``VS_FBP`` or ``PRC_Mode`` not 0 (laws the workbench does not run).

    Notes
    -----
    A file's peak shaving (``PS_Mode = 1``) is the pitch controller's, not this law's:
    :func:`specdesign.rosco.rosco_scheduled` runs it with the file's schedule.

    Examples
    --------
    >>> from specdesign.rosco import iea15mw_discon
    >>> law = torque_law_from_discon(iea15mw_discon(), mode=1)
    >>> law.mode, round(law.min_speed, 4)
    (1, 0.5236)
    """
    entries, _ = read_discon(path)
    p = str(path)

    def f(name, default=None):
        return _entry(p, entries, name, default)

    file_mode = int(f("VS_ControlMode"))
    use = file_mode if mode is None else int(mode)
    if use not in TORQUE_MODES:
        line = entries["VS_ControlMode"].line
        raise ValueError(f"{p}: line {line}: VS_ControlMode = {use} is not run by the workbench (modes {TORQUE_MODES}); "
                         "mode 2 tracks the TSR from ROSCO's wind-speed estimator, which is not modelled: pass mode=3 "
                         "to run the file's PI on the power-based reference")
    for key in ("VS_FBP", "PRC_Mode"):  # they change the law itself: not run here
        if key in entries and int(f(key)) != 0:
            raise ValueError(f"{p}: line {entries[key].line}: {key} = {int(f(key))} is not modelled (the workbench "
                             "runs variable pitch, no power-reference tracking); set it to 0")
    const_power = int(f("VS_ConstPower", 0.0))
    if const_power not in (0, 1):
        raise ValueError(f"{p}: line {entries['VS_ConstPower'].line}: VS_ConstPower = {const_power} must be 0 "
                         "(constant torque above rated) or 1 (constant power)")
    n = f("WE_GearboxRatio")
    if not n > 0:
        raise ValueError(f"{p}: line {entries['WE_GearboxRatio'].line}: WE_GearboxRatio must be positive")
    return TorqueLaw(
        mode=use, k_opt=f("VS_Rgn2K") * n**3, kp=f("VS_KP") * n**2, ki=f("VS_KI") * n**2,
        min_speed=f("VS_MinOMSpd") / n, reference_speed=f("VS_RefSpd") / n, pitch_reference_speed=f("PC_RefSpd") / n,
        rated_torque=f("VS_RtTq") * n, max_torque=f("VS_MaxTq") * n, transition_torque=f("VS_ArSatTq") * n,
        max_rate=f("VS_MaxRat") * n, rated_power=f("VS_RtPwr"), generator_efficiency=f("VS_GenEff") / 100.0,
        min_torque=f("VS_MinTq") * n, filter_type=int(f("F_LPFType")), filter_corner=f("F_LPFCornerFreq"),
        filter_damping=f("F_LPFDamping"), reference_corner=f("F_VSRefSpdCornerFreq", 0.0),
        setpoint_smoothing=bool(int(f("SS_Mode"))), ss_vs_gain=f("SS_VSGain"), ss_pc_gain=f("SS_PCGain"),
        ss_corner=f("F_SSCornerFreq"), pitch_switch=f("PC_Switch"), fine_pitch=f("PC_FinePit"),
        const_power=bool(const_power), name=f"ROSCO torque ({Path(p).name})",
    )


def steady_state(model: TurbineModel, law: TorqueLaw, wind_speed: float) -> tuple[float, float, float, str]:
    """Steady rotor speed, torque and pitch under ``law`` below rated, and the region.

    The pitch is at fine pitch (the pitch controller saturated at its minimum, as ROSCO's is
    below rated). Region 2: Ω solves Q(Ω) = K·Ω² between the two speeds; below the minimum
    speed the transition PI holds it (region 1.5), above ``reference_speed`` it holds that
    (2.5) until the torque reaches ``transition_torque``, and then the speed floats where
    Q(Ω) equals that torque (2.5s). K·Ω² is capped at min(``rated_torque``, ``max_torque``):
    if it reaches the cap below ``reference_speed`` (the IEA 15 MW's ROSCO tuning does, at
    0.72 rad/s) region 2.5 never engages and the speed floats at that torque (2.5s). With
    constant power (``const_power``) the cap is min(``max_torque``, P/(η·Ω)) instead. Modes 3 and
    4 track the same curve in steady state.

    Parameters
    ----------
    model : TurbineModel
        The turbine (its aerodynamic torque Q(Ω, v, β)).
    law : TorqueLaw
        The torque law.
    wind_speed : float
        Mean wind speed (m/s), below rated.

    Returns
    -------
    omega : float
        Rotor speed (rad/s).
    torque : float
        Generator torque (N·m).
    pitch : float
        Blade pitch (rad).
    region : str
        One of :data:`TORQUE_REGIONS` but "3".

    Raises
    ------
    ValueError
        Below cut-in: the rotor cannot hold the minimum speed with a positive torque.
    """
    from scipy.optimize import brentq

    v = float(wind_speed)
    beta = max(float(law.fine_pitch), float(model.pitch_min))
    J = model.drivetrain_inertia

    def q(om):
        return float(model.derivatives(np.array([om, 0.0, 0.0, beta, 0.0]), v, beta, 0.0)[0]) * J

    lo, hi = law.min_speed, law.reference_speed

    def g(om):
        return q(om) - law.k_opt * om * om

    if g(lo) <= 0:
        t = q(lo)
        if not t > law.min_torque:
            raise ValueError(f"wind_speed={v!r} m/s is below cut-in: the aerodynamic torque at the minimum rotor "
                             f"speed {lo:.4g} rad/s is {t:.4g} N·m, not above the minimum generator torque")
        return lo, t, beta, "1.5"
    # K·Ω² is capped at the torque limit: where it reaches it before the reference speed (the
    # IEA 15 MW's tuning does), the torque saturates there and the speed floats up to rated
    # (with constant power the limit is min(VS_MaxTq, P/(η·Ω)), a function of the speed)
    p_eta = law.rated_power / law.generator_efficiency

    def ceiling(om):
        return min(law.max_torque, p_eta / om) if law.const_power else min(law.rated_torque, law.max_torque)

    if law.const_power:  # K·Ω² meets P/(η·Ω) at Ω³ = P/(η·K)
        top = min(hi, math.sqrt(law.max_torque / law.k_opt), (p_eta / law.k_opt) ** (1.0 / 3.0))
    else:
        top = min(hi, math.sqrt(ceiling(hi) / law.k_opt))
    if g(top) < 0:
        om = brentq(g, lo, top, xtol=TRIM_TOL, rtol=TRIM_TOL)
        return float(om), law.k_opt * float(om) ** 2, beta, "2"
    limit = ceiling
    if top == hi:
        t = q(hi)

        def limit(om):
            return min(ceiling(om), law.transition_torque)

        if t <= limit(hi):
            return hi, t, beta, "2.5"
    om = brentq(lambda w: q(w) - limit(w), top, max(float(model.rated_rotor_speed), hi) * 1.5, xtol=TRIM_TOL,
                rtol=TRIM_TOL)
    return float(om), limit(float(om)), beta, "2.5s"


def close_torque_loop(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, law: TorqueLaw, omega: float,
                      region: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list]:
    """Close the torque law around the plant's linearisation (the ``gen_torque`` input stays, added to the law's torque).

    The law's dT/dΩ enters A through the torque column b_T of B: region 2, T = K·Ω², gives
    A + b_T·2KΩ·e₀ᵀ (modes 3 and 4 as the curve they track in steady state); regions 1.5 and
    2.5, the PI on a constant reference, add its integral z as a state: δT = −k_p·δΩ + z,
    ż = −k_i·δΩ; region 2.5s (PI saturated) leaves the torque constant, and so does region 3
    unless the law holds constant power (``const_power``): T = P/(η·Ω) gives
    A − b_T·P/(η·Ω²)·e₀ᵀ. The speed
    filter (corner 1 rad/s, well above the torque loop's 0.1-0.2 rad/s), the torque rate limit
    and setpoint smoothing (inactive in steady state below rated) are left out.

    Parameters
    ----------
    A, B, C, D : numpy.ndarray
        The plant's Jacobians, inputs (wind, pitch_cmd, gen_torque), state 0 the rotor speed.
    law : TorqueLaw
        The torque law.
    omega : float
        Trim rotor speed (rad/s).
    region : str
        The trim's region (:data:`TORQUE_REGIONS`).

    Returns
    -------
    A, B, C, D : numpy.ndarray
        The closed loop, same inputs and outputs.
    extra_states : list of str
        Names of added states (``["torque_pi"]``, N·m, or none).
    """
    n = A.shape[0]
    e0 = np.zeros((1, n))
    e0[0, 0] = 1.0
    bt, dtq = B[:, 2:3], D[:, 2:3]
    if region == "2":
        s = 2.0 * law.k_opt * omega
        return A + s * bt @ e0, B, C + s * dtq @ e0, D, []
    if region == "3" and law.const_power:
        s = -law.rated_power / (law.generator_efficiency * omega**2)
        return A + s * bt @ e0, B, C + s * dtq @ e0, D, []
    if region in ("1.5", "2.5"):
        Aa = np.block([[A - law.kp * bt @ e0, bt], [-law.ki * e0, np.zeros((1, 1))]])
        Ba = np.vstack([B, np.zeros((1, B.shape[1]))])
        Ca = np.hstack([C - law.kp * dtq @ e0, dtq])
        return Aa, Ba, Ca, D, ["torque_pi"]
    return A, B, C, D, []


# ----------------------------------------------------------------------------- compiled step
@njit(cache=True)
def rosco_lpf1(st: np.ndarray, iy: int, iu: int, u: float, corner: float, dt: float, first: bool) -> float:
    """One step of ROSCO's first-order low-pass ``LPFilter`` (``Filters.f90``: Tustin of ω_c/(s + ω_c)).

    Parameters
    ----------
    st : numpy.ndarray
        State array holding the filter's last output at ``iy`` and last input at ``iu``, updated.
    iy, iu : int
        Their indices.
    u : float
        Input.
    corner : float
        Corner ω_c (rad/s).
    dt : float
        Step (s).
    first : bool
        Reset to the input first, as ROSCO does on its first call (set ``st[iy]`` and ``st[iu]``
        and pass False to reset to another value).

    Returns
    -------
    float
        Output.
    """
    if first:
        st[iy] = u
        st[iu] = u
    a1 = 2.0 + corner * dt
    a0 = corner * dt - 2.0
    b = corner * dt
    y = (-a0 * st[iy] + b * u + b * st[iu]) / a1
    st[iy] = y
    st[iu] = u
    return y


@njit(cache=True)
def rosco_lpf2(st: np.ndarray, iy: int, iy2: int, iu1: int, iu2: int, u: float, corner: float, damp: float,
               dt: float, reset: bool) -> float:
    """One step of ROSCO's second-order low-pass ``SecLPFilter`` (``Filters.f90``: Tustin of
    ω_c²/(s² + 2ζω_c·s + ω_c²)).

    Parameters
    ----------
    st : numpy.ndarray
        State array holding the last two outputs at ``iy``, ``iy2`` and inputs at ``iu1``, ``iu2``, updated.
    iy, iy2, iu1, iu2 : int
        Their indices.
    u : float
        Input.
    corner : float
        ω_c (rad/s).
    damp : float
        ζ (-).
    dt : float
        Step (s).
    reset : bool
        Start the filter at its input (ROSCO's first call).

    Returns
    -------
    float
        The filtered value.
    """
    if reset:
        st[iy] = u
        st[iy2] = u
        st[iu1] = u
        st[iu2] = u
    h2 = dt * dt * corner * corner
    a2 = h2 + 4.0 + 4.0 * damp * corner * dt
    y = (h2 * u + 2.0 * h2 * st[iu1] + h2 * st[iu2] - (2.0 * h2 - 8.0) * st[iy]
         - (h2 + 4.0 - 4.0 * damp * corner * dt) * st[iy2]) / a2
    st[iu2] = st[iu1]
    st[iu1] = u
    st[iy2] = st[iy]
    st[iy] = y
    return y


@njit(cache=True)
def _pi(err, kp, ki, lo, hi, dt, i0, st, idx, first):
    # ROSCO's PIController: forward-Euler integral saturated at the output limits
    if first:
        st[idx] = i0
        return i0
    st[idx] = min(max(st[idx] + dt * ki * err, lo), hi)
    return min(max(kp * err + st[idx], lo), hi)


@njit(cache=True)
def torque_step(tq: np.ndarray, st: np.ndarray, omega: float, power: float, pitch: float, dt: float,
                first: bool, pitch_min: float = math.nan, reference: float = math.nan) -> tuple[float, float]:
    """One step of ROSCO's torque controller (compiled; :mod:`specdesign.controller.torque`).

    Parameters
    ----------
    tq : numpy.ndarray
        :meth:`TorqueLaw.params`.
    st : numpy.ndarray
        (:data:`TORQUE_STATES`,) controller state, updated; before the first call its
        torque entry holds the measured torque (N·m) and the rest is ignored.
    omega : float
        Measured rotor speed (rad/s).
    power : float
        Measured electrical power (W).
    pitch : float
        Measured pitch (rad).
    dt : float
        Step (s).
    first : bool
        The first call (filters and integrators start at their inputs, as ROSCO's do).
    pitch_min : float, optional
        The pitch controller's lower limit of the previous step (rad), ROSCO's ``PC_MinPit``:
        NaN (default) for the law's ``fine_pitch`` (``tq[T_PITCH_MIN]``), or the peak-shaving limit
        (:func:`specdesign.controller.peak_shaving.peak_shaving_step`). Region 3 starts
        ``PC_Switch`` above it, and the setpoint smoother measures the pitch from it.
    reference : float, optional
        Modes 3 and 4: the tracking reference (rad/s) to use instead of theirs, ROSCO's
        ``VS_ControlMode = 2`` reference TSR·WE_Vw/R on a wind estimate
        (:func:`specdesign.controller.peak_shaving.tsr_reference`); NaN (default): their own.

    Returns
    -------
    torque : float
        Generator torque command (N·m, ≥ 0).
    pitch_reference : float
        The pitch controller's speed reference after setpoint smoothing (rad/s).
    """
    mode = int(tq[T_MODE])
    c = tq[T_FILT_CORNER]
    if math.isnan(pitch_min):
        pitch_min = tq[T_PITCH_MIN]
    if first:
        st[S_WF] = omega
        st[S_WF2] = omega
        st[S_U1] = omega
        st[S_U2] = omega
        st[S_SSF] = 0.0
        st[S_PLAST] = power
    if tq[T_FILT_TYPE] == 1.0:
        wf = rosco_lpf1(st, S_WF, S_U1, omega, c, dt, False)
    else:
        wf = rosco_lpf2(st, S_WF, S_WF2, S_U1, S_U2, omega, c, tq[T_FILT_DAMP], dt, False)
    # setpoints, with the smoother's shift of the previous step (ComputeVariablesSetpoints)
    ssf = st[S_SSF]
    pc_ref = tq[T_PC_REF] - ssf if ssf < 0.0 else tq[T_PC_REF]
    k = tq[T_K]
    if mode == 3:
        ref = (max(power, 0.0) / tq[T_GEN_EFF] / k) ** (1.0 / 3.0)
    elif mode == 4:
        ref = math.sqrt(max(st[S_TQ], 0.0) / k)
    else:
        ref = tq[T_VS_REF]
    if mode != 1 and not math.isnan(reference):
        ref = reference
    if tq[T_REF_CORNER] > 0.0:
        ref = rosco_lpf1(st, S_REF, S_REF_U, ref, tq[T_REF_CORNER], dt, first)
    vs_ref = min(max(ref, tq[T_MIN_SPEED]), tq[T_VS_REF])
    if ssf > 0.0:
        vs_ref -= ssf
    vs_ref = max(vs_ref, tq[T_MIN_SPEED])
    err = vs_ref - wf
    err_br = tq[T_MIN_SPEED] - wf
    min_om = k * tq[T_MIN_SPEED] ** 2
    max_om = k * tq[T_VS_REF] ** 2
    # state machine, on the previous step's PI outputs (StateMachine)
    rgn3 = pitch_min + tq[T_PC_SWITCH]
    if first:
        state = 4 if pitch >= rgn3 else 2
    elif pitch >= rgn3:
        state = 4
    elif st[S_AR] >= max_om * 1.01:
        state = 3
    elif wf < tq[T_VS_REF] and st[S_BR] >= min_om:
        state = 2
    elif st[S_BR] < min_om:
        state = 1
    else:
        state = 0
    st[S_STATE] = state
    # setpoint smoother (SetpointSmoother), on the measured pitch and the last step's power
    if tq[T_SS_MODE] != 0.0:
        d = ((pitch - pitch_min) / 0.524 * tq[T_SS_VS]
             - (tq[T_RATED_POWER] - st[S_PLAST]) / tq[T_RATED_POWER] * tq[T_SS_PC]) * tq[T_PC_REF]
        st[S_SSF] = rosco_lpf1(st, S_SSF, S_SS_U, d, tq[T_SS_CORNER], dt, first)
    last = st[S_TQ]
    # VS_ConstPower: the rated power on the filtered speed above rated, and as every mode's ceiling
    const_power = tq[T_CONST_POWER] != 0.0
    power_torque = tq[T_RATED_POWER] / tq[T_GEN_EFF] / wf
    ceiling = min(power_torque, tq[T_MAX_TQ]) if const_power else tq[T_RATED_TQ]
    if mode == 1:
        ar = _pi(err, tq[T_KP], tq[T_KI], max_om, tq[T_AR_SAT], dt, max_om, st, S_IAR, first)
        br = _pi(err_br, tq[T_KP], tq[T_KI], tq[T_MIN_TQ], min_om, dt, min_om, st, S_IBR, first)
        st[S_AR] = ar
        st[S_BR] = br
        if state == 1:
            t = br
        elif state == 2:
            t = k * wf * wf
        elif state == 3:
            t = ar
        elif state == 4:
            t = power_torque if const_power else tq[T_RATED_TQ]
        else:  # ROSCO's error state leaves the torque as it was
            t = last
    else:
        t = _pi(err, tq[T_KP], tq[T_KI], tq[T_MIN_TQ], ceiling, dt, last, st, S_IAR, first)
    t = min(max(t, tq[T_MIN_TQ]), min(tq[T_MAX_TQ], ceiling))
    if not first:
        r = tq[T_MAX_RATE] * dt
        t = min(max(t, last - r), last + r)
    st[S_TQ] = t
    st[S_PLAST] = power
    return max(t, 0.0), pc_ref
