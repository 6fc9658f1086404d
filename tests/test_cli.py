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
