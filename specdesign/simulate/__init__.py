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
command low-pass filtered (first order at ``filter_omega``, or second order with
``filter_damping`` as ROSCO filters it), with piecewise-linear weights
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
command in rad for all runs, or a tuple of it and the generator torque in N·m on the rotor
shaft, which the controller then commands; a ``start(dt, wind, pitch, torque)`` method, if it
has one, is called once before the first step; use it for MPC or other time-domain
controllers, and for ROSCO's compiled controller, :class:`specdesign.rosco.Discon`). A
callable must return finite commands; a NaN or inf measurement is handled alike by every
controller of the package (one private helper, ``bad_measurements``): the run holds its
last command and its state until the signal is finite again, with one RuntimeWarning per
signal naming it, the time and the run. A callable that returns a non-finite command anyway
is stopped with a ValueError naming the time and the measurements that were not finite.

Generator torque (``simulate(..., torque_control=...)``): above rated the torque is held at
the trim's (rated) torque, as ever. Below rated the compiled loop runs ROSCO's torque
controller, :class:`specdesign.rosco.TorqueLaw` (the model's ``torque_control``, e.g. the one
:func:`specdesign.turbine.iea15mw` carries, or one read from a DISCON.IN with
:func:`specdesign.rosco.torque_law_from_discon`): each step
:func:`specdesign.rosco.torque_step` filters the measured rotor speed as ROSCO does,
applies K·Ω² with the region-1.5/2.5 PIs and ROSCO's state machine (``VS_ControlMode`` 1) or
the TSR-tracking PI (3, 4), the setpoint smoother, the torque limits and rate limit, and
commands the torque for the step; the smoother's shift of the pitch reference moves the
pitch controller's speed reference (Ω_rated − ΔΩ_f when ΔΩ_f < 0). The pitch controller
runs as above: below rated its error is negative and its command sits at the minimum pitch
(ROSCO's form clamps its integrator there, an LTI controller's integrator is clamped or
frozen, see :func:`simulate`), so the pitch is held at fine pitch as ROSCO holds it.
``torque_control="auto"`` (default) runs the law in the runs whose wind speed is below rated
and holds the trim torque in the others (bit for bit the results before the law existed),
except a law with constant power above rated (``VS_ConstPower = 1``, e.g. the NREL 5 MW's
DISCON.IN), which runs in every run as the linearisation has it, and any law under a
controller with peak shaving (below);
``"rosco"`` runs it in every run (region 3 is then rated torque, or rated power
P/(η·Ω_f) with ``VS_ConstPower = 1``, with the transitions);
a ``TorqueLaw`` runs that law in every run; ``None`` holds the trim torque everywhere.

Peak shaving (a :class:`ScheduledController` in ROSCO's form with ``peak_shaving``, which
:func:`specdesign.rosco.rosco_scheduled` attaches for a DISCON.IN with ``PS_Mode = 1``): each
step :func:`specdesign.controller.peak_shaving.peak_shaving_step` runs ROSCO's wind-speed
estimator (its extended Kalman filter, ported) on the measured rotor speed, the last pitch
command and the last torque command, and lifts the PI's lower limit to ``PS_BldPitchMin`` at
the filtered estimate (the integrator at the last step's limit, the command at this one's, as
ROSCO). As in ROSCO, the torque law then reads the last pitch command as the measured pitch and
that limit as the minimum pitch (smoother, state machine), the smoother's shift of the
speed reference enters the PI's error unfiltered, and a file in ``VS_ControlMode = 2`` gives
the torque law its reference TSR·WE_Vw/R on the estimate
(:func:`specdesign.controller.peak_shaving.tsr_reference`). A controller without it runs bit
for bit as before.
The pitch loop's stability check (:func:`warn_unstable`) covers the speeds at or above rated
only: below rated the pitch loop is open.

A linear simulation of the same closed loop (``linear=True``) integrates the linearisation
``model.linearize(v)`` with the same loop, the same RK4 step and the same discrete
controller, so differences between the two are the plant's nonlinearity only. Below rated
the linearisation has the torque law closed in it (:meth:`specdesign.turbine.TurbineModel.linearize`)
and its torque input is held at the trim.

Layout
------
- :mod:`specdesign.simulate.core`: :func:`simulate`, :class:`SimulationResult`,
  :class:`SimulationDivergedError`.
- :mod:`specdesign.simulate.checks`: the step checks (:func:`check_step`,
  :func:`check_loop_step`, :func:`sampled_loop_radius`).
- :mod:`specdesign.simulate.kernels`: the numba kernels (the compiled loop, the linear plant).
- Re-exported here, the same objects, from the layers the simulator stands on:
  :class:`ScheduledController` (:mod:`specdesign.controller.scheduled`), the controller
  preparation :func:`as_lti`, :func:`tustin_matrices`, :func:`split_integrator`,
  :func:`split_slow` (:mod:`specdesign.controller.lti`), the plant :class:`KernelPlant`,
  :func:`turbine_plant` and :func:`scheduled` (:mod:`specdesign.turbine.plant`),
  :func:`rosco_scheduled` (:mod:`specdesign.rosco`), :func:`wind_series` and :func:`seed_for`
  (:mod:`specdesign.wind`), the measurement model :class:`SensorNoise` and
  :data:`IEA15MW_SENSORS` (:mod:`specdesign.controller.noise`, ``simulate(..., noise=...)``).
"""
from __future__ import annotations

from ..controller.lti import SLOW_OMEGA, as_lti, is_lti_like, split_integrator, split_slow, tustin_matrices
from ..controller.noise import IEA15MW_SENSORS, SensorNoise
from ..controller.scheduled import FORMS, SCHEDULE_FILTER_OMEGA, ScheduledController
from ..rosco import rosco_scheduled
from ..turbine.plant import KernelPlant, scheduled, turbine_plant
from ..wind import seed_for, wind_series
from .checks import MAX_STEP_EIGENVALUE, check_loop_step, check_step, sampled_loop_radius, warn_unstable
from .core import WIND_MEAN_TOLERANCE, SimulationDivergedError, SimulationResult, simulate
from .kernels import linear_plant_params

__all__ = [
    "SensorNoise",
    "IEA15MW_SENSORS",
    "SimulationDivergedError",
    "KernelPlant",
    "ScheduledController",
    "SimulationResult",
    "turbine_plant",
    "scheduled",
    "rosco_scheduled",
    "tustin_matrices",
    "split_integrator",
    "split_slow",
    "sampled_loop_radius",
    "simulate",
    "linear_plant_params",
    "check_step",
    "check_loop_step",
    "is_lti_like",
    "as_lti",
    "seed_for",
    "wind_series",
    "MAX_STEP_EIGENVALUE",
    "WIND_MEAN_TOLERANCE",
    "SCHEDULE_FILTER_OMEGA",
    "SLOW_OMEGA",
    "FORMS",
    "warn_unstable",
]
