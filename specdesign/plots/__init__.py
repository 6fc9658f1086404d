"""Figures: results in, matplotlib axes out (no plt.show()).

Submodules by step of the design loop; matplotlib is imported only here. Magnitudes are in
dB only in figures (and specifications); everything else is SI with ω in rad/s.

- :mod:`specdesign.plots.turbine`: open loop vs ROSCO (Fig. 1), where fatigue comes from (Fig. 3);
- :mod:`specdesign.plots.fatigue`: rainflow histogram vs Dirlik, ΔD%(ω);
- :mod:`specdesign.plots.spec`: specifications and the interactive notch explorer;
- :mod:`specdesign.plots.qft`: QFT design Bode (Fig. 7) and Nichols charts (Figs. 5-6);
- :mod:`specdesign.plots.validation`: spectra (Fig. 8), time series (Fig. 9), DEL reductions (Fig. 10);
- :mod:`specdesign.plots.conventions`: the units, dB references, signs and standard-error rule
  every figure and table follows.

The package itself defines no names: import the figures from their submodule.
"""

__all__: list[str] = []
