"""Campaigns with the generator-torque law (run_campaign(torque_control=...)): the campaign
runs exactly what :func:`specdesign.simulate.simulate` runs with the same ``torque_control``
(the oracle: the simulator called directly on the same wind), a callable controller runs with
the torque it commands itself, and a store refuses another torque setting."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from specdesign import simulate as sm
from specdesign import turbine
from specdesign.validate import indicators, run_campaign

KW = dict(duration=30.0, transient=5.0, progress=False, predict=False)


@pytest.fixture(scope="module")
def setup():
    model = turbine.iea15mw()
    return model, sm.rosco_scheduled(model)


def direct_tower_del(model, ctrl, v, seeds, tc):
    radius = model.rotor_radius
    wind = sm.wind_series(radius, [v], seeds, 5.0 + 30.0 + 0.1, 0.1, "B")
    r = sm.simulate(model, ctrl, [v], seeds=seeds, wind=wind, wind_dt=0.1, duration=30.0, transient=5.0,
                    torque_control=tc)
    return indicators(r.outputs, r.dt, 4.0).as_dict()["tower_del"][0]


# below rated (10.59 m/s) "auto" runs the model's law: None (torque held) and another law differ
@pytest.mark.parametrize("tc", ["other law", None])
def test_campaign_passes_torque_control_to_the_simulator(setup, tc):
    model, ctrl = setup
    seeds, v = np.array([0, 1]), 8.0
    if tc == "other law":
        tc = dataclasses.replace(model.torque_control, k_opt=0.9 * model.torque_control.k_opt)
    camp = run_campaign({"ROSCO": ctrl}, [v], seeds, model=model, torque_control=tc, **KW)
    expected = direct_tower_del(model, ctrl, v, seeds, tc)
    np.testing.assert_array_equal(camp.values["tower_del"][0, 0], expected)
    auto = run_campaign({"ROSCO": ctrl}, [v], seeds, model=model, **KW)
    assert not np.array_equal(auto.values["tower_del"][0, 0], expected)  # the setting took effect


def test_callable_controller_runs_with_its_own_torque(setup):
    model, ctrl = setup

    def hold_pitch(t, y):  # a callable: fixed fine pitch (below rated, the PI would sit there)
        return np.full(y["gen_speed"].shape, model.pitch_min)

    # "rosco" is refused by the simulator for a callable; the campaign runs it with "auto"
    camp = run_campaign({"ROSCO": ctrl, "hold": hold_pitch}, [7.0], [0], model=model, torque_control="rosco", **KW)
    assert np.all(np.isfinite(camp.values["tower_del"]))


def test_torque_control_is_checked_and_stored(setup, tmp_path):
    model, ctrl = setup
    with pytest.raises(ValueError, match="torque_control"):
        run_campaign({"ROSCO": ctrl}, [19.0], [0], model=model, torque_control="on", **KW)
    with pytest.raises(ValueError, match="torque law"):
        run_campaign({"ROSCO": ctrl}, [19.0], [0], model=dataclasses.replace(model, torque_control=None),
                     torque_control="rosco", **KW)
    store = tmp_path / "tq"
    run_campaign({"ROSCO": ctrl}, [19.0], [0], model=model, store=store, **KW)
    with pytest.raises(ValueError, match="settings"):
        run_campaign({"ROSCO": ctrl}, [19.0], [0], model=model, store=store, torque_control="rosco", **KW)
    with pytest.raises(ValueError, match="settings"):
        run_campaign({"ROSCO": ctrl}, [19.0], [0], model=model, store=store, torque_control=model.torque_control, **KW)
