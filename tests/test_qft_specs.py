"""design_qft takes one kind of specification (issue 32): the records its named functions make,
and the design each one leads to.

The routing tests replace the design steps by recorders, so they run in well under a second: each
asserts the exact call the string/tuple forms of design_qft made before the change (commit
480fc96: ``spec="target"``, ``spec="notch"``, a TargetSpecification, a pair), so the designs are
bitwise those of before (a fingerprint of the controllers and promises of every form was compared
once, before and after, on the full designs).
"""
from __future__ import annotations

import dataclasses

import pytest

from specdesign import feasibility, qft
from specdesign import spec as sp
from specdesign.qft import design as qdesign
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def pair(model):
    ds = sp.design_specifications(model, 19.0)
    return ds.tower, ds.speed


@dataclasses.dataclass(frozen=True)
class _Design:
    """A stand-in for a design's record: what design_qft reads of it."""

    success: bool
    wind_speed: float = 19.0
    message: str = "missed"


class _Made:
    """What a design step was called with (positional and keyword arguments); its designs
    succeed as ``outcomes`` says (each failing once it runs out)."""

    def __init__(self, like):
        self.calls, self.outcomes = [], []
        self.__wrapped__ = like  # its signature, which design_qft reads its option names from

    def __call__(self, *args, **kwargs):
        self.calls.append((args, kwargs))
        return _Design(self.outcomes.pop(0) if self.outcomes else False)


@pytest.fixture
def steps(monkeypatch):
    """design_qft's three steps recorded instead of run: the fixed structures, the certificate
    reduction and the making of the certified pair (a stand-in TargetSpecification)."""
    single, certificate = _Made(qdesign._design_single), _Made(qdesign.design_from_certificate)
    made = _Made(qdesign.specification_for_target)
    fake = feasibility.TargetSpecification.__new__(feasibility.TargetSpecification)

    def target(*args, **kwargs):
        made(*args, **kwargs)
        return fake

    monkeypatch.setattr(qdesign, "_design_single", single)
    monkeypatch.setattr(qdesign, "design_from_certificate", certificate)
    monkeypatch.setattr(qdesign, "specification_for_target", target)
    monkeypatch.setattr(qdesign, "spec_made_at", lambda spec, v: None)
    monkeypatch.setattr(feasibility.TargetSpecification, "tower", "W_MyT", raising=False)
    monkeypatch.setattr(feasibility.TargetSpecification, "speed", "W_Ω", raising=False)
    monkeypatch.setattr(feasibility.TargetSpecification, "wind_speed", 19.0, raising=False)
    return single, certificate, made, fake


def test_the_records_say_what_they_are(pair):
    n = qft.spec_notch(20.0, speed_relax_db=4.5)
    assert (n.kind, n.target_reduction, n.speed_relax_db, n.tower) == ("notch", 20.0, (4.5,), None)
    assert qft.spec_notch().speed_relax_db == qft.SPEED_RELAX_DB  # QFT's ladder by default
    p = qft.spec_from_pair(*pair, wind_speed=19.0)
    assert (p.kind, p.tower, p.speed, p.wind_speed, p.target) == ("pair", pair[0], pair[1], 19.0, None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.kind = "notch"
    with pytest.raises(ValueError, match="kind='youla' must be one of"):
        qft.QFTSpecification("youla", *pair)
    with pytest.raises(ValueError, match="'notch' specification has no pair"):
        qft.QFTSpecification("notch", *pair)


def test_bad_specifications_are_named(pair):
    with pytest.raises(TypeError, match="target must be a feasibility.TargetSpecification.*spec_from_pair"):
        qft.spec_from_certified(pair)
    with pytest.raises(TypeError, match="speed must be a specification with response"):
        qft.spec_from_pair(pair[0], 2.0)
    with pytest.raises(ValueError, match="speed_relax_db=.* must increase"):
        qft.spec_notch(speed_relax_db=(4.5, 3.0))
    with pytest.raises(ValueError, match="speed_relax_db=.* ≥ 0 dB"):
        qft.spec_notch(speed_relax_db=float("nan"))
    with pytest.raises(TypeError, match="target_reduction"):
        qft.spec_notch("25")


def test_the_default_makes_the_certified_pair_and_reduces_its_certificate(model, steps):
    # was spec="target": specification_for_target(model, v, target, case_offsets=..., max_hf_gain_ratio=...)
    # then design_from_certificate(model, ts, **the certificate's options)
    single, certificate, made, fake = steps
    qft.design_qft(model, 19.0, 20.0, template_offsets=(-0.5, 0.5), max_hf_gain_ratio=None, max_sensitivity=2.0)
    assert made.calls == [((model, 19.0, 20.0), {"case_offsets": (-0.5, 0.5), "max_hf_gain_ratio": None})]
    assert certificate.calls == [((model, fake), {"max_sensitivity": 2.0})] and not single.calls


def test_the_default_fixed_structure_meets_the_plain_certified_pair(model, steps):
    # was spec="target", structure="fixed": the pair made without the certificate's options, which
    # go to the fixed structures with the first rung of QFT's ladder
    single, certificate, made, _ = steps
    qft.design_qft(model, 19.0, structure="fixed", template_offsets=(-1.0, 1.0), maxfev=5)
    assert made.calls == [((model, 19.0, qdesign.TARGET_REDUCTION), {})] and not certificate.calls
    assert single.calls == [((model, 19.0, None), {"speed_relax_db": 3.0, "given": ("W_MyT", "W_Ω"),
                                                    "template_offsets": (-1.0, 1.0), "maxfev": 5})]


def test_a_certified_pair_is_met_as_before(model, steps):
    # was spec=ts (certificate) and spec=ts, structure="fixed"
    single, certificate, made, fake = steps
    s = qft.spec_from_certified(fake)
    assert (s.kind, s.target, s.tower, s.speed, s.wind_speed) == ("certified", fake, "W_MyT", "W_Ω", 19.0)
    qft.design_qft(model, 19.0, spec=s, min_decay=0.03)
    qft.design_qft(model, 19.0, spec=s, structure="fixed", refine=0)
    assert certificate.calls == [((model, fake), {"min_decay": 0.03})] and not made.calls
    assert single.calls == [((model, 19.0, None), {"speed_relax_db": 3.0, "given": ("W_MyT", "W_Ω"), "refine": 0})]


def test_a_given_pair_is_met_by_the_fixed_structures(model, pair, steps):
    # was spec=(tower, speed)
    single, certificate, made, _ = steps
    qft.design_qft(model, 19.0, spec=qft.spec_from_pair(*pair), maxfev=3)
    assert single.calls == [((model, 19.0, None), {"speed_relax_db": 3.0, "given": pair, "maxfev": 3})]
    assert not certificate.calls and not made.calls


def test_the_notch_design_climbs_its_ladder(model, steps):
    # was spec="notch", target_reduction=20, speed_relax_db=(3, 6): one design per rung, with the
    # DEL target, until one succeeds (else the last, with a warning)
    single, certificate, made, _ = steps
    single.outcomes = [False, True]
    d = qft.design_qft(model, 19.0, spec=qft.spec_notch(20.0, speed_relax_db=(3.0, 6.0)), maxfev=7)
    assert d.success
    assert single.calls == [((model, 19.0, 20.0), {"speed_relax_db": 3.0, "maxfev": 7}),
                            ((model, 19.0, 20.0), {"speed_relax_db": 6.0, "maxfev": 7})]
    with pytest.warns(RuntimeWarning, match=r"relaxed up to 4.5 dB\): missed"):
        assert not qft.design_qft(model, 19.0, spec=qft.spec_notch(20.0, speed_relax_db=4.5)).success
    assert not certificate.calls and not made.calls


def test_a_schedule_of_notch_designs_gives_each_speed_its_target(model, steps, monkeypatch):
    # was design_schedule(model, speeds, (20, 30), specification="notch"): the same calls, from
    # one notch specification per speed
    single, *_ = steps
    monkeypatch.setattr(qdesign, "_warn_held_design", lambda model, design: None)  # the stand-ins have no controller
    with pytest.warns(RuntimeWarning):  # no rung of the stand-ins succeeds: each speed climbs the whole ladder
        qft.design_schedule(model, (19.0, 21.0), spec=[qft.spec_notch(20.0), qft.spec_notch(30.0)], progress=False)
    assert [(c[0][1:], c[1]["speed_relax_db"]) for c in single.calls] == [
        ((v, t), r) for v, t in ((19.0, 20.0), (21.0, 30.0)) for r in qft.SPEED_RELAX_DB]


def test_one_notch_specification_is_applied_at_every_speed(model, steps, monkeypatch):
    # was design_schedule(model, speeds, 20, specification="notch"): its target and its ladder at each speed
    single, certificate, made, _ = steps
    monkeypatch.setattr(qdesign, "_warn_held_design", lambda model, design: None)  # the stand-ins have no controller
    single.outcomes = [True, False, True]
    designs = qft.design_schedule(model, (19.0, 21.0), spec=qft.spec_notch(20.0, speed_relax_db=(3.0, 6.0)),
                                  progress=False, maxfev=5)
    assert [d.success for d in designs] == [True, True]
    assert single.calls == [((model, 19.0, 20.0), {"speed_relax_db": 3.0, "maxfev": 5}),
                            ((model, 21.0, 20.0), {"speed_relax_db": 3.0, "maxfev": 5}),
                            ((model, 21.0, 20.0), {"speed_relax_db": 6.0, "maxfev": 5})]
    assert not certificate.calls and not made.calls


def test_a_schedule_without_spec_makes_the_certified_pair_at_each_speed(model, steps, monkeypatch):
    # was design_schedule(model, speeds, 20) with specification="target", the default: the pair for
    # the target made at each speed, the lowest design held below rated (a model with a torque law)
    single, certificate, made, fake = steps
    monkeypatch.setattr(qdesign, "_warn_held_design", lambda model, design: None)  # the stand-ins have no controller
    qft.design_schedule(model, (21.0, 19.0), 20.0, progress=False)
    assert [c[0][1:] for c in made.calls] == [(21.0, 20.0), (19.0, 20.0)]
    held = [c[1].get("held_below_rated", False) for c in made.calls]
    assert held == [False, model.torque_control is not None]
    assert len(certificate.calls) == 2 and not single.calls


def test_a_schedule_refuses_a_specification_made_at_one_speed(model, pair):
    for spec in (qft.spec_from_pair(*pair, wind_speed=19.0), "notch"):
        with pytest.raises(TypeError, match="spec_notch.*spec_from_certified or qft.spec_from_pair"):
            qft.design_schedule(model, (19.0, 21.0), spec=spec, progress=False)
    with pytest.raises(TypeError, match="target_reduction or spec, not both"):
        qft.design_schedule(model, (19.0,), 20.0, spec=qft.spec_notch(20.0), progress=False)
    with pytest.raises(ValueError, match="1 specifications for 2 wind speeds"):
        qft.design_schedule(model, (19.0, 21.0), spec=[qft.spec_notch()], progress=False)


def test_options_of_the_other_design_are_refused_with_the_way_to_them(model, pair, steps):
    with pytest.raises(TypeError, match=r"\['keep_below'\] belong to the fixed-structure design.*spec_notch"):
        qft.design_qft(model, 19.0, keep_below=0.5)
    with pytest.raises(TypeError, match="held_below_rated belongs to the specification-driven default"):
        qft.design_qft(model, 19.0, spec=qft.spec_notch(), held_below_rated=True)
    with pytest.raises(ValueError, match="structure='certificate' needs a certified specification"):
        qft.design_qft(model, 19.0, spec=qft.spec_from_pair(*pair), structure="certificate")
