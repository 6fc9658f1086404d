"""Issue 14: ``feasibility.shape_whole_band(base, target)``, the user's entry to the certified
whole-band specification (feasibility.element_specification on the baseline's model).

The acceptance numbers are the issue's: promise ≥ 24.5 % recomputed independently (Dirlik DEL on
|W|²S_W against ROSCO's |T|²S_W) within 0.5 pp; the certificate meets the pair at every plant case
(the explicit SISO formula T = P_yw + P_yβ·T_βw on a dense 0.005-20 rad/s grid); the design handed
the pair meets |T_MyT,w| ≤ |W_MyT| + 0.1 dB and predicts ≥ promise − 0.1 pp; the shaping and the
design at v − 1e-9 m/s give the same promise and prediction within 0.01 pp and the same
controller order (issue 28 item 4; issue 14 asked 0.2 pp). The speed is 25 m/s, where the ±3 %
envelope of the certificate alone left no element specification and where v − 1e-9 m/s failed
outright while the fit stopped at an iteration cap (issue 14), and where under the high-frequency
gain bound the envelope fit fell into another local minimum 1e-9 m/s away (5 notches and 4, the
predictions 0.49 pp apart: elements.FIT_INPUT_DB). Everything runs with the default options
(the bound on, the plant cases' margin shaped), as a user gets it.
"""
from __future__ import annotations

import warnings
from dataclasses import astuple

import numpy as np
import pytest

from specdesign import closedloop, spec, spectral, wind
from specdesign import feasibility as fz
from specdesign.qft import design_qft, spec_from_certified
from specdesign.rosco import rosco_baseline
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def base25(model):
    return spec.baseline_analysis(model, 25.0)


def test_the_baseline_keeps_its_model_and_operating_point(model, base25):
    assert base25.model is model and base25.wind_speed == 25.0
    assert base25.extras == {"turbulence_class": "B", "controller": None, "record_length": 600.0}


def test_bad_whole_band_requests_are_named(model, base25):
    with pytest.raises(ValueError, match="quantity='dell' must be"):
        fz.shape_whole_band(base25, 25.0, quantity="dell")
    with pytest.raises(ValueError, match="strictly between 0 and 100"):
        fz.shape_whole_band(base25, 100.0)
    with pytest.raises(TypeError, match="base must be a Baseline"):
        fz.shape_whole_band(base25.omega, 25.0)
    # notch-shaper options have no meaning for the whole band, and the other way round
    with pytest.raises(TypeError, match="keep_below"):
        fz.shape_whole_band(base25, 25.0, keep_below=0.3)
    with pytest.raises(TypeError, match="headroom_pp"):
        spec.shape_to_target(base25, 25.0, headroom_pp=(3.0,))
    # a baseline the certificate cannot be made against: each reason named
    bare = spec.baseline_from_response(base25.omega, base25.t_response, base25.wind_psd)
    with pytest.raises(ValueError, match="carries no model"):
        fz.shape_whole_band(bare, 25.0)
    speed = spec.baseline_analysis(model, 25.0, "gen_speed")
    with pytest.raises(ValueError, match="output is 'gen_speed'"):
        fz.shape_whole_band(speed, 25.0)
    other = spec.baseline_analysis(model, 25.0, controller=rosco_baseline(model, 24.0), turbulence_class="A")
    with pytest.raises(ValueError, match="another controller than ROSCO's; its wind is turbulence class 'A'"):
        fz.shape_whole_band(other, 25.0)


def test_an_unreachable_whole_band_target_says_which_constraint_binds(base25):
    # one headroom, 70 %: the certificate for 73 % does not exist at 25 m/s; the message carries
    # specification_for_target's reason (the speed relaxation it would need and the best promise)
    with pytest.raises(ValueError, match=r"no element specification.*promises 70 % at 25 m/s.*"
                                         r"no pitch specification promises 73 %.*relaxed up to 12 dB \(best"):
        fz.shape_whole_band(base25, 70.0, headroom_pp=(3.0,))


@pytest.fixture(scope="module")
def whole25(base25):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # cvxpy accuracy notes on some rungs
        return fz.shape_whole_band(base25, 25.0)


def _explicit_maps(model, v, controller, w):
    """|T_MyT,w| and |T_Ω,w| of β = −C·Ω_g on the plant at v, by the SISO formula."""
    r = {k: x[:, 0] for k, x in closedloop.plant_responses([model.linearize(v)], w, ("gen_speed", "tower_base_my")).items()}
    c = closedloop.siso_response(controller, w)
    t_bw = -c * r["gen_speed", "wind"] / (1 + c * r["gen_speed", "pitch_cmd"])
    return tuple(np.abs(r[y, "wind"] + r[y, "pitch_cmd"] * t_bw) for y in ("tower_base_my", "gen_speed"))


@pytest.mark.slow
def test_the_whole_band_specification_at_25_mps_promises_the_target_and_is_met(model, whole25, design25):
    res = whole25
    ts = res.certified
    assert res.success and res.specification is ts.tower
    assert ts.max_hf_gain_ratio == fz.MAX_HF_GAIN_RATIO  # the default: the high-frequency gain bound on
    assert {type(e).__name__ for e in ts.tower.elements} <= {"Gain", "LeadLag", "Notch"}
    # the promise, recomputed independently: Dirlik DEL on |W|²S_W against ROSCO's |T|²S_W
    w = np.geomspace(0.0005, 20.0, 4000)
    t_rosco = np.abs(closedloop.t_tower_wind(model.linearize(25.0), rosco_baseline(model, 25.0), w))
    # variance about each 600 s record's mean (wind.record_window), written out: 1 − sinc²(ωT/2)
    psd = wind.rotor_effective_spectrum(w, 25.0, model.rotor_radius) * (1 - (np.sin(300.0 * w) / (300.0 * w)) ** 2)
    del_w = spectral.del_spectral(w, np.abs(ts.tower.response(w)) ** 2 * psd, 4.0)
    del_r = spectral.del_spectral(w, t_rosco**2 * psd, 4.0)
    assert res.promise.exact_del >= 25.0
    assert 100 * (1 - del_w / del_r) >= 24.5
    assert abs(100 * (1 - del_w / del_r) - res.promise.exact_del) <= 0.5
    # the certificate at every plant case, against W_i = T^ROSCO_i · W/T^ROSCO (nominal), both maps;
    # W_MyT with room for the design step (for_tower accepts half of TOWER_ROOM_DB below it on its
    # own grid; this grid is another, so half of that is asserted)
    cert = ts.design.controller(model)
    rosco_nom = _explicit_maps(model, 25.0, rosco_baseline(model, 25.0), w)
    assert len(ts.case_speeds) == 3  # 24, 24.5, 25 m/s: the cases above 25 m/s are clipped to the range
    for v in ts.case_speeds:
        rosco = _explicit_maps(model, v, rosco_baseline(model, v), w)
        got = _explicit_maps(model, v, cert, w)
        for k, (wy, room) in enumerate(((ts.tower, fz.target.TOWER_ROOM_DB / 4), (ts.speed, 0.0))):
            bound = rosco[k] * np.abs(wy.response(w)) / rosco_nom[k]
            assert np.max(20 * np.log10(got[k] / bound)) <= 1e-6 - room, (v, k)
    d = design25
    assert d.success, d.message
    t_my = _explicit_maps(model, 25.0, d.pitch_controller, w)[0]
    assert np.max(20 * np.log10(t_my / np.abs(ts.tower.response(w)))) <= 0.1
    assert d.del_reduction >= res.promise.exact_del - 0.1


@pytest.fixture(scope="module")
def design25(model, whole25):
    return design_qft(model, 25.0, spec=spec_from_certified(whole25.certified))


@pytest.mark.slow
def test_the_promise_is_the_target_plus_the_margin_by_an_independent_dirlik(model, whole25):
    # the settle step raises the gain until the promise is target + PROMISE_MARGIN_PP; recomputed
    # here with spectral.del_spectral on the fit's grid (not the fit's own moment code)
    w = fz.elements.FIT_OMEGA
    base = spec.baseline_analysis(model, 25.0, omega=w)
    tower = whole25.certified.tower
    del_w = spectral.del_spectral(w, np.abs(tower.response(w)) ** 2 * base.wind_psd, 4.0)
    del_r = spectral.del_spectral(w, base.psd, 4.0)
    assert 100 * (1 - del_w / del_r) == pytest.approx(25.0 + fz.elements.PROMISE_MARGIN_PP, abs=1e-6)
    assert whole25.promise.exact_del == pytest.approx(100 * (1 - del_w / del_r), abs=1e-9)


@pytest.mark.slow
def test_a_rounding_error_in_the_wind_speed_moves_neither_promise_nor_prediction(model, base25, whole25, design25):
    # issue 28 item 4: the design at v and at v ± 1e-9 m/s has the same order and predicts the same
    # reduction within 0.01 pp (25 m/s is the top of the model's range, so − 1e-9). The envelope
    # fit runs on inputs rounded to elements.FIT_INPUT_DB, so it returns the same elements (only
    # the settled gain follows the promise, continuous in v); the certificate is the same to its
    # solver's tolerance and the settle step pins the promise at target + margin
    v = 25.0 - 1e-9
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        near = fz.shape_whole_band(spec.baseline_analysis(model, v), 25.0).certified
    ts = whole25.certified
    assert [type(e) for e in near.tower.elements] == [type(e) for e in ts.tower.elements]
    for a, b in zip(near.tower.elements[1:], ts.tower.elements[1:]):  # [0] is the settled Gain
        assert np.allclose(astuple(a), astuple(b), rtol=1e-9, atol=0.0), (a, b)
    assert abs(near.speed_relax_db - ts.speed_relax_db) <= 1e-3
    assert abs(near.promise.exact_del - ts.promise.exact_del) <= 1e-6
    d = design_qft(model, v, spec=spec_from_certified(near))
    assert d.success, d.message
    assert d.parameters["order"] == design25.parameters["order"]
    assert abs(d.del_reduction - design25.del_reduction) <= 0.01


@pytest.mark.slow
def test_a_hand_edit_of_the_whole_band_specification_is_recertified(model, whole25):
    ts = whole25.certified
    # 0.5 dB more room: still met by the certificate, promises less (monotone in |W|)
    looser = fz.recertify(model, ts, tower=ts.tower.add(spec.Gain(0.5)))
    assert looser.promise.exact_del < ts.promise.exact_del
    assert looser.tower.elements[-1] == spec.Gain(0.5)
    # a 6 dB notch at the tower mode asks for more than the certificate gives: said, with where
    with pytest.raises(ValueError, match="exceeds the edited W_MyT by .* dB at .* rad/s for the plant case"):
        fz.recertify(model, ts, tower=ts.tower.add(spec.Notch(1.08, 6.0, 0.3)))


#: The fallback (elements fitted above a certificate for a larger target) is reached only when
#: every followed certificate fails, which the default options do not at 15, 19 or 25 m/s; forced
#: at 25 m/s under the default high-frequency gain bound it refuses, naming the bound (measured:
#: its envelopes promise 21.4-28.8 %, its elements up to 24.3 %, and no certificate promises
#: 32 %, best 31.7 %), so its mechanics are checked without the bound and with the uniform margin.
FALLBACK_OPTIONS = {"max_hf_gain_ratio": None, "margin_bumps": 0}


def test_the_fallback_fits_elements_above_a_larger_certificate(model, monkeypatch):
    # when no followed certificate can be certified (FOLLOW exhausted; forced here), the elements
    # are fitted above the envelope of a certificate for a larger target: still a certified pair
    # that promises the target (+ PROMISE_MARGIN_PP, exact Dirlik on FIT_OMEGA), met by that
    # certificate at every plant case (recertify, which element_specification ends with, raises
    # otherwise; here re-run on the result), its speed map that certificate's
    from specdesign.feasibility import elements

    monkeypatch.setattr(elements, "FOLLOW", ())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        ts = fz.element_specification(model, 25.0, 25.0, **FALLBACK_OPTIONS)
    assert ts.promise.exact_del == pytest.approx(25.0 + elements.PROMISE_MARGIN_PP, abs=1e-6)
    again = fz.recertify(model, ts)
    assert again.speed_relax_db == pytest.approx(ts.speed_relax_db, abs=1e-9)
    # the fallback's certificate was made for a larger target (3 pp or more of headroom)
    assert ts.design.del_reduction > 25.0 + 3.0
