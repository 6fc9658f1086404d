"""Fatigue-based specifications: shaping elements, Eq. (10) vs exact, automatic notch shaping."""
import warnings

import control as ct
import numpy as np
import pytest

from specdesign import spec, spectral
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def base19(model):
    return spec.baseline_analysis(model, 19.0)


# -- elements ------------------------------------------------------------------------------
@pytest.mark.parametrize("depth_db,width", [(6.0, 0.3), (20.0, 0.1), (-3.0, 0.5)])
def test_notch_depth_and_unity_far_away(depth_db, width):
    n = spec.Notch(1.1, depth_db, width)
    # at ω_n the s² and ω_n² terms cancel: |N| = ζ_z/ζ_p exactly
    assert abs(n.response(np.array([1.1]))[0]) == pytest.approx(10 ** (-depth_db / 20), rel=1e-12)
    far = n.response(np.array([1e-4, 1e4]))
    assert np.allclose(np.abs(far), 1.0, atol=1e-3)


@pytest.mark.parametrize("element", [spec.Notch(0.9, 8.0, 0.2), spec.Gain(-2.0), spec.LeadLag(0.5, 2.0), spec.LowPass(3.0, 0.6)])
def test_element_tf_matches_fast_response(element):
    w = np.logspace(-2, 1, 50)
    exact = ct.frequency_response(element.tf(), w).complex.reshape(-1)
    assert np.allclose(element.response(w), exact, rtol=1e-10, atol=0)


def test_specification_is_baseline_times_elements(base19):
    notches = (spec.Notch(1.05, 6.0, 0.2), spec.Notch(2.3, 3.0, 0.1))
    w_spec = spec.Specification(base19.system, notches)
    w = base19.omega
    t = ct.frequency_response(base19.system, w).complex.reshape(-1)
    expected = t * notches[0].response(w) * notches[1].response(w)
    assert np.allclose(w_spec.response(w), expected, rtol=1e-10)
    # the realised W(s) has the same response (minreal must not change it)
    tf_resp = ct.frequency_response(w_spec.tf(), w).complex.reshape(-1)
    assert np.allclose(tf_resp, expected, rtol=1e-6)


def test_baseline_matches_closed_loop_formula(model, base19):
    """The baseline T_{MyT,w} equals the hand formula of WORKBENCH.md (Eq. 5 corrected)."""
    from specdesign.turbine import rosco_baseline

    P = model.linearize(19.0)
    C = rosco_baseline(model, 19.0)
    w = base19.omega

    def fr(sys):
        return ct.frequency_response(sys, w).complex.reshape(-1)

    pyw, pyb = fr(P["tower_base_my", "wind"]), fr(P["tower_base_my", "pitch_cmd"])
    pow_, pob = fr(P["gen_speed", "wind"]), fr(P["gen_speed", "pitch_cmd"])
    c = fr(C)
    t = (pyw + c * (pyw * pob - pyb * pow_)) / (1 + c * pob)
    assert np.allclose(base19.t_response, t, rtol=1e-8)
    assert base19.psd == pytest.approx(np.abs(t) ** 2 * base19.wind_psd, rel=1e-10)
    # ΔD% sums to m/2 for small steps (damage is homogeneous of degree m/2 in S)
    assert base19.sensitivity.sum() == pytest.approx(base19.m / 2, rel=2e-2)


# -- Eq. (10) vs exact ----------------------------------------------------------------------
def test_eq10_agrees_for_small_changes_and_departs_for_large(base19):
    w = base19.omega
    errors = []
    for depth in (0.2, 1.0, 6.0, 20.0):
        shaping = spec.Notch(1.05, depth, 0.3).response(w)
        p = spec.promise_of(shaping, base19)
        # exact, computed independently with spectral.exact_change on the modified PSD
        ch = spectral.exact_change(w, base19.psd, base19.psd * np.abs(shaping) ** 2, base19.m)
        assert p.exact_damage == pytest.approx(float(ch.damage_reduction), rel=1e-10)
        assert p.exact_del == pytest.approx(float(ch.del_reduction), rel=1e-9)
        errors.append(abs(p.linearisation_error) / p.exact_damage)
    assert errors[0] < 0.03, errors  # 0.2 dB: linear regime
    assert errors[-1] > errors[0] * 3, errors  # 20 dB: the linearisation departs
    assert errors == sorted(errors)


def test_del_reduction_is_damage_ratio_to_one_over_m(base19):
    p = spec.promise_of(spec.Notch(1.05, 10.0, 0.3).response(base19.omega), base19)
    assert 1 - p.exact_del / 100 == pytest.approx((1 - p.exact_damage / 100) ** (1 / base19.m), rel=1e-12)


# -- automatic shaping ---------------------------------------------------------------------
def test_shape_to_target_19ms_15pct_damage(base19):
    res = spec.shape_to_target(base19, 15.0, keep_below=0.6)
    assert res.success, res.message
    assert abs(res.promise.exact_damage - 15.0) <= 0.5
    # the notch sits around the tower mode, where ΔD% peaks above the protected band
    assert all(1.0 <= n.omega_n <= 1.15 for n in res.notches), res.notches
    # the protected band keeps the baseline's magnitude: a notch's skirt reaches its edge only
    w = base19.omega
    ratio_db = 20 * np.log10(np.abs(res.specification.response(w) / base19.t_response))
    assert np.max(np.abs(ratio_db[w < 0.5])) < 0.1
    assert np.max(np.abs(ratio_db[w < 0.6])) < 0.25
    # the promised DEL change follows from the damage change
    assert res.promise.exact_del == pytest.approx(100 * (1 - 0.85 ** 0.25), abs=0.2)



@pytest.mark.parametrize("v", [15.0, 17.0])
def test_shape_to_target_gives_the_same_notches_for_a_nudged_wind_speed(model, v):
    # issue 28 item 4: SLSQP's end moved the notch by 1.7e-7 relative (17 m/s, the width) under a
    # 1e-9 m/s nudge, which the QFT tuning amplified to 2.4e-6 in its controller; refined to the
    # KKT point the notches move by what the data do: 1.2e-9 (15 m/s) and 7e-10 (17 m/s) relative
    # measured here (two notches each); the bound keeps 8x room above that and is 15x below the
    # unrefined end's move (1.5e-7 at 17 m/s, the old code failing this test)
    a, b = (spec.shape_to_target(spec.baseline_analysis(model, x), 25.0, quantity="del").notches for x in (v, v - 1e-9))
    assert len(a) == len(b)
    for na, nb in zip(a, b):
        pa, pb = np.array([na.omega_n, na.depth_db, na.width]), np.array([nb.omega_n, nb.depth_db, nb.width])
        assert np.max(np.abs(pb / pa - 1)) <= 1e-8, (na, nb)

def test_shape_to_target_on_del(base19):
    res = spec.shape_to_target(base19, 4.0, quantity="del")  # the paper's notches on a DEL target
    assert res.success
    assert abs(res.promise.exact_del - 4.0) <= 0.5


def test_unreachable_target_is_reported(base19):
    with pytest.warns(RuntimeWarning, match="protected band"):
        res = spec.shape_to_target(base19, 60.0, keep_below=0.6, max_notches=1, max_depth_db=6.0)
    assert not res.success
    assert res.reached < 60.0


@pytest.mark.parametrize("target", [0.0, -5.0, 100.0, 150.0])
def test_bad_targets(base19, target):
    with pytest.raises(ValueError, match="target_reduction"):
        spec.shape_to_target(base19, target)


def test_bad_inputs(base19):
    with pytest.raises(ValueError, match="width"):
        spec.Notch(1.0, 6.0, 0.0)
    with pytest.raises(ValueError, match="omega_n"):
        spec.Notch(-1.0, 6.0, 0.3)
    with pytest.raises(TypeError, match="baseline"):
        spec.Specification(np.ones(3))
    with pytest.raises(ValueError, match="improper"):
        spec.Specification(ct.tf([1, 0, 0], [1, 1]))
    with pytest.raises(ValueError, match="not stable"):
        spec.Specification(ct.tf([1], [1, -1]))
    with pytest.raises(ValueError, match="outside the baseline grid"):
        spec.promise_of(spec.Specification(base19.system, (spec.Notch(50.0, 6.0, 0.3),)), base19)
    with pytest.raises(ValueError, match="keep_below"):
        spec.shape_to_target(base19, 10.0, keep_below=100.0)
    with pytest.raises(ValueError, match="wind_psd"):
        spec.baseline_from_response(base19.omega, base19.t_response, -base19.wind_psd)


def test_speed_specification_margin(model):
    w = np.logspace(-2, 1, 30)
    s0 = spec.speed_specification(model, 19.0)
    s3 = spec.speed_specification(model, 19.0, margin_db=3.0)
    assert np.allclose(s3.magnitude(w) / s0.magnitude(w), 10 ** (3 / 20), rtol=1e-12)


def test_specification_table_rows(model):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows = spec.specification_table(model, (17.0, 23.0), 15.0)
    assert [r["wind_speed"] for r in rows] == [17.0, 23.0]
    for r in rows:
        assert r["success"]
        assert abs(r["promised_damage_pct"] - 15.0) <= 0.5


# ----------------------------------------------------------------------------- one vocabulary with loopshaping
@pytest.mark.parametrize("element", [spec.Notch(1.1, 12.0, 0.3), spec.Gain(-3.0), spec.LeadLag(0.5, 2.0),
                                     spec.LowPass(2.0, 0.7), spec.LowPass(2.0, 1.5)])
def test_spec_elements_are_loopshaping_elements(element):
    # The same factor in both vocabularies: responses equal on a grid through the tower mode
    # (independent evaluations: the spec's own formula vs loopshaping's polynomials).
    from loopshaping.controller import Controller

    w = np.logspace(-2, 1.5, 300)
    got = Controller(element.to_elements()).response(w)
    np.testing.assert_allclose(got, element.response(w), rtol=1e-12)
    if len(element.to_elements()) == 1:  # and back, to the same record
        back = spec.from_element(element.to_elements()[0])
        assert type(back) is type(element)
        np.testing.assert_allclose(back.response(w), element.response(w), rtol=1e-12)


def test_specification_shaping_as_a_controller(model):
    base = spec.baseline_analysis(model, 19.0)
    s = spec.Specification(base.system, (spec.Notch(1.1, 10.0, 0.4), spec.LeadLag(1.3, 2.6)), name="W")
    w = np.logspace(-2, 1, 200)
    np.testing.assert_allclose(s.shaping_controller().response(w), s.shaping(w), rtol=1e-12)


def test_elements_without_a_specification_counterpart_are_refused():
    from loopshaping import controller as lc

    for e in (lc.integrator(1), lc.real_zero(-1.0), lc.gain(-2.0), lc.notch(1.0, 0.5, 0.1)):
        with pytest.raises(ValueError, match="has no specification element"):
            spec.from_element(e)
    with pytest.raises(TypeError, match="loopshaping.controller.Element"):
        spec.from_element(spec.Gain(1.0))
