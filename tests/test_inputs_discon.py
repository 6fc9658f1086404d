"""ROSCO's DISCON doors (issue "Nothing silently wrong, part two"): a file ROSCO will open that
does not exist is refused before the library is loaded, naming the DISCON.IN, the line and the
key. ROSCO's ReadCpFile (ReadSetParameters.f90) opens PerfFileName with STATUS='old' and no
IOSTAT, so without the check gfortran's runtime ends the Python process: the probe runs in a
child process and must come back alive with a Python exception."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from specdesign.rosco import Discon
from specdesign.rosco.discon import _OPENED_FILES

ROOT = Path(__file__).resolve().parents[1]


def _edit(discon_in, tmp_path, key, value):
    """A copy of ``discon_in`` in tmp_path with ``key`` set to ``value``; (path, line of the key)."""
    # the shipped table's relative name made absolute: the copy lives elsewhere
    lines = discon_in.read_text().replace('"../IEA-15-240-RWT/', f'"{discon_in.parent}/../IEA-15-240-RWT/').splitlines()
    for n, line in enumerate(lines):
        _, sep, right = line.partition("!")
        if sep and right.split() and right.split()[0] == key:
            lines[n] = f"{value}   !{right}"
            out = tmp_path / "DISCON.IN"
            out.write_text("\n".join(lines) + "\n")
            return out, n + 1
    raise AssertionError(f"{key} not in {discon_in}")


def test_a_missing_performance_table_is_an_exception_not_the_end_of_the_process(discon_in, tmp_path):
    path, line = _edit(discon_in, tmp_path, "PerfFileName", '"no_such_Cp_Ct_Cq.txt"')
    probe = textwrap.dedent(f"""
        from specdesign.rosco import Discon
        from specdesign.simulate import simulate
        from specdesign.turbine import iea15mw
        try:
            simulate(iea15mw(), Discon({str(path)!r}), [19.0], seeds=[1], duration=1.0, transient=0.0)
        except FileNotFoundError as e:
            print("CAUGHT", e)
    """)
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300, env=env, check=False)
    assert r.returncode == 0, r.stderr[-2000:]  # the interpreter survived
    assert f"CAUGHT {path}: line {line}: PerfFileName" in r.stdout
    assert "no_such_Cp_Ct_Cq.txt does not exist" in r.stdout


@pytest.mark.parametrize("key, mode", _OPENED_FILES)
def test_every_file_rosco_opens_is_checked_when_its_mode_reads_it(discon_in, tmp_path, key, mode):
    path, line = _edit(discon_in, tmp_path, key, '"/nonexistent/file.dat"')
    text = path.read_text().splitlines()
    for n, row in enumerate(text):  # switch its mode on
        _, sep, right = row.partition("!")
        if sep and right.split() and right.split()[0] == mode:
            text[n] = f"1   !{right}"
    path.write_text("\n".join(text) + "\n")
    with pytest.raises(FileNotFoundError, match=rf"line {line}: {key} = .*/nonexistent/file.dat does not exist"):
        Discon(path)


def test_a_folder_as_the_table_is_not_a_readable_file(discon_in, tmp_path):
    (tmp_path / "table").mkdir()
    path, line = _edit(discon_in, tmp_path, "PerfFileName", '"table"')
    with pytest.raises(FileNotFoundError, match=rf"line {line}: PerfFileName = .* is not a readable file"):
        Discon(path)


def test_a_file_not_read_in_its_mode_is_not_checked(discon_in, tmp_path):
    # OL_Mode = 0 in the shipped file: ROSCO never opens OL_Filename, whatever it names
    path, _ = _edit(discon_in, tmp_path, "OL_Filename", '"/nonexistent/ol.dat"')
    assert Discon(path).gearbox_ratio > 0


def test_the_shipped_discon_passes(discon_in):
    assert Discon(discon_in).gearbox_ratio == pytest.approx(1.0)  # the IEA 15 MW is direct drive
