"""The Volterra prediction: the aerodynamic Taylor expansion against the compiled loads, the
load inputs of the linearisation, the series against the linear and the nonlinear
simulation on the same wind (orders of convergence), and its place in a campaign."""
import control
import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign import simulate as sm
from specdesign import turbine
from specdesign import validate as va
from specdesign.fatigue import del_rainflow

V = 19.0
ATD = control.tf([-0.014187, -0.014187 * 4.357], [1, 0.3276])  # the paper's C_ATD, β = −C_atd·ẋ


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


@pytest.fixture(scope="module")
def expansion(model):
    return model.aero_expansion(V)


def test_aero_expansion_gradient_is_the_linearisation(model, expansion):
    """∂(Q, T)/∂(Ω, v, β) from the expansion equal the plant Jacobian times inertia / modal mass."""
    A, B, _, _ = model.jacobians(model.trim(V))
    J, M = model.drivetrain_inertia, model.tower_modal_mass
    lin = np.array([[A[0, 0] * J, B[0, 0] * J, A[0, 3] * J], [A[2, 0] * M, B[2, 0] * M, A[2, 3] * M]])
    assert_allclose(expansion.gradient, lin, rtol=1e-5)
    assert_allclose(expansion.hessian, np.swapaxes(expansion.hessian, 1, 2), rtol=1e-9)  # symmetric
    half = model.aero_expansion(V, steps=np.array(expansion.steps) / 2)  # step-independent
    assert_allclose(half.hessian, expansion.hessian, rtol=1e-4, atol=1e-5 * np.abs(expansion.hessian).max())
    assert_allclose(half.third, expansion.third, atol=1e-3 * np.abs(expansion.third).max())


def test_aero_expansion_converges_with_its_order(model, expansion):
    """Taylor polynomial of order k vs the compiled loads at offsets δ·u (u: class-B-sized
    excursions): the relative error falls as δ^k, and each order improves on the last."""
    p = model.kernel_params()
    u = np.random.default_rng(0).standard_normal((3, 100)) * np.array([0.05, 1.5, 0.03])[:, None]

    def errors(d):
        dz = d * u
        exact = np.array([turbine.aero_loads(p, *(expansion.point + dz[:, k])) for k in range(u.shape[1])]).T
        exact = exact - expansion.loads[:, None]
        return np.array([np.max(np.abs(exact - expansion.evaluate(dz, k))) / np.max(np.abs(exact)) for k in (1, 2, 3)])

    e1, e2 = errors(0.25), errors(0.125)
    assert np.all(np.diff(e1) < 0) and np.all(np.diff(e2) < 0)
    assert e1[0] / e2[0] > 1.7 and e1[1] / e2[1] > 3.2 and e1[2] / e2[2] > 6.4  # ≥ 0.8·2^k
    with pytest.raises(ValueError, match="order"):
        expansion.evaluate(u, 4)
    with pytest.raises(ValueError, match=r"shape \(3, \.\.\.\)"):
        expansion.evaluate(u[:2])
    with pytest.raises(ValueError, match="steps"):
        model.aero_expansion(V, steps=(1e-3, 0.0, 1e-3))


def test_load_inputs_of_the_linearisation(model):
    base, sys = model.linearize(V), model.linearize(V, load_inputs=True)
    assert list(sys.input_labels) == list(base.input_labels) + ["aero_torque", "thrust"]
    assert_allclose(sys.B[:, :3], base.B, rtol=0, atol=0)
    assert_allclose(sys.D[:, :3], base.D, rtol=0, atol=0)
    b = np.zeros((5, 2))
    b[0, 0], b[2, 1] = 1 / model.drivetrain_inertia, 1 / model.tower_modal_mass
    assert_allclose(sys.B[:, 3:], b, rtol=1e-6, atol=1e-15)
    d = np.zeros((len(turbine.OUTPUT_NAMES), 2))
    d[turbine.OUTPUT_NAMES.index("tower_top_acc"), 1] = 1 / model.tower_modal_mass
    # blade_root_my = r_T(β)·T/3: an added thrust moves it by r_T(β₀)·R/3 (specdesign.turbine.kernel)
    from specdesign.turbine.kernel import thrust_centre
    d[turbine.OUTPUT_NAMES.index("blade_root_my"), 1] = thrust_centre(model.trim(V).pitch) * model.rotor_radius / 3
    assert_allclose(sys.D[:, 3:], d, rtol=1e-6, atol=1e-15)


@pytest.fixture(scope="module")
def runs(model):
    """ROSCO at 19 m/s on 4 periodic wind records scaled to 1 and 0.5 × class B: the nonlinear
    and linear simulations and the Volterra terms over the same record window."""
    rosco = turbine.rosco_baseline(model, V)
    wind = sm.wind_series(model.rotor_radius, [V], [1, 2, 3, 4], 660.1, 0.1)
    op = model.trim(V)
    my0 = model.evaluate_outputs(op.x, V, op.pitch, op.gen_torque)[turbine.OUTPUT_NAMES.index("tower_base_my")]
    out = {}
    for a in (1.0, 0.5):
        w = V + a * (wind - V)
        nl = sm.simulate(model, rosco, [V], wind=w, wind_dt=0.1)["tower_base_my"][0]
        li = sm.simulate(model, rosco, [V], wind=w, wind_dt=0.1, linear=True)["tower_base_my"][0]
        terms = va.volterra_response(model, rosco, V, w[0], 0.1, order=3)["tower_base_my"][:, :, 600:600 + nl.shape[1]]
        out[a] = dict(nl=nl, lin=li, partial=my0 + np.cumsum(terms, axis=0), terms=terms)
    return out


def _rms(x):
    return float(np.sqrt(np.mean(x**2)))


def test_volterra_first_order_is_the_linear_simulation(runs):
    """Order 1 = the linear closed loop: equal to simulate(linear=True) on the same wind up to
    the simulator's discrete loop (Tustin, RK4 at 0.02 s, linear wind interpolation)."""
    r = runs[1.0]
    assert _rms(r["lin"] - r["partial"][0]) < 5e-3 * np.std(r["lin"])


def test_volterra_series_converges_to_the_nonlinear_simulation(runs):
    """Each order brings the series closer to the nonlinear simulation; halving the
    turbulence shrinks the residual after order k by about 2^k relative to the signal
    (the residual of the linear response is the quadratic aerodynamics, ∝ TI²)."""
    err = {a: np.array([_rms(r["nl"] - r["partial"][k]) for k in range(3)]) / np.std(r["nl"]) for a, r in runs.items()}
    for a in runs:
        assert np.all(np.diff(err[a]) < 0), err[a]
    assert err[1.0][2] < 0.2 * err[1.0][0] and err[0.5][2] < 0.05 * err[0.5][0]
    assert 0.4 < err[0.5][0] / err[1.0][0] < 0.6   # ∝ a
    assert err[0.5][1] / err[1.0][1] < 0.35         # ∝ a²
    # the DEL: the series to order 3 is closer to the nonlinear DEL than the linear model is
    pooled = lambda y: np.mean([del_rainflow(s, 4.0, 600.0) ** 4 for s in y]) ** 0.25
    r = runs[1.0]
    d_nl = pooled(r["nl"])
    assert abs(pooled(r["partial"][2]) / d_nl - 1) < abs(pooled(r["lin"]) / d_nl - 1)


def test_volterra_terms_are_homogeneous(runs):
    """Term k is of degree k in the turbulence: scaling the wind by ½ scales it by 2^−k."""
    t1, t05 = runs[1.0]["terms"], runs[0.5]["terms"]
    for k in range(3):
        assert_allclose(t05[k], t1[k] / 2 ** (k + 1), rtol=1e-9, atol=1e-9 * np.abs(t1[k]).max())


def test_volterra_rejects_bad_input(model):
    rosco = turbine.rosco_baseline(model, V)
    w = np.full((1, 100), V)
    with pytest.raises(ValueError, match="order"):
        va.volterra_response(model, rosco, V, w, 0.1, order=4)
    with pytest.raises(ValueError, match="outputs"):
        va.volterra_response(model, rosco, V, w, 0.1, outputs=("tower_top_moment",))
    with pytest.raises(ValueError, match="wind"):
        va.volterra_response(model, rosco, V, np.full(8, V), 0.1)
    with pytest.raises(TypeError, match="TurbineModel"):
        va.volterra_response(sm.turbine_plant(model), rosco, V, w, 0.1)
    with pytest.raises(TypeError, match="linear"):
        va.volterra_response(model, lambda t, y: 0.0, V, w, 0.1)


def test_campaign_with_a_volterra_prediction(model):
    """run_campaign(volterra=3): per-run indicators equal the Volterra series over the
    simulation's window by hand; acceptance() compares rainflow with it (SE by hand
    leave-one-out), table3 shows it, passes() reads it; callables get NaN."""
    seeds, kw = [1, 2, 3, 4, 5], dict(duration=200.0, transient=30.0, progress=False)
    rosco = turbine.rosco_baseline(model, V)
    atd = sm.ScheduledController(np.zeros(1), (rosco,), (ATD,), name="ATD")
    camp = va.run_campaign({"ROSCO": rosco, "ATD": atd}, [V], seeds, model=model, volterra=3, **kw)
    assert camp.volterra_order == 3 and camp.linear_values == {}
    wind = sm.wind_series(model.rotor_radius, [V], seeds, 230.1, 0.1)[0]
    op = model.trim(V)
    y0 = dict(zip(turbine.OUTPUT_NAMES, model.evaluate_outputs(op.x, V, op.pitch, op.gen_torque)))
    for c, ctrl in enumerate((rosco, atd)):
        my = y0["tower_base_my"] + va.volterra_response(model, ctrl, V, wind, 0.1)["tower_base_my"].sum(0)[:, 300:2300]
        assert_allclose(camp.volterra_values["tower_del"][c, 0], [del_rainflow(s, 4.0, 200.0) for s in my], rtol=1e-10)
    assert np.all(camp.volterra_values["mean_power"] > 0.9 * y0["power"])

    acc = va.acceptance(camp, "ATD", "ROSCO")
    vc = va.paired_change(camp.volterra_values["tower_del"][1], camp.volterra_values["tower_del"][0], m=4.0)
    assert_allclose(acc.volterra, -vc.change)
    assert acc.volterra_order == 3
    assert_allclose(acc.volterra_deviation, acc.rainflow - acc.volterra, atol=1e-12)

    def reduction(vals, keep):
        d = [np.mean(vals[c, 0, keep] ** 4) ** 0.25 for c in (1, 0)]
        return 100 * (1 - d[0] / d[1])

    nl, vo = camp.values["tower_del"], camp.volterra_values["tower_del"]
    reps = np.array([reduction(nl, np.delete(np.arange(5), i)) - reduction(vo, np.delete(np.arange(5), i)) for i in range(5)])
    assert acc.se_volterra[0] == pytest.approx(np.sqrt(4 / 5 * np.sum((reps - reps.mean()) ** 2)), rel=1e-10)
    assert acc.se_volterra[0] < acc.se[0]  # both evaluations saw the same wind
    assert acc.passes(10.0, against="volterra").all()
    assert not acc.passes(abs(acc.volterra_deviation[0]) / 2, against="volterra").any()
    with pytest.raises(ValueError, match="against"):
        acc.passes(1.0, against="dirlik")
    import matplotlib.pyplot as plt

    from specdesign.plots import validation as pv

    labels = pv.plot_reductions(acc).get_legend_handles_labels()[1]
    assert any("Volterra prediction, order 3" in lab for lab in labels)
    plt.close("all")
    md = va.table3(camp, "ATD", "ROSCO").to_markdown()
    assert "| Volterra prediction (order 3, rainflow, same seeds) |" in md
    assert "| Deviation from the Volterra prediction |" in md

    plain = va.run_campaign({"ROSCO": rosco, "ATD": atd}, [V], seeds[:2], model=model, **kw)
    with pytest.raises(ValueError, match="volterra"):
        va.acceptance(plain, "ATD", "ROSCO").passes(1.0, against="volterra")
    assert "Volterra" not in va.table3(plain, "ATD", "ROSCO").to_markdown()

    pitch0 = op.pitch
    hold = lambda t, y: np.full(np.shape(y["gen_speed"]), pitch0)  # noqa: E731 - a callable: no linear form
    camp2 = va.run_campaign({"ROSCO": rosco, "hold": hold}, [V], [1, 2], model=model, volterra=1, predict=False,
                            progress=False, duration=20.0, transient=5.0)
    assert np.all(np.isfinite(camp2.volterra_values["tower_del"][0])) and np.all(np.isnan(camp2.volterra_values["tower_del"][1]))
    for bad in (4, True, 1.5):
        with pytest.raises(ValueError, match="volterra"):
            va.run_campaign({"ROSCO": rosco}, [V], [1], model=model, volterra=bad, **kw)
    with pytest.raises(TypeError, match="TurbineModel"):
        va.run_campaign({"ROSCO": rosco}, [V], [1], model=sm.turbine_plant(model), volterra=3, **kw)


def test_concat_campaigns_keeps_the_volterra_prediction(model):
    ctrls = {"PI": turbine.rosco_baseline(model, V)}
    kw = dict(model=model, duration=40.0, transient=5.0, progress=False, volterra=2)
    both = va.run_campaign(ctrls, [17.0, 19.0], [1, 2], **kw)
    cat = va.concat_campaigns([va.run_campaign(ctrls, [v], [1, 2], **kw) for v in (17.0, 19.0)])
    for k in both.volterra_values:
        assert_allclose(cat.volterra_values[k], both.volterra_values[k], rtol=1e-12)
    other = va.run_campaign(ctrls, [21.0], [1, 2], **dict(kw, volterra=3))
    with pytest.raises(ValueError, match="Volterra order"):
        va.concat_campaigns([cat, other])


def test_volterra_prediction_before_any_simulation(model):
    """The design-time prediction: its DELs are the Volterra series over wind_series records by
    hand; at order 1 it is the linear prediction (Dirlik) up to sampling and Dirlik's bias;
    at order 3 ROSCO's DEL grows by the few % that the nonlinear simulation shows
    (docs/nonlinearity.md: 1.05 at 19 m/s, class B)."""
    rosco = turbine.rosco_baseline(model, V)
    seeds = range(2000, 2040)
    p1 = va.volterra_prediction(model, rosco, V, seeds=seeds, order=1, chunk=16)
    p3 = va.volterra_prediction(model, rosco, V, seeds=seeds, order=3)
    wind = sm.wind_series(model.rotor_radius, [V], [2005], 600.0, 0.1)[0]
    y = va.volterra_response(model, rosco, V, wind, 0.1)["tower_base_my"].sum(0)[0]
    assert p3.dels[5] == pytest.approx(del_rainflow(y, 4.0, 600.0), rel=1e-12)
    assert p3.del_ == pytest.approx(np.mean(p3.dels**4) ** 0.25, rel=1e-12) and p3.dels.shape == (40,)
    lin = va.linear_prediction(model, rosco, V)
    assert p1.del_ == pytest.approx(lin.del_, rel=0.05) and p1.sd == pytest.approx(lin.sd, rel=0.08)
    assert 1.02 < p3.del_ / p1.del_ < 1.10
    with pytest.raises(ValueError, match="seeds"):
        va.volterra_prediction(model, rosco, V, seeds=[1, 1])
