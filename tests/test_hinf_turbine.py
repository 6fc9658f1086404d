"""specdesign.hinf: H∞ with the fatigue specifications as weights on the IEA 15 MW model.

Acceptance of issue 6 at 19 m/s: ≤ 8 states after reduction, generator-speed spec met
within 1 dB, tower-load spec met at the tower mode, predicted tower-base DEL reduction at
least the specification's promise, on a grid that cannot miss narrow peaks
(:func:`specdesign.closedloop.refine_grid`). Every number is recomputed here by the explicit
closed-loop formula of specdesign.closedloop (not the interconnection design_hinf uses).
The design on QFT's specifications (``spec=spec_like_qft(model, V)``, pitch + ATD, 1×2; the default before the
certified pair of tests/test_hinf_target.py) meets it, the tower spec at the
mode against both QFT's relaxed spec and the unrelaxed notch spec whose 3.98 % DEL promise
is quoted; the pitch-only design does not (strict xfail, docs/hinf.md).
"""
import control as ct
import numpy as np
import pytest

from loopshaping import hinf as lh
from specdesign import closedloop, hinf, spec, spectral, turbine

V = 19.0


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


@pytest.fixture(scope="module")
def plant(model):
    return model.linearize(V)


@pytest.fixture(scope="module")
def specs(model):
    base = spec.baseline_analysis(model, V)
    shaped = spec.shape_to_target(base, 15.0)
    return base, shaped.specification, spec.speed_specification(model, V)


@pytest.fixture(scope="module", params=[("gen_speed",), ("gen_speed", "tower_top_vel")],
                ids=["pitch", "pitch+ATD"])
def design(request, model):
    return hinf.design_hinf(model, V, spec=hinf.spec_like_qft(model, V), measurements=request.param, order=8)


def _resp(sys, w):
    return np.asarray(ct.frequency_response(sys, w).complex).reshape(sys.noutputs, sys.ninputs, -1)


def test_inverse_weight_inverts_the_magnitude():
    s = ct.tf("s")
    # A stable spec with a right-half-plane zero, a zero at s = 0 and relative degree 2.
    W = 3.0 * s * (s - 0.5) * (s**2 + 0.2 * s + 1.2) / ((s + 0.3) * (s**2 + 0.1 * s + 1.0) * (s + 2) ** 2 * (s + 4))
    inv, notes = hinf.inverse_weight(W, rolloff=100.0, shift=1e-4)
    w = np.logspace(-2, 0.5, 400)  # well above the shift, well below the roll-off
    prod = np.abs(_resp(inv, w)[0, 0] * _resp(ct.ss(W), w)[0, 0])
    np.testing.assert_allclose(prod, 1.0, rtol=2e-3)
    assert np.all(inv.poles().real < 0)  # a weight must be stable
    assert np.all(np.isfinite(inv.D)) and inv.D[0, 0] != 0  # biproper
    assert len(notes) == 3 and any("reflected" in n for n in notes)
    with pytest.raises(ValueError, match="poles with Re"):
        hinf.inverse_weight(1 / (s - 1))
    with pytest.raises(ValueError, match="improper"):
        hinf.inverse_weight(s + 1)
    with pytest.raises(ValueError, match="rolloff"):
        hinf.inverse_weight(W, rolloff=0.0)
    with pytest.raises(TypeError, match="specification"):
        hinf.inverse_weight("W")


def test_inverse_weight_min_damping_caps_a_narrow_dip():
    s = ct.tf("s")
    W = (s**2 + 0.02 * s + 1.0) / ((s + 0.5) * (s + 2))  # a ζ = 0.01 dip at 1 rad/s
    exact, _ = hinf.inverse_weight(W, rolloff=100.0)
    capped, notes = hinf.inverse_weight(W, rolloff=100.0, min_damping=0.05)
    assert any("damping 0.05" in n for n in notes)
    p = capped.poles()
    osc = p[np.abs(p.imag) > 1e-9]
    np.testing.assert_allclose(-osc.real / np.abs(osc), 0.05, rtol=1e-9)
    np.testing.assert_allclose(np.abs(osc), 1.0, rtol=1e-9)
    # The peak at the dip drops from 1/(2·0.01) to 1/(2·0.05) of the weight's level; away
    # from the dip (a factor 3) the two weights agree to a few %.
    r = lambda sys, w: np.abs(_resp(sys, np.array([w, 2 * w]))[0, 0, 0])  # noqa: E731
    assert r(exact, 1.0) / r(capped, 1.0) == pytest.approx(5.0, rel=1e-3)
    assert r(exact, 3.0) / r(capped, 3.0) == pytest.approx(1.0, rel=0.05)
    with pytest.raises(ValueError, match="min_damping"):
        hinf.inverse_weight(W, min_damping=1.5)


def test_generalized_plant_integral_corner(plant, specs):
    _, w_tower, w_speed = specs
    gp = hinf.generalized_plant(plant, w_tower, w_speed, integral_corner=0.1)
    assert gp.system.input_labels[-1] == "pitch_u" and gp.n_plant_states == plant.nstates + 1
    w = np.logspace(-2, 0.5, 50)
    F = _resp(gp.input_filter, w)[0, 0]
    np.testing.assert_allclose(F, (1 + 1j * w / 0.1) / (1j * w), rtol=1e-9)
    G = _resp(gp.system, w)
    Pj = _resp(plant, w)
    np.testing.assert_allclose(G[3, 2], Pj[plant.output_labels.index("gen_speed"),
                                            plant.input_labels.index("pitch_cmd")] * F, rtol=1e-8)
    A = np.asarray(gp.system.A)
    assert not np.any(A[:gp.n_plant_states, gp.n_plant_states:])  # weights in series only
    lh.check_well_posed(gp.system, gp.n_meas, gp.n_ctrl)


def test_generalized_plant_channels_match_the_plant(plant, specs):
    _, w_tower, w_speed = specs
    gp = hinf.generalized_plant(plant, w_tower, w_speed, measurements=("gen_speed", "tower_top_vel"))
    G = gp.system
    assert G.input_labels == ["wind", "noise_gen_speed", "noise_tower_top_vel", "pitch_cmd"]
    assert G.output_labels == ["z_tower", "z_speed", "z_pitch", "y_gen_speed", "y_tower_top_vel"]
    w = np.logspace(-2, 0.5, 200)
    Gj = _resp(G, w)
    Pj = _resp(plant, w)
    io = lambda o, i: Pj[plant.output_labels.index(o), plant.input_labels.index(i)]  # noqa: E731
    wt = _resp(ct.ss(w_tower.tf()), w)[0, 0]
    ws = _resp(ct.ss(w_speed.tf()), w)[0, 0]
    # Performance outputs are the plant outputs divided by their specifications, rolled off
    # above 10 rad/s by the relative degree r of the specification (and a 1e-3 rad/s shift
    # of the speed spec's zero at s = 0, < 1 % above 0.01 rad/s).
    def rolloff(W):
        tf = W.tf()
        r = len(np.trim_zeros(tf.den[0][0], "f")) - len(np.trim_zeros(tf.num[0][0], "f"))
        return np.abs(10 / (1j * w + 10)) ** r

    np.testing.assert_allclose(np.abs(Gj[0, 0]),
                               np.abs(io("tower_base_my", "wind") / wt) * rolloff(w_tower), rtol=1e-6)
    np.testing.assert_allclose(np.abs(Gj[1, 3]),
                               np.abs(io("gen_speed", "pitch_cmd") / ws) * rolloff(w_speed), rtol=1e-2)
    np.testing.assert_allclose(Gj[3, 0], io("gen_speed", "wind"), rtol=1e-9)
    np.testing.assert_allclose(Gj[4, 3], io("tower_top_vel", "pitch_cmd"), rtol=1e-9)
    assert np.all(Gj[3, 2] == 0) and np.all(Gj[4, 1] == 0)  # each noise on its own sensor
    lh.check_well_posed(G, gp.n_meas, gp.n_ctrl)  # well posed by construction


def test_generalized_plant_rejects_bad_input(plant, specs):
    _, w_tower, w_speed = specs
    with pytest.raises(ValueError, match="lacks the named signals"):
        hinf.generalized_plant(plant, w_tower, w_speed, measurements=("rotor_thrust",))
    with pytest.raises(ValueError, match="noise"):
        hinf.generalized_plant(plant, w_tower, w_speed, noise={"gen_speed": 0.0})
    with pytest.raises(ValueError, match="noise_band"):
        hinf.generalized_plant(plant, w_tower, w_speed, noise_band=(1.0, 0.1))
    with pytest.raises(TypeError, match="plant"):
        hinf.generalized_plant(ct.tf(plant[0, 1]), w_tower, w_speed)


def _explicit(d, plant, omega):
    """T_MyT,w and T_Ω,w of the reduced design by the explicit formula (C = −K)."""
    n = d.controller.ninputs
    C = [-_resp(d.controller, omega)[0, i] for i in range(n)]
    kw = dict(atd_controller=C[1], atd_measurement="tower_top_vel") if n == 2 else {}
    return (closedloop.t_output_wind(plant, C[0], omega, "tower_base_my", **kw),
            closedloop.t_output_wind(plant, C[0], omega, "gen_speed", **kw))


def test_assessment_grid_catches_a_narrow_resonance():
    omega = spec.default_omega()
    # A ζ = 1e-3 resonance half-way (geometrically) between two points of the 400-point grid.
    k = int(np.searchsorted(omega, 1.08))
    w0, zeta = float(np.sqrt(omega[k - 1] * omega[k])), 1e-3
    G = ct.tf([w0**2], [1, 2 * zeta * w0, w0**2])
    peak = 1 / (2 * zeta * np.sqrt(1 - zeta**2))
    coarse = np.abs(_resp(G, omega)[0, 0]).max()
    assert coarse < 0.5 * peak  # the base grid steps over it
    fine = closedloop.refine_grid(omega, [G])
    assert fine.size < omega.size + 3000 and np.all(np.isin(omega, fine))
    assert np.abs(_resp(G, fine)[0, 0]).max() == pytest.approx(peak, rel=1e-3)
    # Poles given as numbers work the same; well-damped and out-of-band roots add nothing.
    assert np.array_equal(closedloop.refine_grid(omega, G.poles()), fine)
    assert np.array_equal(closedloop.refine_grid(omega, [-1.0, -0.5 + 0.5j, -1 + 50j]), omega)
    with pytest.raises(ValueError, match="omega"):
        closedloop.refine_grid(omega[::-1])


def test_design_grid_misses_no_peak(design, plant):
    # design_hinf's numbers equal a brute-force grid with 1e-4 rad/s steps around the tower
    # mode (where the lightly damped poles and zeros are) to 0.01 dB.
    d = design
    brute = np.unique(np.r_[spec.default_omega(), np.linspace(0.8, 1.4, 6001)])
    _, t_om = _explicit(d, plant, brute)
    brute_excess = np.max(20 * np.log10(np.abs(t_om) / d.w_speed.magnitude(brute)))
    assert d.speed_excess_db >= brute_excess - 0.01
    assert np.isin(spec.default_omega(), d.omega).all()


def test_stability_damping_states_and_del(design, model, plant, specs):
    base, w_tower, _ = specs
    d = design
    assert d.controller.nstates <= 8
    n = d.controller.ninputs
    meas = ("gen_speed",) if n == 1 else ("gen_speed", "tower_top_vel")
    # Every pole of the reduced loop (by interconnection) is stable and damped; the α-shift
    # bounds the full-order loop's poles by −α.
    p = closedloop.closed_loop_mimo(plant, d.controller, meas).poles()
    assert p.real.max() == pytest.approx(d.max_pole_real) and d.max_pole_real < -0.02
    osc = p[np.abs(p.imag) > 1e-6]
    assert np.min(-osc.real / np.abs(osc)) == pytest.approx(d.zeta_min) and d.zeta_min >= 0.05
    assert closedloop.closed_loop_mimo(plant, d.full_controller, meas).poles().real.max() < -d.decay_rate
    assert d.decay_rate == hinf.DEFAULT_DECAY_RATE > 0
    assert d.peak_sensitivity < 1.3
    np.testing.assert_allclose(_resp(d.pitch_controller, d.omega)[0, 0],
                               -_resp(d.controller, d.omega)[0, 0], rtol=1e-6)
    # Predicted DEL reduction ≥ the specification's promise, on the design's (refined) grid.
    t_my, _ = _explicit(d, plant, d.omega)
    t0 = closedloop.frequency_response(closedloop.closed_loop(plant, turbine.rosco_baseline(model, V), warn=False),
                                       d.omega, "tower_base_my")
    s_w = hinf_wind(model, d.omega)
    del0 = spectral.del_spectral(d.omega, np.abs(t0) ** 2 * s_w, 4.0)
    del1 = spectral.del_spectral(d.omega, np.abs(t_my) ** 2 * s_w, 4.0)
    reduction = 100 * (1 - del1 / del0)
    promise = spec.promise_of(w_tower, base).exact_del  # the 15 %-damage notch spec: 3.98 % DEL
    assert d.predicted_del_reduction == pytest.approx(reduction, abs=1e-6)
    assert d.notch_promised_del_reduction == pytest.approx(promise, abs=1e-6)
    # the relaxed spec the design was given promises less (an increase, −2.7 %)
    assert d.promised_del_reduction == pytest.approx(spec.promise_of(d.w_tower, base).exact_del, abs=1e-6)
    assert reduction >= promise > 3.9 and d.promised_del_reduction < 0


def hinf_wind(model, omega):
    from specdesign import wind

    # variance about each 600 s record's mean (wind.record_window), written out: 1 − sinc²(ωT/2)
    w = np.asarray(omega, float)
    return wind.rotor_effective_spectrum(omega, V, model.rotor_radius) * (1 - (np.sin(300.0 * w) / (300.0 * w)) ** 2)


def test_spec_numbers_on_the_refined_grid(design, model, plant, specs):
    _, w_notch, w_rosco = specs
    d = design
    assert d.specs == "qft"
    _, t_om = _explicit(d, plant, d.omega)
    excess = 20 * np.log10(np.abs(t_om) / d.w_speed.magnitude(d.omega))
    assert d.speed_excess_db == pytest.approx(excess.max(), abs=1e-6)
    # the speed spec is ROSCO's T_Ω,w (dip included) raised by the relaxation
    np.testing.assert_allclose(d.w_speed.magnitude(d.omega),
                               w_rosco.magnitude(d.omega) * 10 ** (d.speed_relax_db / 20), rtol=1e-9)
    assert d.speed_excess_baseline_db == pytest.approx(
        np.max(20 * np.log10(np.abs(t_om) / w_rosco.magnitude(d.omega))), abs=1e-6)
    wm = d.tower_mode
    assert 0.9 < wm < 1.2
    wpair = np.array([wm, 2 * wm])
    t_mode, _ = _explicit(d, plant, wpair)
    assert d.tower_excess_db == pytest.approx(
        20 * np.log10(abs(t_mode[0]) / d.w_tower.magnitude(wpair)[0]), abs=1e-6)
    assert d.tower_notch_excess_db == pytest.approx(
        20 * np.log10(abs(t_mode[0]) / w_notch.magnitude(wpair)[0]), abs=1e-6)
    np.testing.assert_allclose(d.notch_spec.magnitude(d.omega), w_notch.magnitude(d.omega), rtol=1e-9)
    # Measured at 19 m/s (docs/hinf.md): what each structure achieves on QFT's specs.
    if d.controller.ninputs == 1:
        assert d.speed_relax_db == 3.0  # the first rung of QFT's ladder already meets both
        assert d.speed_excess_db < -1.5 and -0.2 < d.tower_excess_db < 0 and d.tower_band_excess_db < 0
        assert d.tower_notch_excess_db > 1.5  # but not the unrelaxed notch spec at the mode
    else:
        assert d.speed_relax_db == 4.5  # QFT's ladder picks 4.5 dB at 19 m/s too (docs/qft_turbine.md)
        assert d.speed_excess_db < -1.0 and d.tower_excess_db < -6.0 and d.tower_notch_excess_db < -4.0
        assert d.tower_band_excess_db < -4.0 and d.speed_excess_baseline_db < 3.5
        assert d.predicted_del_reduction > 35.0


def test_acceptance_at_19_mps(design, request):
    d = design
    if d.controller.ninputs == 1:
        request.applymarker(pytest.mark.xfail(strict=True, reason=(
            "pitch-only: P_{Ω,β} has a lightly damped right-half-plane zero pair at 0.0095 ± 1.081j; "
            "the damped loop meets QFT's relaxed tower spec at the mode (−0.08 dB) only because its "
            "relaxation lifts the spec by 1.9 dB there: +1.85 dB over the notch spec (docs/hinf.md)")))
    # issue 6, on the refined grid: ≤ 8 states, damped, robust, speed spec within 1 dB, the
    # tower spec at the mode (the relaxed one given to the design and the notch spec whose
    # promise is quoted), predicted DEL reduction ≥ both promises.
    assert d.controller.nstates <= 8 and d.zeta_min >= 0.05 and d.peak_sensitivity <= 2.0
    assert d.max_pole_real < 0
    assert d.speed_excess_db <= 1.0
    assert d.tower_excess_db <= 0.0 and d.tower_notch_excess_db <= 0.0
    assert d.predicted_del_reduction >= d.notch_promised_del_reduction >= d.promised_del_reduction


def test_qft_specs_are_design_qfts(model):
    # spec_like_qft builds exactly the specs design_qft gives its bounds (a QFT run cut short
    # here: only its specs are used), and spec_from_qft(<QFTDesign>) takes them as they are.
    import warnings

    from specdesign import qft

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        q = qft.design_qft(model, V, spec=qft.spec_notch(speed_relax_db=4.5), maxfev=1, refine=0)
    like = hinf.spec_like_qft(model, V, speed_relax_db=4.5)
    tower, speed, notch = like.tower, like.speed, like.notch
    w = np.logspace(-2, 1, 300)
    for a, b in ((tower, q.tower_spec), (speed, q.speed_spec), (notch, q.shaping.specification)):
        np.testing.assert_allclose(a.response(w), b.response(w), rtol=1e-9)
    d = hinf.design_hinf(model, V, spec=hinf.spec_from_qft(q))
    assert d.specs == "qft_design" and d.speed_relax_db == 4.5
    assert d.w_tower is q.tower_spec and d.w_speed is q.speed_spec
    assert d.notch_promised_del_reduction == pytest.approx(q.shaping.promise.exact_del, abs=1e-6)
    # the first rung (3 dB) leaves the 1×2 design 0.15 dB over the speed spec, inside
    # ROSCO's dip at 1.08 rad/s: the ladder moves on to 4.5 dB
    d3 = hinf.design_hinf(model, V, spec=hinf.spec_like_qft(model, V, speed_relax_db=3.0))
    assert 0 < d3.speed_excess_db < 0.5
    with pytest.raises(TypeError, match="spec_from_qft"):
        hinf.design_hinf(model, V, spec=q)
    with pytest.raises(TypeError, match="QFTDesign"):
        hinf.spec_from_qft("hinf")
    with pytest.raises(ValueError, match="speed_relax_db"):
        hinf.spec_like_qft(model, V, speed_relax_db=-1.0)


def test_rosco_specs_ask_for_the_dip(model):
    # spec_from_rosco (the default before QFT's specs): ROSCO's own T_Ω,w unrelaxed, with its ζ = 0.01 dip
    # at 1.081 rad/s. The damped 1×2 loop meets the tower spec but exceeds the speed spec by
    # ≈ 2.9 dB, by more than 1 dB only inside the dip.
    d = hinf.design_hinf(model, V, spec=hinf.spec_from_rosco(model, V))
    assert d.specs == "rosco" and d.speed_relax_db == 0.0
    assert 2.5 < d.speed_excess_db < 3.5 and d.tower_excess_db < -3.0 and d.zeta_min > 0.1
    from specdesign import closedloop

    cl = closedloop.closed_loop_mimo(model.linearize(V), d.controller, ("gen_speed", "tower_top_vel"))
    r = 20 * np.log10(np.abs(closedloop.frequency_response(cl, d.omega, "gen_speed")) / d.w_speed.magnitude(d.omega))
    over = d.omega[r > 1.0]
    assert over.min() > 1.06 and over.max() < 1.10


def test_loopshaping_check_agrees(design):
    # The QFT-side checker (another module, polynomial closed-loop poles) sees the same.
    res = design.check
    if design.controller.ninputs == 2:
        assert res is None
        return
    assert np.array_equal(res.omega, design.omega)
    assert res.stable.all() and res.phase_margin_deg[0] > 30 and res.gain_margin_db[0] > 6
    speed = res.margins_db[res.names.index("speed")]
    tower = res.margins_db[res.names.index("tower")]
    assert speed.min() == pytest.approx(-design.speed_excess_db, abs=1e-6)
    near_mode = np.abs(design.omega / design.tower_mode - 1) <= hinf.TOWER_BAND
    assert tower[near_mode].min() == pytest.approx(-design.tower_band_excess_db, abs=1e-6)


def test_undamped_default_of_before_is_still_available(model):
    # min_damping=0, decay_rate=0 is the design this module used to make: ζ ≈ 0.003 at
    # 1.08 rad/s and a +6.9 dB narrow-band speed excess that a 400-point grid missed.
    d = hinf.design_hinf(model, V, spec=hinf.spec_from_rosco(model, V), measurements=("gen_speed",), min_damping=0.0,
                         decay_rate=0.0)
    assert d.zeta_min < 0.005 and abs(d.zeta_min_frequency - 1.08) < 0.01
    assert d.speed_excess_db > 5.0


def test_sign_convention_matches_rosco(design, model):
    # β = −C·Ω_g: at low frequency C_β has integral action with ROSCO's sign.
    w = np.array([1e-3, 2e-3])
    c = _resp(design.pitch_controller, w)[0, 0]
    c0 = _resp(ct.ss(turbine.rosco_baseline(model, V)), w)[0, 0]
    assert np.all(np.real(c / c0) > 0)


def test_discrete_controller_exact_at_the_tower_mode(model):
    qs = hinf.spec_like_qft(model, V)
    d = hinf.design_hinf(model, V, spec=qs, order=8, dt=0.05)
    assert d.discrete_controller.dt == 0.05
    wm = d.tower_mode
    kd = np.asarray(d.discrete_controller(np.exp(1j * wm * 0.05))).ravel()[0]
    kc = np.asarray(d.controller(1j * wm)).ravel()[0]
    assert kd == pytest.approx(kc, rel=1e-8)
    assert hinf.design_hinf(model, V, spec=qs, order=8).discrete_controller is None


def test_reduction_report_is_consistent(design):
    red = design.reduction
    assert red.controller is design.controller
    hsv = red.hankel_singular_values
    k = red.controller.nstates - red.n_unstable
    assert hsv[k] * (1 - 1e-6) <= red.error_hinf <= red.bound * (1 + 1e-6)
    w = np.logspace(-3, 3, 4000)
    diff = _resp(design.full_controller, w) - _resp(design.controller, w)
    grid = np.linalg.norm(np.moveaxis(diff, -1, 0), ord=2, axis=(1, 2)).max()
    assert grid <= red.error_hinf * (1 + 1e-6)


def test_a_given_specification_pair_is_the_weights(model):
    # spec_from_pair(W_MyT, W_Ω): the pair handed over is what the synthesis weighs and the assessment
    # measures (a loose pair: ROSCO's tower map + 3 dB, its speed map + 6 dB)
    d = spec.design_specifications(model, V, speed_relax_db=6.0, tower_relax_db=0.0)
    tower = spec.Specification(d.base.system, (spec.Gain(3.0),), name="W_tower")
    res = hinf.design_hinf(model, V, spec=hinf.spec_from_pair(tower, d.speed), measurements=("gen_speed", "tower_top_vel"),
                           order=8)
    assert res.specs == "given" and res.w_tower is tower and res.w_speed is d.speed
    assert res.speed_excess_db <= 0.1
    with pytest.raises(TypeError, match="spec_from_pair"):
        hinf.design_hinf(model, V, spec=(tower, d.speed))
    with pytest.raises(TypeError, match="speed must be"):
        hinf.spec_from_pair(tower, "W")


def test_a_certified_pair_it_does_not_meet_is_said_with_the_miss(model):
    # spec_from_certified(TargetSpecification) with pitch + ATD (issue 14): the multi-model step that makes the
    # pitch-only design meet the pair at every case (tests/test_hinf_target.py) is not taken for a
    # 1×2 controller, and the synthesis alone (it bounds the root-sum-square of the weighted
    # outputs) does not reproduce the pair's narrow pole-zero pattern at the tower mode: the miss
    # must be said, not silently returned. The warned number is checked against the explicit
    # closed-loop formula on a dense grid (independent of the design's own interconnection and grid).
    import re
    import warnings

    from specdesign import closedloop, feasibility

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # cvxpy: "solution may be inaccurate" on some rungs
        # the 25 % pair without the high-frequency gain bound
        ts = feasibility.specification_for_target(model, V, 25.0, max_hf_gain_ratio=None)
    with pytest.warns(RuntimeWarning, match="not met") as rec:
        res = hinf.design_hinf(model, V, spec=hinf.spec_from_certified(ts), measurements=("gen_speed", "tower_top_vel"))
    assert res.case_check is None
    msg = next(str(w.message) for w in rec if "not met" in str(w.message))
    assert res.notes[-1] == msg
    warned = float(re.search(r"tower load by ([+-][0-9.]+) dB", msg).group(1))
    w = np.unique(np.r_[res.omega, np.geomspace(0.005, 20.0, 4000)])
    t_my = np.abs(closedloop.t_tower_wind(model.linearize(V), res.pitch_controller, w,
                                          atd_controller=res.atd_controller))
    excess = np.max(20 * np.log10(t_my / np.abs(ts.tower.response(w))))
    assert warned > 0 and excess >= warned - 0.01  # the refined grid finds the miss the dense one sees
    assert excess <= warned + 0.1                   # and does not understate it


def test_design_records_the_tower_modes_damping(design, model, plant):
    # the record's ratios are those of the loops it describes, recomputed here: the reduced
    # controller's MIMO loop and ROSCO's PI on the same plant, the tower pole located by
    # closedloop.tower_pole (ROSCO's independently by rosco.tower_mode_damping's pole tracking)
    from specdesign import closedloop, rosco
    measurements = ("gen_speed",) if design.atd_controller is None else ("gen_speed", "tower_top_vel")
    loop = closedloop.closed_loop_mimo(plant, design.controller, measurements)
    assert design.tower_damping_ratio == pytest.approx(closedloop.tower_damping(plant, loop)[1], rel=1e-9)
    assert design.baseline_tower_damping_ratio == pytest.approx(rosco.tower_mode_damping(model, V, None), rel=1e-9)


def test_the_high_frequency_gain_against_the_bound_is_measured(design, model):
    # C_β against κ·|C_ROSCO| (issue 28 item 1), recomputed here by python-control's frequency
    # response on the bound's points of the design's grid (its band, ends and 3P), refined around
    # C_β's own poles (its narrow peaks), as the multi-model step's check is
    from specdesign.feasibility import MAX_HF_GAIN_RATIO, hf_check_omega, hf_gain_bound

    w = hf_check_omega(model, design.omega, ct.ss(design.pitch_controller).poles())
    c = np.abs(_resp(design.pitch_controller, w)[0, 0])
    expected = np.max(20 * np.log10(c / hf_gain_bound(model, V, w, MAX_HF_GAIN_RATIO)))
    assert design.hf_excess_db == pytest.approx(expected, abs=1e-6)
    # the synthesis on given specifications does not hold the bound (+39 dB for the 1×2 design,
    # +43 dB pitch only: benchmarks/hinf_structures.py, docs/hinf.md): far over it
    assert design.hf_excess_db > 10.0
    # a stable controller with ROSCO's sign: what test_sign_convention_matches_rosco checks by hand
    assert design.controller_unstable_poles.size == 0 and design.speed_integral_sign == 1


def test_a_design_a_turbine_cannot_carry_is_said(model):
    import warnings

    qs = hinf.spec_like_qft(model, V)
    with pytest.warns(RuntimeWarning, match="exceeds the high-frequency gain bound"):
        hinf.design_hinf(model, V, spec=qs, order=8)
    # 16× the generator-speed noise rolls C_β off under the bound, at the price of an unstable
    # controller whose speed channel has the opposite sign of ROSCO's (docs/hinf.md's table)
    with pytest.warns(RuntimeWarning, match="has unstable poles") as rec:
        d = hinf.design_hinf(model, V, spec=qs, order=8, noise=dict(hinf.DEFAULT_NOISE, gen_speed=0.016))
    said = [str(w.message) for w in rec]
    assert any("opposite sign of ROSCO's" in m for m in said)
    assert not any("exceeds the high-frequency gain bound" in m for m in said) and d.hf_excess_db < 0
    p = np.linalg.eigvals(np.asarray(d.controller.A))
    np.testing.assert_allclose(d.controller_unstable_poles, np.sort_complex(p[p.real > 1e-9]), rtol=1e-9)
    c0 = ct.ss(spec.baseline_controller(model, V))
    ratio = _resp(d.pitch_controller, d.omega[:1])[0, 0, 0] / _resp(c0, d.omega[:1])[0, 0, 0]
    assert ratio.real < 0 and d.speed_integral_sign == -1
    # without a bound nothing is measured against one, nor said
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        free = hinf.design_hinf(model, V, spec=qs, order=8, max_hf_gain_ratio=None)
    assert free.hf_excess_db == -np.inf
    assert not any("high-frequency gain bound" in str(w.message) for w in rec)
