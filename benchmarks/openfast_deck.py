"""Regenerate the shipped OpenFAST deck, specdesign/data/openfast/IEA-15-240-RWT-Monopile/,
from the IEA 15 MW monopile example the ``rosco`` package ships (Examples/Test_Cases).

That example is written for an OpenFAST between v4.2 and v5.0: v5.0.0 refuses its SeaState
file (``WvCrntMod`` missing) and its HydroDyn file (``NAddDOF`` and ``HstMod`` missing), and
openfast-io 5.0's reader stops at the same places. The three missing keys are inserted into a
scratch copy with the v5.0 defaults that keep the old behaviour (``WvCrntMod = 0``: waves and
current superposed; ``NAddDOF = 0``: no additional WAMIT degrees of freedom, unused with
``PotMod = 0``; ``HstMod = 0``: hydrostatics up to the still-water level), then openfast-io
reads the whole deck with its reader and writes it with its writer (v5.0 format): no
hand-written deck. BeamDyn is off in the deck (``CompElast = 1``) and not shipped; the
controller library is named per case by :func:`specdesign.openfast.write_case`; ROSCO's debug
output is off (``LoggingLevel = 0``).

Run: ``python benchmarks/openfast_deck.py`` (a few seconds).
"""
from __future__ import annotations

import contextlib
import io
import shutil
import sys
import tempfile
from pathlib import Path

from openfast_io.FAST_reader import InputReader_OpenFAST
from openfast_io.FAST_writer import InputWriter_OpenFAST

from specdesign.rosco.discon import rosco_test_cases

NAME = "IEA-15-240-RWT-Monopile"
OUT = Path(__file__).resolve().parents[1] / "specdesign" / "data" / "openfast" / NAME
# (file, key after which the new line goes, the line): v5.0 keys the rosco copy lacks
MISSING = [
    (f"{NAME}_SeaState.dat", "WaveStMod",
     "0   WvCrntMod      - Combined wave-current modeling option {0: simple superposition} (switch)"),
    (f"{NAME}_HydroDyn.dat", "PtfmCOByt", "0   NAddDOF        - Number of additional generalized DOF (-)"),
    (f"{NAME}_HydroDyn.dat", "AMMod",
     "0   HstMod         - Method of computing hydrostatic loads (0: up to the still water level)"),
]


def _insert_after(path: Path, key: str, line: str) -> None:
    lines = path.read_text().splitlines(True)
    at = next(i for i, t in enumerate(lines) if len(t.split()) > 1 and t.split()[1] == key)
    lines.insert(at + 1, line + "\n")
    path.write_text("".join(lines))


def _unused_paths(tree, scratch: str) -> None:
    """The reader makes every file name absolute, "unused" and "none" too: those go back to
    the plain word (the others are rewritten by the writer under the deck's names)."""
    items = tree.items() if isinstance(tree, dict) else enumerate(tree) if isinstance(tree, list) else ()
    for k, val in items:
        if isinstance(val, str) and val.startswith(scratch) and Path(val).name.lower() in ("unused", "none"):
            tree[k] = Path(val).name
        elif isinstance(val, (dict, list)):
            _unused_paths(val, scratch)


def main() -> None:
    src = rosco_test_cases() / "IEA-15-240-RWT"
    with tempfile.TemporaryDirectory() as tmp:
        scratch = Path(tmp) / "IEA-15-240-RWT"
        shutil.copytree(src, scratch)
        deck = scratch / NAME
        for name, key, line in MISSING:
            _insert_after(deck / name, key, line)
        reader = InputReader_OpenFAST()
        reader.FAST_InputFile = f"{NAME}.fst"
        reader.FAST_directory = str(deck)
        with contextlib.redirect_stdout(io.StringIO()):  # ROSCO's reader prints what it loads
            reader.execute()
        vt = reader.fst_vt
        _unused_paths(vt, str(scratch))
        vt["BeamDyn"] = {}  # CompElast = 1: ElastoDyn blades; BeamDyn is never read
        for k in (1, 2, 3):
            vt["Fst"][f"BDBldFile({k})"] = "unused"
        vt["ServoDyn"]["DLL_FileName"] = "libdiscon.so"  # named per case by write_case
        # ROSCO's debug file (.RO.dbg, every step of every run) off: campaigns read OpenFAST's outputs
        vt["DISCON_in"]["LoggingLevel"] = 0
        # no HydroDyn joint outputs (none is read): openfast-io 5.0 writes a list of two
        # joints space-separated and its reader, expecting commas, cannot read it back
        vt["HydroDyn"]["NJOutputs"], vt["HydroDyn"]["JOutLst"] = 0, [0]
        if OUT.exists():
            shutil.rmtree(OUT)
        writer = InputWriter_OpenFAST()
        writer.fst_vt = vt
        writer.FAST_runDirectory = str(OUT)
        writer.FAST_namingOut = NAME
        with contextlib.redirect_stdout(io.StringIO()):
            writer.execute()
    n = sum(1 for _ in OUT.rglob("*") if _.is_file())
    print(f"wrote {n} files into {OUT}", file=sys.stderr)


if __name__ == "__main__":
    main()
