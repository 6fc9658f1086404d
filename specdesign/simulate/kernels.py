"""The compiled closed-loop simulator: numba kernels of :mod:`specdesign.simulate`.

One ``@njit`` loop integrates a batch of runs in parallel (``prange`` over runs): per run, fixed-step
RK4 of the plant kernel pair with the wind linearly interpolated between its samples, the pitch
command and generator torque held over a step, and the discrete controller bank of
:mod:`specdesign.controller.scheduled` (output-blended locals, each with its integrator run
apart and clamped or conditionally integrated, and ROSCO's gain-scheduled PI) scheduled on the
filtered pitch command. See :mod:`specdesign.simulate` for the conventions.

The plant is a kernel pair ``rhs(x, wind, pitch_cmd, gen_torque, p, dx)`` /
``outputs(x, wind, pitch_cmd, gen_torque, p, y)``: the turbine's (:func:`specdesign.turbine.rhs`),
the linear one of this module (:func:`linear_rhs`, parameters from :func:`linear_plant_params`), or
any user pair (:func:`compiled_for` rebinds the same loop code to it). Everything here is driven
by :func:`specdesign.simulate.simulate`; nothing is meant to be called directly but
:func:`linear_plant_params`. The loop's inputs come in four records that ``simulate`` builds and
the loop unpacks (NamedTuples, which numba compiles): ``LoopSetup`` (what every run shares),
``Bank`` (the discrete controller bank), ``GainsPI`` (ROSCO's gain-scheduled PI) and ``Runs``
(per-run arrays, the sensor noise of :mod:`specdesign.controller.noise` among them).
"""
from __future__ import annotations

import math
import types
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numba import njit, prange
from numpy.typing import ArrayLike

if TYPE_CHECKING:  # pragma: no cover
    import control

from ..controller.peak_shaving import PEAK_SHAVING_STATES, peak_shaving_step, tsr_reference
from ..controller.torque import S_TQ, T_MODE, T_PC_REF, TORQUE_STATES, torque_step
from ..turbine import aero_loads as _turbine_aero
from ..turbine import mechanics as _turbine_mechanics
from ..turbine import outputs as _turbine_outputs
from ..turbine import outputs_from as _turbine_outputs_from
from ..turbine import rhs as _turbine_rhs
from ..turbine.kernel import mechanics_scalars as _turbine_mechanics_scalars

__all__ = [
    "KIND_TURBINE",
    "KIND_LINEAR",
    "KIND_USER",
    "NONFINITE",
    "linear_rhs",
    "linear_outputs",
    "linear_plant_params",
    "compiled_for",
    "run_callable",
]


# ----------------------------------------------------------------------------- linear kernel
# Parameter layout of the linear kernel: [nx, ny, u0(3), y0(ny), A, B(nx×3), C(ny×nx), D(ny×3)]
@njit(cache=True)
def linear_rhs(x: np.ndarray, wind: float, pitch_cmd: float, gen_torque: float, p: np.ndarray, dx: np.ndarray) -> None:
    """State derivative of the linear plant, ẋ = A x + B (u − u0), written into ``dx``.

    Parameters
    ----------
    x : numpy.ndarray
        Deviation state of the linear model, float64[nx].
    wind : float
        Rotor-effective wind speed (m/s), absolute.
    pitch_cmd : float
        Pitch command (rad), absolute.
    gen_torque : float
        Generator torque (N·m), absolute.
    p : numpy.ndarray
        Flat parameters from :func:`linear_plant_params`.
    dx : numpy.ndarray
        Output: float64[nx], the derivative (written).
    """
    nx = int(p[0])
    ny = int(p[1])
    du0 = wind - p[2]
    du1 = pitch_cmd - p[3]
    du2 = gen_torque - p[4]
    a = 5 + ny
    b = a + nx * nx
    for i in range(nx):
        s = p[b + 3 * i] * du0 + p[b + 3 * i + 1] * du1 + p[b + 3 * i + 2] * du2
        for j in range(nx):
            s += p[a + i * nx + j] * x[j]
        dx[i] = s


@njit(cache=True)
def linear_outputs(x: np.ndarray, wind: float, pitch_cmd: float, gen_torque: float, p: np.ndarray, y: np.ndarray) -> None:
    """Outputs of the linear plant, y = y0 + C x + D (u − u0) (SI), written into ``y``.

    Parameters
    ----------
    x, wind, pitch_cmd, gen_torque, p
        The deviation state (float64[nx]), the absolute wind (m/s), pitch command (rad) and
        generator torque (N·m), and the flat parameters, as :func:`linear_rhs` takes them.
    y : numpy.ndarray
        Output: float64[ny], the absolute outputs (written).
    """
    nx = int(p[0])
    ny = int(p[1])
    du0 = wind - p[2]
    du1 = pitch_cmd - p[3]
    du2 = gen_torque - p[4]
    c = 5 + ny + nx * nx + 3 * nx
    d = c + ny * nx
    for i in range(ny):
        s = p[5 + i] + p[d + 3 * i] * du0 + p[d + 3 * i + 1] * du1 + p[d + 3 * i + 2] * du2
        for j in range(nx):
            s += p[c + i * nx + j] * x[j]
        y[i] = s


def linear_plant_params(sys: control.StateSpace, u0: ArrayLike, y0: ArrayLike) -> np.ndarray:
    """Flat parameter array of the linear kernel (:func:`linear_rhs`, :func:`linear_outputs`).

    Layout: [nx, ny, u0(3), y0(ny), A, B(nx×3), C(ny×nx), D(ny×3)], matrices flattened in C order.

    Parameters
    ----------
    sys : control.StateSpace
        Deviation model with inputs wind (m/s), pitch_cmd (rad), gen_torque (N·m) in that order.
    u0 : array_like
        (3,) inputs at the operating point (SI).
    y0 : array_like
        (ny,) outputs at the operating point (SI).

    Returns
    -------
    numpy.ndarray
        The float64 parameter array.

    Raises
    ------
    ValueError
        If ``sys`` does not have 3 inputs.
    """
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    if B.shape[1] != 3:
        raise ValueError(f"linear plant must have 3 inputs (wind, pitch_cmd, gen_torque), got {B.shape[1]}")
    nx, ny = A.shape[0], C.shape[0]
    return np.concatenate([[nx, ny], np.asarray(u0, float), np.asarray(y0, float), A.ravel(), B.ravel(), C.ravel(), D.ravel()])


# ----------------------------------------------------------------------------- compiled loop
# The turbine's path through the loop is inlined into it (numba IR), as the turbine kernel's
# pieces are: a call passing arrays costs reference-count operations on every step. The other
# kernels' path (_krhs, _kout, _rk4) stays in calls: inlining it too (it holds the turbine's
# kernel as well) made the first, cold-cache compile several times longer.
@njit(cache=True, inline="always")
def _wind_at(w, wdt, t):
    s = t / wdt
    i = int(s)
    if i >= w.size - 1:
        return w[w.size - 1]
    f = s - i
    return w[i] * (1.0 - f) + w[i + 1] * f


#: Kernel kinds of the compiled loop: the turbine's kernel pair, the linear one, or a user pair
#: (:func:`compiled_for`).
KIND_TURBINE, KIND_LINEAR, KIND_USER = 0, 1, 2


@njit(cache=True)
def _krhs(kind, x, wind, pitch_cmd, gen_torque, p, dx):
    # The built-in kernels are called directly (a function passed as an argument would
    # defeat numba's on-disk cache); other kernels get rebound copies, see compiled_for.
    if kind == KIND_TURBINE:
        _turbine_rhs(x, wind, pitch_cmd, gen_torque, p, dx)
    else:
        linear_rhs(x, wind, pitch_cmd, gen_torque, p, dx)


@njit(cache=True)
def _kout(kind, x, wind, pitch_cmd, gen_torque, p, y):
    if kind == KIND_TURBINE:
        _turbine_outputs(x, wind, pitch_cmd, gen_torque, p, y)
    else:
        linear_outputs(x, wind, pitch_cmd, gen_torque, p, y)


@njit(cache=True)
def _rk4(kind, x, w, wdt, t, dt, beta_cmd, torque, p, k1, k2, k3, k4, xt):
    """One RK4 step of ``x``, its first stage ``k1`` (the derivative at t) already computed."""
    n = x.size
    for i in range(n):
        xt[i] = x[i] + 0.5 * dt * k1[i]
    wm = _wind_at(w, wdt, t + 0.5 * dt)
    _krhs(kind, xt, wm, beta_cmd, torque, p, k2)
    for i in range(n):
        xt[i] = x[i] + 0.5 * dt * k2[i]
    _krhs(kind, xt, wm, beta_cmd, torque, p, k3)
    for i in range(n):
        xt[i] = x[i] + dt * k3[i]
    _krhs(kind, xt, _wind_at(w, wdt, t + dt), beta_cmd, torque, p, k4)
    for i in range(n):
        x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True, inline="always")
def _turbine_rk4(x, w, wdt, t, dt, beta_cmd, torque, p, k1):
    """:func:`_rk4` of the turbine's kernel with the state in scalars between the stages (the
    same operations in the same order: the same numbers)."""
    x0, x1, x2, x3, x4 = x[0], x[1], x[2], x[3], x[4]
    a0, a1, a2, a3, a4 = k1[0], k1[1], k1[2], k1[3], k1[4]
    wm = _wind_at(w, wdt, t + 0.5 * dt)
    y0, y1, y2 = x0 + 0.5 * dt * a0, x1 + 0.5 * dt * a1, x2 + 0.5 * dt * a2
    y3, y4 = x3 + 0.5 * dt * a3, x4 + 0.5 * dt * a4
    q, th = _turbine_aero(p, y0, wm - y2, y3)
    b0, b1, b2, b3, b4 = _turbine_mechanics_scalars(y0, y1, y2, y3, y4, q, th, beta_cmd, torque, p)
    y0, y1, y2 = x0 + 0.5 * dt * b0, x1 + 0.5 * dt * b1, x2 + 0.5 * dt * b2
    y3, y4 = x3 + 0.5 * dt * b3, x4 + 0.5 * dt * b4
    q, th = _turbine_aero(p, y0, wm - y2, y3)
    c0, c1, c2, c3, c4 = _turbine_mechanics_scalars(y0, y1, y2, y3, y4, q, th, beta_cmd, torque, p)
    y0, y1, y2, y3, y4 = x0 + dt * c0, x1 + dt * c1, x2 + dt * c2, x3 + dt * c3, x4 + dt * c4
    q, th = _turbine_aero(p, y0, _wind_at(w, wdt, t + dt) - y2, y3)
    e0, e1, e2, e3, e4 = _turbine_mechanics_scalars(y0, y1, y2, y3, y4, q, th, beta_cmd, torque, p)
    x[0] = x0 + dt / 6.0 * (a0 + 2.0 * b0 + 2.0 * c0 + e0)
    x[1] = x1 + dt / 6.0 * (a1 + 2.0 * b1 + 2.0 * c1 + e1)
    x[2] = x2 + dt / 6.0 * (a2 + 2.0 * b2 + 2.0 * c2 + e2)
    x[3] = x3 + dt / 6.0 * (a3 + 2.0 * b3 + 2.0 * c3 + e3)
    x[4] = x4 + dt / 6.0 * (a4 + 2.0 * b4 + 2.0 * c4 + e4)


#: Divergence code of a non-finite output (else the index into the output limits).
NONFINITE = 63


class LoopSetup(NamedTuple):
    """What every run of a batch shares, besides its controller (a record the compiled loop unpacks).

    Attributes
    ----------
    kind : int
        The kernel kind (:data:`KIND_TURBINE`, :data:`KIND_LINEAR`, :data:`KIND_USER`).
    wdt, dt : float
        The wind's sample spacing and the step, s.
    nsteps, rec_every : int
        Steps per run and between records.
    ny : int
        Number of plant outputs.
    i_speed, i_vel, i_power, i_pitch : int
        Indices of the generator speed, tower-top velocity, power and pitch among them (the
        last two read by the torque law only).
    lim_idx : numpy.ndarray
        int64 indices of the outputs with a physical limit.
    lim_val : numpy.ndarray
        Those limits (SI).
    """

    kind: int
    wdt: float
    dt: float
    nsteps: int
    rec_every: int
    ny: int
    i_speed: int
    i_vel: int
    i_power: int
    i_pitch: int
    lim_idx: np.ndarray
    lim_val: np.ndarray


class Bank(NamedTuple):
    """The discrete controller bank of :func:`specdesign.controller.scheduled.controller_bank`,
    padded to K locals of nc states (a record the compiled loop unpacks).

    Attributes
    ----------
    Ad, Bd, Cd, Dd : numpy.ndarray
        (K, nc, nc), (K, nc, 2), (K, nc), (K, 2): each local by Tustin (inputs: the speed error
        rad/s, minus the tower-top velocity m/s; output: pitch, rad).
    Rq : numpy.ndarray
        (K,) gain of each local's integrator, run apart.
    Ns : numpy.ndarray
        (K,) int64, each local's slow states (0: PI-like, clamped).
    same : numpy.ndarray
        (K,) int64, the first local identical to each.
    sched_pitch : numpy.ndarray
        (K,) scheduling pitches, rad.
    sfilt : numpy.ndarray
        The scheduling filter (1 coefficient: first order; 5: second order).
    cmd_lim : numpy.ndarray
        (2,) the plant's pitch limits, rad.
    """

    Ad: np.ndarray
    Bd: np.ndarray
    Cd: np.ndarray
    Dd: np.ndarray
    Rq: np.ndarray
    Ns: np.ndarray
    same: np.ndarray
    sched_pitch: np.ndarray
    sfilt: np.ndarray
    cmd_lim: np.ndarray


class GainsPI(NamedTuple):
    """ROSCO's gain-scheduled PI (``form="gains"``) of the compiled loop.

    Attributes
    ----------
    on : bool
        False: no such PI (the bank's locals alone).
    kp, ki : numpy.ndarray
        (K,) gains at the scheduling pitches, rad per rad/s and rad per rad.
    Af, Bf, Cf, Df : numpy.ndarray
        The speed-error filter by Tustin.
    lim : numpy.ndarray
        (2,) limits of its integrator and output, rad.
    ps : numpy.ndarray
        ROSCO's peak shaving (:meth:`specdesign.controller.peak_shaving.PeakShaving.params`),
        which lifts the lower limit with its wind-speed estimate, or an empty array for none.
    """

    on: bool
    kp: np.ndarray
    ki: np.ndarray
    Af: np.ndarray
    Bf: np.ndarray
    Cf: np.ndarray
    Df: np.ndarray
    lim: np.ndarray
    ps: np.ndarray


class Runs(NamedTuple):
    """Per-run inputs of a batch, R runs along the first axis.

    Attributes
    ----------
    P : numpy.ndarray
        (R, n_p) kernel parameters.
    X0 : numpy.ndarray
        (R, nx) initial states.
    W : numpy.ndarray
        (R, n_w) wind, m/s.
    beta0, omega_ref, torque : numpy.ndarray
        (R,) trim pitch (rad), speed reference (rad/s), trim torque (N·m).
    TQ : numpy.ndarray
        (R, TORQUE_PARAMS) the torque law's parameters (mode 0: the torque held).
    noise : numpy.ndarray
        (R, 2, nsteps): what the controllers' measured generator speed (rad/s) and tower-top
        velocity (m/s) add at each step, or (R, 0, 0) for none (the measurement is then the
        output itself, bit for bit).
    """

    P: np.ndarray
    X0: np.ndarray
    W: np.ndarray
    beta0: np.ndarray
    omega_ref: np.ndarray
    torque: np.ndarray
    TQ: np.ndarray
    noise: np.ndarray


@njit(cache=True)
def _run_one(setup, bank, gpi, p, x, w, beta0, omega_ref, torque, tq, noise, Yr):
    """One run; returns −1, or 64·step + code at the first step where it diverged (code: the
    index of the output limit exceeded, or NONFINITE). ``setup``, ``bank``, ``gpi``: the
    batch's :class:`LoopSetup`, :class:`Bank` and :class:`GainsPI`; the rest is the run's row
    of :class:`Runs`. ``tq``: the torque law's parameters (mode 0: the torque held at
    ``torque``). ``same[q]``: the first local identical to local q
    (its matrices, integrator gain and slow-state count): identical locals see the same inputs
    from the same zero state, so their states and outputs stay equal, bit for bit, and only
    the first is run (ROSCO's gains form pads its bank with K empty locals, a design often
    puts the same ATD on every local)."""
    kind, wdt, dt, nsteps, rec_every = setup.kind, setup.wdt, setup.dt, setup.nsteps, setup.rec_every
    ny, i_speed, i_vel, i_power, i_pitch = setup.ny, setup.i_speed, setup.i_vel, setup.i_power, setup.i_pitch
    lim_idx, lim_val = setup.lim_idx, setup.lim_val
    Ad, Bd, Cd, Dd, Rq, Ns, same = bank.Ad, bank.Bd, bank.Cd, bank.Dd, bank.Rq, bank.Ns, bank.same
    sched_pitch, sfilt, cmd_lim = bank.sched_pitch, bank.sfilt, bank.cmd_lim
    pi_on, kp, ki, Af, Bf, Cf, Df, lim = gpi.on, gpi.kp, gpi.ki, gpi.Af, gpi.Bf, gpi.Cf, gpi.Df, gpi.lim
    ps = gpi.ps
    K = sched_pitch.size
    noisy = noise.shape[1] > 0
    nx = x.size
    nc = Ad.shape[1]
    nf = Af.shape[0]
    k1 = np.empty(nx)
    k2 = np.empty(nx)
    k3 = np.empty(nx)
    k4 = np.empty(nx)
    xt = np.empty(nx)
    y = np.empty(ny)
    xc = np.zeros((K, nc))
    xn = np.empty((K, nc))
    uk = np.empty(K)
    # Anti-windup (see simulate). Each local's integrator r_q/s runs apart from its state space
    # (trapezoid = Tustin). Ns[q] = 0 (PI-like): clamped as ROSCO clamps its integrator, the
    # trim pitch plus the integral within the limits. Ns[q] > 0 (its first Ns[q] states are
    # poles under SLOW_OMEGA): conditional integration, the integrator and those states frozen
    # while the command is saturated and their update would drive it further past the limit.
    iq = np.zeros(K)
    inc = np.zeros(K)
    dslow = np.zeros(K)
    ilo = cmd_lim[0] - beta0
    ihi = cmd_lim[1] - beta0
    e_prev = 0.0
    xf = np.zeros(nf)
    xfn = np.empty(nf)
    integ = 0.0
    ef_prev = 0.0
    bcmd = beta0
    bf = beta0
    # past inputs and outputs of a second-order scheduling filter (ROSCO's), at rest at the trim
    fu1 = beta0
    fu2 = beta0
    fy1 = beta0
    fy2 = beta0
    tq_on = tq[T_MODE] != 0.0
    tst = np.zeros(TORQUE_STATES)
    tst[S_TQ] = torque  # the torque law's last command: the trim torque, as ROSCO measures it at start
    # peak shaving (ROSCO's PC_MinPit from its wind estimate): the limit of the last step and of this one
    ps_on = ps.size > 0
    pst = np.zeros(PEAK_SHAVING_STATES)
    ps_last = lim[0]
    ps_min = lim[0]
    eshift = 0.0  # the pitch reference's shift from ROSCO's setpoint smoother (with peak shaving), rad/s
    qs = 0  # the last step's scheduling segment, where the search starts
    j = 0
    for k in range(nsteps):
        t = k * dt
        wt = _wind_at(w, wdt, t)
        if kind == KIND_TURBINE:
            # the aerodynamic loads at (x, t) serve the outputs and RK4's first stage: of the
            # inputs only the pitch command and the torque change between the two (mechanics)
            aq, athrust = _turbine_aero(p, x[0], wt - x[2], x[3])
            _turbine_mechanics(x, aq, athrust, bcmd, torque, p, k1)
            _turbine_outputs_from(x, k1, torque, p, y)
        else:
            _kout(kind, x, wt, bcmd, torque, p, y)
        for i in range(ny):
            if not math.isfinite(y[i]):
                return 64 * k + NONFINITE
        for i in range(lim_idx.size):
            if abs(y[lim_idx[i]]) > lim_val[i]:
                return 64 * k + i
        if k % rec_every == 0:
            for i in range(ny):
                Yr[i, j] = y[i]
            Yr[ny, j] = bcmd
            j += 1
        # what the controllers measure: the outputs, plus the sensor noise when there is some
        speed = y[i_speed]
        vel = y[i_vel]
        if noisy:
            speed += noise[0, k]
            vel += noise[1, k]
        # Both loops feed back with a minus sign: β = −C_β·ΔΩ_g − C_atd·ẋ_top.
        if ps_on:
            # ROSCO's order: its wind estimate first, on the last torque command, then the torque law on
            # the last step's limit. ROSCO's measured pitch is its own last command (ReadAvrSWAP), and
            # the estimator, the smoother and the state machine near that limit tell the difference.
            ps_last = ps_min
            ps_min = peak_shaving_step(ps, pst, speed, bcmd, torque, w[0], dt, k == 0)
            if k == 0:
                ps_last = ps_min
        if tq_on:  # ROSCO's torque law; its setpoint smoother moves the pitch reference
            if ps_on:
                torque, wref = torque_step(tq, tst, speed, y[i_power], bcmd, dt, k == 0, ps_last,
                                           tsr_reference(ps, pst))
                # ROSCO filters the speed, not its reference: the smoother's shift, which peak
                # shaving turns negative at the limit, enters the PI's error unfiltered (below)
                e = -(speed - tq[T_PC_REF])
                eshift = wref - tq[T_PC_REF]
            else:
                torque, wref = torque_step(tq, tst, speed, y[i_power], y[i_pitch], dt, k == 0)
                e = -(speed - wref)
        else:
            e = -(speed - omega_ref)
        v = -vel
        slow = False
        for q in range(K):
            if same[q] != q:
                continue
            s = Dd[q, 0] * e + Dd[q, 1] * v
            for i in range(nc):
                s += Cd[q, i] * xc[q, i]
            for i in range(nc):
                a = Bd[q, i, 0] * e + Bd[q, i, 1] * v
                for m in range(nc):
                    a += Ad[q, i, m] * xc[q, m]
                xn[q, i] = a
            if Rq[q] != 0.0:
                if Ns[q] == 0:
                    iq[q] = min(max(iq[q] + Rq[q] * 0.5 * dt * (e + e_prev), ilo), ihi)
                else:  # tentatively; undone below if the command saturates this way
                    slow = True
                    inc[q] = Rq[q] * 0.5 * dt * (e + e_prev)
                    iq[q] += inc[q]
                    d = inc[q]
                    for i in range(Ns[q]):
                        d += Cd[q, i] * (xn[q, i] - xc[q, i])
                    dslow[q] = d
                s += iq[q]
            uk[q] = s
        e_prev = e
        # Piecewise-linear weights in the filtered pitch, clamped at the ends: (1 − f) on q, f on q + 1.
        q = 0
        f = 0.0
        if K == 1 or bf <= sched_pitch[0]:
            q = 0
        elif bf >= sched_pitch[K - 1]:
            q = K - 1
        else:
            # the segment with sched_pitch[q] < bf <= sched_pitch[q + 1], searched from the last
            # step's (the filtered pitch moves little per step)
            q = qs
            while q > 0 and sched_pitch[q] >= bf:
                q -= 1
            while sched_pitch[q + 1] < bf:
                q += 1
            qs = q
            f = (bf - sched_pitch[q]) / (sched_pitch[q + 1] - sched_pitch[q])
        # Output blending (of the ATD locals only, in the scheduled-PI form).
        if f == 0.0:
            u = uk[same[q]]
        else:
            u = (1.0 - f) * uk[same[q]] + f * uk[same[q + 1]]
        if slow:
            over = beta0 + u - cmd_lim[1]
            if over <= 0.0:
                over = min(beta0 + u - cmd_lim[0], 0.0)
            if over != 0.0:  # saturated: freeze the slow parts that push further past the limit
                for r in range(K):
                    if same[r] == r and Ns[r] > 0 and Rq[r] != 0.0 and dslow[r] * over > 0.0:
                        iq[r] -= inc[r]
                        uk[r] -= inc[r]
                        for i in range(Ns[r]):
                            xn[r, i] = xc[r, i]
                if f == 0.0:
                    u = uk[same[q]]
                else:
                    u = (1.0 - f) * uk[same[q]] + f * uk[same[q + 1]]
        for r in range(K):
            if same[r] == r:
                for i in range(nc):
                    xc[r, i] = xn[r, i]
        if pi_on:
            # ROSCO's form: one filtered error, gains interpolated in β_f, one integrator of
            # K_i(β_f)·e_f (trapezoid = Tustin of 1/s, so frozen gains give the LTI exactly).
            ef = Df[0] * e
            for i in range(nf):
                ef += Cf[i] * xf[i]
            for i in range(nf):
                a = Bf[i] * e
                for m in range(nf):
                    a += Af[i, m] * xf[m]
                xfn[i] = a
            for i in range(nf):
                xf[i] = xfn[i]
            if ps_on:
                ef += eshift
            if f == 0.0:
                kpv = kp[q]
                kiv = ki[q]
            else:
                kpv = (1.0 - f) * kp[q] + f * kp[q + 1]
                kiv = (1.0 - f) * ki[q] + f * ki[q + 1]
            integ += kiv * 0.5 * dt * (ef + ef_prev)
            ef_prev = ef
            # ROSCO saturates the integrator (the trim pitch + ∫) and the PI output at the
            # pitch limits: anti-windup. With infinite limits this is the plain PI.
            lo = lim[0] - beta0
            hi = lim[1] - beta0
            if ps_on:  # peak shaving: the integrator and PI held at the last step's limit, the command at this one's
                lo = max(lim[0], ps_last) - beta0
                integ = min(max(integ, lo), hi)
                u += max(min(max(kpv * ef + integ, lo), hi), max(lim[0], ps_min) - beta0)
            else:
                integ = min(max(integ, lo), hi)
                u += min(max(kpv * ef + integ, lo), hi)
        if ps_on:
            bcmd = min(max(beta0 + u, cmd_lim[0], ps_min), cmd_lim[1])
        else:
            bcmd = min(max(beta0 + u, cmd_lim[0]), cmd_lim[1])
        if sfilt.size == 1:  # first order, exact discretisation: sfilt = [1 − exp(−ω_f·dt)]
            bf += sfilt[0] * (bcmd - bf)
        else:  # second order by Tustin, sfilt = [b0, b1, b2, a1, a2] normalised by a0
            bf = sfilt[0] * bcmd + sfilt[1] * fu1 + sfilt[2] * fu2 - sfilt[3] * fy1 - sfilt[4] * fy2
            fu2 = fu1
            fu1 = bcmd
            fy2 = fy1
            fy1 = bf
        if kind == KIND_TURBINE:
            _turbine_mechanics(x, aq, athrust, bcmd, torque, p, k1)
            _turbine_rk4(x, w, wdt, t, dt, bcmd, torque, p, k1)
        else:
            _krhs(kind, x, wt, bcmd, torque, p, k1)
            _rk4(kind, x, w, wdt, t, dt, bcmd, torque, p, k1, k2, k3, k4, xt)
    return -1


# nogil: a local campaign post-processes one wind speed while another is simulated
@njit(cache=True, parallel=True, nogil=True)
def _run_batch(setup, bank, gpi, runs, Y, status):
    """All runs, one per prange iteration; the controller bank is shared by the batch.
    ``status[r]``: −1, or where run r diverged (see :func:`_run_one`)."""
    for r in prange(runs.X0.shape[0]):
        x = runs.X0[r].copy()
        status[r] = _run_one(setup, bank, gpi, runs.P[r], x, runs.W[r], runs.beta0[r], runs.omega_ref[r],
                             runs.torque[r], runs.TQ[r], runs.noise[r], Y[r])


@njit(cache=True)
def _step_all(kind, P, X, W, wdt, t, dt, bcmd, torque, Y):
    """One RK4 step of every run with a given pitch command, then the outputs at t + dt.

    Serial: on the callable path the Python controller dominates, and a parallel launch per
    step would cost more than it saves."""
    for r in range(X.shape[0]):
        nx = X.shape[1]
        k1 = np.empty(nx)
        k2 = np.empty(nx)
        k3 = np.empty(nx)
        k4 = np.empty(nx)
        xt = np.empty(nx)
        x = X[r]
        _krhs(kind, x, _wind_at(W[r], wdt, t), bcmd[r], torque[r], P[r], k1)
        _rk4(kind, x, W[r], wdt, t, dt, bcmd[r], torque[r], P[r], k1, k2, k3, k4, xt)
        y = Y[r]
        _kout(kind, x, _wind_at(W[r], wdt, t + dt), bcmd[r], torque[r], P[r], y)


@njit(cache=True)
def _outputs_all(kind, P, X, W, wdt, t, bcmd, torque, Y):
    for r in range(X.shape[0]):
        y = Y[r]
        _kout(kind, X[r], _wind_at(W[r], wdt, t), bcmd[r], torque[r], P[r], y)


_REBOUND = {}


def compiled_for(rhs: Callable, outfn: Callable) -> tuple:
    """The compiled loop functions for a kernel pair.

    The turbine and linear kernels use the cached module functions. Any other pair gets
    copies of the same loop code whose global names ``_krhs``/``_kout`` point at that
    pair: one source for every kernel, compiled once per process for user kernels.

    Parameters
    ----------
    rhs : numba dispatcher
        ``@njit`` ``rhs(x, wind, pitch_cmd, gen_torque, p, dx)`` of the plant.
    outfn : numba dispatcher
        ``@njit`` ``outputs(x, wind, pitch_cmd, gen_torque, p, y)`` of the plant.

    Returns
    -------
    tuple
        ``(kind, run_batch, step_all, outputs_all)``: the kernel kind (:data:`KIND_TURBINE`,
        :data:`KIND_LINEAR`, or :data:`KIND_USER` for a rebound user pair) and the batch loop, the one-step
        function and the outputs function of the callable path (:func:`run_callable`).
    """
    if rhs is linear_rhs:
        return KIND_LINEAR, _run_batch, _step_all, _outputs_all
    if rhs is _turbine_rhs and outfn is _turbine_outputs:
        return KIND_TURBINE, _run_batch, _step_all, _outputs_all
    key = (rhs, outfn)
    if key not in _REBOUND:
        g = dict(_run_one.py_func.__globals__)

        def krhs(kind, x, wind, pitch_cmd, gen_torque, p, dx):
            rhs(x, wind, pitch_cmd, gen_torque, p, dx)

        def kout(kind, x, wind, pitch_cmd, gen_torque, p, y):
            outfn(x, wind, pitch_cmd, gen_torque, p, y)

        g["_krhs"], g["_kout"] = njit(krhs), njit(kout)

        def copy(f, **kw):
            fn = types.FunctionType(f.py_func.__code__, g, f.py_func.__name__)
            # a name of its own: numba names compiled symbols after the qualified name and a
            # per-process counter, and a module function loaded from the on-disk cache (named
            # in the process that saved it) could otherwise link to this copy's symbol
            fn.__qualname__ = f"{f.py_func.__qualname__}_rebound{len(_REBOUND)}"
            return njit(**kw)(fn)

        g["_rk4"] = copy(_rk4)
        g["_run_one"] = copy(_run_one)
        _REBOUND[key] = (KIND_USER, copy(_run_batch, parallel=True), copy(_step_all), copy(_outputs_all))
    return _REBOUND[key]


def _bad_inputs(given, t):
    """The measurements handed to the controller (``given``, as it left them) that were not
    finite at time ``t``, for the message of a non-finite command (a controller that passes a
    NaN sample through names nothing itself)."""
    bad = [(n, np.flatnonzero(~np.isfinite(np.asarray(v, dtype=float)))) for n, v in given.items()]
    bad = [f"{n} (run {int(r[0])})" for n, r in bad if r.size]
    return f" at t = {t:g} s; its measurements held NaN or inf in {', '.join(bad)}" if bad else f" at t = {t:g} s"


def run_callable(fn: Callable, step_all: Callable, outputs_all: Callable, kind: int, P: np.ndarray, X0: np.ndarray,
                 Wr: np.ndarray, wdt: float, dt: float, nsteps: int, rec_every: int, torque: np.ndarray,
                 beta0: np.ndarray, ny: int, Y: np.ndarray, names: Sequence[str], lim_idx: np.ndarray,
                 lim_val: np.ndarray, status: np.ndarray, noise: dict | None = None) -> None:
    """Run a batch with a Python controller ``fn(t, y) -> pitch_cmd`` (the slow path).

    ``fn`` is called once per step with ``y`` a dict of the outputs, each an array over all
    runs; the command it returns is held over the step. It may command the generator torque
    too by returning ``(pitch_cmd, gen_torque)``; otherwise the torque stays at ``torque``.
    If ``fn`` has a ``start`` method, ``fn.start(dt, wind, pitch, torque)`` is called once
    before the first step with the step (s) and, per run, the wind at t = 0 (m/s), the
    initial pitch (rad) and torque (N·m) (a stateful controller initialises itself there).
    The records are written into ``Y``, and the first divergence of each run into ``status``
    (checked at the record steps).

    Parameters
    ----------
    fn : callable
        ``fn(t, y)``: time (s), dict output name → (R,) array (SI) → (R,) absolute pitch
        command (rad), or a tuple of it and the (R,) generator torque on the rotor shaft (N·m).
    step_all, outputs_all : callable
        The one-step and outputs functions of :func:`compiled_for`.
    kind : int
        Kernel kind of :func:`compiled_for`.
    P : numpy.ndarray
        (R, n_p) kernel parameters per run.
    X0 : numpy.ndarray
        (R, nx) initial states.
    Wr : numpy.ndarray
        (R, n_w) wind per run (m/s).
    wdt : float
        Wind sample spacing (s).
    dt : float
        Simulation step (s).
    nsteps : int
        Number of steps.
    rec_every : int
        Steps between records.
    torque : numpy.ndarray
        (R,) generator torque (N·m).
    beta0 : numpy.ndarray
        (R,) initial pitch command (rad).
    ny : int
        Number of plant outputs.
    Y : numpy.ndarray
        Output: (R, ny + 1, n_rec) records, the outputs and the pitch command (written).
    names : sequence of str
        Output names, the keys of ``y``.
    lim_idx : numpy.ndarray
        Indices of the outputs with a physical limit.
    lim_val : numpy.ndarray
        Those limits (SI).
    status : numpy.ndarray
        Output: (R,) int64, −1 or 64·step + code where the run diverged (code: index into
        the limits, or :data:`NONFINITE`).
    noise : dict, optional
        Output name → (R, nsteps) sensor noise added to what ``fn`` is given at each step
        (SI; :class:`specdesign.controller.noise.SensorNoise`); the records keep the outputs.

    Raises
    ------
    ValueError
        If ``fn`` returns a command (pitch or torque) that is not finite or not of shape (R,).
    """
    X = X0.copy()
    R = X.shape[0]
    bcmd = beta0.copy()
    start = getattr(fn, "start", None)
    if callable(start):
        start(dt, Wr[:, 0].copy(), beta0.copy(), torque.copy())
    y = np.empty((R, ny))
    outputs_all(kind, P, X, Wr, wdt, 0.0, bcmd, torque, y)
    j = 0
    for k in range(nsteps):
        t = k * dt
        # checked at the record steps: a per-step numpy check would cost as much as the step
        if k % rec_every == 0:
            bad = ~np.all(np.isfinite(y), axis=1) | np.any(np.abs(y[:, lim_idx]) > lim_val, axis=1)
            if np.any(bad):
                r = np.flatnonzero(bad)
                nonfinite = ~np.all(np.isfinite(y[r]), axis=1)
                over = np.argmax(np.abs(y[r][:, lim_idx]) > lim_val, axis=1)
                status[r] = 64 * k + np.where(nonfinite, NONFINITE, over)
                return
        given = {n: y[:, i].copy() for i, n in enumerate(names)}
        for n, a in (noise or {}).items():
            given[n] += a[:, k]
        cmd = fn(t, given)
        if isinstance(cmd, tuple):
            if len(cmd) != 2:
                raise ValueError(f"controller callable must return pitch_cmd or (pitch_cmd, gen_torque), got {len(cmd)} items")
            cmd, torque = np.asarray(cmd[0], dtype=float), np.asarray(cmd[1], dtype=float)
            # a sum is finite iff every term is (barring overflow past 1e308): cheaper per step
            if torque.shape != (R,) or not math.isfinite(torque.sum()):
                raise ValueError(f"controller callable must return a finite generator torque (N·m) of shape ({R},), "
                                 f"got {torque.shape}" + _bad_inputs(given, t))
        cmd = np.asarray(cmd, dtype=float)
        if cmd.shape != (R,) or not math.isfinite(cmd.sum()):
            raise ValueError(f"controller callable must return a finite pitch command (rad) of shape ({R},), got {cmd.shape}"
                             + _bad_inputs(given, t))
        if k % rec_every == 0:
            Y[:, :ny, j] = y
            Y[:, ny, j] = bcmd  # the command held during the previous step, as in the compiled loop
            j += 1
        bcmd = cmd
        step_all(kind, P, X, Wr, wdt, t, dt, bcmd, torque, y)
