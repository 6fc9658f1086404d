"""Campaign and controller files: every key at every level and every type is checked before
the first simulation, and the CLI answers a user error with one line and exit code 2
(issue "Nothing silently wrong", §4)."""
from __future__ import annotations

import json
import os

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specdesign import cli, validate as va
from specdesign.cli import main

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

    monkeypatch.setattr(cli, "run_campaign", boom)


def _bad(tmp_path, change, match, controller=PI):
    cfg = json.loads(json.dumps(GOOD))
    change(cfg)
    path = _write(tmp_path, cfg, controller)
    with pytest.raises(cli.ConfigError, match=match):
        cli.read_config(path)
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
    # strict types and ranges beyond the first list
    (lambda c: c.update(seeds=[-1, 2]), "0 ≤ seed < 2\\*\\*32"),
    (lambda c: c.update(seeds=[2**70]), "0 ≤ seed < 2\\*\\*32"),  # was an OverflowError traceback
    (lambda c: c.update(seeds=2.0), "seeds must be an integer n"),
    (lambda c: c.update(volterra=2.0), "volterra must be 0"),
    (lambda c: c.update(wind_speeds=[19.0, 19.0]), "wind_speeds must be a list of distinct wind speeds"),
    (lambda c: c.update(wind_speeds=["19"]), "wind_speeds must be a non-empty list"),
    (lambda c: c.update(duration=0.5), "duration must be at least 10 output samples"),
    (lambda c: c.update(duration=1e12), "duration must be at most 86400 s"),
    (lambda c: c.update(transient=1e9), "transient must be at most 86400 s"),
    (lambda c: c.update(dt=float("nan")), "dt must be a positive number"),
    (lambda c: c.update(designed=["PI"]), "designed must be one of the controllers"),
    (lambda c: c.update(baseline="PI", designed="PI"), "designed must be another controller than baseline='PI'"),
    (lambda c: c.update(promised={"19": 10.0, "19.0": 12.0}), r"promised.19.0 must be given once"),
    (lambda c: c.update(promised={"19": {"5": 10.0}}), r"quote a decimal wind speed in TOML: \"19.5\""),
    (lambda c: c.update(promised={"19": 150.0}), r"promised.19 must be a promised reduction in % \(a number < 100\)"),
    (lambda c: c.update(promised=None), "promised must be a table"),
    (lambda c: c.update(output=""), "output must be a folder name"),
    (lambda c: c["controllers"]["ROSCO"].update(kind=["rosco"]), r"controllers.ROSCO.kind=\['rosco'\] must be"),
    (lambda c: c["controllers"]["ROSCO"].update(name=5), "controllers.ROSCO.name must be a non-empty string"),
    (lambda c: c["controllers"]["ROSCO"].update(wind_speeds=[5.0, 19.0]), "controllers.ROSCO.wind_speeds: .*outside"),
    (lambda c: c["controllers"]["ROSCO"].update(wind_speeds=[19.0, 19.0]), "controllers.ROSCO.wind_speeds must be .*distinct"),
    (lambda c: c["controllers"]["PI"].update(file="."), r"controllers.PI.file: .* is not a file"),
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
    ({"num": [0.0], "den": [1.0, 1.0]}, "non-zero controller"),
    ({"atd": PI}, r"unknown key\(s\) \['atd'\]; a controller file holds"),
    ({"pitch": PI, "atd": {"num": [0.0, 0.0], "den": [1.0, 2.0]}}, "atd must be a non-zero controller"),
    ({"wind_speeds": [19.0, 19.0], "pitch": [PI, PI]}, "wind_speeds must be a list of distinct wind speeds"),
    ({"wind_speeds": [5.0, 19.0], "pitch": [PI, PI]}, "wind_speeds: wind_speed=5.0 m/s is outside"),
    ({"wind_speeds": [17.0, 19.0], "pitch": [PI, {"num": [1.0], "den": "s+1"}]}, r"pitch\[1\].den must be"),
    ({"wind_speeds": [17.0, 19.0]}, r"pitch must be a list of one controller per wind speed \(2\)"),
    ({"elements": [{"kind": "differentiator", "params": {"order": 2}}]}, "proper"),  # elements get the same checks
    ({"version": True, "elements": []}, "format version True"),
])
def test_controller_file_errors_name_the_key(tmp_path, no_simulation, controller, match):
    _bad(tmp_path, lambda c: None, match, controller)


def test_unwritable_output_is_refused_before_any_run(tmp_path, no_simulation, capsys):
    (tmp_path / "afile").write_text("")
    cfg = dict(GOOD, output="afile/sub")  # a folder under a regular file cannot be created
    path = _write(tmp_path, cfg)
    with pytest.raises(OSError):
        cli.read_config(path)
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
    c = cli.read_config(_write(tmp_path, GOOD))
    assert c["seeds"].tolist() == [0, 1] == va.seeds_from(2).tolist()
    assert cli.read_config(_write(tmp_path, dict(GOOD, seeds=[5, 7])))["seeds"].tolist() == [5, 7]


@pytest.mark.parametrize("text, match", [
    ('{"wind_speeds": [19.0], "seeds": 2, "seeds": 3, "controllers": {"PI": {"file": "pi.json"}}}',
     "key 'seeds' appears twice"),
    ('{"wind_speeds": [19.0], "seeds": 2, "controllers": {"PI": {"file": "pi.json", "file": "x.json"}}}',
     "key 'file' appears twice"),
])
def test_a_repeated_json_key_is_an_error_not_the_last_value(tmp_path, no_simulation, text, match):
    (tmp_path / "pi.json").write_text(json.dumps(PI))
    (tmp_path / "c.json").write_text(text)
    with pytest.raises(cli.ConfigError, match=match):
        cli.read_config(tmp_path / "c.json")
    (tmp_path / "pi.json").write_text('{"num": [1.0], "num": [2.0], "den": [1.0, 1.0]}')
    (tmp_path / "c2.json").write_text(json.dumps(GOOD))
    with pytest.raises(cli.ConfigError, match=r"pi.json: key 'num' appears twice"):
        cli.read_config(tmp_path / "c2.json")


def test_a_campaign_file_is_toml_or_json_by_its_extension(tmp_path, no_simulation):
    (tmp_path / "pi.json").write_text(json.dumps(PI))
    (tmp_path / "c.cfg").write_text(json.dumps(GOOD))
    with pytest.raises(cli.ConfigError, match=r"c.cfg: a campaign file is a .toml or .json file"):
        cli.read_config(tmp_path / "c.cfg")
    (tmp_path / "c.toml").write_text('wind_speeds = [19.0]\nseeds = 2\nduration = 30.0\n[controllers.PI]\nfile = "pi.json"\n'
                                     '[promised]\n19.0 = 10.0\n')  # unquoted: the dotted key 19 → 0
    with pytest.raises(cli.ConfigError, match=r'quote a decimal wind speed in TOML: "19.0"'):
        cli.read_config(tmp_path / "c.toml")
    with pytest.raises(cli.ConfigError, match="not a file"):
        cli.read_config(tmp_path)


def test_a_controller_file_that_is_not_utf8_json_names_the_file(tmp_path, no_simulation):
    (tmp_path / "c.json").write_text(json.dumps(GOOD))
    (tmp_path / "pi.json").write_bytes(b"\xff\x00\x81{")
    with pytest.raises(cli.ConfigError, match=r"pi.json: a controller file must be valid UTF-8 JSON"):
        cli.read_config(tmp_path / "c.json")


def test_the_output_folder_named_by_out_is_checked_too(tmp_path, no_simulation, capsys):
    path = _write(tmp_path, GOOD)
    (tmp_path / "taken").write_text("")
    with pytest.raises(OSError, match=r"--out: the output folder .*taken.* cannot be created or written"):
        cli.read_config(path, out=tmp_path / "taken")
    assert main(["validate", str(path), "--out", str(tmp_path / "taken")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--out" in err and "writable" in err


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs POSIX permissions and a non-root user")
def test_a_read_only_output_folder_is_refused_before_any_run(tmp_path, no_simulation, capsys):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        path = _write(tmp_path, dict(GOOD, output="ro"))
        with pytest.raises(PermissionError, match=r"output: the output folder .*ro cannot be created or written"):
            cli.read_config(path)
        assert main(["validate", str(path)]) == 2
        assert "Traceback" not in capsys.readouterr().err
    finally:
        ro.chmod(0o700)


def test_cli_errors_are_one_line_naming_file_and_key(tmp_path, no_simulation, capsys):
    path = _bad(tmp_path, lambda c: c["controllers"]["PI"].update(fiel="x.json"), "fiel")
    assert main(["validate", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(path) in err and "controllers.PI" in err and "allowed" in err


def test_a_programming_error_keeps_its_traceback(tmp_path, monkeypatch):
    # only user errors (ConfigError, OSError) become one line: a bug is not disguised as bad input
    def bug(*a, **k):
        raise TypeError("internal")

    monkeypatch.setattr(cli, "run_campaign", bug)
    with pytest.raises(TypeError, match="internal"):
        main(["validate", str(_write(tmp_path, GOOD))])


_STRICT = {  # key → values of a wrong type or out of range that JSON can express
    "duration": st.one_of(st.text(max_size=5), st.booleans(), st.none(), st.floats(max_value=0.0), st.lists(st.integers(1, 9))),
    "dt": st.one_of(st.text(max_size=5), st.booleans(), st.none(), st.floats(max_value=0.0)),
    "transient": st.one_of(st.text(max_size=5), st.booleans(), st.none(), st.floats(max_value=-1e-9)),
    "wohler_exponent": st.one_of(st.text(max_size=5), st.booleans(), st.none(), st.floats(max_value=0.0)),
    "seeds": st.one_of(st.text(max_size=5), st.booleans(), st.none(), st.floats(), st.integers(max_value=0),
                       st.lists(st.integers(-10, 3), min_size=2).filter(lambda s: min(s) < 0 or len(set(s)) < len(s))),
    "linear_twin": st.one_of(st.sampled_from(["false", "true", 0, 1, "no"]), st.none(), st.floats()),
    "volterra": st.one_of(st.booleans(), st.floats(), st.integers().filter(lambda v: v not in (0, 1, 2, 3)), st.text(max_size=3)),
    "turbulence_class": st.one_of(st.text(max_size=3).filter(lambda t: t not in ("A", "B", "C")), st.integers(), st.none()),
    "wind_speeds": st.one_of(st.text(max_size=5), st.none(), st.just([]), st.lists(st.floats(26.0, 1e6), min_size=1, max_size=3),
                             st.lists(st.text(max_size=3), min_size=1, max_size=3)),
    "baseline": st.one_of(st.text(max_size=5).filter(lambda t: t not in GOOD["controllers"]), st.integers(), st.none()),
    "turbine": st.one_of(st.text(max_size=8).filter(lambda t: t != "iea15mw"), st.integers(), st.none()),
}


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=st.data())
def test_every_wrong_value_names_its_key(tmp_path, no_simulation, data):
    key = data.draw(st.sampled_from(sorted(_STRICT)))
    value = data.draw(_STRICT[key])
    path = _write(tmp_path, dict(GOOD, **{key: value}))
    with pytest.raises(cli.ConfigError) as e:
        cli.read_config(path)
    assert str(path) in str(e.value) and key in str(e.value)


def test_a_step_too_large_for_a_controller_is_refused_before_any_run(tmp_path, no_simulation, monkeypatch, capsys):
    # run_campaign refuses it too, but as a ValueError without the file: read_config names file and key
    def refuse(model, controllers, vs, dt):
        assert set(controllers) == {"PI", "ROSCO"} and list(vs) == [19.0]
        raise ValueError(f"campaign controller 'PI': dt={dt:g} s is too large for controller 'PI' at 19 m/s")

    monkeypatch.setattr(cli, "check_campaign_step", refuse)
    path = _bad(tmp_path, lambda c: None, r"c.json: dt: campaign controller 'PI': dt=0.02 s is too large")
    assert main(["validate", str(path)]) == 2
    assert "Traceback" not in capsys.readouterr().err
