"""OpenFAST deck doors (issue "Nothing silently wrong, part two"): from_openfast refuses a
DISCON/ElastoDyn value outside what OpenFAST itself accepts, naming the file, the line and the
key. The ranges are OpenFAST v5's (ElastoDyn_IO.f90: ValidatePrimaryData, ValidateBladeData,
ValidateTowerData) and ROSCO's (ReadSetParameters.f90: "PA_CornerFreq must be greater than 0").
Each case used to give a model silently wrong: PA_CornerFreq = -1 a pole at +0.707 1/s, a
negative blade mass density a drive-train inertia of -3.3e7 kg·m², a fractional NBlInpSt two
stations (J 5.1e6 instead of 4.35e7 kg·m²), PreCone = 1e300 a cosine of noise."""
from __future__ import annotations

import re
import shutil

import pytest

from specdesign.turbine import from_openfast

ED = "NRELOffshrBsline5MW_Onshore_ElastoDyn.dat"
TWR = "NRELOffshrBsline5MW_Onshore_ElastoDyn_Tower.dat"
BLD = "NRELOffshrBsline5MW_Blade.dat"

# the NREL 5 MW DISCON.IN runs VS_ConstPower = 1, which leaves the model above rated with a warning
pytestmark = pytest.mark.filterwarnings("ignore:.*torque law below rated is not modelled:UserWarning")


@pytest.fixture
def deck(rosco_cases, tmp_path):
    d = tmp_path / "NREL-5MW"
    shutil.copytree(rosco_cases / "NREL-5MW", d)
    return d


def _set(path, key, value):
    """Replace the value of ``key`` (OpenFAST "value key" or DISCON "value ! key") and return its 1-based line."""
    lines = path.read_text().splitlines()
    for n, line in enumerate(lines):
        tok = line.replace("!", " ").split()
        if len(tok) >= 2 and tok[1] == key:
            lines[n] = f"{value}   {'! ' if path.name == 'DISCON.IN' else ''}{key}   - edited"
            path.write_text("\n".join(lines) + "\n")
            return n + 1
    raise AssertionError(f"{key} not in {path}")


def _row(path, first_value, column, value):
    """Set ``column`` (0-based) of the table row starting with ``first_value``; its 1-based line."""
    lines = path.read_text().splitlines()
    for n, line in enumerate(lines):
        tok = line.split()
        if tok and re.fullmatch(r"[-+]?[0-9.]+([Ee][-+]?[0-9]+)?", tok[0]) and len(tok) >= 4 and float(tok[0]) == first_value:
            tok[column] = value
            lines[n] = "  ".join(tok)
            path.write_text("\n".join(lines) + "\n")
            return n + 1
    raise AssertionError(f"no row {first_value} in {path}")


def test_the_unedited_deck_reads(deck):
    m = from_openfast(deck / "NREL-5MW.fst")
    assert m.actuator_omega == pytest.approx(3.14) and m.actuator_zeta == pytest.approx(0.707)


@pytest.mark.parametrize("key, value", [("PA_CornerFreq", "-1"), ("PA_CornerFreq", "0"), ("PA_CornerFreq", "nan"),
                                        ("PA_CornerFreq", "fast"), ("PA_Damping", "-0.7"), ("PA_Damping", "0")])
def test_discon_actuator_outside_roscos_range(deck, key, value):
    line = _set(deck / "DISCON.IN", key, value)
    with pytest.raises(ValueError, match=rf"DISCON.IN: line {line}: {key} = "):
        from_openfast(deck / "NREL-5MW.fst")


@pytest.mark.parametrize("key, value, need", [
    ("PreCone(1)", "1e300", r"must lie in \(-90, 90\)"), ("PreCone(1)", "90", r"must lie in \(-90, 90\)"),
    ("PreCone(1)", "-95", r"must lie in \(-90, 90\)"), ("TowerHt", "-87.6", "must be positive"),
    ("HubRad", "70", "must be less than TipRad"), ("Twr2Shft", "-1", "must be non-negative"),
    ("GenIner", "-5", "must be non-negative"), ("HubIner", "inf", "must be non-negative"),
])
def test_elastodyn_values_outside_openfasts_range(deck, key, value, need):
    line = _set(deck / ED, key, value)
    with pytest.raises(ValueError, match=rf"{re.escape(ED)}: line {line}: {re.escape(key)} = .*{need}"):
        from_openfast(deck / "NREL-5MW.fst")


@pytest.mark.parametrize("value, need", [("2.5", "must be a whole number"), ("48.5", "must be a whole number"),
                                         ("1", "at least 2 stations"), ("0", "must be positive")])
def test_blade_station_count_is_a_whole_number(deck, value, need):
    line = _set(deck / BLD, "NBlInpSt", value)
    with pytest.raises(ValueError, match=rf"{BLD}: line {line}: NBlInpSt = .*{need}"):
        from_openfast(deck / "NREL-5MW.fst")


def test_negative_blade_mass_density_names_its_line(deck):
    line = _row(deck / BLD, 0.0, 2, "-678.935")  # BMassDen, the third column, at the root station
    with pytest.raises(ValueError, match=rf"{BLD}: line {line}: BMassDen\(1\) = -678.935 must be greater than zero"):
        from_openfast(deck / "NREL-5MW.fst")


def test_blade_fractions_must_rise_from_0_to_1(deck):
    line = _row(deck / BLD, 3.25e-3, 0, "0.5")  # the second station jumps past later ones
    with pytest.raises(ValueError, match=rf"{BLD}: line {line + 1}: BlFract\(3\) = .*must rise strictly from 0 to 1"):
        from_openfast(deck / "NREL-5MW.fst")


@pytest.mark.parametrize("column, key", [(1, "TMassDen"), (2, "TwFAStif")])
def test_tower_properties_must_be_positive(deck, column, key):
    line = _row(deck / TWR, 0.0, column, "-1")
    with pytest.raises(ValueError, match=rf"{TWR}: line {line}: {key}\(1\) = -1 must be greater than zero"):
        from_openfast(deck / "NREL-5MW.fst")


@pytest.mark.parametrize("value, need", [("110", "must be at most 100"), ("-1", "must be non-negative")])
def test_tower_damping_is_a_percentage(deck, value, need):
    line = _set(deck / TWR, "TwrFADmp(1)", value)
    with pytest.raises(ValueError, match=rf"{TWR}: line {line}: TwrFADmp\(1\) = .*{need}"):
        from_openfast(deck / "NREL-5MW.fst")


def test_tower_station_count_is_a_whole_number(deck):
    line = _set(deck / TWR, "NTwInpSt", "10.5")
    with pytest.raises(ValueError, match=rf"{TWR}: line {line}: NTwInpSt = 10.5 must be a whole number"):
        from_openfast(deck / "NREL-5MW.fst")
