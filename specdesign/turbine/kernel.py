"""The compiled right-hand side of the reduced turbine model (numba), and its interface.

One compiled right-hand side serves the nonlinear simulator and the linearisation, so the
linear model is by construction the Jacobian of what the simulator integrates.

``rhs(x, wind, pitch_cmd, gen_torque, p, dx)`` and ``outputs(x, wind, pitch_cmd, gen_torque, p, y)``
are module-level ``@numba.njit(cache=True)`` functions, callable from other ``@njit`` code.
They are composed of ``aero_loads(p, omega, v_rel, beta)`` → (torque, thrust),
``mechanics(x, aero_torque, thrust, pitch_cmd, gen_torque, p, dx)`` (on scalars:
``mechanics_scalars``) and ``outputs_from(x, dx, gen_torque, p, y)``, so a kernel that changes
only the aerodynamics reuses the rest:

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
- ``p`` is the flat float64 parameter array of :meth:`specdesign.turbine.TurbineModel.kernel_params`: a header of
  :data:`HEADER_SIZE` scalars (indices ``P_*`` in this module) followed by the bicubic Cp and Ct
  patch coefficients, each of shape (n_tsr − 1, n_pitch − 1, 4, 4) flattened in C order.
- ``y`` (float64[7], written) follows :data:`OUTPUT_NAMES`: generator speed (rad/s), tower-base
  fore-aft moment (N·m, deviation of the modal part: k_My · x_top), tower-top acceleration (m/s²),
  tower-top velocity (m/s), pitch (rad), electrical power (W = η_gen · T_gen · Ω), blade-root
  flapwise moment (N·m, collective, quasi-static: below).

Blade-root flapwise moment (``blade_root_my``, appended last so the other indices keep their
places): each of the :data:`BLADE_COUNT` blades carries T/N_b of the rotor thrust T at the
radial centre of thrust r_T(β) = R·(c₀ + c₁β + c₂β²) (:data:`THRUST_CENTRE_COEFFS`, β in rad)::

    M_flap = r_T(β) · T / N_b

The thrust is the one the tower mode feels, recovered from the state derivative,
T = m_t·ẍ_top + k_t·x_top + c_t·ẋ_top (so kernels that replace the aerodynamics, and the
additive thrust input of the load linearisation, move it too). c₀ ≈ 2/3 is the ideal rotor's
centre (thrust per unit span ∝ r); pitching to feather unloads the tip first, which moves the
centre inboard. The coefficients are a least-squares fit to OpenFAST's mean RootMyc (blade-root
out-of-plane moment, mean over the three blades and twelve azimuths) divided by T/3, with T from
this model's Ct table at OpenFAST's operating point (wind, pitch, rotor speed), over the
operating points 7-24 m/s (pitch 0-21.7°) of the IEA-15-240-RWT UMaineSemi linearisation deck
shipped with the ``rosco`` package (``Examples/Test_Cases/IEA-15-240-RWT/IEA-15-240-RWT-UMaineSemi/
linearizations``); the fitted moment is within 2.7 % of OpenFAST's from 7 to 24 m/s
(``tests/test_blade_moment.py`` checks it where the deck is installed). OpenFAST's RootMyc also
carries the blades' weight and centrifugal terms, which the fit absorbs at the mean only; the
fluctuation is that of the thrust (no blade dynamics: the blade's first flap mode is well above
the tower mode and the pitch loop). The same fraction of R serves other rotors (an
approximation: c₀ is generic, c₁ and c₂ are the IEA 15 MW's).

Pitch actuator: β̈ = ω_a²(β_cmd − β) − 2ζ_a ω_a β̇ₛ with ω_a = 3.14 rad/s, ζ_a = 0.707; the
pitch moves at β̇ₛ = clip(β̇, ±rate_limit) and stops at the position limits; the internal rate
does not wind up beyond the rate limit. At trim the rate is 0 and the pitch inside its
limits, so the saturations play no part in the linearisation.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = [
    "STATE_NAMES",
    "INPUT_NAMES",
    "OUTPUT_NAMES",
    "HEADER_SIZE",
    "BLADE_COUNT",
    "THRUST_CENTRE_COEFFS",
    "P_RHO", "P_RADIUS", "P_INERTIA", "P_TWR_MASS", "P_TWR_STIFF", "P_TWR_DAMP", "P_MY_PER_M", "P_ACT_OMEGA",
    "P_ACT_ZETA", "P_RATE_LIM", "P_PITCH_MIN", "P_PITCH_MAX", "P_GEN_EFF", "P_N_TSR", "P_TSR0", "P_DTSR",
    "P_N_PITCH", "P_PITCH0", "P_DPITCH",
    "bicubic",
    "aero_loads",
    "mechanics",
    "mechanics_scalars",
    "rhs",
    "outputs_from",
    "outputs",
    "thrust_centre",
]

STATE_NAMES = ("rotor_speed", "tower_top_disp", "tower_top_vel", "pitch", "pitch_rate")
INPUT_NAMES = ("wind", "pitch_cmd", "gen_torque")
OUTPUT_NAMES = ("gen_speed", "tower_base_my", "tower_top_acc", "tower_top_vel", "pitch", "power", "blade_root_my")

#: Number of blades sharing the thrust in ``blade_root_my``.
BLADE_COUNT = 3
#: (c₀, c₁, c₂): radial centre of thrust r_T/R = c₀ + c₁β + c₂β² (β in rad), fitted to OpenFAST
#: (module docstring; the fit: ``python benchmarks/health_mpc.py --fit-centre``).
THRUST_CENTRE_COEFFS = (0.67280, 0.15642, -1.85570)

# Header of the flat kernel parameter array.
P_RHO, P_RADIUS, P_INERTIA = 0, 1, 2
P_TWR_MASS, P_TWR_STIFF, P_TWR_DAMP, P_MY_PER_M = 3, 4, 5, 6
P_ACT_OMEGA, P_ACT_ZETA, P_RATE_LIM, P_PITCH_MIN, P_PITCH_MAX = 7, 8, 9, 10, 11
P_GEN_EFF = 12
P_N_TSR, P_TSR0, P_DTSR, P_N_PITCH, P_PITCH0, P_DPITCH = 13, 14, 15, 16, 17, 18
#: Length of the header of the flat parameter array (the bicubic coefficients follow it).
HEADER_SIZE = 20



# ----------------------------------------------------------------------------- kernel
# Every piece is inlined into its callers (inline="always", at numba's IR level): a numba call
# passing the parameter array costs reference-count operations and stops LLVM optimising
# across it, and the simulator's loop evaluates these pieces millions of times a campaign.
@njit(cache=True, inline="always")
def bicubic(p: np.ndarray, offset: int, tsr: float, pitch: float) -> float:
    """Evaluate one C2 bicubic table (coefficients at ``p[offset:]``) at (tsr, pitch).

    Outside the table the coefficient is held at its edge value.

    Parameters
    ----------
    p : numpy.ndarray
        Flat parameter array (:meth:`specdesign.turbine.TurbineModel.kernel_params`).
    offset : int
        Index in ``p`` of the table's first coefficient.
    tsr : float
        Tip-speed ratio (-).
    pitch : float
        Blade pitch (rad).

    Returns
    -------
    float
        The coefficient (Cp or Ct, -).
    """
    base, u, v = _cell(p, tsr, pitch)
    return _patch(p, offset + base, u, v)


@njit(cache=True, inline="always")
def _cell(p, tsr, pitch):
    """(index of the cell's first coefficient within a table, u, v in [0, 1]) at (tsr, pitch)."""
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
    return (i * (n_pitch - 1) + j) * 16, u - i, v - j


@njit(cache=True, inline="always")
def _patch(p, base, u, v):
    """The bicubic patch whose 16 coefficients start at ``p[base]``, at (u, v)."""
    out = 0.0
    uk = 1.0
    for k in range(4):
        row = p[base + 4 * k] + v * (p[base + 4 * k + 1] + v * (p[base + 4 * k + 2] + v * p[base + 4 * k + 3]))
        out += uk * row
        uk *= u
    return out


@njit(cache=True, inline="always")
def aero_loads(p: np.ndarray, omega: float, v_rel: float, beta: float) -> tuple[float, float]:
    """Aerodynamic torque and thrust from the compiled Cp/Ct interpolant.

    Parameters
    ----------
    p : numpy.ndarray
        Flat parameter array (:meth:`specdesign.turbine.TurbineModel.kernel_params`).
    omega : float
        Rotor speed (rad/s).
    v_rel : float
        Wind relative to the tower top (m/s).
    beta : float
        Blade pitch (rad).

    Returns
    -------
    torque : float
        Aerodynamic torque (N·m).
    thrust : float
        Thrust (N).
    """
    radius = p[P_RADIUS]
    area = np.pi * radius * radius
    # Kept positive so that a wild transient cannot divide by zero.
    v = max(v_rel, 0.1)
    tsr = max(omega, 1e-6) * radius / v
    n_cells = (int(p[P_N_TSR]) - 1) * (int(p[P_N_PITCH]) - 1) * 16
    # Cp and Ct share the grid: one cell lookup for both (the same numbers as two bicubic calls)
    base, u, w = _cell(p, tsr, beta)
    cp = _patch(p, HEADER_SIZE + base, u, w)
    ct = _patch(p, HEADER_SIZE + n_cells + base, u, w)
    q_dyn = 0.5 * p[P_RHO] * area * v * v
    # Aerodynamic torque = P/Ω = q_dyn·R·Cp/λ, written without 1/Ω.
    return q_dyn * radius * cp / tsr, q_dyn * ct


@njit(cache=True, inline="always")
def mechanics(x: np.ndarray, aero_torque: float, thrust: float, pitch_cmd: float, gen_torque: float, p: np.ndarray,
              dx: np.ndarray) -> None:
    """State derivative given the aerodynamic loads, written into ``dx``.

    Rigid drivetrain, first tower fore-aft mode, pitch actuator with rate and position limits.
    Shared by :func:`rhs` and by kernels that replace only the aerodynamics.

    Parameters
    ----------
    x, pitch_cmd, gen_torque, p, dx
        As :func:`rhs` takes them: the state (float64[5], SI), pitch demand (rad), generator
        torque on the rotor shaft (N·m), parameter array and the derivative (written).
    aero_torque : float
        Aerodynamic torque (N·m).
    thrust : float
        Thrust (N).
    """
    dx[0], dx[1], dx[2], dx[3], dx[4] = mechanics_scalars(x[0], x[1], x[2], x[3], x[4], aero_torque, thrust,
                                                          pitch_cmd, gen_torque, p)


@njit(cache=True, inline="always")
def mechanics_scalars(rotor_speed: float, tower_top_disp: float, tower_top_vel: float, pitch: float, pitch_rate: float,
                      aero_torque: float, thrust: float, pitch_cmd: float, gen_torque: float,
                      p: np.ndarray) -> tuple[float, float, float, float, float]:
    """:func:`mechanics` on the five states as scalars, the derivative returned.

    The compiled simulator's RK4 keeps the state in registers this way (an array between
    the stages costs a store and a load on every stage's critical path).

    Parameters
    ----------
    rotor_speed, tower_top_disp, tower_top_vel, pitch, pitch_rate : float
        The state (:data:`STATE_NAMES`: rad/s, m, m/s, rad, rad/s).
    aero_torque, thrust, pitch_cmd, gen_torque, p
        As :func:`mechanics` takes them (N·m, N, rad, N·m; the flat parameter array).

    Returns
    -------
    tuple of float
        The derivatives of the five states, in their order (rad/s², m/s, m/s², rad/s, rad/s²).
    """
    beta = pitch
    beta_rate = pitch_rate
    qd = tower_top_vel
    d_speed = (aero_torque - gen_torque) / p[P_INERTIA]
    d_disp = qd
    d_vel = (thrust - p[P_TWR_STIFF] * tower_top_disp - p[P_TWR_DAMP] * qd) / p[P_TWR_MASS]

    rate_lim = p[P_RATE_LIM]
    rate = min(max(beta_rate, -rate_lim), rate_lim)
    if (beta >= p[P_PITCH_MAX] and rate > 0.0) or (beta <= p[P_PITCH_MIN] and rate < 0.0):
        rate = 0.0
    wa = p[P_ACT_OMEGA]
    acc = wa * wa * (pitch_cmd - beta) - 2.0 * p[P_ACT_ZETA] * wa * rate
    # No wind-up of the internal rate beyond the rate limit.
    if (beta_rate >= rate_lim and acc > 0.0) or (beta_rate <= -rate_lim and acc < 0.0):
        acc = 0.0
    return d_speed, d_disp, d_vel, rate, acc


@njit(cache=True, inline="always")
def rhs(x: np.ndarray, wind: float, pitch_cmd: float, gen_torque: float, p: np.ndarray, dx: np.ndarray) -> None:
    """State derivative of the reduced IEA 15 MW model, written into ``dx``.

    See the module docstring for the state vector, units and the layout of the parameter
    array ``p``.

    Parameters
    ----------
    x : numpy.ndarray
        State, float64[5] (:data:`STATE_NAMES`, SI).
    wind : float
        Rotor-effective wind speed (m/s).
    pitch_cmd : float
        Collective pitch demand (rad).
    gen_torque : float
        Generator torque on the rotor shaft (N·m).
    p : numpy.ndarray
        Flat parameter array (:meth:`specdesign.turbine.TurbineModel.kernel_params`).
    dx : numpy.ndarray
        Output: float64[5], the state derivative (written).
    """
    # The rotor sees the wind relative to the moving tower top.
    aero_torque, thrust = aero_loads(p, x[0], wind - x[2], x[3])
    mechanics(x, aero_torque, thrust, pitch_cmd, gen_torque, p, dx)


@njit(cache=True, inline="always")
def thrust_centre(pitch: float) -> float:
    """Radial centre of thrust as a fraction of the rotor radius, r_T/R = c₀ + c₁β + c₂β².

    Coefficients :data:`THRUST_CENTRE_COEFFS` (fitted to OpenFAST, see the module docstring).

    Parameters
    ----------
    pitch : float
        Collective blade pitch β (rad).

    Returns
    -------
    float
        r_T/R (-).

    Examples
    --------
    >>> round(thrust_centre(0.0), 4)
    0.6728
    """
    c0, c1, c2 = THRUST_CENTRE_COEFFS
    return c0 + pitch * (c1 + pitch * c2)


@njit(cache=True, inline="always")
def outputs_from(x: np.ndarray, dx: np.ndarray, gen_torque: float, p: np.ndarray, y: np.ndarray) -> None:
    """Outputs (:data:`OUTPUT_NAMES`) from the state and its derivative, written into ``y``.

    Parameters
    ----------
    x : numpy.ndarray
        State, float64[5] (:data:`STATE_NAMES`, SI).
    dx : numpy.ndarray
        Its derivative, float64[5].
    gen_torque : float
        Generator torque on the rotor shaft (N·m).
    p : numpy.ndarray
        Flat parameter array (:meth:`specdesign.turbine.TurbineModel.kernel_params`).
    y : numpy.ndarray
        Output: float64[7], the outputs (written, SI).
    """
    y[0] = x[0]
    y[1] = p[P_MY_PER_M] * x[1]
    y[2] = dx[2]
    y[3] = x[2]
    y[4] = x[3]
    y[5] = p[P_GEN_EFF] * gen_torque * x[0]
    # the thrust as the tower mode's equation of motion sees it (mechanics: dx[2])
    damp = p[P_TWR_DAMP]
    thrust = p[P_TWR_MASS] * dx[2] + p[P_TWR_STIFF] * x[1] + damp * x[2]
    y[6] = thrust_centre(x[3]) * p[P_RADIUS] * thrust / BLADE_COUNT


@njit(cache=True, inline="always")
def outputs(x: np.ndarray, wind: float, pitch_cmd: float, gen_torque: float, p: np.ndarray, y: np.ndarray) -> None:
    """Outputs of the reduced model in the order of :data:`OUTPUT_NAMES`, written into ``y``.

    Parameters
    ----------
    x, wind, pitch_cmd, gen_torque, p
        The state (float64[5], SI), wind (m/s), pitch demand (rad), generator torque (N·m) and
        parameter array, as :func:`rhs` takes them.
    y : numpy.ndarray
        Output: float64[7], written: gen_speed (rad/s), tower_base_my (N·m), tower_top_acc
        (m/s²), tower_top_vel (m/s), pitch (rad), power (W, electrical), blade_root_my (N·m).
    """
    dx = np.empty(5)
    rhs(x, wind, pitch_cmd, gen_torque, p, dx)
    outputs_from(x, dx, gen_torque, p, y)
