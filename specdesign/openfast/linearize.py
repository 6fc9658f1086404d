"""OpenFAST linearisations of a deck at given wind speeds: :func:`linearize_deck` → :class:`LinearTurbine`.

For each wind speed the deck is read with openfast-io, turned into a steady-state trim and
linearisation case (:func:`linearization_case`, written by openfast-io's own writer into its
own folder), run with OpenFAST, and the ``.lin`` files of all speeds are read with
:meth:`LinearTurbine.from_lin_files` (MBC transform, azimuth average, signals by channel
description). What a case changes in the deck, and why:

- **Trim** (``.fst``): ``Linearize``, ``CalcSteady`` with ``TrimCase`` = 3: OpenFAST runs
  the turbine in steady wind, trimming the collective pitch by its own integral controller
  (``TrimGain``) until the rotor speed equals ElastoDyn's ``RotSpeed``, which is set to the
  rated rotor speed (ROSCO's ``PC_RefSpd``/gear ratio from the deck's DISCON.IN), and every
  output repeats over one revolution to ``TrimTol``; then it linearises at ``NLinTimes``
  equally spaced azimuths of that revolution (``n_azimuths``), which
  :func:`read_linearization` averages after the MBC transform. Default 4: after MBC the
  model of a rotor of three identical blades is periodic in the azimuth with period 120°
  (what varies is shear, gravity, tilt and tower shadow seen by the next blade), and 4
  azimuths 90° apart fall at 0°, 90°, 60°, 30° of that period: the same four phases, so
  the same average, as the 12 of the floating IEA 15 MW reference linearisations, at a
  third of the cost; an average of equally spaced phases removes every harmonic of the
  period below the 4th. (A multiple of 3 wastes runs: 6 azimuths give the phases of 2.) ``TMax`` is the budget for the trim; when it runs out,
  OpenFAST linearises where it is and says so, which :func:`linearize_deck` turns into a
  warning naming the speed. During the trim only, ``Twr_Kdmp`` (default
  :data:`TRIM_TOWER_DAMPING`) damps every tower node's velocity so that the tower and
  foundation transients of the start die out in a few periods instead of ringing for
  minutes (the foundation's Guyan DOFs have no structural damping of their own); OpenFAST
  leaves this damping out of the linearisation's Jacobians (it is a custom glue mapping,
  not a mesh mapping), so the linear model is the turbine's own. The trim history is
  written to ``lin.out`` (every ``DT_Out`` = 0.05 s) for whoever wants to watch it.
- **Wind** (InflowWind): steady (``WindType`` = 1) at ``HWindSpeed`` = the speed, the
  deck's shear exponent ``PLExp`` kept (the linearisation input ``wind`` is that
  hub-height speed; the whole profile moves with it).
- **Control** (ServoDyn): OpenFAST linearises no Bladed DLL, so pitch control is off
  (``PCMode`` = 0, the trim sets the pitch) and the generator is the simple variable-speed
  law (``VSContrl`` = 1) with ``VS_RtTq`` the rated torque (DISCON.IN's ``VS_RtTq``) and
  ``VS_RtGnSp`` 1 % below the rated generator speed, so the operating point is in its
  constant-torque region: the plant's generator torque is constant, as the reduced model's
  and ROSCO's above rated (``VS_ConstPower`` = 0); a constant-power law is the design
  loop's to close through the ``gen_torque`` input. The yaw controller, the high-speed
  shaft brake and the structural controls are off.
- **Degrees of freedom** (ElastoDyn, :data:`DEFAULT_DOFS`): the generator (rotor speed),
  the first tower fore-aft mode, and the foundation's fore-aft motion (platform surge and
  pitch, which carry SubDyn's monopile flexibility through its Guyan reduction: without
  them the "tower" mode of a monopile deck sits on a rigid base at a frequency well above
  the real one). All blade modes, the second tower fore-aft mode, the side-side modes,
  yaw, heave, roll and platform yaw are off: what the paper's reduced model keeps (rotor,
  first tower fore-aft mode) plus the foundation that mode stands on. The drivetrain
  torsion (``DrTrDOF``) is off by default because the IEA 15 MW is direct drive: its
  shaft (``DTTorSpr`` = 6.97e10 N·m/rad between the 3.51e8 kg·m² rotor and the
  1.84e6 kg·m² generator) twists at 31 Hz, which the deck's time step cannot integrate
  (OpenFAST stops at 0.1 s with a negative generator speed; the deck itself keeps it off)
  and which is 200 times the tower mode, far outside the pitch loop: the rotor and
  generator turn as one. For a geared turbine give ``dofs=DEFAULT_DOFS + ("DrTrDOF",)``
  (and a ``dt`` that resolves the torsion). Give ``dofs=`` to keep others (e.g.
  ``"FlapDOF1"``).
- **Aerodynamics** (AeroDyn): unsteady airfoil aerodynamics off (``UA_Mod`` = 0) and
  dynamic inflow off (``DBEMT_Mod`` = 0): quasi-steady BEM, as the rotor coefficients of
  ROSCO's tuning (and the reduced model's Cp/Ct table); nacelle drag off (OpenFAST
  cannot linearise it).
- **Hydrodynamics**: off by default (``CompHydro`` = ``CompSeaSt`` = 0): the wind-to-load
  plant of the design loop; ``hydrodynamics=True`` keeps the deck's.
- **Outputs and inputs**: ``LinInputs`` = 1 (the standard inputs: wind, collective pitch,
  generator torque, ...), ``LinOutputs`` = 1 with the OutLists reduced to the channels
  :data:`specdesign.openfast.signals.DEFAULT_SIGNALS` reads (:data:`LIN_OUTPUTS`), written
  with 11 significant digits (``OutFmt``) because the operating points are read from them.

The results are cached: the case folder's files and the OpenFAST version are hashed, and a
case whose digest has a finished result in ``cache`` is not run again.
"""
from __future__ import annotations

import concurrent.futures
import contextlib
import copy
import hashlib
import io
import math
import os
import shutil
import sys
import tempfile
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import positive_scalar
from ..controller.discon_file import from_discon, read_discon
from ..turbine.openfast_deck import read_cp_table
from .deck import IO_LOCK, Case, Deck, OpenFASTRunError, log_tail, read_deck_cached, run_case
from .install import OpenFASTInstall, find_openfast, openfast_version
from .linear_turbine import LinearTurbine

__all__ = [
    "BLADE_MOMENT_OUTPUTS",
    "DEFAULT_DOFS",
    "LIN_OUTPUTS",
    "TRIM_TOWER_DAMPING",
    "LinearizationCase",
    "default_lin_cache",
    "linearization_case",
    "linearize_deck",
    "write_linearization_case",
]

#: ElastoDyn degrees of freedom switched on in a linearisation case (every other one is off).
DEFAULT_DOFS = ("GenDOF", "TwFADOF1", "PtfmSgDOF", "PtfmPDOF")
#: Every ElastoDyn DOF flag a case sets (on if in ``dofs``, off otherwise).
_ALL_DOFS = ("FlapDOF1", "FlapDOF2", "EdgeDOF", "PitchDOF", "TeetDOF", "DrTrDOF", "GenDOF", "YawDOF", "TwFADOF1",
             "TwFADOF2", "TwSSDOF1", "TwSSDOF2", "PtfmSgDOF", "PtfmSwDOF", "PtfmHvDOF", "PtfmRDOF", "PtfmPDOF",
             "PtfmYDOF")
#: Module → output channels kept in the OutLists (what DEFAULT_SIGNALS reads, the rotor area
#: for the rotor radius, and the rotor speed and pitch for the record).
LIN_OUTPUTS = {
    "ElastoDyn": ("GenSpeed", "RotSpeed", "BldPitch1", "TwrBsMyt", "NcIMUTAxs", "YawBrTDxt", "YawBrTAxp"),
    "ServoDyn": ("GenPwr", "GenTq"),
    "AeroDyn": ("RtArea",),
}
#: Added to :data:`LIN_OUTPUTS` by ``blade_moments=True``: the three blades' out-of-plane root
#: moments, a triplet whose collective part (MBC) is ``blade_root_my``, the mean a controller
#: reads from avrSWAP(30-32) (an MPC predicting blade loads needs it). Off by default, so that
#: a linearisation made without them (its cache digest, the models and designs made on it)
#: stays what it was.
BLADE_MOMENT_OUTPUTS = {"ElastoDyn": ("RootMyc1", "RootMyc2", "RootMyc3")}
#: ``Twr_Kdmp`` of the trim (N/(m/s) per tower node): ~30 % of critical on the IEA 15 MW's first
#: tower fore-aft mode (modal mass 1.24e6 kg at 1.08 rad/s, Σφ² ≈ 4 over ElastoDyn's 20 nodes).
TRIM_TOWER_DAMPING = 2.0e5
_RATED_SPEED_MARGIN = 0.99  # VS_RtGnSp / rated generator speed: constant-torque region at the trim point
_FORCED = "Steady state not found before end of simulation"
_CASE = "lin"  # file root of every case: <folder>/lin.fst, lin.1.lin, ...


def default_lin_cache() -> Path:
    """Where :func:`linearize_deck` keeps results: ``$SPECDESIGN_LIN_CACHE`` or ``~/.cache/specdesign/linearizations``.

    Returns
    -------
    pathlib.Path
        The cache folder (not created here).
    """
    env = os.environ.get("SPECDESIGN_LIN_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "specdesign" / "linearizations"


@dataclass(frozen=True)
class LinearizationCase:
    """One written linearisation case.

    Parameters
    ----------
    wind_speed : float
        Mean (hub-height) wind speed (m/s).
    folder : pathlib.Path
        The case folder (openfast-io's files).
    fst : pathlib.Path
        Its ``.fst`` file.
    rotor_speed : float
        Trim target, the rated rotor speed (rad/s).
    gen_torque : float
        Generator torque of the constant-torque law (N·m, generator side).
    initial_pitch : float
        Pitch the trim starts from (rad).
    """

    wind_speed: float
    folder: Path
    fst: Path
    rotor_speed: float
    gen_torque: float
    initial_pitch: float


def _as_deck(fst_path) -> Deck:
    if isinstance(fst_path, Deck):
        return fst_path
    if not isinstance(fst_path, (str, os.PathLike)):
        raise TypeError(f"fst_path must be a path to a .fst file or a Deck, got {type(fst_path).__name__}")
    return Deck(Path(fst_path))


def _read_deck(fst_path) -> dict:
    """openfast-io's dictionary of a deck (``fst_vt``; cached, not to be modified), errors naming the deck."""
    fst = _as_deck(fst_path).fst
    try:
        return read_deck_cached(str(fst), fst.stat().st_mtime)
    except (ValueError, IndexError, KeyError) as exc:
        raise ValueError(f"openfast-io cannot read the deck {str(fst)!r} ({type(exc).__name__}: {exc}); it must be in "
                         "the format of the openfast-io installed (OpenFAST v5.0 for openfast-io 5.0)") from exc


def _discon_path(fst: Path, fst_vt) -> Path | None:
    sd = fst_vt.get("ServoDyn", {})
    name = str(sd.get("DLL_InFile", "")).strip().strip('"')
    if not name or name.lower() in ("unused", "none"):
        return None
    servo = fst.parent / str(fst_vt["Fst"]["ServoFile"]).strip('"')
    path = Path(name) if os.path.isabs(name) else servo.parent / name
    return path if path.is_file() else None


def _pitch_guess(cp_path: Path, rotor_speed, torque, radius, rho, v) -> float:
    """Pitch (rad) where the Cp table's power at the rated speed equals torque × speed (the feathering branch)."""
    tsr, pitch, cp, _ = read_cp_table(cp_path)
    lam = rotor_speed * radius / v
    row = np.array([np.interp(lam, tsr, cp[:, j]) for j in range(pitch.size)])
    need = torque * rotor_speed / (0.5 * rho * math.pi * radius**2 * v**3)
    above = np.nonzero(row >= need)[0]
    if above.size == 0 or above[-1] == pitch.size - 1:
        return float(pitch[np.argmax(row)]) if above.size == 0 else float(pitch[-1])
    j = above[-1]  # last pitch with enough power: the crossing on the feathering side lies in [j, j+1]
    return float(pitch[j] + (row[j] - need) / (row[j] - row[j + 1]) * (pitch[j + 1] - pitch[j]))


def _rated(fst: Path, fst_vt, rotor_speed, gen_torque):
    """(rotor speed rad/s, generator torque N·m generator side, gear ratio, DISCON path or None)."""
    gb = float(fst_vt["ElastoDyn"]["GBRatio"])
    discon = _discon_path(fst, fst_vt)
    sched = from_discon(discon) if discon is not None and (rotor_speed is None or gen_torque is None) else None
    if rotor_speed is None:
        if sched is None:
            raise ValueError(f"{fst}: no DISCON.IN to take the rated rotor speed from; give rotor_speed= (rad/s)")
        rotor_speed = sched.reference_speed / sched.gearbox_ratio
    if gen_torque is None:
        if sched is None:
            raise ValueError(f"{fst}: no DISCON.IN to take the rated generator torque from; give gen_torque= (N·m)")
        gen_torque = sched.rated_torque
    return positive_scalar(rotor_speed, "rotor_speed"), positive_scalar(gen_torque, "gen_torque"), gb, discon


def _initial_pitch(initial_pitch, v, fst_vt, discon, rotor_speed, gen_torque, gb):
    if initial_pitch is not None:
        value = initial_pitch(v) if callable(initial_pitch) else (
            initial_pitch[v] if isinstance(initial_pitch, Mapping) else initial_pitch)
        return float(value)
    if discon is not None:
        entries, _ = read_discon(discon)
        perf = entries.get("PerfFileName")
        if perf is not None:
            cp_path = Path(str(perf.values[0]).strip('"'))
            cp_path = cp_path if cp_path.is_absolute() else discon.parent / cp_path
            if cp_path.is_file():
                ed = fst_vt["ElastoDyn"]
                radius = float(ed["TipRad"]) * math.cos(math.radians(float(ed["PreCone(1)"])))
                rho = float(fst_vt["Fst"]["AirDens"])
                return _pitch_guess(cp_path, rotor_speed, gen_torque * gb, radius, rho, v)
    return math.radians(float(fst_vt["ElastoDyn"]["BlPitch1"]))


def linearization_case(fst_vt: dict, wind_speed: float, *, rotor_speed: float, gen_torque: float, initial_pitch: float,
                       n_azimuths: int = 4, dofs: Sequence[str] = DEFAULT_DOFS, tmax: float = 600.0,
                       trim_tol: float | None = None, trim_gain: float | None = None, dt: float | None = None,
                       trim_damping: float = TRIM_TOWER_DAMPING, hydrodynamics: bool = False,
                       blade_moments: bool = False, overrides: Mapping | None = None) -> dict:
    """The trim-and-linearise case of a deck at one wind speed, as openfast-io's dictionary.

    The module docstring lists what is changed and why. The deck's dictionary is not modified.

    Parameters
    ----------
    fst_vt : dict
        openfast-io's dictionary of the deck (``InputReader_OpenFAST().fst_vt``).
    wind_speed : float
        Hub-height steady wind speed (m/s).
    rotor_speed : float
        Trim target: the rotor speed (rad/s).
    gen_torque : float
        Generator torque of the constant-torque law (N·m, generator side).
    initial_pitch : float
        Collective pitch the trim starts from (rad).
    n_azimuths : int, optional
        ``NLinTimes``: azimuths linearised over one revolution and averaged (default 4, see
        the module docstring).
    dofs : sequence of str, optional
        ElastoDyn DOF flags to switch on (:data:`DEFAULT_DOFS`); every other one is off.
    tmax : float, optional
        ``TMax``, the time budget of the trim (s of simulation).
    trim_tol, trim_gain, dt : float, optional
        ``TrimTol`` (-), ``TrimGain`` (rad/(rad/s)) and ``DT`` (s); default the deck's.
    trim_damping : float, optional
        ``Twr_Kdmp``, tower damping during the trim only (N/(m/s) per node; 0 for none).
    hydrodynamics : bool, optional
        Keep the deck's HydroDyn and SeaState (default off).
    blade_moments : bool, optional
        Also output the blades' out-of-plane root moments (:data:`BLADE_MOMENT_OUTPUTS`; the
        model's ``blade_root_my``). Default off.
    overrides : dict, optional
        ``{(module, key): value}`` set last, e.g. ``{("InflowWind", "PLExp"): 0.0}``.

    Returns
    -------
    dict
        A new ``fst_vt``.

    Raises
    ------
    ValueError
        An unknown DOF name, a non-positive speed, budget or count, or an override of a key
        the deck does not have.
    """
    v = positive_scalar(wind_speed, "wind_speed")
    if isinstance(n_azimuths, bool) or not isinstance(n_azimuths, (int, np.integer)) or n_azimuths < 1:
        raise ValueError(f"n_azimuths={n_azimuths!r} must be a positive integer (azimuths per revolution)")
    dofs = (dofs,) if isinstance(dofs, str) else tuple(dofs)
    unknown = [d for d in dofs if d not in _ALL_DOFS]
    if unknown:
        raise ValueError(f"dofs={unknown} are not ElastoDyn DOF flags; choose among {list(_ALL_DOFS)}")
    vt = copy.deepcopy(fst_vt)
    fst, ed, sd, ifw, ad = vt["Fst"], vt["ElastoDyn"], vt["ServoDyn"], vt["InflowWind"], vt["AeroDyn"]
    gb = float(ed["GBRatio"])

    fst.update(TMax=positive_scalar(tmax, "tmax"), Linearize=True, CalcSteady=True, TrimCase=3, NLinTimes=int(n_azimuths),
               LinInputs=1, LinOutputs=1, LinOutJac=False, LinOutMod=False, WrVTK=0, SumPrint=False, Echo=False,
               OutFmt="ES20.11E3", OutFileFmt=3, TStart=0.0, DT_Out=0.05, ChkptTime=99999.0)
    fst["Twr_Kdmp"] = float(trim_damping)
    if not fst["Twr_Kdmp"] >= 0:
        raise ValueError(f"trim_damping={trim_damping!r} must be zero or positive (N/(m/s) per tower node)")
    fst["LinTimes"] = [fst["TMax"]]  # unused with CalcSteady; one value keeps the line well-formed
    if trim_tol is not None:
        fst["TrimTol"] = positive_scalar(trim_tol, "trim_tol")
    if trim_gain is not None:
        fst["TrimGain"] = positive_scalar(trim_gain, "trim_gain")
    if dt is not None:
        fst["DT"] = positive_scalar(dt, "dt")
    if not hydrodynamics:
        fst["CompHydro"] = 0
        fst["CompSeaSt"] = 0

    for d in _ALL_DOFS:
        ed[d] = d in dofs
    rpm = rotor_speed * 30.0 / math.pi
    ed.update(RotSpeed=rpm, BlPitch1=math.degrees(initial_pitch), BlPitch2=math.degrees(initial_pitch),
              BlPitch3=math.degrees(initial_pitch), Azimuth=0.0, OoPDefl=0.0, IPDefl=0.0, TTDspFA=0.0, TTDspSS=0.0)

    ifw.update(WindType=1, HWindSpeed=v)

    ad.update(UA_Mod=0, DBEMT_Mod=0, NacelleDrag=False)

    sd.update(PCMode=0, VSContrl=1, VS_RtTq=float(gen_torque), VS_RtGnSp=_RATED_SPEED_MARGIN * rpm * gb,
              GenTiStr=True, GenTiStp=True, HSSBrMode=0, YCMode=0, TimGenOn=0.0, SpdGenOn=0.0)
    if sd.get("GenModel") not in (1, 2):
        sd["GenModel"] = 1
    # VS_Rgn2K·VS_RtGnSp² may not exceed VS_RtTq (ServoDyn's check); region 2 is never visited at the trim point
    sd["VS_Rgn2K"] = min(float(sd.get("VS_Rgn2K", 0.0)), 0.9 * sd["VS_RtTq"] / sd["VS_RtGnSp"] ** 2)
    if not sd.get("VS_SlPc") or float(sd["VS_SlPc"]) <= 0:
        sd["VS_SlPc"] = 2.0
    for key in ("AfCmode", "CCmode"):  # flap and cable control off (5 would load the library)
        if key in sd:
            sd[key] = 0
    # no mode is 5, so ServoDyn loads no library: its bare name keeps the case (and its
    # digest) the same wherever the deck lies (openfast-io writes it resolved to an absolute path)
    sd["DLL_FileName"] = os.path.basename(str(sd.get("DLL_FileName", "unused")))
    for kind in ("BStC", "NStC", "TStC", "SStC"):
        sd[f"Num{kind}"] = 0
        sd[f"{kind}files"] = []
        vt[kind] = []

    _bare_unused_names(vt)
    kept = {m: LIN_OUTPUTS.get(m, ()) + (BLADE_MOMENT_OUTPUTS.get(m, ()) if blade_moments else ())
            for m in set(LIN_OUTPUTS) | set(BLADE_MOMENT_OUTPUTS)}
    for module, channels in vt["outlist"].items():
        for ch in channels:
            channels[ch] = ch in kept.get(module, ())
    _apply_overrides(vt, overrides)
    return vt


def _bare_unused_names(vt: dict) -> None:
    """openfast-io resolves the deck's "unused"/"none" file names to absolute paths: back to the
    bare word (in place), so that a case (and its digest) does not depend on where the deck lies."""
    for module in vt.values():
        if isinstance(module, dict):
            for key, value in module.items():
                if isinstance(value, str) and os.path.isabs(value) and os.path.basename(value).lower() in ("unused", "none"):
                    module[key] = os.path.basename(value)


def _apply_overrides(vt: dict, overrides: Mapping | None) -> None:
    """Set ``{(module, key): value}`` in ``vt`` (in place), refusing a key the deck does not have."""
    for key, value in (overrides or {}).items():
        if not (isinstance(key, tuple) and len(key) == 2):
            raise ValueError(f"overrides key {key!r} must be a (module, key) pair, e.g. ('InflowWind', 'PLExp')")
        module, name = key
        if module not in vt or not isinstance(vt[module], dict) or name not in vt[module]:
            raise ValueError(f"overrides: {module!r} has no key {name!r} in the deck read by openfast-io")
        vt[module][name] = value


def write_linearization_case(fst_path, wind_speed: float, folder, *, fst_vt: dict | None = None,
                             rotor_speed: float | None = None, gen_torque: float | None = None,
                             initial_pitch=None, **case_options) -> LinearizationCase:
    """Write the trim-and-linearise case of a deck at one wind speed into ``folder`` (openfast-io's writer).

    Parameters
    ----------
    fst_path : str, os.PathLike or Deck
        The deck's ``.fst``.
    wind_speed : float
        Hub-height steady wind speed (m/s).
    folder : str or os.PathLike
        Where the case is written (created): ``lin.fst`` and the files it names.
    fst_vt : dict, optional
        The deck already read (openfast-io's dictionary), to read it once for many speeds.
    rotor_speed : float, optional
        Trim target (rad/s); default the DISCON.IN's ``PC_RefSpd`` / gear ratio.
    gen_torque : float, optional
        Constant generator torque (N·m, generator side); default the DISCON.IN's ``VS_RtTq``.
    initial_pitch : float, dict or callable, optional
        Pitch the trim starts from (rad), or {speed: rad}, or speed → rad; default where the
        DISCON.IN's Cp table gives rated torque × rated speed (the feathering side), else
        ElastoDyn's ``BlPitch(1)``.
    **case_options
        :func:`linearization_case`'s options (``n_azimuths``, ``dofs``, ``tmax``, ...).

    Returns
    -------
    LinearizationCase
        The case.

    Raises
    ------
    FileNotFoundError
        The deck does not exist.
    ValueError
        As :func:`linearization_case`, or no DISCON.IN for a default rated speed or torque.
    """
    from openfast_io.FAST_writer import (
        InputWriter_OpenFAST,  # heavy: openfast-io imports ROSCO's toolbox; loaded when a case is written
    )

    fst = _as_deck(fst_path).fst
    vt = _read_deck(fst) if fst_vt is None else fst_vt
    v = positive_scalar(wind_speed, "wind_speed")
    speed, torque, gb, discon = _rated(fst, vt, rotor_speed, gen_torque)
    pitch = _initial_pitch(initial_pitch, v, vt, discon, speed, torque, gb)
    case = linearization_case(vt, v, rotor_speed=speed, gen_torque=torque, initial_pitch=pitch, **case_options)
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    writer = InputWriter_OpenFAST()
    writer.fst_vt = case
    writer.FAST_runDirectory = str(out)
    writer.FAST_namingOut = _CASE
    with IO_LOCK, contextlib.redirect_stdout(io.StringIO()):  # openfast-io and ROSCO's writer print what they write
        writer.execute()
    return LinearizationCase(v, out, out / f"{_CASE}.fst", speed, torque, pitch)


#: Files of a case that OpenFAST does not read in a linearisation (pitch control off, simple
#: generator law: no controller library), left out of the case's digest.
_UNREAD = ("_DISCON.IN", "_Cp_Ct_Cq.txt")


def _digest(folder: Path, version: str) -> str:
    h = hashlib.sha256(version.encode())
    for f in sorted(p for p in folder.rglob("*") if p.is_file() and not p.name.endswith(_UNREAD)):
        h.update(str(f.relative_to(folder)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:16]


def _install(openfast) -> OpenFASTInstall:
    if isinstance(openfast, OpenFASTInstall):
        return openfast
    if openfast is None:
        return find_openfast(require_turbsim=False)
    exe = Path(shutil.which(os.fspath(openfast)) or os.fspath(openfast))
    return OpenFASTInstall(exe, None, openfast_version(exe))


def _lin_files(folder: Path) -> list:
    return sorted(folder.glob(f"{_CASE}.*.lin"), key=lambda p: int(p.suffixes[-2][1:]))


def _run_case(install: OpenFASTInstall, deck: Deck, case: LinearizationCase, tmax: float, timeout: float, nice: int):
    """Run one case: (lin files, seconds, trim forced); OpenFASTRunError naming the speed and OpenFAST's message."""
    run = Case(name=_CASE, folder=case.folder, deck=deck, tmax=tmax, wind_speed=case.wind_speed, seed=None,
               channels=("GenSpeed",))
    t0 = time.perf_counter()
    run_case(run, install, timeout=timeout, nice=nice)
    lins = _lin_files(case.folder)
    if not lins:
        raise OpenFASTRunError(run, "wrote no .lin files", log_tail(run.log))
    return lins, time.perf_counter() - t0, _FORCED in run.log.read_text(errors="replace")


def linearize_deck(fst_path, wind_speeds, *, n_azimuths: int = 4, dofs: Sequence[str] = DEFAULT_DOFS,
                   rotor_speed: float | None = None, gen_torque: float | None = None, initial_pitch=None,
                   tmax: float = 600.0, trim_tol: float | None = None, trim_gain: float | None = None,
                   dt: float | None = None, trim_damping: float = TRIM_TOWER_DAMPING, hydrodynamics: bool = False,
                   blade_moments: bool = False,
                   overrides: Mapping | None = None,
                   signals: dict | None = None, openfast=None, cache=None, processes: int = 2,
                   timeout: float = 3600.0, nice: int = 0, progress: bool | None = None,
                   name: str | None = None) -> LinearTurbine:
    """OpenFAST's linear models of a deck at ``wind_speeds``, as the :class:`LinearTurbine` the design loop takes.

    Each speed is written as a trim-and-linearise case (the module docstring says what the
    case changes in the deck and why), run by OpenFAST (in parallel, ``processes`` at a
    time), cached, and read with :meth:`LinearTurbine.from_lin_files`.

    Parameters
    ----------
    fst_path : str, os.PathLike or Deck
        The deck's ``.fst`` (a format the installed openfast-io and OpenFAST read), e.g.
        ``specdesign.openfast.iea15mw_monopile()`` (a :class:`~specdesign.openfast.Deck`
        carries its format version, checked against the executable's).
    wind_speeds : float or sequence of float
        Hub-height steady wind speeds (m/s), distinct.
    n_azimuths : int, optional
        Azimuths linearised per speed and averaged after MBC (default 4: the phases of 12 for
        a three-bladed rotor; module docstring).
    dofs : sequence of str, optional
        ElastoDyn DOFs kept (default :data:`DEFAULT_DOFS`).
    rotor_speed, gen_torque, initial_pitch, tmax, trim_tol, trim_gain, dt, trim_damping, hydrodynamics, blade_moments, overrides
        As :func:`write_linearization_case` and :func:`linearization_case`.
    signals : dict, optional
        Overrides of :data:`specdesign.openfast.signals.DEFAULT_SIGNALS`.
    openfast : OpenFASTInstall, str or os.PathLike, optional
        The ``openfast`` executable; default :func:`specdesign.openfast.find_openfast`'s.
    cache : str or os.PathLike, optional
        Results folder (default :func:`default_lin_cache`): one sub-folder per case digest
        (the case's files and the OpenFAST version), reused when present.
    processes : int, optional
        OpenFAST processes at a time (default 2).
    timeout : float, optional
        Wall-time limit of one OpenFAST run (s).
    nice : int, optional
        Niceness added to the OpenFAST processes (POSIX), for runs in the background.
    progress : bool, optional
        Print a line per finished speed to stderr (default: when stderr is a terminal).
    name : str, optional
        Label of the turbine (default the deck's file name).

    Returns
    -------
    LinearTurbine
        Plants at the speeds, the operating points read from the files (rotor speed, pitch,
        generator torque), ``sources`` the ``.lin`` files.

    Raises
    ------
    FileNotFoundError
        The deck or the executable does not exist, or no OpenFAST is found.
    ValueError
        Bad arguments (named), or a deck openfast-io cannot read.
    OpenFASTRunError
        An OpenFAST run failed, timed out or wrote no ``.lin`` file: the message names the
        wind speed, the case folder and quotes the end of OpenFAST's output.

    Warns
    -----
    UserWarning
        A speed whose trim did not converge within ``tmax`` (OpenFAST linearised anyway).
    """
    deck = _as_deck(fst_path)
    speeds = np.atleast_1d(np.asarray(wind_speeds, float))
    if speeds.ndim != 1 or speeds.size == 0 or not np.all(np.isfinite(speeds)) or np.any(speeds <= 0):
        raise ValueError(f"wind_speeds={wind_speeds!r} must be one or more positive wind speeds in m/s")
    if np.unique(speeds).size != speeds.size:
        raise ValueError(f"wind_speeds={speeds.tolist()} repeat a speed; give each once")
    if isinstance(processes, bool) or not isinstance(processes, (int, np.integer)) or processes < 1:
        raise ValueError(f"processes={processes!r} must be a positive integer")
    timeout = positive_scalar(timeout, "timeout")
    install = _install(openfast)
    root = Path(cache) if cache is not None else default_lin_cache()
    root.mkdir(parents=True, exist_ok=True)
    show = sys.stderr.isatty() if progress is None else bool(progress)
    vt = _read_deck(deck)
    options = {"n_azimuths": n_azimuths, "dofs": dofs, "tmax": tmax, "trim_tol": trim_tol, "trim_gain": trim_gain, "dt": dt,
               "trim_damping": trim_damping, "hydrodynamics": hydrodynamics, "blade_moments": blade_moments,
               "overrides": overrides}

    todo, done = [], {}
    for v in speeds:
        tmp = Path(tempfile.mkdtemp(prefix=f"lin{v:g}-", dir=root))
        case = write_linearization_case(deck, float(v), tmp, fst_vt=vt, rotor_speed=rotor_speed, gen_torque=gen_torque,
                                        initial_pitch=initial_pitch, **options)
        final = root / f"{v:g}mps-{_digest(tmp, install.version)}"
        if (final / "done").is_file():
            shutil.rmtree(tmp)
            done[float(v)] = _lin_files(final)
            if show:
                print(f"linearize_deck: {v:g} m/s from the cache ({final})", file=sys.stderr, flush=True)
            continue
        if final.exists():
            shutil.rmtree(final)  # an unfinished earlier run
        tmp.rename(final)
        todo.append(LinearizationCase(case.wind_speed, final, final / case.fst.name, case.rotor_speed, case.gen_torque,
                                      case.initial_pitch))

    if todo:
        t0 = time.perf_counter()
        with concurrent.futures.ThreadPoolExecutor(max_workers=int(processes)) as pool:
            futures = {pool.submit(_run_case, install, deck, c, float(tmax), timeout, nice): c for c in todo}
            try:
                for k, fut in enumerate(concurrent.futures.as_completed(futures), 1):
                    c = futures[fut]
                    lins, seconds, forced = fut.result()
                    (c.folder / "done").write_text(f"{seconds:.1f} s\n")
                    done[c.wind_speed] = lins
                    if forced:
                        warnings.warn(f"linearize_deck: the trim at {c.wind_speed:g} m/s did not converge within "
                                      f"tmax={tmax:g} s; OpenFAST linearised at the end of the run ({c.folder}): raise "
                                      "tmax or trim_tol", UserWarning, stacklevel=2)
                    if show:
                        print(f"linearize_deck: {c.wind_speed:g} m/s linearised in {seconds:.0f} s ({k}/{len(todo)}, "
                              f"{time.perf_counter() - t0:.0f} s elapsed)", file=sys.stderr, flush=True)
            except BaseException:
                for f in futures:
                    f.cancel()
                raise

    files = [f for v in speeds for f in done[float(v)]]
    return LinearTurbine.from_lin_files(files, signals, name=name or deck.name)
