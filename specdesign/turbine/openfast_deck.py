"""A reduced turbine model from an OpenFAST deck: :func:`from_openfast`.

Read with a line-checked reader of OpenFAST's ``value  Key  - description`` format (every
value the model needs is looked up by key, and a missing or non-numeric one raises a
ValueError naming the file, the line and the key; openfast-io's deck reader raises bare
KeyErrors or reads whole AeroDyn/airfoil sets the model does not need). What is read:

- ``.fst``: ``EDFile``, ``ServoFile``, ``AeroFile``, ``AirDens`` (else AeroDyn's).
- ElastoDyn: ``TipRad``, ``HubRad``, ``PreCone(1)``, ``HubIner``, ``GenIner``, ``GBRatio``,
  ``TowerHt``, ``TowerBsHt``, ``NacMass``, ``NacCMzn``, ``HubMass``, ``Twr2Shft``,
  ``YawBrMass``, ``BldFile(1)`` (or ``BldFile1``),
  ``TwrFile``; the blade file's ``AdjBlMs`` and ``BlFract``/``BMassDen`` table; the tower
  file's ``AdjTwMa``, ``AdjFASt``, ``TwrFADmp(1)``, ``HtFract``/``TMassDen``/``TwFAStif``
  table and first fore-aft mode shape ``TwFAM1Sh(2..6)``.
- ServoDyn: ``DLL_InFile`` (the DISCON.IN when ``discon`` is not given), ``GenEff``.
- DISCON.IN (:func:`specdesign.rosco.from_discon`): rated speed ``PC_RefSpd``/N, torque
  ``VS_RtTq``·N, power ``VS_RtPwr``, efficiency ``VS_GenEff``, pitch limits and rate
  (``PC_MinPit``, ``PC_MaxPit``, ``PC_MaxRat``), ROSCO's actuator ``PA_CornerFreq``,
  ``PA_Damping``, and ``PerfFileName`` (the Cp/Ct/Cq table when ``cp_table`` is not given).

Formulas (the reduced model has one shaft, gear ratio 1: speeds and torques on the rotor
side, N = ``GBRatio``):

- drivetrain inertia J = 3·∫ m_b(r)·(r cos γ)² dr + HubIner + N²·GenIner, over the blade
  r = HubRad … TipRad, m_b = AdjBlMs·BMassDen, γ = PreCone;
- first tower fore-aft mode, φ(x) = Σ_{i=2..6} c_i x^i, x = h/L, L = TowerHt − TowerBsHt,
  φ(1) = 1 (tower-top deflection), θ = φ'(L) the tower-top rotation per metre of it. The
  rotor-nacelle assembly: the nacelle (NacMass, centre NacCMzn above the tower top), the
  hub and blades (HubMass + 3·m_blade at the shaft height Twr2Shft), the yaw bearing
  (YawBrMass, at the top), and the rotor's inertia about a diameter, J_tilt = (3·J_blade +
  HubIner)/2, that the top rotation turns. Modal mass
  m = ∫ μ φ² dh + Σ M_i (1 + z_i θ)² + J_tilt θ², modal stiffness
  k = ∫ EI φ''² dh − g ∫ (M + ∫_h^L μ) φ'² dh (ElastoDyn's gravitational softening, M the
  assembly's mass), μ = AdjTwMa·TMassDen, EI = AdjFASt·TwFAStif, damping ratio TwrFADmp(1)/100;
- tower-base moment per tower-top deflection EI(0)·φ''(0), the mode's bending moment at the base.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np

from .._checks import positive_scalar
from ..controller.discon_file import from_discon, read_discon
from ..controller.torque import torque_law_from_discon
from .model import TurbineModel

__all__ = ["GRAVITY", "read_openfast_file", "read_cp_table", "from_openfast"]

#: Gravitational acceleration (m/s²), ElastoDyn's default.
GRAVITY = 9.80665


def read_openfast_file(path: str | Path) -> tuple[dict, list]:
    """The ``value  Key`` entries of an OpenFAST input file, and its lines.

    Parameters
    ----------
    path : str or pathlib.Path
        An OpenFAST input file (``.fst``, ElastoDyn, ServoDyn, AeroDyn, tower, blade).

    Returns
    -------
    entries : dict
        Key → (first value token, 1-based line number); the first occurrence of a key wins.
    lines : list of str
        The file's lines.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"OpenFAST input file {str(path)!r} does not exist")
    lines = path.read_text(errors="replace").splitlines()
    entries = {}
    for n, line in enumerate(lines, start=1):
        tok = line.split()
        if len(tok) >= 2 and not line.lstrip().startswith(("--", "!", "==")):
            entries.setdefault(tok[1], (tok[0], n))
    return entries, lines


class _File:
    """One OpenFAST file with checked look-ups naming the file, line and key."""

    def __init__(self, path):
        self.path = Path(path)
        self.entries, self.lines = read_openfast_file(self.path)

    def has(self, key):
        return key in self.entries

    def number(self, key, positive=False, nonnegative=False, *, integer=False, below=None, at_most=None):
        """The value of ``key``, checked as OpenFAST checks it (``below``: |v| < below;
        ``at_most``: v ≤ at_most; ``integer``: a whole number, as Fortran reads an INTEGER)."""
        if key not in self.entries:
            raise ValueError(f"{self.path}: key {key!r} is missing")
        tok, n = self.entries[key]
        try:
            v = float(tok)
        except ValueError:
            raise ValueError(f"{self.path}: line {n}: {key} = {tok!r} is not a number") from None
        if not math.isfinite(v) or (positive and not v > 0) or (nonnegative and not v >= 0):
            need = "positive" if positive else "non-negative" if nonnegative else "finite"
            raise ValueError(f"{self.path}: line {n}: {key} = {tok} must be {need}")
        if integer and v != int(v):
            raise ValueError(f"{self.path}: line {n}: {key} = {tok} must be a whole number (OpenFAST reads an integer)")
        if below is not None and not abs(v) < below:
            raise ValueError(f"{self.path}: line {n}: {key} = {tok} must lie in (-{below:g}, {below:g}) (OpenFAST's range)")
        if at_most is not None and not v <= at_most:
            raise ValueError(f"{self.path}: line {n}: {key} = {tok} must be at most {at_most:g} (OpenFAST's range)")
        return v

    def file(self, key):
        if key not in self.entries:
            raise ValueError(f"{self.path}: key {key!r} is missing")
        name = self.entries[key][0].strip('"').strip("'")
        p = Path(name)
        return p if p.is_absolute() else self.path.parent / p

    def table(self, after, columns, rows, *, positive=(), fraction=None):
        """``rows`` rows of the numeric table under the section line containing ``after``
        (two header lines), the named ``columns`` of its header. Columns in ``positive`` must
        be > 0 in every row, and the column ``fraction`` must rise strictly from 0 to 1, as
        ElastoDyn requires (ValidateBladeData, ValidateTowerData): the error names the line."""
        for i, line in enumerate(self.lines):
            if after in line.upper():
                header = self.lines[i + 1].split()
                missing = [c for c in columns if c not in header]
                if missing:
                    raise ValueError(f"{self.path}: line {i + 2}: the {after.lower()} table lacks {missing}")
                data = []
                for k in range(rows):
                    n = i + 4 + k
                    try:
                        data.append([float(x) for x in self.lines[n - 1].split()[:len(header)]])
                    except (ValueError, IndexError):
                        raise ValueError(f"{self.path}: line {n}: row {k + 1} of {rows} of the {after.lower()} table "
                                         "is not numeric") from None
                    if len(data[-1]) != len(header):
                        raise ValueError(f"{self.path}: line {n}: row {k + 1} has {len(data[-1])} values, "
                                         f"the header {len(header)}")
                a = np.array(data)
                if not np.all(np.isfinite(a)):
                    k = int(np.argmin(np.all(np.isfinite(a), axis=1)))
                    raise ValueError(f"{self.path}: line {i + 4 + k}: row {k + 1} of the {after.lower()} table holds "
                                     "NaN or inf")
                for c in positive:
                    col = a[:, header.index(c)]
                    if np.any(col <= 0):
                        k = int(np.argmax(col <= 0))
                        raise ValueError(f"{self.path}: line {i + 4 + k}: {c}({k + 1}) = {col[k]:g} must be greater "
                                         "than zero (as ElastoDyn requires)")
                if fraction is not None:
                    col = a[:, header.index(fraction)]
                    bad = [k for k in range(1, rows) if not col[k] > col[k - 1]]
                    if col[0] != 0.0 or col[-1] != 1.0 or bad:
                        k = 0 if col[0] != 0.0 else bad[0] if bad else rows - 1
                        raise ValueError(f"{self.path}: line {i + 4 + k}: {fraction}({k + 1}) = {col[k]:g}: {fraction} "
                                         "must rise strictly from 0 to 1 (as ElastoDyn requires)")
                return [a[:, header.index(c)] for c in columns]
        raise ValueError(f"{self.path}: no section {after!r}")


def read_cp_table(path: str | Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A rotor performance table in ROSCO's text format (``Cp_Ct_Cq.*.txt``).

    Parameters
    ----------
    path : str or pathlib.Path
        The table file.

    Returns
    -------
    tsr : numpy.ndarray
        (n_tsr,) tip-speed ratios (-).
    pitch : numpy.ndarray
        (n_pitch,) blade pitch (rad; the file's degrees converted).
    cp, ct : numpy.ndarray
        (n_tsr, n_pitch) power and thrust coefficients (-).

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        Naming the file, for a missing pitch/TSR vector or coefficient block, or a block of the
        wrong shape.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"Cp/Ct/Cq table {str(path)!r} does not exist")
    lines = path.read_text(errors="replace").splitlines()
    vec, blocks = {}, {}
    i = 0
    while i < len(lines):
        low = lines[i].strip().lower()
        if low.startswith("#") and ("pitch angle vector" in low or "tsr vector" in low):
            vec["pitch" if "pitch" in low else "tsr"] = np.array(lines[i + 1].split(), float)
        elif low.startswith("#") and "coefficient" in low and "tsr" in vec:
            rows, j = [], i + 1
            while j < len(lines) and len(rows) < vec["tsr"].size and not lines[j].lstrip().startswith("#"):
                if lines[j].strip():
                    rows.append(np.array(lines[j].split(), float))
                j += 1
            blocks[low.split()[1][:2]] = rows
            i = j
            continue
        i += 1
    for k, what in (("pitch", "pitch angle vector"), ("tsr", "TSR vector"), ("po", "power coefficient block"),
                    ("th", "thrust coefficient block")):
        if k not in vec and k not in blocks:
            raise ValueError(f"{path}: no {what} (ROSCO's Cp_Ct_Cq format)")
    shape = (vec["tsr"].size, vec["pitch"].size)
    out = []
    for k in ("po", "th"):
        if len(blocks[k]) != shape[0] or any(r.size != shape[1] for r in blocks[k]):
            raise ValueError(f"{path}: the {'power' if k == 'po' else 'thrust'} coefficient block is not "
                             f"{shape[0]} x {shape[1]} (TSR x pitch)")
        out.append(np.array(blocks[k]))
    return vec["tsr"], np.deg2rad(vec["pitch"]), out[0], out[1]


def _tower(ed: _File, lumped: list, j_tilt: float):
    twr = _File(ed.file("TwrFile"))
    n = int(twr.number("NTwInpSt", positive=True, integer=True))
    if n < 2:
        raise ValueError(f"{twr.path}: line {twr.entries['NTwInpSt'][1]}: NTwInpSt = {n}: the tower needs at least 2 "
                         "stations (0 and 1)")
    frac, mu, ei = twr.table("DISTRIBUTED TOWER PROPERTIES", ("HtFract", "TMassDen", "TwFAStif"), n,
                             positive=("TMassDen", "TwFAStif"), fraction="HtFract")
    c = np.array([twr.number(f"TwFAM1Sh({i})") for i in range(2, 7)])
    if abs(c.sum() - 1.0) > 1e-3:
        raise ValueError(f"{twr.path}: TwFAM1Sh(2..6) sum to {c.sum():.5g}, not 1 (the mode at the tower top)")
    length = ed.number("TowerHt", positive=True) - ed.number("TowerBsHt")
    if not length > 0:
        raise ValueError(f"{ed.path}: TowerHt - TowerBsHt = {length} m must be positive")
    mu = mu * twr.number("AdjTwMa", positive=True)
    ei = ei * twr.number("AdjFASt", positive=True)
    # a fine grid: the tables are linear between stations, the mode a polynomial
    x = np.linspace(0.0, 1.0, 2001)
    h = x * length
    mu_x, ei_x = np.interp(x, frac, mu), np.interp(x, frac, ei)
    powers = np.arange(2, 7)
    phi = (c * x[:, None] ** powers).sum(1)
    dphi = (c * powers * x[:, None] ** (powers - 1)).sum(1) / length
    ddphi = (c * powers * (powers - 1) * x[:, None] ** (powers - 2)).sum(1) / length**2
    above = np.concatenate([np.cumsum((mu_x[1:] + mu_x[:-1]) * np.diff(h) / 2)[::-1], [0.0]])  # ∫_h^L μ
    theta = dphi[-1]
    top_mass = sum(m for m, _ in lumped)
    mass = np.trapezoid(mu_x * phi**2, h) + sum(m * (1 + z * theta) ** 2 for m, z in lumped) + j_tilt * theta**2
    stiff = np.trapezoid(ei_x * ddphi**2, h) - GRAVITY * np.trapezoid((top_mass + above) * dphi**2, h)
    if not stiff > 0:
        raise ValueError(f"{twr.path}: the first fore-aft mode has no positive stiffness with gravity ({stiff:.4g} N/m)")
    return mass, stiff, twr.number("TwrFADmp(1)", nonnegative=True, at_most=100.0) / 100.0, ei_x[0] * ddphi[0]


def from_openfast(fst_path: str | Path, cp_table: str | Path | None = None,
                  discon: str | Path | None = None, *, rotor_inertia: float | None = None) -> TurbineModel:
    """The reduced turbine model of an OpenFAST deck (see the module for what is read and the formulas).

    Parameters
    ----------
    fst_path : str or pathlib.Path
        The deck's ``.fst`` file.
    cp_table : str or pathlib.Path, optional
        Rotor performance table in ROSCO's format (default: the DISCON.IN's ``PerfFileName``).
    discon : str or pathlib.Path, optional
        ROSCO's DISCON.IN (default: ServoDyn's ``DLL_InFile``).
    rotor_inertia : float, optional
        Rotor inertia about the shaft, hub included, kg·m² (e.g. the "Rotor Inertia" of
        OpenFAST's ElastoDyn summary file), instead of the integral over the ElastoDyn blade
        file; the generator's N²·GenIner is added either way. For decks whose blades are
        BeamDyn's (``CompElast`` = 2) the ElastoDyn blade file need not be the blade flown:
        BAR_10's gives 2.4 % less than the 3.0564e8 kg·m² ROSCO's tuning file quotes.

    Returns
    -------
    TurbineModel
        The model, named after the ``.fst`` file, wind range from the first 0.1 m/s above
        rated to 25 m/s. With ROSCO's torque law of the DISCON.IN attached as its
        ``torque_control`` (:func:`specdesign.rosco.torque_law_from_discon`;
        ``VS_ControlMode`` 2 run as 3, TSR tracking on the measured rotor speed),
        :meth:`~specdesign.turbine.TurbineModel.trim` and ``linearize`` hold from cut-in
        (``operating_range``, 3-25 m/s). A DISCON.IN whose law the workbench does not run
        (e.g. ``VS_ConstPower`` = 1) leaves the model above rated only, with a UserWarning.

    Raises
    ------
    FileNotFoundError
        If a file of the deck does not exist.
    ValueError
        Naming the file, line and key, for a value outside what OpenFAST itself accepts
        (ElastoDyn: |PreCone| < 90°, HubRad < TipRad, TowerHt > 0, masses, inertias and
        Twr2Shft ≥ 0, whole station counts, BMassDen/TMassDen/TwFAStif > 0, BlFract and
        HtFract rising from 0 to 1, TwrFADmp in 0-100 %; ROSCO: PA_CornerFreq, PA_Damping > 0),
        for a missing, non-numeric or inconsistent value
        (e.g. ServoDyn's ``GenEff`` against DISCON's ``VS_GenEff``, the gear ratio of
        ElastoDyn and DISCON, a mode shape that does not end at 1), a rotor table the
        compiled model cannot use (a non-uniform grid), or a deck with a flexible substructure
        (``CompSub`` ≠ 0: the tower mode would miss it).

    Examples
    --------
    >>> from specdesign.rosco import rosco_test_cases
    >>> m = from_openfast(rosco_test_cases() / "NREL-5MW/NREL-5MW.fst")  # doctest: +SKIP
    """
    fst = _File(fst_path)
    if fst.has("CompSub") and fst.number("CompSub") != 0:
        raise ValueError(f"{fst.path}: line {fst.entries['CompSub'][1]}: CompSub = {fst.entries['CompSub'][0]}: the "
                         "substructure is flexible (SubDyn) and the reduced model's tower mode, from ElastoDyn's tower "
                         "alone, would miss it; use a deck with a rigid base (CompSub = 0)")
    ed = _File(fst.file("EDFile"))
    sd = _File(fst.file("ServoFile"))
    discon = Path(discon) if discon is not None else sd.file("DLL_InFile")
    ds = from_discon(discon)
    entries, _ = read_discon(discon)
    gb = ed.number("GBRatio", positive=True)
    if abs(gb - ds.gearbox_ratio) > 5e-3 * gb:  # DISCON.IN rounds it (BAR_10: 96.76 and 96.8)
        raise ValueError(f"{ed.path}: GBRatio = {gb:g} but {discon}: WE_GearboxRatio = {ds.gearbox_ratio:g}")
    if sd.has("GenEff") and abs(sd.number("GenEff") / 100 - ds.generator_efficiency) > 5e-3:
        raise ValueError(f"{sd.path}: GenEff = {sd.number('GenEff')} % but {discon}: VS_GenEff = "
                         f"{100 * ds.generator_efficiency:g} %")
    if cp_table is None:
        e = entries.get("PerfFileName")
        if e is None:
            raise ValueError(f"{discon}: key 'PerfFileName' is missing (or pass cp_table=)")
        cp_table = discon.parent / e.values[0].strip('"')
    tsr, pitch, cp, ct = read_cp_table(cp_table)
    # rotor: blades (distributed mass), hub, generator through the gearbox
    tip, hub = ed.number("TipRad", positive=True), ed.number("HubRad", nonnegative=True)
    if not hub < tip:
        raise ValueError(f"{ed.path}: line {ed.entries['HubRad'][1]}: HubRad = {hub:g} m must be less than TipRad = "
                         f"{tip:g} m (as ElastoDyn requires)")
    blade = _File(ed.file("BldFile1" if ed.has("BldFile1") and not ed.has("BldFile(1)") else "BldFile(1)"))
    nb = int(blade.number("NBlInpSt", positive=True, integer=True))
    if nb < 2:
        raise ValueError(f"{blade.path}: line {blade.entries['NBlInpSt'][1]}: NBlInpSt = {nb}: the blade's mass "
                         "integral needs at least 2 stations (0 and 1)")
    frac, mden = blade.table("DISTRIBUTED BLADE PROPERTIES", ("BlFract", "BMassDen"), nb, positive=("BMassDen",),
                             fraction="BlFract")
    r = hub + frac * (tip - hub)
    mden = mden * blade.number("AdjBlMs", positive=True)
    cone = math.radians(ed.number("PreCone(1)", below=90.0))  # ElastoDyn: |PreCone| < 90°
    m_blade = np.trapezoid(mden, r)
    rotor = 3 * np.trapezoid(mden * (r * math.cos(cone)) ** 2, r) + ed.number("HubIner", nonnegative=True)
    if rotor_inertia is not None:
        rotor = positive_scalar(rotor_inertia, "rotor_inertia (kg·m², about the shaft, hub included)")
    inertia = rotor + gb**2 * ed.number("GenIner", nonnegative=True)
    lumped = [(ed.number("NacMass", nonnegative=True), ed.number("NacCMzn")),
              (ed.number("HubMass", nonnegative=True) + 3 * m_blade, ed.number("Twr2Shft", nonnegative=True)),
              (ed.number("YawBrMass", nonnegative=True), 0.0)]
    mass, stiff, zeta, my_per_m = _tower(ed, lumped, rotor / 2)
    if fst.has("AirDens"):
        rho = fst.number("AirDens", positive=True)
    else:
        rho = _File(fst.file("AeroFile")).number("AirDens", positive=True)
    pa = [_discon_positive(discon, entries, k, v) for k, v in (("PA_CornerFreq", 3.14), ("PA_Damping", 0.707))]
    try:
        model = _model(fst_path, rho, tip, inertia, mass, stiff, zeta, my_per_m, pa, ds, gb, tsr, pitch, cp, ct)
        # from the first 0.1 m/s above rated: ROSCO's schedule starts just above rated
        model = dataclasses.replace(model, wind_range=(math.ceil(10 * model.rated_wind_speed() + 1e-9) / 10, 25.0))
    except ValueError as e:
        raise ValueError(f"{fst.path} (rotor table {cp_table}): {e}") from None
    return _with_torque_law(model, discon, entries)


def _discon_positive(discon, entries, key, default):
    """DISCON's ``key`` (default when absent) as a number > 0, else a ValueError naming the file,
    line and key: ROSCO refuses a negative actuator corner or damping ("must be greater than
    0"), and the model's second-order actuator has no pole to place at 0 (a pole at +0.707 1/s
    with PA_CornerFreq = -1)."""
    e = entries.get(key)
    if e is None:
        return default
    try:
        v = float(e.values[0])
    except (ValueError, IndexError):
        raise ValueError(f"{discon}: line {e.line}: {key} = {' '.join(e.values)!r} is not a number") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{discon}: line {e.line}: {key} = {e.values[0]} must be greater than 0 (ROSCO's pitch "
                         "actuator: a corner frequency in rad/s, a damping ratio)")
    return v


def _with_torque_law(model, discon, entries):
    """The model with ROSCO's torque law of its DISCON.IN attached (trim and linearize from
    cut-in), or unchanged with a warning when the workbench does not run that DISCON's law."""
    e = entries.get("VS_ControlMode")
    try:
        # mode 2 tracks the TSR from ROSCO's wind-speed estimator (not modelled): its power-based
        # TSR tracking (mode 3) is the same law on the measured rotor speed
        mode = 3 if e is not None and int(float(e.values[0])) == 2 else None
        law = torque_law_from_discon(discon, mode=mode)
    except ValueError as err:
        warnings.warn(f"{discon}: ROSCO's torque law below rated is not modelled ({err}); the model is above rated "
                      "only (trim and linearize from rated to 25 m/s)", UserWarning, stacklevel=3)
        return model
    return dataclasses.replace(model, torque_control=law)


def _model(fst_path, rho, tip, inertia, mass, stiff, zeta, my_per_m, pa, ds, gb, tsr, pitch, cp, ct):
    return TurbineModel(
        name=Path(fst_path).stem, air_density=rho, rotor_radius=tip, drivetrain_inertia=float(inertia),
        tower_modal_mass=float(mass), tower_modal_stiffness=float(stiff), tower_damping_ratio=zeta,
        tower_base_moment_per_m=float(abs(my_per_m)), actuator_omega=pa[0], actuator_zeta=pa[1],
        pitch_rate_limit=ds.pitch_rate_max, pitch_min=ds.pitch_min, pitch_max=ds.pitch_max,
        generator_efficiency=ds.generator_efficiency, rated_rotor_speed=ds.reference_speed / gb,
        rated_generator_torque=ds.rated_torque * gb, rated_power=ds.rated_power,
        tsr_grid=tsr, pitch_grid=pitch, cp_table=cp, ct_table=ct, wind_range=(3.0, 25.0),
    )
