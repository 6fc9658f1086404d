"""A linear-parameter-varying (LPV) prediction model of the turbine, scheduled by the wind speed.

Seed 002 (Boutrous, Nejjari, Puig, "Health-aware LPV model predictive control of wind
turbines") writes the turbine as x(k+1) = A(θ)x + B(θ)u + B_w(θ)w with the matrices a convex
combination of vertex matrices, Σ α_i = 1, α_i ∈ [0, 1] (its Eqs. 9-11), and freezes the
scheduling parameters over the horizon at their current estimate θ̂ (so the MPC stays a QP).
Here the vertices are the linearisations of the reduced model (:meth:`TurbineModel.linearize`,
the Jacobian of the simulated equations) at a grid of mean wind speeds v_1 < … < v_K,
discretised by zero-order hold (:func:`specdesign.mpc.base.discretize_turbine`), or OpenFAST's
linearisations of a deck (a :class:`specdesign.openfast.LinearTurbine` whose operating points
carry their states and outputs). Each vertex is kept in absolute (affine) form about its own
trim (x̄_i, β̄_i, ȳ_i: ``DiscreteTurbine.x0``, ``pitch0``, ``y0``), so vertices about
different trims can be blended::

    z_i = ȳ_i + Φ_i (x − x̄_i) + Γ_i (U − β̄_i) + Ψ_i (v̂ − v_i)        (vertex i, N steps)
    z   = Σ_i α_i(v̂) z_i

with x the current absolute state (the five of :data:`specdesign.turbine.STATE_NAMES`), U the
N absolute pitch commands, v̂ the estimated rotor-effective wind held over the horizon, and
Φ, Γ, Ψ the condensed prediction matrices (:func:`specdesign.mpc.base.prediction_matrices`).
The scheduling parameter is the wind estimate v̂ (above rated the trim pitch, and with it every
aerodynamic sensitivity, is a function of it): α is piecewise linear between the two
neighbouring vertices, the polytope of one scheduling parameter; outside the grid the end
vertex is used (α held, the wind itself still enters through Ψ). The prediction is affine in
U, so the MPC that uses it is a QP at every sample.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._checks import positive_scalar
from .base import discretize_turbine, kalman_gain, prediction_matrices

__all__ = ["LPVTurbine", "lpv_turbine", "LPVObserver", "lpv_observer", "PREDICTED", "vertex_pair", "check_speeds"]

#: Outputs the health-aware MPC predicts: generator speed (rad/s), blade-root flapwise moment
#: (N·m) and tower-top fore-aft velocity (m/s).
PREDICTED = ("gen_speed", "blade_root_my", "tower_top_vel")


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class LPVTurbine:
    """Vertex prediction matrices of the LPV turbine over a horizon (module docstring).

    Parameters
    ----------
    wind_speeds : numpy.ndarray
        (K,) increasing vertex wind speeds v_i (m/s).
    ts : float
        Sample time (s).
    horizon : int
        N prediction steps.
    output_names : tuple of str
        The q predicted outputs, in the order of the rows of each step.
    x_trim : numpy.ndarray
        (K, n) trim states x̄_i (SI).
    pitch_trim : numpy.ndarray
        (K,) trim pitch β̄_i (rad).
    y_trim : numpy.ndarray
        (K, q) trim outputs ȳ_i (SI).
    Phi, Gamma, Psi : numpy.ndarray
        (K, N·q, n), (K, N·q, N), (K, N·q) condensed predictions of every vertex (step-major rows:
        row j·q + i is output i at step j + 1).
    C, Dw : numpy.ndarray
        (K, q, n) and (K, q): the outputs' state and wind matrices of every vertex (the outputs
        now, :meth:`current`).
    """

    wind_speeds: np.ndarray = field(repr=False)
    ts: float
    horizon: int
    output_names: tuple
    x_trim: np.ndarray = field(repr=False)
    pitch_trim: np.ndarray = field(repr=False)
    y_trim: np.ndarray = field(repr=False)
    Phi: np.ndarray = field(repr=False)
    Gamma: np.ndarray = field(repr=False)
    Psi: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    Dw: np.ndarray = field(repr=False)

    def current(self, x: np.ndarray, wind: float) -> np.ndarray:
        """The predicted outputs at the current sample (step 0).

        Parameters
        ----------
        x : numpy.ndarray
            (n,) absolute state (SI).
        wind : float
            Wind estimate v̂ (m/s).

        Returns
        -------
        numpy.ndarray
            (q,) outputs (SI), :attr:`output_names`.
        """
        i, a = self.alphas(wind)
        out = np.zeros(len(self.output_names))
        for j, w in ((i, 1.0 - a), (min(i + 1, self.wind_speeds.size - 1), a)):
            if w > 0.0:
                out += w * (self.y_trim[j] + self.C[j] @ (x - self.x_trim[j]) + self.Dw[j] * (wind - self.wind_speeds[j]))
        return out

    def alphas(self, wind: float) -> tuple[int, float]:
        """The active vertex pair and its weight: α_i = 1 − a, α_{i+1} = a.

        Parameters
        ----------
        wind : float
            Scheduling wind speed v̂ (m/s).

        Returns
        -------
        i : int
            Index of the lower vertex.
        a : float
            Weight of vertex i + 1, in [0, 1] (held at the end vertices outside the grid).
        """
        return vertex_pair(self.wind_speeds, wind)

    def affine(self, x: np.ndarray, wind: float, pitch_ref: float) -> tuple[np.ndarray, np.ndarray]:
        """Prediction as an affine map of the commands: z = z₀ + Γ(α)·(U − β_ref).

        Parameters
        ----------
        x : numpy.ndarray
            (n,) absolute state (SI).
        wind : float
            Wind estimate v̂ (m/s), held over the horizon and used to schedule.
        pitch_ref : float
            Reference pitch β_ref (rad) the commands are measured from.

        Returns
        -------
        z0 : numpy.ndarray
            (N·q,) predicted outputs for U = β_ref at every step (SI, step-major).
        Gamma : numpy.ndarray
            (N·q, N) sensitivity to the commands (SI per rad).
        """
        i, a = self.alphas(wind)
        z0 = np.zeros(self.Psi.shape[1])
        G = np.zeros(self.Gamma.shape[1:])
        for j, w in ((i, 1.0 - a), (min(i + 1, self.wind_speeds.size - 1), a)):
            if w == 0.0:
                continue
            zj = (np.tile(self.y_trim[j], self.horizon) + self.Phi[j] @ (x - self.x_trim[j])
                  + self.Gamma[j].sum(axis=1) * (pitch_ref - self.pitch_trim[j]) + self.Psi[j] * (wind - self.wind_speeds[j]))
            z0 += w * zj
            G += w * self.Gamma[j]
        return z0, G

    def predict(self, x: np.ndarray, wind: float, commands: np.ndarray) -> np.ndarray:
        """Predicted outputs over the horizon for given absolute commands.

        Parameters
        ----------
        x : numpy.ndarray
            (n,) absolute state (SI).
        wind : float
            Wind estimate v̂ (m/s).
        commands : numpy.ndarray
            (N,) absolute pitch commands (rad).

        Returns
        -------
        numpy.ndarray
            (N, q) outputs at steps 1..N (SI), columns :attr:`output_names`.

        Examples
        --------
        >>> from specdesign.turbine import iea15mw
        >>> m = iea15mw()
        >>> lpv = lpv_turbine(m, 0.2, 5, wind_speeds=[17.0, 19.0])
        >>> op = m.trim(19.0)
        >>> z = lpv.predict(np.array(op.x), 19.0, np.full(5, op.pitch))
        >>> bool(np.allclose(z[:, 0], op.rotor_speed))   # at the trim the model stays there
        True
        """
        u = np.asarray(commands, float)
        z0, G = self.affine(np.asarray(x, float), float(wind), 0.0)
        return (z0 + G @ u).reshape(self.horizon, len(self.output_names))


def vertex_pair(v, wind) -> tuple[int, float]:
    """The vertex pair of ``wind`` on the grid ``v`` and its weight (:meth:`LPVTurbine.alphas`).

    Parameters
    ----------
    v : numpy.ndarray
        (K,) increasing vertex wind speeds (m/s).
    wind : float
        Scheduling wind speed (m/s).

    Returns
    -------
    i : int
        Index of the lower vertex.
    a : float
        Weight of vertex i + 1 in [0, 1] (α_i = 1 − a), held at the ends of the grid.
    """
    if v.size == 1:
        return 0, 0.0
    # plain floats: called per run and sample, where numpy's scalar clip costs more than the rest
    i = min(max(int(np.searchsorted(v, wind, side="right")) - 1, 0), v.size - 2)
    lo, hi = float(v[i]), float(v[i + 1])
    return i, min(max((float(wind) - lo) / (hi - lo), 0.0), 1.0)


def check_speeds(model, wind_speeds) -> np.ndarray:
    """The vertex wind speeds (m/s): ``wind_speeds`` checked, or every 1 m/s over ``model.wind_range``.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    wind_speeds : array_like or None
        Increasing wind speeds within the model's range (m/s).

    Returns
    -------
    numpy.ndarray
        (K,) vertex wind speeds.

    Raises
    ------
    ValueError
        For speeds that are not increasing or outside the model's range.
    """
    lo, hi = (float(v) for v in model.wind_range)
    if wind_speeds is None:
        wind_speeds = np.arange(np.ceil(lo), np.floor(hi) + 0.5, 1.0)
    v = np.atleast_1d(np.asarray(wind_speeds, float))
    if v.ndim != 1 or v.size < 1 or np.any(np.diff(v) <= 0) or v[0] < lo or v[-1] > hi:
        raise ValueError(f"wind_speeds={wind_speeds!r} must be increasing, within the model's range {lo:g}-{hi:g} m/s")
    return v


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class LPVObserver:
    """The Kalman filter of :func:`specdesign.mpc.base.kalman_gain` made LPV, scheduled by its own wind estimate.

    The augmented state ζ = (x, v) (the model's states and the rotor-effective wind, absolute,
    SI) is filtered with the vertex models and gains blended by α(v̂), each vertex in affine
    form about its trim ζ̄_i = (x̄_i, v_i), as the prediction model of :class:`LPVTurbine`::

        ŷ   = Σ α_i (ȳ_i + C_i (ζ − ζ̄_i))                      (measured outputs)
        ζ_f = ζ + (Σ α_i L_i)(y − ŷ)                          (update, α at the prior's v̂)
        ζ⁺  = Σ α_i (ζ̄_i + A_i (ζ_f − ζ̄_i) + B_i (u − β̄_i))   (predict, α at the filtered v̂)

    Observer and predictor then share one model, so the wind estimate that schedules the
    prediction is the one that explains the measurements with it (a fixed-point filter's
    estimate would be biased away from its linearisation point).

    Parameters
    ----------
    wind_speeds : numpy.ndarray
        (K,) vertex wind speeds (m/s).
    measured : tuple of str
        The q measured outputs.
    z_trim : numpy.ndarray
        (K, n+1) trim states with the vertex wind speed last.
    pitch_trim : numpy.ndarray
        (K,) trim pitch (rad).
    y_trim : numpy.ndarray
        (K, q) measured outputs at the trims (SI).
    A, B, C, L : numpy.ndarray
        (K, n+1, n+1), (K, n+1), (K, q, n+1), (K, n+1, q): augmented discrete model and
        steady-state Kalman gain of every vertex (:func:`specdesign.mpc.base.kalman_gain`).
    """

    wind_speeds: np.ndarray = field(repr=False)
    measured: tuple
    z_trim: np.ndarray = field(repr=False)
    pitch_trim: np.ndarray = field(repr=False)
    y_trim: np.ndarray = field(repr=False)
    A: np.ndarray = field(repr=False)
    B: np.ndarray = field(repr=False)
    C: np.ndarray = field(repr=False)
    L: np.ndarray = field(repr=False)

    def _pairs(self, wind):
        i, a = vertex_pair(self.wind_speeds, wind)
        return [(j, w) for j, w in ((i, 1.0 - a), (min(i + 1, self.wind_speeds.size - 1), a)) if w > 0.0]

    def update(self, z: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Measurement update of one run.

        Parameters
        ----------
        z : numpy.ndarray
            (n+1,) prior estimate (states, wind; absolute SI).
        y : numpy.ndarray
            (q,) measured outputs (SI).

        Returns
        -------
        numpy.ndarray
            (n+1,) filtered estimate.
        """
        yhat = np.zeros(y.size)
        gain = np.zeros(self.L.shape[1:])
        for j, w in self._pairs(z[-1]):
            yhat += w * (self.y_trim[j] + self.C[j] @ (z - self.z_trim[j]))
            gain += w * self.L[j]
        return z + gain @ (y - yhat)

    def predict(self, z: np.ndarray, u: float) -> np.ndarray:
        """Time update of one run over one sample.

        Parameters
        ----------
        z : numpy.ndarray
            (n+1,) filtered estimate (absolute SI).
        u : float
            Pitch command held over the sample (rad, absolute).

        Returns
        -------
        numpy.ndarray
            (n+1,) prior estimate at the next sample.
        """
        out = np.zeros(z.size)
        for j, w in self._pairs(z[-1]):
            out += w * (self.z_trim[j] + self.A[j] @ (z - self.z_trim[j]) + self.B[j] * (u - self.pitch_trim[j]))
        return out


def lpv_observer(model, ts: float, measured, *, wind_speeds=None, measurement_std: dict | None = None) -> LPVObserver:
    """Build the :class:`LPVObserver` of ``model`` (vertices at ``wind_speeds``).

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    ts : float
        Sample time (s).
    measured : sequence of str
        Measured outputs (those of :func:`specdesign.mpc.base.kalman_gain`).
    wind_speeds : array_like, optional
        Vertex wind speeds (m/s); default every 1 m/s over the model's range.
    measurement_std : dict, optional
        Output name → noise SD the filter assumes (SI), as :func:`kalman_gain` takes it
        (e.g. :func:`specdesign.mpc.base.filter_noise` of the run's sensors).

    Returns
    -------
    LPVObserver
        The observer.

    Raises
    ------
    ValueError
        As :func:`lpv_turbine`, or for an unknown measured output.
    """
    ts = positive_scalar(ts, "ts")
    v = check_speeds(model, wind_speeds)
    measured = tuple(measured)
    parts = {k: [] for k in ("z", "b", "y", "A", "B", "C", "L")}
    for s in v:
        dm = discretize_turbine(model, float(s), ts)
        Aa, Ba, Ca, L = kalman_gain(dm, measured, measurement_std=measurement_std)
        for k, val in zip(parts, (np.append(dm.x0, s), dm.pitch0, dm.y0[dm.rows(measured)], Aa, Ba, Ca, L)):
            parts[k].append(val)
    st = {k: np.stack(val) if k != "b" else np.array(val) for k, val in parts.items()}
    return LPVObserver(v, measured, st["z"], st["b"], st["y"], st["A"], st["B"], st["C"], st["L"])


def lpv_turbine(model, ts: float, horizon: int, *, wind_speeds=None, outputs=PREDICTED) -> LPVTurbine:
    """Build the LPV prediction model of ``model`` (vertices at ``wind_speeds``).

    Parameters
    ----------
    model : TurbineModel
        The turbine (e.g. :func:`specdesign.turbine.iea15mw`).
    ts : float
        Sample time (s).
    horizon : int
        N prediction steps (≥ 1).
    wind_speeds : array_like, optional
        Increasing vertex wind speeds (m/s) within ``model.wind_range``; default every 1 m/s
        over the range.
    outputs : sequence of str, optional
        Predicted outputs (default :data:`PREDICTED`).

    Returns
    -------
    LPVTurbine
        The vertex matrices.

    Raises
    ------
    ValueError
        For wind speeds that are not increasing or outside the model's range, a non-positive
        ``ts`` or a horizon < 1.
    """
    ts = positive_scalar(ts, "ts")
    v = check_speeds(model, wind_speeds)
    outputs = tuple(outputs)
    mats, xs, bs, ys, cs, ds = [], [], [], [], [], []
    for s in v:
        dm = discretize_turbine(model, float(s), ts)
        mats.append(prediction_matrices(dm, outputs, horizon))
        cs.append(dm.C[dm.rows(outputs)])
        ds.append(dm.Dw[dm.rows(outputs)])
        xs.append(dm.x0)
        bs.append(dm.pitch0)
        ys.append(dm.y0[dm.rows(outputs)])
    Phi, Gam, Psi = (np.stack([m[k] for m in mats]) for k in range(3))
    return LPVTurbine(v, ts, int(horizon), outputs, np.stack(xs), np.array(bs), np.stack(ys), Phi, Gam, Psi,
                      np.stack(cs), np.stack(ds))
