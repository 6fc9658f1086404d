"""Controller elements against python-control, editing, and the JSON round trip."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from loopshaping import controller as lc

s = ct.tf("s")
W = np.logspace(-2, 3, 200)


def resp(sys, w=W):
    return np.squeeze(ct.frequency_response(sys, w).complex)


@pytest.mark.parametrize("element, reference", [
    (lc.gain(-3.5), ct.tf(-3.5, 1)),
    (lc.integrator(2), 1 / s**2),
    (lc.differentiator(), s),
    (lc.real_pole(4.0), 1 / (s / 4 + 1)),
    (lc.real_zero(-2.0), -s / 2 + 1),
    (lc.complex_pole(247.0, 0.5), 1 / (s**2 / 247**2 + s / 247 + 1)),
    (lc.complex_zero(3.0, 0.2), s**2 / 9 + 0.4 * s / 3 + 1),
    (lc.lead_lag(42.0, 165.0), (s / 42 + 1) / (s / 165 + 1)),
    (lc.notch(1.1, 0.05, 0.5), (s**2 + 0.11 * s + 1.21) / (s**2 + 1.1 * s + 1.21)),
])
def test_elements_match_python_control(element, reference):
    np.testing.assert_allclose(element.response(W), resp(reference), rtol=1e-12)
    np.testing.assert_allclose(lc.Controller((element,)).response(W), resp(reference), rtol=1e-12)


def test_published_qft_controller():
    C = lc.Controller((lc.gain(379), lc.real_zero(42), lc.complex_pole(247, 0.5)))
    ref = 379 * (s / 42 + 1) / (s**2 / 247**2 + s / 247 + 1)
    np.testing.assert_allclose(resp(C.tf()), resp(ref), rtol=1e-12)
    np.testing.assert_allclose(C.response(W), resp(ref), rtol=1e-12)
    assert C.is_proper
    assert not C.add(lc.differentiator(2)).is_proper


def test_lead_from_phase_peaks_at_requested_frequency():
    e = lc.lead_from_phase(40.0, 10.0)
    w = np.logspace(0, 2, 20001)
    ph = np.degrees(np.angle(e.response(w)))
    assert abs(ph.max() - 40.0) < 1e-3
    assert abs(w[ph.argmax()] / 10.0 - 1) < 1e-3
    lag = lc.lead_from_phase(-30.0, 2.0)
    assert np.degrees(np.angle(lag.response(2.0))) == pytest.approx(-30.0, abs=1e-9)


def test_editing_returns_new_controllers():
    C = lc.Controller((lc.gain(2.0), lc.real_pole(10.0)))
    C2 = C.add(lc.integrator(), 1)
    assert len(C.elements) == 2 and len(C2.elements) == 3
    assert C2.elements[1].kind == "integrator"
    C3 = C2.set(2, omega=20.0)
    assert C2.elements[2].params["omega"] == 10.0 and C3.elements[2].params["omega"] == 20.0
    C4 = C3.replace(0, lc.gain(5.0)).remove(1)
    np.testing.assert_allclose(C4.response(W), resp(5 / (s / 20 + 1)), rtol=1e-12)
    with pytest.raises(IndexError):
        C.remove(5)


def test_from_zpk_and_from_tf_rebuild_the_transfer_function():
    ref = -4.8167 * (s + 0.6) * (s**2 + 0.7337 * s + 0.2441) / (s * (s**2 + 1.872 * s + 2.306) * (s**2 + 2.297 * s + 26.67))
    C = lc.Controller.from_tf(ref)
    np.testing.assert_allclose(C.response(W), resp(ref), rtol=1e-9)
    kinds = [e.kind for e in C.elements]
    assert kinds.count("integrator") == 1 and kinds.count("complex_pole") == 2 and kinds.count("complex_zero") == 1
    rhp = lc.Controller.from_zpk([2.0], [-1.0], 3.0)  # 3(s − 2)/(s + 1)
    np.testing.assert_allclose(rhp.response(W), resp(3 * (s - 2) / (s + 1)), rtol=1e-12)


finite = st.floats(0.01, 1e3, allow_nan=False)


@settings(max_examples=50, deadline=None)
@given(k=st.floats(-1e3, 1e3).filter(lambda v: abs(v) > 1e-6), w1=finite, w2=finite,
       zeta=st.floats(-0.99, 0.99), order=st.integers(1, 3))
def test_json_round_trip_is_lossless(k, w1, w2, zeta, order):
    C = lc.Controller((lc.gain(k), lc.integrator(order), lc.real_zero(w1), lc.complex_pole(w2, zeta),
                       lc.lead_lag(w1, w2), lc.notch(w2, 0.01, 0.7)))
    back = lc.Controller.from_json(C.to_json())
    assert back == C
    num, den = C.polys()
    num2, den2 = back.polys()
    assert np.array_equal(num, num2) and np.array_equal(den, den2)


def test_bad_elements_name_the_parameter():
    with pytest.raises(ValueError, match="omega"):
        lc.real_pole(0.0)
    with pytest.raises(ValueError, match="zeta"):
        lc.complex_pole(1.0, 1.5)
    with pytest.raises(ValueError, match="order"):
        lc.integrator(1.5)
    with pytest.raises(ValueError, match="kind"):
        lc.Element("pid", {})
    with pytest.raises(TypeError, match="parameters"):
        lc.Element("gain", {"gain": 1.0})
    with pytest.raises(ValueError, match="k"):
        lc.gain(float("nan"))
    with pytest.raises(TypeError, match="Element"):
        lc.Controller((3.0,))
    with pytest.raises(ValueError, match="elements"):
        lc.Controller.from_json("{}")


def test_interactive_designer_numbers_and_widget():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from loopshaping import qft
    from loopshaping.interactive import Designer

    P = [ct.tf([k], [1, 31, 30]) for k in (1.0, 5.0, 10.0)]
    w = np.array([0.1, 5.0, 100.0])
    tmpl = qft.Template.from_systems(P, w)
    b = qft.bounds(tmpl, "stability", 1.2)
    d = Designer(b, tmpl, lc.Controller((lc.gain(379), lc.real_zero(42), lc.complex_pole(247, 0.5))))
    fig = d.draw(live=True)
    st = d.set_param(0, k=100.0)
    G = 100 * (s / 42 + 1) / (s**2 / 247**2 + s / 247 + 1)
    L = np.stack([resp(p * G, d.omega) for p in P], 1)
    np.testing.assert_allclose(st.worst_T_db, 20 * np.log10(np.abs(L / (1 + L)).max(1)), atol=1e-9)
    np.testing.assert_allclose(st.magnitude_db, 20 * np.log10(np.abs(L[:, 0])), atol=1e-9)
    L0 = resp(P[0] * G, w)
    want = b.is_allowed(w, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))
    np.testing.assert_array_equal(st.design_allowed, want)
    np.testing.assert_allclose(d._artists["loop"].get_ydata(), st.magnitude_db)
    d.add("real_pole", omega=2000.0)
    assert d.controller.elements[-1] == lc.real_pole(2000.0)
    d.remove(3)
    assert len(d.controller.elements) == 3
    ui = d.widget()
    assert type(ui).__name__ == "VBox"
    select, row, rows, _, msg = ui.children[0].children
    select.value = 1
    slider, text = rows.children[0].children
    slider.value = 30.0  # drag the zero
    assert d.controller.elements[1] == lc.real_zero(30.0) and text.value == 30.0
    assert select.value == 1 and rows.children[0].children[0] is slider  # the dragged slider survives
    # the front end echoes a value rounded to the slider's step: not a move (the value stays exact)
    text.value = 30.123456789  # typed: kept exactly
    assert d.controller.elements[1] == lc.real_zero(30.123456789)
    slider.value = 10 ** (0.005 * round(np.log10(30.123456789) / 0.005))
    assert d.controller.elements[1] == lc.real_zero(30.123456789)
    row.children[0].value = "notch"
    row.children[1].click()
    assert d.controller.elements[-1].kind == "notch" and select.value == 3
    plt.close(fig)
