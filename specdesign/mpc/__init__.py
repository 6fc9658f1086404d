"""Model predictive and learned pitch controllers (after Collet et al., fatigue-oriented economic MPC and behavioural cloning): a quadratic MPC, the
fatigue-oriented economic MPC of the variance-damage surrogate (Eq. 4), and behavioural
cloning of the long-horizon economic optimiser. The controllers are callables of
:func:`specdesign.simulate.simulate` and :func:`specdesign.validate.run_campaign` (picklable,
so campaigns on executors take them). See docs/mpc.md.

Layout
------
- :mod:`specdesign.mpc.base`: the linearised turbine discretised by zero-order hold, the
  Kalman filter (states and wind estimate), the sampled loop (:class:`SampledController`).
- :mod:`specdesign.mpc.quadratic`: :class:`QuadraticMPC`.
- :mod:`specdesign.mpc.economic`: :func:`fit_fatigue_terms`, :func:`fatigue_terms_from_records`, :func:`surrogate_cost`,
  :func:`economic_open_loop`, :class:`EconomicMPC`.
- :mod:`specdesign.mpc.cloning`: :func:`demonstrations`, :class:`CloningRegressor`,
  :class:`ClonedController`, :class:`OpenLoopPlayback`.
- :mod:`specdesign.mpc.collet`: Collet et al.'s methods as the paper defines them (collective):
  :class:`ColletMPC`, :func:`tune_rho` (Eq. 13), :class:`PreviewClone` of the preview optimum.
- :mod:`specdesign.mpc.sampled`: the sampled loop and its online operating point.
- :mod:`specdesign.mpc.lpv`: the wind-scheduled LPV prediction model and observer (after Boutrous, Nejjari and Puig, health-aware LPV MPC).
- :mod:`specdesign.mpc.health`: :class:`HealthMPC`, the health-aware MPC trading speed tracking
  against blade damage growth (docs/health_mpc.md); :mod:`specdesign.mpc.health_report`: its
  energy / damage trade-off.
"""
from __future__ import annotations

from .base import (
                   MEASURED,
                   OPERATING_POINTS,
                   DiscreteTurbine,
                   discretize_turbine,
                   kalman_gain,
                   pitch_wind_estimate,
                   prediction_matrices,
)
from .cloning import (
                   ClonedController,
                   CloningRegressor,
                   Demonstrations,
                   OpenLoopPlayback,
                   clone,
                   demonstrations,
)
from .collet import (
                   COLLET_OUTPUTS,
                   ColletMPC,
                   PreviewClone,
                   RhoTuning,
                   collet_qp,
                   fatigue_cost,
                   preview_demonstrations,
                   preview_features,
                   tune_rho,
)
from .economic import (
                   WOHLER,
                   EconomicMPC,
                   FatigueTerm,
                   OpenLoopResult,
                   economic_open_loop,
                   economic_problem,
                   fatigue_terms_from_records,
                   fit_fatigue_terms,
                   solve_cone,
                   surrogate_cost,
)
from .health import (
                   HEALTH_OSQP,
                   REF_MARGIN,
                   HealthMPC,
                   health_aware_mpc,
                   health_move,
                   health_qp,
                   health_scale,
)
from .health_report import TradeoffPoint, health_tradeoff, plot_tradeoff
from .lpv import PREDICTED, LPVObserver, LPVTurbine, lpv_observer, lpv_turbine
from .quadratic import QuadraticMPC, loop_gain, quadratic_qp, unconstrained_law
from .sampled import SampledController

__all__ = [
    "COLLET_OUTPUTS",
    "ColletMPC",
    "PreviewClone",
    "RhoTuning",
    "collet_qp",
    "fatigue_cost",
    "preview_demonstrations",
    "preview_features",
    "tune_rho",
    "QuadraticMPC",
    "quadratic_qp",
    "unconstrained_law",
    "loop_gain",
    "EconomicMPC",
    "FatigueTerm",
    "fit_fatigue_terms",
    "fatigue_terms_from_records",
    "surrogate_cost",
    "solve_cone",
    "economic_problem",
    "economic_open_loop",
    "OpenLoopResult",
    "Demonstrations",
    "demonstrations",
    "CloningRegressor",
    "clone",
    "ClonedController",
    "OpenLoopPlayback",
    "DiscreteTurbine",
    "discretize_turbine",
    "kalman_gain",
    "prediction_matrices",
    "MEASURED",
    "WOHLER",
    "HealthMPC",
    "health_aware_mpc",
    "SampledController",
    "OPERATING_POINTS",
    "pitch_wind_estimate",
    "health_qp",
    "health_move",
    "health_scale",
    "HEALTH_OSQP",
    "REF_MARGIN",
    "TradeoffPoint",
    "health_tradeoff",
    "plot_tradeoff",
    "LPVTurbine",
    "lpv_turbine",
    "LPVObserver",
    "lpv_observer",
    "PREDICTED",
]
