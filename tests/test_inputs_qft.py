"""design_schedule's doors (issue "Nothing silently wrong, part two"): every target is checked
before the first design (a bad second target used to be refused only after 19 m/s was designed)."""
from __future__ import annotations

import pytest

from specdesign import qft
from specdesign.qft import design as qdesign
from specdesign.turbine import iea15mw


@pytest.fixture
def no_design(monkeypatch):
    def boom(*a, **k):
        raise AssertionError("a design was made before every target was checked")

    monkeypatch.setattr(qdesign, "design_qft", boom)


@pytest.mark.parametrize("targets, kind, match", [
    ([25, 0], ValueError, r"target_reduction\[1\]=0"),
    ([25, 100], ValueError, r"target_reduction\[1\]"),
    ([25, float("nan")], ValueError, r"target_reduction\[1\]"),
    ([25, True], TypeError, r"target_reduction\[1\]"),
    (["25", 25], TypeError, r"target_reduction\[0\]"),
    (True, TypeError, r"target_reduction"),
    ([25, 25, 25], ValueError, "3 values for 2 wind speeds"),
])
def test_design_schedule_checks_every_target_first(no_design, targets, kind, match):
    with pytest.raises(kind, match=match):
        qft.design_schedule(iea15mw(), [19, 21], targets)
