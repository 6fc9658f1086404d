"""Blade-root flapwise moment output ``blade_root_my`` of the reduced turbine model.

Checked against a hand computation of the thrust from the raw Ct table (parsed here, not
through the model's interpolant), against the model's own thrust derivatives for the
linearisation, and against OpenFAST's mean RootMyc where the rosco package's IEA 15 MW
linearisation deck is installed.
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign import simulate as sim
from specdesign import turbine
from specdesign.turbine.kernel import THRUST_CENTRE_COEFFS, thrust_centre
from specdesign.turbine.tables import read_text

R_FIT_LO, R_FIT_HI = 7.0, 24.0


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


def _raw_ct_table():
    """(pitch deg, tsr, Ct[tsr, pitch]) parsed straight from the shipped ROSCO text file."""
    lines = read_text("Cp_Ct_Cq.IEA15MW.txt").splitlines()
    pitch = np.array(lines[lines.index(next(s for s in lines if s.startswith("# Pitch angle"))) + 1].split(), float)
    tsr = np.array(lines[lines.index(next(s for s in lines if s.startswith("# TSR vector"))) + 1].split(), float)
    i = next(k for k, s in enumerate(lines) if "Thrust coefficient" in s) + 2
    ct = np.array([lines[i + r].split() for r in range(tsr.size)], float)
    return pitch, tsr, ct


def test_blade_moment_is_last_output_and_indices_unchanged():
    # appended: the six earlier outputs keep their indices (the simulator and the
    # closed-loop code index by name, older code by position)
    assert turbine.OUTPUT_NAMES[:6] == ("gen_speed", "tower_base_my", "tower_top_acc", "tower_top_vel", "pitch", "power")
    assert turbine.OUTPUT_NAMES[6] == "blade_root_my"


@pytest.mark.parametrize("i_tsr, i_pitch, wind", [(12, 5, 11.0), (16, 17, 15.0), (14, 26, 23.0)])
def test_blade_moment_hand_thrust_at_table_nodes(model, i_tsr, i_pitch, wind):
    # at a table node the interpolant passes through the table value, so the thrust is
    # 1/2 ρ π R² U² Ct[i, j] by hand; tower at rest: the relative wind is the wind
    pitch_deg, tsr, ct = _raw_ct_table()
    beta = np.deg2rad(pitch_deg[i_pitch])
    radius, rho = 120.97, 1.225  # parameters.json (IEA-15-240-RWT)
    omega = tsr[i_tsr] * wind / radius
    thrust = 0.5 * rho * np.pi * radius**2 * wind**2 * ct[i_tsr, i_pitch]
    c0, c1, c2 = 0.67280, 0.15642, -1.85570  # the documented centre-of-thrust fit
    expected = (c0 + c1 * beta + c2 * beta**2) * radius * thrust / 3.0
    y = model.evaluate_outputs([omega, 0.0, 0.0, beta, 0.0], wind, beta, model.rated_generator_torque)
    assert_allclose(y[6], expected, rtol=1e-9)


def test_blade_moment_follows_tower_deflection_thrust(model):
    # with the tower moving, the moment still follows the aerodynamic thrust at the wind
    # relative to the tower top (the thrust recovered from the tower mode's equation)
    from specdesign.turbine import aero_loads

    x = np.array([0.78, 0.4, -0.3, np.deg2rad(12.0), 0.0])
    y = model.evaluate_outputs(x, 17.0, x[3], model.rated_generator_torque)
    _, thrust = aero_loads(model.kernel_params(), x[0], 17.0 - x[2], x[3])
    assert_allclose(y[6], thrust_centre(x[3]) * model.rotor_radius * thrust / 3, rtol=1e-9)


def test_blade_moment_linearisation_rows(model):
    # the linearisation's blade_root_my row against the chain rule on the model's own
    # aerodynamic thrust: ∂M/∂v = r_T/3 ∂T/∂v, ∂M/∂β = R/3 (r_T'(β) T + r_T ∂T/∂β)
    from specdesign.turbine import aero_loads

    v = 19.0
    op = model.trim(v)
    sys = model.linearize(v)
    p = model.kernel_params()
    h_v, h_b = 1e-3, 1e-5

    def thrust(vv, bb):
        return aero_loads(p, op.rotor_speed, vv, bb)[1]

    dT_dv = (thrust(v + h_v, op.pitch) - thrust(v - h_v, op.pitch)) / (2 * h_v)
    dT_db = (thrust(v, op.pitch + h_b) - thrust(v, op.pitch - h_b)) / (2 * h_b)
    c0, c1, c2 = THRUST_CENTRE_COEFFS
    r = c0 + c1 * op.pitch + c2 * op.pitch**2
    dr = c1 + 2 * c2 * op.pitch
    R = model.rotor_radius
    i = sys.output_labels.index("blade_root_my")
    assert_allclose(sys.D[i, sys.input_labels.index("wind")], r * R / 3 * dT_dv, rtol=1e-4)
    assert_allclose(sys.C[i, sys.state_labels.index("pitch")], R / 3 * (dr * thrust(v, op.pitch) + r * dT_db), rtol=1e-4)


def test_blade_moment_in_simulation(model):
    r = sim.simulate(model, turbine.rosco_baseline(model, 19.0), [19.0], seeds=[3], duration=20.0, transient=5.0)
    my = r["blade_root_my"]
    assert my.shape == r["gen_speed"].shape
    # quasi-static: the recorded moment is r_T(β)·T/3 of the recorded state; at the mean it
    # sits near the trim moment (2 % of turbulence-driven wander in 20 s)
    op = model.trim(19.0)
    trim_my = model.evaluate_outputs(op.x, 19.0, op.pitch, op.gen_torque)[6]
    assert abs(my.mean() / trim_my - 1) < 0.1
    assert my.std() > 0.01 * trim_my


def _openfast_deck():
    spec = importlib.util.find_spec("rosco")
    if spec is None or not spec.submodule_search_locations:
        return None
    d = (Path(list(spec.submodule_search_locations)[0]).parent / "Examples" / "Test_Cases" / "IEA-15-240-RWT"
         / "IEA-15-240-RWT-UMaineSemi" / "linearizations")
    return d if d.is_dir() else None


def test_blade_moment_against_openfast_mean_rootmyc(model):
    # OpenFAST (rosco's IEA-15-240-RWT deck, 12 azimuths per wind speed): mean over blades and
    # azimuths of RootMyc against this model's moment at OpenFAST's operating point (wind,
    # pitch, rotor speed; tower at rest so the thrust is the aerodynamic thrust). The
    # documented acceptance: within 3 % from 7 to 24 m/s (the fit's worst residual is 2.7 %).
    deck = _openfast_deck()
    if deck is None:
        pytest.skip("rosco's OpenFAST example deck is not installed")
    from specdesign.openfast.lin import read_lin_file

    cases = {}
    for f in sorted(deck.glob("lin_*.lin")):
        lin = read_lin_file(f)
        y = dict(zip(lin.y_desc, lin.y_op))
        my = np.mean([y[f"ED RootMyc{b}, (kN-m)"] for b in (1, 2, 3)]) * 1e3
        pitch = np.deg2rad(y["ED BldPitch1, (deg)"])
        cases.setdefault(lin.wind_speed, []).append((my, pitch, lin.rotor_speed))
    assert len(cases) >= 15
    checked = 0
    for v, rows in cases.items():
        if not R_FIT_LO <= v <= R_FIT_HI:
            continue
        my_of, pitch, omega = np.mean(rows, axis=0)
        y = model.evaluate_outputs([omega, 0.0, 0.0, pitch, 0.0], v, pitch, model.rated_generator_torque)
        assert abs(y[6] / my_of - 1) < 0.03, (v, y[6], my_of)
        checked += 1
    assert checked >= 15
