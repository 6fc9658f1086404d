"""H∞ doors (issue "Nothing silently wrong, part two"): a specification made at another wind
speed is refused by design_hinf exactly as by design_qft (one shared check), an ill-posed
synthesis names the wind speed, and a NaN plant is a ValueError before SLICOT."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest

from loopshaping import hinf as lhinf
from loopshaping.wellposed import check_well_posed
from specdesign import spec
from specdesign._checks import finite_system, spec_made_at
from specdesign.feasibility import specification_for_target
from specdesign.hinf import design as hdesign
from specdesign.hinf import design_hinf, spec_from_certified, spec_from_pair
from specdesign import qft
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def at19(model):
    return specification_for_target(model, 19.0, 25.0)


def test_a_target_specification_carries_its_speed_and_cases(at19):
    assert at19.wind_speed == 19.0
    # DEFAULT_CASE_OFFSETS (-1, -0.5, 0.5, 1) around 19 m/s, nominal included
    assert set(at19.case_speeds) == {18.0, 18.5, 19.0, 19.5, 20.0}


@pytest.mark.parametrize("design", ["hinf", "qft"])
def test_a_specification_made_at_19_is_refused_at_21(model, at19, design):
    # design_hinf used to accept it, report the 19 m/s promise and "met" on the 18-20 m/s cases
    with pytest.raises(ValueError, match=r"made at 19 m/s and certified on the plant cases .* not at wind_speed=21 m/s"):
        if design == "hinf":
            design_hinf(model, 21.0, spec=spec_from_certified(at19))
        else:
            qft.design_qft(model, 21.0, spec=qft.spec_from_certified(at19))


def test_design_hinf_refuses_design_specifications_made_elsewhere(model):
    # a DesignSpecifications record carries its speed in base.wind_speed; the pair made from it says so
    d = spec.design_specifications(model, 19.0)
    assert d.base.wind_speed == 19.0
    with pytest.raises(ValueError, match="made at 19 m/s"):
        design_hinf(model, 23.0, spec=spec_from_pair(d.tower, d.speed, wind_speed=d.base.wind_speed))


def test_a_bare_pair_carries_no_speed_and_passes_the_check(at19):
    spec_made_at((at19.tower, at19.speed), 21.0)  # nothing to compare: the user's pair
    spec_made_at(at19, 19.0)


@pytest.mark.parametrize("v", [5.0, 10.0, 25.5, float("nan"), -1.0])
def test_design_hinf_outside_the_model_range_names_the_wind_speed(model, v):
    with pytest.raises(ValueError, match="wind_speed"):
        design_hinf(model, v)


@pytest.mark.parametrize("v", [True, "19"])
def test_design_hinf_wind_speed_is_a_number(model, v):
    with pytest.raises(TypeError, match="wind_speed"):
        design_hinf(model, v)


def test_an_ill_posed_synthesis_names_the_wind_speed(model, monkeypatch, at19):
    # loopshaping's refusal (its own message kept) is prefixed by the operating point
    def ill_posed(*a, **k):
        raise ValueError("ill-posed H∞ problem: D12 (2×1) is not of full column rank")

    monkeypatch.setattr(hdesign.lhinf, "synthesize", ill_posed)
    with pytest.raises(ValueError, match=r"H∞ design at 19 m/s: ill-posed H∞ problem: D12"):
        design_hinf(model, 19.0, spec=spec_from_pair(at19.tower, at19.speed), measurements=("gen_speed",))


class _NaNPlant:
    """iea15mw with one NaN in the linearised A matrix."""

    def __init__(self, model):
        self._m = model

    def __getattr__(self, name):
        return getattr(self._m, name)

    def linearize(self, v, **k):
        p = self._m.linearize(v, **k)
        A = np.array(p.A)
        A[0, 0] = np.nan
        return ct.ss(A, p.B, p.C, p.D, inputs=p.input_labels, outputs=p.output_labels, states=p.state_labels)


def test_a_nan_plant_is_a_value_error_before_slicot(model, monkeypatch):
    def never(*a, **k):
        raise AssertionError("synthesis reached with a NaN plant")

    monkeypatch.setattr(lhinf, "synthesize", never)
    with pytest.raises(ValueError, match=r"plant linearised at 19 m/s has a NaN or inf entry \(A\[0, 0\]"):
        design_hinf(_NaNPlant(model), 19.0)


def test_check_well_posed_refuses_nan_generalized_plant():
    # a 1-state plant with a NaN in B1; without the check LAPACK's svd raises LinAlgError
    P = ct.ss([[-1.0]], [[np.nan, 1.0]], [[1.0], [1.0]], [[0.0, 1.0], [1.0, 0.0]])
    with pytest.raises(ValueError, match="ill-posed H∞ problem: the generalized plant's B1 has NaN"):
        check_well_posed(P, 1, 1)
    with pytest.raises(ValueError, match="B1 has NaN"):
        lhinf.synthesize(P, 1, 1)


def test_finite_system_names_the_transfer_function_coefficient():
    with pytest.raises(ValueError, match=r"K has a NaN or inf entry \(den"):
        finite_system(ct.tf([1.0], [1.0, np.inf]), "K")
    finite_system(ct.tf([1.0], [1.0, 1.0]), "K")  # finite: passes
