"""OpenFAST outputs: units checked and converted, duplicates, the time axis and binary
lengths checked (issue "Nothing silently wrong", §4). Files are synthesised here with the
writers of tests/test_openfast_outputs.py."""
from __future__ import annotations

import numpy as np
import pytest

from specdesign import fatigue, validate as va
from specdesign.openfast import read_outputs
from test_openfast_outputs import NAMES, UNITS, _signals, write_binary, write_text

CH = list(va.OPENFAST_CHANNELS)


@pytest.fixture
def data():
    return _signals()


def test_a_knm_tower_moment_gives_the_same_del_as_nm(tmp_path, data):
    # the same moment written in kN·m (value / 1000) and in N·m: identical SI series and DEL
    i = NAMES.index("TwrBsMyt")
    units_knm = list(UNITS)
    units_knm[i] = "(kN-m)"
    knm = data.copy()
    knm[:, i] = data[:, i] / 1e3
    nm_units = list(UNITS)
    nm_units[i] = "(N-m)"
    write_text(tmp_path / "knm.out", knm, units=units_knm)
    write_text(tmp_path / "nm.out", data, units=nm_units)
    a, _ = va.series_from_openfast(read_outputs(tmp_path / "knm.out", CH))
    b, dt = va.series_from_openfast(read_outputs(tmp_path / "nm.out", CH))
    np.testing.assert_allclose(a["tower_base_my"], b["tower_base_my"], rtol=1e-6)
    assert fatigue.del_rainflow(a["tower_base_my"][0], 4, 10.0) == pytest.approx(
        fatigue.del_rainflow(b["tower_base_my"][0], 4, 10.0), rel=1e-6)


def test_a_unit_that_does_not_convert_is_an_error(tmp_path, data):
    units = list(UNITS)
    units[NAMES.index("TwrBsMyt")] = "(kip-ft)"
    write_text(tmp_path / "kip.out", data, units=units)
    out = read_outputs(tmp_path / "kip.out", CH)
    with pytest.raises(ValueError, match="'TwrBsMyt' is in 'kip-ft'.*N·m"):
        va.series_from_openfast(out)


def test_duplicate_channel_names_are_an_error(tmp_path, data):
    names = list(NAMES)
    names[2] = names[1]
    write_text(tmp_path / "dup.out", data, names=names)
    with pytest.raises(ValueError, match=rf"duplicate channel name\(s\) \['{names[1]}'\]"):
        read_outputs(tmp_path / "dup.out")


@pytest.mark.parametrize("how", ["backwards", "gap"])
def test_the_time_axis_must_increase_uniformly(tmp_path, data, how):
    d = data.copy()
    if how == "backwards":
        d[50:, 0] -= 1.0
    else:
        d[50:, 0] += 0.5
    write_text(tmp_path / "t.out", d)
    with pytest.raises(ValueError, match="time axis must increase uniformly; step 49"):
        read_outputs(tmp_path / "t.out")


@pytest.mark.parametrize("file_id", [2, 3])
def test_binary_header_and_length_must_agree(tmp_path, data, file_id):
    p = tmp_path / "b.outb"
    write_binary(p, data, file_id=file_id)
    read_outputs(p)  # as written: fine
    with open(p, "ab") as f:
        f.write(b"\x00" * 16)  # appended bytes the header does not describe
    with pytest.raises(ValueError, match="binary header describes"):
        read_outputs(p)
