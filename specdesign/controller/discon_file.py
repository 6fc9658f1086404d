"""ROSCO's DISCON.IN read as the workbench's gain schedule: :func:`from_discon`, :class:`DisconSchedule`.

A DISCON.IN line is ``value(s)  ! Name - description``; comment lines start with ``!``. The
reader keeps every named entry (:func:`read_discon`) and :func:`from_discon` takes the pitch
PI schedule (``PC_GS_angles``/``PC_GS_KP``/``PC_GS_KI``), the generator-speed low-pass
(``F_LPFType``/``F_LPFCornerFreq``/``F_LPFDamping``), the pitch limits and rates, and the
torque controller's settings, checking each: a missing, non-numeric or inconsistent value
raises a ValueError naming the file, the line and the key.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["DisconEntry", "DisconSchedule", "read_discon", "from_discon", "write_discon"]


@dataclass(frozen=True)
class DisconEntry:
    """One named entry of a DISCON.IN file.

    Parameters
    ----------
    name : str
        The key (``PC_GS_angles``).
    values : tuple of str
        The tokens before the ``!`` (quotes kept on strings).
    line : int
        1-based line number in the file.
    """

    name: str
    values: tuple
    line: int


_VERSION = re.compile(r"ROSCO\s+version\s+([0-9][0-9.]*[0-9])", re.IGNORECASE)


def read_discon(path: str | Path) -> tuple[dict, str | None]:
    """Every named entry of a DISCON.IN file, and the ROSCO version that wrote it.

    Parameters
    ----------
    path : str or pathlib.Path
        The DISCON.IN file.

    Returns
    -------
    entries : dict
        Key → :class:`DisconEntry`, in file order.
    version : str or None
        The ROSCO version of the header line "File written using ROSCO version X", or None.

    Raises
    ------
    FileNotFoundError
        If ``path`` is not a file.
    ValueError
        If a key appears twice.

    Examples
    --------
    >>> from specdesign.rosco import iea15mw_discon
    >>> entries, version = read_discon(iea15mw_discon())
    >>> version, entries["PC_GS_n"].values
    ('2.9.4', ('30',))
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"DISCON.IN file {str(path)!r} does not exist")
    entries, version = {}, None
    for n, raw in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("!"):
            m = _VERSION.search(line)
            if m and version is None:
                version = m.group(1)
            continue
        if "!" not in line:
            continue
        left, right = line.split("!", 1)
        name = right.split()[0] if right.split() else ""
        if not name:
            continue
        if name in entries:
            raise ValueError(f"{path}: line {n}: key {name!r} appears twice (first on line {entries[name].line})")
        entries[name] = DisconEntry(name, tuple(left.split()), n)
    return entries, version


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class DisconSchedule:
    """ROSCO's pitch PI schedule and the turbine settings of a DISCON.IN file (see :func:`from_discon`).

    Gains in ROSCO's sign (pitch = K_p·e + K_i∫e with e = reference − filtered generator
    speed, both on the generator (high-speed) side); :func:`specdesign.rosco.rosco_scheduled`
    takes it as ``schedule=``.

    Parameters
    ----------
    path : str
        The file read.
    version : str or None
        ROSCO version of its header.
    pitch : numpy.ndarray
        (n,) scheduling pitch angles ``PC_GS_angles`` (rad), strictly increasing.
    kp : numpy.ndarray
        (n,) proportional gains ``PC_GS_KP`` (s, rad per HSS rad/s).
    ki : numpy.ndarray
        (n,) integral gains ``PC_GS_KI`` (rad per HSS rad).
    filter_type : int
        ``F_LPFType``: 1 first-order, 2 second-order generator-speed low-pass.
    filter_corner : float
        ``F_LPFCornerFreq`` (rad/s).
    filter_damping : float
        ``F_LPFDamping`` (-) (second-order filter only).
    reference_speed : float
        ``PC_RefSpd``, the pitch controller's generator-speed reference (HSS rad/s).
    gearbox_ratio : float
        ``WE_GearboxRatio`` (-).
    pitch_min, pitch_max : float
        ``PC_MinPit``, ``PC_MaxPit`` (rad).
    pitch_rate_min, pitch_rate_max : float
        ``PC_MinRat`` (negative), ``PC_MaxRat`` (rad/s).
    fine_pitch : float
        ``PC_FinePit`` (rad).
    vs_control_mode : int
        ``VS_ControlMode``.
    vs_const_power : int
        ``VS_ConstPower`` (0: constant torque above rated).
    rated_torque : float
        ``VS_RtTq`` (HSS N·m).
    max_torque : float
        ``VS_MaxTq`` (HSS N·m).
    rated_power : float
        ``VS_RtPwr`` (W).
    generator_efficiency : float
        ``VS_GenEff`` / 100 (-).
    rated_generator_speed : float
        ``VS_RefSpd`` (HSS rad/s).
    rotor_radius : float
        ``WE_BladeRadius`` (m).
    td_mode : int, optional
        ``TD_Mode``: 0 no tower damper (default), 1 ROSCO's fore-aft damper (pitch +=
        ``FA_KI`` × ∫ high-passed tower-top fore-aft acceleration, saturated at ``FA_IntSat``).
    fa_ki : float, optional
        ``FA_KI`` (rad·s/m): the damper's integral gain on acceleration, i.e. its gain on
        tower-top velocity.
    fa_hpf_corner : float, optional
        ``FA_HPFCornerFreq`` (rad/s): corner of the first-order high-pass on the acceleration.
    fa_int_sat : float, optional
        ``FA_IntSat`` (rad): saturation of the damper's pitch contribution.
    """

    path: str
    version: str | None
    pitch: np.ndarray
    kp: np.ndarray
    ki: np.ndarray
    filter_type: int
    filter_corner: float
    filter_damping: float
    reference_speed: float
    gearbox_ratio: float
    pitch_min: float
    pitch_max: float
    pitch_rate_min: float
    pitch_rate_max: float
    fine_pitch: float
    vs_control_mode: int
    vs_const_power: int
    rated_torque: float
    max_torque: float
    rated_power: float
    generator_efficiency: float
    rated_generator_speed: float
    rotor_radius: float
    td_mode: int = 0
    fa_ki: float = 0.0
    fa_hpf_corner: float = 0.0
    fa_int_sat: float = 0.0

    def gains(self, pitch: float | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(K_p, K_i) at ``pitch`` as ROSCO interpolates them: linear, held at the table ends.

        Parameters
        ----------
        pitch : float or array_like
            Filtered pitch (rad).

        Returns
        -------
        kp : numpy.ndarray
            Proportional gain (s), shaped as ``pitch``.
        ki : numpy.ndarray
            Integral gain (-), shaped as ``pitch``.

        Examples
        --------
        >>> from specdesign.rosco import iea15mw_discon
        >>> s = from_discon(iea15mw_discon())
        >>> bool(s.gains(s.pitch[0])[0] == s.kp[0])
        True
        """
        b = np.asarray(pitch, dtype=float)
        return np.interp(b, self.pitch, self.kp), np.interp(b, self.pitch, self.ki)


def _numbers(path, entries, name, n=None, integer=False):
    e = entries.get(name)
    if e is None:
        raise ValueError(f"{path}: key {name!r} is missing (a DISCON.IN written by ROSCO's toolbox has it)")
    try:
        vals = [float(v) for v in e.values]
    except ValueError:
        raise ValueError(f"{path}: line {e.line}: {name} = {' '.join(e.values)!r} is not numeric") from None
    if n is not None and len(vals) != n:
        raise ValueError(f"{path}: line {e.line}: {name} has {len(vals)} values but PC_GS_n = {n}")
    if n is None and len(vals) != 1:
        raise ValueError(f"{path}: line {e.line}: {name} must be one number, got {len(vals)}")
    if not all(math.isfinite(v) for v in vals):
        raise ValueError(f"{path}: line {e.line}: {name} has a non-finite value")
    if integer and any(v != int(v) for v in vals):
        raise ValueError(f"{path}: line {e.line}: {name} = {vals[0]!r} must be an integer")
    return np.array(vals) if n is not None else (int(vals[0]) if integer else vals[0])


def from_discon(path: str | Path) -> DisconSchedule:
    """The pitch PI gain schedule, filters and limits of a ROSCO DISCON.IN file.

    Parameters
    ----------
    path : str or pathlib.Path
        The DISCON.IN file (any ROSCO 2.x version: only keys common to them are read).

    Returns
    -------
    DisconSchedule
        The schedule (``rosco_scheduled(model, schedule=...)`` runs it).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        Naming the file, line and key, for a missing or non-numeric key, gain arrays whose
        length is not ``PC_GS_n``, scheduling angles that do not strictly increase, a
        filter type other than 1 or 2, a non-positive corner frequency, gear ratio, speed or
        torque, pitch limits with ``PC_MinPit >= PC_MaxPit``, or rate limits of the wrong sign.

    Examples
    --------
    >>> from specdesign.rosco import iea15mw_discon
    >>> s = from_discon(iea15mw_discon())
    >>> s.pitch.size, round(s.filter_corner, 4), s.reference_speed
    (30, 1.0081, 0.79168)
    """
    entries, version = read_discon(path)
    p = str(path)

    def num(name, **kw):
        return _numbers(p, entries, name, **kw)

    n = num("PC_GS_n", integer=True)
    if n < 1:
        raise ValueError(f"{p}: line {entries['PC_GS_n'].line}: PC_GS_n = {n} must be at least 1")
    angles, kp, ki = (num(k, n=n) for k in ("PC_GS_angles", "PC_GS_KP", "PC_GS_KI"))
    if np.any(np.diff(angles) <= 0):
        raise ValueError(f"{p}: line {entries['PC_GS_angles'].line}: PC_GS_angles must strictly increase (rad)")
    ftype = num("F_LPFType", integer=True)
    if ftype not in (1, 2):
        raise ValueError(f"{p}: line {entries['F_LPFType'].line}: F_LPFType = {ftype} must be 1 or 2")
    vals = {k: num(k) for k in ("F_LPFCornerFreq", "F_LPFDamping", "PC_RefSpd", "WE_GearboxRatio", "PC_MinPit",
                                "PC_MaxPit", "PC_MinRat", "PC_MaxRat", "PC_FinePit", "VS_RtTq", "VS_MaxTq",
                                "VS_RtPwr", "VS_GenEff", "VS_RefSpd", "WE_BladeRadius")}
    for k in ("F_LPFCornerFreq", "PC_RefSpd", "WE_GearboxRatio", "VS_RtTq", "VS_MaxTq", "VS_RtPwr", "VS_GenEff",
              "VS_RefSpd", "WE_BladeRadius") + (("F_LPFDamping",) if ftype == 2 else ()):
        if not vals[k] > 0:
            raise ValueError(f"{p}: line {entries[k].line}: {k} = {vals[k]!r} must be positive")
    if not vals["PC_MinPit"] < vals["PC_MaxPit"]:
        raise ValueError(f"{p}: line {entries['PC_MinPit'].line}: PC_MinPit = {vals['PC_MinPit']} must be below "
                         f"PC_MaxPit = {vals['PC_MaxPit']} (rad)")
    if not (vals["PC_MinRat"] < 0 < vals["PC_MaxRat"]):
        raise ValueError(f"{p}: line {entries['PC_MinRat'].line}: PC_MinRat = {vals['PC_MinRat']} must be negative "
                         f"and PC_MaxRat = {vals['PC_MaxRat']} positive (rad/s)")
    if vals["VS_GenEff"] > 100:
        raise ValueError(f"{p}: line {entries['VS_GenEff'].line}: VS_GenEff = {vals['VS_GenEff']} is a percentage "
                         "(at most 100)")
    # ROSCO's tower damper (Controllers.f90, ForeAftDamping): read only when it is on, as
    # ROSCO itself skips FA_* with TD_Mode = 0 (ReadSetParameters.f90).
    td_mode = num("TD_Mode", integer=True) if "TD_Mode" in entries else 0
    if td_mode not in (0, 1):
        raise ValueError(f"{p}: line {entries['TD_Mode'].line}: TD_Mode = {td_mode} must be 0 or 1")
    tower = {}
    if td_mode == 1:
        tower = {"fa_ki": num("FA_KI"), "fa_hpf_corner": num("FA_HPFCornerFreq"), "fa_int_sat": num("FA_IntSat")}
        for k, f in (("FA_KI", "fa_ki"), ("FA_HPFCornerFreq", "fa_hpf_corner"), ("FA_IntSat", "fa_int_sat")):
            if not tower[f] > 0:
                raise ValueError(f"{p}: line {entries[k].line}: {k} = {tower[f]!r} must be positive with TD_Mode = 1 "
                                 "(set TD_Mode = 0 to switch the tower damper off)")
    return DisconSchedule(
        path=p, version=version, pitch=angles, kp=kp, ki=ki, filter_type=ftype,
        filter_corner=vals["F_LPFCornerFreq"], filter_damping=vals["F_LPFDamping"],
        reference_speed=vals["PC_RefSpd"], gearbox_ratio=vals["WE_GearboxRatio"],
        pitch_min=vals["PC_MinPit"], pitch_max=vals["PC_MaxPit"], pitch_rate_min=vals["PC_MinRat"],
        pitch_rate_max=vals["PC_MaxRat"], fine_pitch=vals["PC_FinePit"],
        vs_control_mode=num("VS_ControlMode", integer=True), vs_const_power=num("VS_ConstPower", integer=True),
        rated_torque=vals["VS_RtTq"], max_torque=vals["VS_MaxTq"], rated_power=vals["VS_RtPwr"],
        generator_efficiency=vals["VS_GenEff"] / 100.0, rated_generator_speed=vals["VS_RefSpd"],
        rotor_radius=vals["WE_BladeRadius"], td_mode=td_mode, **tower,
    )


def write_discon(source: str | Path, target: str | Path, **values) -> Path:
    """A copy of a DISCON.IN with some entries changed, runnable from another folder.

    Quoted relative file names (``PerfFileName``) are made absolute from the source's folder,
    where ROSCO would resolve them, so the copy runs wherever it is written.

    Parameters
    ----------
    source : str or pathlib.Path
        The DISCON.IN file.
    target : str or pathlib.Path
        The copy to write.
    **values
        Key → new value (written as given: ``VS_ControlMode=1``, ``PS_Mode=0``).

    Returns
    -------
    pathlib.Path
        ``target``.

    Raises
    ------
    ValueError
        If a key of ``values`` is not an entry of ``source``.

    Examples
    --------
    >>> import tempfile
    >>> from specdesign.rosco import iea15mw_discon
    >>> out = write_discon(iea15mw_discon(), Path(tempfile.mkdtemp()) / "DISCON.IN", PS_Mode=0)
    >>> read_discon(out)[0]["PS_Mode"].values
    ('0',)
    """
    source, target = Path(source), Path(target)
    entries, _ = read_discon(source)
    missing = sorted(set(values) - set(entries))
    if missing:
        raise ValueError(f"{source}: no entries {missing} to change")
    base = source.parent.resolve()
    lines = source.read_text(errors="replace").splitlines()
    for key, val in values.items():
        n = entries[key].line - 1
        left, sep, right = lines[n].partition("!")
        lines[n] = f"{val!s:<20}" + sep + right
    for n, raw in enumerate(lines):
        left, sep, right = raw.partition("!")
        if sep and '"' in left and not raw.lstrip().startswith("!"):
            lines[n] = re.sub(r'"([^"]*)"', lambda m: '"' + (m.group(1) if not m.group(1) or Path(m.group(1)).is_absolute()
                                                           or m.group(1) in ("unused", "DISCON")
                                                           or "://" in m.group(1) else str(base / m.group(1))) + '"',
                              left) + sep + right
    target.write_text("\n".join(lines) + "\n")
    return target
