"""ROSCO in one place: its pitch PI gain schedule, the baseline controller, its scheduled form,
schedules read from DISCON.IN files, its torque law and the compiled ROSCO controller itself.

- :mod:`specdesign.rosco.scheduled`: :func:`rosco_scheduled`, the baseline with ROSCO's gain
  scheduling as the simulator runs it, and :func:`iea15mw_discon`, the shipped DISCON.IN.
- :mod:`specdesign.rosco.discon`: ROSCO's compiled DISCON library (from the ``rosco``
  package, optional extra ``specdesign[rosco]``) as a controller of
  :func:`specdesign.simulate.simulate` (:class:`Discon`).

Re-exported here, the same objects, from the layers ROSCO stands on:

- :mod:`specdesign.turbine.baseline`: the NREL ROSCO controller of the IEA 15 MW as the
  workbench reproduces it from the reduced model (:func:`rosco_gain_schedule`,
  :func:`speed_filter`, :func:`rosco_baseline`); the turbine's public contract
  (``specdesign.turbine.rosco_baseline``), so it lives with the model.
- :mod:`specdesign.controller.discon_file`: a DISCON.IN file read as the schedule
  :func:`rosco_scheduled` runs (:func:`from_discon`, :class:`DisconSchedule`).
- :mod:`specdesign.controller.torque`: ROSCO's generator-torque controller below rated
  (:class:`TorqueLaw`, :func:`torque_law`, :func:`torque_law_from_discon`, its steady state
  :func:`steady_state` and linearisation :func:`close_torque_loop`, the compiled
  :func:`torque_step` the simulator runs), which the turbine model closes in its trim.
- :mod:`specdesign.controller.peak_shaving`: ROSCO's peak shaving (:class:`PeakShaving`,
  :func:`peak_shaving_from_discon`), which :func:`rosco_scheduled` runs with a DISCON.IN's schedule.

Layers: :mod:`specdesign.controller` < :mod:`specdesign.turbine` < this package; it never
imports :mod:`specdesign.simulate` or :mod:`specdesign.closedloop`.
"""
from __future__ import annotations

from ..controller.discon_file import DisconEntry, DisconSchedule, from_discon, read_discon, write_discon
from ..controller.peak_shaving import PeakShaving, peak_shaving_from_discon
from ..controller.torque import (
    TORQUE_MODES,
    TORQUE_REGIONS,
    TorqueLaw,
    close_torque_loop,
    steady_state,
    torque_law,
    torque_law_from_discon,
    torque_step,
)
from ..turbine.baseline import RoscoSchedule, first_order_rotor_model, rosco_baseline, rosco_gain_schedule, speed_filter
from .discon import Discon, DisconError, rosco_library, rosco_test_cases
from .scheduled import TowerDamper, iea15mw_discon, rosco_scheduled, tower_mode_damping, tune_tower_damper

__all__ = [
    "RoscoSchedule",
    "first_order_rotor_model",
    "rosco_gain_schedule",
    "speed_filter",
    "rosco_baseline",
    "rosco_scheduled",
    "TowerDamper",
    "tune_tower_damper",
    "tower_mode_damping",
    "DisconEntry",
    "DisconSchedule",
    "iea15mw_discon",
    "read_discon",
    "from_discon",
    "write_discon",
    "Discon",
    "DisconError",
    "rosco_library",
    "rosco_test_cases",
    "TORQUE_MODES",
    "TORQUE_REGIONS",
    "TorqueLaw",
    "torque_law",
    "torque_law_from_discon",
    "steady_state",
    "close_torque_loop",
    "torque_step",
    "PeakShaving",
    "peak_shaving_from_discon",
]
