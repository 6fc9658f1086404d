"""Automatic loop shaping on the QFT Toolbox example, and infeasibility reporting."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest

from loopshaping import qft
from loopshaping.auto import InfeasibleError, refine, shape
from loopshaping.check import check
from loopshaping.controller import Controller

from test_qft_bounds import G_PUBLISHED, OMEGAS, W_SENS, manual_cases

s = ct.tf("s")
HF = np.logspace(np.log10(2 * 1000), np.log10(1000 * 1000), 30)


@pytest.fixture(scope="module")
def problem():
    # Stability bounds on a denser grid than the performance ones: the shaper only sees
    # the design frequencies, and a tight optimum would otherwise bulge between them.
    cases, nom = manual_cases()
    wd = np.unique(np.r_[OMEGAS, np.logspace(-2, 3, 21)])
    tmpl = qft.Template.from_systems(cases, wd, nominal=nom)
    b = qft.intersect(qft.bounds(tmpl, "stability", 1.2),
                      qft.bounds(tmpl, "sensitivity", W_SENS, band=(0, 10)),
                      qft.bounds(tmpl, "input_disturbance", 0.01, band=(0, 10)))
    return tmpl, b


def test_shaper_beats_the_published_controller(problem):
    tmpl, b = problem
    published = Controller.from_tf(G_PUBLISHED)
    C = shape(b, poles=published, n_zeros=1, initial=published, margin_db=0.05)
    L0 = tmpl.nominal_response * C.response(tmpl.omega)
    assert b.is_allowed(tmpl.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0))).all()
    # Same poles; started from a feasible point, the convex-concave iteration cannot do worse.
    np.testing.assert_allclose(np.sort_complex(np.roots(C.polys()[1])), np.sort_complex(ct.poles(G_PUBLISHED)), rtol=1e-9)
    g_new = np.abs(C.response(HF)).max()
    g_pub = np.abs(np.squeeze(ct.frequency_response(G_PUBLISHED, HF).complex)).max()
    assert g_new <= g_pub * (1 + 1e-6)
    res = check(tmpl, C, b, np.logspace(-2, 3, 1000))
    assert res.stable.all()
    assert res.passed, res.summary()


def test_shaper_from_default_start_finds_a_feasible_loop(problem):
    tmpl, b = problem
    C = shape(b, poles=[-247 * np.exp(1j * np.pi / 3), -247 * np.exp(-1j * np.pi / 3)], margin_db=0.05)
    L0 = tmpl.nominal_response * C.response(tmpl.omega)
    assert b.is_allowed(tmpl.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0))).all()
    assert check(tmpl, C, b, np.logspace(-2, 3, 1000)).stable.all()


def test_infeasible_problem_names_the_binding_frequency():
    # At 10 rad/s |1/(1+L)| ≤ 0.01 needs |G| large, where |G/(1+PG)| → 1/|P| ≈ 10 > 5.
    w = np.array([1.0, 10.0])
    tmpl = qft.Template.from_systems([1 / (s + 1), 1.2 / (s + 1)], w)
    b = qft.intersect(qft.bounds(tmpl, "sensitivity", np.array([0.5, 0.01])),
                      qft.bounds(tmpl, "control_effort", 5.0))
    with pytest.raises(InfeasibleError) as err:
        shape(b, poles=[-1000.0], max_iter=15)
    assert err.value.omega == pytest.approx(10.0)
    assert err.value.spec in ("sensitivity", "control_effort")
    assert err.value.violation_db > 0.1
    assert "10 rad/s" in str(err.value)


def test_bad_input(problem):
    _, b = problem
    with pytest.raises(ValueError, match="n_zeros"):
        shape(b, poles=[-1.0], n_zeros=2)
    with pytest.raises(TypeError, match="Bounds"):
        shape("bounds")
    with pytest.raises(ValueError, match="conjugate"):
        shape(b, poles=[-1 + 1j])


# ----------------------------------------------------------------------------- refine
def _manual_specs():
    return [qft.Spec("stability", 1.2), qft.Spec("sensitivity", W_SENS, band=(0, 10)),
            qft.Spec("input_disturbance", 0.01, band=(0, 10))]


@pytest.mark.parametrize("start", ["published", "default"])
def test_refine_repairs_the_loop_between_the_manual_design_frequencies(start):
    # Only the manual's four design frequencies: the shaped loop meets the bounds there but
    # bulges through the stability (margin) spec around 15-85 rad/s; refine adds the worst
    # frequencies of the failing ranges until the dense check passes.
    cases, nom = manual_cases()
    tmpl = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    specs = _manual_specs()
    dense = np.logspace(-2, 3, 1000)
    published = Controller.from_tf(G_PUBLISHED)
    kw = (dict(poles=published, n_zeros=1, initial=published) if start == "published"
          else dict(poles=[-247 * np.exp(1j * np.pi / 3), -247 * np.exp(-1j * np.pi / 3)]))
    b = qft.intersect(*[qft.bounds(tmpl, sp) for sp in specs])
    plain = check(tmpl, shape(b, margin_db=0.01, **kw), specs, dense)
    assert not plain.passed and plain.worst("stability")[1] < -10
    res = refine(tmpl, specs, dense, **kw)
    assert res.passed, res.check.summary()
    assert res.check.stable.all()
    assert res.rounds >= 2 and res.added.size >= 1
    assert np.all((res.added > 10) & (res.added < 100))
    assert set(OMEGAS) <= set(res.template.omega) and set(res.added) <= set(res.template.omega)
    np.testing.assert_array_equal(res.bounds.omega, res.template.omega)
    L0 = res.template.nominal_response * res.controller.response(res.template.omega)
    assert res.bounds.is_allowed(res.template.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0))).all()
    num, den = res.controller.polys()
    assert len(np.trim_zeros(num, "f")) <= len(np.trim_zeros(den, "f"))


def test_refine_stops_after_max_rounds_and_reports_failure():
    cases, nom = manual_cases()
    tmpl = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    res = refine(tmpl, _manual_specs(), np.logspace(-2, 3, 1000), poles=[-247 * np.exp(1j * np.pi / 3),
                                                                        -247 * np.exp(-1j * np.pi / 3)], max_rounds=1)
    assert res.rounds == 1 and res.added.size == 0 and not res.passed


def test_refine_bad_input():
    cases, nom = manual_cases()
    tmpl = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    dense = np.logspace(-2, 3, 50)
    with pytest.raises(ValueError, match="systems"):
        refine(qft.Template.from_responses(OMEGAS, tmpl.responses), _manual_specs(), dense)
    with pytest.raises(ValueError, match="disk_radius"):
        refine(qft.Template.from_systems(cases, OMEGAS, nom, disk_radius=[0.1, 0.1, 0.2, 0.3]), _manual_specs(), dense)
    with pytest.raises(TypeError, match="Spec"):
        refine(tmpl, ["stability"], dense)
    with pytest.raises(TypeError, match="Template"):
        refine("template", _manual_specs(), dense)
    with pytest.raises(ValueError, match="max_rounds"):
        refine(tmpl, _manual_specs(), dense, max_rounds=0)
