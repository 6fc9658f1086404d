"""A designed controller out of the workbench: a Bladed-interface DISCON library and its parameter file.

:func:`export_discon` writes a design (QFT, H∞, scheduled, ROSCO-form gains, with its tower
damping loop and the generator-torque law) as a parameter file that one compiled library,
built from the C source this package ships (:func:`discon_library`), reads at its
initialisation. OpenFAST's ServoDyn runs the pair (``PCMode = 5``, ``VSContrl = 5``,
``DLL_FileName`` the library, ``DLL_InFile`` the parameter file, ``DLL_ProcName = DISCON``);
the workbench runs it through :class:`specdesign.rosco.Discon`, and its records equal those of
the Python controller (see ``docs/export.md``).

- :mod:`specdesign.export.bladed`: :func:`export_discon`, :func:`discon_parameters`.
- :mod:`specdesign.export.parameters`: the file format (:class:`DisconParameters`,
  :func:`write_parameters`, :func:`read_parameters`).
- :mod:`specdesign.export.library`: the compiled libraries (:func:`discon_library`,
  :func:`forward_library`).
- :mod:`specdesign.export.forward`: Python controllers (the MPCs) behind the Bladed interface:
  :func:`forwarded`, :class:`ForwardServer` (``forward.c`` forwards each call to Python).
"""
from __future__ import annotations

from .bladed import PARAMETER_FILE, DisconExport, discon_parameters, export_discon
from .forward import (
    FORWARD_FORMAT,
    MEASUREMENT_NAMES,
    Forwarded,
    ForwardError,
    ForwardServer,
    forwarded,
    swap_measurements,
)
from .library import FORWARD_SOURCE, SOURCE, CompilerNotFoundError, default_cache, discon_library, forward_library
from .parameters import (
    FORMAT_NAME,
    FORMAT_VERSION,
    TORQUE_MODES,
    DisconParameters,
    read_parameters,
    write_parameters,
)

__all__ = [
    "DisconExport",
    "export_discon",
    "discon_parameters",
    "PARAMETER_FILE",
    "DisconParameters",
    "write_parameters",
    "read_parameters",
    "discon_library",
    "forward_library",
    "forwarded",
    "Forwarded",
    "ForwardServer",
    "ForwardError",
    "swap_measurements",
    "MEASUREMENT_NAMES",
    "FORWARD_FORMAT",
    "FORWARD_SOURCE",
    "default_cache",
    "CompilerNotFoundError",
    "SOURCE",
    "FORMAT_NAME",
    "FORMAT_VERSION",
    "TORQUE_MODES",
]
