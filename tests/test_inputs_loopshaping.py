"""loopshaping and gain-schedule arguments: weights of every form are checked like numbers,
indices and ranges are errors, not silent repairs (issue "Nothing silently wrong", §4)."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest

from loopshaping import qft
from specdesign import turbine

W = np.array([0.1, 1.0, 10.0])
T = qft.Template.from_systems([ct.tf([1.0], [1.0, 1.0]), ct.tf([2.0], [1.0, 1.0])], W)


@pytest.mark.parametrize("weight, match", [
    (-1.2, "must be > 0"),
    (0.0, "must be > 0"),
    (lambda w: -1.2 * np.ones_like(w), "must be > 0"),           # a callable returning a negative magnitude
    (lambda w: np.zeros_like(w), "must be > 0"),
    (ct.tf([1.0, 0.0], [1.0, 1.0]), None),                       # an LTI is fine where it is not 0 …
    (np.array([1.2, -1.0, 1.3]), "must be > 0"),
])
def test_weights_of_every_form_are_checked(weight, match):
    spec = qft.Spec("sensitivity", weight)
    if match is None:
        assert qft.bounds(T, spec).omegas.size == W.size
    else:
        with pytest.raises(ValueError, match=match):
            qft.bounds(T, spec)


def test_an_lti_weight_that_vanishes_on_the_axis_is_an_error():
    # |W(jω)| = 0 at ω = 1 rad/s (a zero pair on the jω axis): no controller meets |S| ≤ 0
    notch = ct.tf([1.0, 0.0, 1.0], [1.0, 1.0, 1.0])
    with pytest.raises(ValueError, match=r"is 0 at ω = 1 rad/s"):
        qft.bounds(T, qft.Spec("sensitivity", notch))


@pytest.mark.parametrize("nominal", [2, -3, 10])
def test_nominal_index_out_of_range(nominal):
    with pytest.raises(ValueError, match="nominal="):
        qft.Template.from_systems([ct.tf([1.0], [1.0, 1.0]), ct.tf([2.0], [1.0, 1.0])], W, nominal=nominal)


def test_gain_schedule_is_not_extrapolated():
    sched = turbine.rosco_gain_schedule(turbine.iea15mw())
    lo, hi = sched.v.min(), sched.v.max()
    kp, ki = sched.gains([lo, 19.0, hi])  # inside (ends included): fine
    assert np.all(np.isfinite(kp)) and np.all(np.isfinite(ki))
    for v in (lo - 0.5, hi + 0.5, np.nan):
        with pytest.raises(ValueError, match="gain schedule covers"):
            sched.gains(v)
