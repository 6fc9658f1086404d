"""Older doors revisited (issue "Nothing silently wrong, part two"): one meaning of an integer
``seeds`` in run_campaign and in a campaign file; a zero transfer function as a controller is a
clear ValueError (it was an IndexError); a diverging simulation names the controller by the
user's name, never python-control's automatic "sys[4]"."""
from __future__ import annotations

import json
import warnings

import control as ct
import numpy as np
import pytest

from loopshaping.controller import Controller
from specdesign.cli import read_config
from specdesign.simulate import SimulationDivergedError, simulate
from specdesign.turbine import iea15mw
from specdesign.validate import run_campaign, seeds_from


@pytest.fixture(scope="module")
def model():
    return iea15mw()


def test_an_integer_seeds_means_the_same_in_a_file_and_in_python(model, tmp_path):
    (tmp_path / "c.json").write_text(json.dumps({"wind_speeds": [19.0], "seeds": 3, "duration": 10.0,
                                                 "transient": 0.0, "controllers": {"ROSCO": {"kind": "rosco"}}}))
    from_file = read_config(tmp_path / "c.json")["seeds"]
    camp = run_campaign({"PI": ct.tf([-0.3, -0.06], [1.0, 0.0])}, [19.0], 3, model=model, duration=10.0,
                        transient=0.0, predict=False, progress=False)
    assert from_file.tolist() == seeds_from(3).tolist() == camp.seeds.tolist() == [0, 1, 2]
    # documented alike: run_campaign's docstring points to seeds_from, the campaign file's schema says the same
    assert "0, 1, …, n − 1" in seeds_from.__doc__ and "seeds_from" in run_campaign.__doc__
    from pathlib import Path

    schema = (Path(__file__).resolve().parents[1] / "docs" / "validation.md").read_text()
    assert "an int n → the seeds 0..n−1 (as run_campaign(seeds=n))" in schema


@pytest.mark.parametrize("zero", [ct.tf([0.0], [1.0]), ct.tf([0.0, 0.0], [1.0, 2.0]), ct.ss([], [], [], [[0.0]])])
def test_a_zero_transfer_function_is_a_clear_value_error(zero):
    with pytest.raises(ValueError, match="sys is zero: a zero transfer function has no factors"):
        Controller.from_tf(zero)


def test_a_non_finite_transfer_function_is_refused():
    with pytest.raises(ValueError, match="non-finite coefficient"):
        Controller.from_tf(ct.tf([np.nan, 1.0], [1.0, 1.0]))


def test_from_tf_still_factors_a_pi():
    c = Controller.from_tf(ct.tf([-0.3, -0.06], [1.0, 0.0]))
    # -0.3 (s + 0.2)/s: DC gain of s·C(s) is -0.06, the high-frequency gain -0.3
    num, den = c.polys()
    assert num[-1] / den[-2] == pytest.approx(-0.06) and num[0] / den[0] == pytest.approx(-0.3)


@pytest.mark.parametrize("linear", [True])  # the nonlinear model saturates its pitch instead of diverging
def test_a_diverging_simulation_is_not_named_sys_n(model, linear):
    wrong_sign = ct.tf([3.0, 0.6], [1.0, 0.0])  # ROSCO's PI with the sign flipped, ×10: unstable
    assert wrong_sign.name.startswith("sys[")  # python-control's automatic name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the up-front stability warning
        with pytest.raises(SimulationDivergedError) as e:
            simulate(model, wrong_sign, [19.0], seeds=[1], duration=60.0, transient=0.0, linear=linear)
    assert "sys[" not in str(e.value) and "controller 'controller'" in str(e.value)
    named = ct.tf([3.0, 0.6], [1.0, 0.0], name="flipped PI")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(SimulationDivergedError, match="controller 'flipped PI'"):
            simulate(model, named, [19.0], seeds=[1], duration=60.0, transient=0.0, linear=linear)
