"""The embedded IEA 15 MW reduced-order model: trim and linearisation (ROSCO: :mod:`specdesign.rosco`).

The model: rigid-drivetrain rotor (aerodynamic torque from Cp(λ, β), thrust from Ct(λ, β)),
first tower fore-aft mode driven by thrust with the rotor seeing the relative wind U − ẋ_top,
a 2nd-order pitch actuator with rate and position limits, and a generator torque that is an
input (constant, ``rated_generator_torque``, above rated). Figures come from the shipped
``specdesign/data/iea15mw`` (IEA Wind Task 37 and NREL ROSCO, Apache-2.0; see NOTICE.md).

Kernel interface
----------------
One compiled right-hand side serves the nonlinear simulator and the linearisation, so the
linear model is by construction the Jacobian of what the simulator integrates.

``rhs(x, wind, pitch_cmd, gen_torque, p, dx)`` and ``outputs(x, wind, pitch_cmd, gen_torque, p, y)``
are module-level ``@numba.njit(cache=True)`` functions, callable from other ``@njit`` code.
They are composed of ``aero_loads(p, omega, v_rel, beta)`` → (torque, thrust),
``mechanics(x, aero_torque, thrust, pitch_cmd, gen_torque, p, dx)`` and
``outputs_from(x, dx, gen_torque, p, y)``, so a kernel that changes only the aerodynamics
reuses the rest:

- ``x`` (float64[5], read) and ``dx`` (float64[5], written) follow :data:`STATE_NAMES`:

  ====  =================  ======  =====================================================
  idx   name               unit    meaning
  ====  =================  ======  =====================================================
  0     ``rotor_speed``    rad/s   rotor = generator speed (gearbox ratio 1)
  1     ``tower_top_disp`` m       first fore-aft modal coordinate = tower-top deflection
  2     ``tower_top_vel``  m/s     its rate
  3     ``pitch``          rad     collective blade pitch
  4     ``pitch_rate``     rad/s   actuator internal rate state (see below)
  ====  =================  ======  =====================================================

- ``wind`` (m/s) rotor-effective wind speed, ``pitch_cmd`` (rad) collective pitch demand,
  ``gen_torque`` (N·m) generator torque on the rotor shaft: scalars (float).
- ``p`` is the flat float64 parameter array of :meth:`TurbineModel.kernel_params`: a header of
  ``_HEADER`` scalars (indices ``P_*`` in this module) followed by the bicubic Cp and Ct
  patch coefficients, each of shape (n_tsr − 1, n_pitch − 1, 4, 4) flattened in C order.
- ``y`` (float64[6], written) follows :data:`OUTPUT_NAMES`: generator speed (rad/s), tower-base
  fore-aft moment (N·m, deviation of the modal part: k_My · x_top), tower-top acceleration (m/s²),
  tower-top velocity (m/s), pitch (rad), electrical power (W = η_gen · T_gen · Ω).

Pitch actuator: β̈ = ω_a²(β_cmd − β) − 2ζ_a ω_a β̇ₛ with ω_a = 3.14 rad/s, ζ_a = 0.707; the
pitch moves at β̇ₛ = clip(β̇, ±rate_limit) and stops at the position limits; the internal rate
does not wind up beyond the rate limit. At trim the rate is 0 and the pitch inside its
limits, so the saturations play no part in the linearisation.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from importlib import resources

import numpy as np
from numba import njit

from ._checks import positive_scalar

__all__ = [
    "STATE_NAMES",
    "INPUT_NAMES",
    "OUTPUT_NAMES",
    "rhs",
    "outputs",
    "aero_loads",
    "mechanics",
    "outputs_from",
    "TurbineModel",
    "OperatingPoint",
    "AeroExpansion",
    "RoscoSchedule",
    "iea15mw",
    "rosco_baseline",
    "rosco_gain_schedule",
]

STATE_NAMES = ("rotor_speed", "tower_top_disp", "tower_top_vel", "pitch", "pitch_rate")
INPUT_NAMES = ("wind", "pitch_cmd", "gen_torque")
OUTPUT_NAMES = ("gen_speed", "tower_base_my", "tower_top_acc", "tower_top_vel", "pitch", "power")
#: Extra inputs of ``linearize(..., load_inputs=True)``: disturbances added to the aerodynamic
#: torque (N·m) and thrust (N).
LOAD_INPUT_NAMES = ("aero_torque", "thrust")
#: Arguments of the aerodynamic loads that :class:`AeroExpansion` expands in.
AERO_VARIABLES = ("rotor_speed", "relative_wind", "pitch")

# Header of the flat kernel parameter array.
P_RHO, P_RADIUS, P_INERTIA = 0, 1, 2
P_TWR_MASS, P_TWR_STIFF, P_TWR_DAMP, P_MY_PER_M = 3, 4, 5, 6
P_ACT_OMEGA, P_ACT_ZETA, P_RATE_LIM, P_PITCH_MIN, P_PITCH_MAX = 7, 8, 9, 10, 11
P_GEN_EFF = 12
P_N_TSR, P_TSR0, P_DTSR, P_N_PITCH, P_PITCH0, P_DPITCH = 13, 14, 15, 16, 17, 18
_HEADER = 20

_DATA = "data/iea15mw"


# ----------------------------------------------------------------------------- kernel
@njit(cache=True)
def _bicubic(p, offset, tsr, pitch):
    """Evaluate one C2 bicubic table (coefficients at p[offset:]) at (tsr, pitch rad)."""
    n_tsr = int(p[P_N_TSR])
    n_pitch = int(p[P_N_PITCH])
    u = (tsr - p[P_TSR0]) / p[P_DTSR]
    v = (pitch - p[P_PITCH0]) / p[P_DPITCH]
    # Outside the table the coefficient is held at its edge value rather than extrapolated:
    # a cubic extrapolation can run away during a simulator transient.
    u = min(max(u, 0.0), n_tsr - 1.0)
    v = min(max(v, 0.0), n_pitch - 1.0)
    i = min(int(u), n_tsr - 2)
    j = min(int(v), n_pitch - 2)
    u -= i
    v -= j
    base = offset + (i * (n_pitch - 1) + j) * 16
    out = 0.0
    uk = 1.0
    for k in range(4):
        row = p[base + 4 * k] + v * (p[base + 4 * k + 1] + v * (p[base + 4 * k + 2] + v * p[base + 4 * k + 3]))
        out += uk * row
        uk *= u
    return out


@njit(cache=True)
def aero_loads(p, omega, v_rel, beta):
    """(aerodynamic torque N·m, thrust N) at rotor speed ``omega`` (rad/s), wind relative to
    the tower top ``v_rel`` (m/s) and pitch ``beta`` (rad), from the compiled Cp/Ct interpolant."""
    radius = p[P_RADIUS]
    area = np.pi * radius * radius
    # Kept positive so that a wild transient cannot divide by zero.
    v = max(v_rel, 0.1)
    tsr = max(omega, 1e-6) * radius / v
    n_cells = (int(p[P_N_TSR]) - 1) * (int(p[P_N_PITCH]) - 1) * 16
    cp = _bicubic(p, _HEADER, tsr, beta)
    ct = _bicubic(p, _HEADER + n_cells, tsr, beta)
    q_dyn = 0.5 * p[P_RHO] * area * v * v
    # Aerodynamic torque = P/Ω = q_dyn·R·Cp/λ, written without 1/Ω.
    return q_dyn * radius * cp / tsr, q_dyn * ct


@njit(cache=True)
def mechanics(x, aero_torque, thrust, pitch_cmd, gen_torque, p, dx):
    """State derivative given the aerodynamic loads: rigid drivetrain, first tower fore-aft
    mode, pitch actuator with rate and position limits (written into ``dx``). Shared by
    :func:`rhs` and by kernels that replace only the aerodynamics."""
    beta = x[3]
    beta_rate = x[4]
    qd = x[2]
    dx[0] = (aero_torque - gen_torque) / p[P_INERTIA]
    dx[1] = qd
    dx[2] = (thrust - p[P_TWR_STIFF] * x[1] - p[P_TWR_DAMP] * qd) / p[P_TWR_MASS]

    rate_lim = p[P_RATE_LIM]
    rate = min(max(beta_rate, -rate_lim), rate_lim)
    if (beta >= p[P_PITCH_MAX] and rate > 0.0) or (beta <= p[P_PITCH_MIN] and rate < 0.0):
        rate = 0.0
    wa = p[P_ACT_OMEGA]
    acc = wa * wa * (pitch_cmd - beta) - 2.0 * p[P_ACT_ZETA] * wa * rate
    # No wind-up of the internal rate beyond the rate limit.
    if (beta_rate >= rate_lim and acc > 0.0) or (beta_rate <= -rate_lim and acc < 0.0):
        acc = 0.0
    dx[3] = rate
    dx[4] = acc


@njit(cache=True)
def rhs(x, wind, pitch_cmd, gen_torque, p, dx):
    """State derivative of the reduced IEA 15 MW model, written into ``dx``.

    See the module docstring, section "Kernel interface", for the state vector, units and
    the layout of the parameter array ``p`` (from :meth:`TurbineModel.kernel_params`).
    """
    # The rotor sees the wind relative to the moving tower top.
    aero_torque, thrust = aero_loads(p, x[0], wind - x[2], x[3])
    mechanics(x, aero_torque, thrust, pitch_cmd, gen_torque, p, dx)


@njit(cache=True)
def outputs_from(x, dx, gen_torque, p, y):
    """Outputs (:data:`OUTPUT_NAMES`) from the state and its derivative, written into ``y``."""
    y[0] = x[0]
    y[1] = p[P_MY_PER_M] * x[1]
    y[2] = dx[2]
    y[3] = x[2]
    y[4] = x[3]
    y[5] = p[P_GEN_EFF] * gen_torque * x[0]


@njit(cache=True)
def outputs(x, wind, pitch_cmd, gen_torque, p, y):
    """Outputs of the reduced model in the order of :data:`OUTPUT_NAMES`, written into ``y``.

    Same arguments as :func:`rhs`; ``y`` is float64[6]: gen_speed (rad/s), tower_base_my
    (N·m), tower_top_acc (m/s²), tower_top_vel (m/s), pitch (rad), power (W, electrical).
    """
    dx = np.empty(5)
    rhs(x, wind, pitch_cmd, gen_torque, p, dx)
    outputs_from(x, dx, gen_torque, p, y)


# ----------------------------------------------------------------------------- data
def _read_text(name: str) -> str:
    return resources.files("specdesign").joinpath(f"{_DATA}/{name}").read_text()


def _read_rotor_table():
    """Parse the ROSCO-format Cp/Ct/Cq text table: pitch (deg), TSR, and (n_tsr, n_pitch) blocks."""
    lines = _read_text("Cp_Ct_Cq.IEA15MW.txt").splitlines()
    pitch = tsr = None
    blocks = {}
    i = 0
    while i < len(lines):
        line = lines[i].strip().lower()
        if line.startswith("# pitch angle vector"):
            pitch = np.array(lines[i + 1].split(), float)
        elif line.startswith("# tsr vector"):
            tsr = np.array(lines[i + 1].split(), float)
        elif line.startswith("#") and "coefficient" in line:
            key = line.split()[1][:2]  # "po", "th", "to"
            rows = []
            j = i + 1
            while len(rows) < len(tsr):
                if lines[j].strip():
                    rows.append(np.array(lines[j].split(), float))
                j += 1
            blocks[key] = np.array(rows)
            i = j
            continue
        i += 1
    return tsr, pitch, blocks["po"], blocks["th"]


def _uniform(grid, name):
    step = np.diff(grid)
    if not np.allclose(step, step[0], rtol=1e-9, atol=1e-12):
        raise ValueError(f"the {name} axis of the rotor table must be uniform for the compiled interpolant")
    return float(step[0])


# Hermite basis: for a cubic on [0, 1] with values f0, f1 and slopes d0, d1, the monomial
# coefficients are H @ [f0, f1, d0, d1].
_H = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [-3.0, 3.0, -2.0, -1.0], [2.0, -2.0, 1.0, 1.0]])


def _bicubic_coefficients(tsr, pitch_rad, table):
    """Per-cell bicubic coefficients a[i, j, k, l] (f = Σ a_kl u^k v^l) reproducing the
    interpolating tensor-product cubic spline of ``table`` (scipy RectBivariateSpline, s=0).

    Within each cell that spline is one bicubic polynomial, fixed by f, f_u, f_v, f_uv at the
    four corners; Hermite patches built from those corner values reproduce it exactly, so the
    compiled kernel evaluates the same C2 surface scipy fits.
    """
    from scipy.interpolate import RectBivariateSpline

    spl = RectBivariateSpline(tsr, pitch_rad, table, kx=3, ky=3, s=0)
    du = tsr[1] - tsr[0]
    dv = pitch_rad[1] - pitch_rad[0]
    f = spl(tsr, pitch_rad)
    fu = spl(tsr, pitch_rad, dx=1) * du
    fv = spl(tsr, pitch_rad, dy=1) * dv
    fuv = spl(tsr, pitch_rad, dx=1, dy=1) * du * dv
    # Corner matrix G[i, j] = [[f00, f01, fv00, fv01], [f10, f11, fv10, fv11], [fu.., ..], [fuv..]]
    # in the ordering of _H: rows (value at u=0, value at u=1, slope at u=0, slope at u=1).
    def corners(a):
        return np.stack([a[:-1, :-1], a[:-1, 1:], a[1:, :-1], a[1:, 1:]], -1)  # 00, 01, 10, 11

    c_f, c_fu, c_fv, c_fuv = corners(f), corners(fu), corners(fv), corners(fuv)
    g = np.empty(f[:-1, :-1].shape + (4, 4))
    # rows: f(u=0), f(u=1), f_u(u=0), f_u(u=1); columns: same for v.
    g[..., 0, 0], g[..., 0, 1], g[..., 0, 2], g[..., 0, 3] = c_f[..., 0], c_f[..., 1], c_fv[..., 0], c_fv[..., 1]
    g[..., 1, 0], g[..., 1, 1], g[..., 1, 2], g[..., 1, 3] = c_f[..., 2], c_f[..., 3], c_fv[..., 2], c_fv[..., 3]
    g[..., 2, 0], g[..., 2, 1], g[..., 2, 2], g[..., 2, 3] = c_fu[..., 0], c_fu[..., 1], c_fuv[..., 0], c_fuv[..., 1]
    g[..., 3, 0], g[..., 3, 1], g[..., 3, 2], g[..., 3, 3] = c_fu[..., 2], c_fu[..., 3], c_fuv[..., 2], c_fuv[..., 3]
    return _H @ g @ _H.T, spl


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True)
class OperatingPoint:
    """A steady operating point (trim) of the reduced model.

    wind_speed (m/s), rotor_speed (rad/s), pitch (rad), gen_torque (N·m), x (state vector,
    :data:`STATE_NAMES`), thrust (N), aero_power (W, mechanical), power (W, electrical),
    tsr (-), cp (-), ct (-).
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

    @property
    def u(self) -> np.ndarray:
        """Input vector (wind m/s, pitch_cmd rad, gen_torque N·m) at the trim."""
        return np.array([self.wind_speed, self.pitch, self.gen_torque])


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class AeroExpansion:
    """Taylor expansion of the aerodynamic loads about a trim, to third order.

    The loads (aerodynamic torque N·m, thrust N) are functions of z = (rotor speed rad/s, wind
    relative to the tower top m/s, pitch rad) (:data:`AERO_VARIABLES`). ``point`` (3,) is z at
    the trim of ``wind_speed`` (m/s) and ``loads`` (2,) the loads there; ``gradient`` (2, 3),
    ``hessian`` (2, 3, 3) and ``third`` (2, 3, 3, 3) are their first, second and third
    partial derivatives in z (SI units of load per unit of each variable), by central
    differences of the compiled interpolant with steps ``steps`` (3,).
    """

    wind_speed: float
    point: np.ndarray
    loads: np.ndarray
    gradient: np.ndarray
    hessian: np.ndarray
    third: np.ndarray
    steps: np.ndarray

    def evaluate(self, dz, order: int = 3) -> np.ndarray:
        """Load change (2, ...) predicted by the Taylor polynomial of ``order`` (1-3) for the
        deviations ``dz`` (3, ...) from ``point`` (same units as :data:`AERO_VARIABLES`)."""
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


@dataclass(frozen=True)
class TurbineModel:
    """Reduced-order turbine: rotor + rigid drivetrain + tower fore-aft mode + pitch actuator.

    All fields SI (rad, rad/s, N·m, kg, N/m). Build the IEA 15 MW with :func:`iea15mw`.
    ``tsr_grid`` (-), ``pitch_grid`` (rad) and the (n_tsr, n_pitch) ``cp_table``, ``ct_table``
    are the rotor performance tables.
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

    state_names = STATE_NAMES
    input_names = INPUT_NAMES
    output_names = OUTPUT_NAMES

    # -- compiled-kernel parameters ------------------------------------------------------
    @cached_property
    def _tables(self):
        cp_coef, cp_spl = _bicubic_coefficients(self.tsr_grid, self.pitch_grid, self.cp_table)
        ct_coef, ct_spl = _bicubic_coefficients(self.tsr_grid, self.pitch_grid, self.ct_table)
        return cp_coef, ct_coef, cp_spl, ct_spl

    @cached_property
    def _params(self) -> np.ndarray:
        cp_coef, ct_coef, _, _ = self._tables
        head = np.zeros(_HEADER)
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
        head[P_DTSR] = _uniform(self.tsr_grid, "TSR")
        head[P_N_PITCH] = self.pitch_grid.size
        head[P_PITCH0] = self.pitch_grid[0]
        head[P_DPITCH] = _uniform(self.pitch_grid, "pitch")
        p = np.concatenate([head, cp_coef.ravel(), ct_coef.ravel()])
        p.flags.writeable = False
        return p

    def kernel_params(self) -> np.ndarray:
        """Flat float64 parameter array for :func:`rhs` / :func:`outputs` (a fresh copy)."""
        return self._params.copy()

    def rotor_coefficients(self, tsr, pitch):
        """(Cp, Ct) of the compiled interpolant at tip-speed ratio ``tsr`` and ``pitch`` (rad)."""
        p = self._params
        n_cells = (self.tsr_grid.size - 1) * (self.pitch_grid.size - 1) * 16
        tsr, pitch = np.broadcast_arrays(np.asarray(tsr, float), np.asarray(pitch, float))
        cp = np.array([_bicubic(p, _HEADER, a, b) for a, b in zip(tsr.ravel(), pitch.ravel())]).reshape(tsr.shape)
        ct = np.array([_bicubic(p, _HEADER + n_cells, a, b) for a, b in zip(tsr.ravel(), pitch.ravel())]).reshape(tsr.shape)
        return cp, ct

    # -- numpy wrappers -------------------------------------------------------------------
    def derivatives(self, x, wind, pitch_cmd, gen_torque) -> np.ndarray:
        """ẋ of the compiled :func:`rhs` for state ``x`` (see :data:`STATE_NAMES`), wind (m/s),
        pitch_cmd (rad) and gen_torque (N·m)."""
        x = self._state(x)
        dx = np.empty(5)
        rhs(x, float(wind), float(pitch_cmd), float(gen_torque), self._params, dx)
        return dx

    def evaluate_outputs(self, x, wind, pitch_cmd, gen_torque) -> np.ndarray:
        """Outputs (:data:`OUTPUT_NAMES`, SI) of the compiled :func:`outputs`."""
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
    def check_wind_speed(self, wind_speed) -> float:
        """``wind_speed`` (m/s) as a float, checked to be within ``wind_range``.

        Raises ValueError outside the above-rated range where the model is valid.
        """
        v = positive_scalar(wind_speed, "wind_speed")
        lo, hi = self.wind_range
        if not lo <= v <= hi:
            raise ValueError(
                f"wind_speed={v!r} m/s is outside the above-rated range {lo}-{hi} m/s where the "
                "constant-torque, pitch-regulated model is valid"
            )
        return v

    _check_wind = check_wind_speed  # TODO(issue 13): remove once callers switch

    def _aero_torque(self, wind, omega, pitch):
        x = np.array([omega, 0.0, 0.0, pitch, 0.0])
        return self.derivatives(x, wind, pitch, 0.0)[0] * self.drivetrain_inertia

    def trim(self, wind_speed) -> OperatingPoint:
        """Steady operating point above rated: rated rotor speed, rated generator torque, the
        pitch (rad) that balances aerodynamic and generator torque, tower at static deflection.

        Raises ValueError outside ``wind_range`` (m/s) or when the wind is below rated (no
        pitch ≥ ``pitch_min`` balances the torque).
        """
        from scipy.optimize import brentq

        v = self.check_wind_speed(wind_speed)
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
        beta = brentq(surplus, grid[k - 1], grid[k], xtol=1e-14, rtol=1e-14)
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

    def jacobians(self, op: OperatingPoint):
        """(A, B, C, D) of :func:`rhs`/:func:`outputs` at ``op`` by central differences.

        Steps are small enough (≤ 1e-5 in scaled units) that the actuator saturations stay
        inactive, large enough that round-off stays far below the 1e-6 relative level.
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
        """Lowest wind speed (m/s) at which rated torque is reached at rated speed and minimum pitch."""
        from scipy.optimize import brentq

        omega, torque = self.rated_rotor_speed, self.rated_generator_torque
        return float(brentq(lambda v: self._aero_torque(v, omega, self.pitch_min) - torque, 5.0, 20.0, xtol=1e-10))

    def linearize(self, wind_speed, *, load_inputs: bool = False):
        """Linear model at the trim for ``wind_speed`` (m/s, 11-25): a ``control.StateSpace``
        with inputs ``wind`` (m/s), ``pitch_cmd`` (rad), ``gen_torque`` (N·m), outputs
        :data:`OUTPUT_NAMES` (SI) and states :data:`STATE_NAMES`, all deviations from the trim.
        Index it by name: ``sys['gen_speed', 'wind']``.

        load_inputs : also take :data:`LOAD_INPUT_NAMES`, disturbances added to the
            aerodynamic torque (N·m) and thrust (N): the inputs through which the higher-order
            aerodynamic terms of :meth:`aero_expansion` act (:func:`specdesign.validate.volterra_response`).
        """
        import control

        op = self.trim(wind_speed)
        A, B, C, D = self.jacobians(op)
        inputs = list(INPUT_NAMES)
        if load_inputs:
            BL, DL = self._load_jacobians(op)
            B, D = np.hstack([B, BL]), np.hstack([D, DL])
            inputs += list(LOAD_INPUT_NAMES)
        return control.ss(
            A, B, C, D,
            inputs=inputs, outputs=list(OUTPUT_NAMES), states=list(STATE_NAMES),
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

    def aero_expansion(self, wind_speed, *, steps=(2e-3, 2e-2, 2e-3)) -> AeroExpansion:
        """Third-order Taylor expansion of (aerodynamic torque, thrust) about the trim of
        ``wind_speed`` (m/s) in (rotor speed, relative wind, pitch): :class:`AeroExpansion`.

        steps : central-difference steps (rad/s, m/s, rad), small against the excursions in
        turbulence (≈ 0.05 rad/s, 1.5 m/s, 0.03 rad at class B) and large enough that
        round-off stays ≤ 1e-6 of the third derivatives.
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
    tower-top deflection. Generator efficiency 0.95756 (electrical power = η·T·Ω).
    """
    par = json.loads(_read_text("parameters.json"))
    tsr, pitch_deg, cp, ct = _read_rotor_table()
    return TurbineModel(
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


# ----------------------------------------------------------------------------- ROSCO (specdesign.rosco)
#: Names that live in :mod:`specdesign.rosco` and stay importable from here (public contract:
#: ``specdesign.turbine.rosco_baseline``). Resolved on first access: :mod:`specdesign.rosco`
#: imports this module, so importing it here at load time would be circular.
_ROSCO_NAMES = ("RoscoSchedule", "rosco_gain_schedule", "speed_filter", "rosco_baseline")


def __getattr__(name):
    if name in _ROSCO_NAMES:
        from . import rosco

        return getattr(rosco, name)
    if name == "_rotor_coefficients":  # TODO(issue 13): remove once callers switch
        from .rosco import first_order_rotor_model

        return first_order_rotor_model
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_ROSCO_NAMES) | {"_rotor_coefficients"})
