"""OpenFAST linearisation files (``*.lin``) → azimuth-averaged, multi-blade-transformed LTI.

:func:`read_linearization` reads the files of one operating point (one per azimuth), applies
the multi-blade coordinate (MBC, Coleman) transform to every blade triplet in the rotating
frame, averages the matrices over azimuth and returns a :class:`LinearizationData`, whose
:meth:`LinearizationData.to_statespace` selects inputs/outputs by OpenFAST description.

The parser is this module's own, line by line, so a malformed file is reported as
``ValueError("<file>:<line>: ...")``. openfast-io's ``FASTLinearizationFile`` reads the same
files but raises bare ``Exception`` without line numbers and keeps operating points in
float32; the tests use it as an oracle on the shipped sample.

MBC (Bir 2008, NREL/CP-500-42553): a rotating triplet q_b (blades b = 1, 2, 3, azimuths
ψ_b = ψ + 2π(b−1)/3) is q_b = q_0 + q_c cos ψ_b + q_s sin ψ_b, i.e. q_rot = T1(ψ) q_nr. For
states, x_rot = T_x x_nr with T_x built from T1 and, for the velocity of a 2nd-order triplet,
the Ω·T2 coupling (T2 = dT1/dψ); then A_nr = T_x⁻¹(A T_x − Ω dT_x/dψ), B_nr = T_x⁻¹ B T_u,
C_nr = T_y⁻¹ C T_x, D_nr = T_y⁻¹ D T_u. Rotating entries without a full triplet (e.g. a
blade-1-only output) are left as they are and averaged.
"""
from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["LinearizationData", "read_linearization", "read_lin_file", "mbc_transform", "signal_label"]

# Output units written by OpenFAST → factor to SI.
_SI = {
    "rpm": (np.pi / 30, "rad/s"),
    "deg": (np.pi / 180, "rad"),
    "deg/s": (np.pi / 180, "rad/s"),
    "deg/s^2": (np.pi / 180, "rad/s^2"),
    "kn": (1e3, "N"),
    "kn-m": (1e3, "N-m"),
    "knm": (1e3, "N-m"),
    "kw": (1e3, "W"),
}

_SECTIONS = {
    "order of continuous states:": "x",
    "order of continuous state derivatives:": "xdot",
    "order of inputs:": "u",
    "order of outputs:": "y",
}
_COUNTS = {
    "x": "Number of continuous states:",
    "u": "Number of inputs:",
    "y": "Number of outputs:",
}


@dataclass(frozen=True)
class _LinFile:
    path: str
    azimuth: float
    rotor_speed: float
    wind_speed: float
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    x_op: np.ndarray
    u_op: np.ndarray
    y_op: np.ndarray
    x_desc: tuple
    u_desc: tuple
    y_desc: tuple
    x_rot: np.ndarray
    u_rot: np.ndarray
    y_rot: np.ndarray
    x_order: np.ndarray


@dataclass(frozen=True)
class LinearizationData:
    """An azimuth-averaged, MBC-transformed OpenFAST linearisation (:func:`read_linearization`).

    Matrices in OpenFAST's units, except outputs converted to SI when read with ``si=True``
    (see ``y_units``). Descriptions rename blade triplets with ``[coll]``, ``[cos]``,
    ``[sin]`` in place of the blade number. :meth:`to_statespace` selects and names signals.

    Parameters
    ----------
    A, B, C, D : numpy.ndarray
        State-space matrices, (nx, nx), (nx, nu), (ny, nx), (ny, nu).
    x_desc, u_desc, y_desc : tuple of str
        Descriptions of the states, inputs and outputs.
    y_units : tuple of str
        Unit of each output.
    x_op, u_op, y_op : numpy.ndarray
        Operating point (averaged, rotating frame).
    wind_speed : float
        Mean wind speed (m/s).
    rotor_speed : float
        Rotor speed (rad/s).
    azimuths : numpy.ndarray
        Azimuths of the files averaged (rad).
    paths : tuple of str
        The files read.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    x_desc: tuple
    u_desc: tuple
    y_desc: tuple
    y_units: tuple
    x_op: np.ndarray
    u_op: np.ndarray
    y_op: np.ndarray
    wind_speed: float
    rotor_speed: float
    azimuths: np.ndarray
    paths: tuple

    def _select(self, which, wanted):
        desc = {"inputs": self.u_desc, "outputs": self.y_desc}[which]
        if wanted is None:
            return list(range(len(desc))), [signal_label(d) for d in desc]
        items = list(wanted.items()) if isinstance(wanted, dict) else [(w, w) for w in ([wanted] if isinstance(wanted, str) else wanted)]
        idx, names = [], []
        for name, sub in items:
            exact = [i for i, d in enumerate(desc) if d == sub]
            hits = exact or [i for i, d in enumerate(desc) if sub.lower() in d.lower()]
            if len(hits) != 1:
                shown = [desc[i] for i in hits] if hits else "none"
                raise ValueError(
                    f"{which}: {sub!r} must match exactly one OpenFAST description, matched {shown}; "
                    f"use a longer substring (see LinearizationData.{'u' if which == 'inputs' else 'y'}_desc)"
                )
            idx.append(hits[0])
            names.append(str(name))
        return idx, names

    def to_statespace(self, inputs=None, outputs=None):
        """``control.StateSpace`` with the selected signals.

        Parameters
        ----------
        inputs, outputs : None, list of str or dict
            None (all), a list of description substrings (each must match one description; an
            exact description always wins) or a dict {signal name: substring} to rename, e.g.
            ``{"wind": "horizontal wind speed", "pitch_cmd": "collective blade-pitch"}``.

        Returns
        -------
        control.StateSpace
            The linearisation restricted to the selected inputs and outputs, signals named by
            their (renamed) descriptions, states ``x0, x1, ...``; units as in the file.

        Raises
        ------
        ValueError
            If a substring matches no description or several.
        """
        import control

        iu, un = self._select("inputs", inputs)
        iy, yn = self._select("outputs", outputs)
        states = [f"x{i}" for i in range(self.A.shape[0])]
        return control.ss(self.A, self.B[:, iu], self.C[iy], self.D[np.ix_(iy, iu)], inputs=un, outputs=yn, states=states)


def signal_label(description: str) -> str:
    """The name of an OpenFAST signal or state in a python-control system.

    Parameters
    ----------
    description : str
        OpenFAST's description of the signal or state (a .lin file's row label).

    Returns
    -------
    str
        The description with "." replaced by "_" (python-control reads a "." in a name as a
        subsystem's).
    """
    return description.replace(".", "_")


class _Lines:
    """Line cursor that reports errors as 'file:line: message'."""

    def __init__(self, path):
        self.path = str(path)
        try:
            self.lines = Path(path).read_text(errors="surrogateescape").splitlines()
        except OSError as e:
            raise ValueError(f"{self.path}: cannot read linearisation file ({e.strerror})") from None
        self.i = 0

    def error(self, msg, line=None):
        n = (self.i if line is None else line) + 1
        return ValueError(f"{self.path}:{n}: {msg}")

    def next(self, what):
        if self.i >= len(self.lines):
            raise self.error(f"file ends early while reading {what} (truncated file?)", line=len(self.lines) - 1)
        line = self.lines[self.i]
        self.i += 1
        return line


def _header_value(cur, key, kind):
    for n, line in enumerate(cur.lines[:40]):
        if key in line:
            tok = line.split(key, 1)[1].split()
            try:
                return kind(tok[0])
            except (IndexError, ValueError):
                raise cur.error(f"cannot read {key!r} as {kind.__name__}: {line.strip()!r}", line=n) from None
    raise cur.error(f"header has no {key!r} (not an OpenFAST .lin file?)", line=0)


def _read_table(cur, n, what):
    cur.next(what)  # column titles
    cur.next(what)  # dashes
    op, rot, order, desc = [], [], [], []
    for k in range(n):
        line = cur.next(what)
        tok = line.split()
        try:
            if int(tok[0]) != k + 1:
                raise cur.error(f"{what}: expected row {k + 1}, found {tok[0]!r}", line=cur.i - 1)
            # Orientation operating points are written as three comma-separated numbers.
            j = 1
            vals = []
            while tok[j].endswith(","):
                vals.append(float(tok[j][:-1]))
                j += 1
            vals.append(float(tok[j]))
            flag = tok[j + 1]
            if flag not in ("T", "F"):
                raise ValueError
            d_order = int(tok[j + 2])
            text = " ".join(tok[j + 3:])
        except (IndexError, ValueError):
            raise cur.error(f"{what}: malformed row {k + 1}: {line.strip()[:80]!r}", line=cur.i - 1) from None
        op.append(vals[0])
        rot.append(flag == "T")
        order.append(d_order)
        desc.append(text)
    return np.array(op), np.array(rot, bool), np.array(order, int), tuple(desc)


def _read_matrix(cur, n, m, name):
    rows = []
    for k in range(n):
        line = cur.next(f"matrix {name}")
        tok = line.split()
        if len(tok) != m:
            raise cur.error(f"matrix {name} row {k + 1} has {len(tok)} values, expected {m}", line=cur.i - 1)
        try:
            vals = [float(t) for t in tok]
        except ValueError:
            bad = next(t for t in tok if not _is_float(t))
            raise cur.error(f"matrix {name} row {k + 1}: {bad!r} is not a number", line=cur.i - 1) from None
        if not np.all(np.isfinite(vals)):
            raise cur.error(f"matrix {name} row {k + 1} contains NaN or inf", line=cur.i - 1)
        rows.append(vals)
    return np.array(rows).reshape(n, m)


def _is_float(t):
    try:
        float(t)
        return True
    except ValueError:
        return False


def read_lin_file(path: str | os.PathLike) -> _LinFile:
    """Parse one ``.lin`` file, without transform.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.lin`` file.

    Returns
    -------
    _LinFile
        Matrices, operating point, descriptions, rotating-frame flags and derivative orders
        as written in the file, azimuth (rad), rotor speed (rad/s) and wind speed (m/s).

    Raises
    ------
    ValueError
        ``'file:line: message'`` for an unreadable, truncated or malformed file.
    """
    cur = _Lines(path)
    n = {k: _header_value(cur, key, int) for k, key in _COUNTS.items()}
    azimuth = _header_value(cur, "Azimuth:", float)
    rotor_speed = _header_value(cur, "Rotor Speed:", float)
    wind_speed = _header_value(cur, "Wind Speed:", float)
    tables = {}
    mats = {}
    shapes = {"A": ("x", "x"), "B": ("x", "u"), "C": ("y", "x"), "D": ("y", "u")}
    while cur.i < len(cur.lines):
        line = cur.next("the file").strip()
        key = line.lower()
        if key in _SECTIONS:
            sec = _SECTIONS[key]
            tables[sec] = _read_table(cur, n["x" if sec == "xdot" else sec], line.rstrip(":"))
            continue
        m = re.match(r"^([ABCD]):\s*(\d+)\s*x\s*(\d+)\s*$", line)
        if m:
            name = m.group(1)
            rows, cols = (n[s] for s in shapes[name])
            if (int(m.group(2)), int(m.group(3))) != (rows, cols):
                raise cur.error(f"matrix {name} is declared {m.group(2)} x {m.group(3)}, the header implies {rows} x {cols}", line=cur.i - 1)
            mats[name] = _read_matrix(cur, rows, cols, name)
    for sec, title in (("x", "Order of continuous states"), ("u", "Order of inputs"), ("y", "Order of outputs")):
        if sec not in tables and n[sec] > 0:
            raise cur.error(f"section {title!r} is missing (truncated file?)", line=len(cur.lines) - 1)
    for name, (r, c) in shapes.items():
        if name not in mats:
            if n[r] and n[c]:
                raise cur.error(f"matrix {name} is missing (truncated file?)", line=len(cur.lines) - 1)
            mats[name] = np.zeros((n[r], n[c]))
    empty = (np.zeros(0), np.zeros(0, bool), np.zeros(0, int), ())
    x, u, y = (tables.get(k, empty) for k in ("x", "u", "y"))
    return _LinFile(
        path=str(path), azimuth=azimuth, rotor_speed=rotor_speed, wind_speed=wind_speed,
        A=mats["A"], B=mats["B"], C=mats["C"], D=mats["D"],
        x_op=x[0], u_op=u[0], y_op=y[0], x_desc=x[3], u_desc=u[3], y_desc=y[3],
        x_rot=x[1], u_rot=u[1], y_rot=y[1], x_order=x[2],
    )


# ----------------------------------------------------------------------------- MBC
_TAGS = ("[coll]", "[cos]", "[sin]")


def _triplets(desc, rotating):
    """Blade triplets among the rotating entries: list of (i1, i2, i3, digit position)."""
    rot = {d: i for i, d in enumerate(desc) if rotating[i]}
    out, used = [], set()
    for d, i in rot.items():
        if i in used:
            continue
        for pos in (mm.start() for mm in re.finditer(r"[123]", d)):
            names = [d[:pos] + b + d[pos + 1:] for b in "123"]
            if d[pos] == "1" and all(nm in rot for nm in names):
                idx = tuple(rot[nm] for nm in names)
                out.append((*idx, pos))
                used.update(idx)
                break
    return out


def _t_blocks(psi):
    az = psi + 2 * np.pi * np.arange(3) / 3
    one, c, s = np.ones(3), np.cos(az), np.sin(az)
    t1 = np.column_stack([one, c, s])
    t2 = np.column_stack([0 * one, -s, c])
    t3 = np.column_stack([0 * one, -c, -s])
    return t1, t2, t3


def _io_transform(n, trip, psi):
    T = np.eye(n)
    t1, _, _ = _t_blocks(psi)
    for *idx, _ in trip:
        T[np.ix_(idx, idx)] = t1
    return T


def _state_transform(desc, rotating, order, psi, omega):
    """(T_x, dT_x/dt) for the state vector; 2nd-order velocity triplets pair with positions."""
    n = len(desc)
    T, Td = np.eye(n), np.zeros((n, n))
    t1, t2, t3 = _t_blocks(psi)
    trip = _triplets(desc, rotating)
    first = {tuple(t[:3]) for t in trip}
    by_desc = {desc[t[0]]: tuple(t[:3]) for t in trip}
    for idx in first:
        T[np.ix_(idx, idx)] = t1
        Td[np.ix_(idx, idx)] = omega * t2
        d = desc[idx[0]]
        prefix = "First time derivative of "
        if order[idx[0]] == 2 and d.startswith(prefix):
            pos_idx = by_desc.get(d[len(prefix):])
            if pos_idx is None:
                continue
            T[np.ix_(idx, pos_idx)] = omega * t2
            Td[np.ix_(idx, pos_idx)] = omega**2 * t3
    return T, Td, trip


def mbc_transform(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, x_desc, x_rot, x_order, u_desc, u_rot,
                  y_desc, y_rot, azimuth: float, rotor_speed: float) -> tuple:
    """Multi-blade coordinate transform of one azimuth's (A, B, C, D) (see module docstring).

    Parameters
    ----------
    A, B, C, D : numpy.ndarray
        State-space matrices at this azimuth.
    x_desc : sequence of str
        Descriptions of the states (blade triplets are found by the descriptions).
    x_rot : numpy.ndarray
        Bool per state: in the rotating frame.
    x_order : numpy.ndarray
        Derivative order of each state (2 for velocities of second-order states).
    u_desc : sequence of str
        Descriptions of the inputs.
    u_rot : numpy.ndarray
        Bool per input: in the rotating frame.
    y_desc : sequence of str
        Descriptions of the outputs.
    y_rot : numpy.ndarray
        Bool per output: in the rotating frame.
    azimuth : float
        Azimuth of blade 1 (rad).
    rotor_speed : float
        Rotor speed (rad/s).

    Returns
    -------
    tuple
        (A, B, C, D) in the non-rotating frame and the transformed descriptions
        (x_desc, u_desc, y_desc).
    """
    Tx, Txd, tx = _state_transform(x_desc, x_rot, x_order, azimuth, rotor_speed)
    tu = _triplets(u_desc, u_rot)
    ty = _triplets(y_desc, y_rot)
    Tu = _io_transform(len(u_desc), tu, azimuth)
    Ty = _io_transform(len(y_desc), ty, azimuth)
    Txi = np.linalg.inv(Tx)
    Tyi = np.linalg.inv(Ty)
    A_nr = Txi @ (A @ Tx - Txd)
    B_nr = Txi @ B @ Tu
    C_nr = Tyi @ C @ Tx
    D_nr = Tyi @ D @ Tu
    return A_nr, B_nr, C_nr, D_nr, _rename(x_desc, tx), _rename(u_desc, tu), _rename(y_desc, ty)


def _rename(desc, trip):
    out = list(desc)
    for *idx, pos in trip:
        for i, tag in zip(idx, _TAGS):
            d = desc[idx[0]]
            out[i] = d[:pos] + tag + d[pos + 1:]
    return tuple(out)


def _unit(desc):
    m = re.search(r"\(([^()]*)\)\s*$", desc)
    return m.group(1) if m else ""


def read_linearization(paths: str | os.PathLike | Sequence[str | os.PathLike], inputs=None, outputs=None, *,
                       si: bool = True) -> LinearizationData:
    """Read the ``.lin`` files of one operating point, MBC-transform and average over azimuth.

    Parameters
    ----------
    paths : str or os.PathLike, or a sequence of them
        One file per azimuth, same signals.
    inputs, outputs : list or dict, optional
        Selection, as in :meth:`LinearizationData.to_statespace`; when given, the result keeps
        only those signals.
    si : bool, default True
        Convert outputs written in rpm, deg, deg/s, kN, kN-m, kW to rad/s, rad, rad/s, N,
        N·m, W (inputs are already SI in OpenFAST).

    Returns
    -------
    LinearizationData
        The averaged, non-rotating-frame linearisation.

    Raises
    ------
    ValueError
        No paths, files of different linearisations, a selection that does not match one
        description, or a malformed file (naming file and line).

    Examples
    --------
    >>> from importlib import resources
    >>> lin = resources.files("specdesign") / "data/iea15mw/sample_floating_19mps.1.lin"
    >>> round(read_linearization(lin).wind_speed, 1)
    19.0
    """
    if isinstance(paths, (str, Path)):
        paths = [paths]
    paths = [str(p) for p in paths]
    if not paths:
        raise ValueError("paths is empty; pass one or more OpenFAST .lin files")
    files = [read_lin_file(p) for p in paths]
    ref = files[0]
    for f in files[1:]:
        if (f.x_desc, f.u_desc, f.y_desc) != (ref.x_desc, ref.u_desc, ref.y_desc):
            raise ValueError(f"{f.path} has different states/inputs/outputs from {ref.path}; pass files of one linearisation")
    acc = None
    for f in files:
        res = mbc_transform(f.A, f.B, f.C, f.D, f.x_desc, f.x_rot, f.x_order, f.u_desc, f.u_rot, f.y_desc, f.y_rot, f.azimuth, f.rotor_speed)
        acc = list(res[:4]) if acc is None else [a + r for a, r in zip(acc, res[:4])]
        descs = res[4:]
    A, B, C, D = (a / len(files) for a in acc)
    units = [_unit(d) for d in descs[2]]
    y_desc = descs[2]
    if si:
        scale = np.array([_SI.get(u.lower(), (1.0, u))[0] for u in units])
        units = [_SI.get(u.lower(), (1.0, u))[1] for u in units]
        # descriptions carry the unit actually used, so nothing reads "(rpm)" in rad/s
        y_desc = tuple(re.sub(r"\(([^()]*)\)\s*$", f"({u})", d) if _unit(d) else d for d, u in zip(y_desc, units))
        C = C * scale[:, None]
        D = D * scale[:, None]
        y_op = np.mean([f.y_op for f in files], axis=0) * scale
    else:
        y_op = np.mean([f.y_op for f in files], axis=0)
    data = LinearizationData(
        A=A, B=B, C=C, D=D, x_desc=descs[0], u_desc=descs[1], y_desc=y_desc, y_units=tuple(units),
        x_op=np.mean([f.x_op for f in files], axis=0), u_op=np.mean([f.u_op for f in files], axis=0), y_op=y_op,
        wind_speed=float(np.mean([f.wind_speed for f in files])), rotor_speed=float(np.mean([f.rotor_speed for f in files])),
        azimuths=np.array([f.azimuth for f in files]), paths=tuple(paths),
    )
    if inputs is None and outputs is None:
        return data
    iu, _ = data._select("inputs", inputs)
    iy, _ = data._select("outputs", outputs)
    return LinearizationData(
        A=data.A, B=data.B[:, iu], C=data.C[iy], D=data.D[np.ix_(iy, iu)], x_desc=data.x_desc,
        u_desc=tuple(data.u_desc[i] for i in iu), y_desc=tuple(data.y_desc[i] for i in iy),
        y_units=tuple(data.y_units[i] for i in iy), x_op=data.x_op, u_op=data.u_op[iu], y_op=data.y_op[iy],
        wind_speed=data.wind_speed, rotor_speed=data.rotor_speed, azimuths=data.azimuths, paths=data.paths,
    )
