"""ROSCO's pitch controller as the simulator runs it: :func:`rosco_scheduled`.

The baseline PI of :func:`specdesign.rosco.rosco_baseline` scheduled on the filtered pitch,
from the model's gain schedule (:func:`specdesign.rosco.rosco_gain_schedule`) or from a
DISCON.IN (:func:`specdesign.rosco.from_discon`; the IEA 15 MW's ships with the package,
:func:`iea15mw_discon`), as a :class:`specdesign.simulate.ScheduledController`.
"""
from __future__ import annotations

import dataclasses
import math
from importlib import resources
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike

from ..controller.discon_file import DisconSchedule
from ..controller.scheduled import FORMS, SCHEDULE_FILTER_OMEGA, ScheduledController
from ..turbine import TurbineModel, iea15mw
from ..turbine.baseline import (
    RoscoSchedule,
    rosco_baseline,
    rosco_gain_schedule,
    speed_filter,
)
from ..turbine.plant import scheduled, turbine_plant
from ..turbine.tables import DATA_DIR

__all__ = ["SCHEDULING_FILTERS", "ROSCO_SCHEDULE_CORNER", "ROSCO_SCHEDULE_DAMPING", "iea15mw_discon", "rosco_scheduled"]


def iea15mw_discon() -> Path:
    """Path of the shipped DISCON.IN of the IEA 15 MW monopile (ROSCO 2.9.4 tuning).

    Its ``PerfFileName`` points outside the package: it reads as a schedule
    (:func:`from_discon`) but the compiled ROSCO cannot run it as it is.

    Returns
    -------
    pathlib.Path
        ``specdesign/data/iea15mw/IEA-15-240-RWT-Monopile_DISCON.IN``.

    Examples
    --------
    >>> iea15mw_discon().name
    'IEA-15-240-RWT-Monopile_DISCON.IN'
    """
    return Path(str(resources.files("specdesign").joinpath(f"{DATA_DIR}/IEA-15-240-RWT-Monopile_DISCON.IN")))


#: Scheduling filters of :func:`rosco_scheduled`: the workbench's first-order low-pass at
#: :data:`specdesign.simulate.SCHEDULE_FILTER_OMEGA` (the default), or ROSCO's own.
SCHEDULING_FILTERS = ("first_order", "rosco")

#: ROSCO's scheduling-pitch filter (``Filters.f90``): second order at this fraction of
#: F_LPFCornerFreq, with damping :data:`ROSCO_SCHEDULE_DAMPING`.
ROSCO_SCHEDULE_CORNER = 0.25
#: Damping ratio of ROSCO's scheduling-pitch filter.
ROSCO_SCHEDULE_DAMPING = 0.7


def rosco_scheduled(model: TurbineModel | None = None, wind_speeds: ArrayLike | None = None, *, name: str = "ROSCO",
                    form: str = "gains", schedule: object = None,
                    scheduling_filter: str = "first_order") -> ScheduledController:
    """The ROSCO baseline PI (tower damping off) with its gain schedule on filtered pitch.

    ``form="gains"`` (default) is ROSCO's own scheduling: K_p and K_i of
    :func:`rosco_baseline` at ``wind_speeds``, placed at each speed's trim pitch, interpolated
    linearly in the filtered pitch command, applied to one error filtered by
    :func:`speed_filter` with one integrator of K_i(β_f)·e_f, integrator and output saturated
    at the model's pitch limits as ROSCO's PI does (anti-windup). ``form="output"`` blends the
    outputs of the local PIs instead (the general scheme of
    :func:`specdesign.simulate.scheduled`; kept for comparison).

    Parameters
    ----------
    model : TurbineModel, optional
        The reduced turbine model (default :func:`specdesign.turbine.iea15mw`).
    wind_speeds : array_like, optional
        Scheduling wind speeds (m/s). Default: every whole m/s where the model's above-rated
        range and the gain schedule overlap (12-25 m/s for the IEA 15 MW).
    name : str, optional
        Label of the controller in tables and figures.
    form : {"gains", "output"}, optional
        ROSCO's gain scheduling, or output blending of the local PIs.
    schedule : RoscoSchedule or DisconSchedule, optional
        The gains to schedule. Default :func:`rosco_gain_schedule` of ``model``. A
        :class:`~specdesign.rosco.DisconSchedule` (:func:`~specdesign.rosco.from_discon`) runs
        the DISCON.IN's own controller: its gains at its ``PC_GS_angles`` (``wind_speeds``
        must then be None; gains per generator-side rad/s times ``WE_GearboxRatio`` on the
        model's rotor speed), its speed filter (``F_LPFType``, ``F_LPFCornerFreq``,
        ``F_LPFDamping``) and its pitch limits within the model's (``form="gains"`` only).
    scheduling_filter : {"first_order", "rosco"}, optional
        The low-pass giving the scheduling pitch: ``"first_order"`` (default) at
        :data:`specdesign.simulate.SCHEDULE_FILTER_OMEGA` = 0.1 rad/s; ``"rosco"`` ROSCO's
        own, second order at :data:`ROSCO_SCHEDULE_CORNER` × the speed filter's corner
        (``F_LPFCornerFreq``; 1.0081 rad/s for the model's own schedule), damping
        :data:`ROSCO_SCHEDULE_DAMPING`, discretised by Tustin as ROSCO does.

    Returns
    -------
    specdesign.simulate.ScheduledController
        The scheduled controller, for :func:`specdesign.simulate.simulate`.

    Raises
    ------
    ValueError
        For an unknown ``form`` or ``scheduling_filter``, a wind speed outside the model's or
        the schedule's range, or a DisconSchedule with ``wind_speeds``, with ``form="output"``
        or whose reference speed (``PC_RefSpd`` / ``WE_GearboxRatio``) differs from the model's
        rated rotor speed by more than 0.1 %.
    TypeError
        For a ``schedule`` that is neither a RoscoSchedule nor a DisconSchedule.
    RuntimeError
        If the scheduled gains at a scheduling speed differ from :func:`rosco_baseline`
        (an internal consistency check).

    Examples
    --------
    >>> sc = rosco_scheduled()
    >>> sc.form, sc.schedule_pitch.size
    ('gains', 14)
    >>> from specdesign.rosco import from_discon, iea15mw_discon
    >>> sc = rosco_scheduled(schedule=from_discon(iea15mw_discon()), scheduling_filter="rosco")
    >>> sc.schedule_pitch.size, round(sc.filter_omega, 4), sc.filter_damping
    (30, 0.252, 0.7)
    """
    if model is None:
        model = iea15mw()
    if scheduling_filter not in SCHEDULING_FILTERS:
        raise ValueError(f"scheduling_filter must be one of {SCHEDULING_FILTERS}, got {scheduling_filter!r}")
    if isinstance(schedule, DisconSchedule):
        return _discon_scheduled(model, schedule, wind_speeds, name, form, scheduling_filter)
    if schedule is not None and not isinstance(schedule, RoscoSchedule):
        raise TypeError(f"schedule must be a RoscoSchedule or a DisconSchedule (from_discon), got {type(schedule).__name__}")
    filt = ({} if scheduling_filter == "first_order" else
            {"filter_omega": ROSCO_SCHEDULE_CORNER * 1.0081, "filter_damping": ROSCO_SCHEDULE_DAMPING})
    # The gains of rosco_baseline: pole placement on the straight-line fits of A, B_β.
    sched = rosco_gain_schedule(model) if schedule is None else schedule
    if wind_speeds is None:  # every whole m/s where both the model and the gain schedule hold
        lo, hi = getattr(model, "wind_range", (11.0, 25.0))
        lo, hi = max(lo, float(np.min(sched.v))), min(hi, float(np.max(sched.v)))
        wind_speeds = np.arange(math.ceil(lo), math.floor(hi) + 0.5, 1.0)
    vs = [float(v) for v in np.atleast_1d(np.asarray(wind_speeds, dtype=float))]
    if form == "output":
        return dataclasses.replace(scheduled(model, {v: rosco_baseline(model, v, schedule=sched) for v in vs},
                                             name=name), **filt)
    if form != "gains":
        raise ValueError(f"form must be one of {FORMS}, got {form!r}")
    v = np.array(sorted(set(vs)))
    kp, ki = sched.gains(v)
    plant = turbine_plant(model)
    beta = np.array([plant.trim(s)[1] for s in v])
    order = np.argsort(beta)
    sc = ScheduledController.gain_scheduled_pi(beta[order], kp[order], ki[order], speed_filter(), name=name,
                                               pitch_limits=(model.pitch_min, model.pitch_max), **filt)
    # Same controller as rosco_baseline at each speed (checked against its transfer function).
    jw = 1j * np.array([0.05, 0.5, 2.0])
    for k, s in enumerate(v[order]):
        ref = np.asarray(rosco_baseline(model, float(s), schedule=sched)(jw), complex)
        if not np.allclose(np.asarray(sc.pitch[k](jw), complex), ref, rtol=1e-9, atol=0):
            raise RuntimeError(f"rosco_scheduled's gains at {s:g} m/s differ from rosco_baseline")
    return sc


def _discon_scheduled(model, schedule, wind_speeds, name, form, scheduling_filter):
    """rosco_scheduled with a DisconSchedule: its own gains, speed filter and pitch limits."""
    import control

    where = f"schedule ({schedule.path})"
    if wind_speeds is not None:
        raise ValueError(f"wind_speeds must be None with a DisconSchedule: {where} schedules on its own PC_GS_angles")
    if form != "gains":
        raise ValueError(f"form must be 'gains' with a DisconSchedule ({where} holds gains, not designed controllers)")
    n = schedule.gearbox_ratio
    ref = schedule.reference_speed / n
    if abs(ref - model.rated_rotor_speed) > 1e-3 * model.rated_rotor_speed:
        raise ValueError(f"{where}: PC_RefSpd / WE_GearboxRatio = {ref:.6g} rad/s but the model's rated rotor speed is "
                         f"{model.rated_rotor_speed:.6g} rad/s: the DISCON.IN is for another turbine")
    wf = schedule.filter_corner
    speed = speed_filter(wf, schedule.filter_damping) if schedule.filter_type == 2 else control.tf([wf], [1.0, wf])
    filt = ({"filter_omega": SCHEDULE_FILTER_OMEGA} if scheduling_filter == "first_order" else
            {"filter_omega": ROSCO_SCHEDULE_CORNER * wf, "filter_damping": ROSCO_SCHEDULE_DAMPING})
    lim = (max(model.pitch_min, schedule.pitch_min), min(model.pitch_max, schedule.pitch_max))
    # ROSCO's gains act on the generator speed: N times the rotor speed the model feeds back
    return ScheduledController.gain_scheduled_pi(schedule.pitch, schedule.kp * n, schedule.ki * n, speed, name=name,
                                                 pitch_limits=lim, **filt)
