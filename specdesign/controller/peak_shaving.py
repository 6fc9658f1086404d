"""ROSCO's peak shaving: :class:`PeakShaving`, read from a DISCON.IN, and its compiled step.

With ``PS_Mode = 1`` ROSCO (``PitchControl`` of ``Controllers.f90``, ``PitchSaturation`` of
``ControllerBlocks.f90``, ROSCO 2.10) lifts the pitch controller's lower limit every step to

    PC_MinPit = max(interp(PS_WindSpeeds, PS_BldPitchMin, WE_Vw_F), PC_FinePit),

WE_Vw_F its wind-speed estimate low-passed at ``F_WECornerFreq`` (first order, Tustin,
``PreFilterMeasuredSignals`` of ``Filters.f90``: the previous step's estimate). The PI's
integrator is clamped at the previous step's limit, its command at the new one; the torque
controller's setpoint smoother and state machine read the same limit (``SetpointSmoother``,
``ComputeVariablesSetpoints``), which :func:`specdesign.controller.torque.torque_step` takes.

The estimate is ROSCO's own, ported: the extended Kalman filter of ``WindSpeedEstimator``
(``WE_Mode = 2``) on the rotor speed low-passed as the generator speed (``F_LPFType``,
``F_LPFCornerFreq``, ``F_LPFDamping``), the measured pitch and the last torque command
low-passed at ``F_LPFCornerFreq`` (second order, ζ = 0.7): three states (rotor speed,
turbulent and mean wind), ROSCO's process and measurement noise, its first-order poles
``WE_FOPoles`` at the estimated wind and ROSCO's bilinear lookup of Cp(β, λ). The one
approximation: the Cp surface is the turbine model's table (for a deck read by
:func:`specdesign.turbine.from_openfast` that is the DISCON's ``PerfFileName``; for
:func:`specdesign.turbine.iea15mw` the shipped table of the same name), ROSCO reading the same
file. The hub-height wind ROSCO falls back on when an input leaves the estimator's range
(pitch below ``PC_MinPit`` or past the table, torque or speed near zero) is the run's wind at
t = 0, as the workbench's harness of the compiled library gives it (:class:`specdesign.rosco.Discon`).

A file in ``VS_ControlMode = 2`` tracks the tip-speed ratio ``VS_TSRopt`` on the same estimate;
:func:`tsr_reference` gives that reference, TSR·WE_Vw/R, which the simulator hands to the
torque law (run as mode 3, the same PI) in place of mode 3's power-based one.

Quantities on the rotor (low-speed) shaft, SI: a DISCON.IN's generator-side speed and torque
are converted by ``WE_GearboxRatio``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from .discon_file import read_discon
from .torque import rosco_lpf1, rosco_lpf2

__all__ = ["WE_MODES", "PeakShaving", "peak_shaving_from_discon", "peak_shaving_step", "tsr_reference",
           "PEAK_SHAVING_STATES"]

#: ROSCO wind-speed estimators :class:`PeakShaving` runs (``WE_Mode``): 2, the extended Kalman filter.
WE_MODES = (2,)

# Header of the flat parameter array of peak_shaving_step (PeakShaving.params()); the tables follow:
# PS wind speeds and minimum pitches (n_ps each), the estimator's pole table (n_fo speeds, n_fo
# poles), the Cp grid (n_tsr tip-speed ratios, n_pitch pitches in rad) and Cp (n_tsr × n_pitch, C order).
(H_N_PS, H_N_FO, H_N_TSR, H_N_PITCH, H_WE_CORNER, H_FINE_PITCH, H_MIN_PITCH, H_RADIUS, H_INERTIA, H_RHO,
 H_MIN_SPEED, H_RATED_TQ, H_FILT_TYPE, H_FILT_CORNER, H_FILT_DAMP, H_TSR) = range(16)
_HEADER = 16
# Layout of the state array of peak_shaving_step.
(S_WF, S_WF2, S_WU1, S_WU2, S_TF, S_TF2, S_TU1, S_TU2, S_VF, S_VU, S_HF, S_HU, S_VW, S_OM, S_VT, S_VM, S_VH,
 S_X0, S_X1, S_X2, S_K0, S_K1, S_K2, S_OP) = range(24)
S_P = 24  # the 3×3 covariance, C order
#: Length of the state array of :func:`peak_shaving_step`.
PEAK_SHAVING_STATES = S_P + 9


@dataclass(frozen=True)
class PeakShaving:
    """ROSCO's peak shaving with its extended-Kalman-filter wind estimate (see :mod:`specdesign.controller.peak_shaving`).

    Parameters
    ----------
    wind_speeds : array_like
        ``PS_WindSpeeds`` (m/s), strictly increasing.
    min_pitch : array_like
        ``PS_BldPitchMin`` (rad), one per wind speed.
    we_corner : float
        ``F_WECornerFreq`` (rad/s), the low-pass on the estimate.
    fine_pitch : float
        ``PC_FinePit`` (rad): the limit never drops below it.
    pitch_min : float
        ``PC_MinPit`` (rad): below it the estimator's pitch input is out of range.
    rotor_radius : float
        ``WE_BladeRadius`` (m).
    inertia : float
        ``WE_Jtot`` (kg·m²), the drivetrain on the rotor shaft.
    air_density : float
        ``WE_RhoAir`` (kg/m³).
    min_speed : float
        ``VS_MinOMSpd`` / ``WE_GearboxRatio`` (rad/s): the estimator's speed input is held above a quarter of it.
    rated_torque : float
        ``VS_RtTq`` × ``WE_GearboxRatio`` (N·m): its torque input is held above 10⁻⁴ of it.
    pole_speeds, poles : array_like
        ``WE_FOPoles_v`` (m/s) and ``WE_FOPoles`` (1/s), the rotor's first-order pole vs wind speed.
    tsr_grid : array_like
        (n_tsr,) tip-speed ratios of the Cp table (-), strictly increasing.
    pitch_grid : array_like
        (n_pitch,) pitches of the Cp table (rad), strictly increasing.
    cp_table : array_like
        (n_tsr, n_pitch) power coefficients (-).
    filter_type : int, optional
        ``F_LPFType`` of the rotor-speed low-pass: 1 first order, 2 second order.
    filter_corner : float, optional
        ``F_LPFCornerFreq`` (rad/s), also the corner of the torque's second-order low-pass.
    filter_damping : float, optional
        ``F_LPFDamping`` (-), second-order speed filter only.
    tsr : float, optional
        ``VS_TSRopt`` (-) of a file in ``VS_ControlMode = 2``, or 0 (default): ROSCO's torque
        controller then tracks the speed TSR·WE_Vw/R on this estimate, and the simulator hands
        it to the torque law (mode 3 in the workbench) as its reference (:func:`tsr_reference`).
    name : str, optional
        Label (the file it was read from).
    """

    wind_speeds: np.ndarray = field(repr=False)
    min_pitch: np.ndarray = field(repr=False)
    we_corner: float
    fine_pitch: float
    pitch_min: float
    rotor_radius: float
    inertia: float
    air_density: float
    min_speed: float
    rated_torque: float
    pole_speeds: np.ndarray = field(repr=False)
    poles: np.ndarray = field(repr=False)
    tsr_grid: np.ndarray = field(repr=False)
    pitch_grid: np.ndarray = field(repr=False)
    cp_table: np.ndarray = field(repr=False)
    filter_type: int = 2
    filter_corner: float = 1.0081
    filter_damping: float = 0.7
    tsr: float = 0.0
    name: str = "ROSCO peak shaving"

    def __post_init__(self):
        for k, pair in (("wind_speeds", "min_pitch"), ("pole_speeds", "poles")):
            x = np.atleast_1d(np.asarray(getattr(self, k), dtype=float))
            y = np.atleast_1d(np.asarray(getattr(self, pair), dtype=float))
            if x.ndim != 1 or x.size < 1 or x.shape != y.shape or np.any(np.diff(x) <= 0) \
                    or not np.all(np.isfinite(x)) or not np.all(np.isfinite(y)):
                raise ValueError(f"{k} must be strictly increasing and finite (m/s), with {pair} of the same length; "
                                 f"got {x.size} and {y.size} values")
            object.__setattr__(self, k, x)
            object.__setattr__(self, pair, y)
        tsr = np.asarray(self.tsr_grid, dtype=float)
        pitch = np.asarray(self.pitch_grid, dtype=float)
        cp = np.asarray(self.cp_table, dtype=float)
        for k, g in (("tsr_grid", tsr), ("pitch_grid", pitch)):
            if g.ndim != 1 or g.size < 2 or np.any(np.diff(g) <= 0):
                raise ValueError(f"{k} must be a strictly increasing 1-D grid of at least 2 points")
        if cp.shape != (tsr.size, pitch.size) or not np.all(np.isfinite(cp)):
            raise ValueError(f"cp_table must be finite with shape (n_tsr, n_pitch) = ({tsr.size}, {pitch.size}), "
                             f"got {cp.shape}")
        object.__setattr__(self, "tsr_grid", tsr)
        object.__setattr__(self, "pitch_grid", pitch)
        object.__setattr__(self, "cp_table", cp)
        for k in ("we_corner", "rotor_radius", "inertia", "air_density", "min_speed", "rated_torque", "filter_corner"):
            if not (math.isfinite(getattr(self, k)) and getattr(self, k) > 0):
                raise ValueError(f"{k}={getattr(self, k)!r} must be a positive finite number (SI, rotor shaft)")
        if self.filter_type not in (1, 2):
            raise ValueError(f"filter_type={self.filter_type!r} must be 1 or 2 (ROSCO F_LPFType)")
        if not (math.isfinite(self.tsr) and self.tsr >= 0):
            raise ValueError(f"tsr={self.tsr!r} must be a finite tip-speed ratio >= 0 (0: no TSR tracking)")

    def limit(self, wind_speed: ArrayLike) -> np.ndarray:
        """The pitch controller's lower limit at a filtered wind estimate, max(PS_BldPitchMin(v), PC_FinePit) (rad).

        Parameters
        ----------
        wind_speed : array_like
            Estimated wind speed (m/s); held at the table's ends as ROSCO's ``interp1d``.

        Returns
        -------
        numpy.ndarray
            The minimum pitch (rad).
        """
        return np.maximum(np.interp(wind_speed, self.wind_speeds, self.min_pitch), self.fine_pitch)

    def params(self) -> np.ndarray:
        """Flat float64 parameter array of :func:`peak_shaving_step` (a header, then the tables).

        Returns
        -------
        numpy.ndarray
            The parameters (SI, rotor shaft).
        """
        head = np.zeros(_HEADER)
        head[[H_N_PS, H_N_FO, H_N_TSR, H_N_PITCH, H_WE_CORNER, H_FINE_PITCH, H_MIN_PITCH, H_RADIUS, H_INERTIA, H_RHO,
              H_MIN_SPEED, H_RATED_TQ, H_FILT_TYPE, H_FILT_CORNER, H_FILT_DAMP, H_TSR]] = [
            self.wind_speeds.size, self.poles.size, self.tsr_grid.size, self.pitch_grid.size, self.we_corner,
            self.fine_pitch, self.pitch_min, self.rotor_radius, self.inertia, self.air_density, self.min_speed,
            self.rated_torque, self.filter_type, self.filter_corner, self.filter_damping, self.tsr]
        return np.concatenate([head, self.wind_speeds, self.min_pitch, self.pole_speeds, self.poles, self.tsr_grid,
                               self.pitch_grid, self.cp_table.ravel()])


def peak_shaving_from_discon(path: str | Path, tsr_grid: ArrayLike, pitch_grid: ArrayLike,
                             cp_table: ArrayLike) -> PeakShaving | None:
    """ROSCO's peak shaving as a DISCON.IN sets it, or None where the file has ``PS_Mode = 0``.

    Parameters
    ----------
    path : str or pathlib.Path
        The DISCON.IN file.
    tsr_grid : array_like
        (n_tsr,) tip-speed ratios of the turbine's Cp table (-).
    pitch_grid : array_like
        (n_pitch,) its pitches (rad).
    cp_table : array_like
        (n_tsr, n_pitch) its power coefficients (-): the surface ROSCO's estimator reads
        from ``PerfFileName`` (the model's own, e.g. ``model.cp_table``).

    Returns
    -------
    PeakShaving or None
        The peak shaving (rotor shaft, SI), or None without it.

    Raises
    ------
    ValueError
        Naming the file, line and key: a missing or non-numeric entry, ``PS_Mode`` not 0 or 1,
        or ``WE_Mode`` not in :data:`WE_MODES` (0 reads a measured hub-height wind and 1 the
        immersion-and-invariance estimator, neither of which is modelled: set ``PS_Mode = 0``
        to run without peak shaving, or ``WE_Mode = 2``).

    Examples
    --------
    >>> from specdesign.rosco import iea15mw_discon
    >>> from specdesign.turbine import iea15mw
    >>> m = iea15mw()
    >>> ps = peak_shaving_from_discon(iea15mw_discon(), m.tsr_grid, m.pitch_grid, m.cp_table)
    >>> round(float(ps.limit(20.0)[()]), 4) > 0
    True
    """
    entries, _ = read_discon(path)
    p = str(path)

    def numbers(name):
        e = entries.get(name)
        if e is None:
            raise ValueError(f"{p}: key {name!r} is missing (a DISCON.IN written by ROSCO's toolbox has it)")
        try:
            vals = np.array([float(v) for v in e.values])
        except ValueError:
            raise ValueError(f"{p}: line {e.line}: {name} = {' '.join(e.values)!r} is not numeric") from None
        if not np.all(np.isfinite(vals)):
            raise ValueError(f"{p}: line {e.line}: {name} has a non-finite value")
        return vals

    def one(name):
        return float(numbers(name)[0])

    if "PS_Mode" not in entries:
        return None
    mode = one("PS_Mode")
    if mode == 0:
        return None
    if mode != 1:
        raise ValueError(f"{p}: line {entries['PS_Mode'].line}: PS_Mode = {mode:g} must be 0 (no peak shaving) or 1")
    we = int(one("WE_Mode"))
    if we not in WE_MODES:
        raise ValueError(f"{p}: line {entries['WE_Mode'].line}: WE_Mode = {we} with PS_Mode = 1: peak shaving reads "
                         "ROSCO's wind-speed estimate, and the workbench runs only its extended Kalman filter "
                         f"(WE_Mode in {WE_MODES}); set WE_Mode = 2, or PS_Mode = 0 to run without peak shaving "
                         "(write_discon(path, out, PS_Mode=0))")
    n = one("WE_GearboxRatio")
    if not n > 0:
        raise ValueError(f"{p}: line {entries['WE_GearboxRatio'].line}: WE_GearboxRatio must be positive")
    try:
        return PeakShaving(
            wind_speeds=numbers("PS_WindSpeeds"), min_pitch=numbers("PS_BldPitchMin"),
            we_corner=one("F_WECornerFreq"), fine_pitch=one("PC_FinePit"), pitch_min=one("PC_MinPit"),
            rotor_radius=one("WE_BladeRadius"), inertia=one("WE_Jtot"), air_density=one("WE_RhoAir"),
            min_speed=one("VS_MinOMSpd") / n, rated_torque=one("VS_RtTq") * n, pole_speeds=numbers("WE_FOPoles_v"),
            poles=numbers("WE_FOPoles"), tsr_grid=tsr_grid, pitch_grid=pitch_grid, cp_table=cp_table,
            filter_type=int(one("F_LPFType")), filter_corner=one("F_LPFCornerFreq"),
            filter_damping=one("F_LPFDamping"), name=f"ROSCO peak shaving ({Path(p).name})",
            tsr=one("VS_TSRopt") if int(one("VS_ControlMode")) == 2 else 0.0)
    except ValueError as err:
        raise ValueError(f"{p}: peak shaving (PS_Mode = 1): {err}") from None


# ----------------------------------------------------------------------------- compiled step
@njit(cache=True)
def _interp1(ps, ix, iy, n, x):
    # ROSCO's interp1d: linear, held at the ends
    if x <= ps[ix]:
        return ps[iy]
    if x >= ps[ix + n - 1]:
        return ps[iy + n - 1]
    i = 1
    while x > ps[ix + i]:
        i += 1
    x0, x1 = ps[ix + i - 1], ps[ix + i]
    return ps[iy + i - 1] + (ps[iy + i] - ps[iy + i - 1]) / (x1 - x0) * (x - x0)


@njit(cache=True)
def _cp(ps, it, ip, ic, nt, npt, tsr, pitch):
    # ROSCO's interp2d of Cp(β, λ): bilinear, each coordinate held at the table's ends
    pc = min(max(pitch, ps[ip]), ps[ip + npt - 1])
    lc = min(max(tsr, ps[it]), ps[it + nt - 1])
    j = 0
    while j < npt - 2 and pc > ps[ip + j + 1]:
        j += 1
    i = 0
    while i < nt - 2 and lc > ps[it + i + 1]:
        i += 1
    fx = (pc - ps[ip + j]) / (ps[ip + j + 1] - ps[ip + j])
    fy = (lc - ps[it + i]) / (ps[it + i + 1] - ps[it + i])
    r0 = (1.0 - fx) * ps[ic + i * npt + j] + fx * ps[ic + i * npt + j + 1]
    r1 = (1.0 - fx) * ps[ic + (i + 1) * npt + j] + fx * ps[ic + (i + 1) * npt + j + 1]
    return (1.0 - fy) * r0 + fy * r1


_EPS = 2.220446049250313e-16  # Fortran's EPSILON(1.0_DbKi)


@njit(cache=True)
def peak_shaving_step(ps: np.ndarray, st: np.ndarray, omega: float, pitch: float, torque: float, hub_wind: float,
                      dt: float, first: bool) -> float:
    """One step of ROSCO's wind-speed estimator and peak shaving (compiled; :mod:`specdesign.controller.peak_shaving`).

    Parameters
    ----------
    ps : numpy.ndarray
        :meth:`PeakShaving.params`.
    st : numpy.ndarray
        (:data:`PEAK_SHAVING_STATES`,) state, updated; ignored before the first call.
    omega : float
        Measured rotor speed (rad/s).
    pitch : float
        Measured pitch (rad).
    torque : float
        The last generator-torque command (N·m, rotor shaft).
    hub_wind : float
        The hub-height wind ROSCO is given (m/s): its estimator's start and fall-back.
    dt : float
        Step (s).
    first : bool
        The first call.

    Returns
    -------
    float
        The pitch controller's lower limit this step, max(PS_BldPitchMin(WE_Vw_F), PC_FinePit) (rad).
    """
    n_ps, n_fo, nt, npt = int(ps[H_N_PS]), int(ps[H_N_FO]), int(ps[H_N_TSR]), int(ps[H_N_PITCH])
    i_ws = _HEADER
    i_pm = i_ws + n_ps
    i_fv = i_pm + n_ps
    i_fa = i_fv + n_fo
    i_t = i_fa + n_fo
    i_p = i_t + nt
    i_c = i_p + npt
    c, R, J = ps[H_FILT_CORNER], ps[H_RADIUS], ps[H_INERTIA]
    if first:
        st[S_VW] = hub_wind  # ROSCO's WE_Vw starts at the hub-height wind
        st[S_OP] = 1.0
    # PreFilterMeasuredSignals: the rotor speed as the generator speed, the last torque, the last estimate
    if ps[H_FILT_TYPE] == 1.0:
        wf = rosco_lpf1(st, S_WF, S_WU1, omega, c, dt, first)
    else:
        wf = rosco_lpf2(st, S_WF, S_WF2, S_WU1, S_WU2, omega, c, ps[H_FILT_DAMP], dt, first)
    tf = rosco_lpf2(st, S_TF, S_TF2, S_TU1, S_TU2, torque, c, 0.7, dt, first)
    vw_f = rosco_lpf1(st, S_VF, S_VU, st[S_VW], ps[H_WE_CORNER], dt, first)
    # WindSpeedEstimator: inputs held in the estimator's range, which it leaves when one is held
    lo_speed = 0.25 * ps[H_MIN_SPEED]
    w_in = lo_speed + _EPS if wf < lo_speed else wf
    b_in = min(max(pitch, ps[H_MIN_PITCH]), ps[i_p + npt - 1])
    t_floor = 1e-4 * ps[H_RATED_TQ]
    t_in = max(tf, t_floor)
    op_last = st[S_OP]
    op = 0.0 if (b_in != pitch or t_in != tf or w_in != wf) else 1.0
    st[S_OP] = op
    restart = first or (op == 0.0 and op_last == 1.0) or (op == 1.0 and op_last == 0.0)
    if restart:  # ROSCO restarts the hub-height wind's filter at the estimate
        st[S_HF] = st[S_VW]
        st[S_HU] = st[S_VW]
    hw_f = rosco_lpf1(st, S_HF, S_HU, hub_wind, ps[H_WE_CORNER] / 10.0, dt, False)
    if op == 0.0:
        st[S_VW] = hw_f
    elif restart:
        st[S_OM] = w_in
        st[S_VT] = 0.0
        st[S_VM] = max(hw_f, 3.0)
        st[S_VH] = st[S_VM]
        st[S_VW] = st[S_VM]
        st[S_X0], st[S_X1], st[S_X2] = w_in, 0.0, st[S_VM]
        for i in range(9):
            st[S_P + i] = 0.0
        st[S_P], st[S_P + 4], st[S_P + 8] = 0.01, 0.01, 1.0
        st[S_K0], st[S_K1], st[S_K2] = 0.0, 0.0, 0.0
    else:
        L = 6.0 * R
        ti = 0.18
        r_m = 0.02
        vh, vm, vt, om = st[S_VH], st[S_VM], st[S_VT], st[S_OM]
        a_op = _interp1(ps, i_fv, i_fa, n_fo, vh)
        cp_op = max(0.0, _cp(ps, i_t, i_p, i_c, nt, npt, max(w_in, _EPS) * R / vh, b_in))
        # ROSCO's Jacobian F (rows: rotor speed, turbulent wind, mean wind) and process noise Q
        f12 = 1.0 / (2.0 * J) * ps[H_RHO] * math.pi * R * R * (1.0 / om) * 3.0 * cp_op * vh * vh
        f11 = -math.pi * vm / (2.0 * L)
        f21 = -math.pi * vt / (2.0 * L)
        q0, q1, q2 = 0.00001, math.pi * vm ** 3 * ti * ti / L, 4.0 / 600.0
        # AeroDynTorque at the last estimate
        vw = max(st[S_VW], _EPS)
        cp_t = _cp(ps, i_t, i_p, i_c, nt, npt, w_in * R / vw, b_in)
        tau = max(0.5 * ps[H_RHO] * math.pi * R * R * (st[S_VW] ** 3 / w_in) * cp_t, 0.0)
        a = math.pi * vm / (2.0 * L)
        st[S_X0] += dt * (1.0 / J * (tau - t_in))
        st[S_X1] += dt * (-a * vt)
        # P += dt·(F·P + P·Fᵀ + Q − K·R·Kᵀ), written out (F's last row is zero): no array per step
        k0, k1, k2 = st[S_K0], st[S_K1], st[S_K2]
        p00, p01, p02 = st[S_P], st[S_P + 1], st[S_P + 2]
        p10, p11, p12 = st[S_P + 3], st[S_P + 4], st[S_P + 5]
        p20, p21, p22 = st[S_P + 6], st[S_P + 7], st[S_P + 8]
        st[S_P] = p00 + dt * (((a_op * p00 + f12 * p10 + f12 * p20) + (p00 * a_op + p01 * f12 + p02 * f12) + q0)
                              - k0 * r_m * k0)
        st[S_P + 1] = p01 + dt * (((a_op * p01 + f12 * p11 + f12 * p21) + (p01 * f11 + p02 * f21)) - k0 * r_m * k1)
        st[S_P + 2] = p02 + dt * ((a_op * p02 + f12 * p12 + f12 * p22) - k0 * r_m * k2)
        st[S_P + 3] = p10 + dt * (((f11 * p10 + f21 * p20) + (p10 * a_op + p11 * f12 + p12 * f12)) - k1 * r_m * k0)
        st[S_P + 4] = p11 + dt * (((f11 * p11 + f21 * p21) + (p11 * f11 + p12 * f21) + q1) - k1 * r_m * k1)
        st[S_P + 5] = p12 + dt * ((f11 * p12 + f21 * p22) - k1 * r_m * k2)
        st[S_P + 6] = p20 + dt * ((p20 * a_op + p21 * f12 + p22 * f12) - k2 * r_m * k0)
        st[S_P + 7] = p21 + dt * ((p21 * f11 + p22 * f21) - k2 * r_m * k1)
        st[S_P + 8] = p22 + dt * (q2 - k2 * r_m * k2)
        # measurement update on the rotor speed: K = P·Hᵀ/(H·P·Hᵀ + R), x += K·(ω − ω̂), P = (I − K·H)·P
        s = st[S_P] + r_m
        k0, k1, k2 = st[S_P] / s, st[S_P + 3] / s, st[S_P + 6] / s
        innov = w_in - om
        st[S_X0] += k0 * innov
        st[S_X1] += k1 * innov
        st[S_X2] += k2 * innov
        h = (st[S_P], st[S_P + 1], st[S_P + 2])  # H·P, the first row
        for j in range(3):
            st[S_P + j] -= k0 * h[j]
            st[S_P + 3 + j] -= k1 * h[j]
            st[S_P + 6 + j] -= k2 * h[j]
        st[S_K0], st[S_K1], st[S_K2] = k0, k1, k2
        st[S_OM] = max(st[S_X0], _EPS)
        st[S_VT] = st[S_X1]
        st[S_VM] = st[S_X2]
        st[S_VH] = st[S_VT] + st[S_VM]
        st[S_VW] = st[S_VM] + st[S_VT]
        if math.isnan(st[S_VH]):
            st[S_OM] = w_in
            st[S_VT] = 0.0
            st[S_VM] = hub_wind
            st[S_VH] = hub_wind
            st[S_VW] = hub_wind
    # PitchSaturation on the filtered estimate, never below fine pitch
    return max(_interp1(ps, i_ws, i_pm, n_ps, vw_f), ps[H_FINE_PITCH])


@njit(cache=True)
def tsr_reference(ps: np.ndarray, st: np.ndarray) -> float:
    """ROSCO's ``VS_ControlMode = 2`` speed reference, TSR·WE_Vw/R, on this step's estimate (compiled).

    Parameters
    ----------
    ps : numpy.ndarray
        :meth:`PeakShaving.params`.
    st : numpy.ndarray
        The state of :func:`peak_shaving_step` after this step's call.

    Returns
    -------
    float
        The reference rotor speed (rad/s), or NaN for a file in another torque mode (``tsr`` 0).
    """
    if ps[H_TSR] == 0.0:
        return math.nan
    return ps[H_TSR] * st[S_VW] / ps[H_RADIUS]
