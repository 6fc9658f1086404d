"""ROSCO's compiled controller in the simulator: :class:`Discon`.

ROSCO's DISCON library (``libdiscon.so`` of the ``rosco`` package, optional extra
``specdesign[rosco]``) is driven through the Bladed-style interface its OpenFAST users call:
``DISCON(avrSWAP, aviFAIL, accINFILE, avcOUTNAME, avcMSG)`` with ``avrSWAP`` a float32 swap
array (1-based indices of the Bladed user manual, Appendix A). ROSCO keeps its state in
Fortran ``SAVE`` variables and refuses a second initialisation in one loaded library, so each
run gets its own copy of the library file, loaded apart.

:class:`Discon` is a controller callable of :func:`specdesign.simulate.simulate` that commands
pitch and generator torque; the simulator calls :meth:`Discon.start` once before the first
step. What ROSCO reads at each step (1-based ``avrSWAP`` index → value):

====  ====================================================================================
1     status: 0 on the first call (initialisation at the trim), 1 after, −1 at the end
2, 3  time (s), step (s)
4     blade-1 pitch (rad), also 33, 34 (ROSCO feeds its own last command back after the first call)
14    shaft power T·Ω_g (W); 15 electrical power, the plant's ``power`` (W)
20    generator speed N·Ω (rad/s); 21 rotor speed Ω (rad/s), N = ``WE_GearboxRatio``
23    measured generator torque: the last command (HSS N·m)
27    hub-height wind: the run's wind at t = 0 (m/s), ROSCO's initial wind estimate
53    tower-top fore-aft acceleration (m/s²)
60    rotor azimuth (rad), integrated from the rotor speed; 61 number of blades (3)
====  ====================================================================================

and what it returns: 45, the collective pitch command (rad), and 47, the generator torque
command (HSS N·m, N times that on the rotor shaft, which the plant takes).
"""
from __future__ import annotations

import ctypes
import importlib.metadata
import os
import re
import shutil
import tempfile
from pathlib import Path

import numpy as np
from numba import njit

from .._checks import bad_measurements
from ..controller.discon_file import read_discon

__all__ = ["SWAP_SIZE", "DisconError", "rosco_library", "rosco_test_cases", "Discon"]

#: Length of the swap array handed to ROSCO (it reads and writes indices up to 1018).
SWAP_SIZE = 2000
#: Length of the message buffer (avcMSG).
_MSG_SIZE = 1024


@njit(cache=True)
def _fill_swap(sw, t, omega, pitch, power, acc, n):
    """The measurements of one step into each run's swap array (0-based: Bladed index − 1)."""
    for r in range(sw.shape[0]):
        sw[r, 1] = t
        sw[r, 3] = pitch[r]
        sw[r, 32] = pitch[r]
        sw[r, 33] = pitch[r]
        sw[r, 13] = sw[r, 22] * omega[r] * n
        sw[r, 14] = power[r]
        sw[r, 19] = omega[r] * n
        sw[r, 20] = omega[r]
        sw[r, 52] = acc[r]


@njit(cache=True)
def _read_swap(sw, omega, dt, n, pitch, torque):
    """ROSCO's commands out of the swap arrays; the azimuth and measured torque for the next step."""
    for r in range(sw.shape[0]):
        sw[r, 59] = (sw[r, 59] + omega[r] * dt) % (2.0 * np.pi)
        sw[r, 22] = sw[r, 46]  # the torque ROSCO measures next is the one it commands now
        pitch[r] = sw[r, 44]
        torque[r] = sw[r, 46] * n


class DisconError(RuntimeError):
    """ROSCO stopped a run (``aviFAIL < 0`` after the initialisation); the message is ROSCO's."""


def _rosco_file(rel: str) -> Path:
    try:
        dist = importlib.metadata.distribution("rosco")
    except importlib.metadata.PackageNotFoundError:
        raise ModuleNotFoundError("the compiled ROSCO controller needs the 'rosco' package: "
                                  "pip install 'specdesign[rosco]'") from None
    path = Path(str(dist.locate_file(rel)))
    if not path.exists():
        raise FileNotFoundError(f"the installed rosco {dist.version} has no {rel} (expected at {path})")
    return path


def rosco_library() -> Path:
    """Path of the compiled ROSCO controller shipped by the ``rosco`` package.

    Returns
    -------
    pathlib.Path
        ``<site-packages>/rosco/lib/libdiscon.so``.

    Raises
    ------
    ModuleNotFoundError
        If the ``rosco`` package is not installed (``pip install 'specdesign[rosco]'``).
    """
    return _rosco_file("rosco/lib/libdiscon.so")


def rosco_test_cases() -> Path:
    """The OpenFAST decks the ``rosco`` package ships (``Examples/Test_Cases``).

    Among them ``NREL-5MW/`` (``NREL-5MW.fst``, ``DISCON.IN``, ``Cp_Ct_Cq.NREL5MW.txt``),
    ``BAR_10/``, ``NREL_2p8_127/`` and ``IEA-15-240-RWT/IEA-15-240-RWT-Monopile/``.

    Returns
    -------
    pathlib.Path
        The folder.

    Raises
    ------
    ModuleNotFoundError
        If the ``rosco`` package is not installed (``pip install 'specdesign[rosco]'``).
    """
    return _rosco_file("Examples/Test_Cases")


#: First word of a parameter file of :func:`specdesign.export.export_discon` (its own format, not ROSCO's).
_EXPORTED = "specdesign-discon"
#: First word of a parameter file of :func:`specdesign.export.forwarded` (read by its forwarding library).
_FORWARD = "specdesign-forward"


def _exported_gearbox_ratio(path: Path) -> float | None:
    """The ``gearbox_ratio`` of an exported controller's parameter file, None for a ROSCO DISCON.IN."""
    with open(path, errors="replace") as f:
        # a forwarding file (specdesign-forward) embeds an exported one: the same key
        if f.readline().split()[:1] not in ([_EXPORTED], [_FORWARD]):
            return None
        for line in f:
            words = line.partition("#")[0].split()
            if words[:1] == ["gearbox_ratio"] and len(words) == 2:
                try:
                    return float(words[1])
                except ValueError:
                    break
    raise ValueError(f"{path}: no numeric gearbox_ratio: write the file with specdesign.export.export_discon")


def _refused_parameter(msg: str) -> str | None:
    """The DISCON.IN key a ROSCO error message names, if any."""
    m = re.search(r"\bfor ([A-Za-z][A-Za-z0-9_]*)", msg) or re.search(r"\b([A-Z][A-Za-z0-9]*_[A-Za-z0-9_]+)\b(?!.*:)", msg)
    return m.group(1) if m else None


_QUOTED = re.compile(r'"([^"]*)"')


def _run_copy(discon_in: Path, folder: Path) -> Path:
    """A copy of ``discon_in`` in ``folder`` that ROSCO runs as the original: relative file
    names made absolute (ROSCO resolves them from the file's own folder), no debug output."""
    base = discon_in.parent.resolve()
    lines = []
    for raw in discon_in.read_text(errors="replace").splitlines():
        left, sep, right = raw.partition("!")
        key = right.split()[0] if right.split() else ""
        if key in ("LoggingLevel", "Echo"):
            # a .dbg line per step would cost more than the controller and fill the disk
            left = "0" + " " * max(1, len(left) - 1)
        elif sep and '"' in left:
            left = _QUOTED.sub(lambda m: '"' + (m.group(1) if not m.group(1) or Path(m.group(1)).is_absolute()
                                                else str(base / m.group(1))) + '"', left)
        lines.append(left + sep + right)
    out = folder / "DISCON.IN"
    out.write_text("\n".join(lines) + "\n")
    return out


#: The files ROSCO opens, by the DISCON.IN key naming each and the mode key that makes it read
#: it (ReadSetParameters.f90, ROSCO 2.9): ReadCpFile opens PerfFileName with STATUS='old' and
#: no IOSTAT when WE_Mode > 0, so a missing table ends the whole process (gfortran's runtime
#: error), taking the caller's interpreter with it.
_OPENED_FILES = (("PerfFileName", "WE_Mode"), ("OL_Filename", "OL_Mode"), ("DLL_FileName", "Ext_Mode"))


def _check_opened_files(discon_in: Path, entries: dict) -> None:
    """Raise FileNotFoundError, naming the DISCON.IN, the line and the key, for a file ROSCO
    will open that is missing or unreadable (checked before the library is loaded: ROSCO's
    Fortran runtime would stop the process instead)."""
    for key, mode in _OPENED_FILES:
        e, m = entries.get(key), entries.get(mode)
        try:
            used = m is not None and int(float(m.values[0])) > 0
        except (ValueError, IndexError):
            raise ValueError(f"{discon_in}: line {m.line}: {mode} = {' '.join(m.values)!r} is not a whole number") from None
        if not used:
            continue
        if e is None or not e.values or not e.values[0].strip('"'):
            raise ValueError(f"{discon_in}: {mode} > 0 makes ROSCO read {key}, which is missing or empty")
        name = e.values[0].strip('"')
        path = Path(name) if Path(name).is_absolute() else discon_in.parent / name  # ROSCO: from the file's folder
        if not path.is_file() or not os.access(path, os.R_OK):
            why = "does not exist" if not path.exists() else "is not a readable file"
            raise FileNotFoundError(f"{discon_in}: line {e.line}: {key} = {e.values[0]}: {path} {why}; ROSCO "
                                    f"({mode} = {m.values[0]}) would stop the Python process opening it")


class Discon:
    """ROSCO's compiled controller (its DISCON library) as a controller of :func:`specdesign.simulate.simulate`.

    One library copy per run, initialised at the run's trim (the simulator's first step);
    ROSCO commands collective pitch and generator torque. See :mod:`specdesign.rosco.discon`
    for the swap-array signals. The run uses a copy of ``discon_in`` with ``LoggingLevel``
    and ``Echo`` set to 0 (no debug files) and its relative file names made absolute; ROSCO
    prints its banner and a status line every 10 s of simulated time on the process's stdout.

    An exported controller runs the same way: ``Discon(rec.parameters, library=rec.library)``
    for a record of :func:`specdesign.export.export_discon`; its parameter file (first word
    ``specdesign-discon``) is read as it is, its ``gearbox_ratio`` converting the speeds.

    Parameters
    ----------
    discon_in : str or pathlib.Path
        The DISCON.IN file, written for the library's ROSCO version, or the parameter file of
        an exported controller.
    library : str or pathlib.Path, optional
        The compiled controller (default :func:`rosco_library`, the ``rosco`` package's).
    name : str, optional
        Label of the controller in results.

    Raises
    ------
    FileNotFoundError
        If ``discon_in`` or ``library`` does not exist, or a file ROSCO will open does not
        (``PerfFileName`` with ``WE_Mode`` > 0, ``OL_Filename`` with ``OL_Mode`` > 0,
        ``DLL_FileName`` with ``Ext_Mode`` > 0; relative names from the DISCON.IN's folder):
        ROSCO's Fortran runtime would end the Python process on a missing performance table,
        so every such file is checked before the library is loaded, and the message names the
        DISCON.IN, the line and the key.
    ModuleNotFoundError
        Without ``library``, if the ``rosco`` package is not installed.
    ValueError
        If an exported controller's file has no numeric ``gearbox_ratio``; if ``discon_in``
        lacks ``WE_GearboxRatio`` or has a non-positive one, or uses
        ``WE_Mode = 0`` (ROSCO would read a hub-height wind the simulator does not give).

    Notes
    -----
    A DISCON.IN that ROSCO refuses (one written for another ROSCO version) raises ValueError
    at the first step, naming the parameter ROSCO refused and quoting ROSCO's message; a
    later failure raises :class:`DisconError`.

    Each simulation loads fresh copies (about 1 MB each), which stay mapped until the process
    ends; a campaign of a few hundred runs is fine. ROSCO's hub-height wind input receives the
    run's wind at t = 0 only (its estimators, ``WE_Mode`` 1 or 2, use it to start). A pickled
    Discon (a campaign task sent to a worker) carries its file names and starts there anew.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.simulate import simulate
    >>> from specdesign.turbine import iea15mw
    >>> deck = rosco_test_cases() / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile"  # doctest: +SKIP
    >>> r = simulate(iea15mw(), Discon(deck / "IEA-15-240-RWT-Monopile_DISCON.IN"), [19.0],
    ...              seeds=[1], duration=10.0, transient=5.0)  # doctest: +SKIP
    """

    def __init__(self, discon_in: str | Path, library: str | Path | None = None, *, name: str = "ROSCO DISCON"):
        self.discon_in = Path(discon_in)
        if not self.discon_in.is_file():
            raise FileNotFoundError(f"discon_in={str(self.discon_in)!r} does not exist")
        # an exported controller's parameter file (specdesign.export): its library reads it as it is
        exported = _exported_gearbox_ratio(self.discon_in)
        self.exported = exported is not None
        self.library = Path(library) if library is not None else rosco_library()
        if not self.library.is_file():
            raise FileNotFoundError(f"library={str(self.library)!r} does not exist")
        self.__name__ = str(name)
        self._tmp = None
        self._runs = 0
        if self.exported:
            self.gearbox_ratio, self.file_version = exported, _EXPORTED
            return
        entries, self.file_version = read_discon(self.discon_in)
        _check_opened_files(self.discon_in, entries)  # before the library is loaded (it can end the process)
        e = entries.get("WE_GearboxRatio")
        try:
            ratio = float(e.values[0]) if e is not None else float("nan")
        except (ValueError, IndexError):
            ratio = float("nan")
        if not ratio > 0:
            raise ValueError(f"{self.discon_in}: WE_GearboxRatio is missing or not positive: ROSCO's speeds are "
                             "generator speeds, the plant's rotor speeds, and the ratio converts them")
        we = entries.get("WE_Mode")
        if we is not None and we.values and we.values[0] == "0":
            raise ValueError(f"{self.discon_in}: line {we.line}: WE_Mode = 0 reads the measured hub-height wind, which "
                             "the simulator does not give the controller; use WE_Mode = 1 or 2 (ROSCO's estimators)")
        self.gearbox_ratio = ratio

    def __getstate__(self):
        # the loaded library copies stay with this process: a pickled Discon (a campaign's
        # task on another worker) carries its files and starts fresh copies there
        keep = ("discon_in", "exported", "file_version", "library", "gearbox_ratio", "__name__")
        return {**{k: self.__dict__[k] for k in keep}, "_tmp": None, "_runs": 0}

    def start(self, dt: float, wind: np.ndarray, pitch: np.ndarray, torque: np.ndarray) -> None:
        """Prepare one fresh library copy per run (the simulator calls it before the first step).

        Parameters
        ----------
        dt : float
            Simulation step (s), ROSCO's sample time.
        wind : numpy.ndarray
            (R,) rotor-effective wind of each run at t = 0 (m/s): ROSCO's initial wind estimate.
        pitch : numpy.ndarray
            (R,) trim pitch of each run (rad).
        torque : numpy.ndarray
            (R,) trim generator torque on the rotor shaft (N·m).
        """
        self.close()
        R = int(np.size(wind))
        self._tmp = tempfile.TemporaryDirectory(prefix="specdesign_discon_")
        folder = Path(self._tmp.name)
        infile = self.discon_in.resolve() if self.exported else _run_copy(self.discon_in, folder)
        # loading the original first resolves the copies' dependencies (its RPATH points next to it)
        ctypes.CDLL(str(self.library))
        self._fns = []
        for r in range(R):
            so = folder / f"libdiscon_{r}{self.library.suffix}"
            shutil.copyfile(self.library, so)
            lib = ctypes.CDLL(str(so))
            fn = lib.DISCON
            fn.restype = None
            fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_void_p]
            self._fns.append(fn)
        # ROSCO prints through gfortran's stdout, buffered on a pipe: flushed after each step, or
        # it would surface at exit, far from its run (and outside pytest's capture)
        flush = getattr(lib, "_gfortran_flush_i4", None) if R else None
        if flush is not None:
            flush.restype = None
            flush.argtypes = [ctypes.c_void_p]
            self._unit6 = ctypes.c_int32(6)
            self._flush = lambda: flush(ctypes.addressof(self._unit6))
        else:
            self._flush = lambda: None
        self._infile = str(infile).encode() + b"\0"
        self._outnames = [str(folder / f"run{r}").encode() + b"\0" for r in range(R)]
        self._swap = np.zeros((R, SWAP_SIZE), dtype=np.float32)
        self._fail = np.zeros(R, dtype=np.int32)
        self._msg = np.zeros((R, _MSG_SIZE + 1), dtype=np.uint8)
        self._swap[:, 48] = _MSG_SIZE
        self._swap[:, 49] = len(self._infile)
        self._swap[:, 50] = [len(o) for o in self._outnames]
        self._swap[:, 60] = 3.0
        self._swap[:, 2] = float(dt)
        self._swap[:, 26] = np.asarray(wind, dtype=np.float32)
        self._swap[:, 22] = np.asarray(torque, dtype=float) / self.gearbox_ratio
        self._args = [(self._swap[r].ctypes.data, self._fail[r:].ctypes.data, self._outnames[r], self._msg[r].ctypes.data)
                      for r in range(R)]
        self._dt = float(dt)
        self._step = 0
        self._runs = R

    def _message(self, r: int) -> str:
        return bytes(self._msg[r]).split(b"\0", 1)[0].decode(errors="replace").strip()

    def _call_all(self, status: int, skip=None) -> None:
        sw = self._swap
        sw[:, 0] = status
        fns, infile = self._fns, self._infile
        for r, (a, f, o, m) in enumerate(self._args):
            if skip is None or not skip[r]:  # a skipped run (a bad sample) keeps ROSCO's state and command
                fns[r](a, f, infile, o, m)
        self._flush()
        if self._fail.min() < 0:
            r = int(np.flatnonzero(self._fail < 0)[0])
            msg = self._message(r)
            if status == 0 and self.exported:
                raise ValueError(f"the exported controller ({self.library.name}) refused its parameter file: {msg}")
            if status == 0:
                key = _refused_parameter(msg)
                what = f"parameter {key}" if key else "its input"
                raise ValueError(
                    f"ROSCO ({self.library.name}) refused DISCON.IN {str(self.discon_in)!r} (written by ROSCO "
                    f"{self.file_version or 'of unknown version'}): {what}. ROSCO says: {msg!r}. Write the file "
                    "for this ROSCO version (rosco's Examples/19_update_discon_version.py converts one)")
            raise DisconError(f"ROSCO stopped run {r} at t = {float(sw[r, 1]):.2f} s: {msg}")

    def __call__(self, t: float, y: dict) -> tuple[np.ndarray, np.ndarray]:
        """One controller step for every run.

        Parameters
        ----------
        t : float
            Time (s).
        y : dict
            The plant outputs, name → (R,) array (SI): ``gen_speed`` (rotor side, rad/s),
            ``pitch`` (rad), ``power`` (W), ``tower_top_acc`` (m/s²).

        Returns
        -------
        pitch_cmd : numpy.ndarray
            (R,) collective pitch command (rad).
        gen_torque : numpy.ndarray
            (R,) generator torque command on the rotor shaft (N·m).

        Raises
        ------
        RuntimeError
            If :meth:`start` was not called.
        ValueError
            If ROSCO refuses the DISCON.IN at its initialisation (the parameter is named), or
            a measurement is NaN or inf at the first call (ROSCO initialises on it).
        DisconError
            If ROSCO stops a run later.

        Warns
        -----
        RuntimeWarning
            Once per signal, for a NaN or inf measurement after the first call: ROSCO is not
            called for that run at that step, which holds its last commands (and ROSCO its
            state) until the signal is finite again (:func:`specdesign._checks.bad_measurements`,
            the convention of every controller).
        """
        if not self._runs:
            raise RuntimeError("Discon.start(dt, wind, pitch, torque) must run first (simulate calls it)")
        signals = ("gen_speed", "pitch", "power", "tower_top_acc")
        if self._step == 0:
            self._warned = set()
            bad = [n for n in signals if not np.all(np.isfinite(np.asarray(y[n], float)))]
            if bad:  # ROSCO initialises on this sample: no command to hold yet
                raise ValueError(f"{self.__name__}: measurement {bad[0]!r} is not finite at the first call (t = "
                                 f"{float(t):g} s): ROSCO initialises on it, and there is no command to hold yet")
        bad = bad_measurements(y, signals, float(t), self._warned, self.__name__)
        keep = self._swap[bad].copy() if bad.any() else None
        omega = np.ascontiguousarray(np.where(bad, 0.0, y["gen_speed"]), dtype=float)  # the azimuth holds too
        _fill_swap(self._swap, float(t), omega, np.ascontiguousarray(y["pitch"], dtype=float),
                   np.ascontiguousarray(y["power"], dtype=float), np.ascontiguousarray(y["tower_top_acc"], dtype=float),
                   self.gearbox_ratio)
        if keep is not None:
            self._swap[bad] = keep
        self._call_all(0 if self._step == 0 else 1, skip=bad if keep is not None else None)
        self._step += 1
        pitch, torque = np.empty(self._runs), np.empty(self._runs)
        _read_swap(self._swap, omega, self._dt, self.gearbox_ratio, pitch, torque)
        return pitch, torque

    def close(self) -> None:
        """End the runs (ROSCO's final call, status −1) and remove their library copies.

        Called by :meth:`start` before new runs; call it after the last simulation to free
        the files at once (they are removed at exit otherwise).
        """
        if self._runs and self._step:
            try:
                self._call_all(-1)
            except (ValueError, DisconError):
                pass
        self._runs = 0
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None
