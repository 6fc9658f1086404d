"""The parameter file of the exported controller: :class:`DisconParameters`, written and read.

A plain-text file, one keyword then its numbers, in a fixed order, ``#`` to the end of a line
a comment; its first words are ``specdesign-discon 2`` (the format and its version). Numbers
are written as Python's ``repr`` of a float (the shortest text that reads back to the same
double, ``inf`` for infinity), so matrices round-trip exactly. The format, keyword by keyword,
is in ``docs/export.md``; :func:`read_parameters` and the C library read it with the same rules.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from ..controller.torque import TORQUE_PARAMS

__all__ = ["FORMAT_NAME", "FORMAT_VERSION", "TORQUE_MODES", "SAME_DESIGN_RTOL", "DisconParameters", "write_parameters",
           "read_parameters"]

#: First word of a parameter file.
FORMAT_NAME = "specdesign-discon"
#: Two parameter files whose controllers' responses differ by at most this (relative,
#: :meth:`DisconParameters.response_change`) hold the same design, and a 600 s OpenFAST run of
#: one counts as a run of the other: the design code's or the linearisation's last digits moved
#: (Table 3's designs made again on the linearisations of an OpenFAST built on another machine:
#: 2.4e-9 to 1.3e-7; the 25 m/s QFT+ATD design after the notch shaper's KKT refinement: 3.1e-6, its
#: seed 0 run again gave every indicator within 1.2e-6 relative of the stored run, tower DEL
#: 6.6e-7, 2026-11-28); a new design moves by 1e-1 and more.
SAME_DESIGN_RTOL = 1e-5
#: Version of the format this package writes and its library reads.
FORMAT_VERSION = 2
#: ``torque_mode`` codes of the file: the rated torque held, constant power P/(η·Ω_f), ROSCO's law,
#: ROSCO's law with constant power in region 3 (``VS_ConstPower = 1``).
TORQUE_MODES = {"constant": 0, "power": 1, "rosco": 2, "rosco_power": 3}


@dataclass(frozen=True, eq=False)  # array fields: compare with :meth:`same`
class DisconParameters:
    """Everything the exported library reads: the controller discrete at ``dt`` (SI, rotor shaft).

    The pitch part is :func:`specdesign.controller.scheduled.controller_bank` of the controller at ``dt``:
    K local controllers x⁺ = A x + B [e, −v], u = C x + D [e, −v] + i, with e = Ω_ref − Ω
    (rad/s) and v the tower-top fore-aft velocity (m/s), each integrator i (gain
    ``integrator_gain``, rad per rad) run apart by the trapezoid rule; output-blended in the
    scheduling pitch; plus ROSCO's gain-scheduled PI when ``pi_kp`` is given.

    Parameters
    ----------
    dt : float
        Sample time (s) of the discretisation; the library refuses another call interval.
    gearbox_ratio : float
        Generator speed / rotor speed (-): avrSWAP(20) is divided by it, the torque command too.
    rated_speed : float
        Speed reference Ω_ref (rotor rad/s).
    pitch_limits : tuple of float
        (min, max) pitch command (rad).
    pitch_rate_limit : float
        Largest |rate| of the command (rad/s); ``inf`` for none (the workbench's runs).
    torque_mode : int
        0 constant (``rated_torque``), 1 constant power, 2 ROSCO's law (``torque_law``), 3 the
        same with constant power in region 3.
    rated_torque, max_torque : float
        Generator torque held above rated, and the ceiling of constant power (rotor N·m).
    rated_power : float
        Electrical power of constant power (W).
    generator_efficiency : float
        η (-) of constant power: T = P/(η·Ω_f).
    speed_filter : tuple of float
        (corner rad/s, damping) of the 2nd-order low-pass Ω_f of constant power.
    torque_law : numpy.ndarray
        (25,) :meth:`specdesign.rosco.TorqueLaw.params` (zeros unless mode 2 or 3; its last
        entry, ``VS_ConstPower``, is 1 in mode 3 and 0 in mode 2).
    schedule_filter : numpy.ndarray
        (1,) or (5,) :func:`specdesign.controller.scheduled.schedule_filter_coefficients`.
    atd_highpass : float
        Corner w (rad/s) of the tower-top velocity estimate from acceleration,
        s/(s + w)·1/(s + w); 0: the plain integral.
    schedule_pitch : numpy.ndarray
        (K,) scheduling pitches (rad).
    integrator_gain : numpy.ndarray
        (K,) integrator gains r_q (rad per rad).
    slow_states : numpy.ndarray
        (K,) int, the leading states under :data:`specdesign.simulate.SLOW_OMEGA` (0: clamped integrator).
    A, B, C, D : numpy.ndarray
        (K, n, n), (K, n, 2), (K, n), (K, 2) discrete matrices, zero-padded to one n.
    pi_kp, pi_ki : numpy.ndarray or None
        (K,) ROSCO-form gains (rad per rad/s, rad per rad), or None without that part.
    pi_A, pi_B, pi_C, pi_D : numpy.ndarray or None
        Its discrete speed-error filter: (m, m), (m,), (m,), (1,).
    pi_limits : tuple of float
        (min, max) pitch of its integrator and output clamps (rad).
    name : str
        Label, written as a comment.
    """

    dt: float
    gearbox_ratio: float
    rated_speed: float
    pitch_limits: tuple
    pitch_rate_limit: float
    torque_mode: int
    rated_torque: float
    max_torque: float
    rated_power: float
    generator_efficiency: float
    speed_filter: tuple
    torque_law: np.ndarray = field(repr=False)
    schedule_filter: np.ndarray = field(repr=False)
    atd_highpass: float
    schedule_pitch: np.ndarray = field(repr=False)
    integrator_gain: np.ndarray = field(repr=False)
    slow_states: np.ndarray = field(repr=False)
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    D: np.ndarray = field(repr=False)
    pi_kp: np.ndarray | None = field(default=None, repr=False)
    pi_ki: np.ndarray | None = field(default=None, repr=False)
    pi_A: np.ndarray | None = field(default=None, repr=False)
    pi_B: np.ndarray | None = field(default=None, repr=False)
    pi_C: np.ndarray | None = field(default=None, repr=False)
    pi_D: np.ndarray | None = field(default=None, repr=False)
    pi_limits: tuple = (-math.inf, math.inf)
    name: str = "controller"

    def same(self, other: DisconParameters) -> bool:
        """Whether ``other`` holds the same numbers, bit for bit (the name aside).

        Parameters
        ----------
        other : DisconParameters
            Another parameter set.

        Returns
        -------
        bool
            True if every field but ``name`` is equal as float64 bits (shapes included).
        """
        for f in fields(self):
            if f.name == "name":
                continue
            a, b = getattr(self, f.name), getattr(other, f.name)
            if (a is None) != (b is None):
                return False
            if a is None:
                continue
            a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
            if a.shape != b.shape or a.tobytes() != b.tobytes():
                return False
        return True

    def response_change(self, other: DisconParameters, omega: np.ndarray | None = None) -> float:
        """How far ``other``'s controller is from this one: the largest relative change of a response.

        Every field that is not the controller (sample time, limits, torque law, filters,
        scheduling pitches, the count of slow states) must be equal bit for bit, else the answer
        is ``inf``. The controller is compared by what it does, not by its realisation: each local
        controller's discrete responses from e and from −v at z = exp(jω·dt) (and the PI part's
        speed-error filter, when there is one), as |H' − H| / max(|H|, 1 % of max|H| over ω) (a
        dip of the response is compared to the response's size, not to itself), and the
        integrator and PI gains relatively.

        Parameters
        ----------
        other : DisconParameters
            Another parameter set, e.g. an earlier export of the same design.
        omega : numpy.ndarray, optional
            Frequencies, rad/s (default 400 from 0.005 rad/s to 10 rad/s or 0.9 of Nyquist).

        Returns
        -------
        float
            The largest relative change (-); 0.0 for :meth:`same` sets, ``inf`` for sets that
            differ in anything but the controller's numbers.
        """
        if self.same(other):
            return 0.0
        exact = ("dt", "gearbox_ratio", "rated_speed", "pitch_limits", "pitch_rate_limit", "torque_mode", "rated_torque",
                 "max_torque", "rated_power", "generator_efficiency", "speed_filter", "torque_law", "schedule_filter",
                 "atd_highpass", "schedule_pitch", "slow_states", "pi_limits")
        for name in exact:
            a, b = np.asarray(getattr(self, name), float), np.asarray(getattr(other, name), float)
            if a.shape != b.shape or a.tobytes() != b.tobytes():
                return math.inf
        if (self.pi_kp is None) != (other.pi_kp is None) or self.A.shape[0] != other.A.shape[0]:
            return math.inf
        w = np.geomspace(0.005, min(10.0, 0.9 * math.pi / self.dt), 400) if omega is None else np.asarray(omega, float)
        z = np.exp(1j * w * self.dt)

        def relative(a, b):  # a, b: (n_omega, n_channels) responses, or gains
            a, b = np.atleast_1d(a), np.atleast_1d(b)
            floor = 1e-2 * np.max(np.abs(a), axis=0) if a.ndim > 1 else np.zeros(a.shape)
            scale = np.maximum(np.abs(a), floor)
            d = np.abs(b - a)
            return float(np.max(np.where(scale > 0, d / np.where(scale > 0, scale, 1.0), np.where(d > 0, np.inf, 0.0))))

        def bank(p, q):
            n = p.A.shape[1]
            H = [p.C[q] @ np.linalg.solve(zk * np.eye(n) - p.A[q], p.B[q]) + p.D[q] for zk in z] if n else [p.D[q]] * z.size
            return np.array(H)

        def pi_filter(p):
            m = p.pi_A.shape[0]
            return np.array([[p.pi_C @ np.linalg.solve(zk * np.eye(m) - p.pi_A, p.pi_B) + p.pi_D[0]] for zk in z])

        changes = [relative(self.integrator_gain, other.integrator_gain)]
        changes += [relative(bank(self, q), bank(other, q)) for q in range(self.A.shape[0])]
        if self.pi_kp is not None:
            changes += [relative(self.pi_kp, other.pi_kp), relative(self.pi_ki, other.pi_ki),
                        relative(pi_filter(self), pi_filter(other))]
        return max(changes)


def _num(x: float) -> str:
    # repr: the shortest decimal that reads back to the same double (C's strtod included)
    return repr(float(x))


def _line(key: str, values) -> str:
    return key + " " + " ".join(_num(v) for v in np.ravel(values))


def write_parameters(p: DisconParameters, path: str | Path, *, comment: str = "") -> Path:
    """Write ``p`` as a parameter file (the format of :mod:`specdesign.export.parameters`).

    Parameters
    ----------
    p : DisconParameters
        The parameters.
    path : str or pathlib.Path
        The file (overwritten).
    comment : str, optional
        Lines written as comments after the header.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    K, n = p.A.shape[0], p.A.shape[1]
    out = [f"{FORMAT_NAME} {FORMAT_VERSION}",
           f"# {p.name}".replace("\n", " ")]
    out += [f"# {c}" for c in comment.splitlines()]
    out += ["# SI units; speeds and torques on the rotor shaft (avrSWAP(20) and avrSWAP(47) are divided by",
            "# gearbox_ratio); e = rated_speed - rotor speed (rad/s), v = tower-top fore-aft velocity (m/s).",
            _line("dt", [p.dt]), _line("gearbox_ratio", [p.gearbox_ratio]), _line("rated_speed", [p.rated_speed]),
            _line("pitch_limits", p.pitch_limits), _line("pitch_rate_limit", [p.pitch_rate_limit]),
            "# torque: 0 constant rated_torque, 1 constant power, 2 ROSCO's law (torque_law, 25 numbers),",
            "# 3 ROSCO's law with constant power in region 3",
            f"torque_mode {int(p.torque_mode)}", _line("rated_torque", [p.rated_torque]),
            _line("max_torque", [p.max_torque]), _line("rated_power", [p.rated_power]),
            _line("generator_efficiency", [p.generator_efficiency]), _line("speed_filter", p.speed_filter),
            _line("torque_law", p.torque_law),
            f"schedule_filter {p.schedule_filter.size} " + " ".join(_num(v) for v in p.schedule_filter),
            _line("atd_highpass", [p.atd_highpass]),
            f"locals {K}", f"states {n}", _line("schedule_pitch", p.schedule_pitch)]
    for q in range(K):
        out += [f"local {q}", _line("integrator_gain", [p.integrator_gain[q]]), f"slow_states {int(p.slow_states[q])}",
                "A"] + ["  " + " ".join(_num(v) for v in row) for row in p.A[q]]
        out += ["B"] + ["  " + " ".join(_num(v) for v in row) for row in p.B[q]]
        out += [_line("C", p.C[q]), _line("D", p.D[q])]
    if p.pi_kp is None:
        out.append("pi 0")
    else:
        m = p.pi_A.shape[0]
        out += ["pi 1", f"pi_filter_states {m}", _line("pi_kp", p.pi_kp), _line("pi_ki", p.pi_ki),
                "pi_A"] + ["  " + " ".join(_num(v) for v in row) for row in p.pi_A]
        out += [_line("pi_B", p.pi_B), _line("pi_C", p.pi_C), _line("pi_D", p.pi_D), _line("pi_limits", p.pi_limits)]
    out.append("end")
    path = Path(path)
    path.write_text("\n".join(out) + "\n")
    return path


class _Reader:
    """Tokens of a parameter file with their line numbers, read in the file's fixed order."""

    def __init__(self, path: Path):
        self.path = path
        self.tokens = [(tok, i) for i, line in enumerate(path.read_text(errors="replace").splitlines(), 1)
                       for tok in line.partition("#")[0].split()]
        self.k = 0

    def _fail(self, what: str):
        line = self.tokens[min(self.k, len(self.tokens) - 1)][1] if self.tokens else 1
        raise ValueError(f"{self.path}:{line}: {what}")

    def _next(self, what: str) -> str:
        if self.k >= len(self.tokens):
            self._fail(f"the file ends where {what} is expected")
        self.k += 1
        return self.tokens[self.k - 1][0]

    def key(self, name: str) -> None:
        tok = self._next(f"'{name}'")
        if tok != name:
            self.k -= 1
            self._fail(f"expected '{name}', found '{tok}'")

    def numbers(self, name: str, n: int | None = None, *, keyed: bool = True) -> np.ndarray:
        if keyed:
            self.key(name)
        out = np.empty(n)
        for i in range(n):
            tok = self._next(f"a number for '{name}'")
            try:
                out[i] = float(tok)
            except ValueError:
                self.k -= 1
                self._fail(f"'{tok}' is not a number (for '{name}')")
            if math.isnan(out[i]):
                self.k -= 1
                self._fail(f"NaN for '{name}'")
        return out

    def integer(self, name: str) -> int:
        v = float(self.numbers(name, 1)[0])
        if v != int(v) or v < 0:
            self.k -= 1
            self._fail(f"'{name}' must be a whole number >= 0, got {v!r}")
        return int(v)


def read_parameters(path: str | Path) -> DisconParameters:
    """Read a parameter file written by :func:`write_parameters` (the library's rules).

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    DisconParameters
        Its numbers (the name from its first comment line).

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        For another format or version, or a missing, misplaced or non-numeric entry (the
        message names the file, the line and the keyword).
    """
    path = Path(path)
    r = _Reader(path)
    if not r.tokens or r.tokens[0][0] != FORMAT_NAME:
        r._fail(f"not a specdesign DISCON parameter file: its first word must be '{FORMAT_NAME}'")
    r.k = 1
    version = r.numbers("version", 1, keyed=False)[0]
    if version != FORMAT_VERSION:
        r._fail(f"format version {version:g}; this package reads version {FORMAT_VERSION}")
    first = path.read_text(errors="replace").splitlines()[1:2]
    name = first[0][1:].strip() if first and first[0].startswith("#") else "controller"
    kw = dict(dt=r.numbers("dt", 1)[0], gearbox_ratio=r.numbers("gearbox_ratio", 1)[0],
              rated_speed=r.numbers("rated_speed", 1)[0], pitch_limits=tuple(r.numbers("pitch_limits", 2)),
              pitch_rate_limit=r.numbers("pitch_rate_limit", 1)[0], torque_mode=r.integer("torque_mode"),
              rated_torque=r.numbers("rated_torque", 1)[0], max_torque=r.numbers("max_torque", 1)[0],
              rated_power=r.numbers("rated_power", 1)[0], generator_efficiency=r.numbers("generator_efficiency", 1)[0],
              speed_filter=tuple(r.numbers("speed_filter", 2)), torque_law=r.numbers("torque_law", TORQUE_PARAMS))
    nsf = r.integer("schedule_filter")
    if nsf not in (1, 5):
        r._fail("schedule_filter has 1 (first order) or 5 (second order) coefficients")
    kw["schedule_filter"] = r.numbers("schedule_filter", nsf, keyed=False)
    kw["atd_highpass"] = r.numbers("atd_highpass", 1)[0]
    K, n = r.integer("locals"), r.integer("states")
    kw["schedule_pitch"] = r.numbers("schedule_pitch", K)
    gains, slow = np.empty(K), np.empty(K, dtype=np.int64)
    A, B, C, D = np.empty((K, n, n)), np.empty((K, n, 2)), np.empty((K, n)), np.empty((K, 2))
    for q in range(K):
        if r.integer("local") != q:
            r.k -= 1
            r._fail(f"local {q} expected here")
        gains[q], slow[q] = r.numbers("integrator_gain", 1)[0], r.integer("slow_states")
        A[q] = r.numbers("A", n * n).reshape(n, n)
        B[q] = r.numbers("B", 2 * n).reshape(n, 2)
        C[q], D[q] = r.numbers("C", n), r.numbers("D", 2)
    kw.update(integrator_gain=gains, slow_states=slow, A=A, B=B, C=C, D=D)
    if r.integer("pi"):
        m = r.integer("pi_filter_states")
        kw.update(pi_kp=r.numbers("pi_kp", K), pi_ki=r.numbers("pi_ki", K), pi_A=r.numbers("pi_A", m * m).reshape(m, m),
                  pi_B=r.numbers("pi_B", m), pi_C=r.numbers("pi_C", m), pi_D=r.numbers("pi_D", 1),
                  pi_limits=tuple(r.numbers("pi_limits", 2)))
    r.key("end")
    if r.k < len(r.tokens):
        r._fail(f"'{r.tokens[r.k][0]}' after 'end'")
    return DisconParameters(**kw, name=name)
