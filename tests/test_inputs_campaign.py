"""Campaign and controller files: every key at every level and every type is checked before
the first simulation, and the CLI answers a user error with one line and exit code 2
(issue "Nothing silently wrong", §4)."""
from __future__ import annotations

import json

import pytest

from specdesign import validate as va
from specdesign.__main__ import main

PI = {"num": [-0.3, -0.06], "den": [1.0, 0.0]}
GOOD = {"wind_speeds": [19.0], "seeds": 2, "duration": 30.0, "transient": 5.0,
        "controllers": {"PI": {"file": "pi.json"}, "ROSCO": {"kind": "rosco"}}}


def _write(tmp_path, cfg, controller=PI, name="c.json"):
    (tmp_path / "pi.json").write_text(json.dumps(controller))
    (tmp_path / name).write_text(json.dumps(cfg))
    return tmp_path / name


@pytest.fixture
def no_simulation(monkeypatch):
    # everything must be refused before any run starts
    def boom(*a, **k):
        raise AssertionError("run_campaign was called before the file was fully checked")

    monkeypatch.setattr(va, "run_campaign", boom)


def _bad(tmp_path, change, match, controller=PI):
    cfg = json.loads(json.dumps(GOOD))
    change(cfg)
    path = _write(tmp_path, cfg, controller)
    with pytest.raises(va.ConfigError, match=match):
        va.read_config(path)
    return path


@pytest.mark.parametrize("change, match", [
    (lambda c: c.update(colour="red"), r"unknown key\(s\) \['colour'\]"),
    (lambda c: c["controllers"]["PI"].update(fiel="x.json"), r"unknown key\(s\) \['fiel'\] in controllers.PI"),
    (lambda c: c["controllers"]["ROSCO"].update(file="pi.json"), r"unknown key\(s\) \['file'\] in controllers.ROSCO"),
    (lambda c: c.update(seeds=2.5), "seeds must be an integer n"),
    (lambda c: c.update(seeds=True), "seeds must be an integer n"),
    (lambda c: c.update(seeds=[1, 1]), "seeds must be distinct"),
    (lambda c: c.update(seeds=["1"]), "seeds must be an integer n"),
    (lambda c: c.update(seeds=0), "must be ≥ 1"),
    (lambda c: c.update(linear_twin="false"), "linear_twin must be true or false"),
    (lambda c: c.update(duration=-600), "duration must be a positive number"),
    (lambda c: c.update(duration="600"), "duration must be a positive number"),
    (lambda c: c.update(transient=-1), "transient must be a number ≥ 0"),
    (lambda c: c.update(record_dt=0.03), "record_dt must be a whole multiple of dt"),
    (lambda c: c.update(dt=1.0, record_dt=1.0), r"dt=1 s is too large"),
    (lambda c: c.update(volterra=True), "volterra must be 0"),
    (lambda c: c.update(turbulence_class="D"), "turbulence_class"),
    (lambda c: c.update(wind_speeds=[40.0]), "wind_speeds: .*outside"),
    (lambda c: c.update(baseline="ROSCOO"), r"baseline must be one of the controllers \['PI', 'ROSCO'\]"),
    (lambda c: c.update(promised={"17": 10.0}), "promised.17 must be at one of the wind_speeds"),
    (lambda c: c.update(promised={"19": "ten"}), "promised.19 must be a promised reduction"),
    (lambda c: c.update(controllers={}), "controllers must be a table"),
])
def test_campaign_file_errors_name_the_key(tmp_path, no_simulation, change, match):
    path = _bad(tmp_path, change, match)
    # the CLI: one line naming file and key, exit code 2, no traceback
    assert main(["validate", str(path)]) == 2


@pytest.mark.parametrize("controller, match", [
    ({"pitch": PI, "atdd": PI}, r"unknown key\(s\) \['atdd'\]"),
    ({"num": [-0.3, -0.06], "den": [1.0, 0.0], "gain": 2}, "exactly 'num' and 'den'"),
    ({"num": [-0.3, "x"], "den": [1.0, 0.0]}, r"the file.num must be a non-empty list of finite numbers"),
    ({"num": [1.0, 2.0, 3.0], "den": [1.0, 0.0]}, "proper"),
    ({"num": [1.0], "den": [0.0, 1.0]}, "leading coefficient"),
    ({"wind_speeds": [19.0], "pitch": [PI, PI]}, r"pitch must be a list of one controller per wind speed \(1\)"),
    ({"elements": [{"kind": "integrator", "params": {"order": 1e9}}]}, r"element 0: integrator: order"),
    ({"elements": [{"kind": "gain", "params": {"k": -1.0}}, {"kind": "notch", "params": {"omega": 1.0}}]},
     r"element 1: element 'notch' takes parameters"),
    ({"elements": [{"kind": "gain"}]}, r"element 0: must be an object with exactly 'kind' and 'params'"),
    ({"version": 1, "elements": [], "extra": 0}, r"unknown controller keys \['extra'\]"),
    ([1, 2], "holds a JSON object"),
])
def test_controller_file_errors_name_the_key(tmp_path, no_simulation, controller, match):
    _bad(tmp_path, lambda c: None, match, controller)


def test_unwritable_output_is_refused_before_any_run(tmp_path, no_simulation, capsys):
    (tmp_path / "afile").write_text("")
    cfg = dict(GOOD, output="afile/sub")  # a folder under a regular file cannot be created
    path = _write(tmp_path, cfg)
    with pytest.raises(OSError):
        va.read_config(path)
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "afile" in err


def test_invalid_syntax_and_missing_files_are_user_errors(tmp_path, capsys):
    (tmp_path / "bad.toml").write_text("wind_speeds = [19.0\n")
    assert main(["validate", str(tmp_path / "bad.toml")]) == 2
    assert "invalid TOML" in capsys.readouterr().err
    assert main(["validate", str(tmp_path / "missing.toml")]) == 2
    cfg = dict(GOOD, controllers={"PI": {"file": "nothere.json"}})
    (tmp_path / "c2.json").write_text(json.dumps(cfg))
    assert main(["validate", str(tmp_path / "c2.json")]) == 2
    assert "controllers.PI.file" in capsys.readouterr().err


def test_an_integer_means_the_same_seeds_in_a_file_and_in_run_campaign(tmp_path):
    # documented meaning (docs/validation.md): n → the seeds 0..n−1
    c = va.read_config(_write(tmp_path, GOOD))
    assert c["seeds"].tolist() == [0, 1] == va.seeds_from(2).tolist()
    assert va.read_config(_write(tmp_path, dict(GOOD, seeds=[5, 7])))["seeds"].tolist() == [5, 7]
