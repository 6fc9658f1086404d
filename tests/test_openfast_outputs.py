"""read_outputs: text and binary OpenFAST outputs, SI conversion, and the errors users hit."""
import math
import struct

import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign.openfast import OpenFASTOutput, read_outputs

NAMES = ["Time", "GenSpeed", "TwrBsMyt", "BldPitch1", "GenPwr"]
UNITS = ["(s)", "(rpm)", "(kN-m)", "(deg)", "(kW)"]


def _signals(n=200, dt=0.05):
    t = np.arange(n) * dt
    return np.column_stack([
        t,
        7.5 + 0.3 * np.sin(0.7 * t),          # rpm
        8.0e4 + 2.0e4 * np.sin(1.1 * t),      # kN-m
        15.0 + 2.0 * np.cos(0.2 * t),         # deg
        1.5e4 + 100.0 * np.sin(0.5 * t),      # kW
    ])


def write_text(path, data, names=NAMES, units=UNITS):
    """OpenFAST text layout: 6 preamble lines, names on line 7, units on line 8."""
    lines = [
        "",
        "Predictions were generated on 21-Nov-2026 at 23:59:00 using OpenFAST (synthetic test file)",
        "linked with NWTC Subroutine Library",
        "",
        "Description from the FAST input file: synthetic",
        "",
        "\t".join(names),
        "\t".join(units),
    ]
    lines += ["\t".join(f"{v:.10E}" for v in row) for row in data]
    path.write_text("\n".join(lines) + "\n")


def write_binary(path, data, names=NAMES, units=UNITS, file_id=3):
    """OpenFAST binary layout as openfast-io's load_binary_output reads it.

    file_id 3: float64 channels, no compression, time from (first, increment).
    file_id 2: int16 channels scaled by float32 slopes/offsets, same time convention.
    """
    nt, nc = data.shape[0], data.shape[1] - 1
    t, ch = data[:, 0], data[:, 1:]
    b = struct.pack("h", file_id) + struct.pack("i", nc) + struct.pack("i", nt)
    b += struct.pack("d", t[0]) + struct.pack("d", t[1] - t[0])
    if file_id == 2:
        lo, hi = ch.min(axis=0), ch.max(axis=0)
        scl = (2 ** 15 - 2) * 2 / (hi - lo)
        off = -32767 - lo * scl
        scl, off = scl.astype(np.float32), off.astype(np.float32)
        b += struct.pack(f"{nc}f", *scl) + struct.pack(f"{nc}f", *off)
    desc = b"synthetic binary"
    b += struct.pack("i", len(desc)) + desc
    b += b"".join(n.ljust(10).encode() for n in names)
    b += b"".join(u.ljust(10).encode() for u in units)
    if file_id == 3:
        b += ch.astype("<f8").tobytes()
    else:
        packed = np.round(ch * scl.astype(float) + off.astype(float)).astype("<i2")
        b += packed.tobytes()
    path.write_bytes(b)


@pytest.fixture
def data():
    return _signals()


def test_text_channels_in_si_with_units_recorded(tmp_path, data):
    p = tmp_path / "run.out"
    write_text(p, data)
    out = read_outputs(p, ["GenSpeed", "TwrBsMyt", "BldPitch1", "GenPwr"])
    assert isinstance(out, OpenFASTOutput)
    assert_allclose(out.time, data[:, 0])
    assert_allclose(out["GenSpeed"], data[:, 1] * 2 * math.pi / 60, rtol=1e-9)
    assert_allclose(out["TwrBsMyt"], data[:, 2] * 1000.0, rtol=1e-9)
    assert_allclose(out["BldPitch1"], np.deg2rad(data[:, 3]), rtol=1e-9)
    assert_allclose(out["GenPwr"], data[:, 4] * 1000.0, rtol=1e-9)
    assert out.units == {"GenSpeed": "rad/s", "TwrBsMyt": "N·m", "BldPitch1": "rad", "GenPwr": "W"}
    assert out.original_units == {"GenSpeed": "rpm", "TwrBsMyt": "kN-m", "BldPitch1": "deg", "GenPwr": "kW"}
    assert out.dt == pytest.approx(0.05)


def test_binary_float64_equals_text(tmp_path, data):
    write_text(tmp_path / "a.out", data)
    write_binary(tmp_path / "a.outb", data, file_id=3)
    a, b = read_outputs([tmp_path / "a.out", tmp_path / "a.outb"])
    for n in NAMES[1:]:
        assert_allclose(b[n], a[n], rtol=1e-9)
        assert a.units[n] == b.units[n]


def test_binary_int16_compressed_within_quantisation(tmp_path, data):
    p = tmp_path / "c.outb"
    write_binary(p, data, file_id=2)
    out = read_outputs(p, ["TwrBsMyt"])
    # int16 packing: one quantum is (max - min)/65532 of the channel range (then ×1e3 to N·m)
    q = (data[:, 2].max() - data[:, 2].min()) / 65532 * 1e3
    assert np.max(np.abs(out["TwrBsMyt"] - data[:, 2] * 1e3)) <= q


def test_all_channels_when_none_selected(tmp_path, data):
    p = tmp_path / "r.out"
    write_text(p, data)
    assert set(read_outputs(p).channels) == set(NAMES[1:])


def test_missing_channel_names_file_and_channel(tmp_path, data):
    p = tmp_path / "r.out"
    write_text(p, data)
    with pytest.raises(ValueError, match=r"r\.out.*'RotThrust'"):
        read_outputs(p, ["GenSpeed", "RotThrust"])


def test_binary_named_out_is_refused(tmp_path, data):
    p = tmp_path / "binary.out"
    write_binary(p, data)
    with pytest.raises(ValueError, match=r"binary\.out.*binary.*\.outb"):
        read_outputs(p)


def test_truncated_text_names_file_and_line(tmp_path, data):
    p = tmp_path / "t.out"
    write_text(p, data)
    txt = p.read_text()
    p.write_text(txt[: len(txt) - 40])  # cut the last row in the middle
    with pytest.raises(ValueError, match=r"t\.out, line 208"):
        read_outputs(p)


def test_truncated_binary_names_file(tmp_path, data):
    p = tmp_path / "t.outb"
    write_binary(p, data)
    p.write_bytes(p.read_bytes()[:-100])
    with pytest.raises(ValueError, match=r"t\.outb.*truncated"):
        read_outputs(p)


def test_bad_arguments(tmp_path, data):
    with pytest.raises(FileNotFoundError, match="nope.out"):
        read_outputs(tmp_path / "nope.out")
    p = tmp_path / "r.csv"
    p.write_text("x")
    with pytest.raises(ValueError, match="extension"):
        read_outputs(p)
    write_text(tmp_path / "r.out", data)
    with pytest.raises(TypeError, match="channels"):
        read_outputs(tmp_path / "r.out", [1, 2])
