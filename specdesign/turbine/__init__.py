"""The embedded IEA 15 MW reduced-order model: trim, linearisation and the compiled kernel.

The model: rigid-drivetrain rotor (aerodynamic torque from Cp(λ, β), thrust from Ct(λ, β)),
first tower fore-aft mode driven by thrust with the rotor seeing the relative wind U − ẋ_top,
a 2nd-order pitch actuator with rate and position limits, and a generator torque that is an
input (constant, ``rated_generator_torque``, above rated; below rated set by ROSCO's torque law,
the model's ``torque_control``, :mod:`specdesign.controller.torque`, closed in :meth:`TurbineModel.trim`
and :meth:`TurbineModel.linearize` from cut-in to cut-out). Figures come from the shipped
``specdesign/data/iea15mw`` (IEA Wind Task 37 and NREL ROSCO, Apache-2.0; see NOTICE.md).

Layout
------
- :mod:`specdesign.turbine.model`: :class:`TurbineModel` (trim, linearisation, aerodynamic
  expansion) and :func:`iea15mw`; its results :class:`OperatingPoint` and
  :class:`AeroExpansion` in :mod:`specdesign.turbine.operating`.
- :mod:`specdesign.turbine.kernel`: the compiled right-hand side :func:`rhs` / :func:`outputs`
  (and its parts :func:`aero_loads`, :func:`mechanics`, :func:`outputs_from`), the state,
  input and output names and the layout of the parameter array: see its docstring, "the
  kernel interface".
- :mod:`specdesign.turbine.tables`: the shipped data and the bicubic rotor-table coefficients.
- :mod:`specdesign.turbine.openfast_deck`: :func:`from_openfast`, a model from an OpenFAST deck.
- :mod:`specdesign.turbine.plant`: the model as the compiled loops run it
  (:class:`~specdesign.turbine.plant.KernelPlant`, :func:`~specdesign.turbine.plant.turbine_plant`,
  :func:`~specdesign.turbine.plant.scheduled`; re-exported by :mod:`specdesign.simulate`).
- :mod:`specdesign.turbine.baseline`: ROSCO's pitch PI from the model (:func:`rosco_baseline`,
  :func:`rosco_gain_schedule`, :class:`RoscoSchedule`, :func:`speed_filter`), re-exported by
  :mod:`specdesign.rosco`.

Layers: this package stands on :mod:`specdesign.controller` (the torque law, the DISCON.IN
reader); :mod:`specdesign.rosco`, :mod:`specdesign.closedloop` and :mod:`specdesign.simulate`
stand on it.
"""
from __future__ import annotations

from .baseline import RoscoSchedule, rosco_baseline, rosco_gain_schedule, speed_filter
from .kernel import (
    INPUT_NAMES,
    OUTPUT_NAMES,
    P_ACT_OMEGA,
    P_ACT_ZETA,
    P_DPITCH,
    P_DTSR,
    P_GEN_EFF,
    P_INERTIA,
    P_MY_PER_M,
    P_N_PITCH,
    P_N_TSR,
    P_PITCH0,
    P_PITCH_MAX,
    P_PITCH_MIN,
    P_RADIUS,
    P_RATE_LIM,
    P_RHO,
    P_TSR0,
    P_TWR_DAMP,
    P_TWR_MASS,
    P_TWR_STIFF,
    STATE_NAMES,
    aero_loads,
    mechanics,
    outputs,
    outputs_from,
    rhs,
)
from .model import TurbineModel, iea15mw
from .openfast_deck import from_openfast
from .operating import AERO_VARIABLES, LOAD_INPUT_NAMES, AeroExpansion, OperatingPoint

__all__ = [
    "STATE_NAMES",
    "INPUT_NAMES",
    "OUTPUT_NAMES",
    "LOAD_INPUT_NAMES",
    "AERO_VARIABLES",
    "rhs",
    "outputs",
    "aero_loads",
    "mechanics",
    "outputs_from",
    "TurbineModel",
    "OperatingPoint",
    "AeroExpansion",
    "RoscoSchedule",
    "iea15mw",
    "from_openfast",
    "rosco_baseline",
    "rosco_gain_schedule",
    "speed_filter",
]
