"""Closed-loop maps wind → output for a pitch controller and an optional tower-damping loop.

Sign convention (the documentation's method page): the pitch command is

    β_cmd = −C_β·Ω_g − C_atd·z,

C_β the pitch controller on generator speed Ω_g (ROSCO's PI with its speed filter, see
:func:`specdesign.rosco.rosco_baseline`) and C_atd the active tower damping (ATD)
controller on the tower-motion measurement z (``tower_top_vel`` by default). Both are
negative feedback; L = C_β·P_{Ω,β} is the loop QFT shapes. The generator-torque input is held
constant (zero deviation), as above rated.

Closing the loops by hand gives, with Δ = 1 + C_β P_{Ω,β} + C_atd P_{z,β},

    T_{y,w} = [P_{y,w} + C_β(P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w}) + C_atd(P_{y,w}P_{z,β} − P_{y,β}P_{z,w})] / Δ

(Eq. 4 of the paper is y = Ω_g without ATD, Eq. 5 y = MyT). :func:`closed_loop` builds the
same system with ``control.interconnect``; the tests check the two agree.

Every closed-loop construction of the workbench lives here, one module a concern:

- :mod:`~specdesign.closedloop.maps`: T_{y,w}(jω) by formula, plant responses of several
  cases, sequential closure and QFT's general form (A + B·G)/(C + D·G);
- :mod:`~specdesign.closedloop.interconnect`: the same loops as named state-space systems
  (SISO pitch + ATD, a MIMO controller, one loop closed);
- :mod:`~specdesign.closedloop.stability`: the loop as the simulator runs it (scheduled
  controllers blended at the trim), its poles, hidden modes and instability messages;
- :mod:`~specdesign.closedloop.modes`: the tower mode's pole and damping ratio in a loop, and the
  designs' warning when it falls well below ROSCO's;
- :mod:`~specdesign.closedloop.grid`: frequency grids refined around lightly damped roots.
"""
from __future__ import annotations

from .grid import FREQUENCY_RTOL, case_speeds, lightly_damped, merge_frequencies, refine_grid, system_roots
from .interconnect import (
                           PLANT_INPUTS,
                           check_stability,
                           closed_loop,
                           closed_loop_mimo,
                           named_siso,
                           partial_loop,
                           require_signals,
)
from .maps import (
                           LOOP_OUTPUTS,
                           LoopMaps,
                           close_responses,
                           closed_loop_del,
                           closed_map,
                           frequency_response,
                           general_coefficients,
                           general_form,
                           loop_maps,
                           output_psd,
                           plant_responses,
                           siso_response,
                           t_gen_speed_wind,
                           t_output_wind,
                           t_tower_wind,
)
from .modes import (
                           MIN_TOWER_DAMPING_FRACTION,
                           TOWER_MODE_SPAN,
                           TowerDampingWarning,
                           tower_damping,
                           tower_damping_message,
                           tower_pole,
)
from .stability import (
                           CERTIFICATE_MAX_SENSITIVITY,
                           DESIGN_MAX_SENSITIVITY,
                           MAX_SENSITIVITY,
                           MIN_DECAY_RATE,
                           ORIGIN_TOL,
                           UNSTABLE_CONTROLLER_RATE,
                           ClosedLoopUnstableWarning,
                           closed_loop_matrices,
                           fine_pitch_lift,
                           hidden_origin_poles,
                           local_response,
                           loop_parts,
                           trim_weights,
                           turbine_loop_poles,
                           unstable_message,
                           unstable_poles,
)

__all__ = [
    "MIN_TOWER_DAMPING_FRACTION",
    "TOWER_MODE_SPAN",
    "TowerDampingWarning",
    "tower_damping",
    "tower_damping_message",
    "tower_pole",
    "ClosedLoopUnstableWarning",
    "fine_pitch_lift",
    "closed_loop",
    "closed_loop_mimo",
    "partial_loop",
    "check_stability",
    "named_siso",
    "require_signals",
    "frequency_response",
    "siso_response",
    "t_output_wind",
    "t_gen_speed_wind",
    "t_tower_wind",
    "output_psd",
    "closed_loop_del",
    "closed_map",
    "LoopMaps",
    "loop_maps",
    "plant_responses",
    "close_responses",
    "general_coefficients",
    "general_form",
    "loop_parts",
    "local_response",
    "trim_weights",
    "closed_loop_matrices",
    "turbine_loop_poles",
    "hidden_origin_poles",
    "unstable_poles",
    "unstable_message",
    "system_roots",
    "lightly_damped",
    "refine_grid",
    "merge_frequencies",
    "FREQUENCY_RTOL",
    "case_speeds",
    "ORIGIN_TOL",
    "UNSTABLE_CONTROLLER_RATE",
    "MAX_SENSITIVITY",
    "DESIGN_MAX_SENSITIVITY",
    "CERTIFICATE_MAX_SENSITIVITY",
    "MIN_DECAY_RATE",
    "PLANT_INPUTS",
    "LOOP_OUTPUTS",
]
