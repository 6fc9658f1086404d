"""Model predictive and learned pitch controllers (seed 000): a quadratic MPC, the
fatigue-oriented economic MPC of the variance-damage surrogate, and behavioural cloning of the
long-horizon economic optimiser. All are callable controllers of
:func:`specdesign.simulate.simulate` and :func:`specdesign.validate.run_campaign`.

Layout
------
- :mod:`specdesign.mpc.base`: the discretised linear model, the Kalman filter, the sampled loop.
- :mod:`specdesign.mpc.quadratic`: :class:`QuadraticMPC`.
"""
from __future__ import annotations

from .base import MEASURED, DiscreteTurbine, SampledController, discretize_turbine, kalman_gain, prediction_matrices
from .quadratic import QuadraticMPC, quadratic_qp

__all__ = [
    "QuadraticMPC",
    "quadratic_qp",
    "DiscreteTurbine",
    "SampledController",
    "discretize_turbine",
    "kalman_gain",
    "prediction_matrices",
    "MEASURED",
]
