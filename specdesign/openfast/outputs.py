"""OpenFAST time-series outputs (``.out`` text, ``.outb`` binary) → named SI channels.

An adapter: arrays and labels in, no physics. Parsing is delegated to openfast-io's
``FAST_output_reader`` (``load_ascii_output`` / ``load_binary_output``); this module adds
what that reader leaves out: detection of a binary file carrying a ``.out`` name, clear
errors for truncated files and missing channels (naming file, line and channel), and
conversion of every selected channel to SI with its original unit recorded.

Unit conversions (exact factors): rpm → rad/s (×2π/60), deg → rad, deg/s → rad/s,
kN·m → N·m (×1e3), kN → N, kW → W (×1e3), MW → W, MN·m → N·m (spellings kN-m, kNm, kN*m,
kN.m, kN·m; case-insensitive except the prefix M, mega, against m, milli, which is not
converted). Units already SI (s, m, m/s, m/s^2, rad, rad/s, N, N·m, W, -) pass through; any
other unit is kept unchanged and recorded as such (``si_unit == original unit``), and a
consumer that needs a given SI unit checks ``units`` (``openfast.series_from_openfast``
refuses a tower moment, speed, pitch or power it cannot convert).

Checked on reading, each an error naming the file: a ``Time`` channel in seconds (s or sec),
distinct channel names, a time axis increasing uniformly, finite values, and for binary
files a header (file ID 1-4, channel and step counts ≥ 1) that agrees with the file length.
"""
from __future__ import annotations

import math
import os
import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["OpenFASTOutput", "read_outputs", "to_si"]

# original unit (lower case, spaces removed) → (SI unit, factor)
_UNITS = {
    "rpm": ("rad/s", 2.0 * math.pi / 60.0),
    "deg": ("rad", math.pi / 180.0),
    "deg/s": ("rad/s", math.pi / 180.0),
    "deg/s^2": ("rad/s^2", math.pi / 180.0),
    "kn-m": ("N·m", 1e3),
    "knm": ("N·m", 1e3),
    "kn·m": ("N·m", 1e3),
    "kn*m": ("N·m", 1e3),
    "kn.m": ("N·m", 1e3),
    "mn.m": ("N·m", 1e6),
    "mnm": ("N·m", 1e6),
    "n.m": ("N·m", 1.0),
    "n·m": ("N·m", 1.0),
    "n*m": ("N·m", 1.0),
    "deg/s2": ("rad/s^2", math.pi / 180.0),
    "m/s2": ("m/s^2", 1.0),
    "mn-m": ("N·m", 1e6),
    "n-m": ("N·m", 1.0),
    "nm": ("N·m", 1.0),
    "kn": ("N", 1e3),
    "n": ("N", 1.0),
    "kw": ("W", 1e3),
    "mw": ("W", 1e6),
    "w": ("W", 1.0),
    "rad": ("rad", 1.0),
    "rad/s": ("rad/s", 1.0),
    "s": ("s", 1.0),
    "sec": ("s", 1.0),
    "m": ("m", 1.0),
    "m/s": ("m/s", 1.0),
    "m/s^2": ("m/s^2", 1.0),
}


def to_si(unit: str) -> tuple[str, float]:
    """The SI unit of an OpenFAST unit string and the factor to it.

    Parameters
    ----------
    unit : str
        A unit as OpenFAST writes it, with or without parentheses (``"(rpm)"`` or ``"rpm"``).

    Returns
    -------
    si_unit : str
        The SI unit (the unit itself when unknown, or already SI).
    factor : float
        Multiply a channel by it to express it in ``si_unit`` (1.0 for an unknown unit).

    Examples
    --------
    >>> to_si("(kN-m)")
    ('N·m', 1000.0)
    """
    u = unit.strip()
    if u.startswith("(") and u.endswith(")"):
        u = u[1:-1]
    key = u.replace(" ", "").lower()
    if u[:1] == "m" and key[1:] in ("w", "n", "n-m", "nm", "n.m", "n·m", "n*m"):
        return u, 1.0  # milli (mW, mN·m), not the mega (MW, MN·m) the table means: not converted
    if key in _UNITS:
        return _UNITS[key]
    return u, 1.0


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class OpenFASTOutput:
    """Channels of one OpenFAST output file, in SI (:func:`read_outputs` makes them).

    ``output["GenSpeed"]`` is the channel's array; ``dt`` and ``duration`` (s) describe the
    time axis.

    Parameters
    ----------
    path : pathlib.Path
        The file read.
    time : numpy.ndarray
        (n,) simulation time (s).
    channels : dict
        Name → (n,) array in SI (see the module docstring for the conversions).
    units : dict
        Name → SI unit of the array in ``channels``.
    original_units : dict
        Name → unit written in the file (e.g. ``"rpm"``, ``"kN-m"``).
    description : str, default ""
        The file's description line.
    """

    path: Path
    time: np.ndarray
    channels: dict = field(repr=False)
    units: dict
    original_units: dict
    description: str = ""

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.channels:
            raise KeyError(f"channel {name!r} not in {self.path.name}; available: {sorted(self.channels)}")
        return self.channels[name]

    @property
    def dt(self) -> float:
        """Output time step in s (mean spacing of ``time``)."""
        return float((self.time[-1] - self.time[0]) / (self.time.size - 1))

    @property
    def duration(self) -> float:
        """Span of the record in s, ``time[-1] - time[0] + dt`` (one sample per step)."""
        return float(self.time[-1] - self.time[0]) + self.dt


def _is_binary(path: Path) -> bool:
    # OpenFAST text outputs are ASCII; the binary header starts with a small int16 file ID
    # whose high byte is 0, so a NUL in the first block is a reliable tell.
    with open(path, "rb") as f:
        head = f.read(512)
    if b"\x00" in head:
        return True
    try:
        head.decode("ascii")
    except UnicodeDecodeError:
        return True
    return False


def _read_text(path: Path):
    from openfast_io.FAST_output_reader import load_ascii_output

    try:
        data, info = load_ascii_output(str(path))
    except ValueError:
        # openfast-io builds one array from all rows; find the offending line ourselves.
        with open(path) as f:
            lines = f.readlines()
        if len(lines) < 8:
            raise ValueError(f"{path}: truncated OpenFAST text output, only {len(lines)} lines (the header alone has 8)") from None
        ncol = len(lines[6].split())
        for i, line in enumerate(lines[8:], start=9):
            parts = line.split()
            try:
                [float(p) for p in parts]
                ok = len(parts) == ncol
            except ValueError:
                ok = False
            if not ok:
                raise ValueError(
                    f"{path}, line {i}: expected {ncol} numbers (one per channel), got {len(parts)} fields "
                    f"{line.strip()[:60]!r}; the file is truncated or corrupt"
                ) from None
        raise
    names, units = info["attribute_names"], info["attribute_units"]
    if len(names) != len(units):
        raise ValueError(f"{path}, lines 7-8: {len(names)} channel names but {len(units)} units")
    if data.ndim != 2 or data.shape[0] == 0:
        raise ValueError(f"{path}: no data rows after the 8-line header (truncated file?)")
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {data.shape[1]} data columns but {len(names)} channel names (line 7)")
    return data, names, units, info.get("description", "")


def _binary_size(path: Path) -> int:
    """The byte length an OpenFAST binary output must have by its own header (the layout
    openfast-io's ``load_binary_output`` reads: file ID 1 with packed time, 2 and 4 int16
    channels with scales, 3 float64 channels)."""
    with open(path, "rb") as f:
        head = f.read(2 + 2 + 4 + 4)
        if len(head) < 10:
            raise ValueError(f"{path}: truncated OpenFAST binary output ({len(head)} bytes of header)")
        file_id = struct.unpack("h", head[:2])[0]
        if file_id not in (1, 2, 3, 4):
            raise ValueError(f"{path}: binary file ID {file_id} is not an OpenFAST output format (1-4)")
        off = 4 if file_id == 4 else 2
        len_name = struct.unpack("h", head[2:4])[0] if file_id == 4 else 10
        n_ch, nt = struct.unpack("ii", head[off:off + 8])
        if n_ch < 1 or nt < 1 or len_name < 1:
            raise ValueError(f"{path}: the binary header gives {n_ch} channels, {nt} time steps and {len_name}-character "
                             "names; a corrupt or non-OpenFAST file")
        pos = off + 8 + 16 + (0 if file_id == 3 else 8 * n_ch)
        f.seek(pos)
        raw = f.read(4)
        if len(raw) < 4:
            raise ValueError(f"{path}: truncated OpenFAST binary output (header ends at byte {pos})")
        len_desc = struct.unpack("i", raw)[0]
        if len_desc < 0:
            raise ValueError(f"{path}: the binary header gives a description of {len_desc} bytes; a corrupt file")
    return (pos + 4 + len_desc + 2 * (n_ch + 1) * len_name + (4 * nt if file_id == 1 else 0)
            + nt * n_ch * (8 if file_id == 3 else 2))


def _read_binary(path: Path):
    from openfast_io.FAST_output_reader import load_binary_output

    expected, actual = _binary_size(path), path.stat().st_size
    if expected != actual:
        raise ValueError(f"{path}: the binary header describes {expected} bytes but the file has {actual}: "
                         "truncated, appended to, or not an OpenFAST output")

    try:
        data, info, _ = load_binary_output(str(path))
    except Exception as e:  # openfast-io raises struct.error or a bare Exception on short reads
        raise ValueError(f"{path}: truncated or corrupt OpenFAST binary output ({e})") from None
    names, units = info["attribute_names"], info["attribute_units"]
    if data.shape[1] != len(names):
        raise ValueError(f"{path}: {data.shape[1]} data columns but {len(names)} channel names")
    return data, names, units, info.get("description", "")


def _read_one(path, channels) -> OpenFASTOutput:
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"OpenFAST output {path} does not exist")
    ext = path.suffix.lower()
    if ext not in (".out", ".outb"):
        raise ValueError(f"{path}: unsupported extension {ext!r}; expected .out (text) or .outb (binary)")
    binary = _is_binary(path)
    if ext == ".out" and binary:
        raise ValueError(
            f"{path}: this file is binary but carries a text '.out' name; rename it to '.outb' "
            "(OpenFAST writes binary outputs with OutFileFmt = 2 as .outb)"
        )
    if ext == ".outb" and not binary:
        raise ValueError(f"{path}: this file is text but carries a binary '.outb' name; rename it to '.out'")
    data, names, units, desc = (_read_binary if binary else _read_text)(path)
    if not np.all(np.isfinite(data)):
        r, c = np.argwhere(~np.isfinite(data))[0]
        raise ValueError(f"{path}: channel {names[c]!r} has a non-finite value at row {r}")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"{path}: duplicate channel name(s) {dup}; each OutList channel must appear once")
    idx = {n: i for i, n in enumerate(names)}
    time_name = next((n for n in names if n.lower() == "time"), None)
    if time_name is None:
        raise ValueError(f"{path}: no 'Time' channel among {names[:8]}{' …' if len(names) > 8 else ''}; "
                         "an OpenFAST output starts with Time (s)")
    wanted = [n for n in names if n != time_name] if channels is None else list(channels)
    missing = [n for n in wanted if n not in idx]
    if missing:
        raise ValueError(f"{path}: channel(s) {missing} not found; available: {[n for n in names if n != time_name]}")
    t_unit, t_fac = to_si(units[idx[time_name]])
    if t_unit != "s":
        raise ValueError(f"{path}: channel {time_name!r} is in {units[idx[time_name]]!r}; the time must be in seconds (s)")
    time = data[:, idx[time_name]] * t_fac
    out, si_units, orig = {}, {}, {}
    for n in wanted:
        si, fac = to_si(units[idx[n]])
        out[n] = np.ascontiguousarray(data[:, idx[n]] * fac)
        si_units[n] = si
        orig[n] = units[idx[n]]
    if time.size < 2:
        raise ValueError(f"{path}: needs at least 2 time steps, got {time.size} (truncated file?)")
    step = np.diff(time)
    h = float(np.median(step))
    # uniform to the precision the text format prints time with (OpenFAST: ≥ 4 decimals)
    if not (h > 0 and np.all(step > 0) and np.max(np.abs(step - h)) <= 1e-3 * h + 1e-6):
        i = int(np.argmax(np.abs(step - h))) if h > 0 else int(np.argmin(step))
        raise ValueError(f"{path}: the time axis must increase uniformly; step {i} is {step[i]:g} s where the others "
                         f"are {h:g} s (rows {i + 1}-{i + 2}: a restart or a merged file?)")
    return OpenFASTOutput(path=path, time=time, channels=out, units=si_units, original_units=orig, description=desc)


def read_outputs(paths: str | os.PathLike | Sequence[str | os.PathLike],
                 channels: Sequence[str] | None = None) -> OpenFASTOutput | list[OpenFASTOutput]:
    """Read OpenFAST ``.out`` (text) / ``.outb`` (binary) outputs and convert channels to SI.

    Parameters
    ----------
    paths : str or os.PathLike, or a sequence of them
        The output files.
    channels : sequence of str, optional
        Channel names (e.g. ``["GenSpeed", "TwrBsMyt", "BldPitch1", "GenPwr"]``), or None for
        every channel. Names are matched exactly (OpenFAST spelling).

    Returns
    -------
    OpenFASTOutput or list of OpenFASTOutput
        One for a single path, else a list of them in the order given.

    Raises
    ------
    ValueError
        Naming the file (and the line or channel): a binary file with a ``.out`` name, a
        truncated or corrupt file, or a missing channel; an empty sequence of paths.
    TypeError
        Channel names that are not strings.
    FileNotFoundError
        A path that does not exist.
    """
    if channels is not None:
        if isinstance(channels, str):
            channels = [channels]
        channels = list(channels)
        if not all(isinstance(c, str) for c in channels):
            raise TypeError("channels must be a sequence of channel-name strings, e.g. ['GenSpeed', 'TwrBsMyt']")
    if isinstance(paths, (str, os.PathLike)):
        return _read_one(paths, channels)
    paths = list(paths)
    if not paths:
        raise ValueError("paths is empty; pass one or more .out/.outb files")
    return [_read_one(p, channels) for p in paths]
