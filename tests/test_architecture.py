"""Architecture rules: loopshaping is generic and never imports specdesign; data is shipped."""
import subprocess
import sys


def test_loopshaping_never_imports_specdesign():
    code = (
        "import importlib, pkgutil, sys, loopshaping\n"
        "for m in pkgutil.iter_modules(loopshaping.__path__):\n"
        "    importlib.import_module('loopshaping.' + m.name)\n"
        "bad = [k for k in sys.modules if k == 'specdesign' or k.startswith('specdesign.')]\n"
        "assert not bad, bad\n"
        "print('ok', len([k for k in sys.modules if k.startswith('loopshaping')]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("ok")


def test_package_ships_its_data(package_data, shared_data):
    for f in shared_data.iterdir():
        shipped = package_data / f.name
        assert shipped.is_file(), f"{f.name} is not shipped in specdesign/data/iea15mw"
        assert shipped.read_bytes() == f.read_bytes(), f"{f.name} differs from ../shared"
