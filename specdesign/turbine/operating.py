"""Results of the turbine model: a trim (:class:`OperatingPoint`) and the Taylor expansion of the
aerodynamic loads about it (:class:`AeroExpansion`), with the names of the load inputs and
of the aerodynamic variables."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["LOAD_INPUT_NAMES", "AERO_VARIABLES", "OperatingPoint", "AeroExpansion"]

#: Extra inputs of ``linearize(..., load_inputs=True)``: disturbances added to the aerodynamic
#: torque (N·m) and thrust (N).
LOAD_INPUT_NAMES = ("aero_torque", "thrust")
#: Arguments of the aerodynamic loads that :class:`AeroExpansion` expands in.
AERO_VARIABLES = ("rotor_speed", "relative_wind", "pitch")

@dataclass(frozen=True)
class OperatingPoint:
    """A steady operating point (trim) of the reduced model (:meth:`specdesign.turbine.TurbineModel.trim`).

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s).
    rotor_speed : float
        Rotor speed (rad/s).
    pitch : float
        Blade pitch (rad).
    gen_torque : float
        Generator torque (N·m).
    x : numpy.ndarray
        State vector (:data:`STATE_NAMES`, SI).
    thrust : float
        Rotor thrust (N).
    aero_power : float
        Aerodynamic (mechanical) power (W).
    power : float
        Electrical power (W).
    tsr : float
        Tip-speed ratio (-).
    cp : float
        Power coefficient (-).
    ct : float
        Thrust coefficient (-).
    region : str, optional
        Control region: "3" above rated (pitch-regulated), below rated one of
        :data:`specdesign.rosco.TORQUE_REGIONS` ("1.5", "2", "2.5", "2.5s").
    """

    wind_speed: float
    rotor_speed: float
    pitch: float
    gen_torque: float
    x: np.ndarray
    thrust: float
    aero_power: float
    power: float
    tsr: float
    cp: float
    ct: float
    region: str = "3"

    @property
    def u(self) -> np.ndarray:
        """Input vector (wind m/s, pitch_cmd rad, gen_torque N·m) at the trim."""
        return np.array([self.wind_speed, self.pitch, self.gen_torque])


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class AeroExpansion:
    """Taylor expansion of the aerodynamic loads about a trim, to third order.

    The loads (aerodynamic torque N·m, thrust N) are functions of z = (rotor speed rad/s, wind
    relative to the tower top m/s, pitch rad) (:data:`AERO_VARIABLES`); the derivatives are
    central differences of the compiled interpolant (:meth:`specdesign.turbine.TurbineModel.aero_expansion`).

    Parameters
    ----------
    wind_speed : float
        Mean wind speed of the trim (m/s).
    point : numpy.ndarray
        (3,) z at the trim (rad/s, m/s, rad).
    loads : numpy.ndarray
        (2,) the loads there (N·m, N).
    gradient : numpy.ndarray
        (2, 3) first partial derivatives in z (SI units of load per unit of each variable).
    hessian : numpy.ndarray
        (2, 3, 3) second partial derivatives.
    third : numpy.ndarray
        (2, 3, 3, 3) third partial derivatives.
    steps : numpy.ndarray
        (3,) the central-difference steps (rad/s, m/s, rad).
    """

    wind_speed: float
    point: np.ndarray
    loads: np.ndarray
    gradient: np.ndarray
    hessian: np.ndarray
    third: np.ndarray
    steps: np.ndarray

    def evaluate(self, dz: ArrayLike, order: int = 3) -> np.ndarray:
        """Load change predicted by the Taylor polynomial of ``order`` for deviations ``dz``.

        Parameters
        ----------
        dz : array_like
            (3, ...) deviations from ``point`` (rad/s, m/s, rad, ordered as :data:`AERO_VARIABLES`).
        order : int, optional
            Order of the polynomial, 1-3.

        Returns
        -------
        numpy.ndarray
            (2, ...) change of (aerodynamic torque N·m, thrust N).

        Raises
        ------
        ValueError
            For ``dz`` of the wrong shape or an order outside 1-3.
        """
        dz = np.asarray(dz, dtype=float)
        if dz.ndim < 1 or dz.shape[0] != 3:
            raise ValueError(f"dz must have shape (3, ...) ordered as {AERO_VARIABLES}, got {dz.shape}")
        if order not in (1, 2, 3):
            raise ValueError(f"order={order!r} must be 1, 2 or 3")
        out = np.einsum("ki,i...->k...", self.gradient, dz)
        if order >= 2:
            out = out + 0.5 * np.einsum("kij,i...,j...->k...", self.hessian, dz, dz)
        if order == 3:
            out = out + np.einsum("kijl,i...,j...,l...->k...", self.third, dz, dz, dz) / 6.0
        return out
