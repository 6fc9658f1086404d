"""The embedded IEA 15 MW model against ROSCO, OpenFAST and independent calculations."""
import dataclasses
import json

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.integrate import solve_ivp
from scipy.interpolate import RectBivariateSpline

from specdesign import turbine
from specdesign.turbine import iea15mw, rosco_baseline, rosco_gain_schedule


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def rosco(package_data):
    return json.loads((package_data / "rosco_gain_schedule.json").read_text())


@pytest.fixture(scope="module")
def openfast_ref(package_data):
    return json.loads((package_data / "rotor_linearization_reference.json").read_text())


def _table(package_data):
    """Independent parse of the ROSCO text table."""
    lines = (package_data / "Cp_Ct_Cq.IEA15MW.txt").read_text().splitlines()
    pitch = np.array(lines[4].split(), float)
    tsr = np.array(lines[6].split(), float)
    cp = np.loadtxt(lines[12:38])
    ct = np.loadtxt(lines[42:68])
    return tsr, np.deg2rad(pitch), cp, ct


def test_compiled_interpolant_is_the_scipy_spline(model, package_data):
    tsr, pitch, cp, ct = _table(package_data)
    rng = np.random.default_rng(0)
    t = rng.uniform(tsr[0], tsr[-1], 400)
    b = rng.uniform(pitch[0], pitch[-1], 400)
    got_cp, got_ct = model.rotor_coefficients(t, b)
    assert_allclose(got_cp, RectBivariateSpline(tsr, pitch, cp, s=0).ev(t, b), atol=1e-12)
    assert_allclose(got_ct, RectBivariateSpline(tsr, pitch, ct, s=0).ev(t, b), atol=1e-12)
    T, B = np.meshgrid(tsr, pitch, indexing="ij")
    assert_allclose(model.rotor_coefficients(T, B)[0], cp, atol=1e-12)  # passes through the table


def test_trim_pitch_matches_rosco(model, rosco):
    for v, pitch_deg in zip(rosco["v"], rosco["pitch_op_deg"]):
        if v < 15:
            continue
        op = model.trim(v)
        assert abs(np.rad2deg(op.pitch) - pitch_deg) < 0.5
        # the trim is an equilibrium of the kernel
        assert_allclose(model.derivatives(op.x, v, op.pitch, op.gen_torque), 0, atol=1e-9)
        assert_allclose(op.aero_power, model.rated_generator_torque * model.rated_rotor_speed, rtol=1e-9)


def test_rotor_coefficients_match_rosco(model, rosco):
    s = rosco_gain_schedule(model, rosco["v"])
    for key in ("A", "B_beta", "B_wind"):
        assert_allclose(getattr(s, key), rosco[key], rtol=0.02, err_msg=key)
    kp, ki = np.array(rosco["Kp"]), np.array(rosco["Ki"])
    # 3 %, or 0.005 absolute where Kp crosses zero near 22 m/s
    assert np.all(np.abs(s.Kp - kp) <= np.maximum(0.03 * np.abs(kp), 0.005))
    assert np.all(np.abs(s.Ki - ki) <= np.maximum(0.03 * np.abs(ki), 0.005))
    assert_allclose(s.pitch_op, np.deg2rad(rosco["pitch_op_deg"]), atol=np.deg2rad(0.5))


def test_rotor_coefficients_from_spline_derivatives(model, package_data):
    # A = ∂Ω̇/∂Ω and B_β = ∂Ω̇/∂β written out from the scipy spline's partial derivatives
    tsr, pitch, cp, _ = _table(package_data)
    spl = RectBivariateSpline(tsr, pitch, cp, s=0)
    v = 19.0
    op = model.trim(v)
    R, J = model.rotor_radius, model.drivetrain_inertia
    lam = op.rotor_speed * R / v
    q = 0.5 * model.air_density * np.pi * R**2 * v**2
    cp0 = spl.ev(lam, op.pitch)
    d_lam = spl.ev(lam, op.pitch, dx=1)
    d_beta = spl.ev(lam, op.pitch, dy=1)
    A_ref = q * R * (d_lam / lam - cp0 / lam**2) * (R / v) / J
    B_ref = q * R * d_beta / lam / J
    P = model.linearize(v)
    assert_allclose(P.A[0, 0], A_ref, rtol=1e-6)
    assert_allclose(P.A[0, 3], B_ref, rtol=1e-6)
    # rotor sees U − ẋ_top: the tower velocity enters with the opposite sign of the wind
    assert_allclose(P.A[0, 2], -P.B[0, 0], rtol=1e-6)


def test_linear_structure(model):
    P = model.linearize(17.0)
    wa, za = model.actuator_omega, model.actuator_zeta
    assert P.input_labels == ["wind", "pitch_cmd", "gen_torque"]
    assert P.output_labels == list(turbine.OUTPUT_NAMES)
    assert_allclose(P.A[3:, 3:], [[0, 1], [-wa**2, -2 * za * wa]], atol=1e-6)
    assert_allclose(P.B[4, 1], wa**2, rtol=1e-6)
    assert_allclose(P.A[1, 2], 1.0)
    assert_allclose(P.A[2, 1], -model.tower_modal_stiffness / model.tower_modal_mass, rtol=1e-6)
    assert_allclose(P.B[0, 2], -1 / model.drivetrain_inertia, rtol=1e-6)
    assert_allclose(P.C[1, 1], model.tower_base_moment_per_m, rtol=1e-9)
    assert_allclose(P.D[5, 2], model.generator_efficiency * model.rated_rotor_speed, rtol=1e-6)
    # tower_top_acc = third row of (A, B)
    assert_allclose(P.C[2], P.A[2], rtol=1e-9, atol=1e-12)
    # named indexing as the contract promises
    sub = P["gen_speed", "wind"]
    assert_allclose(control.dcgain(sub), -P.B[0, 0] / P.A[0, 0], rtol=1e-6)


def test_saturations_inactive_at_trim(model):
    loose = dataclasses.replace(model, pitch_rate_limit=1e9, pitch_min=-0.05, pitch_max=1.5)
    for v in (11.0, 19.0, 25.0):
        a = model.jacobians(model.trim(v))
        b = loose.jacobians(loose.trim(v))
        for x, y in zip(a, b):
            assert_allclose(x, y, rtol=1e-8, atol=1e-12)  # trims differ only by root-finding round-off


def test_actuator_limits_in_rhs(model):
    op = model.trim(19.0)
    x = np.array(op.x)
    x[4] = 0.2  # internal rate beyond the 0.0349 rad/s limit
    dx = model.derivatives(x, 19.0, op.pitch + 1.0, op.gen_torque)
    assert dx[3] == pytest.approx(model.pitch_rate_limit)
    assert dx[4] == 0.0  # no wind-up of the rate state
    x = np.array(op.x)
    x[3] = model.pitch_max
    x[4] = 0.01
    assert model.derivatives(x, 19.0, model.pitch_max + 0.1, op.gen_torque)[3] == 0.0


def test_linearisation_matches_nonlinear_step(model):
    # a small wind step through the kernel (scipy solve_ivp) vs the linear model's step
    v, du = 19.0, 0.05
    op = model.trim(v)
    P = model.linearize(v)
    t = np.linspace(0, 30, 301)
    sol = solve_ivp(lambda _t, x: model.derivatives(x, v + du, op.pitch, op.gen_torque), (0, 30), op.x, t_eval=t, rtol=1e-10, atol=1e-12)
    lin = control.forced_response(P[["gen_speed", "tower_base_my"], "wind"], t, du * np.ones_like(t))
    ys = np.array([model.evaluate_outputs(x, v + du, op.pitch, op.gen_torque) for x in sol.y.T])
    d_omega = ys[:, 0] - op.rotor_speed
    d_my = ys[:, 1] - model.tower_base_moment_per_m * op.x[1]
    assert_allclose(d_omega, lin.outputs[0], atol=0.02 * np.abs(lin.outputs[0]).max())
    assert_allclose(d_my, lin.outputs[1], atol=0.02 * np.abs(lin.outputs[1]).max())


def test_tower_frequencies(model, package_data):
    fe = json.loads((package_data / "tower_fe.json").read_text())["with gravity (P-delta)"]
    w_struct = np.sqrt(model.tower_modal_stiffness / model.tower_modal_mass)
    assert abs(w_struct / fe["w1"] - 1) < 0.01
    assert abs(w_struct / 1.081 - 1) < 0.01
    for v in (15.0, 19.0, 25.0):
        poles = model.linearize(v).poles()
        tower = poles[np.argmin(np.abs(np.abs(poles) - w_struct))]
        wn, zeta = abs(tower), -tower.real / abs(tower)
        assert 1.0 < wn < w_struct  # aerodynamic stiffness softens it a little
        assert 0.02 < zeta < 0.2  # several % aerodynamic damping on top of the 1 % structural


def test_against_openfast_linearisation(model, openfast_ref):
    for row in openfast_ref:
        P = model.linearize(row["U"])
        dc = control.dcgain(P["gen_speed", "wind"])
        assert abs(dc / row["OF_DC_GenSpeed_per_U"] - 1) < 0.10, row["U"]
        assert abs(P.A[0, 0] / row["OF_A"] - 1) < 0.20, row["U"]


def test_rosco_baseline_is_pi_times_filter(model, rosco):
    s = rosco_gain_schedule(model)
    k = 9
    v = s.v[k]
    C = rosco_baseline(model, v, schedule=s)
    w = np.logspace(-3, 1, 50)
    jw = 1j * w
    wf, zf = 1.0081, 0.7
    expected = (s.Kp[k] + s.Ki[k] / jw) * wf**2 / (jw**2 + 2 * zf * wf * jw + wf**2)
    assert_allclose(C(jw), expected, rtol=1e-9)
    assert C.input_labels == ["gen_speed"] and C.output_labels == ["pitch_cmd"]
    # against ROSCO's shipped gains at the nearest schedule point
    j = int(np.argmin(np.abs(np.array(rosco["v"]) - v)))
    assert abs(s.Kp[k] - rosco["Kp"][j]) <= max(0.03 * abs(rosco["Kp"][j]), 0.005)


def test_rosco_baseline_sign_and_stability(model):
    for v in (15.0, 19.0, 25.0):
        P = model.linearize(v)
        C = rosco_baseline(model, v)
        p0 = control.dcgain(P["gen_speed", "pitch_cmd"])
        ki = (C(1e-6j) * 1e-6j).real  # s·C(s) → Ki as s → 0
        assert p0 < 0 and ki < 0  # both factors of L = C·P negative at low frequency
        L = control.ss(C) * P["gen_speed", "pitch_cmd"]
        cl = control.feedback(L, 1)
        assert np.all(cl.poles().real < 0)


def test_validity_range_errors(model):
    for v in (2.0, 26.0):  # outside cut-in to cut-out (below rated: tests/test_below_rated.py)
        with pytest.raises(ValueError, match="wind_speed"):
            model.linearize(v)
    bare = dataclasses.replace(model, torque_control=None)  # no torque law: the pitch-regulated range only
    for v in (8.0, 10.9, 26.0):
        with pytest.raises(ValueError, match="wind_speed"):
            bare.linearize(v)
    wide = dataclasses.replace(bare, wind_range=(3.0, 25.0))
    with pytest.raises(ValueError, match="below rated"):
        wide.trim(8.0)
    with pytest.raises(ValueError, match="x must be"):
        model.derivatives(np.zeros(3), 19.0, 0.2, 1e7)
    with pytest.raises(ValueError, match="wind_speeds"):
        rosco_gain_schedule(model, [19.0])


def test_rated_wind_speed_near_rosco(model):
    # ROSCO's schedule starts one step above its rated speed, (25 − v_rated)/30 apart
    assert abs(model.rated_wind_speed() - 10.59) < 0.05


def test_models_compare_and_hash_by_their_fields():
    # The dataclass's generated __eq__ compared the fields as tuples, and a tuple holding the
    # rotor tables has no truth value: ``model == model`` raised, and a model could not key a
    # dict. Two builds of the same turbine are equal whatever either has computed (trims are
    # derived state), and a change of one table entry or one scalar makes them differ.
    a, b = iea15mw(), iea15mw()
    a.trim(19.0)
    assert a == b and hash(a) == hash(b) and {a: "x"}[b] == "x"
    table = b.cp_table.copy()
    table[3, 4] *= 1 + 1e-12
    assert a != dataclasses.replace(b, cp_table=table)
    assert a != dataclasses.replace(b, tower_damping_ratio=b.tower_damping_ratio * 1.01)
    assert a != dataclasses.replace(b, cp_table=b.cp_table[:, :-1])  # another shape, not an error
    assert (a == "iea15mw") is False
