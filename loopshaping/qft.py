"""QFT in one import: templates, specifications and exact bounds (a facade).

The code lives in

- :mod:`loopshaping.templates`: :class:`Template` (plant cases at the design
  frequencies), :func:`tracking_pairs`;
- :mod:`loopshaping.specs`: :class:`Spec`, :data:`KINDS`;
- :mod:`loopshaping.bounds`: :func:`bounds`, :class:`Bounds`, :func:`intersect`, :func:`as_specs`,
  :class:`BoundsWarning` and the closed-form solver;
- :mod:`loopshaping.freqresp`: :func:`evaluate` and the grid checks.

and every name is re-exported here, so ``from loopshaping import qft`` then ``qft.bounds``,
``qft.Template``, ... keep working. Frequencies in rad/s; magnitudes in dB only in the
bound tables (``forbidden_db``).
"""
from __future__ import annotations

from .bounds import (
    DEFAULT_PHASES_DEG,
    Bounds,
    BoundsWarning,
    as_specs,
    bounds,
    intersect,
)
from .freqresp import check_grid, evaluate
from .specs import KINDS, Spec, controller_gain
from .templates import Template, tracking_pairs

__all__ = [
    "DEFAULT_PHASES_DEG",
    "KINDS",
    "Bounds",
    "BoundsWarning",
    "Spec",
    "Template",
    "as_specs",
    "bounds",
    "check_grid",
    "controller_gain",
    "evaluate",
    "intersect",
    "tracking_pairs",
]
