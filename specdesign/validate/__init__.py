"""Offline validation: indicators, spectra, paired-seed statistics and the paper's Tables 2-3.

Works on arrays, so the same post-processing serves :func:`specdesign.simulate.simulate` runs
and the user's OpenFAST outputs (:func:`specdesign.openfast.series_from_openfast`).

Modules, in the order they build on each other:

- :mod:`~specdesign.validate.metrics`: per-run indicators (the paper's four, plus pitch
  rate): tower-base DEL by rainflow (a range, N·m, 1 Hz convention, Wöhler exponent m = 4 by
  default), generator-speed SD (rad/s), mean electrical power (W), pitch SD (rad) and
  pitch-rate SD (rad/s).
- :mod:`~specdesign.validate.stats`: Weibull weights, Welch spectra per rad/s, pooling over
  seeds and paired-seed changes with jackknife or bootstrap standard errors.
- :mod:`~specdesign.validate.prediction`: the closed-loop map T_{y,w}(jω) of any controller
  the simulator runs and the linear prediction |T|²S_W with its spectral DEL.
- :mod:`~specdesign.validate.volterra`: the Volterra (perturbation) series of the nonlinear
  loop and the DEL it predicts.
- :mod:`~specdesign.validate.campaign`: controllers × wind speeds × paired seeds, simulated
  and post-processed (:class:`Campaign`), with the up-front checks.
- :mod:`~specdesign.validate.tables`: the paper's Tables 2-3 and the acceptance of a design.
- :mod:`~specdesign.validate.lifetime_del`: per-bin DELs combined over a Weibull or user-given wind
  climate into the lifetime DEL, with paired-seed SEs and the bins a campaign lacks.
- :mod:`~specdesign.validate.surrogate`: a Gaussian-process surrogate of a campaign's DEL over
  its conditions, against the look-up table.

How seeds are pooled per wind speed (as fatigue adds up), what a relative change and a
reduction are, and the paired-seed standard errors: :mod:`~specdesign.validate.stats`.

Weibull mean (Table 2's "Mean" column): Σ w_i c_i with w_i = f(v_i)/Σ_j f(v_j), f the Weibull
pdf with k = 2.2, A = 11.29 m/s evaluated at the operating points. This reproduces the means
printed in the paper's Table 2 from its per-speed values (tested).

Campaign files and the command line (reading a TOML/JSON campaign, writing tables, CSV and
figures) live in :mod:`specdesign.cli`; this package imports neither matplotlib nor
:mod:`specdesign.plots` nor :mod:`loopshaping`.
"""
from __future__ import annotations

from ..openfast.series import OPENFAST_CHANNELS, series_from_openfast
from .campaign import check_campaign_step, check_plant_step, concat_campaigns, run_campaign
from .campaign_record import Campaign
from .lifetime_del import DEL_CHANNELS, LifetimeDEL, WindClimate, lifetime, weibull_bins, wind_climate
from .metrics import ACTUATOR_INDICATORS, INDICATORS, Indicators, indicators
from .openfast_campaign import OpenFASTRun, read_openfast_runs
from .prediction import LinearPrediction, closed_loop_response, linear_prediction, loop_plant, prediction_grid
from .stats import (WEIBULL_A, WEIBULL_K, PairedChange, paired_change, pool, resampled_se, seeds_from, weibull_weights,
                    welch_psd)
from .surrogate import (CONDITIONS, DelData, GPSurrogate, LookupTable, SurrogateComparison, SurrogatePrediction,
                        compare_surrogates, del_data, fit_gp, fit_lut)
from .tables import Acceptance, Table, acceptance, actuator_rows, linear_table3, table2, table3
from .volterra import VolterraPrediction, volterra_prediction, volterra_response

__all__ = [
    # stats
    "WEIBULL_K", "WEIBULL_A", "weibull_weights", "welch_psd", "pool", "resampled_se", "PairedChange", "paired_change",
    # indicators
    "INDICATORS", "ACTUATOR_INDICATORS", "Indicators", "indicators",
    # OpenFAST outputs (home: specdesign.openfast)
    "OPENFAST_CHANNELS", "series_from_openfast",
    # prediction
    "closed_loop_response", "prediction_grid", "LinearPrediction", "linear_prediction", "loop_plant",
    # volterra
    "volterra_response", "VolterraPrediction", "volterra_prediction",
    # campaign
    "Campaign", "run_campaign", "concat_campaigns", "seeds_from", "check_plant_step", "check_campaign_step",
    "OpenFASTRun", "read_openfast_runs",
    # surrogate
    "CONDITIONS", "DelData", "del_data", "SurrogatePrediction", "GPSurrogate", "fit_gp", "LookupTable", "fit_lut",
    "SurrogateComparison", "compare_surrogates",
    # tables
    "Table", "table2", "table3", "linear_table3", "Acceptance", "acceptance", "actuator_rows",
    # lifetime
    "DEL_CHANNELS", "WindClimate", "weibull_bins", "wind_climate", "LifetimeDEL", "lifetime",
]
