"""The record of a validation campaign: controllers × wind speeds × seeds, paired.

:class:`Campaign` is what :func:`specdesign.validate.run_campaign` returns, on the reduced model
and in OpenFAST alike (both campaign engines build it; neither imports the other).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .stats import PairedChange, paired_change

__all__ = ["Campaign"]


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class Campaign:
    """Results of controllers × wind speeds × seeds (paired: every controller saw the same seeds).

    Parameters
    ----------
    controllers : tuple of str
        Controller names, in order (C).
    wind_speeds : numpy.ndarray
        (W,) wind speeds (m/s).
    seeds : numpy.ndarray
        (S,) seeds.
    duration : float
        Record length (s).
    dt : float
        Sample spacing of the records (s).
    m : float
        Wöhler exponent of the DEL.
    values : dict
        Indicator → (C, W, S) per-run values (units: :class:`~specdesign.validate.Indicators`).
    predicted_del : numpy.ndarray
        (C, W) linear prediction of the tower-base DEL (Dirlik on |T|²S_W, N·m); NaN for
        controllers without a linear form (callables).
    omega : numpy.ndarray
        (nω,) Welch grid (rad/s).
    welch : dict
        Output → (C, W, nω) seed-averaged Welch PSD (SI² per rad/s).
    predicted_psd : dict
        Output → (C, W, nω) |T|²S_W on the same grid.
    series : dict, optional
        Controller → :class:`~specdesign.simulate.SimulationResult` (W, k, n) of the first k
        seeds kept (``keep_series``), else {}.
    linear_values : dict, optional
        Like ``values``, from the same seeds run through the *linearised* model
        (``run_campaign(linear_twin=True)``; NaN for controllers without a linear form), else
        {}. It splits the prediction error into the spectral method's part and the plant's
        nonlinearity (:func:`~specdesign.validate.acceptance`).
    volterra_values : dict, optional
        Like ``values``, from the Volterra series of order ``volterra_order``
        (:func:`~specdesign.validate.volterra_response`) on the same wind
        (``run_campaign(volterra=k)``; NaN for controllers without a linear form), else {}: a
        prediction that includes the aerodynamic nonlinearity, still made from the linear loop.
    volterra_order : int, default 0
        Order of ``volterra_values`` (0: none).
    unstable : numpy.ndarray, optional
        (C, W) bool: the controller destabilises the linearised loop or its simulation
        diverged at that wind speed; its values and predictions there are NaN (with a warning
        when the campaign ran), and the tables print "unstable". Default: all False.

    See Also
    --------
    run_campaign : Runs one.
    concat_campaigns : Joins campaigns over different wind speeds.
    """

    controllers: tuple
    wind_speeds: np.ndarray
    seeds: np.ndarray
    duration: float
    dt: float
    m: float
    values: dict = field(repr=False)
    predicted_del: np.ndarray = field(repr=False)
    omega: np.ndarray = field(repr=False)
    welch: dict = field(repr=False)
    predicted_psd: dict = field(repr=False)
    series: dict = field(default_factory=dict, repr=False)
    linear_values: dict = field(default_factory=dict, repr=False)
    volterra_values: dict = field(default_factory=dict, repr=False)
    volterra_order: int = 0
    unstable: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.unstable is None:
            object.__setattr__(self, "unstable", np.zeros((len(self.controllers), np.size(self.wind_speeds)), bool))

    def index(self, controller: str) -> int:
        """Position of a controller in :attr:`controllers`.

        Parameters
        ----------
        controller : str
            Its name.

        Returns
        -------
        int
            Index along the first axis of the arrays.

        Raises
        ------
        ValueError
            A name that is not in the campaign.
        """
        if controller not in self.controllers:
            raise ValueError(f"controller {controller!r} not in the campaign {self.controllers}")
        return self.controllers.index(controller)

    def change(self, designed: str, baseline: str, indicator: str = "tower_del", **kw) -> PairedChange:
        """:func:`~specdesign.validate.paired_change` of ``indicator`` between two controllers.

        Parameters
        ----------
        designed, baseline : str
            Controller names.
        indicator : str, default "tower_del"
            The indicator compared.
        **kw
            ``method``, ``n_boot``, ``seed`` of :func:`~specdesign.validate.paired_change`.

        Returns
        -------
        PairedChange
            Change (%) and SE (pp) per wind speed.
        """
        i, j = self.index(designed), self.index(baseline)
        return paired_change(self.values[indicator][i], self.values[indicator][j], indicator, m=self.m,
                             wind_speeds=self.wind_speeds, **kw)
