"""The MPCs on OpenFAST's linearisations (issue 31, "model ≠ plant"): QuadraticMPC and its LPV
Kalman filter built on a :class:`specdesign.openfast.LinearTurbine`, and its loop gain.

Oracles: the discrete model of a plant with a pitch feedthrough against the continuous plant
integrated by scipy's Radau with the command held (the measurement at a sample is the left limit,
the command held up to it); the MPC on ``LinearTurbine.from_model`` (the reduced model's own
linearisations and trims) against the MPC on the reduced model itself, command for command; the
unconstrained law against the MPC stepped sample by sample; the loop gain against python-control's
frequency response of the same two discrete systems in series.
"""
from __future__ import annotations

import dataclasses

import control
import numpy as np
import pytest
import scipy.integrate
from numpy.testing import assert_allclose

from specdesign.mpc import (
    HealthMPC,
    QuadraticMPC,
    discretize_turbine,
    loop_gain,
    unconstrained_law,
)
from specdesign.openfast import LinearTurbine
from specdesign.simulate import simulate
from specdesign.turbine import iea15mw

TS = 0.1


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def floating(package_data, model):
    """OpenFAST's linearisation of the floating IEA 15 MW at 19 m/s (shipped sample): no pitch
    actuator, so the measured pitch and the tower-top acceleration have a pitch feedthrough."""
    lt = LinearTurbine.from_lin_files(package_data / "sample_floating_19mps.1.lin")
    return dataclasses.replace(lt, pitch_min=model.pitch_min, pitch_max=model.pitch_max,
                               pitch_rate_limit=model.pitch_rate_limit)


def test_discrete_model_with_feedthrough_is_the_sampled_plant(floating):
    """y_k = C x(t_k) + D_u u_{k−1} + D_w d: the held command is a state of the discrete model."""
    sys = floating.linearize(19.0)
    A, B, C, D = (np.asarray(m, float) for m in (sys.A, sys.B, sys.C, sys.D))
    iw, iu = sys.input_labels.index("wind"), sys.input_labels.index("pitch_cmd")
    dm = discretize_turbine(floating, 19.0, TS)
    n = A.shape[0]
    assert dm.A.shape == (n + 1, n + 1) and dm.x0[-1] == floating.trim(19.0).pitch
    u = 1e-3 * np.sin(np.arange(8))  # commands held over each sample (rad), from zero before
    d = 0.3  # a wind deviation held throughout (m/s)
    x, xd, prev = np.zeros(n), np.zeros(n + 1), 0.0
    for k, uk in enumerate(u):
        y_ref = C @ x + D[:, iu] * prev + D[:, iw] * d
        assert_allclose(dm.C @ xd + dm.Dw * d, y_ref, rtol=1e-6, atol=1e-9 * np.abs(y_ref).max(), err_msg=f"sample {k}")
        sol = scipy.integrate.solve_ivp(lambda _t, s, uk=uk: A @ s + B[:, iu] * uk + B[:, iw] * d, (0.0, TS), x,
                                        method="Radau", rtol=1e-11, atol=1e-14)
        x, xd, prev = sol.y[:, -1], dm.A @ xd + dm.Bu * uk + dm.Bw * d, uk


# how far from the trim pitch (rad) each MPC may command at the trim's measurements: the quadratic
# MPC tracks the trim's own outputs (round-off); the excursion MPC tracks the model's rated rotor
# speed, which this sample's header gives rounded (0.7919 rad/s) below the generator speed of its
# outputs (0.791996 rad/s): it pitches up by 1.3e-5 rad for that 1.2e-4 over-speed; 1e-4 rad is
# below what the 0.01 rad/s over-speed of the test asks of either (> 1e-4)
@pytest.mark.parametrize("make, hold_tol", [(lambda m: QuadraticMPC(m, ts=TS), 1e-12),
                                            (lambda m: HealthMPC(m, health_weight=10.0), 1e-4)],
                         ids=["quadratic", "excursion"])
def test_mpc_on_openfast_linearisation_holds_the_trim_and_pickles(floating, make, hold_tol):
    """At the trim's measurements the MPC (estimated operating point) commands the trim pitch; an
    over-speed pitches up; the controller pickles (a forwarded controller is pickled to its server).
    The excursion MPC reads the blades' collective moment (RootMyc1-3 of the sample, MBC) and starts
    its LPV filter from the discrete model's trim state, which carries the held command of a plant
    whose pitch feeds through (it started from the plant's trim state alone, one entry short)."""
    import pickle

    assert "blade_root_my" in floating.output_names
    op = floating.trim(19.0)
    y0 = dict(zip(floating.output_names, op.y))
    for over, sign in ((0.0, 0), (0.01, 1)):
        mpc = pickle.loads(pickle.dumps(make(floating)))
        mpc.start(0.02, np.array([19.0]), np.array([op.pitch]), np.array([op.gen_torque]))
        y = {k: np.array([v + (over if k == "gen_speed" else 0.0)]) for k, v in y0.items()}
        cmd = [float(mpc(0.02 * k, y)[0]) for k in range(10)]
        if sign == 0:
            assert_allclose(cmd, op.pitch, rtol=0, atol=hold_tol)
        else:
            assert cmd[-1] > op.pitch + 1e-4


def test_mpc_on_linear_turbine_of_the_reduced_model_is_the_reduced_models_mpc(model):
    """The LinearTurbine route (plants, trim states and outputs, the held-command rule that a model
    without feedthrough does not trigger) gives the reduced model's MPC, command for command."""
    speeds = np.arange(15.0, 26.0)
    lt = LinearTurbine.from_model(model, speeds)
    kw = {"ts": TS, "wind_speeds": speeds}
    ref, got = (simulate(model, QuadraticMPC(m, **kw), [19.0], seeds=[1], duration=8.0, transient=2.0)["pitch_cmd"]
                for m in (model, lt))
    assert np.ptp(ref) > 1e-3  # the MPC moves the pitch
    assert_allclose(got, ref, rtol=0, atol=1e-9)


def test_unconstrained_law_is_the_mpcs_first_move(model):
    """Stepping the MPC (fixed operating point, no constraint active) on perturbed measurements gives
    the law's output sample by sample."""
    mpc = QuadraticMPC(model, ts=TS, operating_point="initial pitch")
    op = model.trim(19.0)
    mpc.start(TS, np.array([19.0]), np.array([op.pitch]), np.array([op.gen_torque]))
    dm = mpc.point(19.0)["model"]
    y0 = dm.y0[dm.rows(mpc.measured)]
    A, B, C, D = unconstrained_law(mpc, 19.0)
    scale = np.array([2e-3, 2e-2, 1e-4])  # speed (rad/s), acceleration (m/s²), pitch (rad): small moves
    dy = np.random.default_rng(0).standard_normal((30, 3)) * scale
    s, prev = np.zeros(A.shape[0]), op.pitch
    for k, e in enumerate(dy):
        cmd = float(mpc(k * TS, {n: np.array([y0[i] + e[i]]) for i, n in enumerate(mpc.measured)})[0])
        law = C @ s + D @ e
        s = A @ s + B @ e
        assert abs(cmd - prev) < model.pitch_rate_limit * TS  # no constraint active: the law applies
        assert_allclose(cmd - op.pitch, law, rtol=1e-9, atol=1e-13, err_msg=f"sample {k}")
        prev = cmd


def test_loop_gain_is_the_frequency_response_of_law_and_plant_in_series(model, floating):
    """loop_gain = python-control's response of the law and the discretised plant in series, on the
    MPC's own model and on another plant (OpenFAST's linearisation); the nominal loop is stable."""
    mpc = QuadraticMPC(model, ts=TS, operating_point="initial pitch")
    w = np.array([0.3, 1.1, 2.5, 6.0, 20.0])
    law = control.ss(*unconstrained_law(mpc, 19.0), dt=TS)
    for plant in (None, floating):
        dm = mpc.point(19.0)["model"] if plant is None else discretize_turbine(plant, 19.0, TS)
        rows = dm.rows(mpc.measured)
        p = control.ss(dm.A, dm.Bu[:, None], dm.C[rows], np.zeros((rows.size, 1)), dt=TS)
        ref = np.array([complex(np.squeeze(control.series(p, law)(np.exp(1j * wi * TS)))) for wi in w])
        assert_allclose(loop_gain(mpc, 19.0, w, plant=plant), ref, rtol=1e-8)
    # the nominal sampled loop (plant = the MPC's model): u = C s + D y, y = C_p x
    Ac, Bc, Cc, Dc = unconstrained_law(mpc, 19.0)
    dm = mpc.point(19.0)["model"]
    Cp = dm.C[dm.rows(mpc.measured)]
    closed = np.block([[dm.A + np.outer(dm.Bu, Dc @ Cp), np.outer(dm.Bu, Cc)], [Bc @ Cp, Ac]])
    assert np.abs(np.linalg.eigvals(closed)).max() < 1.0
