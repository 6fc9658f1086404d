"""What validation needs from the simulator's controller handling, in one place.

The only module of :mod:`specdesign.validate` that imports private names of
:mod:`specdesign.simulate` (``_as_lti``, ``_is_lti_like``, ``_check_step``,
``_check_loop_step``); the rest of the package calls the helpers below. The imports stay
inside the functions: importing :mod:`specdesign.validate` does not compile the simulator.
"""
from __future__ import annotations

import warnings

import numpy as np


def local_response(controller, model, wind_speed, s):
    """(C_β(s), C_atd(s)) of a controller at a wind speed, blended as the simulator blends.
    An integrator evaluated at s = 0 gives inf (or nan) silently: the closed-loop formulas take
    the limit there."""
    with warnings.catch_warnings(), np.errstate(divide="ignore", invalid="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        return _local_response_unchecked(controller, model, wind_speed, s)


def _local_response_unchecked(controller, model, wind_speed, s):
    from ..simulate import ScheduledController, _as_lti, turbine_plant

    if isinstance(controller, ScheduledController):
        b0 = turbine_plant(model).trim(wind_speed)[1]
        K = controller.schedule_pitch.size
        w = np.array([np.interp(b0, controller.schedule_pitch, np.eye(K)[q]) for q in range(K)])
        cb = sum(w[q] * np.asarray(controller.pitch[q](s)) for q in range(K) if w[q] != 0)
        ca = 0.0 if controller.atd is None else sum(w[q] * np.asarray(controller.atd[q](s)) for q in range(K) if w[q] != 0)
        return np.asarray(cb, complex), np.asarray(ca, complex) * np.ones_like(s)
    c = _as_lti(controller, "controller")
    return np.asarray(c(s), complex), np.zeros_like(s)


def has_linear_form(c) -> bool:
    """True for controllers with a frequency response (LTI-like or scheduled), False for callables."""
    from ..simulate import ScheduledController, _is_lti_like

    return isinstance(c, ScheduledController) or _is_lti_like(c)


def check_step(plant, vs, dt):
    """:func:`specdesign.simulate._check_step`: a step the plant's RK4 cannot resolve raises."""
    from ..simulate import _check_step

    _check_step(plant, vs, dt)


def check_loop_step(plant, controller, v, dt):
    """:func:`specdesign.simulate._check_loop_step`: a step at which the sampled loop is unstable raises."""
    from ..simulate import _check_loop_step

    _check_loop_step(plant, controller, v, dt)


def rotor_radius(model):
    """The model's rotor radius (m); the embedded IEA 15 MW's for a model without one."""
    if model is None or not hasattr(model, "rotor_radius"):
        from .. import turbine

        return turbine.iea15mw().rotor_radius
    return model.rotor_radius
