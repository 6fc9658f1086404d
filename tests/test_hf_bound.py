"""Issue 28 item 1 (the convex part): a bound on the certificate's high-frequency gain.

YoulaProblem(max_hf_gain_ratio=κ) bounds |Y| = |C·S| by κ·|C_ROSCO| from HF_OMEGA (2 rad/s) to
10 rad/s and makes C strictly proper. Checked here independently of the Youla coordinates:
Y recovered from the controller's own response, Y = C/(1 + C·P_{Ω,β}).
"""
from __future__ import annotations

import control as ct
import numpy as np
import pytest

from specdesign import closedloop, spec
from specdesign.feasibility import YoulaProblem
from specdesign.feasibility.achievable import HF_OMEGA
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


def test_the_high_frequency_gain_bound_holds_and_the_controller_rolls_off(model):
    kappa = 50.0
    free = YoulaProblem(model, 19.0, max_sensitivity=1.8).solve(3.0)
    bounded = YoulaProblem(model, 19.0, max_sensitivity=1.8, max_hf_gain_ratio=kappa).solve(3.0)
    w = np.geomspace(HF_OMEGA, 10.0, 300)  # another grid than the problem's
    c = closedloop.siso_response(bounded.controller(model), w)
    p = closedloop.frequency_response(model.linearize(19.0), w, "gen_speed", "pitch_cmd")
    y = c / (1 + c * p)
    c_r = np.abs(closedloop.siso_response(spec.baseline_controller(model, 19.0), w))
    # the bound holds between the problem's grid points up to the solver's feasibility tolerance
    # (1e-7) and the interpolation error of a smooth Y between points 1.7 % apart (< 1 %)
    assert np.max(np.abs(y) / (kappa * c_r)) <= 1.01
    assert float(np.asarray(ct.ss(bounded.controller(model)).D).ravel()[0]) == pytest.approx(0.0, abs=1e-9)
    c_free = np.abs(closedloop.siso_response(free.controller(model), w))
    assert np.max(c_free / c_r) > 10 * kappa  # without the bound the gain runs away (issue: 2 300-8 000× at 10 rad/s)
    assert bounded.del_reduction < free.del_reduction  # a constraint costs promise
    with pytest.raises(ValueError, match="hf_omega"):
        YoulaProblem(model, 19.0, max_hf_gain_ratio=kappa, hf_omega=20.0)
    with pytest.raises(ValueError, match="max_hf_gain_ratio"):
        YoulaProblem(model, 19.0, max_hf_gain_ratio=-1.0)
