"""ROSCO's pitch PI as the workbench reproduces it from the reduced model: gain schedule and baseline.

The NREL ROSCO controller of the IEA 15 MW, from the reduced model of :mod:`specdesign.turbine`:

- :func:`rosco_gain_schedule` (a :class:`RoscoSchedule`): ROSCO's pole placement of the pitch
  PI on the first-order rotor-speed model (:func:`first_order_rotor_model`), with the
  straight-line fits of ROSCO's tuning;
- :func:`speed_filter`: ROSCO's 2nd-order generator-speed low-pass;
- :func:`rosco_baseline`: the baseline at one wind speed as an LTI, C(s) = (Kp + Ki/s)·F(s),
  in the workbench's sign convention β = −C·Ω_g (tower damping off, as in the paper).

Its scheduled form, :func:`specdesign.rosco.rosco_scheduled`, stands on the simulator's plant
and lives in :mod:`specdesign.rosco`, which re-exports these names (ROSCO in one place).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._checks import positive_scalar
from .model import TurbineModel

if TYPE_CHECKING:  # pragma: no cover
    import control

__all__ = [
    "RoscoSchedule",
    "first_order_rotor_model",
    "rosco_gain_schedule",
    "speed_filter",
    "rosco_baseline",
]


@dataclass(frozen=True)
class RoscoSchedule:
    """ROSCO's pitch PI gain schedule computed from a :class:`~specdesign.turbine.TurbineModel`.

    Gains follow ROSCO's sign: pitch = Kp·e + Ki∫e with e = reference − filtered speed.
    Build it with :func:`rosco_gain_schedule`.

    Parameters
    ----------
    v : numpy.ndarray
        Wind speeds of the schedule (m/s), shape (n,).
    pitch_op : numpy.ndarray
        Trim pitch at each wind speed (rad).
    Kp : numpy.ndarray
        Proportional gains (s), from the straight-line fits ``A_fit``, ``B_beta_fit``.
    Ki : numpy.ndarray
        Integral gains (-).
    A : numpy.ndarray
        δΩ̇/δΩ of the first-order rotor model δΩ̇ = A δΩ + B_beta δβ + B_wind δv (1/s).
    B_beta : numpy.ndarray
        δΩ̇/δβ of that model (1/s²).
    B_wind : numpy.ndarray
        δΩ̇/δv of that model (rad/m).
    A_fit : numpy.ndarray
        Straight-line fit of ``A`` over ``v`` that ROSCO's tuning uses
        (``second_order_PI(..., linearize=True)``) (1/s).
    B_beta_fit : numpy.ndarray
        Straight-line fit of ``B_beta`` over ``v`` (1/s²).
    omega_pc : float
        Natural frequency of the placed closed-loop rotor-speed poles (rad/s).
    zeta_pc : float
        Damping ratio of those poles (-).
    """

    v: np.ndarray
    pitch_op: np.ndarray
    Kp: np.ndarray
    Ki: np.ndarray
    A: np.ndarray
    B_beta: np.ndarray
    B_wind: np.ndarray
    A_fit: np.ndarray
    B_beta_fit: np.ndarray
    omega_pc: float
    zeta_pc: float

    def gains(self, wind_speeds: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(Kp, Ki) at ``wind_speeds`` from the straight-line fits, in ROSCO's sign.

        The same pole placement as ``Kp``, ``Ki``, with A and B_β from their straight-line
        fits over ``v`` evaluated at ``wind_speeds``.

        Parameters
        ----------
        wind_speeds : float or array_like
            Wind speeds (m/s) within the schedule's range ``[min(v), max(v)]``.

        Returns
        -------
        Kp : numpy.ndarray
            Proportional gains (s), shaped as ``wind_speeds``.
        Ki : numpy.ndarray
            Integral gains (-), shaped as ``wind_speeds``.

        Raises
        ------
        ValueError
            Outside the schedule's wind speeds: the line fits are not extrapolated (ROSCO's own
            schedule ends there too).

        Examples
        --------
        >>> from specdesign.turbine import iea15mw
        >>> kp, ki = rosco_gain_schedule(iea15mw()).gains(19.0)
        >>> bool(kp < 0 and ki < 0)
        True
        """
        v = np.asarray(wind_speeds, dtype=float)
        lo, hi = float(np.min(self.v)), float(np.max(self.v))
        if not np.all(np.isfinite(v)) or np.any(v < lo - 1e-9) or np.any(v > hi + 1e-9):
            raise ValueError(f"wind_speeds={wind_speeds!r} m/s: the gain schedule covers {lo:g}-{hi:g} m/s only "
                             "(build it over a wider range with rosco_gain_schedule(model, wind_speeds=...))")
        a = np.polyval(np.polyfit(self.v, self.A, 1), v)
        b = np.polyval(np.polyfit(self.v, self.B_beta, 1), v)
        return (2 * self.zeta_pc * self.omega_pc + a) / b, self.omega_pc**2 / b


def first_order_rotor_model(model: TurbineModel, wind_speed: float) -> tuple[float, float, float, float]:
    """The first-order rotor-speed model δΩ̇ = A δΩ + B_β δβ + B_wind δv at a trim.

    From the kernel's Jacobian at the trim of ``wind_speed``: the rotor equation's row.

    Parameters
    ----------
    model : TurbineModel
        The reduced turbine model.
    wind_speed : float
        Mean wind speed (m/s), in ``model.wind_range``.

    Returns
    -------
    pitch_op : float
        Trim pitch (rad).
    A : float
        δΩ̇/δΩ (1/s).
    B_beta : float
        δΩ̇/δβ (1/s²), with respect to the pitch state.
    B_wind : float
        δΩ̇/δv (rad/m).

    Raises
    ------
    ValueError
        If ``wind_speed`` is outside the model's above-rated range.
    """
    op = model.trim(wind_speed)
    A, B, _, _ = model.jacobians(op)
    # Row 0 is δΩ̇; column 3 is the pitch state, input 0 the wind.
    return op.pitch, A[0, 0], A[0, 3], B[0, 0]


def rosco_gain_schedule(model: TurbineModel, wind_speeds: ArrayLike | None = None, *, omega_pc: float = 0.2,
                        zeta_pc: float = 1.0, constant_power: bool = False) -> RoscoSchedule:
    """ROSCO's pitch PI schedule by pole placement on the first-order rotor model.

    With e = Ω_ref − Ω and β = Kp·e + Ki∫e, the closed rotor loop is
    s² + (B_β·Kp − A)s + B_β·Ki; matching s² + 2ζ_pc ω_pc s + ω_pc² gives
    Kp = (2ζ_pc ω_pc + A)/B_β and Ki = ω_pc²/B_β, where, as in ROSCO, A and B_β are replaced
    by their straight-line fits over ``wind_speeds`` (:func:`first_order_rotor_model`).

    Parameters
    ----------
    model : TurbineModel
        The reduced turbine model.
    wind_speeds : array_like, optional
        At least 2 wind speeds (m/s). Default ROSCO's grid: 30 speeds from rated (exclusive)
        to the top of ``model.wind_range`` (25 m/s).
    omega_pc : float, optional
        Natural frequency of the desired closed-loop rotor-speed poles (rad/s).
    zeta_pc : float, optional
        Their damping ratio (-).
    constant_power : bool, optional
        Tune as ROSCO does for a torque controller that holds the power above rated
        (DISCON.IN ``VS_ConstPower = 1``): A gains ROSCO's term P_rated/(J·Ω_rated²), the
        torque falling as the speed rises. The reduced model itself holds the torque
        constant; default False (the IEA 15 MW's ROSCO, ``VS_ConstPower = 0``).

    Returns
    -------
    RoscoSchedule
        The schedule over ``wind_speeds`` (with ``constant_power``, ``A`` includes the term).

    Raises
    ------
    ValueError
        For fewer than 2 wind speeds, a non-positive ``omega_pc``/``zeta_pc``, or a wind speed
        outside the model's range.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> s = rosco_gain_schedule(iea15mw())
    >>> s.v.size
    30
    """
    omega_pc = positive_scalar(omega_pc, "omega_pc")
    zeta_pc = positive_scalar(zeta_pc, "zeta_pc")
    if wind_speeds is None:
        wind_speeds = np.linspace(model.rated_wind_speed(), model.wind_range[1], 31)[1:]
    v = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    if v.ndim != 1 or v.size < 2:
        raise ValueError(f"wind_speeds must be a 1-D array of at least 2 speeds in m/s (the gains use a line fit), got shape {v.shape}")
    rows = np.array([first_order_rotor_model(model, s) for s in v])
    pitch, A, Bb, Bw = rows.T
    if constant_power:
        A = A + model.rated_power / (model.drivetrain_inertia * model.rated_rotor_speed**2)
    A_fit = np.polyval(np.polyfit(v, A, 1), v)
    B_fit = np.polyval(np.polyfit(v, Bb, 1), v)
    return RoscoSchedule(
        v=v, pitch_op=pitch, Kp=(2 * zeta_pc * omega_pc + A_fit) / B_fit, Ki=omega_pc**2 / B_fit,
        A=A, B_beta=Bb, B_wind=Bw, A_fit=A_fit, B_beta_fit=B_fit, omega_pc=omega_pc, zeta_pc=zeta_pc,
    )


def speed_filter(corner: float = 1.0081, damping: float = 0.7) -> control.TransferFunction:
    """ROSCO's 2nd-order generator-speed low-pass F(s) = ω_f²/(s² + 2ζω_f s + ω_f²).

    Parameters
    ----------
    corner : float, optional
        Corner frequency ω_f (rad/s); default ROSCO's for the IEA 15 MW.
    damping : float, optional
        Damping ratio ζ (-).

    Returns
    -------
    control.TransferFunction
        F(s), unit gain at s = 0.

    Raises
    ------
    ValueError
        For a non-positive or non-finite ``corner`` or ``damping``.

    Examples
    --------
    >>> float(abs(speed_filter()(0.0)))
    1.0
    """
    import control

    wf = positive_scalar(corner, "corner")
    z = positive_scalar(damping, "damping")
    return control.tf([wf**2], [1.0, 2 * z * wf, wf**2])


def rosco_baseline(model: TurbineModel, wind_speed: float, *, omega_pc: float = 0.2, zeta_pc: float = 1.0,
                   schedule: RoscoSchedule | None = None) -> control.TransferFunction:
    """ROSCO's baseline pitch controller at one wind speed as C(s) = (Kp + Ki/s)·F_lpf(s).

    Sign convention of the workbench: β = −C·Ω_g (pitch in rad, generator speed in rad/s), so
    ROSCO's negative gains on e = reference − speed give C directly, and L = C·P_{Ω,β} has both
    factors negative at low frequency. Kp, Ki come from the straight-line fits of
    :func:`rosco_gain_schedule` (default grid) evaluated at ``wind_speed``; F_lpf is
    :func:`speed_filter`. Tower damping off, as in the paper's baseline.

    From cut-in to cut-out (a model with a ``torque_control``, ``model.operating_range``) it is
    ROSCO's pitch loop *linearised at the trim*: below rated (trim region other than "3") the
    PI sits at fine pitch, its output and integrator clamped at the limit, so its linearisation
    is zero, C = 0 (the pitch loop open; the torque loop is closed in the plant,
    :meth:`~specdesign.turbine.TurbineModel.linearize`). From rated to the schedule's first
    speed (ROSCO's grid starts one step above rated) the gains are the first entry's, as ROSCO's
    ``interp1d`` holds the ends of its gain table.

    Parameters
    ----------
    model : TurbineModel
        The reduced turbine model.
    wind_speed : float
        Mean wind speed (m/s), in ``model.wind_range``, or ``model.operating_range`` for a model
        with a ``torque_control``.
    omega_pc : float, optional
        Closed-loop rotor-speed pole frequency (rad/s) of the schedule (when ``schedule`` is None).
    zeta_pc : float, optional
        Their damping ratio (-) (when ``schedule`` is None).
    schedule : RoscoSchedule, optional
        A schedule to take the gains from (default: ``rosco_gain_schedule(model, ...)``).

    Returns
    -------
    control.TransferFunction
        C(s) from ``gen_speed`` (rad/s) to ``pitch_cmd`` (rad), named ``ROSCO_PI@<v>mps``
        (``ROSCO_PI@<v>mps_fine_pitch``, C = 0, below rated).

    Raises
    ------
    ValueError
        If ``wind_speed`` is outside the model's range or above the schedule's.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> rosco_baseline(iea15mw(), 19.0).name
    'ROSCO_PI@19mps'
    >>> c = rosco_baseline(iea15mw(), 8.0)  # below rated: at fine pitch, the loop open
    >>> c.name, float(c.dcgain())
    ('ROSCO_PI@8mps_fine_pitch', 0.0)
    """
    import control

    with_torque_law = getattr(model, "torque_control", None) is not None
    v = model.check_operating_speed(wind_speed) if with_torque_law else model.check_wind_speed(wind_speed)
    name = f"ROSCO_PI@{v:g}mps".replace(".", "p")
    if with_torque_law and model.trim(v).region != "3":
        return control.tf([0.0], [1.0], inputs="gen_speed", outputs="pitch_cmd", name=f"{name}_fine_pitch")
    if schedule is None:
        schedule = rosco_gain_schedule(model, omega_pc=omega_pc, zeta_pc=zeta_pc)
    v_gains = v
    if with_torque_law and hasattr(schedule, "v"):
        # above rated but below the grid's first speed: ROSCO's interp1d holds the first gains
        v_gains = max(v, float(np.min(schedule.v)))
    kp, ki = (float(g) for g in schedule.gains(v_gains))
    pi = control.tf([kp, ki], [1.0, 0.0])
    c = pi * speed_filter()
    return control.tf(c.num[0][0], c.den[0][0], inputs="gen_speed", outputs="pitch_cmd", name=name)
