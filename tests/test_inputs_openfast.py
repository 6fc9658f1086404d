"""OpenFAST outputs: units checked and converted, duplicates, the time axis and binary
lengths checked (issue "Nothing silently wrong", §4). Files are synthesised here with the
writers of tests/test_openfast_outputs.py."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from specdesign import fatigue
from specdesign.openfast import OPENFAST_CHANNELS, read_outputs, series_from_openfast
from test_openfast_outputs import NAMES, UNITS, _signals, write_binary, write_text

CH = list(OPENFAST_CHANNELS)


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
    a, _ = series_from_openfast(read_outputs(tmp_path / "knm.out", CH))
    b, dt = series_from_openfast(read_outputs(tmp_path / "nm.out", CH))
    np.testing.assert_allclose(a["tower_base_my"], b["tower_base_my"], rtol=1e-6)
    assert fatigue.del_rainflow(a["tower_base_my"][0], 4, 10.0) == pytest.approx(
        fatigue.del_rainflow(b["tower_base_my"][0], 4, 10.0), rel=1e-6)


def test_a_unit_that_does_not_convert_is_an_error(tmp_path, data):
    units = list(UNITS)
    units[NAMES.index("TwrBsMyt")] = "(kip-ft)"
    write_text(tmp_path / "kip.out", data, units=units)
    out = read_outputs(tmp_path / "kip.out", CH)
    with pytest.raises(ValueError, match="'TwrBsMyt' is in 'kip-ft'.*N·m"):
        series_from_openfast(out)


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


@pytest.mark.parametrize("unit, factor, si", [
    ("(kN-m)", 1e3, "N·m"), ("(kNm)", 1e3, "N·m"), ("(kN*m)", 1e3, "N·m"), ("(KN-M)", 1e3, "N·m"),
    ("(MN-m)", 1e6, "N·m"), ("(N-m)", 1.0, "N·m"), ("(Nm)", 1.0, "N·m"),
])
def test_every_spelling_of_a_moment_arrives_in_n_m(tmp_path, data, unit, factor, si):
    i = NAMES.index("TwrBsMyt")
    units = list(UNITS)
    units[i] = unit
    d = data.copy()
    d[:, i] = data[:, i] * 1e3 / factor  # the same physical moment (data is in kN·m)
    write_text(tmp_path / "m.out", d, units=units)
    out = read_outputs(tmp_path / "m.out", CH)
    assert out.units["TwrBsMyt"] == si and out.original_units["TwrBsMyt"] == unit.strip("()")
    np.testing.assert_allclose(out["TwrBsMyt"], data[:, i] * 1e3, rtol=1e-9)


def test_milli_is_not_mega(tmp_path, data):
    # lower-case m is milli: "mN-m" is not converted as if it were MN·m, and the workbench refuses it
    units = list(UNITS)
    units[NAMES.index("TwrBsMyt")] = "(mN-m)"
    write_text(tmp_path / "milli.out", data, units=units)
    out = read_outputs(tmp_path / "milli.out", CH)
    assert out.units["TwrBsMyt"] == "mN-m"
    with pytest.raises(ValueError, match="'TwrBsMyt' is in 'mN-m'"):
        series_from_openfast(out)


@pytest.mark.parametrize("unit", ["(ms)", "(min)", "(-)"])
def test_the_time_must_be_in_seconds(tmp_path, data, unit):
    units = list(UNITS)
    units[0] = unit
    write_text(tmp_path / "t.out", data, units=units)
    with pytest.raises(ValueError, match=r"t.out: channel 'Time' is in .*seconds"):
        read_outputs(tmp_path / "t.out")


def test_a_file_without_time_channel_is_an_error(tmp_path, data):
    names = list(NAMES)
    names[0] = "Clock"
    write_text(tmp_path / "nt.out", data, names=names)
    with pytest.raises(ValueError, match="nt.out: no 'Time' channel"):
        read_outputs(tmp_path / "nt.out")


@pytest.mark.parametrize("what, offset, value, match", [
    ("file id", 0, ("h", 9), "binary file ID 9 is not an OpenFAST output format"),
    ("channels", 2, ("i", -4), "gives -4 channels"),
    ("steps", 6, ("i", 0), "0 time steps"),
])
def test_a_corrupt_binary_header_is_an_error(tmp_path, data, what, offset, value, match):
    import struct

    p = tmp_path / "c.outb"
    write_binary(p, data, file_id=3)
    raw = bytearray(p.read_bytes())
    fmt, v = value
    raw[offset:offset + struct.calcsize(fmt)] = struct.pack(fmt, v)
    p.write_bytes(bytes(raw))
    with pytest.raises(ValueError, match=match):
        read_outputs(p)


def test_a_truncated_binary_file_is_an_error(tmp_path, data):
    p = tmp_path / "t.outb"
    write_binary(p, data, file_id=3)
    p.write_bytes(p.read_bytes()[:-8])
    with pytest.raises(ValueError, match="binary header describes .* but the file has"):
        read_outputs(p)


def test_a_non_finite_value_names_channel_and_row(tmp_path, data):
    d = data.copy()
    d[7, NAMES.index("GenPwr")] = np.nan
    write_text(tmp_path / "nan.out", d)
    with pytest.raises(ValueError, match="channel 'GenPwr' has a non-finite value at row 7"):
        read_outputs(tmp_path / "nan.out")


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(row=st.integers(1, 198), shift=st.floats(-0.2, 0.2).filter(lambda s: abs(s) > 1e-3))
def test_any_jump_in_the_time_axis_is_found(tmp_path, row, shift):
    d = _signals()
    d[row:, 0] += shift
    write_text(tmp_path / "j.out", d)
    with pytest.raises(ValueError, match=rf"step {row - 1} is"):
        read_outputs(tmp_path / "j.out")
