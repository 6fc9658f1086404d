"""loopshaping and gain-schedule arguments: weights of every form are checked like numbers,
indices and ranges are errors, not silent repairs (issue "Nothing silently wrong", §4)."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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
        assert qft.bounds(T, spec).omega.size == W.size
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


@pytest.mark.parametrize("weight, exc, match", [
    ("1.2", TypeError, "weight of spec 'sensitivity' must be a number"),
    (True, TypeError, "got bool True"),
    (lambda w: "x", TypeError, "a callable returning str"),
    ([1.0, 2.0], ValueError, r"one value \(or row\) per design frequency \(3\); got shape \(2,\)"),
    (np.ones((3, 2, 2)), ValueError, "per design frequency"),
    (ct.tf([-1.2], [1.0]), ValueError, "static gain -1.2; it must be > 0"),
    (ct.ss([], [], [], [[-2.0]]), ValueError, "static gain -2"),
    ([ct.tf([1.0], [1.0]), ct.tf([0.0], [1.0])], ValueError, r"weight\[1\] of spec 'sensitivity' is the static gain 0"),
    (-np.inf, ValueError, "must be > 0"),
    (lambda w: np.where(w > 1, np.nan, 1.0), ValueError, "is NaN"),
])
def test_weight_errors_name_the_argument(weight, exc, match):
    with pytest.raises(exc, match=match):
        qft.bounds(T, qft.Spec("sensitivity", weight))


@pytest.mark.parametrize("upper, lower, match", [
    (-1.0, 1.0, "upper of spec 'tracking' must be > 0"),
    (1.0, lambda w: -np.ones_like(w), "lower of spec 'tracking' must be > 0"),
    (ct.tf([-3.0], [1.0]), 1.0, "upper of spec 'tracking' is the static gain -3"),
])
def test_tracking_limits_are_checked_like_weights(upper, lower, match):
    with pytest.raises(ValueError, match=match):
        qft.bounds(T, qft.Spec("tracking", kind_args=dict(upper=upper, lower=lower)))


def test_a_dynamic_lti_weight_is_its_magnitude():
    # a sign of a dynamic LTI is no mistake (|W(jω)| is the weight): −(s+1)/(s+10) is |(s+1)/(s+10)|
    a = qft.bounds(T, qft.Spec("sensitivity", -ct.tf([1.0, 1.0], [1.0, 10.0])))
    b = qft.bounds(T, qft.Spec("sensitivity", ct.tf([1.0, 1.0], [1.0, 10.0])))
    np.testing.assert_array_equal(a.forbidden_db, b.forbidden_db)


@pytest.mark.parametrize("nominal", [1.5, True, "1", None])
def test_nominal_must_be_an_integer_index(nominal):
    with pytest.raises(ValueError, match=r"nominal=.* must be an integer index"):
        qft.Template.from_systems([ct.tf([1.0], [1.0, 1.0]), ct.tf([2.0], [1.0, 1.0])], W, nominal=nominal)


@pytest.mark.parametrize("nominal", [2, -3])
def test_operating_point_nominal_out_of_range_is_not_wrapped(nominal):
    # nominal % len(systems) used to pick another case silently
    with pytest.raises(ValueError, match=rf"nominal={nominal} is not a case index \(n_cases=2\)"):
        qft.Template.from_operating_points([ct.tf([1.0], [1.0, 1.0]), ct.tf([2.0], [1.0, 1.0])], W,
                                           nominal=nominal, n_between=2)
    t = qft.Template.from_operating_points([ct.tf([1.0], [1.0, 1.0]), ct.tf([2.0], [1.0, 1.0])], W,
                                           nominal=-1, n_between=2)
    assert t.nominal == 3  # the last original point, after the two inserted cases


@pytest.mark.parametrize("band", ["ab", (1.0,), (2.0, 1.0), (-1.0, 1.0)])
def test_band_errors_name_band(band):
    with pytest.raises(ValueError, match="band="):
        qft.Spec("sensitivity", 1.2, band=band)


@settings(max_examples=60, deadline=None)
@given(values=st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=3, max_size=3),
       form=st.sampled_from(["array", "callable"]))
def test_a_weight_with_any_non_positive_value_is_refused(values, form):
    arr = np.array(values)
    weight = arr if form == "array" else (lambda w, a=arr: a.copy())
    spec = qft.Spec("sensitivity", weight)
    if np.all(arr > 0):
        np.testing.assert_allclose(spec.weights(W, T.n_cases, design=W)[:, 0], arr)
    else:
        with pytest.raises(ValueError, match="weight of spec 'sensitivity' must be > 0"):
            qft.bounds(T, spec)
