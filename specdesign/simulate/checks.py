"""The step checks of the simulator: a step ``dt`` the RK4 integration cannot resolve, or at which
the loop as simulated (command held over the step, controller discretised by Tustin) is
unstable, is refused before any run (:func:`specdesign.simulate.simulate` applies them).
"""
from __future__ import annotations

import math
import warnings
import weakref
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..closedloop import (
    ClosedLoopUnstableWarning,
    closed_loop_matrices,
    hidden_origin_poles,
    loop_parts,
    unstable_message,
    unstable_poles,
)

if TYPE_CHECKING:  # pragma: no cover
    from ..turbine.plant import KernelPlant

__all__ = ["MAX_STEP_EIGENVALUE", "check_step", "sampled_loop_radius", "check_loop_step", "checked_loop",
           "warn_unstable"]

# What the checks found, per plant object (dropped with it): a campaign checks every controller at
# every speed up front, and each simulation checks its own again; the plant's linearisation and
# the loop's poles are the same each time. Plants and controllers are not changed in place (the
# workbench's plant, loop and controller-bank caches assume it too).
_FASTEST: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # plant → {wind speed: fastest |λ|}
_LOOPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # plant → {(id(c), v, dt): (c, poles)}

#: Largest |λ|·dt accepted, λ the fastest eigenvalue of the linearised plant: RK4 is stable up
#: to about 2.8 and resolves a mode to a fraction of a percent per step at 1 (dt ≤ 0.32 s on
#: the IEA 15 MW, whose pitch actuator is at 3.14 rad/s); larger steps gave NaN or wrong DELs.
#: A bound against nonsense, not an accuracy target: the held command is a dt/2 delay, and
#: ROSCO's tower-base DEL (13-25 m/s, 3 seeds × 600 s) moves from dt = 0.02 s by ≤ 1.0 % at
#: dt = 0.1 s, ≤ 2.4 % at 0.2 s and ≤ 3.8 % at 0.3 s (most near rated). Besides this bound, a
#: step at which the sampled loop is unstable is refused (:func:`sampled_loop_radius`).
MAX_STEP_EIGENVALUE = 1.0


def check_step(plant: KernelPlant, wind_speeds: Sequence[float], dt: float) -> None:
    """Reject a step the RK4 integration cannot resolve (see :data:`MAX_STEP_EIGENVALUE`).

    Parameters
    ----------
    plant : KernelPlant
        The plant; without a ``linearize`` nothing is checked.
    wind_speeds : sequence of float
        Mean wind speeds (m/s) whose linearisations are checked.
    dt : float
        Simulation step (s).

    Raises
    ------
    ValueError
        If ``dt`` times the largest |eigenvalue| of a linearisation exceeds
        :data:`MAX_STEP_EIGENVALUE`; the message names the largest step accepted.

    Examples
    --------
    >>> from specdesign.simulate import turbine_plant
    >>> check_step(turbine_plant(), [19.0], 0.02)
    """
    if plant.linearize is None:
        return
    known = _FASTEST.setdefault(plant, {})
    for v in wind_speeds:
        if float(v) not in known:
            known[float(v)] = float(np.max(np.abs(np.linalg.eigvals(np.asarray(plant.linearize(v).A))), initial=0.0))
    fastest = max(known[float(v)] for v in wind_speeds)
    if fastest * dt > MAX_STEP_EIGENVALUE:
        raise ValueError(f"dt={dt:g} s is too large for this plant: its fastest mode has |λ| = {fastest:.3g} rad/s, so "
                         f"dt must be ≤ {MAX_STEP_EIGENVALUE / fastest:.3g} s (RK4 would be inaccurate or unstable)")


def sampled_loop_radius(plant: KernelPlant, controller: object, wind_speed: float, dt: float, *,
                        parts: tuple | None = None) -> float:
    """Spectral radius of the linearised closed loop as the simulator samples it at step ``dt``.

    The plant's linearisation at ``wind_speed`` advanced by one RK4 step with the pitch
    command held, the measurements taken at the start of the step, the controller (blended at
    the trim pitch, :func:`specdesign.closedloop.loop_parts`) discretised by Tustin at ``dt``:
    the loop the compiled kernel of :func:`specdesign.simulate.simulate` runs, linearised.
    Below 1 the sampled loop is stable. Modes at s = 0 the wind cannot excite
    (:func:`specdesign.closedloop.hidden_origin_poles`; z = 1 here) are left out, as the
    continuous check leaves them out.

    Parameters
    ----------
    plant : KernelPlant or TurbineModel
        The plant, with a linearisation.
    controller : control.LTI, loopshaping.controller.Controller or ScheduledController
        The controller.
    wind_speed : float
        Mean wind speed (m/s) of the linearisation.
    dt : float
        Simulation step (s).
    parts : tuple, optional
        The result of :func:`specdesign.closedloop.loop_parts` for these arguments, if at hand.

    Returns
    -------
    float
        The spectral radius (-).

    Examples
    --------
    >>> from specdesign.turbine import iea15mw, rosco_baseline
    >>> m = iea15mw()
    >>> bool(sampled_loop_radius(m, rosco_baseline(m, 19.0), 19.0, 0.02) < 1.0)
    True
    """
    if parts is None:
        parts = loop_parts(plant, controller, wind_speed)
    G, rows, K = parts
    A, B, C, D = (np.asarray(x, dtype=float) for x in (G.A, G.B, G.C, G.D))
    n = A.shape[0]
    hA = dt * A
    phi, gam, term = np.eye(n), np.eye(n), np.eye(n)
    for k in range(1, 5):  # RK4 on ẋ = Ax + Bu, u held: Φ = Σ_{k≤4} (hA)^k/k!, Γ = h·Σ_{k≤3} (hA)^k/(k+1)!·B
        term = term @ hA / k
        phi = phi + term
        if k < 4:
            gam = gam + term / (k + 1)
    gam = dt * gam @ B[:, 1]
    cm, dmu = C[rows], D[rows, 1]
    nk = K.nstates
    Ak, Bk, Ck, Dk = (np.asarray(x, dtype=float) for x in (K.A, K.B, K.C, K.D))
    Ak, Bk, Ck, Dk = Ak.reshape(nk, nk), Bk.reshape(nk, 2), Ck.reshape(1, nk), Dk.reshape(1, 2)
    if nk:  # Tustin, as control.c2d(..., "tustin") (scipy's bilinear transform) computes it
        ima = np.eye(nk) - 0.5 * dt * Ak
        bd = np.linalg.solve(ima, dt * Bk)
        Ak, Bk, Ck, Dk = np.linalg.solve(ima, np.eye(nk) + 0.5 * dt * Ak), bd, np.linalg.solve(ima.T, Ck.T).T, Dk + 0.5 * Ck @ bd
    # state [x; x_c; u_prev]: m_k = cm x_k + dmu u_{k−1}; u_k = −(Ck x_c + Dk m_k); x_c⁺ = Ak x_c + Bk m_k
    mx = np.hstack([cm, np.zeros((2, nk)), dmu[:, None]])
    u = -(np.hstack([np.zeros((1, n)), Ck, np.zeros((1, 1))]) + Dk @ mx)[0]
    M = np.zeros((n + nk + 1, n + nk + 1))
    M[:n, :n] = phi
    M[:n] += np.outer(gam, u)
    M[n:n + nk, n:n + nk] = Ak
    M[n:n + nk] += Bk @ mx
    M[-1] = u
    z = np.linalg.eigvals(M)
    if np.max(np.abs(z)) > 1.0 + _RADIUS_TOL:  # conserved modes, if any, sit at z = 1: drop them
        n0 = int(np.count_nonzero(hidden_origin_poles(*closed_loop_matrices(plant, controller, wind_speed, parts=parts))))
        if n0:
            z = np.delete(z, np.argsort(np.abs(z - 1.0))[:n0])
    return float(np.max(np.abs(z), initial=0.0))


#: Tolerance on the spectral radius of the sampled loop (:func:`sampled_loop_radius`).
_RADIUS_TOL = 1e-9


def check_loop_step(plant: KernelPlant, controller: object, wind_speed: float, dt: float,
                    parts: tuple | None = None) -> None:
    """Reject a step at which the sampled loop is unstable while the continuous one is stable.

    The controller's hold and Tustin map add phase lag (:func:`sampled_loop_radius`); the
    message names the largest step at which the sampled loop is stable.

    Parameters
    ----------
    plant, controller, wind_speed, dt, parts
        As :func:`sampled_loop_radius` takes them: the plant (with a linearisation), the
        controller, the linearisation's mean wind speed (m/s), the simulation step (s) and,
        optionally, the loop parts.

    Raises
    ------
    ValueError
        If the sampled loop is unstable at ``dt``.
    """
    v = wind_speed

    if parts is None:
        parts = loop_parts(plant, controller, v)

    def stable(h):
        return sampled_loop_radius(plant, controller, v, h, parts=parts) <= 1.0 + _RADIUS_TOL

    if stable(dt):
        return
    lo, hi = dt, dt
    while lo > 1e-6 * dt and not stable(lo):
        lo /= 2.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid) else (lo, mid)
        if hi - lo <= 1e-4 * hi:
            break
    q = 10.0 ** (math.floor(math.log10(lo)) - 2)
    limit = math.floor(lo / q) * q  # 3 significant digits, rounded down to a stable step
    name = getattr(controller, "name", None) or type(controller).__name__
    raise ValueError(f"dt={dt:g} s is too large for controller {name!r} at {v:g} m/s: the loop as simulated (the "
                     "command held over each step, the controller discretised by Tustin) is unstable although the "
                     f"continuous loop is stable; dt must be ≤ {limit:.3g} s (the smaller, the closer "
                     "to the continuous loop: dt = 0.02 s by default)")


def checked_loop(plant: KernelPlant, controller: object, wind_speed: float, dt: float) -> np.ndarray:
    """The linearised loop's unstable poles at ``wind_speed``; where there are none, the step checked.

    :func:`specdesign.closedloop.unstable_poles`, then, for a stable loop,
    :func:`check_loop_step`; the answer is kept per plant, controller, wind speed and step, so
    a campaign's up-front checks and its simulations check each loop once.

    Parameters
    ----------
    plant, controller, wind_speed, dt
        The loop, as :func:`sampled_loop_radius` takes them (a KernelPlant; wind speed in m/s, step
        in s).

    Returns
    -------
    numpy.ndarray
        The unstable closed-loop poles (1/s, complex); empty when the loop is stable (and then
        the step is one at which the sampled loop is stable too).

    Raises
    ------
    ValueError
        If the sampled loop is unstable at ``dt`` where the continuous one is stable.

    Examples
    --------
    >>> from specdesign.simulate import turbine_plant
    >>> from specdesign.turbine import iea15mw, rosco_baseline
    >>> m = iea15mw()
    >>> checked_loop(turbine_plant(m), rosco_baseline(m, 19.0), 19.0, 0.02).size
    0
    """
    key = (id(controller), float(wind_speed), float(dt))
    known = _LOOPS.setdefault(plant, {})
    hit = known.get(key)
    if hit is not None and hit[0] is controller:
        return hit[1].copy()
    parts = loop_parts(plant, controller, wind_speed)
    bad = unstable_poles(plant, controller, wind_speed, parts=parts)
    if not bad.size:
        check_loop_step(plant, controller, wind_speed, dt, parts)
    if len(known) >= _LOOPS_SIZE:
        try:  # another thread (a threaded dask worker) may have changed it meanwhile: drop any entry
            known.pop(next(iter(known)), None)
        except (RuntimeError, StopIteration):
            pass
    # the controller is held with its answer, so its id cannot be reused while the entry lives
    known[key] = (controller, bad)
    return bad.copy()


#: Loop answers kept per plant (:func:`checked_loop`), oldest dropped first.
_LOOPS_SIZE = 1024


def warn_unstable(plant: KernelPlant, controller: object, wind_speeds: Sequence[float], dt: float) -> None:
    """Warn where the linearised loop is unstable; where it is stable, check the step.

    Saturations may keep a run of an unstable loop bounded (a limit cycle between the pitch
    limits), but it is no result: a ``ClosedLoopUnstableWarning`` says so. Where the loop is
    stable, a step ``dt`` at which the sampled loop is not is rejected (:func:`check_loop_step`).

    Parameters
    ----------
    plant : KernelPlant
        The plant; without a ``linearize`` nothing is checked.
    controller : control.LTI, loopshaping.controller.Controller or ScheduledController
        The controller.
    wind_speeds : sequence of float
        Mean wind speeds (m/s) to check.
    dt : float
        Simulation step (s).

    Raises
    ------
    ValueError
        If the sampled loop is unstable at ``dt`` where the continuous one is stable.
    """
    if plant.linearize is None:
        return
    for v in wind_speeds:
        bad = checked_loop(plant, controller, v, dt)
        if bad.size:
            tail = ("; the simulation runs on the pitch limits (a limit cycle, no result) if it does not diverge"
                    if plant.pitch_limits is not None else "; the simulated response grows without bound")
            warnings.warn(unstable_message(controller, v, bad) + tail, ClosedLoopUnstableWarning, stacklevel=3)
