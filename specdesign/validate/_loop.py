"""Small helpers the validation modules share about controllers and models.

The simulator is imported inside the functions: importing :mod:`specdesign.validate` does not
load numba.
"""
from __future__ import annotations

from .. import turbine
from ..simulate import ScheduledController, is_lti_like


def has_linear_form(c) -> bool:
    """True for controllers with a frequency response (LTI-like or scheduled), False for callables."""
    return isinstance(c, ScheduledController) or is_lti_like(c)


def rotor_radius(model):
    """The model's rotor radius (m); the embedded IEA 15 MW's for a model without one."""
    if model is None or not hasattr(model, "rotor_radius"):
        return turbine.iea15mw().rotor_radius
    return model.rotor_radius
