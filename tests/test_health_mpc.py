"""Online damage D(k), the LPV prediction model and the health-aware LPV MPC (issue 17, part 2).

Oracles: the streaming counter against the batch counter (``fatigue.rainflow`` +
``miner_damage``), against the ``rainflow`` package and against a cycle count done by hand;
the QP's moves against the same QP minimised by hand (a 2-state model simulated step by step,
its quadratic cost recovered exactly and solved by linear algebra, the rate-limited case by its
KKT conditions); the MPC against itself through pickling and ``run_campaign``.
"""
import pickle

import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign.fatigue import SNCurve, del_rainflow, miner_damage, rainflow
from specdesign.fatigue_online import StreamingDamage, accumulated_damage
from specdesign.mpc.base import DiscreteTurbine, prediction_matrices
from specdesign.mpc.health import HealthMPC, health_aware_mpc, health_move, health_scale
from specdesign.mpc.lpv import PREDICTED, LPVTurbine, lpv_turbine
from specdesign.simulate import simulate
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


# ----------------------------------------------------------------------------- streaming damage
def test_streaming_damage_by_hand():
    # turning points 0 3 1 4 0 2 1, S-N m = 3, S_ref = 10. Closed online: (3, 1) full, range 2
    # → 0.2³ = 0.008 when the 5th sample shows 4 to be a turning point; then (0, 4) holds the
    # first point: half, range 4 → 0.5·0.4³ = 0.032, when the 6th shows 0 to be one.
    # The residue 4 0 2 1 as half cycles: 0.5·(0.4³ + 0.2³ + 0.1³) = 0.0365.
    sd = StreamingDamage(SNCurve(m=3, s_ref=10.0))
    trace = np.concatenate([sd.update([0.0, 3.0]), sd.update(1.0), sd.update([4.0, 0.0, 2.0, 1.0])])
    assert_allclose(trace, [0, 0, 0, 0, 0.008, 0.040, 0.040], atol=1e-15)
    assert_allclose(sd.damage, 0.040, rtol=1e-14)
    assert_allclose(sd.total(), 0.0765, rtol=1e-14)
    assert_allclose(sd.residue, [4.0, 0.0, 2.0, 1.0])
    assert sd.total() == sd.total()  # total() leaves the state alone


@pytest.mark.parametrize("kind", ["noise", "walk", "quantised", "bilinear"])
def test_streaming_damage_equals_batch_for_any_chunking(kind):
    rng = np.random.default_rng(7)
    sn = SNCurve(m=3, s_ref=40.0, knee_cycles=1e3, m2=5.0) if kind == "bilinear" else SNCurve(m=10, s_ref=40.0)
    for trial in range(20):
        n = int(rng.integers(2, 4000))
        x = {"noise": rng.normal(size=n), "walk": np.cumsum(rng.normal(size=n)),
             "quantised": np.round(rng.normal(size=n), 1), "bilinear": np.cumsum(rng.normal(size=n))}[kind]
        c = rainflow(x)
        ref = miner_damage(c.ranges, c.counts, sn)
        traces = []
        for chunk in (1, 7, None):  # sample by sample, small blocks, random blocks
            sd, i, tr = StreamingDamage(sn), 0, []
            while i < n:
                k = int(rng.integers(0, 60)) if chunk is None else chunk
                tr.append(sd.update(x[i:i + k]))
                i += k
            assert sd.samples_seen == n
            assert_allclose(sd.total(), ref, rtol=1e-12, atol=0)
            traces.append(np.concatenate(tr))
        # the counting is sequential: the trace D(k) does not depend on the chunking, bit for bit
        assert np.array_equal(traces[0], traces[1]) and np.array_equal(traces[0], traces[2])
        assert np.all(np.diff(traces[0]) >= 0)
        assert traces[0][-1] <= ref * (1 + 1e-12)


def test_streaming_damage_against_rainflow_package():
    rf = pytest.importorskip("rainflow")
    x = np.cumsum(np.random.default_rng(3).normal(size=20000))
    sn = SNCurve(m=4, s_ref=25.0)
    ref = sum(n * (r / 25.0) ** 4 for r, _, n, _, _ in rf.extract_cycles(x))
    assert np.array_equal(accumulated_damage(x, sn), StreamingDamage(sn).update(x))
    sd = StreamingDamage(sn)
    sd.update(x)
    assert_allclose(sd.total(), ref, rtol=1e-11)


def test_streaming_damage_errors():
    with pytest.raises(TypeError, match="SNCurve"):
        StreamingDamage(4.0)
    with pytest.raises(ValueError, match="NaN"):
        StreamingDamage(SNCurve(m=4)).update([0.0, np.nan])


# ----------------------------------------------------------------------------- LPV model
def test_lpv_blend_is_convex_combination_of_vertices(model):
    lpv = lpv_turbine(model, 0.2, 6, wind_speeds=[17.0, 19.0, 21.0])
    op = model.trim(18.0)
    x, u = np.array(op.x), np.full(6, op.pitch + 0.01)
    one = LPVTurbine(lpv.wind_speeds[:1], 0.2, 6, lpv.output_names, *(a[:1] for a in (lpv.x_trim, lpv.pitch_trim,
                     lpv.y_trim, lpv.Phi, lpv.Gamma, lpv.Psi, lpv.C, lpv.Dw)))
    two = LPVTurbine(lpv.wind_speeds[1:2], 0.2, 6, lpv.output_names, *(a[1:2] for a in (lpv.x_trim, lpv.pitch_trim,
                     lpv.y_trim, lpv.Phi, lpv.Gamma, lpv.Psi, lpv.C, lpv.Dw)))
    # Eq. (10)-(11) of seed 002: α = (0.25, 0.75) at 18.5 m/s between the 17 and 19 m/s vertices
    assert lpv.alphas(18.5) == (0, 0.75)
    assert_allclose(lpv.predict(x, 18.5, u), 0.25 * one.predict(x, 18.5, u) + 0.75 * two.predict(x, 18.5, u))
    assert lpv.alphas(30.0) == (1, 1.0) and lpv.alphas(5.0) == (0, 0.0)


def test_lpv_prediction_tracks_nonlinear_model_better_than_fixed(model):
    # a run started at 15 m/s whose wind has drifted to 20 m/s: from the 20 m/s trim, a pitch
    # step of 0.01 rad and 0.5 m/s more wind, held 6 s. The speed predicted by the scheduled
    # model against the nonlinear model's (RK4 at 0.02 s), and the fixed 15 m/s linearisation's
    ts, N = 0.2, 30
    lpv = lpv_turbine(model, ts, N)
    fixed = lpv_turbine(model, ts, N, wind_speeds=[15.0])
    op = model.trim(20.0)
    x, beta, v = np.array(op.x, float), op.pitch + 0.01, 20.5
    truth = []
    for _ in range(N):
        for _ in range(10):
            h = 0.02
            k1 = model.derivatives(x, v, beta, op.gen_torque)
            k2 = model.derivatives(x + h / 2 * k1, v, beta, op.gen_torque)
            k3 = model.derivatives(x + h / 2 * k2, v, beta, op.gen_torque)
            k4 = model.derivatives(x + h * k3, v, beta, op.gen_torque)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        truth.append(x[0])
    x0, u = np.array(op.x, float), np.full(N, beta)
    err_lpv = np.abs(lpv.predict(x0, v, u)[:, 0] - truth).max()
    err_fixed = np.abs(fixed.predict(x0, v, u)[:, 0] - truth).max()
    # (0.2 mrad/s against 55 mrad/s when written)
    assert err_lpv < 0.05 * err_fixed


# ----------------------------------------------------------------------------- the QP by hand
def _two_state():
    """A 2-state model (speed-like x₁, pitch-like x₂) with the three predicted outputs."""
    A = np.array([[0.95, -0.2], [0.0, 0.6]])
    Bu, Bw = np.array([0.0, 0.4]), np.array([0.05, 0.0])
    C = np.array([[1.0, 0.0], [2.0, -3.0], [0.0, 0.1]])  # gen_speed, blade_root_my, tower_top_vel
    Dw = np.array([0.0, 0.5, 0.0])
    dm = DiscreteTurbine(10.0, 0.1, A, Bu, Bw, C, Dw, PREDICTED, 0.0, 0.0, np.zeros(3))
    N = 2
    Phi, Gam, Psi = prediction_matrices(dm, PREDICTED, N)
    lpv = LPVTurbine(np.array([10.0]), 0.1, N, PREDICTED, np.zeros((1, 2)), np.zeros(1), np.zeros((1, 3)),
                     Phi[None], Gam[None], Psi[None], C[None], Dw[None])
    return A, Bu, Bw, C, Dw, lpv


def _hand_cost(u, x0, d, uprev, wts, rated, step, mbar, mscale, A, Bu, Bw, C, Dw):
    """The cost of the module docstring, the model simulated step by step."""
    qo, qt, qd, psi, pacc = wts
    x, J, up, msum = x0.copy(), 0.0, uprev, 0.0
    for uj in u:
        x = A @ x + Bu * uj + Bw * d
        y = C @ x + Dw * d
        J += qo * ((y[0] - rated) / rated) ** 2 + qt * y[2] ** 2 + qd * ((uj - up) / step) ** 2
        J += psi * ((y[1] - mbar) / mscale) ** 2
        msum += y[1]
        up = uj
    return J + pacc * msum / (len(u) * mscale)


def _quadratic(f, n):
    """Exact Hessian and gradient at 0 of a quadratic f by second differences (unit steps)."""
    f0, E = f(np.zeros(n)), np.eye(n)
    H = np.array([[f(E[i] + E[j]) - f(E[i]) - f(E[j]) + f0 for j in range(n)] for i in range(n)])
    g = np.array([(f(E[i]) - f(-E[i])) / 2 for i in range(n)])
    return H, g


@pytest.mark.parametrize("wts", [(100.0, 50.0, 0.1, 0.0, 0.0), (100.0, 0.0, 0.1, 30.0, 5.0)])
def test_health_qp_first_move_against_hand_solution(wts):
    A, Bu, Bw, C, Dw, lpv = _two_state()
    x0, d, rated, step, mbar, mscale = np.array([0.3, -0.1]), 0.4, 1.0, 20.0, 0.2, 2.0
    kw = dict(weights=wts, rated_speed=rated, step=step, pitch_limits=(-1e3, 1e3), moment_scale=mscale)
    args = (x0, d, 0.0, wts, rated, step, mbar, mscale, A, Bu, Bw, C, Dw)
    # unconstrained: H u* = −g of the exact quadratic (the commands are absolute, trim at 0)
    H, g = _quadratic(lambda u: _hand_cost(u, *args), 2)
    u_hand = np.linalg.solve(H, -g)
    assert np.all(np.abs(np.diff(np.concatenate([[0.0], u_hand]))) < step)  # the rate limit is inactive
    u = health_move(lpv, x0, 10.0 + d, 0.0, 0.0, mbar, **kw)
    assert_allclose(u, u_hand, rtol=1e-8, atol=1e-10)
    # the previous command far from the optimum: the first move is pinned at the rate limit,
    # u₀ = u₋₁ + step, and u₁ minimises the 1-D quadratic in u₁ at that u₀ (KKT by hand)
    uprev = u_hand[0] - 3 * step
    args = (x0, d, uprev, wts, rated, step, mbar, mscale, A, Bu, Bw, C, Dw)
    H, g = _quadratic(lambda u: _hand_cost(u, *args), 2)
    u0 = uprev + step
    u1 = np.clip(-(g[1] + H[1, 0] * u0) / H[1, 1], u0 - step, u0 + step)
    grad0 = H[0] @ np.array([u0, u1]) + g[0]
    assert grad0 < 0  # the cost still falls along u₀: the bound is active with a positive multiplier
    u = health_move(lpv, x0, 10.0 + d, 0.0, uprev, mbar, **kw)
    assert_allclose(u, [u0, u1], atol=1e-6)


def test_health_scale_by_hand():
    # damage (DEL/budget)^m per second: 1.5^10 for 200 s with a 50 s prior at the budget
    d = 1.5**10 * 200.0
    assert_allclose(health_scale(d, 200.0, 10.0, 50.0), ((d + 50.0) / 250.0) ** 0.1, rtol=1e-14)
    assert_allclose(health_scale(0.0, 0.0, 10.0, 50.0), 1.0)


# ----------------------------------------------------------------------------- the controller
def test_health_mpc_trades_speed_for_blade_damage(model):
    # the documented behaviour (docs/health_mpc.md): the health weight lowers the blade-root
    # DEL and raises the generator-speed SD; the mean power falls by less than 3 %
    res = {}
    for w in (0.0, 100.0):
        r = simulate(model, HealthMPC(model, health_weight=w), [19.0], seeds=[1], duration=200.0, transient=30.0)
        res[w] = (del_rainflow(r["blade_root_my"][0, 0], 10.0, 200.0), r["gen_speed"].std(), r["power"].mean())
    assert res[100.0][0] < 0.7 * res[0.0][0]
    assert res[100.0][1] > 1.5 * res[0.0][1]
    assert abs(res[0.0][2] / model.rated_power - 1) < 0.002
    assert 0.97 < res[100.0][2] / res[0.0][2] < 1.0


def test_health_mpc_pickles_and_runs_in_campaign(model):
    from specdesign.validate import run_campaign

    mpc = HealthMPC(model, health_weight=10.0, wind_speeds=[17.0, 19.0, 21.0], del_budget=4e6)
    a = simulate(model, mpc, [19.0], seeds=[2], duration=20.0, transient=5.0)
    assert mpc.blade_damage.shape == (1,) and mpc.blade_damage[0] > 0
    twin = pickle.loads(pickle.dumps(mpc))
    b = simulate(model, twin, [19.0], seeds=[2], duration=20.0, transient=5.0)
    assert np.array_equal(a["pitch_cmd"], b["pitch_cmd"])
    camp = run_campaign({"health": twin}, [19.0], [2], duration=20.0, transient=5.0, predict=False)
    # the pickled controller ran in the campaign: one run, its indicators finite and the DEL positive
    assert camp.controllers == ("health",) and camp.values["tower_del"].shape == (1, 1, 1)
    assert all(np.all(np.isfinite(camp.values[k])) for k in ("tower_del", "gen_speed_sd", "mean_power", "pitch_sd"))
    assert camp.values["tower_del"][0, 0, 0] > 0


def test_health_mpc_errors(model):
    with pytest.raises(ValueError, match="activity_weight"):
        HealthMPC(model, activity_weight=0.0)
    with pytest.raises(ValueError, match="health_weight"):
        HealthMPC(model, health_weight=-1.0)
    with pytest.raises(RuntimeError, match="start"):
        HealthMPC(model)(0.0, {})


def test_health_weight_follows_the_damage_budget(model):
    # with a blade DEL budget far below what the blade accumulates (≈ 5 MN·m at 19 m/s), the
    # health factor DEL(k)/budget (health_scale, from the online D(k)) grows above 1, the
    # weight with it, and the blade DEL falls below that of the same weight without a budget
    dels, factors = {}, {}
    for budget in (None, 1e6):
        mpc = HealthMPC(model, health_weight=3.0, del_budget=budget, budget_prior=10.0)
        r = simulate(model, mpc, [19.0], seeds=[1], duration=120.0, transient=20.0)
        dels[budget] = del_rainflow(r["blade_root_my"][0, 0], 10.0, 120.0)
        if budget is not None:
            factors[budget] = health_scale(mpc.blade_damage[0], 140.0, 10.0, 10.0)
    assert factors[1e6] > 2.0
    assert dels[1e6] < 0.9 * dels[None]


def test_names_and_the_papers_health_aware_term_derates(model):
    # the default label names the workbench's excursion penalty; Boutrous et al.'s controller
    # is health_aware_mpc: the accumulated-moment term alone, which derates (their Table 2:
    # power falls as the weight grows); the reference is the same MPC without the term
    assert HealthMPC(model).name == "excursion MPC"
    ha = health_aware_mpc(model)
    assert ha.name == "health-aware MPC" and ha.weights[3:] == (0.0, 30.0)
    kw = dict(seeds=[1], duration=60.0, transient=40.0)
    p0 = simulate(model, HealthMPC(model), [13.0], **kw)["power"].mean()
    p1 = simulate(model, ha, [13.0], **kw)["power"].mean()
    assert p1 < 0.99 * p0
    with pytest.raises(ValueError, match="health_weight"):
        health_aware_mpc(model, health_weight=1.0)
    with pytest.raises(ValueError, match="stress_weight"):
        health_aware_mpc(model, stress_weight=0.0)
