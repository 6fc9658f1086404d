"""Command line: bad input gives a one-line error naming the problem and exit status 2."""
import subprocess
import sys


def _run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "specdesign", *args], capture_output=True, text=True, cwd=cwd)


def test_validate_missing_config_is_a_clear_error(tmp_path):
    r = _run("validate", str(tmp_path / "nope.toml"))
    assert r.returncode == 2
    assert "nope.toml" in r.stderr and "does not exist" in r.stderr
    assert "Traceback" not in r.stderr


def test_validate_malformed_toml_names_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("wind_speeds = [19,\n")
    r = _run("validate", str(bad))
    assert r.returncode == 2
    assert "bad.toml" in r.stderr and "TOML" in r.stderr


def test_unknown_command_is_rejected():
    r = _run("design")
    assert r.returncode == 2
    assert "invalid choice" in r.stderr


def test_python_m_specdesign_is_the_cli():
    r = _run("--version")
    assert r.returncode == 0 and r.stdout.startswith("specdesign ")
    from specdesign import __main__, cli

    assert __main__.main is cli.main


def _clean_env(**extra):
    import os

    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    env.update(extra)
    return env


def test_the_cli_chooses_agg_only_when_no_backend_was_asked_for(tmp_path):
    code = ("import sys, matplotlib\nfrom specdesign.cli import main\n"
            "assert main(['validate', sys.argv[1]]) == 2\nprint(matplotlib.get_backend())\n")
    missing = str(tmp_path / "missing.toml")
    r = subprocess.run([sys.executable, "-c", code, missing], capture_output=True, text=True, env=_clean_env())
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().lower() == "agg"
    r = subprocess.run([sys.executable, "-c", code, missing], capture_output=True, text=True,
                       env=_clean_env(MPLBACKEND="pdf"))
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().lower() == "pdf"


def test_a_campaign_file_writes_its_figures_without_pyplot(tmp_path):
    """The command-line path end to end in a fresh process where no backend is chosen (pyplot
    imported first, so the CLI leaves the backend alone): tables, indicators and Figs. 8-10
    are written on matplotlib.figure.Figure, never through pyplot."""
    (tmp_path / "pi.json").write_text('{"num": [-0.3, -0.06], "den": [1.0, 0.0]}')
    (tmp_path / "c.toml").write_text('wind_speeds = [19.0]\nseeds = 1\nduration = 30.0\ntransient = 5.0\n'
                                     'baseline = "ROSCO"\ndesigned = "PI"\n'
                                     '[controllers.ROSCO]\nkind = "rosco"\n[controllers.PI]\nfile = "pi.json"\n')
    code = ("import sys\nimport matplotlib.pyplot as plt\n"  # python-control imports pyplot anyway
            "def no_pyplot_figure(*a, **k):\n    raise AssertionError('a figure made through pyplot')\n"
            "plt.figure = plt.subplots = no_pyplot_figure\n"
            "from specdesign.cli import main\n"
            "assert main(['validate', sys.argv[1], '--out', sys.argv[2]]) == 0\n")
    r = subprocess.run([sys.executable, "-c", code, str(tmp_path / "c.toml"), str(tmp_path / "out")],
                       capture_output=True, text=True, env=_clean_env())
    assert r.returncode == 0, r.stderr
    for f in ("table2.md", "table2.csv", "table3.md", "table3.csv", "indicators.csv", "fig8_19mps.png",
              "fig9_19mps.png", "fig10.png"):
        assert (tmp_path / "out" / f).stat().st_size > 0, f


def test_version_is_the_package_version():
    from specdesign import __version__

    r = _run("--version")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"specdesign {__version__}"


def test_help_is_plain_text_without_rest_markup():
    """argparse prints help as it is: no ``literals``, :func:`roles` or other reST markup."""
    import re

    for args in (("--help",), ("demo", "--help"), ("validate", "--help")):
        r = _run(*args)
        assert r.returncode == 0, r.stderr
        assert r.stdout.startswith("usage: specdesign"), args
        assert "``" not in r.stdout, (args, r.stdout)
        assert not re.search(r":[a-z]+:`|`[^`\n]+`_|^\s*\.\. [a-z]+::", r.stdout, re.M), (args, r.stdout)
    top = _run("--help").stdout
    assert "demo" in top and "validate" in top and "--version" in top


def test_validate_prints_tables_3_and_2_and_the_files_it_wrote(tmp_path, capsys):
    """The campaign's answer on the terminal: Table 3 (promise vs rainflow) and Table 2 as
    written to table3.md/table2.md, then every file written, each of which exists."""
    from specdesign.cli import main

    (tmp_path / "pi.json").write_text('{"num": [-0.3, -0.06], "den": [1.0, 0.0]}')
    (tmp_path / "c.toml").write_text('wind_speeds = [19.0]\nseeds = 1\nduration = 30.0\ntransient = 5.0\n'
                                     'baseline = "ROSCO"\ndesigned = "PI"\n'
                                     '[controllers.ROSCO]\nkind = "rosco"\n[controllers.PI]\nfile = "pi.json"\n')
    out = tmp_path / "out"
    assert main(["validate", str(tmp_path / "c.toml"), "--out", str(out)]) == 0
    stdout = capsys.readouterr().out
    t3, t2 = (out / "table3.md").read_text(), (out / "table2.md").read_text()
    assert "Table 3" in t3 and "Table 2" in t2
    assert t3.strip() in stdout and t2.strip() in stdout
    assert stdout.index("Table 3") < stdout.index("Table 2")
    listed = [line.strip() for line in stdout.splitlines() if line.startswith("  ")]
    files = sorted(str(p) for p in out.iterdir())
    assert sorted(listed) == files  # every file written is listed, and only those
    assert f"wrote {len(files)} files to {out}" in stdout


def test_campaign_file_torque_control_and_speeds_below_rated(tmp_path):
    """``torque_control`` and wind speeds from cut-in in a campaign file: the campaign it runs is
    run_campaign's with the same arguments (the oracle: the direct call, compared bitwise)."""
    import numpy as np
    import pytest

    from specdesign import simulate as sm
    from specdesign import turbine
    from specdesign.cli import ConfigError, read_config, run_config
    from specdesign.validate import run_campaign

    def config(extra, speeds="[7.0, 19.0]"):
        p = tmp_path / "c.toml"
        p.write_text(f'wind_speeds = {speeds}\nseeds = 1\nduration = 30.0\ntransient = 5.0\n{extra}'
                     '[controllers.ROSCO]\nkind = "rosco"\n')
        return p

    assert read_config(config('torque_control = "rosco"\n'))["kwargs"]["torque_control"] == "rosco"
    assert read_config(config(""))["kwargs"]["torque_control"] == "auto"
    with pytest.raises(ConfigError, match="torque_control must be"):
        read_config(config('torque_control = "on"\n'))
    with pytest.raises(ConfigError, match="wind_speeds: wind_speed=2.0 m/s is outside the operating range 3-25 m/s"):
        read_config(config("", speeds="[2.0]"))
    camp = run_config(config('torque_control = "none"\n', speeds="[7.0]"), tmp_path / "out")
    model = turbine.iea15mw()
    direct = run_campaign({"ROSCO": sm.rosco_scheduled(model)}, [7.0], 1, model=model, duration=30.0, transient=5.0,
                          torque_control=None, progress=False)
    np.testing.assert_array_equal(camp.values["tower_del"], direct.values["tower_del"])
    auto = run_campaign({"ROSCO": sm.rosco_scheduled(model)}, [7.0], 1, model=model, duration=30.0, transient=5.0,
                        progress=False)
    assert not np.array_equal(auto.values["tower_del"], direct.values["tower_del"])
