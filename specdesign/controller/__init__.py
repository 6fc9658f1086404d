"""How a controller is represented, below both the linear loop and the simulator.

:mod:`specdesign.closedloop` (the linearised loop) and :mod:`specdesign.simulate` (the compiled
loop) both run the controllers defined here, the turbine model closes the torque law in its
trim and linearisation, and :mod:`specdesign.rosco` builds ROSCO's controllers from them. This
package stands on nothing of specdesign but its argument checks.

Layout
------
- :mod:`specdesign.controller.lti`: LTI controllers as the loops take them (:func:`as_lti`,
  :func:`is_lti_like`), their Tustin matrices (:func:`tustin_matrices`) and the integrator and
  slow-mode splits (:func:`split_integrator`, :func:`split_slow`).
- :mod:`specdesign.controller.scheduled`: :class:`ScheduledController` (output-blended locals
  or ROSCO's gain-scheduled PI) and its discrete bank for the compiled loop.
- :mod:`specdesign.controller.torque`: ROSCO's generator-torque controller below rated
  (:class:`TorqueLaw`, its steady state, its linearisation and its compiled step).
- :mod:`specdesign.controller.peak_shaving`: ROSCO's peak shaving (:class:`PeakShaving`), its
  minimum pitch at ROSCO's extended-Kalman-filter wind estimate (ported) and its compiled step.
- :mod:`specdesign.controller.noise`: what a controller measures, :class:`SensorNoise` (white
  sensor noise and the 3P ripple the simulator adds between the plant and every controller).
- :mod:`specdesign.controller.discon_file`: ROSCO's parameter file DISCON.IN read and written
  (:func:`read_discon`, :func:`from_discon`, :func:`write_discon`).

Users reach these names where they use them: :mod:`specdesign.simulate` re-exports the
scheduled and LTI ones, :mod:`specdesign.rosco` the torque law and the DISCON.IN ones (the same
objects).
"""
from __future__ import annotations

from .discon_file import (
    DisconEntry,
    DisconSchedule,
    from_discon,
    read_discon,
    write_discon,
)
from .lti import (
    SLOW_OMEGA,
    as_lti,
    is_lti_like,
    split_integrator,
    split_slow,
    tustin_matrices,
)
from .noise import IEA15MW_SENSORS, SensorNoise
from .peak_shaving import PeakShaving, peak_shaving_from_discon
from .scheduled import FORMS, SCHEDULE_FILTER_OMEGA, ScheduledController
from .torque import (
    TORQUE_MODES,
    TORQUE_REGIONS,
    TorqueLaw,
    close_torque_loop,
    steady_state,
    torque_law,
    torque_law_from_discon,
    torque_step,
)

__all__ = [
    "SensorNoise",
    "IEA15MW_SENSORS",
    "DisconEntry",
    "DisconSchedule",
    "read_discon",
    "from_discon",
    "write_discon",
    "SLOW_OMEGA",
    "as_lti",
    "is_lti_like",
    "split_integrator",
    "split_slow",
    "tustin_matrices",
    "FORMS",
    "SCHEDULE_FILTER_OMEGA",
    "ScheduledController",
    "PeakShaving",
    "peak_shaving_from_discon",
    "TORQUE_MODES",
    "TORQUE_REGIONS",
    "TorqueLaw",
    "close_torque_loop",
    "steady_state",
    "torque_law",
    "torque_law_from_discon",
    "torque_step",
]
