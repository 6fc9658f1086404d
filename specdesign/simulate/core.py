"""The simulator's Python API: :func:`simulate`, its plant (:class:`KernelPlant`,
:func:`turbine_plant`) and result (:class:`SimulationResult`), and the step checks.

See :mod:`specdesign.simulate` for the conventions (signs, scheduling, anti-windup).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._checks import positive_scalar
from ..wind import wind_series
from .controllers import controller_bank, is_lti_like
from .kernels import NONFINITE, compiled_for, linear_outputs, linear_plant_params, linear_rhs, run_callable
from .schedule import ScheduledController

__all__ = [
    "MAX_STEP_EIGENVALUE",
    "WIND_MEAN_TOLERANCE",
    "SimulationDivergedError",
    "KernelPlant",
    "turbine_plant",
    "SimulationResult",
    "simulate",
    "check_step",
    "sampled_loop_radius",
    "check_loop_step",
]

#: Largest |λ|·dt accepted, λ the fastest eigenvalue of the linearised plant: RK4 is stable up
#: to about 2.8 and resolves a mode to a fraction of a percent per step at 1 (dt ≤ 0.32 s on
#: the IEA 15 MW, whose pitch actuator is at 3.14 rad/s); larger steps gave NaN or wrong DELs.
#: A bound against nonsense, not an accuracy target: the held command is a dt/2 delay, and
#: ROSCO's tower-base DEL (13-25 m/s, 3 seeds × 600 s) moves from dt = 0.02 s by ≤ 1.0 % at
#: dt = 0.1 s, ≤ 2.4 % at 0.2 s and ≤ 3.8 % at 0.3 s (most near rated). Besides this bound, a
#: step at which the sampled loop is unstable is refused (:func:`sampled_loop_radius`).
MAX_STEP_EIGENVALUE = 1.0

#: Largest difference (m/s) between the mean of a given wind record and its ``wind_speeds``
#: entry: half an IEC 2 m/s bin. The trim, the linearisation and the scheduling all use
#: ``wind_speeds``, so a record from another bin would be simulated about the wrong point.
WIND_MEAN_TOLERANCE = 1.0


class SimulationDivergedError(RuntimeError):
    """A run left the physically possible range (non-finite state, or an output beyond
    :attr:`KernelPlant.output_limits`): the closed loop is unstable or the step too large."""


# ----------------------------------------------------------------------------- plant
@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class KernelPlant:
    """A plant given by a compiled kernel pair, as :mod:`specdesign.turbine` defines it.

    rhs, outputs : ``@njit`` functions ``rhs(x, wind, pitch_cmd, gen_torque, p, dx)`` and
        ``outputs(x, wind, pitch_cmd, gen_torque, p, y)`` (SI units).
    params : flat float64 parameter array ``p``.
    output_names : names of ``y`` in order; must contain ``gen_speed`` (rad/s),
        ``tower_top_vel`` (m/s) and ``pitch`` (rad).
    trim : ``trim(wind_speed) -> (x0, pitch0 rad, gen_torque N·m)`` steady operating point.
    rated_speed : generator-speed reference Ω_rated (rad/s).
    linearize : optional ``linearize(wind_speed) -> control.StateSpace`` with inputs
        (wind, pitch_cmd, gen_torque) and outputs ``output_names``, deviations from trim.
    pitch_limits : optional (min, max) pitch command (rad): every controller's command is
        saturated there, with anti-windup (see :func:`simulate`).
    output_limits : dict output name → largest physically possible |y| (SI); a run whose
        output leaves it, or turns non-finite, has diverged and :func:`simulate` raises.
    """

    rhs: object
    outputs: object
    params: np.ndarray = field(repr=False)
    output_names: tuple
    trim: object = field(repr=False)
    rated_speed: float
    linearize: object = field(default=None, repr=False)
    name: str = "plant"
    pitch_limits: tuple | None = None
    output_limits: dict = field(default_factory=dict)

    def index(self, name: str) -> int:
        if name not in self.output_names:
            raise ValueError(f"output {name!r} not among the plant outputs {self.output_names}")
        return self.output_names.index(name)


def turbine_plant(model=None) -> KernelPlant:
    """Wrap a :class:`specdesign.turbine.TurbineModel` (default: ``iea15mw()``) as a KernelPlant."""
    from .. import turbine

    if model is None:
        model = turbine.iea15mw()
    if isinstance(model, KernelPlant):
        return model

    def trim(v):
        op = model.trim(v)
        return np.array(op.x, dtype=float), float(op.pitch), float(op.gen_torque)

    return KernelPlant(
        rhs=turbine.rhs,
        outputs=turbine.outputs,
        params=np.ascontiguousarray(model.kernel_params(), dtype=float),
        output_names=tuple(turbine.OUTPUT_NAMES),
        trim=trim,
        rated_speed=float(model.rated_rotor_speed),
        linearize=model.linearize,
        name=model.name,
        pitch_limits=(float(model.pitch_min), float(model.pitch_max)),
        # divergence: twice the rated speed is far past any overspeed trip; a tower-base moment
        # of 10 m of tower-top deflection is far past the tower's strength
        output_limits={"gen_speed": 2.0 * float(model.rated_rotor_speed),
                       "tower_base_my": 10.0 * float(model.tower_base_moment_per_m)},
    )



# ----------------------------------------------------------------------------- results
@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class SimulationResult:
    """Time series of a batch of runs, shaped (n_wind_speeds, n_seeds, n_samples).

    time : (n,) s, from the end of the discarded transient (starts at 0).
    wind_speeds : (W,) mean wind speeds, m/s. seeds : (S,) integer seeds (None if the wind
    was given). outputs : dict output name → (W, S, n) array in SI, plus ``pitch_cmd`` (rad)
    and ``wind`` (m/s, the rotor-effective wind that drove the run).
    dt : sample spacing of ``time`` (s); sim_dt : integration step (s); linear : True if
    the linearised plant was integrated; controller : label.
    """

    time: np.ndarray
    wind_speeds: np.ndarray
    seeds: np.ndarray | None
    outputs: dict = field(repr=False)
    dt: float
    sim_dt: float
    linear: bool = False
    controller: str = "controller"

    def __getitem__(self, name):
        if name not in self.outputs:
            raise KeyError(f"no output {name!r}; available: {sorted(self.outputs)}")
        return self.outputs[name]

    @property
    def duration(self) -> float:
        """Length of each recorded run, s (n_samples × dt)."""
        return float(self.time.size * self.dt)


def simulate(plant, controller, wind_speeds, *, seeds=None, wind=None, duration=600.0, dt=0.02,
             record_dt=0.1, transient=60.0, wind_dt=None, turbulence_class="B", linear=False,
             wind_rotor_radius=None, wind_mean_tol=WIND_MEAN_TOLERANCE) -> SimulationResult:
    """Simulate the closed loop for every (wind speed, seed), all runs batched.

    Parameters
    ----------
    plant : TurbineModel (e.g. ``turbine.iea15mw()``) or KernelPlant.
    controller : LTI, loopshaping Controller, ScheduledController, or callable ``f(t, y)``
        (see the module docstring for the sign convention and the callable contract).
    wind_speeds : mean wind speeds, m/s (W of them).
    seeds : integer seeds (S of them) for the turbulent wind; or give ``wind`` instead.
    wind : optional (W, S, n_w) rotor-effective wind in m/s sampled every ``wind_dt`` s,
        covering ``transient + duration``.
    wind_dt : spacing of the wind samples, s (default ``record_dt`` when synthesised; keep it
        a multiple of ``dt`` so the interpolated wind is smooth within each RK4 step).
    turbulence_class : IEC NTM class of the synthesised wind. wind_rotor_radius : rotor radius
        for the rotor-effective spectrum, m (default: the IEA 15 MW's).
    duration : recorded length of each run, s. transient : simulated before the record
        starts (discarded), s. dt : integration and controller step, s. record_dt : sample
        spacing of the recorded outputs, s (a multiple of ``dt``).
    linear : integrate the linearisation at each wind speed instead of the nonlinear model.
    wind_mean_tol : largest |mean of a given wind record − its wind speed|, m/s (default
        :data:`WIND_MEAN_TOLERANCE`).

    Returns
    -------
    SimulationResult with outputs (W, S, n) for every plant output, ``pitch_cmd`` and ``wind``.

    Raises
    ------
    ValueError
        for a step ``dt`` above 1/|λ|max of the linearised plant (:data:`MAX_STEP_EIGENVALUE`),
        or at which the loop as simulated (command held over the step, controller by Tustin)
        is unstable while the continuous loop is stable (:func:`sampled_loop_radius`; both
        limits are in the message), or for a wind record whose mean is more than
        ``wind_mean_tol`` off its wind speed.
    SimulationDivergedError
        when a run diverges (non-finite, or an output beyond ``plant.output_limits``: for the
        turbine twice the rated generator speed or the tower-base moment of 10 m of tower-top
        deflection), naming its wind speed, seed and time.

    Pitch limits and anti-windup: with ``plant.pitch_limits`` (the turbine's pitch range) the
    command of every compiled controller is saturated there, and no controller winds up:

    * ROSCO's form of a scheduled PI clamps its integrator (as absolute pitch) and its output
      at the limits, as ROSCO does (see :class:`ScheduledController`).
    * An LTI pitch controller (``rosco_baseline``, a designed one, each local of an
      output-blended schedule) runs its pole at s = 0 as a separate integrator
      (:func:`split_integrator`). If the rest has no pole slower than :data:`SLOW_OMEGA`
      (PI-like: ``rosco_baseline``, whose speed filter is at 1 rad/s), the integral is the
      pitch the controller holds, and it is clamped as ROSCO clamps its own: the trim pitch
      plus the integral within the limits (``rosco_baseline`` then runs exactly as ROSCO's
      form at frozen gains). Otherwise (a lag, an H∞ controller: slow modes that integrate
      the error too, with residues that may be far larger than the integral itself)
      conditional integration: while the command is saturated, the integrator and those slow
      modes are frozen at every step where their update would drive it further past the
      limit. The rest (filters, lead-lag, notches, ATD) is left running: with poles faster
      than :data:`SLOW_OMEGA` it cannot wind up over an excursion to a limit. (An ATD
      controller's own pole at 0, as a 1×2 H∞ controller split in two carries, integrates
      the tower-top velocity, i.e. the tower deflection, which is bounded.)

    Where the command never reaches a limit the result is that of the unsaturated loop, bit
    for bit (for a PI-like controller, as for ROSCO, where its integral does not either: the
    two part only next to a limit). A callable controller's command is used as it is (the
    plant's actuator still stops at its limits; the callable sees the pitch in ``y["pitch"]``).
    """
    plant = turbine_plant(plant) if not isinstance(plant, KernelPlant) else plant
    dt = positive_scalar(dt, "dt")
    duration = positive_scalar(duration, "duration")
    record_dt = positive_scalar(record_dt, "record_dt")
    transient = float(transient)
    if not transient >= 0:
        raise ValueError(f"transient={transient!r} must be >= 0 s")
    rec_every = int(round(record_dt / dt))
    if rec_every < 1 or abs(rec_every * dt - record_dt) > 1e-9 * record_dt:
        raise ValueError(f"record_dt={record_dt} must be a whole multiple of dt={dt}")
    vs = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    if vs.ndim != 1 or not np.all(np.isfinite(vs)) or np.any(vs <= 0):
        raise ValueError(f"wind_speeds must be a 1-D array of positive mean wind speeds in m/s, got {wind_speeds!r}")
    total = transient + duration
    nsteps = int(round(total / dt))
    if wind is None:
        if seeds is None:
            raise ValueError("give either seeds (turbulent wind is synthesised) or wind (W, S, n) in m/s")
        seeds = np.atleast_1d(np.asarray(seeds, dtype=np.int64))
        wind_dt = record_dt if wind_dt is None else positive_scalar(wind_dt, "wind_dt")
        radius = wind_rotor_radius
        if radius is None:
            from .. import turbine

            radius = turbine.iea15mw().rotor_radius
        wind = wind_series(radius, vs, seeds, total + wind_dt, wind_dt, turbulence_class)
    else:
        wind = np.asarray(wind, dtype=float)
        if wind.ndim != 3 or wind.shape[0] != vs.size:
            raise ValueError(f"wind must have shape (n_wind_speeds={vs.size}, n_seeds, n_samples), got {wind.shape}")
        if wind_dt is None:
            raise ValueError("wind_dt (s) is required with an explicit wind array")
        wind_dt = positive_scalar(wind_dt, "wind_dt")
        if (wind.shape[2] - 1) * wind_dt < total - 1e-9:
            raise ValueError(f"wind covers {(wind.shape[2] - 1) * wind_dt:g} s but transient + duration = {total:g} s")
        if not np.all(np.isfinite(wind)):
            raise ValueError("wind contains NaN or inf")
        # the record's own mean (a short run over part of a record sees ~1 m/s of turbulence in its mean)
        means = wind.mean(axis=2)
        off = np.abs(means - vs[:, None]) > positive_scalar(wind_mean_tol, "wind_mean_tol")
        if np.any(off):
            iw, js = np.argwhere(off)[0]
            raise ValueError(f"wind[{iw}, {js}] has mean {means[iw, js]:.3f} m/s but wind_speeds[{iw}] = {vs[iw]:g} m/s "
                             f"(tolerance {wind_mean_tol:g} m/s): pass the record's own mean wind speed, which sets "
                             "the trim and the scheduling")
        seeds = None if seeds is None else np.atleast_1d(np.asarray(seeds))
        if seeds is not None and seeds.shape != (wind.shape[1],):
            raise ValueError(f"seeds label the records of wind: {wind.shape[1]} of them, got {seeds.size}")
    W, S = wind.shape[:2]
    R = W * S
    Wr = np.ascontiguousarray(wind.reshape(R, -1))
    ny = len(plant.output_names)
    i_speed, i_vel = plant.index("gen_speed"), plant.index("tower_top_vel")

    check_step(plant, vs, dt)
    trims = [plant.trim(v) for v in vs]
    beta0 = np.repeat([t[1] for t in trims], S)
    torque = np.repeat([t[2] for t in trims], S)
    if linear:
        if plant.linearize is None:
            raise ValueError("linear=True needs a plant with a linearize method")
        rhs, outfn = linear_rhs, linear_outputs
        rows, x0s = [], []
        for v, (x0, b0, tq) in zip(vs, trims):
            sys = plant.linearize(v)
            y0 = np.empty(ny)
            plant.outputs(np.asarray(x0, float), float(v), b0, tq, plant.params, y0)
            rows.append(linear_plant_params(sys, [v, b0, tq], y0))
            x0s.append(np.zeros(sys.nstates))
        P = np.repeat(np.stack(rows), S, axis=0)
        X0 = np.repeat(np.stack(x0s), S, axis=0)
    else:
        rhs, outfn = plant.rhs, plant.outputs
        P = np.ascontiguousarray(np.broadcast_to(plant.params, (R, plant.params.size)))
        X0 = np.repeat(np.stack([np.asarray(t[0], float) for t in trims]), S, axis=0)
    X0 = np.ascontiguousarray(X0)
    kind, run_batch, step_all, outputs_all = compiled_for(rhs, outfn)
    n_rec = (nsteps + rec_every - 1) // rec_every
    Y = np.empty((R, ny + 1, n_rec))
    omega_ref = np.full(R, plant.rated_speed)
    lim_names = tuple(plant.output_limits)
    lim_idx = np.array([plant.index(n) for n in lim_names], dtype=np.int64)
    lim_val = np.array([float(plant.output_limits[n]) for n in lim_names])
    status = np.full(R, -1, dtype=np.int64)

    if callable(controller) and not is_lti_like(controller) and not isinstance(controller, ScheduledController):
        label = getattr(controller, "__name__", "callable")
        run_callable(controller, step_all, outputs_all, kind, P, X0, Wr, wind_dt, dt, nsteps, rec_every, torque, beta0, ny, Y,
                      plant.output_names, lim_idx, lim_val, status)
        _raise_diverged(status, vs, seeds, S, dt, transient, lim_names, lim_val, str(label), linear)
    else:
        label = getattr(controller, "name", "controller")
        _warn_unstable(plant, controller, vs, dt)
        sched_pitch, mats, fw, pi = controller_bank(controller, dt)
        K = sched_pitch.size
        nc = max(1, max(m[0].shape[0] for m in mats))
        Ad = np.zeros((K, nc, nc))
        Bd = np.zeros((K, nc, 2))
        Cd = np.zeros((K, nc))
        Dd = np.zeros((K, 2))
        Rq, Ns = np.zeros(K), np.zeros(K, dtype=np.int64)
        for q, (A, B, C, D, r, ns) in enumerate(mats):
            n = A.shape[0]
            Ad[q, :n, :n], Bd[q, :n, :], Cd[q, :n], Dd[q, :], Rq[q], Ns[q] = A, B, C, D, r, ns
        a_filt = 1.0 - math.exp(-fw * dt)
        cmd_lim = np.array((-np.inf, np.inf) if plant.pitch_limits is None else plant.pitch_limits, dtype=float)
        if pi is None:
            pi_on, kp, ki = False, np.zeros(K), np.zeros(K)
            Af, Bf, Cf, Df, lim = np.zeros((0, 0)), np.zeros(0), np.zeros(0), np.zeros(1), np.array([-np.inf, np.inf])
        else:
            pi_on, (kp, ki, Af, Bf, Cf, Df, lim) = True, pi
            # the PI's integrator never holds more than the command can reach: its own limits
            # narrowed to the plant's (the plant's alone when it has none), so it cannot wind up
            lim = np.array([max(lim[0], cmd_lim[0]), min(lim[1], cmd_lim[1])])
        run_batch(kind, P, X0, Wr, wind_dt, dt, nsteps, rec_every, Ad, Bd, Cd, Dd, np.ascontiguousarray(sched_pitch),
                  beta0, omega_ref, torque, a_filt, i_speed, i_vel, ny, Y, pi_on,
                  *(np.ascontiguousarray(a, dtype=float) for a in (kp, ki, Af, Bf, Cf, Df, lim, cmd_lim)),
                  lim_idx, lim_val, Rq, Ns, status)
    _raise_diverged(status, vs, seeds, S, dt, transient, lim_names, lim_val, str(label), linear)

    skip = int(round(transient / record_dt))
    t_rec = np.arange(n_rec) * record_dt
    keep = slice(skip, skip + int(round(duration / record_dt)))
    outs = {name: Y[:, i, keep].reshape(W, S, -1) for i, name in enumerate(plant.output_names)}
    outs["pitch_cmd"] = Y[:, ny, keep].reshape(W, S, -1)
    # The wind at the recorded instants, for spectra and plots.
    idx_t = t_rec[keep]
    outs["wind"] = np.stack([np.interp(idx_t, np.arange(Wr.shape[1]) * wind_dt, Wr[r]) for r in range(R)]).reshape(W, S, -1)
    return SimulationResult(
        time=idx_t - idx_t[0], wind_speeds=vs, seeds=seeds, outputs=outs, dt=record_dt, sim_dt=dt,
        linear=linear, controller=str(label),
    )


def check_step(plant, vs, dt):
    """Reject a step the RK4 integration cannot resolve (see :data:`MAX_STEP_EIGENVALUE`)."""
    if plant.linearize is None:
        return
    fastest = max(float(np.max(np.abs(np.linalg.eigvals(np.asarray(plant.linearize(v).A))), initial=0.0)) for v in vs)
    if fastest * dt > MAX_STEP_EIGENVALUE:
        raise ValueError(f"dt={dt:g} s is too large for this plant: its fastest mode has |λ| = {fastest:.3g} rad/s, so "
                         f"dt must be ≤ {MAX_STEP_EIGENVALUE / fastest:.3g} s (RK4 would be inaccurate or unstable)")


def sampled_loop_radius(plant, controller, wind_speed, dt, *, parts=None) -> float:
    """Spectral radius of the linearised closed loop as :func:`simulate` samples it at step ``dt`` (s).

    The plant's linearisation at ``wind_speed`` (m/s) advanced by one RK4 step with the pitch
    command held, the measurements taken at the start of the step, the controller (blended at
    the trim pitch, :func:`specdesign.closedloop.loop_parts`; ``parts``: its result, if at
    hand) discretised by Tustin at ``dt``: the loop the compiled kernel runs, linearised. Below
    1 the sampled loop is stable. Modes at s = 0 the wind cannot excite
    (:func:`specdesign.closedloop.hidden_origin_poles`; z = 1 here) are left out, as the
    continuous check leaves them out.
    """
    from ..closedloop import closed_loop_matrices, hidden_origin_poles, loop_parts

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


def check_loop_step(plant, controller, v, dt, parts=None):
    """Reject a step at which the sampled loop is unstable while the continuous one is stable
    (the controller's hold and Tustin map add phase lag): name the largest step that is not."""
    from ..closedloop import loop_parts

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


def _warn_unstable(plant, controller, vs, dt):
    """Warn (ClosedLoopUnstableWarning) where the linearised loop is unstable: saturations
    may keep such a run bounded (a limit cycle between the pitch limits), but it is no result.
    Where it is stable, reject a step ``dt`` at which the sampled loop is not (:func:`check_loop_step`)."""
    if plant.linearize is None:
        return
    import warnings

    from ..closedloop import ClosedLoopUnstableWarning, loop_parts, unstable_message, unstable_poles

    for v in vs:
        parts = loop_parts(plant, controller, v)
        bad = unstable_poles(plant, controller, v, parts=parts)
        if bad.size:
            tail = ("; the simulation runs on the pitch limits (a limit cycle, no result) if it does not diverge"
                    if plant.pitch_limits is not None else "; the simulated response grows without bound")
            warnings.warn(unstable_message(controller, v, bad) + tail, ClosedLoopUnstableWarning, stacklevel=3)
        else:
            check_loop_step(plant, controller, v, dt, parts)


def _raise_diverged(status, vs, seeds, S, dt, transient, lim_names, lim_val, label, linear):
    bad = np.flatnonzero(status >= 0)
    if not bad.size:
        return
    r = int(bad[0])
    step, code = divmod(int(status[r]), 64)
    what = ("a non-finite output" if code == NONFINITE
            else f"|{lim_names[code]}| above its physical limit {lim_val[code]:.4g}")
    seed = f"seed {seeds[r % S]}" if seeds is not None else f"record {r % S}"
    raise SimulationDivergedError(
        f"{'linear ' if linear else ''}simulation with controller {label!r} diverged at wind speed {vs[r // S]:g} m/s, "
        f"{seed}, t = {step * dt:.1f} s into the run (the record starts after {transient:g} s) ({what}; "
        f"{bad.size} of {status.size} runs): "
        "the closed loop is unstable at this operating point, or dt is too large")
