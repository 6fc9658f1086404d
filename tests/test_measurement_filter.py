"""A fixed filter on the measurements of the fixed-structure QFT design (``measurement_filter``,
``qft.three_p_notch``): in OpenFAST 53-82 % of QFT+ATD's pitch-rate variance sits at 3P and above
(docs/openfast.md, the pitch's band table), which the linear model lacks; the filter keeps it out
of the pitch and the tuner designs around it."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign import qft, turbine
from specdesign.qft.structure import controller_polys, controllers, filter_polys, rosco_start
from specdesign.turbine import rosco_baseline


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


def test_the_three_p_notch_has_its_depth_at_3p_and_unit_gain_away_from_it(model):
    w3 = 3 * model.rated_rotor_speed  # 2.375 rad/s: 3 × the IEA 15 MW's rated rotor speed, 7.56 rpm
    for depth in (10.0, 20.0, 40.0):
        f = qft.three_p_notch(model, depth_db=depth, zeta_pole=0.4)
        assert_allclose(20 * np.log10(abs(f(1j * w3))), -depth, atol=1e-9)
        assert_allclose(abs(f(0)), 1.0, rtol=1e-12)
        assert_allclose(abs(f(1j * 1e6)), 1.0, rtol=1e-5)
    # the docstring's width: ≥ 13 dB over the 3P band 2.2-2.6 rad/s at ζ_p = 0.5, depth 20 dB
    # (by hand at the band's ends: −14.8 dB at 2.2, −13.8 dB at 2.6 rad/s)
    f = qft.three_p_notch(model)
    band = np.linspace(2.2, 2.6, 41)
    assert np.max(20 * np.log10(np.abs(f(1j * band)))) <= -13.0


def test_the_rolloff_is_a_unit_gain_second_order_low_pass():
    # ω²/(s² + 2ζω s + ω²): |F(j·2.5ω)| = 1/√((1 − 6.25)² + (2·0.7071·2.5)²) = 1/√39.8 by hand
    f = qft.rolloff(4.0)
    assert_allclose(abs(f(0)), 1.0, rtol=1e-12)
    assert_allclose(abs(f(10j)), 1 / np.sqrt((1 - 6.25) ** 2 + (2 * 2**-0.5 * 2.5) ** 2), rtol=1e-12)
    assert_allclose(np.angle(f(4j), deg=True), -90.0, atol=1e-9)
    for bad in (dict(omega=0.0), dict(omega=np.nan), dict(omega=4.0, zeta=-0.1)):
        with pytest.raises(ValueError, match=next(iter(k for k, v in bad.items() if not (np.isfinite(v) and v > 0)))):
            qft.rolloff(**bad)


def test_both_controllers_are_the_structures_times_the_filter(model):
    # controller_polys with a filter equals the unfiltered structures times F, evaluated apart
    x = rosco_start(rosco_baseline(model, 19.0))
    f = qft.three_p_notch(model)
    w = np.geomspace(0.01, 10.0, 50)
    nb, db, na, da = controller_polys(x)
    fb, fdb, fa, fda = controller_polys(x, filter_polys(f))
    s = 1j * w
    F = np.array([complex(f(z)) for z in s])
    assert_allclose(np.polyval(fb, s) / np.polyval(fdb, s), np.polyval(nb, s) / np.polyval(db, s) * F, rtol=1e-10)
    assert_allclose(np.polyval(fa, s) / np.polyval(fda, s), np.polyval(na, s) / np.polyval(da, s) * F, rtol=1e-10)
    cb, ca = controllers(x, 19.0, filter_polys(f))
    assert cb.input_labels == ["gen_speed"] and ca.input_labels == ["tower_top_vel"]
    assert_allclose(np.array([complex(ca(z)) for z in s]), np.polyval(na, s) / np.polyval(da, s) * F, rtol=1e-10)


def test_a_bad_filter_is_named():
    with pytest.raises(TypeError, match="measurement_filter must be a control"):
        filter_polys(np.array([1.0, 2.0]))
    with pytest.raises(ValueError, match="measurement_filter is improper"):
        filter_polys(ct.tf([1.0, 1.0, 1.0], [1.0, 1.0]))
    with pytest.raises(ValueError, match="poles at or right of the imaginary axis"):
        filter_polys(ct.tf([1.0], [1.0, -1.0]))
    with pytest.raises(ValueError, match="gain 0.0 at 0"):
        filter_polys(ct.tf([1.0, 0.0], [1.0, 1.0]))
    with pytest.raises(ValueError, match="SISO"):
        filter_polys(ct.ss(np.eye(2) * -1, np.eye(2), np.eye(2), np.zeros((2, 2))))
    with pytest.raises(ValueError, match="continuous-time"):
        filter_polys(ct.tf([1.0], [1.0, 0.5], 0.1))
    with pytest.raises(ValueError, match="rated_rotor_speed"):
        qft.three_p_notch(object())
    with pytest.raises(ValueError, match="depth_db"):
        qft.three_p_notch(turbine.iea15mw(), depth_db=0.0)


def test_the_filter_belongs_to_the_fixed_structures(model):
    # the certificate design (the default) has no place for it: named, not ignored
    with pytest.raises(TypeError, match="measurement_filter"):
        qft.design_qft(model, 19.0, measurement_filter=qft.three_p_notch(model))


def test_the_papers_structure_designed_with_a_3p_notch_meets_its_specification_and_carries_it(model):
    # design_qft(..., measurement_filter=F): tuned with F, returned with it: C_atd/F is the
    # lead-lag k_a·(s/z_a + 1)/(s/p_a + 1) of the design's own parameters, C_β/F the PI + notch
    # + low-pass; every specification met over the plant cases with every loop stable (success)
    f = qft.three_p_notch(model)
    d = qft.design_qft(model, 19.0, spec=qft.spec_notch(25.0), measurement_filter=f)
    assert d.success and d.all_stable and d.bounds_met
    p = d.parameters
    w = np.geomspace(0.01, 10.0, 40)
    s = 1j * w
    F = np.array([complex(f(z)) for z in s])
    lead_lag = p["k_atd"] * (s / p["z_atd"] + 1) / (s / p["p_atd"] + 1)
    assert_allclose(np.array([complex(d.atd_controller(z)) for z in s]) / F, lead_lag, rtol=1e-8)
    pi = p["k"] * (s + p["z"]) / s
    notch = (s**2 + 2 * p["zeta_n"] * p["omega_n"] * s + p["omega_n"] ** 2) / p["omega_n"] ** 2
    lows = [q**2 / (s**2 + 2 * z * q * s + q**2) for q, z in ((p["omega_d"], p["zeta_d"]), (p["omega_f"], p["zeta_f"]))]
    assert_allclose(np.array([complex(d.pitch_controller(z)) for z in s]) / F, pi * notch * lows[0] * lows[1], rtol=1e-8)
    # the notch is where it was asked: 20 dB below the structure's own gain at 3P
    w3 = 3 * model.rated_rotor_speed
    lag = p["k_atd"] * (1j * w3 / p["z_atd"] + 1) / (1j * w3 / p["p_atd"] + 1)
    assert_allclose(abs(complex(d.atd_controller(1j * w3))) / abs(lag), 0.1, rtol=1e-9)
    assert d.options["measurement_filter"] is not None
