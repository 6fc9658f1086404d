"""OpenFAST decks and cases: a case folder written from a deck (wind, controller, outputs,
length) with openfast-io's reader and writer, and OpenFAST run on it in a subprocess.

The workbench ships the IEA 15 MW monopile deck in the OpenFAST v5.0 format
(:func:`iea15mw_monopile`; SeaState and HydroDyn on). Any other deck openfast-io reads works
the same way (:class:`Deck`).
"""
from __future__ import annotations

import contextlib
import copy
import hashlib
import io
import math
import numbers
import os
import re
import resource
import signal
import subprocess
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

from ..wind import seed_for
from .install import OpenFASTInstall, check_deck_version, find_openfast, run_environment
from .outputs import OpenFASTOutput, read_outputs

__all__ = ["Deck", "Case", "OpenFASTRunError", "iea15mw_monopile", "write_case", "run_case", "CAMPAIGN_CHANNELS", "wave_seed_for",
           "WAVE_SEED_OFFSET", "named_digest"]

_SHIPPED = Path(__file__).resolve().parents[1] / "data" / "openfast" / "IEA-15-240-RWT-Monopile" / "IEA-15-240-RWT-Monopile.fst"

#: The output channels a campaign reads (and the only ones its cases write: each channel
#: written costs time and disk): hub-height wind, pitch, rotor and generator speed, generator
#: torque and power, tower-base fore-aft moment, blade-root flapwise moment, tower-top
#: fore-aft acceleration.
CAMPAIGN_CHANNELS = ("Wind1VelX", "BldPitch1", "RotSpeed", "GenSpeed", "GenTq", "GenPwr", "TwrBsMyt", "RootMyb1",
                     "YawBrTAxp")


@dataclass(frozen=True)
class Deck:
    """An OpenFAST deck: its main input file and the format version it is written for.

    Parameters
    ----------
    fst : str or os.PathLike
        The main input file (``.fst``); the files it names are found relative to it.
    version : str, optional
        The OpenFAST version its files are written for (``"5.0"``); checked against the
        executable before a run (:func:`specdesign.openfast.check_deck_version`). None:
        not checked (a mismatch then shows as OpenFAST's own input error).

    Raises
    ------
    FileNotFoundError
        ``fst`` does not exist.

    Examples
    --------
    >>> deck = iea15mw_monopile()
    >>> deck.fst.name, deck.version
    ('IEA-15-240-RWT-Monopile.fst', '5.0')
    """

    fst: Path
    version: str | None = None

    def __post_init__(self):
        fst = Path(self.fst).expanduser().resolve()
        if not fst.is_file():
            raise FileNotFoundError(f"Deck: fst={str(self.fst)!r} does not exist; give an OpenFAST main input file (.fst)")
        object.__setattr__(self, "fst", fst)

    @property
    def name(self) -> str:
        """The deck's name: its ``.fst`` without the suffix."""
        return self.fst.stem

    @property
    def digest(self) -> str:
        """16 hex digits of the deck's content: the ``.fst`` and every file it names, in turn
        (:func:`named_digest`), so that a changed ElastoDyn, AeroDyn or airfoil file is a changed
        deck, and a deck copied elsewhere is the same deck."""
        return named_digest(self.fst)


#: A quoted token of an input file: OpenFAST's, ROSCO's DISCON.IN and the workbench's name their
#: files in double quotes.
_QUOTED = re.compile(rb'"([^"\r\n\x00]+)"')


def named_digest(path) -> str:
    """16 hex digits of an input file by what it says, not where it lies.

    Every quoted name of an existing file in it (absolute, or relative to the naming file, as
    OpenFAST and ROSCO read them) counts by that file's own digest, in turn, instead of its
    path: a deck's ``.fst`` covers its modules, their blade, tower and airfoil files; a
    DISCON.IN its Cp table. A file whose text names no file digests as its bytes.

    Parameters
    ----------
    path : str or os.PathLike
        The input file.

    Returns
    -------
    str
        The first 16 hex digits of the SHA-256.

    Examples
    --------
    >>> named_digest(iea15mw_monopile().fst) == iea15mw_monopile().digest
    True
    """
    def digest(path: Path, within: frozenset) -> str:
        within = within | {path}

        def content(m):
            try:
                name = Path(m.group(1).decode())
                f = (name if name.is_absolute() else path.parent / name).resolve()
                found = f.is_file() and f not in within  # a file naming itself, or an ancestor, counts by its name
            except (OSError, UnicodeDecodeError, ValueError):  # bytes of a binary file, not a name
                return m.group(0)
            return b'"sha256:' + digest(f, within).encode() + b'"' if found else m.group(0)

        return hashlib.sha256(_QUOTED.sub(content, path.read_bytes())).hexdigest()[:16]

    return digest(Path(path).resolve(), frozenset())


def iea15mw_monopile() -> Deck:
    """The IEA 15 MW monopile deck shipped with the workbench (OpenFAST v5.0 format).

    From the IEA Wind Task 37 / NREL ROSCO example (Apache-2.0; ``specdesign/data/openfast/NOTICE.md``),
    brought to v5.0 by ``benchmarks/openfast_deck.py``: ElastoDyn, AeroDyn, ServoDyn
    (Bladed-interface controller), SeaState, HydroDyn and SubDyn on.

    Returns
    -------
    Deck
        The deck, ``version="5.0"``.
    """
    return Deck(_SHIPPED, version="5.0")


@dataclass(frozen=True)
class Case:
    """A case folder ready for OpenFAST.

    Parameters
    ----------
    name : str
        Case name (also the ``.fst`` file's stem and of the outputs).
    folder : pathlib.Path
        The folder holding the case's input files.
    deck : Deck
        The deck it was written from.
    tmax : float
        Simulated time (s).
    wind_speed : float
        Mean (hub-height) wind speed (m/s).
    seed : int or None
        Seed of its turbulent wind (None: steady wind).
    channels : tuple of str
        The output channels it writes.
    """

    name: str
    folder: Path
    deck: Deck
    tmax: float
    wind_speed: float
    seed: int | None
    channels: tuple

    @property
    def fst(self) -> Path:
        """The case's main input file."""
        return self.folder / f"{self.name}.fst"

    @property
    def outb(self) -> Path:
        """The binary output file OpenFAST writes."""
        return self.folder / f"{self.name}.outb"

    @property
    def log(self) -> Path:
        """OpenFAST's screen output of the run."""
        return self.folder / f"{self.name}.log"


class OpenFASTRunError(RuntimeError):
    """OpenFAST failed, timed out or wrote no outputs; the message names the case, its seed
    and the tail of OpenFAST's own message.

    Parameters
    ----------
    case : Case
        The case that failed.
    reason : str
        What went wrong ("failed (exit code 1, after 3 s)", "did not finish in 600 s").
    tail : str
        The last lines OpenFAST printed.

    Attributes
    ----------
    case : Case
        The case.
    tail : str
        The last lines OpenFAST printed.
    """

    def __init__(self, case: Case, reason: str, tail: str):
        self.case, self.tail = case, tail
        seed = "steady wind" if case.seed is None else f"seed {case.seed}"
        super().__init__(f"OpenFAST case {case.name!r} ({case.wind_speed:g} m/s, {seed}) {reason} "
                         f"(folder {case.folder}); the end of its output:\n{tail}")


# openfast-io's reader and writer print through sys.stdout, which is swapped to silence them:
# one at a time, so that threads writing cases at once (a campaign) never leave it swapped
IO_LOCK = threading.Lock()
_DECK_LOCK = threading.Lock()


@lru_cache(maxsize=8)
def read_deck_cached(fst: str, mtime: float) -> dict:
    """openfast-io's variable tree of a deck (cached per file and modification time)."""
    from openfast_io.FAST_reader import InputReader_OpenFAST  # heavy: openfast-io imports ROSCO's toolbox; loaded when a case is written

    reader = InputReader_OpenFAST()
    reader.FAST_InputFile = os.path.basename(fst)
    reader.FAST_directory = os.path.dirname(fst)
    with IO_LOCK, contextlib.redirect_stdout(io.StringIO()):  # ROSCO's DISCON reader prints what it loads
        reader.execute()
    return reader.fst_vt


#: Offset of a run's wave seed from its wind seed (:func:`specdesign.wind.seed_for`, which is
#: ``1000·seed + round(10·speed)``): below the next seed's block and above every wind speed's
#: own offset up to 50 m/s, so no sea shares its seed with any TurbSim field.
WAVE_SEED_OFFSET = 500


def wave_seed_for(wind_speed: float, seed: int) -> int:
    """SeaState's wave seed of the run at ``wind_speed`` (m/s) and wind ``seed``.

    Each (speed, seed) has its own sea, as it has its own TurbSim field, and every controller
    of a campaign meets the same sea at the same (speed, seed): runs stay paired while the
    seed-to-seed spread includes the waves'.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed of the run, m/s.
    seed : int
        The run's wind seed (as :func:`specdesign.wind.seed_for` takes it).

    Returns
    -------
    int
        SeaState's ``WaveSeed(1)``: :func:`specdesign.wind.seed_for` + :data:`WAVE_SEED_OFFSET`.

    Examples
    --------
    >>> from specdesign.openfast.deck import wave_seed_for
    >>> wave_seed_for(19.0, 2)
    2690
    """
    return seed_for(wind_speed, seed) + WAVE_SEED_OFFSET


def write_case(deck: Deck, folder: str | os.PathLike, *, tmax: float, wind_speed: float,
               wind_file: str | os.PathLike | None = None, seed: int | None = None,
               library: str | os.PathLike | None = None, parameters: str | os.PathLike | None = None,
               controller_dt: float | None = None, dt: float | None = None, dt_out: float | None = None,
               channels: Sequence[str] | None = CAMPAIGN_CHANNELS,
               initial_pitch: float | None = None, initial_rotor_speed: float | None = None, hydro: bool = True,
               wave_seed: int | None = None, name: str | None = None) -> Case:
    """Write a case folder from a deck with openfast-io (its reader and its writer).

    Parameters
    ----------
    deck : Deck
        The deck (e.g. :func:`iea15mw_monopile`).
    folder : str or os.PathLike
        Where the case's files go (created).
    tmax : float
        Simulated time (s).
    wind_speed : float
        Mean hub-height wind speed (m/s): the steady wind's speed (power-law shear of the
        deck), or the speed of the ``wind_file``, for the record.
    wind_file : str or os.PathLike, optional
        A TurbSim full-field ``.bts`` file (InflowWind ``WindType = 3``); None: steady wind.
    seed : int, optional
        The seed of ``wind_file``, kept with the case (for messages and results).
    library : str or os.PathLike, optional
        A Bladed-interface controller library (``DISCON``; ROSCO's
        ``specdesign.rosco.discon.rosco_library()`` or an exported design's ``.library``);
        default the deck's ``DLL_FileName`` (which must then exist).
    parameters : str or os.PathLike, optional
        The file the library reads at initialisation (``DLL_InFile``: a ROSCO ``DISCON.IN``
        or an exported design's ``.parameters``); default the deck's.
    controller_dt : float, optional
        The library's sample time (s), ServoDyn's ``DLL_DT`` (an exported design's ``.dt``; a
        whole multiple of ``dt``); default the deck's (``"default"``: every time step).
    dt : float, optional
        Glue-code time step (s); default the deck's (0.005 s for the shipped deck).
    dt_out : float, optional
        Output spacing (s), a multiple of ``dt``; default ``dt``.
    channels : sequence of str or None, default CAMPAIGN_CHANNELS
        The only output channels written (OpenFAST names, e.g. ``"TwrBsMyt"``); None keeps
        the deck's own list.
    initial_pitch : float, optional
        Initial blade pitch (rad); default the deck's. Starting near the trim shortens the
        transient to discard.
    initial_rotor_speed : float, optional
        Initial rotor speed (rad/s); default the deck's.
    hydro : bool, default True
        Keep SeaState and HydroDyn on (as the deck has them); False switches both off.
    wave_seed : int, optional
        SeaState's first wave seed (``WaveSeed(1)``, a 32-bit signed integer): a sea of its own
        per run; default the deck's (the same sea in every case).
    name : str, optional
        Case name; default the folder's name.

    Returns
    -------
    Case
        The case (``case.fst`` is its main input file).

    Raises
    ------
    TypeError
        ``deck`` is not a :class:`Deck`.
    ValueError
        A non-positive ``tmax``, ``dt`` or ``dt_out``, a ``dt_out`` that is not a multiple of
        ``dt``, a negative wind speed, an empty or unknown channel.
    FileNotFoundError
        ``wind_file``, ``library`` or ``parameters`` does not exist.
    """
    if not isinstance(deck, Deck):
        raise TypeError(f"deck must be a specdesign.openfast.Deck, got {type(deck).__name__}")
    for key, val in (("tmax", tmax), ("dt", dt), ("dt_out", dt_out), ("controller_dt", controller_dt)):
        if val is not None and not (math.isfinite(val) and val > 0):
            raise ValueError(f"{key}={val!r} must be a positive number of seconds")
    if not (math.isfinite(wind_speed) and wind_speed >= 0):
        raise ValueError(f"wind_speed={wind_speed!r} must be a non-negative speed in m/s")
    with _DECK_LOCK:  # one read of a deck, however many threads ask for it at once
        vt = copy.deepcopy(read_deck_cached(str(deck.fst), deck.fst.stat().st_mtime))
    folder = Path(folder).expanduser().resolve()
    name = name or folder.name
    fst, sd, ifw, ed = vt["Fst"], vt["ServoDyn"], vt["InflowWind"], vt["ElastoDyn"]
    fst["TMax"] = float(tmax)
    if dt is not None:
        fst["DT"] = float(dt)
    step = float(fst["DT"])
    if dt_out is not None:
        if abs(dt_out / step - round(dt_out / step)) > 1e-9:
            raise ValueError(f"dt_out={dt_out} s must be a multiple of the time step {step} s")
        fst["DT_Out"] = float(dt_out)
    else:
        fst["DT_Out"] = "default"
    fst["OutFileFmt"] = 2  # binary .outb: compact and exact
    fst["SumPrint"] = False
    fst["TStart"] = 0.0
    if wind_file is None:
        ifw["WindType"] = 1
        ifw["HWindSpeed"] = float(wind_speed)
    else:
        wind_file = _existing(wind_file, "wind_file")
        ifw["WindType"] = 3
        ifw["FileName_BTS"] = str(wind_file)
    sd["DLL_FileName"] = str(_existing(library, "library")) if library is not None else sd["DLL_FileName"]
    if not Path(sd["DLL_FileName"]).is_file():
        raise FileNotFoundError(f"the deck's controller library {sd['DLL_FileName']} does not exist: pass library= "
                                "(e.g. specdesign.rosco.discon.rosco_library())")
    if parameters is not None:
        sd["DLL_InFile"] = str(_existing(parameters, "parameters"))
    if controller_dt is not None:
        if abs(controller_dt / step - round(controller_dt / step)) > 1e-9:
            raise ValueError(f"controller_dt={controller_dt} s must be a whole multiple of the time step {step} s")
        sd["DLL_DT"] = float(controller_dt)
    vt.pop("DISCON_in", None)  # the controller's file is the one named, not rewritten by openfast-io
    if initial_pitch is not None:
        for k in (1, 2, 3):
            ed[f"BlPitch{k}"] = math.degrees(initial_pitch)
    if initial_rotor_speed is not None:
        ed["RotSpeed"] = initial_rotor_speed * 30.0 / math.pi  # rad/s → rpm
    if not hydro:
        fst["CompSeaSt"], fst["CompHydro"] = 0, 0
    if wave_seed is not None:
        if isinstance(wave_seed, bool) or not isinstance(wave_seed, numbers.Integral):
            raise TypeError(f"wave_seed must be an integer (SeaState's WaveSeed(1)), got {type(wave_seed).__name__}")
        if not -2**31 <= wave_seed < 2**31:
            raise ValueError(f"wave_seed={wave_seed!r} must lie in [-2**31, 2**31) (SeaState's WaveSeed(1), 32-bit)")
        vt["SeaState"]["WaveSeed1"] = int(wave_seed)
    if channels is not None:
        _set_outputs(vt, channels)
    from openfast_io.FAST_writer import InputWriter_OpenFAST  # heavy, as in read_deck_cached

    writer = InputWriter_OpenFAST()
    writer.fst_vt = vt
    writer.FAST_runDirectory = str(folder)
    writer.FAST_namingOut = name
    with IO_LOCK, contextlib.redirect_stdout(io.StringIO()):
        writer.execute()
    return Case(name=name, folder=folder, deck=deck, tmax=float(tmax), wind_speed=float(wind_speed),
                seed=None if seed is None else int(seed), channels=tuple(channels or ()))


def _existing(path, key) -> Path:
    p = Path(path).expanduser().resolve()
    if not p.is_file():
        raise FileNotFoundError(f"{key}={str(path)!r} does not exist")
    return p


def _set_outputs(vt: dict, channels) -> None:
    """Only ``channels`` on in openfast-io's output tree (per module; node outputs off)."""
    channels = [str(c) for c in channels]
    if not channels:
        raise ValueError("channels must name at least one output channel")
    found = set()
    for module, chans in vt["outlist"].items():
        for ch in chans:
            on = ch in channels
            chans[ch] = on
            if on:
                found.add(ch)
    missing = [c for c in channels if c not in found]
    if missing:
        raise ValueError(f"channels {missing} are not OpenFAST output channels openfast-io knows")
    for mod in ("ElastoDyn", "AeroDyn", "BeamDyn"):  # per-node outputs: none
        if "BldNd_BladesOut" in vt.get(mod, {}):
            vt[mod]["BldNd_BladesOut"] = 0


def run_case(case: Case, install: OpenFASTInstall | None = None, *, cpu_limit: float | None = None,
             timeout: float | None = None, channels: Sequence[str] | None = None, nice: int = 0,
             env: Mapping[str, str] | None = None) -> OpenFASTOutput:
    """Run OpenFAST on a case in a subprocess and read its outputs.

    Parameters
    ----------
    case : Case
        From :func:`write_case`.
    install : OpenFASTInstall, optional
        The executables; default :func:`specdesign.openfast.find_openfast`.
    cpu_limit : float, optional
        CPU-time limit of the OpenFAST process (s); default 10 × ``case.tmax`` + 120 s
        (OpenFAST runs the shipped deck at about 1.3 s of CPU per simulated second). A CPU
        limit, unlike a wall-clock one, does not fire on a busy machine: a run that exceeds it
        is stuck (e.g. a diverging simulation cutting its step), not starved.
    timeout : float, optional
        Wall-clock limit (s); default none.
    channels : sequence of str, optional
        Channels read; default the case's (every channel when the case kept the deck's list).
    nice : int, default 0
        Niceness added to the OpenFAST process (POSIX), for runs in the background.
    env : mapping, optional
        Environment variables set for this run on top of this process's, e.g.
        ``{"SPECDESIGN_OPENFAST_BLAS": "system"}`` (the BLAS is
        :func:`specdesign.openfast.install.run_environment`'s).

    Returns
    -------
    OpenFASTOutput
        The outputs in SI (:func:`specdesign.openfast.read_outputs`).

    Raises
    ------
    ValueError
        The deck is written for another OpenFAST version than the executable's (naming both).
    OpenFASTRunError
        OpenFAST exited with an error, timed out, or wrote no (or a truncated) output file:
        the message names the case and its seed, with the tail of OpenFAST's message.
    """
    install = install or find_openfast(require_turbsim=False)
    check_deck_version(install, case.deck.version, case.deck.fst)
    cpu_limit = 10.0 * case.tmax + 120.0 if cpu_limit is None else float(cpu_limit)
    case.outb.unlink(missing_ok=True)
    t0 = time.monotonic()

    def limits():  # in the child, before OpenFAST starts
        resource.setrlimit(resource.RLIMIT_CPU, (math.ceil(cpu_limit), math.ceil(cpu_limit) + 5))
        if nice:
            os.nice(nice)

    # gfortran buffers a redirected stdout: unbuffered, the log keeps OpenFAST's last words
    # even when the process is killed; the BLAS is install.run_environment's (a serial OpenBLAS when there is one)
    env = dict(run_environment({**os.environ, **(env or {})}), GFORTRAN_UNBUFFERED_PRECONNECTED="y")
    with open(case.log, "w") as log:
        try:
            rc = subprocess.run([str(install.openfast), case.fst.name], cwd=case.folder, stdout=log,
                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, timeout=timeout,
                                preexec_fn=limits, env=env).returncode
        except subprocess.TimeoutExpired:
            rc = None
    tail = log_tail(case.log)
    if rc is None:
        raise OpenFASTRunError(case, f"did not finish in {timeout:g} s of wall time", tail)
    if rc in (-signal.SIGXCPU, -signal.SIGKILL) and time.monotonic() - t0 >= 0.9 * cpu_limit:
        raise OpenFASTRunError(case, f"used more than its {cpu_limit:g} s of CPU time (cpu_limit)", tail)
    text = case.log.read_text(errors="replace")
    if rc != 0 or "Aborting OpenFAST" in text or not case.outb.is_file():
        raise OpenFASTRunError(case, f"failed (exit code {rc}, after {time.monotonic() - t0:.0f} s)", tail)
    try:
        return read_outputs(case.outb, list(channels or case.channels) or None)
    except ValueError as e:
        raise OpenFASTRunError(case, f"wrote outputs that cannot be read ({e})", tail) from None


def log_tail(log: Path, n: int = 12) -> str:
    """The last ``n`` non-blank lines of an OpenFAST log, for error messages."""
    lines = [ln.rstrip() for ln in log.read_text(errors="replace").splitlines() if ln.strip()]
    return "\n".join(lines[-n:])
