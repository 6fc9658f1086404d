"""A turbine given by linear models at several wind speeds: the design loop on OpenFAST linearisations.

:class:`LinearTurbine` holds named LTI plants at strictly increasing mean wind speeds, their
operating points and the rotor radius, and offers the part of
:class:`specdesign.turbine.TurbineModel` the design loop uses: ``linearize(v)`` with the same
named inputs and outputs, ``wind_range``, ``rotor_radius``, ``check_wind_speed``, ``trim``,
plus :meth:`LinearTurbine.baseline_controller` (ROSCO's PI by pole placement on its own
linearisations, what :func:`specdesign.rosco.rosco_baseline` is for the reduced model) and
:meth:`LinearTurbine.kernel_plant` (the loop analysis of :mod:`specdesign.closedloop`).
So :func:`specdesign.spec.baseline_analysis`, :func:`specdesign.spec.shape_to_target`,
:func:`specdesign.spec.design_specifications`, :func:`specdesign.validate.linear_prediction`
and :func:`specdesign.validate.linear_table3` take it where they take a model.

Wind speeds between two linearisations: the state-space matrices and the operating point are
interpolated linearly, element by element, between the two neighbours (as ROSCO's
``LinearTurbineModel`` does); at a linearisation's speed it is returned as stored. This
needs one state basis for all (the same OpenFAST model: checked by state names). Speeds
outside the set are refused (no extrapolation); a set of one speed takes that speed only.

Build it from OpenFAST ``.lin`` files (:meth:`LinearTurbine.from_lin_files`, signals by
channel description: :data:`specdesign.openfast.signals.DEFAULT_SIGNALS`), from a dict of
plants (:meth:`LinearTurbine.from_plants`) or from a reduced model
(:meth:`LinearTurbine.from_model`).
"""
from __future__ import annotations

import glob
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .._checks import positive_scalar
from .._docs import docstring_of
from ..rosco import rosco_baseline, rosco_gain_schedule
from ..simulate import KernelPlant
from ..simulate.kernels import linear_outputs, linear_plant_params, linear_rhs
from ..turbine import TurbineModel
from .lin import read_lin_file, read_linearization, signal_label
from .signals import plant_from_linearization

__all__ = ["LinearOperatingPoint", "RotorModelSchedule", "LinearTurbine", "rotor_speed_model"]

_REQUIRED_IO = (("wind", "pitch_cmd"), ("gen_speed", "tower_base_my", "tower_top_vel"))
_SAME_SPEED = 1e-9  # relative: a requested speed this close to a linearisation's is that one


@dataclass(frozen=True)
class LinearOperatingPoint:
    """The operating point of one linearisation.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed (m/s).
    rotor_speed : float
        Rotor speed (rad/s).
    pitch : float
        Collective blade pitch (rad).
    gen_torque : float
        Generator torque (N·m; nan when unknown).
    x : tuple of float, optional
        The plant's states at the operating point (SI, in the order of the plant's states;
        OpenFAST's ``x_op``): the trim a model predicting in absolute values is about (the
        MPCs' scheduled Kalman filter). Empty when unknown.
    y : tuple of float, optional
        The plant's outputs at the operating point (SI, in the order of its outputs;
        OpenFAST's ``y_op``, zero for a ``d/dt`` output). Empty when unknown.
    """

    wind_speed: float
    rotor_speed: float
    pitch: float
    gen_torque: float = float("nan")
    x: tuple = ()
    y: tuple = ()


def rotor_speed_model(plant) -> tuple[float, float, float]:
    """The first-order rotor model δΩ̇_g = a·δΩ_g + b_β·δβ + b_v·δv read off a linearisation.

    The generator speed must be one state times a constant c (its C row, D row zero): then
    a = A[k, k], b_v = c·B[k, wind], and b_β = c·B[k, pitch_cmd] when the pitch command
    acts on the rotor directly (OpenFAST: no actuator), else c·A[k, j] with j the pitch
    state that the ``pitch`` output reads (the reduced model's actuator). The other states
    are frozen, as in ROSCO's tuning (for the reduced model this is
    :func:`specdesign.rosco.first_order_rotor_model`).

    Parameters
    ----------
    plant : control.StateSpace
        Named plant with inputs ``wind``, ``pitch_cmd`` and output ``gen_speed`` (and
        ``pitch`` when the pitch command reaches the rotor through an actuator).

    Returns
    -------
    a : float
        δΩ̇/δΩ (1/s).
    b_beta : float
        δΩ̇_g/δβ (rad/s² per rad).
    b_wind : float
        δΩ̇_g/δv (rad/s² per m/s).

    Raises
    ------
    ValueError
        The generator speed is not one state, or no pitch path to the rotor is found.
    """
    A, B, C, D = (np.asarray(m, float) for m in (plant.A, plant.B, plant.C, plant.D))
    ins, outs = list(plant.input_labels), list(plant.output_labels)
    row, drow = C[outs.index("gen_speed")], D[outs.index("gen_speed")]
    k = int(np.argmax(np.abs(row)))
    c = row[k]
    if c == 0 or np.any(np.abs(np.delete(row, k)) > 1e-9 * abs(c)) or np.any(drow):
        raise ValueError("gen_speed is not one state of the plant, so the first-order rotor model cannot be read off; "
                         "give the baseline gains with schedule=")
    b_beta = c * B[k, ins.index("pitch_cmd")]
    if b_beta == 0 and "pitch" in outs:
        prow = C[outs.index("pitch")]
        j = int(np.argmax(np.abs(prow)))
        b_beta = c * A[k, j] / prow[j]
    if b_beta == 0:
        raise ValueError("the pitch command does not reach the rotor-speed state; give the baseline gains with schedule=")
    return float(A[k, k]), float(b_beta), float(c * B[k, ins.index("wind")])


@dataclass(frozen=True)
class RotorModelSchedule:
    """ROSCO's pole placement on the first-order rotor model of each linearisation.

    With e = Ω_ref − Ω_g and β = Kp·e + Ki∫e the rotor loop is s² + (b_β·Kp − a)s + b_β·Ki;
    matching s² + 2ζω s + ω² gives Kp = (2ζω + a)/b_β, Ki = ω²/b_β (ROSCO's sign), with
    (a, b_β) of :func:`rotor_speed_model` on ``turbine.linearize(v)``: at each speed, no line
    fit (ROSCO fits a line over ~30 speeds; a set may have one).

    Parameters
    ----------
    turbine : LinearTurbine
        The linearisations.
    omega_pc : float
        Natural frequency of the placed rotor-speed poles (rad/s).
    zeta_pc : float
        Their damping ratio (-).
    """

    turbine: object = field(repr=False)
    omega_pc: float = 0.2
    zeta_pc: float = 1.0

    def gains(self, wind_speeds) -> tuple[np.ndarray, np.ndarray]:
        """(Kp, Ki) at ``wind_speeds`` in ROSCO's sign (s, -).

        Parameters
        ----------
        wind_speeds : float or array_like
            Mean wind speeds (m/s) within the turbine's ``wind_range``.

        Returns
        -------
        Kp, Ki : numpy.ndarray
            Proportional (s) and integral (-) gains, shaped as ``wind_speeds``.

        Raises
        ------
        ValueError
            A speed outside the linearisations.
        """
        v = np.asarray(wind_speeds, float)
        ab = np.array([rotor_speed_model(self.turbine.linearize(float(s)))[:2] for s in v.ravel()]).reshape(v.shape + (2,))
        a, b = ab[..., 0], ab[..., 1]
        return (2 * self.zeta_pc * self.omega_pc + a) / b, self.omega_pc**2 / b


def _as_plant(sys, v):
    import control

    if not isinstance(sys, control.StateSpace):
        if not isinstance(sys, control.LTI):
            raise TypeError(f"plant at {v:g} m/s must be a python-control LTI system, got {type(sys).__name__}")
        sys = control.ss(sys)
    ins, outs = list(sys.input_labels), list(sys.output_labels)
    missing = [n for n in _REQUIRED_IO[0] if n not in ins] + [n for n in _REQUIRED_IO[1] if n not in outs]
    if missing:
        raise ValueError(f"plant at {v:g} m/s lacks the signals {missing} (inputs {ins}, outputs {outs}); the design loop "
                         "needs inputs wind, pitch_cmd and outputs gen_speed, tower_base_my, tower_top_vel")
    if sys.isdtime(strict=True):
        raise ValueError(f"plant at {v:g} m/s is discrete-time; give the continuous linearisation")
    return sys


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class LinearTurbine:
    """Linear plants at strictly increasing wind speeds, usable where the design loop takes a model.

    See the module docstring for the interpolation between speeds. Build it with
    :meth:`from_lin_files`, :meth:`from_plants` or :meth:`from_model`.

    Parameters
    ----------
    wind_speeds : array_like
        Mean wind speeds of the linearisations (m/s), strictly increasing, at least one.
    plants : sequence of control.StateSpace
        One per speed, inputs ``wind`` (m/s), ``pitch_cmd`` (rad) [, ``gen_torque`` N·m],
        outputs at least ``gen_speed`` (rad/s), ``tower_base_my`` (N·m), ``tower_top_vel``
        (m/s); the same signals and states at every speed; deviations from the operating point.
    operating_points : sequence of LinearOperatingPoint
        One per speed (its ``wind_speed`` must be that speed).
    rotor_radius : float
        Rotor radius (m), for the rotor-effective wind spectrum.
    name : str, optional
        Label.
    schedule : object, optional
        The baseline PI gains: anything with ``gains(wind_speed) -> (Kp, Ki)`` in ROSCO's sign
        (a :class:`specdesign.rosco.RoscoSchedule`); default :class:`RotorModelSchedule`. A
        :class:`RotorModelSchedule` is always placed on this turbine's plants (its ``turbine``
        rebound: on a copy made by ``dataclasses.replace``, the copy's).
    sources : tuple of str, optional
        Where the plants came from (file paths), for the record.
    pitch_min, pitch_max : float, optional
        Pitch position limits (rad) of the turbine's actuator, which a linearisation does not
        carry (nan: unknown): what a controller that constrains its commands reads, as it reads a
        :class:`~specdesign.turbine.TurbineModel`'s (``dataclasses.replace(lt, pitch_min=...)``).
    pitch_rate_limit : float, optional
        Pitch-rate limit (rad/s) of the actuator; nan: unknown.

    Raises
    ------
    ValueError
        Speeds not strictly increasing (repeated speeds named), counts that differ, plants
        without the required signals or with other signals or states than the first, a
        non-positive rotor radius, operating-point states or outputs of another length than the
        plant's.

    Notes
    -----
    Picklable (python-control's systems are not): the plants are pickled as their matrices and
    signal names, and the default schedule is rebuilt on the unpickled turbine.
    """

    wind_speeds: np.ndarray
    plants: tuple = field(repr=False)
    operating_points: tuple = field(repr=False)
    rotor_radius: float
    name: str = "linear turbine"
    schedule: object = field(default=None, repr=False)
    sources: tuple = ()
    pitch_min: float = float("nan")
    pitch_max: float = float("nan")
    pitch_rate_limit: float = float("nan")

    def __post_init__(self):
        v = np.atleast_1d(np.asarray(self.wind_speeds, float))
        if v.ndim != 1 or v.size == 0 or not np.all(np.isfinite(v)) or np.any(v <= 0):
            raise ValueError(f"wind_speeds={self.wind_speeds!r} must be one or more positive wind speeds in m/s")
        dup = v[1:][np.diff(v) == 0]
        if dup.size:
            raise ValueError(f"wind_speeds repeat {sorted(set(dup.tolist()))} m/s: give one linearisation per speed "
                             "(the azimuth files of one operating point are averaged by read_linearization)")
        if np.any(np.diff(v) < 0):
            raise ValueError(f"wind_speeds={v.tolist()} must be strictly increasing")
        plants = tuple(_as_plant(p, s) for p, s in zip(self.plants, v))
        ops = tuple(self.operating_points)
        if len(plants) != v.size or len(ops) != v.size:
            raise ValueError(f"{v.size} wind speeds need as many plants and operating points, got {len(self.plants)} "
                             f"and {len(ops)}")
        for p, s in zip(plants[1:], v[1:]):
            if (p.input_labels, p.output_labels, p.state_labels) != (plants[0].input_labels, plants[0].output_labels,
                                                                     plants[0].state_labels):
                raise ValueError(f"plant at {s:g} m/s has other signals or states than at {v[0]:g} m/s: the matrices "
                                 "of one OpenFAST model are interpolated, so every plant needs the same ones")
        for op, s in zip(ops, v):
            if not isinstance(op, LinearOperatingPoint) or not math.isclose(op.wind_speed, s, rel_tol=_SAME_SPEED):
                raise ValueError(f"operating_points must be LinearOperatingPoint records at the wind speeds, got {op!r} "
                                 f"at {s:g} m/s")
            if len(op.x) not in (0, plants[0].nstates) or len(op.y) not in (0, plants[0].noutputs):
                raise ValueError(f"the operating point at {s:g} m/s has {len(op.x)} states and {len(op.y)} outputs; the "
                                 f"plant has {plants[0].nstates} and {plants[0].noutputs} (or give none: unknown)")
        v.flags.writeable = False
        object.__setattr__(self, "wind_speeds", v)
        object.__setattr__(self, "plants", plants)
        object.__setattr__(self, "operating_points", ops)
        object.__setattr__(self, "rotor_radius", positive_scalar(self.rotor_radius, "rotor_radius"))
        if self.schedule is None:
            object.__setattr__(self, "schedule", RotorModelSchedule(self))
        elif isinstance(self.schedule, RotorModelSchedule) and self.schedule.turbine is not self:
            # pole placement on *these* plants (a copy by dataclasses.replace, an unpickled turbine)
            object.__setattr__(self, "schedule", RotorModelSchedule(self, self.schedule.omega_pc, self.schedule.zeta_pc))
        for k in ("pitch_min", "pitch_max", "pitch_rate_limit"):
            object.__setattr__(self, k, float(getattr(self, k)))

    def __reduce__(self):
        plants = tuple((np.asarray(p.A, float), np.asarray(p.B, float), np.asarray(p.C, float), np.asarray(p.D, float),
                        tuple(p.input_labels), tuple(p.output_labels), tuple(p.state_labels)) for p in self.plants)
        schedule = self.schedule
        if isinstance(schedule, RotorModelSchedule):  # refers back to this turbine: rebound by __post_init__
            schedule = RotorModelSchedule(None, schedule.omega_pc, schedule.zeta_pc)
        return _unpickle_linear_turbine, (self.wind_speeds.copy(), plants, self.operating_points, self.rotor_radius,
                                          self.name, schedule, self.sources, self.pitch_min, self.pitch_max,
                                          self.pitch_rate_limit)

    # -- the TurbineModel interface the design loop uses ------------------------------------
    @property
    def wind_range(self) -> tuple[float, float]:
        """(lowest, highest) wind speed of the linearisations (m/s)."""
        return float(self.wind_speeds[0]), float(self.wind_speeds[-1])

    @property
    def output_names(self) -> tuple:
        """Names of the plant outputs."""
        return tuple(self.plants[0].output_labels)

    @property
    def rated_rotor_speed(self) -> float:
        """Rotor-speed reference (rad/s): the operating points' rotor speed at the highest wind speed."""
        return float(self.operating_points[-1].rotor_speed)

    @docstring_of(TurbineModel)
    def check_wind_speed(self, wind_speed: float) -> float:
        v = positive_scalar(wind_speed, "wind_speed")
        lo, hi = self.wind_range
        tol = _SAME_SPEED * hi
        if not lo - tol <= v <= hi + tol:
            which = f"{lo:g} m/s only (one linearisation)" if lo == hi else f"{lo:g}-{hi:g} m/s"
            raise ValueError(f"wind_speed={v!r} m/s is outside the linearisations of {self.name!r}: {which}; a "
                             "LinearTurbine interpolates between its speeds and does not extrapolate (add a .lin set there)")
        return v

    def _bracket(self, v):
        """(i, j, t): the neighbours and the weight of j (t = 0 at a linearisation's speed)."""
        v = self.check_wind_speed(v)
        vs = self.wind_speeds
        near = int(np.argmin(np.abs(vs - v)))
        if math.isclose(vs[near], v, rel_tol=_SAME_SPEED):
            return near, near, 0.0
        j = int(np.searchsorted(vs, v))
        return j - 1, j, float((v - vs[j - 1]) / (vs[j] - vs[j - 1]))

    def linearize(self, wind_speed: float):
        """The plant at ``wind_speed``: stored at a linearisation's speed, interpolated between two.

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s) within ``wind_range``.

        Returns
        -------
        control.StateSpace
            Named like the stored plants, named ``<name>@<v>mps``.

        Raises
        ------
        ValueError
            Outside ``wind_range``.

        Examples
        --------
        >>> from specdesign.turbine import iea15mw
        >>> lt = LinearTurbine.from_model(iea15mw(), (17.0, 19.0))
        >>> lt.linearize(18.0).output_labels[0]
        'gen_speed'
        """
        import control

        i, j, t = self._bracket(wind_speed)
        p, q = self.plants[i], self.plants[j]
        mats = [np.asarray(a, float) if t == 0 else (1 - t) * np.asarray(a, float) + t * np.asarray(b, float)
                for a, b in ((p.A, q.A), (p.B, q.B), (p.C, q.C), (p.D, q.D))]
        v = float(wind_speed)
        return control.ss(*mats, inputs=list(p.input_labels), outputs=list(p.output_labels),
                          states=list(p.state_labels), name=f"{self.name}@{v:g}mps".replace(".", "p").replace(" ", "_"))

    def trim(self, wind_speed: float) -> LinearOperatingPoint:
        """The operating point at ``wind_speed`` (interpolated as the plants are).

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s) within ``wind_range``.

        Returns
        -------
        LinearOperatingPoint
            Rotor speed, pitch and generator torque there, and the states and outputs when the
            operating points carry them.

        Raises
        ------
        ValueError
            Outside ``wind_range``.
        """
        i, j, t = self._bracket(wind_speed)
        a, b = self.operating_points[i], self.operating_points[j]
        mix = [(1 - t) * x + t * y if t else x for x, y in ((a.rotor_speed, b.rotor_speed), (a.pitch, b.pitch),
                                                             (a.gen_torque, b.gen_torque))]
        vec = [tuple(float(e) for e in ((1 - t) * np.asarray(x, float) + t * np.asarray(y, float)))
               if len(x) and len(y) else () for x, y in ((a.x, b.x), (a.y, b.y))]
        return LinearOperatingPoint(float(wind_speed), *(float(m) for m in mix), *vec)

    def evaluate_outputs(self, x, wind_speed: float, pitch: float, gen_torque: float) -> np.ndarray:
        """The linear model's outputs at state ``x`` about the operating point at ``wind_speed``.

        y = ȳ + C (x − x̄) + D_β (β − β̄) + D_τ (τ − τ̄), the wind at its mean: what
        :meth:`specdesign.turbine.TurbineModel.evaluate_outputs` is for the reduced model, so a
        controller that predicts in absolute values (:func:`specdesign.mpc.base.discretize_turbine`)
        takes this turbine.

        Parameters
        ----------
        x : array_like
            (n,) absolute state (SI, the plant's states).
        wind_speed : float
            Mean wind speed (m/s) within ``wind_range``.
        pitch : float
            Pitch command (rad).
        gen_torque : float
            Generator torque (N·m); ignored by a plant without a ``gen_torque`` input.

        Returns
        -------
        numpy.ndarray
            (p,) outputs in the order of :attr:`output_names` (SI).

        Raises
        ------
        ValueError
            Outside ``wind_range``, or operating points without their states and outputs
            (``x``, ``y``: :meth:`from_lin_files` reads them, :meth:`from_model` computes them).
        """
        op, sys = self.trim(wind_speed), self.linearize(wind_speed)
        if not op.x or not op.y:
            raise ValueError(f"the operating points of {self.name!r} carry no states and outputs (x, y), so absolute "
                             "outputs are unknown; build it with from_lin_files or from_model")
        C, D = np.asarray(sys.C, float), np.asarray(sys.D, float)
        ins = list(sys.input_labels)
        y = np.asarray(op.y, float) + C @ (np.asarray(x, float) - np.asarray(op.x, float))
        y += D[:, ins.index("pitch_cmd")] * (float(pitch) - op.pitch)
        if "gen_torque" in ins:
            y += D[:, ins.index("gen_torque")] * (float(gen_torque) - op.gen_torque)
        return y

    def baseline_controller(self, wind_speed: float):
        """ROSCO's baseline PI at ``wind_speed``: C(s) = (Kp + Ki/s)·F_lpf(s), gains from ``schedule``.

        :func:`specdesign.rosco.rosco_baseline` with this turbine's schedule (sign convention
        β = −C·Ω_g; tower damping off); ROSCO's speed filter
        (:func:`specdesign.rosco.speed_filter`).

        Parameters
        ----------
        wind_speed : float
            Mean wind speed (m/s) within ``wind_range``.

        Returns
        -------
        control.TransferFunction
            C(s) from ``gen_speed`` (rad/s) to ``pitch_cmd`` (rad).

        Raises
        ------
        ValueError
            Outside ``wind_range``, or a plant whose rotor model cannot be read
            (:func:`rotor_speed_model`).
        """
        return rosco_baseline(self, wind_speed, schedule=self.schedule)

    def kernel_plant(self):
        """The set as a :class:`specdesign.simulate.KernelPlant` for the loop analysis.

        What :mod:`specdesign.closedloop` (poles, blending of scheduled controllers) and
        :func:`specdesign.validate.closed_loop_response` read: ``linearize`` (with a zero
        ``gen_torque`` column when the plants have none), ``output_names`` and ``trim``. Its
        kernel is the linear one about the *first* linearisation: a time-domain
        simulation of it is that linear model at that speed only.

        Returns
        -------
        KernelPlant
            The plant.
        """
        import control

        def linearize(v):
            sys = self.linearize(v)
            if "gen_torque" in sys.input_labels:
                return sys
            B = np.hstack([np.asarray(sys.B, float), np.zeros((sys.nstates, 1))])
            D = np.hstack([np.asarray(sys.D, float), np.zeros((sys.noutputs, 1))])
            return control.ss(sys.A, B, sys.C, D, inputs=list(sys.input_labels) + ["gen_torque"],
                              outputs=list(sys.output_labels), states=list(sys.state_labels))

        def trim(v):
            op = self.trim(v)
            return np.zeros(self.plants[0].nstates), op.pitch, op.gen_torque

        op0 = self.operating_points[0]
        params = linear_plant_params(linearize(op0.wind_speed), [op0.wind_speed, op0.pitch, op0.gen_torque],
                                     np.zeros(len(self.output_names)))
        return KernelPlant(rhs=linear_rhs, outputs=linear_outputs, params=params, output_names=self.output_names,
                           trim=trim, rated_speed=self.rated_rotor_speed, linearize=linearize, name=self.name)

    # -- constructors -----------------------------------------------------------------------
    @classmethod
    def from_plants(cls, plants: Mapping, *, rotor_radius: float, operating_points: Mapping | None = None,
                    name: str = "linear turbine", schedule: object = None) -> LinearTurbine:
        """From a dict {wind speed (m/s): named plant}.

        Parameters
        ----------
        plants : dict
            Wind speed (m/s) → ``control.StateSpace`` (signals as in :class:`LinearTurbine`);
            any order (sorted here).
        rotor_radius : float
            Rotor radius (m).
        operating_points : dict, optional
            Wind speed → :class:`LinearOperatingPoint`; default: unknown (nan rotor speed,
            pitch and torque: enough for LTI controllers, not for a scheduled one).
        name : str, optional
            Label.
        schedule : object, optional
            Baseline gains (see :class:`LinearTurbine`).

        Returns
        -------
        LinearTurbine
            The set.

        Raises
        ------
        ValueError
            An empty dict or invalid plants (see :class:`LinearTurbine`).
        """
        if not isinstance(plants, Mapping) or not plants:
            raise ValueError("plants must be a non-empty dict {wind speed m/s: plant}")
        vs = sorted(float(v) for v in plants)
        by = {float(v): p for v, p in plants.items()}
        nan = float("nan")
        ops = {float(v): op for v, op in (operating_points or {}).items()}
        return cls(np.array(vs), tuple(by[v] for v in vs),
                   tuple(ops.get(v, LinearOperatingPoint(v, nan, nan, nan)) for v in vs), rotor_radius, name, schedule)

    @classmethod
    def from_model(cls, model, wind_speeds: Sequence[float], *, schedule: object = "rosco") -> LinearTurbine:
        """The linearisations of a :class:`specdesign.turbine.TurbineModel` at ``wind_speeds``.

        Parameters
        ----------
        model : TurbineModel
            The reduced model.
        wind_speeds : sequence of float
            Mean wind speeds (m/s).
        schedule : "rosco", None or object, optional
            ``"rosco"`` (default): the model's own :func:`specdesign.rosco.rosco_gain_schedule`,
            so the baseline is the model's :func:`~specdesign.rosco.rosco_baseline`; None:
            :class:`RotorModelSchedule`; or any ``gains(v)`` object.

        Returns
        -------
        LinearTurbine
            Plants ``model.linearize(v)``, operating points of ``model.trim(v)`` (with its states
            and outputs), the model's pitch limits and pitch-rate limit.
        """
        vs = [float(v) for v in wind_speeds]
        sched = rosco_gain_schedule(model) if isinstance(schedule, str) and schedule == "rosco" else schedule
        ops = {}
        for v in vs:
            op = model.trim(v)
            ops[v] = LinearOperatingPoint(v, float(op.rotor_speed), float(op.pitch), float(op.gen_torque),
                                          tuple(float(e) for e in op.x),
                                          tuple(float(e) for e in model.evaluate_outputs(op.x, v, op.pitch, op.gen_torque)))
        lt = cls.from_plants({v: model.linearize(v) for v in vs}, rotor_radius=model.rotor_radius, operating_points=ops,
                             name=model.name, schedule=sched)
        for k in ("pitch_min", "pitch_max", "pitch_rate_limit"):  # the reduced model's actuator limits
            object.__setattr__(lt, k, float(getattr(model, k)))
        return lt

    @classmethod
    def from_lin_files(cls, paths, signals: dict | None = None, *, rotor_radius: float | None = None,
                       name: str | None = None, schedule: object = None) -> LinearTurbine:
        """From OpenFAST ``.lin`` files at one or more wind speeds.

        Files are grouped by the wind speed in their header; the files of one speed (one per
        azimuth) are MBC-transformed and averaged (:func:`specdesign.openfast.read_linearization`).

        Parameters
        ----------
        paths : str, os.PathLike or sequence of them
            Files, or a glob pattern (``"lin/*.lin"``).
        signals : dict, optional
            Overrides of :data:`specdesign.openfast.signals.DEFAULT_SIGNALS`.
        rotor_radius : float, optional
            Rotor radius (m); default √(A/π) of AeroDyn's rotor area output ``RtArea`` at the
            operating point (the swept area, with precone and deflection).
        name : str, optional
            Label; default the first file's name without its extensions.
        schedule : object, optional
            Baseline gains (see :class:`LinearTurbine`).

        Returns
        -------
        LinearTurbine
            The set; ``sources`` lists the files.

        Raises
        ------
        ValueError
            No file matches; a signal is missing (named, with the file's channels); no rotor
            radius; or the errors of :func:`specdesign.openfast.read_linearization`.

        Examples
        --------
        >>> from importlib import resources
        >>> lt = LinearTurbine.from_lin_files(resources.files("specdesign") / "data/iea15mw/sample_floating_19mps.1.lin")
        >>> lt.wind_range, round(lt.rotor_radius, 1)
        ((19.0, 19.0), 119.5)
        """
        if isinstance(paths, (str, os.PathLike)):
            p = os.fspath(paths)
            files = sorted(glob.glob(p)) if glob.has_magic(p) else [p]
        else:
            files = [os.fspath(f) for f in paths]
        if not files:
            raise ValueError(f"paths={paths!r} matches no .lin file")
        groups = {}
        for f in files:
            groups.setdefault(read_lin_file(f).wind_speed, []).append(f)
        plants, ops, radius = {}, {}, rotor_radius
        for v, group in groups.items():
            data = read_linearization(group)
            plants[v], used = plant_from_linearization(data, signals)
            u = dict(zip(data.u_desc, data.u_op))
            pitch = next((x for d, x in u.items() if "collective blade-pitch" in d.lower()), float("nan"))
            torque = next((x for d, x in u.items() if "generator torque" in d.lower()), float("nan"))
            # the kept states by their labels (plant_from_linearization's); a d/dt output is 0 at the
            # operating point (a steady state, averaged over the azimuths)
            xd = [signal_label(d) for d in data.x_desc]
            x_op = tuple(float(data.x_op[xd.index(s)]) for s in plants[v].state_labels)
            y_op = tuple(0.0 if used[n].startswith("d/dt ") else float(data.y_op[data.y_desc.index(used[n])])
                         for n in plants[v].output_labels)
            ops[v] = LinearOperatingPoint(float(v), data.rotor_speed, float(pitch), float(torque), x_op, y_op)
            if radius is None:
                area = [x for d, x in zip(data.y_desc, data.y_op) if d.startswith("AD RtArea")]
                if not area:
                    raise ValueError(f"{group[0]} has no AeroDyn RtArea output to take the rotor radius from; give rotor_radius= (m)")
                radius = math.sqrt(area[0] / math.pi)
        label = name or os.path.basename(files[0]).split(".")[0]
        lt = cls.from_plants(plants, rotor_radius=radius, operating_points=ops, name=label, schedule=schedule)
        object.__setattr__(lt, "sources", tuple(files))
        return lt


def _unpickle_linear_turbine(wind_speeds, plants, operating_points, rotor_radius, name, schedule, sources, pitch_min,
                             pitch_max, pitch_rate_limit):
    """A :class:`LinearTurbine` from its :meth:`LinearTurbine.__reduce__` record."""
    import control  # imported where used, as this module's other builders of systems do (heavy)

    systems = tuple(control.ss(A, B, C, D, inputs=list(i), outputs=list(o), states=list(x)) for A, B, C, D, i, o, x in plants)
    return LinearTurbine(wind_speeds, systems, operating_points, rotor_radius, name, schedule, sources, pitch_min,
                         pitch_max, pitch_rate_limit)
