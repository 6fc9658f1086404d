"""The paper's Tables 2 and 3 and the acceptance of a design: the linear (and Volterra)
prediction of the tower-base DEL reduction against rainflow, with standard errors over
paired seeds."""
from __future__ import annotations

import csv
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fatigue import TOWER_M
from .campaign_record import Campaign
from .lifetime_del import lifetime
from .prediction import linear_prediction
from .stats import (
    WEIBULL_A,
    WEIBULL_K,
    paired_change,
    pool,
    resampled_se,
    weibull_weights,
)

__all__ = ["Table", "table2", "table3", "linear_table3", "Acceptance", "acceptance", "actuator_rows"]

_LABELS = {
    "gen_speed_sd": "Generator speed SD",
    "mean_power": "Mean power",
    "tower_del": "Tower base DEL",
    "pitch_sd": "Pitch activity (SD)",
    "pitch_rate_sd": "Pitch rate SD",
    "blade_del": "Blade root DEL (m = 10)",
    "pitch_travel": "Pitch travel per hour",
    "rate_limit_time": "Time at the pitch-rate limit",
}
#: The actuator's cost in the tables, absolute per controller: indicator → (row label, factor
#: from the campaign's SI value, format). Pitch in degrees as the tables show it
#: (:mod:`specdesign.plots.conventions`); the time at the rate limit as % of the record.
_ACTUATOR_ROWS = {
    "pitch_travel": ("pitch travel (deg/h)", 180.0 / math.pi, "{:.0f} deg/h"),
    "pitch_rate_sd": ("pitch-rate SD (deg/s)", 180.0 / math.pi, "{:.3f} deg/s"),
    "rate_limit_time": ("time at the pitch-rate limit (% of the record)", 100.0, "{:.2f} %"),
}


def _seed_mean(campaign: Campaign, name: str, ind: str) -> np.ndarray:
    """(W,) mean over the seeds of one controller's indicator (NaN seeds left out: a run
    stored before the indicator existed; all NaN: NaN)."""
    x = np.asarray(campaign.values[ind][campaign.index(name)], dtype=float)
    n = np.sum(~np.isnan(x), axis=-1)
    with np.errstate(invalid="ignore"):  # 0/0 where every seed is NaN: NaN, as wanted
        return np.nansum(x, axis=-1) / n


def actuator_rows(campaign: Campaign, names, weights=None) -> tuple[list, list]:
    """Rows of the actuator's cost of each controller: pitch travel (deg/h), pitch-rate SD
    (deg/s) and time at the pitch-rate limit (% of the record), seed means per wind speed and
    their ``weights``-weighted mean (NaN without weights).

    Parameters
    ----------
    campaign : Campaign
        The campaign.
    names : sequence of str
        Controllers, in row order.
    weights : array_like, optional
        (W,) weights of the Mean column (e.g. the Weibull pdf, normalised).

    Returns
    -------
    rows : list
        (label, values) pairs: per speed, then the mean.
    formats : list
        (label, fmt) pairs for :class:`Table`'s ``row_fmt``.
    """
    rows, fmts = [], []
    for ind, (label, factor, fmt) in _ACTUATOR_ROWS.items():
        for n in names:
            x = factor * _seed_mean(campaign, n, ind)
            mean = float(np.asarray(weights, dtype=float) @ x) if weights is not None else float("nan")
            rows.append((f"{n}: {label}", tuple(x) + (mean,)))
            fmts.append((f"{n}: {label}", fmt))
    return rows, fmts


@dataclass(frozen=True)
class Table:
    """A plain table, shown as Markdown in a notebook and written as Markdown or CSV.

    Parameters
    ----------
    title : str
        Title (bold in Markdown).
    columns : tuple of str
        Header strings: the row label's column, then one per value.
    rows : tuple
        (label, values) pairs, values as floats (NaN shown empty).
    fmt : str, default "{:.2f} %"
        Format of the values.
    note : str, default ""
        Text below the table.
    row_fmt : tuple, default ()
        (label, fmt) pairs overriding ``fmt`` for those rows (e.g. percentage points).
    marks : tuple, default ()
        Per value column, a word shown in place of NaN (e.g. "unstable").

    Examples
    --------
    >>> t = Table("t", ("Indicator", "19 m/s"), (("Reduction", (25.0,)),))
    >>> print(t.to_markdown().splitlines()[4])
    | Reduction | 25.00 % |
    """

    title: str
    columns: tuple
    rows: tuple
    fmt: str = "{:.2f} %"
    note: str = ""
    row_fmt: tuple = ()  # (label, fmt) pairs overriding ``fmt`` for those rows (e.g. pp)
    marks: tuple = ()

    def _cell(self, v, fmt=None, mark=""):
        return mark if v is None or (isinstance(v, float) and math.isnan(v)) else (fmt or self.fmt).format(v)

    def to_markdown(self) -> str:
        """The table as Markdown (title, header, rows, note).

        Returns
        -------
        str
            Markdown text ending with a newline.
        """
        head = "| " + " | ".join(self.columns) + " |"
        sep = "|" + "|".join("---" for _ in self.columns) + "|"
        fmts = dict(self.row_fmt)
        marks = tuple(self.marks) + ("",) * (len(self.columns) - 1 - len(self.marks))
        body = ["| " + " | ".join([label] + [self._cell(float(v), fmts.get(label), mk) for v, mk in zip(vals, marks)]) + " |"
                for label, vals in self.rows]
        text = [f"**{self.title}**", "", head, sep, *body]
        if self.note:
            text += ["", self.note]
        return "\n".join(text) + "\n"

    _repr_markdown_ = to_markdown

    def to_csv(self, path) -> Path:
        """Write the table (values as plain numbers, NaN empty) as CSV.

        Parameters
        ----------
        path : str or os.PathLike
            File to write.

        Returns
        -------
        pathlib.Path
            The path written.
        """
        path = Path(path)
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(self.columns)
            for label, vals in self.rows:
                w.writerow([label] + ["" if math.isnan(float(v)) else repr(float(v)) for v in vals])
        return path

    def values(self) -> np.ndarray:
        """The table body as numbers.

        Returns
        -------
        numpy.ndarray
            (n_rows, n_columns − 1) floats.
        """
        return np.array([[float(v) for v in vals] for _, vals in self.rows])


def _speed_columns(vs):
    return tuple(["Indicator"] + [f"{v:g} m/s" for v in vs] + ["Mean"])


def _unstable_marks(campaign, *names):
    """Per speed column (+ Mean): "unstable" where any of the controllers is (the Mean too
    when any speed is: its NaN is theirs, not a missing number)."""
    bad = np.any(campaign.unstable[[campaign.index(n) for n in names]], axis=0)
    return tuple("unstable" if b else "" for b in bad) + ("unstable" if np.any(bad) else "",)


def table2(campaign: Campaign, designed: str, baseline: str, *, k: float = WEIBULL_K, scale: float = WEIBULL_A,
           climate=None) -> Table:
    """The paper's Table 2: relative change (%) of each indicator, designed vs baseline.

    With a wind ``climate`` the table gains a "Lifetime" column: each indicator pooled over the
    time in the covered bins (bin b's share p_b/Σp) the way it adds up, as the seeds of one speed
    are (:func:`~specdesign.validate.pool`), then compared: the tower-base DEL's row is the
    lifetime DEL change of :func:`~specdesign.validate.lifetime` (damage-weighted), the mean
    power's the change of the energy Σ_b p_b·P̄_b, a standard deviation's the change of
    √(Σ_b p_b·mean_s SD²/Σp) (defined where one bin's SD is 0 for both controllers, as the pitch's
    below rated). The note gives the lifetime DEL change's standard error and names the climate's
    bins the campaign did not simulate.

    Parameters
    ----------
    campaign : Campaign
        A campaign holding both controllers.
    designed, baseline : str
        Controller names.
    k : float, default WEIBULL_K
        Weibull shape of the Mean column's weights (:func:`~specdesign.validate.weibull_weights`).
    scale : float, default WEIBULL_A
        Weibull scale (m/s).
    climate : WindClimate or tuple, optional
        Wind-speed bins and their probabilities (:func:`~specdesign.validate.weibull_bins`,
        :func:`~specdesign.validate.wind_climate`, or a (centres, probabilities) pair) whose
        centres include the campaign's wind speeds: adds the "Lifetime" column.

    Returns
    -------
    Table
        One row per indicator, one column per wind speed, the Weibull-weighted mean, and with
        ``climate`` the lifetime change.

    Raises
    ------
    ValueError
        A controller name that is not in the campaign; with ``climate``, as
        :func:`~specdesign.validate.lifetime` (e.g. a campaign wind speed that is no bin centre).
    """
    w = weibull_weights(campaign.wind_speeds, k, scale)
    life = None
    if climate is not None:
        life = lifetime(campaign, climate, controllers=(baseline, designed), m=campaign.m)
    rows = []
    for ind in ("gen_speed_sd", "mean_power", "tower_del", "pitch_sd", "pitch_rate_sd", "pitch_travel"):
        with np.errstate(invalid="ignore", divide="ignore"):  # 0/0: the pitch held at fine pitch by both (below rated), shown empty
            ch = campaign.change(designed, baseline, ind).change
        row = tuple(ch) + (float(w @ ch),)
        if life is not None:
            row += (_lifetime_cell(campaign, designed, baseline, ind, life),)
        rows.append((_LABELS[ind], row))
    # the time at the rate limit is a fraction, often 0 for the baseline: its change in
    # percentage points of the record, not relative
    diff = 100.0 * (_seed_mean(campaign, designed, "rate_limit_time") - _seed_mean(campaign, baseline, "rate_limit_time"))
    row = tuple(diff) + (float(w @ diff),)
    if life is not None:
        row += (float(life.probabilities @ diff / life.probabilities.sum()),)
    rows.append((_LABELS["rate_limit_time"], row))
    actuator, fmts = actuator_rows(campaign, (designed, baseline), w)
    rows += [(label, vals + ((float("nan"),) if life is not None else ())) for label, vals in actuator]
    note = (f"Relative change 100·(X_{designed}/X_{baseline} − 1), negative: lower than {baseline} (Table 3 gives "
            f"the DEL's as a reduction, positive), over {campaign.seeds.size} paired seeds of "
            f"{campaign.duration:g} s; DEL with m = {campaign.m:g}, 1 Hz. Mean: weighted by the Weibull pdf "
            f"(k = {k}, A = {scale} m/s) at the operating points, normalised. Time at the pitch-rate limit: "
            f"difference in percentage points of the record. Below: the actuator's cost of each controller, seed "
            f"means (pitch travel Σ|Δβ| per hour, counted on the record's {campaign.dt:g} s samples).")
    marks = _unstable_marks(campaign, designed, baseline)
    columns = _speed_columns(campaign.wind_speeds)
    if life is not None:
        columns += ("Lifetime",)
        marks += (marks[-1],)
        note += (f" Lifetime ({life.climate}; covered probability {life.covered_probability:.4g}): tower-base DEL "
                 f"change of the lifetime DEL {life.change[1, 0]:+.2f} ± {life.change_se[1, 0]:.2f} % (SE, "
                 f"{life.method}); mean power: change of the energy Σ p_b·P̄_b; standard deviations: change of "
                 "√(Σ p_b·mean SD² / Σ p_b).")
        if life.missing_speeds.size:
            note += (f" MISSING bins (not simulated, excluded): {', '.join(f'{x:g}' for x in life.missing_speeds)} "
                     f"m/s, probability {float(life.missing_probability.sum()):.4g}.")
    return Table(title=f"Table 2: change of the indicators, {designed} vs {baseline}", columns=columns,
                 rows=tuple(rows), note=note, marks=marks, row_fmt=((_LABELS["rate_limit_time"], "{:+.2f} pp"), *fmts))


def _lifetime_cell(campaign, designed, baseline, ind, life):
    """The Lifetime column's entry of one indicator (see :func:`table2`)."""
    if ind == "tower_del":
        return float(life.change[1, 0])
    # pooled over the covered time as each adds up (a bin's share of it is p_b): the energy for
    # the power, the travel for the pitch travel, √(mean variance) for a standard deviation; lifetime() keeps the campaign's order
    p = life.probabilities / life.probabilities.sum()
    x = [np.asarray(campaign.values[ind][campaign.index(c)], dtype=float) for c in (designed, baseline)]
    if ind in ("mean_power", "pitch_travel"):  # rates: the time-weighted mean
        des, base = (p @ a.mean(axis=-1) for a in x)
    else:
        des, base = (np.sqrt(p @ (a**2).mean(axis=-1)) for a in x)
    return float(100.0 * (des / base - 1.0))


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Acceptance:
    """Linear prediction vs rainflow of the tower-base DEL reduction, per wind speed.

    With a linear twin (``run_campaign(linear_twin=True)``), the deviation splits exactly into
    ``spectral_deviation`` (the spectral method against rainflow on the linearised model, same
    seeds) and ``nonlinear_deviation`` (the plant's nonlinearity; small SE because both runs
    saw the same wind); all NaN without a linear twin. With a Volterra prediction
    (``run_campaign(volterra=k)``) the ``volterra*`` fields compare it with rainflow; NaN
    (order 0) without one.

    Parameters
    ----------
    wind_speeds : numpy.ndarray
        (W,) wind speeds (m/s).
    predicted : numpy.ndarray
        100·(1 − DEL_pred,des/DEL_pred,base) from Dirlik on |T|²S_W (%).
    rainflow : numpy.ndarray
        100·(1 − DEL_rf,des/DEL_rf,base), seeds pooled by damage, paired (%).
    deviation : numpy.ndarray
        Rainflow − predicted (percentage points).
    se : numpy.ndarray
        Standard error of the deviation over paired seeds (pp; the prediction has none).
    n_seeds : int
        Number of paired seeds S.
    method : str
        SE method ("jackknife" or "bootstrap").
    rainflow_linear : numpy.ndarray
        Rainflow reduction on the linearised model (%).
    spectral_deviation : numpy.ndarray
        Rainflow_linear − predicted (pp).
    se_spectral : numpy.ndarray
        Its standard error (pp).
    nonlinear_deviation : numpy.ndarray
        Rainflow − rainflow_linear (pp).
    se_nonlinear : numpy.ndarray
        Its standard error (pp).
    volterra : numpy.ndarray
        Reduction by rainflow on the order-``volterra_order`` Volterra series over the same
        wind (%).
    volterra_deviation : numpy.ndarray
        Rainflow − volterra (pp).
    se_volterra : numpy.ndarray
        Its standard error over paired seeds (pp).
    volterra_order : int, default 0
        Order of the Volterra prediction (0: none).
    """

    wind_speeds: np.ndarray
    predicted: np.ndarray
    rainflow: np.ndarray
    deviation: np.ndarray
    se: np.ndarray
    n_seeds: int
    method: str
    rainflow_linear: np.ndarray
    spectral_deviation: np.ndarray
    se_spectral: np.ndarray
    nonlinear_deviation: np.ndarray
    se_nonlinear: np.ndarray
    volterra: np.ndarray
    volterra_deviation: np.ndarray
    se_volterra: np.ndarray
    volterra_order: int = 0

    def passes(self, tolerance_pp: float = 1.0, against: str = "linear") -> np.ndarray:
        """Where the prediction is within a tolerance of rainflow.

        Parameters
        ----------
        tolerance_pp : float, default 1.0
            Tolerance on |rainflow − prediction| (percentage points).
        against : {"linear", "volterra"}, default "linear"
            The linear prediction (Dirlik on |T|²S_W) or the Volterra series (same seeds).

        Returns
        -------
        numpy.ndarray
            (W,) bool.

        Raises
        ------
        ValueError
            An unknown ``against``, or "volterra" without a Volterra prediction.
        """
        if against not in ("linear", "volterra"):
            raise ValueError(f"against={against!r} must be 'linear' or 'volterra'")
        if against == "volterra" and not self.volterra_order:
            raise ValueError("against='volterra' needs a campaign run with run_campaign(volterra=k)")
        dev = self.deviation if against == "linear" else self.volterra_deviation
        return np.abs(dev) <= tolerance_pp


def _paired_gap(values, twin, i, j, m, method):
    """(reduction on ``twin`` − reduction on ``values``, pp, and its SE): the rainflow
    reduction of controller i vs j on two evaluations of the same seeds."""
    a, b, al, bl = values[i], values[j], twin[i], twin[j]

    def gap(idx):
        return 100.0 * (pool("tower_del", al[:, idx], m) / pool("tower_del", bl[:, idx], m)
                        - pool("tower_del", a[:, idx], m) / pool("tower_del", b[:, idx], m))

    return gap(slice(None)), resampled_se(gap, a.shape[1], a.shape[0], method)


def acceptance(campaign: Campaign, designed: str, baseline: str, *, method: str = "jackknife") -> Acceptance:
    """Linear-prediction vs rainflow reduction of the tower-base DEL, per wind speed.

    Their deviation (pp) and its standard error over paired seeds; split into the spectral
    and the nonlinear part when the campaign has a linear twin, and compared with the
    Volterra prediction when it has one.

    Parameters
    ----------
    campaign : Campaign
        A campaign holding both controllers.
    designed, baseline : str
        Controller names.
    method : {"jackknife", "bootstrap"}, default "jackknife"
        Standard-error method (:func:`~specdesign.validate.paired_change`).

    Returns
    -------
    Acceptance
        Predicted and rainflow reductions, deviations and standard errors.

    Raises
    ------
    ValueError
        A controller name that is not in the campaign, or an unknown ``method``.
    """
    i, j = campaign.index(designed), campaign.index(baseline)
    pred = 100.0 * (1.0 - campaign.predicted_del[i] / campaign.predicted_del[j])
    ch = campaign.change(designed, baseline, "tower_del", method=method)
    rf = -ch.change
    nan = np.full(rf.shape, np.nan)
    rfl, dsp, sesp, dnl, senl = nan, nan, nan, nan, nan
    vol, dvol, sevol = nan, nan, nan
    values = campaign.values["tower_del"]
    if campaign.linear_values:
        lin = paired_change(campaign.linear_values["tower_del"][i], campaign.linear_values["tower_del"][j], "tower_del",
                            m=campaign.m, wind_speeds=campaign.wind_speeds, method=method)
        rfl, sesp = -lin.change, lin.se
        dsp = rfl - pred
        dnl, senl = _paired_gap(values, campaign.linear_values["tower_del"], i, j, campaign.m, method)
    if campaign.volterra_values:
        vc = paired_change(campaign.volterra_values["tower_del"][i], campaign.volterra_values["tower_del"][j],
                           "tower_del", m=campaign.m, wind_speeds=campaign.wind_speeds, method=method)
        vol = -vc.change
        dvol, sevol = _paired_gap(values, campaign.volterra_values["tower_del"], i, j, campaign.m, method)
    return Acceptance(wind_speeds=campaign.wind_speeds, predicted=pred, rainflow=rf, deviation=rf - pred, se=ch.se,
                      n_seeds=ch.n_seeds, method=method, rainflow_linear=rfl, spectral_deviation=dsp, se_spectral=sesp,
                      nonlinear_deviation=dnl, se_nonlinear=senl, volterra=vol, volterra_deviation=dvol,
                      se_volterra=sevol, volterra_order=campaign.volterra_order)


def table3(campaign: Campaign, designed: str, baseline: str, *, promised: Mapping | None = None,
           method: str = "jackknife") -> Table:
    """The paper's Table 3: tower-base fatigue (DEL) reduction, promised, predicted and by rainflow.

    Rows: the reduction promised by the specification (when given), the linear prediction,
    the rainflow evaluation, the |deviation| and its SE; with a linear twin the split of the
    signed deviation into the spectral method's and the nonlinear part, with a Volterra
    prediction its reduction and deviation. Mean column: plain mean of the |deviation| (as in
    the paper).

    Parameters
    ----------
    campaign : Campaign
        A campaign holding both controllers.
    designed, baseline : str
        Controller names.
    promised : mapping, optional
        Wind speed (m/s) → promised DEL reduction (%).
    method : {"jackknife", "bootstrap"}, default "jackknife"
        Standard-error method.

    Returns
    -------
    Table
        The rows above, one column per wind speed and the Mean.

    Raises
    ------
    ValueError
        A controller name that is not in the campaign, or an unknown ``method``.
    """
    acc = acceptance(campaign, designed, baseline, method=method)
    nan = float("nan")
    rows = []
    if promised is not None:
        prom = {float(k): float(v) for k, v in promised.items()}
        rows.append(("Specification", tuple(prom.get(float(v), nan) for v in acc.wind_speeds) + (nan,)))
    dev = np.abs(acc.deviation)
    rows += [
        ("Linear prediction", tuple(acc.predicted) + (nan,)),
        ("Rainflow evaluation", tuple(acc.rainflow) + (nan,)),
        ("Estimation deviation", tuple(dev) + (float(np.mean(dev)),)),
        (f"Standard error ({method}, paired seeds)", tuple(acc.se) + (nan,)),
    ]
    pp = [("Estimation deviation", "{:.2f} pp"), (f"Standard error ({method}, paired seeds)", "{:.2f} pp")]
    extra = []  # (row label, per-speed values, format or None for the table's default)
    if campaign.linear_values:  # the split of the signed deviation: spectral method + plant nonlinearity
        extra += [
            ("Rainflow evaluation, linearised model", acc.rainflow_linear, None),
            ("Spectral-method part (linearised − prediction)", acc.spectral_deviation, "{:+.2f} pp"),
            ("Spectral-method part: standard error", acc.se_spectral, "{:.2f} pp"),
            ("Nonlinear part (rainflow − linearised)", acc.nonlinear_deviation, "{:+.2f} pp"),
            ("Nonlinear part: standard error", acc.se_nonlinear, "{:.2f} pp"),
        ]
    if campaign.volterra_values:  # the prediction that includes the aerodynamic nonlinearity
        extra += [
            (f"Volterra prediction (order {acc.volterra_order}, rainflow, same seeds)", acc.volterra, None),
            ("Deviation from the Volterra prediction", acc.volterra_deviation, "{:+.2f} pp"),
            ("Deviation from the Volterra prediction: standard error", acc.se_volterra, "{:.2f} pp"),
        ]
    for name, vals, fmt in extra:
        rows.append((name, tuple(vals) + (nan,)))
        if fmt:
            pp.append((name, fmt))
    # what the reduction costs the pitch actuator, beside it
    actuator, fmts = actuator_rows(campaign, (designed, baseline))
    rows += actuator
    pp += fmts
    return Table(
        title=f"Table 3: tower-base fatigue (DEL) reduction, {designed} vs {baseline}",
        columns=_speed_columns(campaign.wind_speeds), rows=tuple(rows),
        note=f"Reduction 100·(1 − DEL_{designed}/DEL_{baseline}), positive: lower than {baseline} (Table 2 gives "
             f"it as a change, negative); {acc.n_seeds} paired seeds of {campaign.duration:g} s; DEL with "
             f"m = {campaign.m:g} at 1 Hz; linear prediction by Dirlik on |T|²S_W; deviation in percentage points; "
             "below, the actuator's cost of each controller (seed means; pitch travel Σ|Δβ| per hour).",
        row_fmt=tuple(pp),
        marks=_unstable_marks(campaign, designed, baseline),
    )


def _at(controller, v, what):
    if isinstance(controller, Mapping):
        hit = [c for k, c in controller.items() if math.isclose(float(k), v, rel_tol=1e-9)]
        if not hit:
            raise ValueError(f"{what} has no controller for {v:g} m/s (its speeds: {sorted(float(k) for k in controller)})")
        return hit[0]
    return controller


def linear_table3(model, designed, wind_speeds, *, baseline=None, promised: Mapping | None = None, m: float = TOWER_M,
                  turbulence_class: str = "B", name: str = "designed") -> Table:
    """The linear rows of the paper's Table 3, without simulation: promised and predicted DEL reduction.

    For any model the design loop takes, a :class:`specdesign.openfast.LinearTurbine` too:
    the reduction of the tower-base DEL that :func:`~specdesign.validate.linear_prediction`
    (Dirlik on |T|²S_W) predicts for ``designed`` against ``baseline``, per wind speed, and
    the specification's promise when given. The rainflow rows need simulations
    (:func:`table3` on a :func:`~specdesign.validate.run_campaign`).

    Parameters
    ----------
    model : TurbineModel or LinearTurbine
        The turbine.
    designed : controller or mapping
        A controller with a linear form, or wind speed (m/s) → controller (one design per speed).
    wind_speeds : sequence of float
        Columns (m/s).
    baseline : controller or mapping, optional
        Default the model's baseline (:func:`specdesign.spec.baseline_controller`).
    promised : mapping, optional
        Wind speed (m/s) → promised DEL reduction (%).
    m : float, default 4.0
        Wöhler exponent of the DEL (-).
    turbulence_class : {"A", "B", "C"}, default "B"
        IEC NTM class of the wind spectrum.
    name : str, default "designed"
        The designed controller's name in the title.

    Returns
    -------
    Table
        Rows "Specification" (when ``promised``) and "Linear prediction" (%), Mean column.

    Raises
    ------
    ValueError
        A speed without a controller in a mapping, or a controller that destabilises the loop.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw
    >>> from specdesign.rosco import rosco_baseline
    >>> model = iea15mw()
    >>> t = linear_table3(model, rosco_baseline(model, 19.0), [19.0])   # the baseline against itself
    >>> float(t.values()[0, 0])
    0.0
    """
    from ..spec import baseline_controller
    vs = [float(v) for v in np.atleast_1d(np.asarray(wind_speeds, float))]
    pred = []
    for v in vs:
        c0 = baseline_controller(model, v) if baseline is None else _at(baseline, v, "baseline")
        d1 = linear_prediction(model, _at(designed, v, "designed"), v, m=m, turbulence_class=turbulence_class).del_
        d0 = linear_prediction(model, c0, v, m=m, turbulence_class=turbulence_class).del_
        pred.append(100.0 * (1.0 - d1 / d0))
    rows = []
    if promised is not None:
        prom = {float(k): float(x) for k, x in promised.items()}
        vals = [prom.get(v, float("nan")) for v in vs]
        rows.append(("Specification", tuple(vals) + (float(np.mean(vals)),)))
    rows.append(("Linear prediction", tuple(pred) + (float(np.mean(pred)),)))
    return Table(title=f"Table 3 (linear rows): tower-base DEL reduction, {name} vs baseline, "
                       f"{getattr(model, 'name', 'model')}",
                 columns=_speed_columns(vs), rows=tuple(rows),
                 note=f"Linear prediction by Dirlik on |T|²S_W (IEC class {turbulence_class}), m = {m:g}, 1 Hz.")
