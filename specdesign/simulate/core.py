"""The simulator's Python API: :func:`simulate` and its result (:class:`SimulationResult`). Its
plant is :class:`specdesign.turbine.plant.KernelPlant`; the step checks it applies are in
:mod:`specdesign.simulate.checks`.

See :mod:`specdesign.simulate` for the conventions (signs, scheduling, anti-windup).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from .._checks import positive_scalar
from ..controller.lti import is_lti_like
from ..controller.noise import MEASURED, SensorNoise
from ..controller.scheduled import ScheduledController, controller_bank, schedule_filter_coefficients
from ..controller.torque import TORQUE_PARAMS, TorqueLaw
from ..turbine import iea15mw
from ..turbine.plant import KernelPlant, turbine_plant
from ..wind import RECORD_LENGTH, wind_series
from .checks import check_step, warn_unstable
from .kernels import (NONFINITE, Bank, GainsPI, LoopSetup, Runs, compiled_for, linear_outputs, linear_plant_params,
                      linear_rhs, run_callable)

if TYPE_CHECKING:  # pragma: no cover
    from ..turbine import TurbineModel

__all__ = [
    "WIND_MEAN_TOLERANCE",
    "SimulationDivergedError",
    "SimulationResult",
    "simulate",
]

#: Largest difference (m/s) between the mean of a given wind record and its ``wind_speeds``
#: entry: half an IEC 2 m/s bin. The trim, the linearisation and the scheduling all use
#: ``wind_speeds``, so a record from another bin would be simulated about the wrong point.
WIND_MEAN_TOLERANCE = 1.0
#: python-control's automatic system names ("sys[4]"): not the user's, so not used as a label.
_AUTO_NAME = re.compile(r"sys\[\d+\]")


class SimulationDivergedError(RuntimeError):
    """A run left the physically possible range: the closed loop is unstable or the step too large.

    Raised by :func:`simulate` for a non-finite state, or an output beyond
    :attr:`KernelPlant.output_limits`; the message names the wind speed, seed and time.
    """


# ----------------------------------------------------------------------------- results
@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class SimulationResult:
    """Time series of a batch of runs, shaped (n_wind_speeds, n_seeds, n_samples).

    Index it by output name: ``result["gen_speed"]``.

    Parameters
    ----------
    time : numpy.ndarray
        (n,) time (s), from the end of the discarded transient (starts at 0).
    wind_speeds : numpy.ndarray
        (W,) mean wind speeds (m/s).
    seeds : numpy.ndarray or None
        (S,) integer seeds (None if the wind was given).
    outputs : dict
        Output name → (W, S, n) array in SI, plus ``pitch_cmd`` (rad) and ``wind`` (m/s, the
        rotor-effective wind that drove the run).
    dt : float
        Sample spacing of ``time`` (s).
    sim_dt : float
        Integration step (s).
    linear : bool, optional
        True if the linearised plant was integrated.
    controller : str, optional
        Label of the controller.
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


def simulate(plant: TurbineModel | KernelPlant, controller: object, wind_speeds: ArrayLike, *,
             seeds: ArrayLike | None = None, wind: ArrayLike | None = None, duration: float = RECORD_LENGTH, dt: float = 0.02,
             record_dt: float = 0.1, transient: float = 60.0, wind_dt: float | None = None,
             turbulence_class: str = "B", linear: bool = False, wind_rotor_radius: float | None = None,
             wind_mean_tol: float = WIND_MEAN_TOLERANCE, torque_control: object = "auto",
             noise: SensorNoise | None = None) -> SimulationResult:
    """Simulate the closed loop for every (wind speed, seed), all runs batched.

    Parameters
    ----------
    plant : TurbineModel or KernelPlant
        The plant (e.g. ``turbine.iea15mw()``).
    controller : control.LTI, loopshaping.controller.Controller, ScheduledController or callable
        The pitch controller, or a callable ``f(t, y)`` (see :mod:`specdesign.simulate` for the
        sign convention and the callable contract).
    wind_speeds : array_like
        Mean wind speeds (m/s), W of them.
    seeds : array_like of int, optional
        Integer seeds (S of them) for the turbulent wind; or give ``wind`` instead.
    wind : array_like, optional
        (W, S, n_w) rotor-effective wind (m/s) sampled every ``wind_dt``, covering
        ``transient + duration``.
    duration : float, optional
        Recorded length of each run (s).
    dt : float, optional
        Integration and controller step (s).
    record_dt : float, optional
        Sample spacing of the recorded outputs (s), a multiple of ``dt``.
    transient : float, optional
        Simulated before the record starts and discarded (s).
    wind_dt : float, optional
        Spacing of the wind samples (s) (default ``record_dt`` when synthesised; keep it a
        multiple of ``dt`` so the interpolated wind is smooth within each RK4 step).
    turbulence_class : str, optional
        IEC NTM class of the synthesised wind.
    linear : bool, optional
        Integrate the linearisation at each wind speed instead of the nonlinear model.
    wind_rotor_radius : float, optional
        Rotor radius for the rotor-effective spectrum (m) (default: ``plant.rotor_radius``
        for a TurbineModel, e.g. one of :func:`specdesign.turbine.from_openfast`, else the
        IEA 15 MW's).
    wind_mean_tol : float, optional
        Largest |mean of a given wind record − its wind speed| (m/s) (default
        :data:`WIND_MEAN_TOLERANCE`).
    torque_control : {"auto", "rosco", None} or specdesign.rosco.TorqueLaw, optional
        Generator torque of the compiled loop (see :mod:`specdesign.simulate`): "auto" runs
        the plant's torque law (the model's ``torque_control``) in the runs below rated and
        holds the trim torque above (a constant-power law runs in every run, and so does any
        law under a controller with peak shaving, whose limit can hold the pitch above rated
        while ROSCO's torque controller regulates the speed); "rosco" runs it
        in every run; a TorqueLaw runs that one in every run; None holds the trim torque
        everywhere. Ignored with ``linear=True`` (the linearisation closes the law below
        rated, and above rated a constant-power one) and for a callable controller (it
        commands the torque itself, or holds the trim torque).
    noise : specdesign.controller.noise.SensorNoise, optional
        The sensors between the plant and the controller (white noise on the measured
        generator speed, tower-top acceleration and velocity and blade-root moment, and a 3P
        ripple on the speed; see :mod:`specdesign.controller.noise`), seeded per (wind speed,
        seed) so that every controller run on the same runs reads the same noise. The compiled
        loop's pitch controller, ATD and torque law read the noisy generator speed and tower-top
        velocity; a callable gets every noisy signal in ``y``. The recorded outputs are the
        plant's. None (default): the controllers read the outputs themselves (the results of
        the simulator before the noise model, bit for bit). E.g.
        :data:`specdesign.controller.noise.IEA15MW_SENSORS`.

    Returns
    -------
    SimulationResult
        Outputs (W, S, n) for every plant output, ``pitch_cmd`` and ``wind``.

    Raises
    ------
    ValueError
        for a step ``dt`` above 1/|λ|max of the linearised plant (:data:`specdesign.simulate.checks.MAX_STEP_EIGENVALUE`),
        or at which the loop as simulated (command held over the step, controller by Tustin)
        is unstable while the continuous loop is stable (:func:`sampled_loop_radius`; both
        limits are in the message), or for a wind record whose mean is more than
        ``wind_mean_tol`` off its wind speed.
    SimulationDivergedError
        when a run diverges (non-finite, or an output beyond ``plant.output_limits``: for the
        turbine twice the rated generator speed or the tower-base moment of 10 m of tower-top
        deflection), naming its wind speed, seed and time.

    Notes
    -----
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

    Examples
    --------
    >>> from specdesign.turbine import iea15mw, rosco_baseline
    >>> m = iea15mw()
    >>> r = simulate(m, rosco_baseline(m, 19.0), [19.0], seeds=[1], duration=10.0, transient=5.0)
    >>> r["gen_speed"].shape
    (1, 1, 100)
    """
    model_radius = getattr(plant, "rotor_radius", None)
    plant = turbine_plant(plant) if not isinstance(plant, KernelPlant) else plant
    times = _times(dt, duration, record_dt, transient)
    vs = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    if vs.ndim != 1 or not np.all(np.isfinite(vs)) or np.any(vs <= 0):
        raise ValueError(f"wind_speeds must be a 1-D array of positive mean wind speeds in m/s, got {wind_speeds!r}")
    if noise is not None and not isinstance(noise, SensorNoise):
        raise TypeError(f"noise must be a specdesign.controller.noise.SensorNoise or None, got {type(noise).__name__}")
    radius = wind_rotor_radius if wind_rotor_radius is not None else model_radius
    wind, wind_dt, seeds = _wind_records(vs, seeds, wind, wind_dt, times, radius, turbulence_class, wind_mean_tol)
    S = wind.shape[1]
    check_step(plant, vs, times.dt)
    peak_shaving = getattr(controller, "peak_shaving", None) is not None
    TQ, above = _torque_params(plant, torque_control, vs, S, linear, peak_shaving)
    rhs, outfn, runs, trim_speeds = _plant_runs(plant, vs, S, linear, wind, TQ)
    noise_of = _measurement_noise(noise, plant, vs, seeds, S, times, trim_speeds)
    kind, run_batch, step_all, outputs_all = compiled_for(rhs, outfn)
    ny = len(plant.output_names)
    lim_names = tuple(plant.output_limits)
    setup = LoopSetup(kind, wind_dt, times.dt, times.nsteps, times.rec_every, ny, plant.index("gen_speed"),
                      plant.index("tower_top_vel"), *_torque_outputs(plant, TQ, peak_shaving),
                      np.array([plant.index(n) for n in lim_names], dtype=np.int64),
                      np.array([float(plant.output_limits[n]) for n in lim_names]))
    Y = np.empty((runs.X0.shape[0], ny + 1, (times.nsteps + times.rec_every - 1) // times.rec_every))
    status = np.full(runs.X0.shape[0], -1, dtype=np.int64)
    if callable(controller) and not is_lti_like(controller) and not isinstance(controller, ScheduledController):
        label = getattr(controller, "__name__", "callable")
        if torque_control == "rosco" or TQ[:, 0].any() and torque_control != "auto":
            raise ValueError("a callable controller commands the generator torque itself (or holds the trim torque): "
                             "torque_control must be 'auto' or None with it")
        run_callable(controller, step_all, outputs_all, kind, runs.P, runs.X0, runs.W, wind_dt, times.dt, times.nsteps,
                     times.rec_every, runs.torque, runs.beta0, ny, Y, plant.output_names, setup.lim_idx, setup.lim_val,
                     status, noise_of)
    else:
        label = getattr(controller, "name", None)
        if label is None or _AUTO_NAME.fullmatch(str(label)):
            # python-control names an unnamed system "sys[4]": a name the user never gave
            label = "controller"
        # below rated the pitch loop is open (its PI sits at the minimum pitch): not checked there
        warn_unstable(plant, controller, vs[above], times.dt)
        bank, gpi = _bank_records(controller, plant, times.dt)
        if noise_of:  # the compiled loop reads the generator speed and the tower-top velocity
            R, n = runs.X0.shape[0], times.nsteps
            runs = runs._replace(noise=np.ascontiguousarray(np.stack(
                [noise_of.get(k, np.zeros((R, n))) for k in ("gen_speed", "tower_top_vel")], axis=1)))
        run_batch(setup, bank, gpi, runs, Y, status)
    _raise_diverged(status, vs, seeds, S, times.dt, times.transient, lim_names, setup.lim_val, str(label), linear)
    return _result(plant, Y, runs.W, wind_dt, vs, seeds, times, linear, str(label))


class _Times(NamedTuple):
    """The checked time settings of :func:`simulate` (s), the steps per run and between records."""

    dt: float
    duration: float
    record_dt: float
    transient: float
    rec_every: int
    nsteps: int


def _times(dt, duration, record_dt, transient) -> _Times:
    dt = positive_scalar(dt, "dt")
    duration = positive_scalar(duration, "duration")
    record_dt = positive_scalar(record_dt, "record_dt")
    transient = float(transient)
    if not transient >= 0:
        raise ValueError(f"transient={transient!r} must be >= 0 s")
    rec_every = int(round(record_dt / dt))
    if rec_every < 1 or abs(rec_every * dt - record_dt) > 1e-9 * record_dt:
        raise ValueError(f"record_dt={record_dt} must be a whole multiple of dt={dt}")
    return _Times(dt, duration, record_dt, transient, rec_every, int(round((transient + duration) / dt)))


def _wind_records(vs, seeds, wind, wind_dt, times, radius, turbulence_class, wind_mean_tol):
    """(W, S, n_w) wind (m/s), its spacing (s) and the seeds (or None): synthesised from the
    seeds, or the given records checked."""
    total = times.transient + times.duration
    if wind is None:
        if seeds is None:
            raise ValueError("give either seeds (turbulent wind is synthesised) or wind (W, S, n) in m/s")
        seeds = np.atleast_1d(np.asarray(seeds, dtype=np.int64))
        wind_dt = times.record_dt if wind_dt is None else positive_scalar(wind_dt, "wind_dt")
        radius = iea15mw().rotor_radius if radius is None else radius
        return wind_series(radius, vs, seeds, total + wind_dt, wind_dt, turbulence_class), wind_dt, seeds
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
    return wind, wind_dt, seeds


def _plant_runs(plant, vs, S, linear, wind, TQ):
    """The kernel pair, the per-run inputs (:class:`Runs`, no noise yet) and the trims'
    generator speeds (W,) (rad/s), of the nonlinear plant or its linearisations."""
    R = vs.size * S
    ny = len(plant.output_names)
    i_speed = plant.index("gen_speed")
    trims = [plant.trim(v) for v in vs]
    y0s = []
    for v, (x0, b0, tq) in zip(vs, trims):
        y0 = np.empty(ny)
        plant.outputs(np.asarray(x0, float), float(v), b0, tq, plant.params, y0)
        y0s.append(y0)
    if linear:
        if plant.linearize is None:
            raise ValueError("linear=True needs a plant with a linearize method")
        rhs, outfn = linear_rhs, linear_outputs
        rows, x0s = [], []
        for v, (x0, b0, tq), y0 in zip(vs, trims, y0s):
            sys = plant.linearize(v)
            rows.append(linear_plant_params(sys, [v, b0, tq], y0))
            x0s.append(np.zeros(sys.nstates))
        P = np.repeat(np.stack(rows), S, axis=0)
        X0 = np.repeat(np.stack(x0s), S, axis=0)
    else:
        rhs, outfn = plant.rhs, plant.outputs
        # a writeable copy whatever R (a read-only array of one run would compile another kernel)
        P = np.repeat(np.asarray(plant.params, dtype=float)[None], R, axis=0)
        X0 = np.repeat(np.stack([np.asarray(t[0], float) for t in trims]), S, axis=0)
    runs = Runs(P, np.ascontiguousarray(X0), np.ascontiguousarray(wind.reshape(R, -1)),
                np.repeat([t[1] for t in trims], S), np.full(R, plant.rated_speed), np.repeat([t[2] for t in trims], S),
                TQ, np.zeros((R, 0, 0)))
    return rhs, outfn, runs, np.array([y0[i_speed] for y0 in y0s])


def _measurement_noise(noise, plant, vs, seeds, S, times, trim_speeds):
    """Output name → (R, nsteps) noise on what the controllers measure ({} without noise):
    :class:`SensorNoise` on every measured signal the plant has; runs labelled by their seeds,
    or by their record index when the wind was given without seeds."""
    if noise is None or not noise.active:
        return {}
    labels = np.arange(S) if seeds is None else seeds
    out = {}
    for name in MEASURED:
        if name in plant.output_names and (noise.sd(name, times.dt) > 0 or name == "gen_speed" and noise.ripple_3p > 0):
            out[name] = noise.series(name, vs, labels, times.nsteps, times.dt,
                                     trim_speeds / noise.gear_ratio).reshape(vs.size * S, -1)
    return out


def _bank_records(controller, plant, dt):
    """The compiled loop's :class:`Bank` and :class:`GainsPI` of a controller at step ``dt``."""
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
    same = _same_locals(Ad, Bd, Cd, Dd, Rq, Ns)
    sfilt = schedule_filter_coefficients(fw, getattr(controller, "filter_damping", None), dt)
    cmd_lim = np.array((-np.inf, np.inf) if plant.pitch_limits is None else plant.pitch_limits, dtype=float)
    ps = np.zeros(0)
    if pi is None:
        pi_on, kp, ki = False, np.zeros(K), np.zeros(K)
        Af, Bf, Cf, Df, lim = np.zeros((0, 0)), np.zeros(0), np.zeros(0), np.zeros(1), np.array([-np.inf, np.inf])
    else:
        pi_on, (kp, ki, Af, Bf, Cf, Df, lim) = True, pi
        # the PI's integrator never holds more than the command can reach: its own limits
        # narrowed to the plant's (the plant's alone when it has none), so it cannot wind up
        lim = np.array([max(lim[0], cmd_lim[0]), min(lim[1], cmd_lim[1])])
        if controller.peak_shaving is not None:  # ROSCO's minimum pitch from its wind estimate (form="gains")
            ps = controller.peak_shaving.params()
    bank = Bank(Ad, Bd, Cd, Dd, Rq, Ns, same, np.ascontiguousarray(sched_pitch), sfilt, cmd_lim)
    gpi = GainsPI(pi_on, *(np.ascontiguousarray(a, dtype=float) for a in (kp, ki, Af, Bf, Cf, Df, lim, ps)))
    return bank, gpi


def _result(plant, Y, Wr, wind_dt, vs, seeds, times, linear, label):
    """The :class:`SimulationResult` of the records ``Y`` (R, ny + 1, n_rec), the transient dropped."""
    W, R = vs.size, Wr.shape[0]
    ny = len(plant.output_names)
    skip = int(round(times.transient / times.record_dt))
    t_rec = np.arange(Y.shape[2]) * times.record_dt
    keep = slice(skip, skip + int(round(times.duration / times.record_dt)))
    outs = {name: Y[:, i, keep].reshape(W, R // W, -1) for i, name in enumerate(plant.output_names)}
    outs["pitch_cmd"] = Y[:, ny, keep].reshape(W, R // W, -1)
    # The wind at the recorded instants, for spectra and plots.
    idx_t = t_rec[keep]
    outs["wind"] = np.stack([np.interp(idx_t, np.arange(Wr.shape[1]) * wind_dt, Wr[r])
                             for r in range(R)]).reshape(W, R // W, -1)
    return SimulationResult(
        time=idx_t - idx_t[0], wind_speeds=vs, seeds=seeds, outputs=outs, dt=times.record_dt, sim_dt=times.dt,
        linear=linear, controller=label,
    )


def _same_locals(Ad, Bd, Cd, Dd, Rq, Ns):
    """(K,) int64: for each local of the bank, the first local with the same discrete matrices,
    integrator gain and slow-state count (the compiled loop runs only those, see ``_run_one``)."""
    # compared bit for bit (a −0.0 gain is not merged with a +0.0 one)
    keys = [b"".join(np.ascontiguousarray(a[q]).tobytes() for a in (Ad, Bd, Cd, Dd, Rq, Ns)) for q in range(Rq.size)]
    first = {}
    return np.array([first.setdefault(k, q) for q, k in enumerate(keys)], dtype=np.int64)


def _torque_params(plant, torque_control, vs, S, linear, peak_shaving=False):
    """(R, TORQUE_PARAMS) torque-law parameters per run (mode 0: torque held) and the mask of
    wind speeds where the pitch loop is active (not below rated under the torque law)."""
    rated = plant.rated_wind_speed
    above = np.ones(vs.size, dtype=bool) if rated is None else vs >= rated
    on = np.zeros(vs.size, dtype=bool)
    law = plant.torque_law
    if isinstance(torque_control, TorqueLaw):
        law, on[:] = torque_control, True
    elif torque_control == "rosco":
        if law is None:
            raise ValueError("torque_control='rosco' needs a plant with a torque law (a TurbineModel with "
                             "torque_control, e.g. iea15mw()); pass a specdesign.rosco.TorqueLaw instead")
        on[:] = True
    elif torque_control == "auto":  # a constant-power law (VS_ConstPower = 1) acts above rated too, and
        # any law with peak shaving: at its limit the pitch stops regulating and the torque PI takes over
        on = (~above | law.const_power | peak_shaving) if law is not None else on
    elif torque_control is not None:
        raise ValueError(f"torque_control={torque_control!r} must be 'auto', 'rosco', None or a specdesign.rosco.TorqueLaw")
    if linear:
        on[:] = False
    TQ = np.zeros((vs.size * S, TORQUE_PARAMS))
    if on.any():
        TQ[np.repeat(on, S)] = law.params()
    return TQ, above


def _torque_outputs(plant, TQ, peak_shaving=False):
    """Indices of the power and the pitch, which the torque law and peak shaving read (0 for unread)."""
    if peak_shaving and not TQ[:, 0].any():
        return 0, plant.index("pitch")
    if not TQ[:, 0].any():
        return 0, 0
    return plant.index("power"), plant.index("pitch")


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
