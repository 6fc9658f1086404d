"""The reduced-order turbine model: trim, linearisation, aerodynamic expansion; the IEA 15 MW.

The model: rigid-drivetrain rotor (aerodynamic torque from Cp(λ, β), thrust from Ct(λ, β)),
first tower fore-aft mode driven by thrust with the rotor seeing the relative wind U − ẋ_top,
a 2nd-order pitch actuator with rate and position limits, and a generator torque that is an
input (constant, ``rated_generator_torque``, above rated; below rated set by ROSCO's torque law,
the model's ``torque_control``, :mod:`specdesign.controller.torque`, closed in :meth:`TurbineModel.trim`
and :meth:`TurbineModel.linearize` from cut-in to cut-out). Figures come from the shipped
``specdesign/data/iea15mw`` (IEA Wind Task 37 and NREL ROSCO, Apache-2.0; see NOTICE.md).

The state, input and output vectors and the compiled kernel are those of
:mod:`specdesign.turbine.kernel`; the data and the table preparation are in
:mod:`specdesign.turbine.tables`; the model's results (:class:`OperatingPoint`,
:class:`AeroExpansion`) in :mod:`specdesign.turbine.operating`.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._checks import positive_scalar
from ..controller.torque import TRIM_TOL, close_torque_loop, steady_state, torque_law

if TYPE_CHECKING:  # pragma: no cover
    import control
from .kernel import (
    HEADER_SIZE,
    INPUT_NAMES,
    OUTPUT_NAMES,
    P_ACT_OMEGA,
    P_ACT_ZETA,
    P_DPITCH,
    P_DTSR,
    P_GEN_EFF,
    P_INERTIA,
    P_MY_PER_M,
    P_N_PITCH,
    P_N_TSR,
    P_PITCH0,
    P_PITCH_MAX,
    P_PITCH_MIN,
    P_RADIUS,
    P_RATE_LIM,
    P_RHO,
    P_TSR0,
    P_TWR_DAMP,
    P_TWR_MASS,
    P_TWR_STIFF,
    STATE_NAMES,
    aero_loads,
    bicubic,
    mechanics,
    outputs,
    outputs_from,
    rhs,
)
from .operating import LOAD_INPUT_NAMES, AeroExpansion, OperatingPoint
from .tables import bicubic_coefficients, read_rotor_table, read_text, uniform_step

__all__ = ["TurbineModel", "iea15mw"]


@dataclass(frozen=True, eq=False)  # eq/hash below: the generated ones compare arrays with ==
class TurbineModel:
    """Reduced-order turbine: rotor + rigid drivetrain + tower fore-aft mode + pitch actuator.

    Build the IEA 15 MW with :func:`iea15mw`.

    Parameters
    ----------
    name : str
        Label of the turbine.
    air_density : float
        Air density (kg/m³).
    rotor_radius : float
        Rotor radius (m).
    drivetrain_inertia : float
        Rotor and drivetrain inertia on the rotor shaft (kg·m²).
    tower_modal_mass : float
        Modal mass of the first tower fore-aft mode (kg).
    tower_modal_stiffness : float
        Its modal stiffness (N/m).
    tower_damping_ratio : float
        Its damping ratio (-).
    tower_base_moment_per_m : float
        Tower-base fore-aft moment per metre of tower-top deflection (N·m/m).
    actuator_omega : float
        Pitch-actuator natural frequency (rad/s).
    actuator_zeta : float
        Pitch-actuator damping ratio (-).
    pitch_rate_limit : float
        Pitch rate limit (rad/s).
    pitch_min : float
        Lower pitch limit (rad).
    pitch_max : float
        Upper pitch limit (rad).
    generator_efficiency : float
        Generator efficiency (-).
    rated_rotor_speed : float
        Rated rotor (= generator) speed (rad/s).
    rated_generator_torque : float
        Rated generator torque on the rotor shaft (N·m).
    rated_power : float
        Rated electrical power (W).
    tsr_grid : numpy.ndarray
        (n_tsr,) uniform tip-speed-ratio grid of the rotor tables (-).
    pitch_grid : numpy.ndarray
        (n_pitch,) uniform pitch grid of the rotor tables (rad).
    cp_table : numpy.ndarray
        (n_tsr, n_pitch) power coefficients (-).
    ct_table : numpy.ndarray
        (n_tsr, n_pitch) thrust coefficients (-).
    wind_range : tuple of float, optional
        (low, high) mean wind speeds (m/s) of the pitch-regulated design range (above rated):
        :meth:`check_wind_speed` and the design tools keep to it.
    operating_range : tuple of float, optional
        (cut-in, cut-out) mean wind speeds (m/s) where :meth:`trim` and :meth:`linearize`
        hold when the model has a ``torque_control``.
    torque_control : specdesign.rosco.TorqueLaw, optional
        The generator-torque controller below rated (ROSCO's law); without one the model is
        the constant-torque, pitch-regulated model of ``wind_range`` only.
    """

    name: str
    air_density: float
    rotor_radius: float
    drivetrain_inertia: float
    tower_modal_mass: float
    tower_modal_stiffness: float
    tower_damping_ratio: float
    tower_base_moment_per_m: float
    actuator_omega: float
    actuator_zeta: float
    pitch_rate_limit: float
    pitch_min: float
    pitch_max: float
    generator_efficiency: float
    rated_rotor_speed: float
    rated_generator_torque: float
    rated_power: float
    tsr_grid: np.ndarray = field(repr=False)
    pitch_grid: np.ndarray = field(repr=False)
    cp_table: np.ndarray = field(repr=False)
    ct_table: np.ndarray = field(repr=False)
    wind_range: tuple = (11.0, 25.0)
    operating_range: tuple = (3.0, 25.0)
    torque_control: object = None

    state_names = STATE_NAMES
    input_names = INPUT_NAMES
    output_names = OUTPUT_NAMES

    # -- compiled-kernel parameters ------------------------------------------------------
    @cached_property
    def _tables(self):
        cp_coef, cp_spl = bicubic_coefficients(self.tsr_grid, self.pitch_grid, self.cp_table)
        ct_coef, ct_spl = bicubic_coefficients(self.tsr_grid, self.pitch_grid, self.ct_table)
        return cp_coef, ct_coef, cp_spl, ct_spl

    @cached_property
    def _params(self) -> np.ndarray:
        cp_coef, ct_coef, _, _ = self._tables
        head = np.zeros(HEADER_SIZE)
        head[P_RHO] = self.air_density
        head[P_RADIUS] = self.rotor_radius
        head[P_INERTIA] = self.drivetrain_inertia
        head[P_TWR_MASS] = self.tower_modal_mass
        head[P_TWR_STIFF] = self.tower_modal_stiffness
        head[P_TWR_DAMP] = 2.0 * self.tower_damping_ratio * np.sqrt(self.tower_modal_stiffness * self.tower_modal_mass)
        head[P_MY_PER_M] = self.tower_base_moment_per_m
        head[P_ACT_OMEGA] = self.actuator_omega
        head[P_ACT_ZETA] = self.actuator_zeta
        head[P_RATE_LIM] = self.pitch_rate_limit
        head[P_PITCH_MIN] = self.pitch_min
        head[P_PITCH_MAX] = self.pitch_max
        head[P_GEN_EFF] = self.generator_efficiency
        head[P_N_TSR] = self.tsr_grid.size
        head[P_TSR0] = self.tsr_grid[0]
        head[P_DTSR] = uniform_step(self.tsr_grid, "TSR")
        head[P_N_PITCH] = self.pitch_grid.size
        head[P_PITCH0] = self.pitch_grid[0]
        head[P_DPITCH] = uniform_step(self.pitch_grid, "pitch")
        p = np.concatenate([head, cp_coef.ravel(), ct_coef.ravel()])
        p.flags.writeable = False
        return p

    def kernel_params(self) -> np.ndarray:
        """Flat float64 parameter array of the compiled kernel (a fresh copy).

        Returns
        -------
        numpy.ndarray
            The ``p`` of :func:`specdesign.turbine.rhs` / :func:`specdesign.turbine.outputs`.
        """
        return self._params.copy()

    def rotor_coefficients(self, tsr: ArrayLike, pitch: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(Cp, Ct) of the compiled interpolant.

        Parameters
        ----------
        tsr : array_like
            Tip-speed ratio (-).
        pitch : array_like
            Blade pitch (rad), broadcast with ``tsr``.

        Returns
        -------
        cp, ct : numpy.ndarray
            Power and thrust coefficients (-), of the broadcast shape.
        """
        p = self._params
        n_cells = (self.tsr_grid.size - 1) * (self.pitch_grid.size - 1) * 16
        tsr, pitch = np.broadcast_arrays(np.asarray(tsr, float), np.asarray(pitch, float))
        cp = np.array([bicubic(p, HEADER_SIZE, a, b) for a, b in zip(tsr.ravel(), pitch.ravel())]).reshape(tsr.shape)
        ct = np.array([bicubic(p, HEADER_SIZE + n_cells, a, b) for a, b in zip(tsr.ravel(), pitch.ravel())]).reshape(tsr.shape)
        return cp, ct

    # -- numpy wrappers -------------------------------------------------------------------
    def derivatives(self, x: ArrayLike, wind: float, pitch_cmd: float, gen_torque: float) -> np.ndarray:
        """ẋ of the compiled :func:`specdesign.turbine.rhs`.

        Parameters
        ----------
        x : array_like
            State, shape (5,) (:data:`STATE_NAMES`, SI).
        wind : float
            Rotor-effective wind speed (m/s).
        pitch_cmd : float
            Collective pitch demand (rad).
        gen_torque : float
            Generator torque (N·m).

        Returns
        -------
        numpy.ndarray
            (5,) state derivative (SI per second).

        Raises
        ------
        ValueError
            If ``x`` is not of shape (5,).
        """
        x = self._state(x)
        dx = np.empty(5)
        rhs(x, float(wind), float(pitch_cmd), float(gen_torque), self._params, dx)
        return dx

    def evaluate_outputs(self, x: ArrayLike, wind: float, pitch_cmd: float, gen_torque: float) -> np.ndarray:
        """Outputs of the compiled :func:`specdesign.turbine.outputs`.

        Parameters
        ----------
        x, wind, pitch_cmd, gen_torque
            The state (5,) (SI), wind (m/s), pitch demand (rad) and generator torque (N·m), as
            :meth:`derivatives` takes them.

        Returns
        -------
        numpy.ndarray
            (7,) outputs (:data:`OUTPUT_NAMES`, SI).

        Raises
        ------
        ValueError
            If ``x`` is not of shape (5,).
        """
        x = self._state(x)
        y = np.empty(len(OUTPUT_NAMES))
        outputs(x, float(wind), float(pitch_cmd), float(gen_torque), self._params, y)
        return y

    @staticmethod
    def _state(x):
        x = np.ascontiguousarray(x, dtype=float)
        if x.shape != (5,):
            raise ValueError(f"x must be a state vector of shape (5,) ordered as {STATE_NAMES}, got {x.shape}")
        return x

    # -- trim and linearisation -------------------------------------------------------------
    def check_wind_speed(self, wind_speed: float) -> float:
        """``wind_speed`` as a float, checked to be within ``wind_range``.

        Every model the design loop takes has it (:class:`specdesign.openfast.LinearTurbine`
        shares this docstring).

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s).

        Returns
        -------
        float
            The wind speed (m/s).

        Raises
        ------
        ValueError
            Outside ``wind_range``: for a TurbineModel the above-rated range where it is valid,
            for a LinearTurbine its linearisations' speeds (it interpolates, never extrapolates).
        """
        v = positive_scalar(wind_speed, "wind_speed")
        lo, hi = self.wind_range
        if not lo <= v <= hi:
            raise ValueError(
                f"wind_speed={v!r} m/s is outside the above-rated range {lo}-{hi} m/s where the "
                "constant-torque, pitch-regulated model is valid"
            )
        return v

    def _aero_torque(self, wind, omega, pitch):
        x = np.array([omega, 0.0, 0.0, pitch, 0.0])
        return self.derivatives(x, wind, pitch, 0.0)[0] * self.drivetrain_inertia

    def check_operating_speed(self, wind_speed: float) -> float:
        """``wind_speed`` as a float, checked to be where :meth:`trim` and :meth:`linearize` hold.

        That is ``operating_range`` (cut-in to cut-out) for a model with a ``torque_control``,
        ``wind_range`` (above rated) for one without.

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s).

        Returns
        -------
        float
            The wind speed (m/s).

        Raises
        ------
        ValueError
            Outside that range.

        Examples
        --------
        >>> from specdesign.turbine import iea15mw
        >>> iea15mw().check_operating_speed(5)
        5.0
        """
        if self.torque_control is None:
            return self.check_wind_speed(wind_speed)
        v = positive_scalar(wind_speed, "wind_speed")
        lo, hi = self.operating_range
        if not lo <= v <= hi:
            raise ValueError(f"wind_speed={v!r} m/s is outside the operating range {lo}-{hi} m/s (cut-in to cut-out)")
        return v

    @cached_property
    def _rated_v(self) -> float:
        return self.rated_wind_speed()

    def trim(self, wind_speed: float) -> OperatingPoint:
        """Steady operating point: above rated pitch-regulated, below rated under the torque law.

        Above rated (``region`` "3"): rated rotor speed, rated generator torque, the pitch that
        balances aerodynamic and generator torque, tower at static deflection. Below rated
        (a model with ``torque_control``, from cut-in): fine pitch and the rotor speed and torque
        the torque law holds (:func:`specdesign.rosco.steady_state`; regions "1.5", "2",
        "2.5", "2.5s").

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s), within ``operating_range`` (with a torque law) or ``wind_range``.

        Returns
        -------
        OperatingPoint
            The trim.

        Raises
        ------
        ValueError
            Outside the range, or below rated for a model without ``torque_control`` (no
            pitch ≥ ``pitch_min`` balances the torque).

        Examples
        --------
        >>> op = iea15mw().trim(19.0)
        >>> bool(0.2 < op.pitch < 0.3)
        True
        >>> iea15mw().trim(8.0).region
        '2'
        """
        v = self.check_operating_speed(wind_speed)
        # a trim is an immutable record of the model at v; the design loop asks for the same
        # speeds over and over (ROSCO's 30-speed schedule, the plant cases: 175 trims, 30
        # distinct, in one specification_for_target)
        cache = self._trims
        if v not in cache:
            cache[v] = self._trim_below(v) if self.torque_control is not None and v < self._rated_v else self._trim_above(v)
        return cache[v]

    @cached_property
    def _trims(self) -> dict:
        return {}

    def __eq__(self, other) -> bool:
        # field by field, arrays by shape and value (the dataclass's own __eq__ compared the
        # fields as a tuple, and a tuple of arrays has no truth value: model == model raised)
        if not isinstance(other, TurbineModel):
            return NotImplemented
        return all(_same(getattr(self, f.name), getattr(other, f.name)) for f in fields(self))

    def __hash__(self) -> int:
        return hash(tuple(_hashable(getattr(self, f.name)) for f in fields(self)))

    def __getstate__(self) -> dict:
        # the fields only: what is derived from them (compiled tables, trims) is rebuilt on
        # demand, so a model's pickle, and its store fingerprint, does not depend on its history
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def _trim_above(self, v):
        from scipy.optimize import brentq

        omega = self.rated_rotor_speed
        torque = self.rated_generator_torque

        def surplus(beta):
            return self._aero_torque(v, omega, beta) - torque

        lo = self.pitch_min
        hi = float(min(self.pitch_max, self.pitch_grid[-1]))
        if surplus(lo) <= 0:
            raise ValueError(
                f"wind_speed={v!r} m/s is below rated: even at minimum pitch the rotor cannot reach "
                "rated torque; this model covers the pitch-regulated region only"
            )
        # Aerodynamic torque falls monotonically with pitch above rated; bracket on a coarse
        # grid first so brentq never straddles a second root near the table edge.
        grid = np.linspace(lo, hi, 61)
        vals = np.array([surplus(b) for b in grid])
        k = int(np.argmax(vals <= 0))
        if vals[k] > 0:
            raise ValueError(f"no pitch within the table balances the torque at wind_speed={v!r} m/s")
        beta = brentq(surplus, grid[k - 1], grid[k], xtol=TRIM_TOL, rtol=TRIM_TOL)
        tsr = omega * self.rotor_radius / v
        cp, ct = (float(c) for c in self.rotor_coefficients(tsr, beta))
        area = np.pi * self.rotor_radius**2
        thrust = 0.5 * self.air_density * area * v**2 * ct
        x = np.array([omega, thrust / self.tower_modal_stiffness, 0.0, beta, 0.0])
        x.flags.writeable = False
        aero_power = self._aero_torque(v, omega, beta) * omega
        return OperatingPoint(
            wind_speed=v,
            rotor_speed=omega,
            pitch=float(beta),
            gen_torque=torque,
            x=x,
            thrust=float(thrust),
            aero_power=float(aero_power),
            power=float(self.generator_efficiency * torque * omega),
            tsr=float(tsr),
            cp=cp,
            ct=ct,
        )

    def _trim_below(self, v):
        omega, torque, beta, region = steady_state(self, self.torque_control, v)
        tsr = omega * self.rotor_radius / v
        cp, ct = (float(c) for c in self.rotor_coefficients(tsr, beta))
        thrust = 0.5 * self.air_density * np.pi * self.rotor_radius**2 * v**2 * ct
        x = np.array([omega, thrust / self.tower_modal_stiffness, 0.0, beta, 0.0])
        x.flags.writeable = False
        return OperatingPoint(
            wind_speed=v, rotor_speed=omega, pitch=float(beta), gen_torque=float(torque), x=x, thrust=float(thrust),
            aero_power=float(self._aero_torque(v, omega, beta) * omega),
            power=float(self.generator_efficiency * torque * omega), tsr=float(tsr), cp=cp, ct=ct, region=region,
        )

    def jacobians(self, op: OperatingPoint) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Jacobians of the compiled kernel at ``op`` by central differences.

        Steps are small enough (≤ 1e-5 in scaled units) that the actuator saturations stay
        inactive, large enough that round-off stays far below the 1e-6 relative level.

        Parameters
        ----------
        op : OperatingPoint
            The trim to linearise about.

        Returns
        -------
        A, B, C, D : numpy.ndarray
            (5, 5), (5, 3), (7, 5), (7, 3) matrices of :func:`specdesign.turbine.rhs` /
            :func:`specdesign.turbine.outputs` in (state, input) (SI).
        """
        x0 = np.array(op.x, dtype=float)
        u0 = op.u
        hx = np.array([1e-6, 1e-5, 1e-6, 1e-7, 1e-7])
        hu = np.array([1e-5, 1e-7, 1.0])
        n, m, ny = 5, 3, len(OUTPUT_NAMES)
        p = self._params
        f, y = np.empty(n), np.empty(ny)

        def evaluate(z):  # (dx/dt, y) at z = (x, u), as one vector
            rhs(z[:n], z[n], z[n + 1], z[n + 2], p, f)
            outputs(z[:n], z[n], z[n + 1], z[n + 2], p, y)
            return np.concatenate([f, y])

        z0, hz = np.concatenate([x0, u0]), np.concatenate([hx, hu])
        J = np.empty((n + ny, n + m))
        for k in range(n + m):
            zp, zm = z0.copy(), z0.copy()
            zp[k] += hz[k]
            zm[k] -= hz[k]
            J[:, k] = (evaluate(zp) - evaluate(zm)) / (2 * hz[k])
        A, B, C, D = J[:n, :n], J[:n, n:], J[n:, :n], J[n:, n:]
        return A, B, C, D

    def rated_wind_speed(self) -> float:
        """Lowest wind speed at which rated torque is reached at rated speed and minimum pitch.

        Returns
        -------
        float
            The rated wind speed (m/s).
        """
        from scipy.optimize import brentq

        omega, torque = self.rated_rotor_speed, self.rated_generator_torque
        return float(brentq(lambda v: self._aero_torque(v, omega, self.pitch_min) - torque, 5.0, 20.0, xtol=1e-10))

    def linearize(self, wind_speed: float, *, load_inputs: bool = False) -> control.StateSpace:
        """Linear model at the trim for ``wind_speed``.

        Inputs ``wind`` (m/s), ``pitch_cmd`` (rad), ``gen_torque`` (N·m), outputs
        :data:`OUTPUT_NAMES` (SI) and states :data:`STATE_NAMES`, all deviations from the trim.
        Index it by name: ``sys['gen_speed', 'wind']``.

        Below rated (a model with ``torque_control``) the torque loop is closed
        (:func:`specdesign.rosco.close_torque_loop`): the law's dT/dΩ enters A (region 2:
        2KΩ; regions 1.5 and 2.5: the transition PI, its integral an extra state
        ``torque_pi``), and ``gen_torque`` is a torque added to the law's. Above rated a law
        with constant power (``VS_ConstPower = 1``) enters A the same way (dT/dΩ = −P/(η·Ω²));
        one with constant torque leaves the torque an input. The pitch loop is
        open there: ROSCO's pitch PI sits at its minimum below rated.

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s), within ``wind_range`` (11-25), or from cut-in to cut-out
            (``operating_range``) with a torque law.
        load_inputs : bool, optional
            Also take :data:`LOAD_INPUT_NAMES`, disturbances added to the aerodynamic torque
            (N·m) and thrust (N): the inputs through which the higher-order aerodynamic terms
            of :meth:`aero_expansion` act (the Volterra prediction of :mod:`specdesign.validate`).

        Returns
        -------
        control.StateSpace
            The linear model, named ``<name>@<v>mps``.

        Raises
        ------
        ValueError
            Outside the range (see :meth:`trim`).

        Examples
        --------
        >>> iea15mw().linearize(19.0).nstates
        5
        >>> iea15mw().linearize(5.0).nstates  # region 1.5: the torque PI's integral, a 6th state
        6
        """
        import control

        op = self.trim(wind_speed)
        A, B, C, D = self.jacobians(op)
        inputs, states = list(INPUT_NAMES), list(STATE_NAMES)
        if self.torque_control is not None:  # above rated it matters only for constant power
            A, B, C, D, extra = close_torque_loop(A, B, C, D, self.torque_control, op.rotor_speed, op.region)
            states += extra
        if load_inputs:
            BL, DL = self._load_jacobians(op)
            BL = np.vstack([BL, np.zeros((len(states) - BL.shape[0], BL.shape[1]))])
            B, D = np.hstack([B, BL]), np.hstack([D, DL])
            inputs += list(LOAD_INPUT_NAMES)
        return control.ss(
            A, B, C, D,
            inputs=inputs, outputs=list(OUTPUT_NAMES), states=states,
            name=f"{self.name}@{op.wind_speed:g}mps".replace(".", "p"),
        )

    def _load_jacobians(self, op: OperatingPoint):
        """(B, D) columns of additive aerodynamic torque and thrust at ``op``: :func:`mechanics`
        and :func:`outputs_from` are linear in the loads, so one difference of 1 N·m / 1 N is exact
        up to round-off."""
        p, x0 = self._params, np.array(op.x, dtype=float)
        q0, t0 = self._aero_point(op)[1]
        dx, y = np.empty(5), np.empty(len(OUTPUT_NAMES))

        def evaluate(q, t):
            mechanics(x0, q, t, op.pitch, op.gen_torque, p, dx)
            outputs_from(x0, dx, op.gen_torque, p, y)
            return np.concatenate([dx, y])

        base = evaluate(q0, t0)
        h = np.array([1.0e3, 1.0e3])  # N·m, N: exact for a linear map, well above round-off
        cols = [(evaluate(q0 + h[0], t0) - base) / h[0], (evaluate(q0, t0 + h[1]) - base) / h[1]]
        J = np.stack(cols, axis=1)
        return J[:5], J[5:]

    def _aero_point(self, op: OperatingPoint):
        """(z0, loads0): the aerodynamic arguments (:data:`AERO_VARIABLES`) and loads (torque
        N·m, thrust N) at the trim ``op`` (tower at rest, so the relative wind is the wind)."""
        z0 = np.array([op.rotor_speed, op.wind_speed, op.pitch])
        return z0, np.array(aero_loads(self._params, z0[0], z0[1], z0[2]))

    def aero_expansion(self, wind_speed: float, *, steps: tuple[float, float, float] = (2e-3, 2e-2, 2e-3)) -> AeroExpansion:
        """Third-order Taylor expansion of (aerodynamic torque, thrust) about a trim.

        In (rotor speed, relative wind, pitch) (:data:`AERO_VARIABLES`).

        Parameters
        ----------
        wind_speed : float
            Mean wind speed of the trim (m/s).
        steps : tuple of float, optional
            Central-difference steps (rad/s, m/s, rad), small against the excursions in
            turbulence (≈ 0.05 rad/s, 1.5 m/s, 0.03 rad at class B) and large enough that
            round-off stays ≤ 1e-6 of the third derivatives.

        Returns
        -------
        AeroExpansion
            The expansion.

        Raises
        ------
        ValueError
            Outside ``wind_range`` or for steps that are not three positive numbers.
        """
        op = self.trim(wind_speed)
        z0, loads0 = self._aero_point(op)
        h = np.asarray(steps, dtype=float)
        if h.shape != (3,) or not np.all(np.isfinite(h)) or np.any(h <= 0):
            raise ValueError(f"steps={steps!r} must be three positive step sizes (rad/s, m/s, rad)")
        p = self._params
        E = np.diag(h)

        def f(z):
            return np.array(aero_loads(p, z[0], z[1], z[2]))

        grad = np.stack([(f(z0 + E[i]) - f(z0 - E[i])) / (2 * h[i]) for i in range(3)], axis=-1)
        hess = np.empty((2, 3, 3))
        third = np.empty((2, 3, 3, 3))
        signs = np.array([(a, b, c) for a in (1, -1) for b in (1, -1) for c in (1, -1)], dtype=float)
        for i in range(3):
            for j in range(3):
                hess[:, i, j] = (f(z0 + E[i] + E[j]) - f(z0 + E[i] - E[j]) - f(z0 - E[i] + E[j])
                                 + f(z0 - E[i] - E[j])) / (4 * h[i] * h[j])
                for k in range(3):
                    acc = sum(s.prod() * f(z0 + s[0] * E[i] + s[1] * E[j] + s[2] * E[k]) for s in signs)
                    third[:, i, j, k] = acc / (8 * h[i] * h[j] * h[k])
        for a in (z0, loads0, grad, hess, third, h):
            a.flags.writeable = False
        return AeroExpansion(wind_speed=op.wind_speed, point=z0, loads=loads0, gradient=grad, hessian=hess,
                             third=third, steps=h)


def iea15mw() -> TurbineModel:
    """The embedded IEA 15 MW reduced model built from the shipped data (SI units).

    Tower: first fore-aft mode of the finite-element model with gravity (modal mass and
    stiffness, 1.081 rad/s), 1 % damping, tower-base moment at z = 15 m per metre of
    tower-top deflection. Generator efficiency 0.95756 (electrical power = η·T·Ω). Below
    rated, ROSCO's torque law (``VS_ControlMode`` 1) tuned on this model
    (:func:`specdesign.rosco.torque_law`: minimum speed 0.5236 rad/s, ω_vs = 0.12 rad/s,
    ζ_vs = 0.85): trim and linearisation from cut-in (3 m/s) to cut-out (25 m/s).

    Returns
    -------
    TurbineModel
        The IEA 15 MW reduced model.

    Examples
    --------
    >>> iea15mw().name
    'IEA-15-240-RWT'
    """
    par = json.loads(read_text("parameters.json"))
    tsr, pitch_deg, cp, ct = read_rotor_table()
    model = TurbineModel(
        name="IEA-15-240-RWT",
        air_density=par["air_density_kg_m3"],
        rotor_radius=par["rotor_radius_m"],
        drivetrain_inertia=par["drivetrain_inertia_total_kg_m2"],
        tower_modal_mass=par["tower_modal_mass_kg_fe"],
        tower_modal_stiffness=par["tower_modal_stiffness_N_m_fe"],
        tower_damping_ratio=par["tower_fa1_damping_ratio"],
        tower_base_moment_per_m=par["tower_base_moment_per_top_deflection_Nm_per_m_fe"],
        actuator_omega=3.14,
        actuator_zeta=0.707,
        pitch_rate_limit=par["pitch_rate_limit_rad_s"],
        pitch_min=par["pitch_min_rad"],
        pitch_max=par["pitch_max_rad"],
        generator_efficiency=par["generator_efficiency"],
        rated_rotor_speed=par["rated_rotor_speed_rad_s"],
        rated_generator_torque=par["rated_generator_torque_Nm"],
        rated_power=par["rated_power_W"],
        tsr_grid=tsr,
        pitch_grid=np.deg2rad(pitch_deg),
        cp_table=cp,
        ct_table=ct,
    )
    law = torque_law(model, min_speed=par["min_rotor_speed_rad_s"], max_torque=par["max_generator_torque_Nm"],
                     max_rate=par["max_generator_torque_rate_Nm_s"], omega_vs=par["rosco_tuning"]["omega_vs_rad_s"],
                     zeta_vs=par["rosco_tuning"]["zeta_vs"])
    return dataclasses.replace(model, torque_control=law)


def _same(a, b) -> bool:
    """Whether two field values are equal; arrays by shape and value."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.shape == b.shape and bool(np.array_equal(a, b))
    return bool(a == b)


def _hashable(x):
    """A field value as something hashable (an array by its dtype, shape and bytes)."""
    if isinstance(x, np.ndarray):
        return (x.dtype.str, x.shape, x.tobytes())
    return x
