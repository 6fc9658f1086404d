"""Layout of loopshaping (issue 13): one home per concept, re-exports; no deprecated names (issue 32)."""
from __future__ import annotations

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


def test_the_former_names_are_gone():
    # renamed before the first release (issue 32): one name per meaning, no alias left behind
    t = _template()
    b = qft.bounds(t, "sensitivity", 2.0)
    G = Controller((gain(2.0), real_pole(10.0)))
    w = np.logspace(-2, 2, 50)
    res = lcheck.check(t, G, qft.Spec("sensitivity", 2.0), w)
    for obj in (t, b, res):
        assert not hasattr(obj, "omegas") and obj.omega.size > 0
    assert not hasattr(lcheck, "closed_loop_poles")
    with pytest.raises(TypeError, match="omegas"):
        qft.Template.from_systems([1 / (s + 1)], omegas=[0.1, 1.0])
    with pytest.raises(TypeError, match="omegas"):
        t.at(omegas=1.0)
    with pytest.raises(TypeError, match="omega_dense"):
        lcheck.check(t, G, qft.Spec("sensitivity", 2.0), omega_dense=w)


def test_check_takes_the_plants_first():
    # check(controller, plants, ...) was guessed and swapped; now the first argument is the plants
    t = _template()
    G = Controller((gain(2.0), real_pole(10.0)))
    spec = qft.Spec("sensitivity", 2.0)
    w = np.logspace(-2, 2, 50)
    res = lcheck.check(t, G, spec, w)
    # oracle: the feedback poles of each plant case with G, computed on their own
    want = [np.max(lcheck.feedback_poles(p, G).real) for p in t.systems]
    np.testing.assert_array_equal(res.max_pole_real, want)
    with pytest.raises(TypeError):
        lcheck.check(G, t, spec, w)
