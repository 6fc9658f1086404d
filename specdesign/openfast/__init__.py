"""OpenFAST file adapters: arrays and labels in, no physics.

- :func:`read_linearization` (``.lin`` files → azimuth-averaged, MBC-transformed named LTI)
- :func:`read_outputs` (``.out`` / ``.outb`` → named channels with units)
- :func:`series_from_openfast` (outputs → the workbench's SI series, :data:`OPENFAST_CHANNELS`)
- :class:`LinearTurbine` (``.lin`` sets at several wind speeds → a model the design loop takes;
  signals by channel description, :data:`DEFAULT_SIGNALS`, :func:`plant_from_linearization`)
- :func:`find_openfast`, :func:`build_openfast` (the executables: found, or built from source
  into a cache; :class:`OpenFASTInstall`)
- :class:`Deck`, :func:`iea15mw_monopile` (the shipped v5.0 deck), :func:`write_case`,
  :func:`run_case` (case folders written with openfast-io and run in a subprocess),
  :func:`wave_seed_for` (each run's sea)
- :func:`linearize_deck` (a deck → OpenFAST trim-and-linearise runs at several wind speeds →
  :class:`LinearTurbine`; :func:`write_linearization_case` writes one case)
"""
from __future__ import annotations

import importlib

_LAZY = {
    "read_linearization": ".lin",
    "LinearizationData": ".lin",
    "read_outputs": ".outputs",
    "OpenFASTOutput": ".outputs",
    "series_from_openfast": ".series",
    "OPENFAST_CHANNELS": ".series",
    "LinearTurbine": ".linear_turbine",
    "LinearOperatingPoint": ".linear_turbine",
    "RotorModelSchedule": ".linear_turbine",
    "rotor_speed_model": ".linear_turbine",
    "DEFAULT_SIGNALS": ".signals",
    "plant_from_linearization": ".signals",
    "OpenFASTInstall": ".install",
    "OpenFASTNotFound": ".install",
    "find_openfast": ".install",
    "build_openfast": ".install",
    "check_deck_version": ".install",
    "Deck": ".deck",
    "Case": ".deck",
    "OpenFASTRunError": ".deck",
    "iea15mw_monopile": ".deck",
    "write_case": ".deck",
    "run_case": ".deck",
    "CAMPAIGN_CHANNELS": ".deck",
    "wave_seed_for": ".deck",
    "linearize_deck": ".linearize",
    "write_linearization_case": ".linearize",
    "LinearizationCase": ".linearize",
}

__all__ = list(_LAZY)


def __getattr__(name):  # the adapters import openfast-io only when used
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name], __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
