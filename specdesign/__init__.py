"""specdesign: fatigue-based specifications and controller design for wind-turbine pitch control.

The design loop, one module a step:

- :mod:`specdesign.wind`: rotor-effective wind spectra and turbulent time series.
- :mod:`specdesign.turbine`: the embedded IEA 15 MW reduced model, trim, linearisation.
- :mod:`specdesign.rosco`: ROSCO's gain schedule, its PI baseline and its own gain scheduling.
- :mod:`specdesign.closedloop`: closed-loop maps T_{y,w}(jω) for any controller set.
- :mod:`specdesign.spectral`: spectral moments, Dirlik & co., DEL, damage sensitivity ΔD%(ω).
- :mod:`specdesign.fatigue`: rainflow counting, S-N curves, Palmgren-Miner, DEL from time series.
- :mod:`specdesign.spec`: notch-shaped specifications W_y(s) that promise a fatigue reduction.
- :mod:`specdesign.feasibility`: whether a specification pair can be met by pitch control, and
  the frontier of what it can promise.
- :mod:`specdesign.qft`: QFT design of the pitch and tower-damping controllers against the specs.
- :mod:`specdesign.hinf`: H∞ design with the fatigue-based specifications as weights.
- :mod:`specdesign.simulate`: batched nonlinear time-domain simulation.
- :mod:`specdesign.validate`: rainflow validation, indicators, the paper's tables, lifetime DEL,
  campaigns, the GP surrogate.
- :mod:`specdesign.mpc`: the related methods as controllers: quadratic MPC, fatigue-oriented
  economic MPC (Collet et al.'s Eq. 4), behavioural cloning, health-aware LPV-MPC (Boutrous, Nejjari and Puig).
- :mod:`specdesign.fatigue_online`: streaming rainflow + Miner (accumulated damage D(k)).
- :mod:`specdesign.openfast`: OpenFAST file adapters (.lin, .out/.outb) and
  :class:`~specdesign.openfast.LinearTurbine` (designs on OpenFAST linearisations).
- :mod:`specdesign.demo`: the 19 m/s design loop behind ``python -m specdesign demo``.
- :mod:`specdesign.cli`: the command line (``specdesign demo``, ``specdesign validate CONFIG``).

Generic control design (QFT, loop shaping, H∞) lives in the sibling package :mod:`loopshaping`.
Units are SI throughout; frequencies in rad/s; PSDs one-sided per rad/s.
"""
__version__ = "0.1.0"
