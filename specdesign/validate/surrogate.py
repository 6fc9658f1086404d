"""A Gaussian-process surrogate of a campaign's DEL over its conditions, with the look-up table as comparator.

The conditions of a campaign are its mean wind speeds, optionally the turbulence intensity
(one campaign per IEC turbulence class: :func:`run_campaign` sets the wind's turbulence by
``turbulence_class``, so a campaign per class gives the intensity axis) and optionally a
controller parameter (a family of controllers in one campaign, each named with its value,
e.g. the ATD gain). At every condition the campaign holds one value per seed.

- :func:`del_data` gathers the per-run values of one indicator and controller (or family).
- :func:`fit_gp` fits scikit-learn's ``GaussianProcessRegressor`` to the per-run values:
  inputs scaled to [0, 1] over the training conditions, outputs standardised
  (``normalize_y``), the kernel C·k(anisotropic Matérn ν = 5/2 or RBF) + white noise, the
  white noise being the seed-to-seed scatter. It predicts the expected per-run value (the
  mean over seeds) with its standard deviation.
- :func:`fit_lut`: the look-up-table method, linear interpolation of the per-condition seed
  mean (multilinear on a full grid, on a Delaunay triangulation otherwise).
- :func:`compare_surrogates`: both fitted on the training conditions, RMSE and MAE on
  held-out ones (the truth there: the seed mean of the simulated runs), as the Gaussian-process
  study of damage-equivalent loads under yaw misalignment does (its Table 3, blade-root edgewise
  moment: RMSE 22.69-50.09 % for the LUT against 5.45-15.19 % for the GP at 5-9 m/s, differences
  of 17.24-34.90 percentage points of RMSE, not relative improvements).

The target is the arithmetic seed mean of the per-run value, not the fatigue-pooled DEL
(mean DEL^m)^{1/m} of :func:`~specdesign.validate.pool`: a surrogate's prediction at a new
wind speed weighted by :func:`~specdesign.validate.weibull_weights` fills the lifetime
weighting between the simulated bins. scikit-learn is an optional dependency
(``pip install specdesign[surrogate]``).
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..wind import TURBULENCE_CLASSES
from .campaign_record import Campaign
from .metrics import INDICATORS

__all__ = ["CONDITIONS", "DelData", "del_data", "SurrogatePrediction", "GPSurrogate", "fit_gp", "LookupTable",
           "fit_lut", "SurrogateComparison", "compare_surrogates"]

#: names of the condition axes, in the order :func:`del_data` stacks them.
CONDITIONS = ("wind_speed", "turbulence_intensity", "parameter")


def _sklearn():
    try:
        from sklearn import gaussian_process
    except ImportError as err:
        raise ImportError("specdesign.validate.surrogate needs scikit-learn: pip install 'specdesign[surrogate]'") from err
    return gaussian_process


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class DelData:
    """Per-run values of one indicator at distinct campaign conditions.

    Parameters
    ----------
    names : tuple of str
        Condition axes (a subset of :data:`CONDITIONS`, in that order).
    conditions : numpy.ndarray
        (N, d) distinct conditions (wind speed m/s, turbulence intensity 1, parameter in its unit).
    values : numpy.ndarray
        (N, S) per-run values (units of the indicator, e.g. N·m for ``tower_del``).
    indicator : str
        The indicator (:data:`~specdesign.validate.INDICATORS`).
    controller : str
        The controller, or the controllers of a family joined by "|".
    """

    names: tuple
    conditions: np.ndarray
    values: np.ndarray
    indicator: str
    controller: str


def _turbulence_key(key) -> float:
    if isinstance(key, str):
        if key not in TURBULENCE_CLASSES:
            raise ValueError(f"campaigns key {key!r} must be an IEC turbulence class {sorted(TURBULENCE_CLASSES)} "
                             "or a turbulence intensity (a float)")
        return TURBULENCE_CLASSES[key]
    ti = float(key)
    if not 0.0 < ti < 1.0:
        raise ValueError(f"campaigns key {key!r}: a turbulence intensity must lie in (0, 1), e.g. 0.14 for class B")
    return ti


def del_data(campaigns, controller, indicator: str = "tower_del") -> DelData:
    """Gather the per-run values of one indicator over the conditions of campaigns.

    Parameters
    ----------
    campaigns : Campaign or mapping
        One :class:`~specdesign.validate.Campaign`, or turbulence → Campaign where the key is
        an IEC turbulence class ("A+", "A", "B", "C": its reference intensity I_ref, the one
        ``run_campaign(turbulence_class=...)`` used) or the intensity itself; then
        ``turbulence_intensity`` is a condition. All campaigns must share their seeds count.
    controller : str or mapping
        A controller name, or a family: name → parameter value (then ``parameter`` is a
        condition, e.g. {"atd_0.5": 0.5, "atd_1": 1.0}).
    indicator : str, default "tower_del"
        One of :data:`~specdesign.validate.INDICATORS`.

    Returns
    -------
    DelData
        Conditions (wind speed, then turbulence intensity, then parameter, as present) and
        the (N, S) per-run values.

    Raises
    ------
    ValueError
        An unknown indicator or controller (the message lists the campaign's), a NaN value
        (an unstable or diverged run: leave that wind speed or controller out), campaigns
        with different numbers of seeds, or a repeated condition.
    TypeError
        ``campaigns`` is neither a Campaign nor a non-empty mapping of them.
    """
    if indicator not in INDICATORS:
        raise ValueError(f"indicator={indicator!r} must be one of {INDICATORS}")
    if isinstance(campaigns, Campaign):
        camps, with_ti = {None: campaigns}, False
    elif isinstance(campaigns, Mapping) and campaigns and all(isinstance(c, Campaign) for c in campaigns.values()):
        camps, with_ti = {_turbulence_key(k): c for k, c in campaigns.items()}, True
    else:
        raise TypeError("campaigns must be a validate.Campaign or a non-empty mapping {turbulence class or "
                        "intensity: Campaign}")
    family = isinstance(controller, Mapping)
    members = dict(controller) if family else {controller: None}
    if not members:
        raise ValueError("controller must be a name or a non-empty mapping {name: parameter value}")
    rows, vals = [], []
    for ti, camp in camps.items():
        for name, p in members.items():
            if name not in camp.controllers:
                raise ValueError(f"controller {name!r} not in the campaign's controllers {camp.controllers}: "
                                 "pass one of these")
            block = np.asarray(camp.values[indicator][camp.controllers.index(name)], dtype=float)  # (W, S)
            bad = ~np.isfinite(block).all(axis=1)
            if bad.any():
                raise ValueError(f"controller {name!r} has NaN {indicator} at {camp.wind_speeds[bad].tolist()} m/s "
                                 "(unstable or diverged runs): leave these wind speeds or this controller out")
            for v, row in zip(camp.wind_speeds, block):
                rows.append([float(v)] + ([ti] if with_ti else []) + ([float(p)] if family else []))
                vals.append(row)
    if len({len(r) for r in vals}) != 1:
        raise ValueError("the campaigns have different numbers of seeds: run them with the same seeds")
    cond = np.asarray(rows, dtype=float)
    if np.unique(cond, axis=0).shape[0] != cond.shape[0]:
        raise ValueError("a condition repeats (the same wind speed, turbulence and parameter twice): "
                         "give each controller of a family a distinct parameter value")
    names = ("wind_speed",) + (("turbulence_intensity",) if with_ti else ()) + (("parameter",) if family else ())
    return DelData(names=names, conditions=cond, values=np.asarray(vals, dtype=float), indicator=indicator,
                   controller="|".join(members))


def _training(conditions, values):
    """(N, d) conditions and (N, S) values, checked."""
    x = np.asarray(conditions, dtype=float)
    x = x[:, None] if x.ndim == 1 else x
    y = np.asarray(values, dtype=float)
    y = y[:, None] if y.ndim == 1 else y
    if x.ndim != 2 or y.ndim != 2 or x.shape[0] != y.shape[0]:
        raise ValueError(f"conditions {np.shape(conditions)} must be (N,) or (N, d) and values {np.shape(values)} "
                         "(N,) or (N, S) with the same N")
    if not np.isfinite(x).all():
        raise ValueError("conditions must be finite")
    if not np.isfinite(y).all():
        raise ValueError("values contain NaN or inf (unstable or diverged runs?): leave those conditions out")
    if np.unique(x, axis=0).shape[0] != x.shape[0]:
        raise ValueError("conditions must be distinct (put the seeds of a condition in one row of values)")
    if x.shape[0] < 3:
        raise ValueError(f"{x.shape[0]} conditions: a surrogate needs at least 3 distinct training conditions")
    for j in range(x.shape[1]):
        if np.unique(x[:, j]).size < 2:
            raise ValueError(f"condition axis {j} takes one value ({x[0, j]}) only: drop that axis or add conditions")
    return x, y


def _query(x, d: int) -> np.ndarray:
    q = np.asarray(x, dtype=float)
    q = q.reshape(-1, 1) if (q.ndim <= 1 and d == 1) else np.atleast_2d(q)
    if q.shape[1] != d or not np.isfinite(q).all():
        raise ValueError(f"conditions {np.shape(x)} must be finite, (k, {d}) (or (k,) for one axis)")
    return q


@dataclass(frozen=True)
class SurrogatePrediction:
    """A GP surrogate's prediction at some conditions.

    Parameters
    ----------
    mean : numpy.ndarray
        (k,) predicted mean over seeds (the indicator's unit).
    std : numpy.ndarray
        (k,) standard deviation of that mean (the GP's latent uncertainty, same unit).
    noise_sd : float
        Seed-to-seed standard deviation of one run (the fitted white noise, same unit): an
        average of S new seeds has SD √(std² + noise_sd²/S) about ``mean``.
    """

    mean: np.ndarray
    std: np.ndarray
    noise_sd: float


@dataclass(frozen=True, eq=False)
class GPSurrogate:
    """A fitted Gaussian-process surrogate (:func:`fit_gp`).

    Parameters
    ----------
    names : tuple of str
        Condition axes.
    lower, upper : numpy.ndarray
        (d,) range of the training conditions; inputs are scaled to (x − lower)/(upper − lower).
    y_scale : float
        SD of the training values, the unit of the regressor's standardised outputs.
    regressor : sklearn.gaussian_process.GaussianProcessRegressor
        The fitted regressor (on scaled inputs, ``normalize_y=True``).
    """

    names: tuple
    lower: np.ndarray
    upper: np.ndarray
    y_scale: float
    regressor: object = field(repr=False)

    def scale(self, conditions) -> np.ndarray:
        """Scale conditions the way the regressor saw them.

        Parameters
        ----------
        conditions : array_like
            (k, d) conditions (or (k,) with one axis), in their units.

        Returns
        -------
        numpy.ndarray
            (k, d) scaled conditions, 0 and 1 at the training range's ends.
        """
        return (_query(conditions, self.lower.size) - self.lower) / (self.upper - self.lower)

    @property
    def noise_sd(self) -> float:
        """float: Fitted seed-to-seed SD of one run (the indicator's unit)."""
        return float(np.sqrt(self.regressor.kernel_.k2.noise_level) * self.y_scale)

    def predict(self, conditions) -> SurrogatePrediction:
        """Predict the seed mean and its uncertainty at conditions.

        Parameters
        ----------
        conditions : array_like
            (k, d) conditions (or (k,) with one axis), in their units (e.g. wind speeds in m/s
            between simulated bins). Outside the training range the GP extrapolates towards
            its prior mean with a growing ``std``.

        Returns
        -------
        SurrogatePrediction
            Mean, its SD and the per-run noise SD.

        Raises
        ------
        ValueError
            Conditions of the wrong shape or not finite.
        """
        mean, sd = self.regressor.predict(self.scale(conditions), return_std=True)
        noise = self.noise_sd
        # the regressor's SD includes the white noise of one run; rounding may leave -1e-16
        latent = np.sqrt(np.maximum(np.asarray(sd, float) ** 2 - noise ** 2, 0.0))
        return SurrogatePrediction(mean=np.asarray(mean, float).ravel(), std=latent, noise_sd=noise)


def fit_gp(conditions, values, *, names=None, kernel: str = "matern", n_restarts: int = 5,
           random_state: int = 0) -> GPSurrogate:
    """Fit a Gaussian process to per-run values over conditions.

    Kernel: ConstantKernel(1, (1e-3, 1e3)) · k(scaled x) + WhiteKernel(0.1, (1e-6, 10)) with k
    an anisotropic Matérn (ν = 5/2) or RBF, length scales 1 in (g, 1e2) per axis, g the
    smallest gap between the axis's training values (scaled, at least 1e-2); the
    marginal likelihood is maximised by L-BFGS-B from the initial values and ``n_restarts``
    random ones (``random_state``).

    Parameters
    ----------
    conditions : array_like
        (N,) or (N, d) distinct training conditions, each axis with at least two values.
    values : array_like
        (N,) or (N, S) per-run values at each condition (every run is a training point).
    names : tuple of str, optional
        Condition axes (default "x0", "x1", …).
    kernel : {"matern", "rbf"}, default "matern"
        Stationary kernel of the conditions.
    n_restarts : int, default 5
        Random restarts of the hyper-parameter optimiser.
    random_state : int, default 0
        Seed of the restarts.

    Returns
    -------
    GPSurrogate
        The fitted surrogate.

    Raises
    ------
    ValueError
        Fewer than 3 conditions, an axis with one value, repeated conditions, NaN values, an
        unknown kernel or a negative ``n_restarts``.
    ImportError
        scikit-learn is missing.

    Examples
    --------
    >>> v = np.arange(12.0, 25.0, 2.0)
    >>> gp = fit_gp(v, np.c_[v, v + 0.1])  # two seeds, 0.1 apart, on a line
    >>> bool(abs(gp.predict([19.0]).mean[0] - 19.05) < 0.01)
    True
    """
    x, y = _training(conditions, values)
    if kernel not in ("matern", "rbf"):
        raise ValueError(f"kernel={kernel!r} must be 'matern' or 'rbf'")
    if isinstance(n_restarts, bool) or not isinstance(n_restarts, (int, np.integer)) or n_restarts < 0:
        raise ValueError(f"n_restarts={n_restarts!r} must be an integer ≥ 0")
    names = tuple(names) if names is not None else tuple(f"x{j}" for j in range(x.shape[1]))
    if len(names) != x.shape[1]:
        raise ValueError(f"names {names} must name the {x.shape[1]} condition axes")
    gpm = _sklearn()
    k = gpm.kernels
    lo, hi = x.min(axis=0), x.max(axis=0)
    ls = np.ones(x.shape[1])
    # a length scale below the gap between training values is not identified by the data:
    # the GP would fall back to its mean between bins, worse than the table it replaces
    gaps = [np.diff(np.unique((x[:, j] - lo[j]) / (hi[j] - lo[j]))).min() for j in range(x.shape[1])]
    bounds = np.array([[max(g, 1e-2), 1e2] for g in gaps])
    base = (k.Matern(ls, bounds, nu=2.5) if kernel == "matern" else k.RBF(ls, bounds))
    kern = k.ConstantKernel(1.0, (1e-3, 1e3)) * base + k.WhiteKernel(0.1, (1e-6, 10.0))
    s = y.shape[1]
    xs = np.repeat((x - lo) / (hi - lo), s, axis=0)
    reg = gpm.GaussianProcessRegressor(kern, normalize_y=True, n_restarts_optimizer=int(n_restarts),
                                       random_state=random_state)
    reg.fit(xs, y.ravel())
    # normalize_y divides by this same population SD (ddof 0)
    return GPSurrogate(names=names, lower=lo, upper=hi, y_scale=float(np.std(y.ravel())), regressor=reg)


@dataclass(frozen=True, eq=False)
class LookupTable:
    """The look-up-table method: linear interpolation of the per-condition seed mean (:func:`fit_lut`).

    Parameters
    ----------
    names : tuple of str
        Condition axes.
    conditions : numpy.ndarray
        (N, d) table conditions.
    mean : numpy.ndarray
        (N,) seed mean at each.
    grid : bool
        The conditions form a full grid (multilinear interpolation), else Delaunay triangles.
    interpolant : callable
        The scipy interpolant on the scaled conditions.
    """

    names: tuple
    conditions: np.ndarray
    mean: np.ndarray
    grid: bool
    interpolant: object = field(repr=False)

    def predict(self, conditions) -> np.ndarray:
        """Interpolate the table.

        Parameters
        ----------
        conditions : array_like
            (k, d) conditions (or (k,) with one axis) inside the table.

        Returns
        -------
        numpy.ndarray
            (k,) interpolated seed means.

        Raises
        ------
        ValueError
            A condition outside the table (a table does not extrapolate), or the wrong shape.
        """
        q = _query(conditions, self.conditions.shape[1])
        lo, hi = self.conditions.min(axis=0), self.conditions.max(axis=0)
        out = np.asarray(self.interpolant((q - lo) / (hi - lo)), float).ravel()
        if not np.isfinite(out).all():
            raise ValueError(f"conditions {q[~np.isfinite(out)].tolist()} lie outside the look-up table "
                             f"({lo.tolist()} to {hi.tolist()}): a table does not extrapolate")
        return out


def fit_lut(conditions, values, *, names=None) -> LookupTable:
    """Build the look-up table of the seed means: linear interpolation over the conditions.

    Inputs are scaled like :func:`fit_gp`'s. On a full grid (every combination of the axes'
    values present) the interpolation is multilinear (``scipy.interpolate.RegularGridInterpolator``),
    otherwise piecewise linear on a Delaunay triangulation (``LinearNDInterpolator``).

    Parameters
    ----------
    conditions : array_like
        (N,) or (N, d) distinct conditions, each axis with at least two values.
    values : array_like
        (N,) or (N, S) per-run values; the table holds their seed mean.
    names : tuple of str, optional
        Condition axes.

    Returns
    -------
    LookupTable
        The table.

    Raises
    ------
    ValueError
        As :func:`fit_gp`.

    Examples
    --------
    >>> fit_lut([13.0, 15.0, 17.0], [[1.0, 3.0], [4.0, 4.0], [5.0, 7.0]]).predict([14.0, 16.5]).tolist()
    [3.0, 5.5]
    """
    from scipy.interpolate import LinearNDInterpolator, RegularGridInterpolator

    x, y = _training(conditions, values)
    names = tuple(names) if names is not None else tuple(f"x{j}" for j in range(x.shape[1]))
    lo, hi = x.min(axis=0), x.max(axis=0)
    xs = (x - lo) / (hi - lo)
    mean = y.mean(axis=1)
    axes = [np.unique(xs[:, j]) for j in range(xs.shape[1])]
    grid = int(np.prod([a.size for a in axes])) == xs.shape[0]
    if grid:
        idx = tuple(np.searchsorted(a, xs[:, j]) for j, a in enumerate(axes))
        table = np.empty([a.size for a in axes])
        table[idx] = mean
        interp = RegularGridInterpolator(axes, table, method="linear", bounds_error=False, fill_value=np.nan)
    else:
        interp = LinearNDInterpolator(xs, mean, fill_value=np.nan)
    return LookupTable(names=names, conditions=x, mean=mean, grid=grid, interpolant=interp)


@dataclass(frozen=True, eq=False)
class SurrogateComparison:
    """GP vs look-up table on held-out conditions (:func:`compare_surrogates`).

    Parameters
    ----------
    names : tuple of str
        Condition axes.
    train, held_out : numpy.ndarray
        (N_t, d) training and (N_h, d) held-out conditions.
    truth : numpy.ndarray
        (N_h,) seed mean of the runs at the held-out conditions.
    gp_mean, gp_std : numpy.ndarray
        (N_h,) GP prediction and the SD of an S-seed mean about it, √(std² + noise_sd²/S).
    lut : numpy.ndarray
        (N_h,) look-up-table prediction.
    rmse_gp, mae_gp, rmse_lut, mae_lut : float
        Root-mean-square and mean absolute errors against ``truth`` (the indicator's unit).
    coverage : float
        Fraction of held-out truths within gp_mean ± 2 gp_std.
    surrogate : GPSurrogate
        The fitted GP.
    """

    names: tuple
    train: np.ndarray
    held_out: np.ndarray
    truth: np.ndarray
    gp_mean: np.ndarray
    gp_std: np.ndarray
    lut: np.ndarray
    rmse_gp: float
    mae_gp: float
    rmse_lut: float
    mae_lut: float
    coverage: float
    surrogate: GPSurrogate = field(repr=False)


def compare_surrogates(data: DelData, held_out, **gp_kw) -> SurrogateComparison:
    """Fit the GP and the look-up table on some conditions and score both on the others.

    Parameters
    ----------
    data : DelData
        Per-run values (:func:`del_data`).
    held_out : array_like
        (k,) or (k, d) conditions of ``data`` left out of training (e.g. the odd wind
        speeds); they must lie inside the training range (the table does not extrapolate).
    **gp_kw
        ``kernel``, ``n_restarts``, ``random_state`` of :func:`fit_gp`.

    Returns
    -------
    SurrogateComparison
        Predictions, RMSE and MAE of both methods, and the GP's 2σ coverage.

    Raises
    ------
    TypeError
        ``data`` is not a DelData.
    ValueError
        A held-out condition that is not in ``data`` or lies outside the training range, or
        errors of :func:`fit_gp` (e.g. too few training conditions).
    """
    if not isinstance(data, DelData):
        raise TypeError(f"data must be a DelData (from del_data), got {type(data).__name__}")
    d = data.conditions.shape[1]
    q = _query(held_out, d)
    out = np.zeros(data.conditions.shape[0], bool)
    for row in q:
        hit = np.all(np.isclose(data.conditions, row, rtol=0, atol=1e-9), axis=1)
        if not hit.any():
            raise ValueError(f"held_out condition {row.tolist()} is not among the data's conditions "
                             f"{data.conditions.tolist()}")
        out |= hit
    x, y = data.conditions[~out], data.values[~out]
    gp = fit_gp(x, y, names=data.names, **gp_kw)
    lut = fit_lut(x, y, names=data.names)
    held, truth = data.conditions[out], data.values[out].mean(axis=1)
    p = gp.predict(held)
    sd = np.sqrt(p.std ** 2 + p.noise_sd ** 2 / data.values.shape[1])
    table = lut.predict(held)
    eg, el = p.mean - truth, table - truth
    return SurrogateComparison(
        names=data.names, train=x, held_out=held, truth=truth, gp_mean=p.mean, gp_std=sd, lut=table,
        rmse_gp=float(np.sqrt(np.mean(eg ** 2))), mae_gp=float(np.mean(np.abs(eg))),
        rmse_lut=float(np.sqrt(np.mean(el ** 2))), mae_lut=float(np.mean(np.abs(el))),
        coverage=float(np.mean(np.abs(eg) <= 2 * sd)), surrogate=gp)
