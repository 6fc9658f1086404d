"""loopshaping: generic frequency-domain control design.

- :mod:`loopshaping.qft`: templates, exact QFT bounds by spec name, intersection.
- :mod:`loopshaping.controller`: controllers as ordered lists of elements ↔ transfer functions.
- :mod:`loopshaping.nichols`: Nichols charts with bounds and loops.
- :mod:`loopshaping.auto`: automatic loop shaping (cvxpy).
- :mod:`loopshaping.check`: dense-grid specification check and robust stability.
- :mod:`loopshaping.interactive`: the Jupyter loop-shaping designer (ipywidgets, ipympl).
- :mod:`loopshaping.hinf`: H∞ synthesis with well-posedness checks, order reduction.

This package knows nothing about wind turbines and never imports :mod:`specdesign`.
Frequencies in rad/s; magnitudes in dB only in bound tables and plots.
"""
__version__ = "0.1.0"
