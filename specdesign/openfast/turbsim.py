"""TurbSim full-field winds (IEC Kaimal, NTM) per wind speed and seed, cached by their inputs.

The input file is written with openfast-io's ``TurbsimWriter``; the ``.bts`` it produces is
kept under ``<cache>/<digest16>/`` where the digest covers the input file's text and the
TurbSim version, so the same (speed, seed, grid, length) is generated once and every
controller of a campaign sees the same field.
"""
from __future__ import annotations

import fcntl
import hashlib
import math
import os
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace

from openfast_io.turbsim_util import TurbsimWriter

from ..wind import seed_for
from .install import OpenFASTInstall, find_openfast, run_environment

__all__ = ["WindField", "turbsim_field", "turbsim_cache", "TURBSIM_GRID"]

#: Default grid: points per side (square, odd so one point sits at hub height) and side (m).
#: 290 m about the 150 m hub reaches from 5 m to 295 m: the IEA 15 MW rotor (240 m) and the
#: whole tower down to the transition piece at 15 m, whose aerodynamic nodes InflowWind must
#: find inside the field (TurbSim writes no tower points under a grid this low); 13 × 13
#: points (24.2 m spacing) were chosen for cost (docs/openfast.md: times per grid).
TURBSIM_GRID = {"points": 13, "size": 290.0}


@dataclass(frozen=True)
class WindField:
    """A TurbSim full-field wind file and what it was made from.

    Parameters
    ----------
    path : pathlib.Path
        The ``.bts`` file.
    wind_speed : float
        Mean hub-height wind speed (m/s).
    seed : int
        The campaign's seed (TurbSim's ``RandSeed1`` is ``specdesign.wind.seed_for(wind_speed, seed)``).
    length : float
        Usable length of the field (s).
    settings : dict
        The TurbSim inputs that vary (grid, step, turbulence class, hub height, seeds).
    seconds : float
        Wall time TurbSim took (s); 0 when the file came from the cache.
    """

    path: Path
    wind_speed: float
    seed: int
    length: float
    settings: dict = field(repr=False)
    seconds: float = 0.0


def turbsim_cache() -> Path:
    """The wind cache: ``$SPECDESIGN_TURBSIM_CACHE`` or ``~/.cache/specdesign/turbsim``.

    Returns
    -------
    pathlib.Path
        The folder (not created).
    """
    env = os.environ.get("SPECDESIGN_TURBSIM_CACHE")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "specdesign" / "turbsim"


def turbsim_field(wind_speed: float, seed: int, *, length: float = 660.0, hub_height: float = 150.0,
                  grid_points: int = TURBSIM_GRID["points"], grid_size: float = TURBSIM_GRID["size"],
                  time_step: float = 0.05, turbulence_class: str = "B", cache: str | os.PathLike | None = None,
                  install: OpenFASTInstall | None = None, timeout: float | None = None) -> WindField:
    """An IEC Kaimal NTM full-field wind from TurbSim, generated once per inputs.

    Parameters
    ----------
    wind_speed : float
        Mean wind speed at hub height (m/s).
    seed : int
        The campaign's seed; TurbSim's ``RandSeed1 = seed_for(wind_speed, seed)`` (as the
        reduced model's winds), ``RandSeed2 = "RanLux"``.
    length : float, default 660.0
        Usable length (s): the discarded transient plus the recorded time (60 + 600 s);
        TurbSim adds the time the field takes to cross the grid.
    hub_height : float, default 150.0
        Hub height (m), the grid's centre.
    grid_points : int, default 13
        Points per side of the square grid (odd: one at hub height).
    grid_size : float, default 290.0
        Side of the grid (m); must be below twice the hub height. It must reach below the
        lowest aerodynamic tower node (AeroDyn's tower, 15 m on the monopile): InflowWind
        stops a run whose node leaves the field.
    time_step : float, default 0.05
        Time step of the field (s).
    turbulence_class : {"A", "B", "C"}, default "B"
        IEC 61400-1 ed. 3 turbulence class (NTM).
    cache : str or os.PathLike, optional
        Cache folder; default :func:`turbsim_cache`.
    install : OpenFASTInstall, optional
        The executables; default :func:`specdesign.openfast.find_openfast`.
    timeout : float, optional
        Wall-clock limit for TurbSim (s); default 3600 s.

    Returns
    -------
    WindField
        The ``.bts`` and its inputs.

    Raises
    ------
    ValueError
        A non-positive speed, length or step, a grid of fewer than 3 points, or a grid not
        below twice the hub height; a class other than A, B, C.
    RuntimeError
        TurbSim failed or timed out (the tail of its output).
    """
    for key, val in (("wind_speed", wind_speed), ("length", length), ("time_step", time_step),
                     ("hub_height", hub_height), ("grid_size", grid_size)):
        if not (math.isfinite(val) and val > 0):
            raise ValueError(f"{key}={val!r} must be positive")
    if int(grid_points) != grid_points or grid_points < 3:
        raise ValueError(f"grid_points={grid_points!r} must be an integer ≥ 3")
    if grid_size >= 2 * hub_height:
        raise ValueError(f"grid_size={grid_size} m must be below twice the hub height ({2 * hub_height} m): "
                         "TurbSim's grid cannot reach the ground")
    if turbulence_class not in ("A", "B", "C"):
        raise ValueError(f"turbulence_class={turbulence_class!r} must be 'A', 'B' or 'C'")
    install = install or find_openfast()
    settings = {"grid_points": int(grid_points), "grid_size": float(grid_size), "time_step": float(time_step),
                "hub_height": float(hub_height), "turbulence_class": turbulence_class, "length": float(length),
                "RandSeed1": seed_for(wind_speed, seed), "RandSeed2": "RanLux", "turbsim_version": install.version}
    cache = Path(cache).expanduser() if cache is not None else turbsim_cache()
    with tempfile.TemporaryDirectory() as tmp:
        inp = Path(tmp) / "wind.inp"
        _write_input(inp, wind_speed, settings)
        text = inp.read_text()
    digest = hashlib.sha256((text + install.version).encode()).hexdigest()[:16]
    folder = cache / digest
    name = f"wind_{wind_speed:g}mps_seed{int(seed)}"
    bts = folder / f"{name}.bts"
    if bts.is_file():
        return WindField(bts, float(wind_speed), int(seed), float(length), settings)
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # another process making the same field: wait for it
        if bts.is_file():
            return WindField(bts, float(wind_speed), int(seed), float(length), settings)
        (folder / f"{name}.inp").write_text(text)
        # TurbSim writes <root>.bts as it goes: a run killed half-way must not leave a file
        # that looks finished, so it writes under a partial name, renamed when it succeeds
        part = f"{name}.partial"
        (folder / f"{part}.inp").write_text(text)
        t0 = time.monotonic()
        try:
            r = subprocess.run([str(install.turbsim), f"{part}.inp"], cwd=folder, capture_output=True, text=True,
                               stdin=subprocess.DEVNULL, timeout=timeout or 3600.0, env=run_environment())
        except subprocess.TimeoutExpired:
            raise RuntimeError(f"TurbSim ({wind_speed:g} m/s, seed {seed}) did not finish in {timeout or 3600:g} s "
                               f"(folder {folder})") from None
        out = (r.stdout + r.stderr).strip().splitlines()
        (folder / f"{name}.log").write_text("\n".join(out) + "\n")
        if r.returncode != 0 or not (folder / f"{part}.bts").is_file():
            raise RuntimeError(f"TurbSim ({wind_speed:g} m/s, seed {seed}) failed with exit code {r.returncode} "
                               f"(folder {folder}); the end of its output:\n" + "\n".join(out[-12:]))
        os.replace(folder / f"{part}.bts", bts)
        (folder / f"{part}.inp").unlink()
    return WindField(bts, float(wind_speed), int(seed), float(length), settings, time.monotonic() - t0)


def _write_input(path: Path, wind_speed: float, s: dict) -> None:
    """The TurbSim input file, written by openfast-io's TurbsimWriter."""
    n = s["grid_points"]
    inputs = SimpleNamespace(
        Echo=False, RandSeed1=s["RandSeed1"], RandSeed2=s["RandSeed2"], WrBHHTP=False, WrFHHTP=False, WrADHH=False,
        WrADFF=True, WrBLFF=False, WrADTWR=False, WrFMTFF=False, WrACT=False, Clockwise=True, ScaleIEC=0,
        NumGrid_Z=n, NumGrid_Y=n, TimeStep=s["time_step"], AnalysisTime=s["length"], UsableTime=s["length"],
        HubHt=s["hub_height"], GridHeight=s["grid_size"], GridWidth=s["grid_size"], VFlowAng=0.0, HFlowAng=0.0,
        TurbModel='"IECKAI"', UserFile='"unused"', IECstandard='"1-ED3"', IECturbc=f'"{s["turbulence_class"]}"',
        IEC_WindType='"NTM"', ETMc="default", WindProfileType='"PL"', ProfileFile='"unused"', RefHt=s["hub_height"],
        URef=float(wind_speed), ZJetMax="default", PLExp="default", Z0="default", Latitude="default", RICH_NO=0.0,
        UStar="default", ZI="default", PC_UW="default", PC_UV="default", PC_VW="default", SCMod1="default",
        SCMod2="default", SCMod3="default", InCDec1="default", InCDec2="default", InCDec3="default",
        CohExp="default", CTEventPath='"unused"', CTEventFile='"random"', Randomize="true", DistScl=1.0, CTLy=0.5,
        CTLz=0.5, CTStartTime=30)
    TurbsimWriter(inputs).execute(str(path))
