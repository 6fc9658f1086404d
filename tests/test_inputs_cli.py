"""The demo's command line (issue "Nothing silently wrong, part two" and the aimable demo of
"Layers without cycles ...", item 6): --wind-speed, --target, --seeds, --duration for the
design demo, --design-speeds and --bin-width for --lifetime; every user error is one line on
stderr and exit code 2, before any design or simulation (and before the output folder is made)."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specdesign import demo
from specdesign.cli import main
from specdesign.qft import design as qdesign


@pytest.fixture
def no_work(monkeypatch):
    # the CLI imports run_demo / run_lifetime_demo from specdesign.demo at call time
    def boom(*a, **k):
        raise AssertionError("work started before the options were checked")

    for name in ("run_demo", "run_lifetime_demo"):
        monkeypatch.setattr(demo, name, boom)
    monkeypatch.setattr(qdesign, "design_qft", boom)


def _refused(capsys, tmp_path, *args):
    out = tmp_path / "out"
    assert main(["demo", "--out", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("specdesign demo: error: "), err  # one line, no traceback
    assert not out.exists()  # refused before the output folder was made
    return err


@pytest.mark.parametrize("args, flag", [
    (("--lifetime", "--design-speeds", "5,7"), "--design-speeds[0]: wind_speed=5.0"),  # used to print a traceback
    (("--lifetime", "--design-speeds", "19,30"), "--design-speeds[1]"),
    (("--lifetime", "--design-speeds", "19,19"), "--design-speeds"),
    (("--lifetime", "--design-speeds", "19,x"), "--design-speeds"),
    (("--lifetime", "--bin-width", "1e-9"), "--bin-width"),  # used to print a traceback (2e10 bins)
    (("--lifetime", "--bin-width", "5"), "--bin-width"),
    (("--lifetime", "--bin-width", "-2"), "--bin-width"),
    (("--lifetime", "--duration", "-1"), "--duration"),  # used to fail after ~27 s of designs
    (("--lifetime", "--seeds", "1"), "--seeds"),
    (("--lifetime", "--target", "0"), "--target"),
    (("--lifetime", "--wind-speed", "19"), "--wind-speed belongs to the design demo"),
    (("--lifetime", "--method", "notch"), "--method belongs to the design demo"),
    (("--wind-speed", "5"), "--wind-speed=5.0 m/s is below rated"),
    (("--wind-speed", "30"), "--wind-speed"),
    (("--wind-speed", "nan"), "--wind-speed"),
    (("--wind-speed", "fast"), "--wind-speed='fast' must be a number"),
    (("--target", "0"), "--target"),
    (("--target", "100"), "--target"),
    (("--target", "-5"), "--target"),
    (("--target", "inf"), "--target"),
    (("--target", "25%"), "--target='25%' must be a number"),
    (("--seeds", "1"), "--seeds=1: the paired change's standard error needs at least 2"),
    (("--seeds", "0"), "--seeds"),  # 0 used to mean "the default"
    (("--seeds", "2.5"), "--seeds='2.5' must be a whole number"),
    (("--duration", "0"), "--duration"),
    (("--duration", "-1"), "--duration"),
    (("--duration", "0.5"), "--duration"),
    (("--duration", "1e9"), "--duration"),
    (("--bin-width", "2"), "--bin-width belongs to --lifetime"),
    (("--design-speeds", "19"), "--design-speeds belongs to --lifetime"),
])
def test_a_bad_option_is_one_line_and_exit_2_before_any_work(no_work, capsys, tmp_path, args, flag):
    assert flag in _refused(capsys, tmp_path, *args)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(st.floats(max_value=0.999), st.floats(min_value=86400.001), st.just(float("nan"))))
def test_every_duration_outside_1_86400_s_is_refused(no_work, capsys, tmp_path_factory, d):
    # the "--duration=X" form: argparse takes "-1e-05" or "-inf" after a space for an option
    assert "--duration" in _refused(capsys, tmp_path_factory.mktemp("d"), f"--duration={d!r}")


def test_the_design_demo_can_be_aimed(monkeypatch, tmp_path):
    # valid options reach run_demo as given
    seen = {}
    monkeypatch.setattr(demo, "run_demo", lambda **k: seen.update(k))
    assert main(["demo", "--out", str(tmp_path / "o"), "--wind-speed", "21", "--target", "20", "--seeds", "3",
                 "--duration", "60", "--method", "notch"]) == 0
    assert seen == dict(out=str(tmp_path / "o"), fast=False, method="notch", wind_speed=21.0, target_reduction=20.0,
                        n_seeds=3, duration=60.0)


def test_the_lifetime_demo_takes_seeds_duration_and_target(monkeypatch, tmp_path):
    seen = {}
    monkeypatch.setattr(demo, "run_lifetime_demo", lambda **k: seen.update(k))
    assert main(["demo", "--lifetime", "--out", str(tmp_path / "o"), "--seeds", "2", "--duration", "30",
                 "--design-speeds", "15,19", "--bin-width", "1", "--target", "20"]) == 0
    assert seen["n_seeds"] == 2 and seen["duration"] == 30.0 and seen["design_speeds"] == (15.0, 19.0)
    assert seen["bin_width"] == 1.0 and seen["target_reduction"] == 20.0


@pytest.mark.parametrize("kw, kind, match", [
    (dict(n_seeds=True), TypeError, "n_seeds"), (dict(n_seeds=2.0), TypeError, "n_seeds"),
    (dict(duration="60"), TypeError, "duration"), (dict(wind_speed=True), TypeError, "wind_speed"),
    (dict(target_reduction=True), TypeError, "target_reduction"), (dict(spec_reduction=0), ValueError, "spec_reduction"),
])
def test_run_demo_checks_its_arguments_before_any_work(tmp_path, kw, kind, match):
    out = tmp_path / "o"
    with pytest.raises(kind, match=match):
        demo.run_demo(out=out, **kw)
    assert not out.exists()


@pytest.mark.parametrize("kw, match", [
    (dict(design_speeds=[19, 21], duration=-1), "duration"), (dict(design_speeds=[]), "design_speeds"),
    (dict(design_speeds="19"), "design_speeds"), (dict(design_speeds=[19, 5]), r"design_speeds\[1\]"),
    (dict(bin_width=1e-9), "bin_width"), (dict(target_reduction=0), "target_reduction"),
])
def test_run_lifetime_demo_checks_everything_before_the_first_design(monkeypatch, tmp_path, kw, match):
    def boom(*a, **k):
        raise AssertionError("a design was made before every option was checked")

    monkeypatch.setattr(qdesign, "design_qft", boom)
    with pytest.raises(ValueError, match=match):
        demo.run_lifetime_demo(out=tmp_path / "o", **kw)
    assert not (tmp_path / "o").exists()
