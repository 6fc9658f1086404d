"""loopshaping: generic frequency-domain control design.

- :mod:`loopshaping.freqresp`: frequency-response helpers every module shares: ``evaluate``,
  ``check_grid``, ``check_phases``, ``is_lti`` and ``as_siso`` (make it a SISO LTI).
- :mod:`loopshaping.templates`: QFT templates (plant cases at the design frequencies).
- :mod:`loopshaping.specs`: QFT specifications by kind name (``Spec``, ``KINDS``).
- :mod:`loopshaping.bounds`: exact QFT bounds (closed form), ``Bounds``, ``intersect``.
- :mod:`loopshaping.qft`: the QFT facade, re-exporting templates, specs, bounds, ``evaluate``.
- :mod:`loopshaping.controller`: controllers as ordered lists of elements ↔ transfer functions.
- :mod:`loopshaping.nichols`: Nichols charts with bounds and loops.
- :mod:`loopshaping.interactive`: the Jupyter loop-shaping designer (ipywidgets, ipympl).
- :mod:`loopshaping.auto`: automatic loop shaping (cvxpy).
- :mod:`loopshaping.check`: dense-grid specification check and robust stability.
- :mod:`loopshaping.hinf`: H∞ synthesis (``synthesize``, ``mixed_sensitivity``).
- :mod:`loopshaping.wellposed`: well-posedness checks and regularisation of H∞ problems.
- :mod:`loopshaping.reduction`: controller order reduction and discretisation.

This package knows nothing about wind turbines and never imports :mod:`specdesign`.
Frequencies in rad/s (a frequency grid is called ``omega`` everywhere); magnitudes in dB only
in bound tables and plots; arguments in ``(plant, controller)`` order.
"""
__version__ = "0.1.0"
