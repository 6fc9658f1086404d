"""Layout of loopshaping (issue 13): one home per concept, re-exports, deprecated names."""
from __future__ import annotations

import warnings

import control as ct
import numpy as np
import pytest

from loopshaping import check as lcheck
from loopshaping import qft
from loopshaping.controller import Controller, gain, real_pole

s = ct.tf("s")


def test_names_stay_importable_from_their_former_homes():
    from loopshaping.hinf import (HinfResult, ReductionResult, WellPosednessWarning, check_well_posed,  # noqa: F401
                                  discretize, mixed_sensitivity, reduce, synthesize)
    from loopshaping.qft import (KINDS, Bounds, BoundsWarning, Spec, Template, as_specs, bounds,  # noqa: F401
                                 evaluate, intersect, tracking_pairs)
    from loopshaping import bounds as b, freqresp, reduction, specs, templates, wellposed

    assert qft.Template is templates.Template and qft.Spec is specs.Spec and qft.bounds is b.bounds
    assert qft.evaluate is freqresp.evaluate and qft.check_grid is freqresp.check_grid
    assert reduce is reduction.reduce and check_well_posed is wellposed.check_well_posed


def test_as_siso_contract():
    from loopshaping.freqresp import as_siso

    G = 1 / (s + 1)
    assert as_siso(G) is G
    S = ct.ss(G)
    assert as_siso(S) is S
    k = as_siso(2.5)
    assert isinstance(k, ct.TransferFunction) and float(k.num[0][0][0]) == 2.5
    for bad in ("1/(s+1)", [1.0, 2.0], lambda w: w, 1 + 2j, True, None):
        with pytest.raises(TypeError, match="plant"):
            as_siso(bad, "plant")
    with pytest.raises(ValueError, match="plant"):
        as_siso(ct.ss(np.eye(2) * -1, np.eye(2), np.eye(2), np.zeros((2, 2))), "plant")
    with pytest.raises(ValueError, match="improper"):
        as_siso(s**2 / (s + 1), "plant")
    assert as_siso(s**2 / (s + 1), proper=False) is not None
    with pytest.raises(ValueError, match="discrete"):
        as_siso(ct.tf([1], [1, -0.5], 0.1), "plant")
    with pytest.raises(ValueError, match="finite"):
        as_siso(np.inf, "plant")


def test_check_grid_and_evaluate():
    from loopshaping.freqresp import check_grid, evaluate, is_lti

    np.testing.assert_array_equal(check_grid([1.0, 2.0]), [1.0, 2.0])
    with pytest.raises(ValueError, match="omega must be strictly increasing"):
        check_grid([2.0, 1.0])
    assert is_lti(s) and not is_lti(1.0)
    np.testing.assert_array_equal(evaluate(1 / (s + 1), [1.0]), [1 / (1j + 1)])


def _template():
    return qft.Template.from_systems([1 / (s + 1), 2 / (s + 1)], [0.1, 1.0])


def test_omegas_is_a_deprecated_alias_of_omega():
    t = _template()
    with pytest.warns(DeprecationWarning, match="Template.omega"):
        np.testing.assert_array_equal(t.omegas, t.omega)
    with pytest.warns(DeprecationWarning, match="'omega'"):
        t2 = qft.Template.from_systems([1 / (s + 1)], omegas=[0.1, 1.0])
    np.testing.assert_array_equal(t2.omega, t.omega)
    with pytest.warns(DeprecationWarning, match="'omega'"):
        t3 = qft.Template(omegas=[0.1, 1.0], responses=t.responses)
    np.testing.assert_array_equal(t3.responses, t.responses)
    with pytest.raises(TypeError, match="both"):
        qft.Template.from_systems([1 / (s + 1)], omega=[1.0], omegas=[1.0])
    b = qft.bounds(t, "sensitivity", 2.0)
    with pytest.warns(DeprecationWarning, match="Bounds.omega"):
        np.testing.assert_array_equal(b.omegas, b.omega)
    with pytest.warns(DeprecationWarning, match="'omega'"):
        t.at(omegas=1.0)


def test_check_takes_plants_first_and_warns_on_the_former_order():
    t = _template()
    G = Controller((gain(2.0), real_pole(10.0)))
    spec = qft.Spec("sensitivity", 2.0)
    w = np.logspace(-2, 2, 50)
    new = lcheck.check(t, G, spec, w)
    with pytest.warns(DeprecationWarning, match=r"check\(plants, controller"):
        old = lcheck.check(G, t, spec, w)
    with pytest.warns(DeprecationWarning, match="'omega'"):
        kw = lcheck.check(t, G, spec, omega_dense=w)
    for r in (old, kw):
        np.testing.assert_array_equal(r.margins_db, new.margins_db)
        np.testing.assert_array_equal(r.max_pole_real, new.max_pole_real)
    with pytest.warns(DeprecationWarning, match="CheckResult.omega"):
        np.testing.assert_array_equal(new.omegas, new.omega)


def test_closed_loop_poles_is_deprecated_for_feedback_poles():
    P, G = 1 / (s * (s + 1)), 2 * (s + 3) / (s + 10)
    want = lcheck.feedback_poles(P, G)
    with pytest.warns(DeprecationWarning, match="feedback_poles"):
        got = lcheck.closed_loop_poles(G, P)
    np.testing.assert_array_equal(got, want)


def test_internal_callers_use_no_deprecated_form():
    t = _template()
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)
        b = qft.intersect(qft.bounds(t, "sensitivity", 2.0), qft.bounds(t, "stability", 1.3))
        lcheck.check(t, Controller((gain(1.0),)), b, np.logspace(-2, 2, 50))
        from loopshaping.nichols import loop_nichols

        loop_nichols(1 / (s + 1), np.logspace(-1, 1, 5))


def test_hf_omegas_and_omega_dense_keywords_are_deprecated():
    from loopshaping import auto

    with pytest.warns(DeprecationWarning, match="'hf_omega'"), pytest.raises(TypeError, match="Bounds"):
        auto.shape("not bounds", hf_omegas=[100.0])
    with pytest.warns(DeprecationWarning, match="'omega'"), pytest.raises(TypeError, match="Template"):
        auto.refine("not a template", [], omega_dense=[1.0])
