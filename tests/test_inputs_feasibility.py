"""Feasibility doors (issue "Nothing silently wrong, part two"): tolerances that cannot end a
bisection, bools or strings where a number is meant, and ω = 0 in a pitch-feasibility grid are
refused at the door, before any design (each case here returned never or silently wrong)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specdesign import spec
from specdesign._checks import MAX_BISECTIONS, bisection_tolerance, del_target, real_scalar
from specdesign.feasibility import CertificateSearch, element_specification, pitch_feasibility, specification_for_target
from specdesign.turbine import iea15mw


class _NoPlant:
    """A model whose every use fails loudly: a door check must answer before the model is touched."""

    wind_range = (3.0, 25.0)

    def __getattr__(self, name):
        raise AssertionError(f"the model was used ({name}) before the arguments were checked")


@pytest.mark.parametrize("tol", [0, 0.0, -1, -1e-9, float("nan"), float("inf")])
def test_specification_for_target_refuses_a_tolerance_that_never_ends(tol):
    with pytest.raises(ValueError, match="tolerance_db"):
        specification_for_target(_NoPlant(), 19.0, 25.0, tolerance_db=tol)


@pytest.mark.parametrize("tol", [0, -1])
def test_element_specification_refuses_a_tolerance_that_never_ends(tol):
    with pytest.raises(ValueError, match="tolerance_db"):
        element_specification(_NoPlant(), 19.0, 25.0, tolerance_db=tol)


@pytest.mark.parametrize("bad, kind", [(True, TypeError), (False, TypeError), ("25", TypeError), (b"25", TypeError),
                                       (np.bool_(True), TypeError), ([25.0], TypeError), (float("nan"), ValueError),
                                       (0, ValueError), (100, ValueError), (-5, ValueError)])
def test_a_target_is_a_number_in_0_100(bad, kind):
    # True used to be read as a 1 % target
    with pytest.raises(kind, match="target_reduction"):
        specification_for_target(_NoPlant(), 19, bad)
    with pytest.raises(kind, match="target_reduction"):
        element_specification(_NoPlant(), 19, bad)


@pytest.mark.parametrize("key", ["slack_db", "speed_slack_db", "max_relax_db", "speed_relax_db"])
@pytest.mark.parametrize("bad, kind", [(True, TypeError), ("1", TypeError), (-1.0, ValueError),
                                       (float("nan"), ValueError)])
def test_search_options_are_checked_at_the_door(key, bad, kind):
    with pytest.raises(kind, match=key):
        specification_for_target(_NoPlant(), 19.0, 25.0, **{key: bad})
    with pytest.raises(kind, match=key):
        element_specification(_NoPlant(), 19.0, 25.0, **{key: bad})


def test_element_specification_max_notches_is_not_a_bool():
    with pytest.raises(ValueError, match="max_notches"):
        element_specification(_NoPlant(), 19.0, 25.0, max_notches=True)


@settings(max_examples=60, deadline=None)
@given(st.one_of(st.floats(max_value=0.0), st.floats(allow_nan=True).filter(lambda x: not np.isfinite(x))))
def test_bisection_tolerance_refuses_every_non_positive_or_non_finite(x):
    with pytest.raises(ValueError, match="tol"):
        bisection_tolerance(x, "tol")


@settings(max_examples=60, deadline=None)
@given(st.floats(min_value=1e-300, max_value=1e300))
def test_bisection_tolerance_keeps_every_positive_float(x):
    assert bisection_tolerance(x, "tol") == x


@given(st.one_of(st.booleans(), st.text(), st.binary(), st.none(), st.lists(st.floats(), min_size=1)))
def test_real_scalar_refuses_what_is_not_a_number(x):
    with pytest.raises(TypeError, match="arg"):
        real_scalar(x, "arg")


def test_del_target_keeps_numbers():
    assert del_target(np.float32(25.0)) == 25.0 and del_target(1) == 1.0


@pytest.fixture(scope="module")
def search():
    return CertificateSearch(iea15mw(), 19.0)


def test_a_tolerance_below_float_resolution_still_ends(search):
    # 1e-300 dB next to a rung of a few dB is never reached by halving (float64 spacing ~1e-16):
    # the bisection stops after MAX_BISECTIONS halvings and returns the same kind of record
    coarse = search.for_target(25.0)
    fine = search.for_target(25.0, tolerance_db=1e-300)
    assert fine.promise.exact_del >= 25.0
    # the fine relaxation lies within the coarse bisection's final bracket (0.05 dB wide)
    assert coarse.speed_relax_db - 0.05 - 1e-9 <= fine.speed_relax_db <= coarse.speed_relax_db + 1e-9
    assert MAX_BISECTIONS >= 60  # enough halvings to go below 1e-15 dB from a 12 dB bracket


@pytest.fixture(scope="module")
def rosco_pair():
    model = iea15mw()
    return model, spec.design_specifications(model, 19.0, speed_relax_db=0.0, tower_relax_db=0.0)


@pytest.mark.parametrize("omega", [np.r_[0.0, np.logspace(-2, 1, 200)], np.r_[-0.1, np.logspace(-2, 1, 200)]])
def test_pitch_feasibility_refuses_omega_zero_or_negative(rosco_pair, omega):
    model, specs = rosco_pair
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no division warning on the way to the error
        with pytest.raises(ValueError, match=r"omega must be positive"):
            pitch_feasibility(model, 19.0, specs.base.system, specs.speed, omega=omega)


def test_pitch_feasibility_without_zero_is_feasible(rosco_pair):
    # the same grid without ω = 0: ROSCO meets its own specification (the docstring's example)
    model, specs = rosco_pair
    r = pitch_feasibility(model, 19.0, specs.base.system, specs.speed, omega=np.logspace(-2, 1, 200))
    assert r.feasible


@pytest.mark.parametrize("bad, kind", [(True, TypeError), ("19", TypeError), (float("nan"), ValueError)])
def test_pitch_feasibility_wind_speed_and_cases_are_numbers(rosco_pair, bad, kind):
    model, specs = rosco_pair
    with pytest.raises(kind, match="wind_speed"):
        pitch_feasibility(model, bad, specs.base.system, specs.speed)
    with pytest.raises(kind, match=r"cases\[1\]"):
        pitch_feasibility(model, 19.0, specs.base.system, specs.speed, cases=[19.0, bad])
