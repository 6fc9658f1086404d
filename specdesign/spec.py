"""Fatigue-based specifications: W_y(s) = baseline T_{y,w}(s) × shaping elements.

The seed paper's main contribution (Sect. 3): from the damage sensitivity ΔD%(ω) of the
baseline closed loop (Eq. 7), shape a specification W_y(s) with notch filters where ΔD% is
high, and quantify the fatigue it promises, by Eq. (10) (linear in the spectral change) and
exactly (Dirlik on |W_y|² S_W). Damage is the quantity that Eq. (10) is linear in; the DEL
change follows as DEL ratio = damage ratio^(1/m), reported beside it.

Units: ω in rad/s, depths in dB (positive = attenuation), PSDs one-sided per rad/s.

Typical use::

    base = baseline_analysis(model, 19.0)             # T_{MyT,w}, S_W, ΔD%(ω) at 19 m/s
    res = shape_to_target(base, 15.0)                  # notches promising 15 % less damage
    res.specification.tf()                             # W_MyT(s)
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace

import control as ct
import numpy as np

from . import spectral
from ._checks import as_omega, as_psd, positive_scalar
from .closedloop import siso_response

__all__ = [
    "Notch",
    "Gain",
    "LeadLag",
    "LowPass",
    "Specification",
    "Baseline",
    "Promise",
    "ShapingResult",
    "baseline_analysis",
    "baseline_from_response",
    "evaluate",
    "shape_to_target",
    "speed_specification",
    "specification_table",
]


# --------------------------------------------------------------------------------------
# Shaping elements: frozen records with an exact transfer function and a fast response.
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Notch:
    """Second-order notch N(s) = (s² + 2ζ_z ω_n s + ω_n²) / (s² + 2ζ_p ω_n s + ω_n²).

    Parameters
    ----------
    omega_n : float
        Centre frequency, rad/s.
    depth_db : float
        Attenuation at ω_n in dB (> 0 attenuates; |N(jω_n)| = ζ_z/ζ_p = 10^(−depth/20)).
    width : float
        Damping ratio ζ_p of the pole pair (dimensionless, 0 < width ≤ 2): the relative
        bandwidth of the notch; 0.1 is narrow, 0.7 wide. Unity gain at DC and at ∞.
    """

    omega_n: float
    depth_db: float
    width: float = 0.3

    def __post_init__(self):
        positive_scalar(self.omega_n, "Notch.omega_n (rad/s)")
        if not np.isfinite(self.depth_db):
            raise ValueError(f"Notch.depth_db={self.depth_db!r} must be finite (dB)")
        if not 0 < self.width <= 2:
            raise ValueError(f"Notch.width={self.width!r} is the pole damping ratio; use 0 < width <= 2")

    @property
    def zeta_zero(self) -> float:
        return self.width * 10 ** (-self.depth_db / 20)

    def tf(self) -> ct.TransferFunction:
        w = self.omega_n
        return ct.tf([1, 2 * self.zeta_zero * w, w * w], [1, 2 * self.width * w, w * w])

    def response(self, omega: np.ndarray) -> np.ndarray:
        s = 1j * np.asarray(omega, dtype=float)
        w = self.omega_n
        return (s * s + 2 * self.zeta_zero * w * s + w * w) / (s * s + 2 * self.width * w * s + w * w)


@dataclass(frozen=True)
class Gain:
    """Constant gain in dB (negative attenuates everywhere)."""

    gain_db: float

    def tf(self) -> ct.TransferFunction:
        return ct.tf([10 ** (self.gain_db / 20)], [1])

    def response(self, omega):
        return np.full(np.shape(omega), 10 ** (self.gain_db / 20), dtype=complex)


@dataclass(frozen=True)
class LeadLag:
    """(1 + s/ω_z) / (1 + s/ω_p): lead if ω_z < ω_p, lag otherwise. Frequencies in rad/s."""

    omega_zero: float
    omega_pole: float

    def __post_init__(self):
        positive_scalar(self.omega_zero, "LeadLag.omega_zero (rad/s)")
        positive_scalar(self.omega_pole, "LeadLag.omega_pole (rad/s)")

    def tf(self):
        return ct.tf([1 / self.omega_zero, 1], [1 / self.omega_pole, 1])

    def response(self, omega):
        s = 1j * np.asarray(omega, dtype=float)
        return (1 + s / self.omega_zero) / (1 + s / self.omega_pole)


@dataclass(frozen=True)
class LowPass:
    """Second-order low-pass ω_c² / (s² + 2ζ ω_c s + ω_c²), ω_c in rad/s."""

    omega_c: float
    zeta: float = 0.7

    def __post_init__(self):
        positive_scalar(self.omega_c, "LowPass.omega_c (rad/s)")
        positive_scalar(self.zeta, "LowPass.zeta")

    def tf(self):
        w = self.omega_c
        return ct.tf([w * w], [1, 2 * self.zeta * w, w * w])

    def response(self, omega):
        s = 1j * np.asarray(omega, dtype=float)
        w = self.omega_c
        return w * w / (s * s + 2 * self.zeta * w * s + w * w)


_ELEMENTS = (Notch, Gain, LeadLag, LowPass)


@dataclass(frozen=True)
class Specification:
    """W_y(s) = baseline(s) × Π elements(s).

    ``baseline`` is the closed-loop map wind → y of the baseline controller (a SISO
    python-control LTI); ``elements`` a tuple of shaping elements (:class:`Notch`, ...).
    """

    baseline: object
    elements: tuple = ()
    name: str = "W"

    def __post_init__(self):
        if not isinstance(self.baseline, ct.LTI):
            raise TypeError(f"baseline must be a python-control LTI system (wind → output), got {type(self.baseline).__name__}")
        if self.baseline.ninputs != 1 or self.baseline.noutputs != 1:
            raise ValueError(f"baseline must be SISO (one wind input, one output), got {self.baseline.noutputs}x{self.baseline.ninputs}")
        _check_proper_stable(self.baseline, "baseline")
        object.__setattr__(self, "elements", tuple(self.elements))
        for i, e in enumerate(self.elements):
            if not isinstance(e, _ELEMENTS):
                raise TypeError(f"elements[{i}] must be one of {[c.__name__ for c in _ELEMENTS]}, got {type(e).__name__}")

    def shaping(self, omega) -> np.ndarray:
        """Product of the elements' responses on ω (rad/s), complex."""
        out = np.ones(np.shape(omega), dtype=complex)
        for e in self.elements:
            out = out * e.response(omega)
        return out

    def response(self, omega) -> np.ndarray:
        """W_y(jω) on the grid ω (rad/s), complex."""
        omega = np.asarray(omega, dtype=float)
        return siso_response(self.baseline, omega, "baseline") * self.shaping(omega)

    def magnitude(self, omega) -> np.ndarray:
        return np.abs(self.response(omega))

    def tf(self) -> ct.TransferFunction:
        """W_y(s) as a transfer function (minimal realisation of the product)."""
        w = ct.tf(self.baseline)
        for e in self.elements:
            w = w * e.tf()
        return ct.minreal(w, verbose=False)

    def add(self, element) -> "Specification":
        return replace(self, elements=self.elements + (element,))

    def with_elements(self, elements) -> "Specification":
        return replace(self, elements=tuple(elements))


def _check_proper_stable(sys, name):
    if isinstance(sys, ct.TransferFunction):
        num, den = sys.num[0][0], sys.den[0][0]
        if len(np.trim_zeros(num, "f")) > len(np.trim_zeros(den, "f")):
            raise ValueError(f"{name} is improper (numerator degree > denominator degree); a specification must be a proper transfer function")
    poles = ct.poles(sys)
    if sys.isctime() and np.any(poles.real >= 0):
        bad = poles[poles.real >= 0]
        raise ValueError(f"{name} is not stable (poles {np.round(bad, 4)} in the closed right half-plane); a specification must be a stable closed-loop map")


# --------------------------------------------------------------------------------------
# Baseline analysis and promises
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Baseline:
    """The baseline loop seen by one output: everything Eq. (7) and Eq. (10) need.

    omega (rad/s), t_response = T_{y,w}(jω), s_wind = S_W(ω) (one-sided, (m/s)²/(rad/s)),
    psd = |T|² S_W, damage_rate (1/s, S-N with S_ref = 1 in the output's units),
    sensitivity = ΔD%(ω) per 1 % reduction of S_y at each grid point (computed with a finite
    step ``reduction``), m (Wöhler exponent, range-based S-N), method (damage method name).
    """

    omega: np.ndarray
    t_response: np.ndarray
    s_wind: np.ndarray
    psd: np.ndarray
    damage_rate: float
    sensitivity: np.ndarray
    m: float
    method: str
    reduction: float
    system: object = None
    output: str = ""
    wind_speed: float = float("nan")
    extras: dict = field(default_factory=dict)

    @property
    def del_1hz(self) -> float:
        """DEL at 1 Hz of the baseline output, in the output's units."""
        return float(self.damage_rate ** (1.0 / self.m))


def baseline_from_response(omega, t_response, s_wind, m=4.0, *, method="dirlik", reduction=0.01, system=None, output="", wind_speed=float("nan")) -> Baseline:
    """Baseline from a closed-loop frequency response T(jω) and an input spectrum S_W(ω)."""
    omega = as_omega(omega)
    t_response = np.asarray(t_response, dtype=complex)
    if t_response.shape != omega.shape:
        raise ValueError(f"t_response must have the shape of omega {omega.shape}, got {t_response.shape}")
    s_wind = as_psd(s_wind, omega.size, "s_wind")
    psd = np.abs(t_response) ** 2 * s_wind
    d0 = float(spectral.damage_rate(omega, psd, m, method=method))
    if not d0 > 0:
        raise ValueError("the baseline output spectrum carries no damage (all-zero PSD); check the output and the wind spectrum")
    # Eq. (10) reads ΔD% as "per 1 % reduction"; a different finite step is rescaled to it.
    sens = spectral.sensitivity(omega, psd, m, reduction=reduction, method=method) * (0.01 / reduction)
    return Baseline(omega, t_response, s_wind, psd, d0, np.asarray(sens), float(m), method, float(reduction), system, output, float(wind_speed))


def default_omega(n: int = 400, lo: float = 0.01, hi: float = 10.0) -> np.ndarray:
    """Log-spaced design grid in rad/s (covers the wind band, the tower mode and 3P)."""
    return np.logspace(np.log10(lo), np.log10(hi), n)


def baseline_analysis(model, wind_speed, output="tower_base_my", *, m=4.0, omega=None, controller=None, turbulence_class="B", method="dirlik", reduction=0.01) -> Baseline:
    """ΔD%(ω) of the baseline closed loop of ``model`` at ``wind_speed`` (m/s) for ``output``.

    The baseline controller is ROSCO's PI (tower damping off) unless ``controller`` is given;
    the disturbance is the rotor-effective wind spectrum (IEC NTM ``turbulence_class``).
    """
    from . import closedloop, turbine, wind

    omega = default_omega() if omega is None else as_omega(omega, allow_zero=False)
    plant = model.linearize(wind_speed)
    c = turbine.rosco_baseline(model, wind_speed) if controller is None else controller
    cl = closedloop.closed_loop(plant, c)
    t_sys = cl[output, "wind"]
    t = closedloop.frequency_response(cl, omega, output, "wind")
    s_w = wind.rotor_effective_spectrum(omega, wind_speed, model.rotor_radius, turbulence_class=turbulence_class)
    return baseline_from_response(omega, t, s_w, m, method=method, reduction=reduction, system=t_sys, output=output, wind_speed=wind_speed)


@dataclass(frozen=True)
class Promise:
    """What a specification promises against its baseline (all in %, positive = less fatigue).

    ``predicted_damage``: Eq. (10), linear in the spectral change; ``exact_damage``: Dirlik
    on |W|² S_W; the DEL reductions follow from DEL ratio = damage ratio^(1/m).
    """

    predicted_damage: float
    exact_damage: float
    predicted_del: float
    exact_del: float

    @property
    def linearisation_error(self) -> float:
        """Eq. (10) minus exact, percentage points of damage."""
        return self.predicted_damage - self.exact_damage


def evaluate(spec_or_shaping, base: Baseline) -> Promise:
    """Promised fatigue reduction of a specification (or a shaping response) vs ``base``.

    ``spec_or_shaping`` is a :class:`Specification` (W_y on ``base.omega``) or a complex /
    real array of the shaping |W_y|/|T| on the baseline grid.
    """
    if isinstance(spec_or_shaping, Specification):
        for e in spec_or_shaping.elements:
            if isinstance(e, Notch) and not base.omega[0] <= e.omega_n <= base.omega[-1]:
                raise ValueError(
                    f"notch at omega_n={e.omega_n:g} rad/s lies outside the baseline grid "
                    f"[{base.omega[0]:.3g}, {base.omega[-1]:.3g}] rad/s: its effect cannot be evaluated there"
                )
        w_mag2 = np.abs(spec_or_shaping.response(base.omega)) ** 2
        t_mag2 = np.abs(base.t_response) ** 2
        ratio = np.divide(w_mag2, t_mag2, out=np.ones_like(w_mag2), where=t_mag2 > 0)
    else:
        shaping = np.asarray(spec_or_shaping)
        if shaping.shape != base.omega.shape:
            raise ValueError(f"shaping must have the shape of the baseline grid {base.omega.shape}, got {shaping.shape}")
        ratio = np.abs(shaping) ** 2
    return _promise(base, ratio)


def _promise(base: Baseline, ratio: np.ndarray) -> Promise:
    predicted = float(spectral.predicted_change(base.omega, base.sensitivity, np.ones_like(ratio), ratio))
    d_new = float(spectral.damage_rate(base.omega, base.psd * ratio, base.m, method=base.method))
    exact = 100.0 * (1 - d_new / base.damage_rate)
    return Promise(predicted, exact, float(spectral.del_reduction(predicted, base.m)), float(spectral.del_reduction(exact, base.m)))


# --------------------------------------------------------------------------------------
# Automatic shaping
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ShapingResult:
    """Outcome of :func:`shape_to_target`.

    ``specification`` (None when no system is attached to the baseline), ``notches``,
    ``promise`` (exact and Eq. 10), ``target`` and ``quantity`` ("damage" or "del"),
    ``success`` and a human-readable ``message`` saying why not when it failed.
    """

    notches: tuple
    promise: Promise
    target: float
    quantity: str
    success: bool
    message: str
    specification: Specification | None = None

    @property
    def reached(self) -> float:
        return self.promise.exact_damage if self.quantity == "damage" else self.promise.exact_del


def _notch_mag2(omega, params):
    """|Π notches(jω)|² for params rows (ω_n, depth_db, width), vectorised."""
    s = 1j * omega[None, :]
    wn, depth, zp = params[:, 0:1], params[:, 1:2], params[:, 2:3]
    zz = zp * 10 ** (-depth / 20)
    n = (s * s + 2 * zz * wn * s + wn * wn) / (s * s + 2 * zp * wn * s + wn * wn)
    return np.prod(np.abs(n) ** 2, axis=0)


def shape_to_target(base: Baseline, target_reduction: float, *, quantity="damage", keep_below=0.6, n_notches=None, max_notches=3, max_depth_db=30.0, width_range=(0.05, 0.8), tolerance=0.5) -> ShapingResult:
    """Place and size notches where ΔD% is largest above ``keep_below`` to reach a target.

    Parameters
    ----------
    base : Baseline
        From :func:`baseline_analysis` or :func:`baseline_from_response`.
    target_reduction : float
        Requested reduction in percent (0 < target < 100) of ``quantity``.
    quantity : {"damage", "del"}
        Whether the target is a reduction of damage (Eq. 10's quantity) or of DEL at 1 Hz.
    keep_below : float
        Protected band upper edge, rad/s: the power-regulation band the notches must leave
        alone (their effect below it is penalised heavily and the notch centres stay above).
    n_notches : int, optional
        Fixed number of notches; by default 1, 2, ... up to ``max_notches`` until reached.
    tolerance : float
        Accepted shortfall, percentage points.

    The problem solved (scipy SLSQP, exact Dirlik in the constraint): minimise the mean
    squared log-magnitude change of the specification, Σ_k w_k (20 log10 |N(jω_k)|)², with
    w_k = 1 above ``keep_below`` and 100 below, subject to reduction ≥ target.
    """
    from scipy.optimize import minimize

    if not isinstance(base, Baseline):
        raise TypeError(f"base must be a Baseline (see baseline_analysis), got {type(base).__name__}")
    if quantity not in ("damage", "del"):
        raise ValueError(f"quantity={quantity!r} must be 'damage' or 'del'")
    t = float(target_reduction)
    if not 0 < t < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a percentage strictly between 0 and 100")
    omega = base.omega
    keep_below = float(keep_below)
    if not omega[0] <= keep_below < omega[-1]:
        raise ValueError(f"keep_below={keep_below} rad/s must lie inside the grid [{omega[0]:.3g}, {omega[-1]:.3g}] rad/s")
    target_damage = t if quantity == "damage" else 100.0 * (1 - (1 - t / 100.0) ** base.m)
    protected = omega < keep_below
    weights = np.where(protected, 100.0, 1.0) * np.gradient(np.log(omega))
    weights = weights / weights.sum()
    lo_w, hi_w = width_range

    def damage_reduction(x):
        ratio = _notch_mag2(omega, x.reshape(-1, 3))
        return 100.0 * (1 - spectral.damage_rate(omega, base.psd * ratio, base.m, method=base.method) / base.damage_rate)

    def cost(x):
        ratio = _notch_mag2(omega, x.reshape(-1, 3))
        return float(np.sum(weights * (10 * np.log10(ratio)) ** 2))

    # Seed centres at the largest ΔD% density peaks above the protected band: that is where a
    # given attenuation buys the most damage (Eq. 7).
    density = np.where(~protected, base.sensitivity, -np.inf)
    order = np.argsort(density)[::-1]
    candidates = []
    for k in order:
        if not np.isfinite(density[k]):
            break
        if all(abs(np.log(omega[k] / c)) > 0.25 for c in candidates):
            candidates.append(omega[k])
        if len(candidates) >= max_notches:
            break
    if not candidates:
        raise ValueError("no grid frequency lies above keep_below; extend the grid or lower keep_below")

    counts = [n_notches] if n_notches else range(1, max_notches + 1)
    best = None
    for n in counts:
        centres = (candidates * n)[:n]
        x0 = np.concatenate([[c, 6.0, 0.3] for c in centres])
        lo_omega = max(keep_below, omega[0])
        bounds = [(lo_omega, omega[-1]), (0.0, max_depth_db), (lo_w, hi_w)] * n
        # Upper bound first: the deepest, widest notches show whether the target is reachable.
        x_max = np.concatenate([[c, max_depth_db, hi_w] for c in centres])
        if damage_reduction(x_max) < target_damage - tolerance:
            best = best or (x_max, False)
            continue
        res = minimize(
            cost, x0, method="SLSQP", bounds=bounds,
            constraints=[{"type": "ineq", "fun": lambda x: damage_reduction(x) - target_damage}],
            options={"maxiter": 300, "ftol": 1e-10},
        )
        x = res.x
        if damage_reduction(x) >= target_damage - tolerance:
            best = (x, True)
            break
        best = (x, False)

    x, ok = best
    notches = tuple(Notch(float(p[0]), float(p[1]), float(p[2])) for p in x.reshape(-1, 3))
    promise = _promise(base, _notch_mag2(omega, x.reshape(-1, 3)))
    reached = promise.exact_damage if quantity == "damage" else promise.exact_del
    success = ok and reached >= t - tolerance
    if success:
        message = f"reached {reached:.2f} % {quantity} reduction (target {t:.2f} %) with {len(notches)} notch(es)"
    else:
        message = (
            f"cannot reach {t:.2f} % {quantity} reduction with up to {max(counts)} notch(es) of at most {max_depth_db:g} dB "
            f"above {keep_below:g} rad/s (best {reached:.2f} %): the fatigue sits in the protected band; "
            "lower keep_below, allow deeper notches or lower the target"
        )
        warnings.warn(message, RuntimeWarning, stacklevel=2)
    spec = Specification(base.system, notches, name=f"W_{base.output}") if base.system is not None else None
    return ShapingResult(notches, promise, t, quantity, bool(success), message, spec)


def speed_specification(model, wind_speed, *, margin_db=0.0, controller=None):
    """Generator-speed specification: the baseline's T_{Ω,w}, optionally relaxed by ``margin_db``."""
    from . import closedloop, turbine

    plant = model.linearize(wind_speed)
    c = turbine.rosco_baseline(model, wind_speed) if controller is None else controller
    cl = closedloop.closed_loop(plant, c)
    elements = (Gain(float(margin_db)),) if margin_db else ()
    return Specification(cl["gen_speed", "wind"], elements, name="W_gen_speed")


def specification_table(model, wind_speeds=(15, 17, 19, 21, 23, 25), target_reduction=15.0, **kwargs):
    """The "Specifications" row of the paper's Table 3: promised reduction per wind speed.

    Returns a list of dicts (wind_speed m/s, notches, promised damage and DEL reduction %,
    Eq. 10 prediction %, success) — one per wind speed.
    """
    rows = []
    shape_kw = {k: kwargs.pop(k) for k in list(kwargs) if k in ("quantity", "keep_below", "n_notches", "max_notches", "max_depth_db", "width_range", "tolerance")}
    for v in wind_speeds:
        base = baseline_analysis(model, v, **kwargs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            res = shape_to_target(base, target_reduction, **shape_kw)
        rows.append(
            {
                "wind_speed": float(v),
                "notches": res.notches,
                "promised_damage_pct": res.promise.exact_damage,
                "promised_del_pct": res.promise.exact_del,
                "eq10_damage_pct": res.promise.predicted_damage,
                "success": res.success,
                "result": res,
            }
        )
    return rows
