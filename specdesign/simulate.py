"""Batched time-domain simulation of the turbine in closed loop with any pitch controller.

The plant is the compiled right-hand side of :mod:`specdesign.turbine` (the same function the
linearisation differentiates), integrated by fixed-step RK4 inside one ``@njit`` loop that
runs all seeds and wind speeds in parallel (``prange`` over runs). The wind is linearly
interpolated between its samples for the RK4 stages; the pitch command and generator
torque are held over a step (the controller is discrete, sampled at the simulation step).

Controller convention (as everywhere in the workbench)::

    β_cmd = β₀ − C_β·(Ω_g − Ω_rated) − C_atd·ẋ_top

with C_β the pitch controller on the generator speed (β = −C·Ω_g in deviations) and an
optional active-tower-damping controller C_atd on the tower-top fore-aft velocity (m/s),
summed into the pitch command with the same negative-feedback sign as in
:mod:`specdesign.closedloop`. β₀ is the trim pitch at the run's mean wind speed.

Gain scheduling (``ScheduledController``) has two forms, both scheduled on β_f, the pitch
command low-pass filtered (first order, ``filter_omega``), with piecewise-linear weights
between K scheduling pitches β_k, clamped at the ends:

* ``form="output"`` (general designed controllers, :func:`scheduled`): the K local
  controllers run in parallel on the same measurements and their *outputs* are blended
  (as in the seed paper). For PI locals with different K_i this computes
  K_i(β_f)·∫e, not ∫K_i(β_f)·e: the two differ by a coupling term K_i′(β_f)·β̇_f·∫e while
  β_f moves (see ``docs/nonlinearity.md``).
* ``form="gains"`` (ROSCO's own scheduling, the default of :func:`rosco_scheduled`): one PI
  whose gains are interpolated in β_f and applied to one filtered error with ONE
  integrator of K_i(β_f)·e_f, u = K_p(β_f)·e_f + ∫K_i(β_f)·e_f dt, e_f = F·(Ω_rated − Ω_g).
  Discrete at the simulation step as the LTI path is (Tustin): F by Tustin, the integral
  by the trapezoid rule with the gain of the current step, I_k = I_{k−1} +
  K_i(β_f,k)·dt/2·(e_f,k + e_f,k−1). With ``pitch_limits`` (``rosco_scheduled``: the
  model's) the integrator, as absolute pitch β_0 + I, and the PI output are saturated at
  them, as ROSCO's PI does (anti-windup near rated, where the pitch reaches its minimum).
  Without limits, or while they are not reached, and with frozen gains it is exactly the
  LTI (K_p + K_i/s)·F simulated on the ordinary path.

An ATD controller, if present, is output-blended in both forms.

Three controller kinds are accepted wherever a controller is asked for: a python-control
LTI system (SISO, proper; discretised by Tustin at the simulation step), a
``loopshaping.controller.Controller`` (its ``.tf()``), a ``ScheduledController``, or a
Python callable ``f(t, y) -> pitch_cmd`` (the slow path: called once per step with ``y`` a
dict of the model outputs, each an array over all runs, returning the absolute pitch
command in rad for all runs; use it for MPC or other time-domain controllers).

A linear simulation of the same closed loop (``linear=True``) integrates the linearisation
``model.linearize(v)`` with the same loop, the same RK4 step and the same discrete
controller, so differences between the two are the plant's nonlinearity only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from ._checks import positive_scalar
from .rosco import rosco_scheduled
from .wind import seed_for, wind_series
from .turbine import outputs as _turbine_outputs
from .turbine import rhs as _turbine_rhs

__all__ = [
    "SimulationDivergedError",
    "KernelPlant",
    "ScheduledController",
    "SimulationResult",
    "turbine_plant",
    "scheduled",
    "rosco_scheduled",
    "discretize",
    "split_integrator",
    "split_slow",
    "sampled_loop_radius",
    "simulate",
    "linear_plant_params",
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


#: Default low-pass corner of the scheduling pitch filter (rad/s): slow enough that the
#: scheduling variable follows the mean operating point rather than the turbulence
#: (ROSCO filters its scheduling pitch at 0.1 × the 1 rad/s speed-filter corner).
SCHEDULE_FILTER_OMEGA = 0.1


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
    from . import turbine

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


# ----------------------------------------------------------------------------- linear kernel
# Parameter layout of the linear kernel: [nx, ny, u0(3), y0(ny), A, B(nx×3), C(ny×nx), D(ny×3)]
@njit(cache=True)
def _lin_rhs(x, wind, pitch_cmd, gen_torque, p, dx):
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
def _lin_outputs(x, wind, pitch_cmd, gen_torque, p, y):
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


def linear_plant_params(sys, u0, y0) -> np.ndarray:
    """Flat parameter array of the linear kernel for ``sys`` (deviation model, inputs
    wind/pitch_cmd/gen_torque in that order) around inputs ``u0`` and outputs ``y0`` (SI)."""
    A, B, C, D = (np.asarray(m, dtype=float) for m in (sys.A, sys.B, sys.C, sys.D))
    if B.shape[1] != 3:
        raise ValueError(f"linear plant must have 3 inputs (wind, pitch_cmd, gen_torque), got {B.shape[1]}")
    nx, ny = A.shape[0], C.shape[0]
    return np.concatenate([[nx, ny], np.asarray(u0, float), np.asarray(y0, float), A.ravel(), B.ravel(), C.ravel(), D.ravel()])


# ----------------------------------------------------------------------------- controllers
def _as_lti(c, name):
    import control

    if hasattr(c, "tf") and callable(c.tf) and not isinstance(c, control.LTI):
        c = c.tf()
    if not isinstance(c, control.LTI):
        raise TypeError(f"{name} must be a python-control LTI system or a loopshaping Controller, got {type(c).__name__}")
    if c.ninputs != 1 or c.noutputs != 1:
        raise ValueError(f"{name} must be SISO, got {c.noutputs}×{c.ninputs}")
    if c.isdtime(strict=True):
        raise ValueError(f"{name} is discrete-time; pass the continuous controller (it is discretised at the simulation step)")
    return c


def discretize(controller, dt):
    """Tustin discretisation of a SISO continuous controller at step ``dt`` (s).

    Returns ``(A, B, C, D)`` float arrays of shapes (n, n), (n,), (n,) and (1,) of the
    discrete state-space form x⁺ = A x + B u, y = C x + D u.
    Raises ValueError for an improper controller (more zeros than poles).
    """
    import control

    dt = positive_scalar(dt, "dt")
    c = _as_lti(controller, "controller")
    if isinstance(c, control.TransferFunction):
        num, den = np.atleast_1d(np.squeeze(c.num[0][0])), np.atleast_1d(np.squeeze(c.den[0][0]))
        num = np.trim_zeros(num, "f")
        if num.size > np.trim_zeros(den, "f").size:
            raise ValueError("controller is improper (more zeros than poles); add a roll-off pole")
    s = control.ss(c)
    n = s.nstates
    if n == 0:
        return np.zeros((0, 0)), np.zeros(0), np.zeros(0), np.array([float(np.squeeze(s.D))])
    d = control.c2d(s, dt, method="tustin")
    return (np.asarray(d.A, float), np.asarray(d.B, float).ravel(), np.asarray(d.C, float).ravel(),
            np.array([float(np.squeeze(d.D))]))


def split_integrator(controller):
    """(r, C_r): C(s) = r/s + C_r(s) for a SISO controller with one pole at s = 0.

    The simulator runs r/s as a separate integrator (trapezoid rule = Tustin, so the sum is
    the Tustin discretisation of C exactly) and clamps it at the pitch limits as ROSCO clamps
    its integrator (anti-windup); C_r has no pole at 0 and cannot wind up. A controller
    without a pole at 0 gives (0, C); one with several is returned whole, unclamped.
    """
    import control

    c = _as_lti(controller, "controller")
    tf = control.tf(c)
    num = np.trim_zeros(np.atleast_1d(np.squeeze(tf.num[0][0])).astype(float), "f")
    den = np.trim_zeros(np.atleast_1d(np.squeeze(tf.den[0][0])).astype(float), "f")
    tiny = 1e-12 * np.max(np.abs(den))
    if den.size < 2 or abs(den[-1]) > tiny or (den.size > 2 and abs(den[-2]) <= tiny):
        return 0.0, c
    d1 = den[:-1]
    r = float(num[-1] / d1[-1]) if num.size else 0.0
    rest = np.polysub(num, r * d1)[:-1]  # (num − r·d1)/s: its constant term is zero
    return r, control.tf(rest if rest.size else [0.0], d1)


#: Corner (rad/s) under which a pole of a pitch controller (besides its integrator) belongs to
#: its slow part (:func:`split_slow`): a time constant above 10 s, longer than an excursion to
#: the pitch floor, over which such a mode integrates the speed error as the integrator does.
#: A controller with a slow part gets conditional integration, one without (PI-like, ROSCO's:
#: its speed filter is at 1 rad/s) ROSCO's integrator clamp; see :func:`simulate`.
SLOW_OMEGA = 0.1


def split_slow(controller, omega=SLOW_OMEGA):
    """(C_s or None, C_f): C = C_s + C_f with C_s the modes of ``controller`` (no pole at 0,
    e.g. C_r of :func:`split_integrator`) with |pole| < ``omega`` (rad/s), strictly proper, and
    C_f the others plus the feedthrough. Without slow poles: (None, controller), unchanged.

    Block-diagonalised from the ordered real Schur form (a Sylvester equation decouples the
    blocks), so C_s + C_f equals C to rounding."""
    import control
    import scipy.linalg

    c = control.ss(_as_lti(controller, "controller"))
    A, B, C, D = (np.asarray(x, dtype=float) for x in (c.A, c.B, c.C, c.D))
    n = A.shape[0]
    if n == 0 or not np.any(np.abs(np.linalg.eigvals(A)) < omega):
        return None, controller
    T, Z, k = scipy.linalg.schur(A, output="real", sort=lambda x, y: math.hypot(x, y) < omega)
    X = scipy.linalg.solve_sylvester(T[:k, :k], -T[k:, k:], -T[:k, k:])
    V = Z @ np.block([[np.eye(k), X], [np.zeros((n - k, k)), np.eye(n - k)]])
    Bt, Ct = np.linalg.solve(V, B), C @ V
    slow = control.ss(T[:k, :k], Bt[:k], Ct[:, :k], np.zeros_like(D))
    fast = control.ss(T[k:, k:], Bt[k:], Ct[:, k:], D) if k < n else control.ss([], [], [], D)
    return slow, fast


_FORMS = ("output", "gains")


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class ScheduledController:
    """Local pitch (and optional ATD) controllers scheduled on filtered pitch.

    schedule_pitch : (K,) increasing scheduling pitches β_k (rad), one per local controller.
    pitch : K continuous SISO controllers C_β,k on the generator speed (β = −C·Ω_g): the
        local controllers (in ``form="gains"``, the frozen-gain PIs (K_p,k + K_i,k/s)·F).
    atd : K continuous SISO controllers on tower-top velocity (β −= C_atd·ẋ_top), or None;
        output-blended in both forms.
    filter_omega : corner (rad/s) of the first-order low-pass on the pitch command that
        gives the scheduling variable β_f.
    name : label used in tables and figures.
    form : ``"output"`` blends the local controllers' outputs; ``"gains"`` runs ROSCO's form,
        u = K_p(β_f)·e_f + ∫K_i(β_f)·e_f dt with e_f = error_filter·(Ω_rated − Ω_g), the gains
        interpolated linearly in β_f (see the module docstring). Build it with
        :meth:`gain_scheduled_pi`.
    kp, ki : (K,) PI gains at the scheduling pitches (``form="gains"`` only; in the workbench's
        convention C = (K_p + K_i/s)·F, i.e. ROSCO's negative gains), rad/(rad/s) and rad/rad.
    error_filter : SISO LTI filter F on the speed error (``form="gains"`` only).
    pitch_limits : (min, max) absolute pitch (rad) at which ``form="gains"`` saturates its
        integrator (the trim pitch plus ∫K_i·e_f) and its PI output, as ROSCO's PI does
        (anti-windup). :func:`simulate` narrows them to the plant's pitch limits, and uses the
        plant's alone when this is None (default): the integrator never winds up beyond what
        the actuator can reach; on a plant without limits, None means no saturation.
    """

    schedule_pitch: np.ndarray
    pitch: tuple
    atd: tuple | None = None
    filter_omega: float = SCHEDULE_FILTER_OMEGA
    name: str = "controller"
    form: str = "output"
    kp: np.ndarray | None = field(default=None, repr=False)
    ki: np.ndarray | None = field(default=None, repr=False)
    error_filter: object = field(default=None, repr=False)
    pitch_limits: tuple | None = None

    def __post_init__(self):
        b = np.atleast_1d(np.asarray(self.schedule_pitch, dtype=float))
        if b.ndim != 1 or b.size < 1 or np.any(np.diff(b) <= 0) or not np.all(np.isfinite(b)):
            raise ValueError(f"schedule_pitch must be a 1-D strictly increasing array of pitches in rad, got {b}")
        object.__setattr__(self, "schedule_pitch", b)
        if len(self.pitch) != b.size:
            raise ValueError(f"pitch needs one controller per scheduling pitch ({b.size}), got {len(self.pitch)}")
        if self.atd is not None and len(self.atd) != b.size:
            raise ValueError(f"atd needs one controller per scheduling pitch ({b.size}), got {len(self.atd)}")
        positive_scalar(self.filter_omega, "filter_omega")
        if self.form not in _FORMS:
            raise ValueError(f"form must be one of {_FORMS}, got {self.form!r}")
        if self.form == "output":
            if self.kp is not None or self.ki is not None or self.error_filter is not None or self.pitch_limits is not None:
                raise ValueError("kp, ki, error_filter and pitch_limits are for form='gains' only")
            return
        if self.pitch_limits is not None:
            lim = tuple(float(x) for x in self.pitch_limits)
            if len(lim) != 2 or not lim[0] < lim[1] or any(math.isnan(x) for x in lim):
                raise ValueError(f"pitch_limits must be (min, max) pitch in rad with min < max, got {self.pitch_limits!r}")
            object.__setattr__(self, "pitch_limits", lim)
        gains = []
        for g, nm in ((self.kp, "kp"), (self.ki, "ki")):
            a = np.atleast_1d(np.asarray(g, dtype=float)) if g is not None else None
            if a is None or a.shape != b.shape or not np.all(np.isfinite(a)):
                raise ValueError(f"form='gains' needs {nm} as {b.size} finite gains, one per scheduling pitch, got {g!r}")
            gains.append(a)
        object.__setattr__(self, "kp", gains[0])
        object.__setattr__(self, "ki", gains[1])
        f = _as_lti(self.error_filter, "error_filter")
        object.__setattr__(self, "error_filter", f)
        # The local controllers must be the frozen-gain PIs, or the linear prediction (which
        # blends them) would describe another controller than the one simulated.
        jw = 1j * np.array([0.03, 0.3, 1.0, 3.0])
        fj = np.asarray(f(jw), complex)
        for k in range(b.size):
            ref = (gains[0][k] + gains[1][k] / jw) * fj
            got = np.asarray(_as_lti(self.pitch[k], f"pitch[{k}]")(jw), complex)
            if not np.allclose(got, ref, rtol=1e-8, atol=0):
                raise ValueError(f"pitch[{k}] is not (kp[{k}] + ki[{k}]/s)·error_filter; build form='gains' "
                                 "with ScheduledController.gain_scheduled_pi")

    def local(self, k: int):
        """(C_β, C_atd or None) of the k-th local controller."""
        return self.pitch[k], (None if self.atd is None else self.atd[k])

    @classmethod
    def gain_scheduled_pi(cls, schedule_pitch, kp, ki, error_filter, *, atd=None,
                          filter_omega=SCHEDULE_FILTER_OMEGA, name="PI", pitch_limits=None) -> "ScheduledController":
        """ROSCO-form gain-scheduled PI: u = K_p(β_f)·e_f + ∫K_i(β_f)·e_f dt, e_f = F·(Ω_ref − Ω_g).

        schedule_pitch (rad), kp, ki : (K,) gains at the scheduling pitches, in the
        workbench's convention C = (K_p + K_i/s)·F (ROSCO's negative gains).
        error_filter : SISO LTI F on the speed error (e.g. :func:`specdesign.turbine.speed_filter`).
        atd : K ATD controllers (output-blended) or None.
        pitch_limits : (min, max) pitch (rad) saturating the integrator and the PI output
            (ROSCO's anti-windup), or None (the simulated plant's limits, see the class).
        """
        import control

        f = _as_lti(error_filter, "error_filter")
        kp = np.atleast_1d(np.asarray(kp, dtype=float))
        ki = np.atleast_1d(np.asarray(ki, dtype=float))
        if kp.shape != ki.shape or kp.ndim != 1:
            raise ValueError(f"kp and ki must be 1-D arrays of the same length, got shapes {kp.shape} and {ki.shape}")
        pitch = tuple(control.tf([a, c], [1.0, 0.0]) * f for a, c in zip(kp, ki))
        return cls(schedule_pitch, pitch, None if atd is None else tuple(atd), filter_omega, name,
                   form="gains", kp=kp, ki=ki, error_filter=f, pitch_limits=pitch_limits)


def scheduled(model, pitch, atd=None, *, filter_omega=SCHEDULE_FILTER_OMEGA, name="designed") -> ScheduledController:
    """Build a ScheduledController from controllers designed per wind speed.

    pitch : dict wind speed (m/s) → pitch controller C_β (LTI or Controller).
    atd : dict wind speed (m/s) → ATD controller, same keys, or None.
    model : TurbineModel or KernelPlant whose trim gives each wind speed's scheduling pitch.
    """
    if not isinstance(pitch, dict) or not pitch:
        raise TypeError("pitch must be a non-empty dict {wind_speed_m_s: controller}")
    if atd is not None and set(atd) != set(pitch):
        raise ValueError(f"atd must have the same wind speeds as pitch: {sorted(pitch)} vs {sorted(atd)}")
    plant = turbine_plant(model)
    vs = sorted(pitch)
    b = np.array([plant.trim(v)[1] for v in vs])
    order = np.argsort(b)
    vs = [vs[i] for i in order]
    return ScheduledController(
        schedule_pitch=b[order],
        pitch=tuple(_as_lti(pitch[v], f"pitch[{v}]") for v in vs),
        atd=None if atd is None else tuple(_as_lti(atd[v], f"atd[{v}]") for v in vs),
        filter_omega=filter_omega,
        name=name,
    )


_BANKS: dict = {}


def _bank(controller, dt):
    """Discrete arrays of one controller (K local 2-input controllers) and its filter corner.

    Memoised per (controller object, dt): a campaign simulates the same controllers at
    every wind speed, and discretising a 15-point ROSCO schedule costs more than a run.
    """
    key = (id(controller), float(dt))
    hit = _BANKS.get(key)
    if hit is not None and hit[0] is controller:
        return hit[1]
    out = _make_bank(controller, dt)
    if len(_BANKS) > 64:
        _BANKS.clear()
    _BANKS[key] = (controller, out)
    return out


def _make_bank(controller, dt):
    """(schedule_pitch, per-local (A, B, C, D, r, ns) of the output-blended part (r: the
    pitch controller's integrator gain, run apart, see :func:`split_integrator`; its first ns
    states: the modes of the rest under SLOW_OMEGA, :func:`split_slow`), filter corner,
    scheduled-PI arrays (kp, ki, Af, Bf, Cf, Df, limits) or None; limits (2,) in rad, ±inf
    for none).

    In ``form="gains"`` the local pitch controllers are not in the blended bank (only the ATD
    locals are); the PI runs as one filter, one integrator and interpolated gains."""
    if not isinstance(controller, ScheduledController):
        controller = ScheduledController(np.zeros(1), (_as_lti(controller, "controller"),), None, name="controller")
    gains = controller.form == "gains"
    none = (np.zeros((0, 0)), np.zeros(0), np.zeros(0), np.zeros(1))
    mats = []
    for k in range(controller.schedule_pitch.size):
        cb, ca = controller.local(k)
        r, rest = (0.0, None) if gains else split_integrator(cb)
        slow, rest = (None, rest) if gains or r == 0.0 else split_slow(rest)
        As, Bs, Cs, Ds = none if slow is None else discretize(slow, dt)  # states first: the kernel's ns
        Ab, Bb, Cb, Db = none if gains else discretize(rest, dt)
        Aa, Ba, Ca, Da = none if ca is None else discretize(ca, dt)
        ns, nb, na = As.shape[0], Ab.shape[0], Aa.shape[0]
        nt = ns + nb + na
        A = np.zeros((nt, nt))
        A[:ns, :ns], A[ns:ns + nb, ns:ns + nb], A[ns + nb:, ns + nb:] = As, Ab, Aa
        B = np.zeros((nt, 2))
        B[:ns, 0], B[ns:ns + nb, 0], B[ns + nb:, 1] = Bs, Bb, Ba
        mats.append((A, B, np.concatenate([Cs, Cb, Ca]), np.array([(Ds[0] if ns else 0.0) + Db[0], Da[0]]), r, ns))
    pi = None
    if gains:
        Af, Bf, Cf, Df = discretize(controller.error_filter, dt)
        lim = (-np.inf, np.inf) if controller.pitch_limits is None else controller.pitch_limits
        pi = (controller.kp, controller.ki, Af, Bf, Cf, Df, np.array(lim, dtype=float))
    return controller.schedule_pitch, mats, controller.filter_omega, pi


# ----------------------------------------------------------------------------- compiled loop
@njit(cache=True)
def _wind_at(w, wdt, t):
    s = t / wdt
    i = int(s)
    if i >= w.size - 1:
        return w[w.size - 1]
    f = s - i
    return w[i] * (1.0 - f) + w[i + 1] * f


_KIND_TURBINE, _KIND_LINEAR = 0, 1


@njit(cache=True)
def _krhs(kind, x, wind, pitch_cmd, gen_torque, p, dx):
    # The built-in kernels are called directly (a function passed as an argument would
    # defeat numba's on-disk cache); other kernels get rebound copies, see _compiled_for.
    if kind == _KIND_TURBINE:
        _turbine_rhs(x, wind, pitch_cmd, gen_torque, p, dx)
    else:
        _lin_rhs(x, wind, pitch_cmd, gen_torque, p, dx)


@njit(cache=True)
def _kout(kind, x, wind, pitch_cmd, gen_torque, p, y):
    if kind == _KIND_TURBINE:
        _turbine_outputs(x, wind, pitch_cmd, gen_torque, p, y)
    else:
        _lin_outputs(x, wind, pitch_cmd, gen_torque, p, y)


@njit(cache=True)
def _rk4(kind, x, w, wdt, t, dt, beta_cmd, torque, p, k1, k2, k3, k4, xt):
    n = x.size
    _krhs(kind, x, _wind_at(w, wdt, t), beta_cmd, torque, p, k1)
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


_NONFINITE = 63  # divergence code of a non-finite output (else the index into the output limits)


@njit(cache=True)
def _run_one(kind, p, x, w, wdt, dt, nsteps, rec_every, Ad, Bd, Cd, Dd, sched_pitch, K,
             beta0, omega_ref, torque, a_filt, i_speed, i_vel, ny, Yr, pi_on, kp, ki, Af, Bf, Cf, Df, lim,
             cmd_lim, lim_idx, lim_val, Rq, Ns):
    """One run; returns −1, or 64·step + code at the first step where it diverged (code: the
    index of the output limit exceeded, or _NONFINITE)."""
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
    j = 0
    for k in range(nsteps):
        t = k * dt
        _kout(kind, x, _wind_at(w, wdt, t), bcmd, torque, p, y)
        for i in range(ny):
            if not math.isfinite(y[i]):
                return 64 * k + _NONFINITE
        for i in range(lim_idx.size):
            if abs(y[lim_idx[i]]) > lim_val[i]:
                return 64 * k + i
        if k % rec_every == 0:
            for i in range(ny):
                Yr[i, j] = y[i]
            Yr[ny, j] = bcmd
            j += 1
        # Both loops feed back with a minus sign: β = −C_β·ΔΩ_g − C_atd·ẋ_top.
        e = -(y[i_speed] - omega_ref)
        v = -y[i_vel]
        slow = False
        for q in range(K):
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
            while sched_pitch[q + 1] < bf:
                q += 1
            f = (bf - sched_pitch[q]) / (sched_pitch[q + 1] - sched_pitch[q])
        # Output blending (of the ATD locals only, in the scheduled-PI form).
        if f == 0.0:
            u = uk[q]
        else:
            u = (1.0 - f) * uk[q] + f * uk[q + 1]
        if slow:
            over = beta0 + u - cmd_lim[1]
            if over <= 0.0:
                over = min(beta0 + u - cmd_lim[0], 0.0)
            if over != 0.0:  # saturated: freeze the slow parts that push further past the limit
                for r in range(K):
                    if Ns[r] > 0 and Rq[r] != 0.0 and dslow[r] * over > 0.0:
                        iq[r] -= inc[r]
                        uk[r] -= inc[r]
                        for i in range(Ns[r]):
                            xn[r, i] = xc[r, i]
                if f == 0.0:
                    u = uk[q]
                else:
                    u = (1.0 - f) * uk[q] + f * uk[q + 1]
        for r in range(K):
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
            integ = min(max(integ, lo), hi)
            u += min(max(kpv * ef + integ, lo), hi)
        bcmd = min(max(beta0 + u, cmd_lim[0]), cmd_lim[1])
        bf += a_filt * (bcmd - bf)
        _rk4(kind, x, w, wdt, t, dt, bcmd, torque, p, k1, k2, k3, k4, xt)
    return -1


@njit(cache=True, parallel=True)
def _run_batch(kind, P, X0, W, wdt, dt, nsteps, rec_every, Ad, Bd, Cd, Dd, sched_pitch,
               beta0, omega_ref, torque, a_filt, i_speed, i_vel, ny, Y, pi_on, kp, ki, Af, Bf, Cf, Df, lim,
               cmd_lim, lim_idx, lim_val, Rq, Ns, status):
    """All runs, one per prange iteration; the controller bank is shared by the batch.
    ``status[r]``: −1, or where run r diverged (see :func:`_run_one`)."""
    K = sched_pitch.size
    for r in prange(X0.shape[0]):
        x = X0[r].copy()
        status[r] = _run_one(kind, P[r], x, W[r], wdt, dt, nsteps, rec_every, Ad, Bd, Cd, Dd, sched_pitch, K,
                             beta0[r], omega_ref[r], torque[r], a_filt, i_speed, i_vel, ny, Y[r], pi_on, kp, ki, Af, Bf,
                             Cf, Df, lim, cmd_lim, lim_idx, lim_val, Rq, Ns)


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
        _rk4(kind, x, W[r], wdt, t, dt, bcmd[r], torque[r], P[r], k1, k2, k3, k4, xt)
        y = Y[r]
        _kout(kind, x, _wind_at(W[r], wdt, t + dt), bcmd[r], torque[r], P[r], y)


@njit(cache=True)
def _outputs_all(kind, P, X, W, wdt, t, bcmd, torque, Y):
    for r in range(X.shape[0]):
        y = Y[r]
        _kout(kind, X[r], _wind_at(W[r], wdt, t), bcmd[r], torque[r], P[r], y)


_REBOUND = {}


def _compiled_for(rhs, outfn):
    """(kind, run_batch, step_all, outputs_all) for a kernel pair.

    The turbine and linear kernels use the cached module functions. Any other pair gets
    copies of the same loop code whose global names ``_krhs``/``_kout`` point at that
    pair: one source for every kernel, compiled once per process for user kernels.
    """
    import types

    if rhs is _lin_rhs:
        return _KIND_LINEAR, _run_batch, _step_all, _outputs_all
    if rhs is _turbine_rhs and outfn is _turbine_outputs:
        return _KIND_TURBINE, _run_batch, _step_all, _outputs_all
    key = (rhs, outfn)
    if key not in _REBOUND:
        g = dict(_run_one.py_func.__globals__)

        def krhs(kind, x, wind, pitch_cmd, gen_torque, p, dx):
            rhs(x, wind, pitch_cmd, gen_torque, p, dx)

        def kout(kind, x, wind, pitch_cmd, gen_torque, p, y):
            outfn(x, wind, pitch_cmd, gen_torque, p, y)

        g["_krhs"], g["_kout"] = njit(krhs), njit(kout)

        def copy(f, **kw):
            return njit(**kw)(types.FunctionType(f.py_func.__code__, g, f.py_func.__name__))

        g["_rk4"] = copy(_rk4)
        g["_run_one"] = copy(_run_one)
        _REBOUND[key] = (0, copy(_run_batch, parallel=True), copy(_step_all), copy(_outputs_all))
    return _REBOUND[key]


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
            from . import turbine

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

    _check_step(plant, vs, dt)
    trims = [plant.trim(v) for v in vs]
    beta0 = np.repeat([t[1] for t in trims], S)
    torque = np.repeat([t[2] for t in trims], S)
    if linear:
        if plant.linearize is None:
            raise ValueError("linear=True needs a plant with a linearize method")
        rhs, outfn = _lin_rhs, _lin_outputs
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
    kind, run_batch, step_all, outputs_all = _compiled_for(rhs, outfn)
    n_rec = (nsteps + rec_every - 1) // rec_every
    Y = np.empty((R, ny + 1, n_rec))
    omega_ref = np.full(R, plant.rated_speed)
    lim_names = tuple(plant.output_limits)
    lim_idx = np.array([plant.index(n) for n in lim_names], dtype=np.int64)
    lim_val = np.array([float(plant.output_limits[n]) for n in lim_names])
    status = np.full(R, -1, dtype=np.int64)

    if callable(controller) and not _is_lti_like(controller) and not isinstance(controller, ScheduledController):
        label = getattr(controller, "__name__", "callable")
        _run_callable(controller, step_all, outputs_all, kind, P, X0, Wr, wind_dt, dt, nsteps, rec_every, torque, beta0, ny, Y,
                      plant.output_names, lim_idx, lim_val, status)
        _raise_diverged(status, vs, seeds, S, dt, transient, lim_names, lim_val, str(label), linear)
    else:
        label = getattr(controller, "name", "controller")
        _warn_unstable(plant, controller, vs, dt)
        sched_pitch, mats, fw, pi = _bank(controller, dt)
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


def _check_step(plant, vs, dt):
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
    from .closedloop import closed_loop_matrices, hidden_origin_poles, loop_parts

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


def _check_loop_step(plant, controller, v, dt, parts=None):
    """Reject a step at which the sampled loop is unstable while the continuous one is stable
    (the controller's hold and Tustin map add phase lag): name the largest step that is not."""
    from .closedloop import loop_parts

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
    Where it is stable, reject a step ``dt`` at which the sampled loop is not (:func:`_check_loop_step`)."""
    if plant.linearize is None:
        return
    import warnings

    from .closedloop import ClosedLoopUnstableWarning, loop_parts, unstable_message, unstable_poles

    for v in vs:
        parts = loop_parts(plant, controller, v)
        bad = unstable_poles(plant, controller, v, parts=parts)
        if bad.size:
            tail = ("; the simulation runs on the pitch limits (a limit cycle, no result) if it does not diverge"
                    if plant.pitch_limits is not None else "; the simulated response grows without bound")
            warnings.warn(unstable_message(controller, v, bad) + tail, ClosedLoopUnstableWarning, stacklevel=3)
        else:
            _check_loop_step(plant, controller, v, dt, parts)


def _raise_diverged(status, vs, seeds, S, dt, transient, lim_names, lim_val, label, linear):
    bad = np.flatnonzero(status >= 0)
    if not bad.size:
        return
    r = int(bad[0])
    step, code = divmod(int(status[r]), 64)
    what = ("a non-finite output" if code == _NONFINITE
            else f"|{lim_names[code]}| above its physical limit {lim_val[code]:.4g}")
    seed = f"seed {seeds[r % S]}" if seeds is not None else f"record {r % S}"
    raise SimulationDivergedError(
        f"{'linear ' if linear else ''}simulation with controller {label!r} diverged at wind speed {vs[r // S]:g} m/s, "
        f"{seed}, t = {step * dt:.1f} s into the run (the record starts after {transient:g} s) ({what}; "
        f"{bad.size} of {status.size} runs): "
        "the closed loop is unstable at this operating point, or dt is too large")


def _is_lti_like(c) -> bool:
    import control

    return isinstance(c, control.LTI) or (hasattr(c, "tf") and callable(getattr(c, "tf")))


def _run_callable(fn, step_all, outputs_all, kind, P, X0, Wr, wdt, dt, nsteps, rec_every, torque, beta0, ny, Y, names,
                  lim_idx, lim_val, status):
    X = X0.copy()
    R = X.shape[0]
    bcmd = beta0.copy()
    y = np.empty((R, ny))
    outputs_all(kind, P, X, Wr, wdt, 0.0, bcmd, torque, y)
    j = 0
    for k in range(nsteps):
        t = k * dt
        # checked at the record steps: a per-step numpy check would cost as much as the step
        bad = (~np.all(np.isfinite(y), axis=1) | np.any(np.abs(y[:, lim_idx]) > lim_val, axis=1)
               if k % rec_every == 0 else np.zeros(0, bool))
        if np.any(bad):
            r = np.flatnonzero(bad)
            nonfinite = ~np.all(np.isfinite(y[r]), axis=1)
            over = np.argmax(np.abs(y[r][:, lim_idx]) > lim_val, axis=1)
            status[r] = 64 * k + np.where(nonfinite, _NONFINITE, over)
            return
        cmd = np.asarray(fn(t, {n: y[:, i].copy() for i, n in enumerate(names)}), dtype=float)
        if cmd.shape != (R,) or not np.all(np.isfinite(cmd)):
            raise ValueError(f"controller callable must return a finite pitch command (rad) of shape ({R},), got {cmd.shape}")
        if k % rec_every == 0:
            Y[:, :ny, j] = y
            Y[:, ny, j] = bcmd  # the command held during the previous step, as in the compiled loop
            j += 1
        bcmd = cmd
        step_all(kind, P, X, Wr, wdt, t, dt, bcmd, torque, y)
