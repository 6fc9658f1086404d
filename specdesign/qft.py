"""QFT design of the pitch controller C_β and an active tower damping (ATD) controller.

The seed paper's Sect. 4 on the embedded turbine model, as a deterministic automatic
procedure. Sign convention (WORKBENCH.md, :mod:`specdesign.closedloop`):

    β_cmd = −C_β·Ω_g − C_atd·z,    z = tower-top fore-aft velocity (m/s),

both negative feedback; ω in rad/s; transfer functions are python-control objects.

Sequential loop closure and the general form
--------------------------------------------
With one loop closed (controller K on measurement m: β_cmd = u − K·m) the plant seen from
the free pitch input u is, with Δ_K = 1 + K·P_{m,β},

    P'_{y,w} = P_{y,w} − P_{y,β}·K·P_{m,w}/Δ_K,        P'_{y,β} = P_{y,β}/Δ_K.

Closing the second loop u = −G·n (G the controller designed now, n its measurement) gives
every wind map in QFT's general form |(A + B·G)/(C + D·G)| with, per plant case,

    A = P'_{y,w},  B = P'_{y,w}P'_{n,β} − P'_{y,β}P'_{n,w},  C = 1,  D = P'_{n,β}

(B = 0 when y = n). For the pitch controller (G = C_β, n = Ω_g, ATD closed) and y = MyT this
is WORKBENCH.md's tower-load form with the primed plant; for the ATD (G = C_atd, n = z,
pitch loop closed) the roles swap. :func:`general_form` computes A..D; the tests check
(A + B·G)/(C + D·G) against ``control.interconnect`` to 1e-9.

Specifications (per plant case i, at the design frequencies)
-----------------------------------------------------------
- tower load ``tower``: |T_{MyT,w}| ≤ |W_MyT,i| = |T^ROSCO_{MyT,w,i}|·|notches|·|relaxation|,
  the notches from :func:`specdesign.spec.shape_to_target` at the nominal speed, the
  relaxation two lead elements (+``tower_relax_db`` above ``tower_relax_omega``) where the
  damage sensitivity ΔD%(ω) is negligible (the waterbed of a higher-gain loop goes there;
  the paper's Fig. 7 shows the same excess at 2-5 rad/s). Both promises are reported: the
  notch specification's (``QFTDesign.shaping.promise``, what the paper's Table 3 lists) and
  the relaxed one's (``QFTDesign.promise``, smaller: the relaxation gives some back).
- generator speed ``speed``: |T_{Ω,w}| ≤ |T^ROSCO_{Ω,w,i}|·10^(speed_relax_db/20); by Bode's
  sensitivity integral a loop reshaped for fatigue cannot stay below ROSCO's everywhere, so
  :func:`design_qft` tries 3, 4.5, 6, 8 dB in turn and keeps the smallest that works.
- stability margins ``margin``: |1/(1 + L)| ≤ ``max_sensitivity`` on each loop with the other
  closed (1.9 guarantees GM ≥ 6.5 dB and PM ≥ 30.5°), and ``actuator_margin``: the same at
  the pitch actuator, |1/(1 + C_β P_{Ω,β} + C_atd P_{z,β})|, in general form for C_β.

Templates: linear models at neighbouring operating points v + ``template_offsets`` (m/s,
clipped to the model's above-rated range), nominal v.

Automatic design
----------------
Fixed structures (6 states in all):

    C_β(s)   = k·(s + z)/s · (s² + 2ζ_n ω_n s + ω_n²)/ω_n² · ω_d²/(s² + 2ζ_d ω_d s + ω_d²)
                           · ω_f²/(s² + 2ζ_f ω_f s + ω_f²),      k < 0
    C_atd(s) = k_a·(s/z_a + 1)/(s/p_a + 1),                        k_a < 0

started from ROSCO's PI and filter (the complex pair cancelled) and a weak ATD, tuned to:
minimise (σ_β̇/σ_β̇,ROSCO)² + 0.1·(σ_Ω/σ_Ω,ROSCO)² subject to a predicted tower-base DEL
reduction ≥ ``target_reduction`` (Dirlik on |T|²S_W, nominal case), every bound at every
design frequency for every case with a safety margin (0.1 dB on the stability specs, 0.02 dB
on the performance specs), and every closed loop (full interconnection, every case) with
poles left of −``min_decay`` 1/s. scipy's Powell method explores on exterior penalties, SLSQP
polishes the Powell end point and the start to KKT points of the constrained problem, and the
best candidate is kept by a total order (feasible first, then the smaller objective): a
polished optimum moves continuously with the data, so the design does not jump when the
wind speed moves by round-off (Powell's end point alone did). The two loops' bounds are then computed exactly with
:func:`loopshaping.qft.bounds` for the final controllers and the design is checked on a dense
grid over all cases with :func:`loopshaping.check.check`; frequencies where the dense check
fails are added to the design set and the tuning repeated (up to ``refine`` times).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import control as ct
import numpy as np

from ._checks import positive_scalar
from .closedloop import _named_siso, _require, check_stability, closed_loop, frequency_response, siso_response

__all__ = [
    "QFTDesign",
    "general_form",
    "partial_loop",
    "design_qft",
    "design_schedule",
    "design_table",
    "format_table",
    "DEFAULT_DESIGN_OMEGAS",
]

#: Default QFT design frequencies, rad/s: the wind band, the tower mode (~1.06 rad/s) and
#: the actuator band.
DEFAULT_DESIGN_OMEGAS = np.unique(np.r_[0.005, 0.007, np.logspace(-2, 1, 37), 0.9, 0.95, 1.0, 1.03, 1.05, 1.07, 1.1, 1.15, 1.2])

_OUTPUTS = ("gen_speed", "tower_base_my", "tower_top_vel", "pitch")
_INPUTS = ("wind", "pitch_cmd")
_SAFETY_DB = 0.1
_PERF_SAFETY_DB = 0.02
_DC_SAFETY_DB = 0.005


# ----------------------------------------------------------------------------- plant algebra
def _plant_responses(plants, omega, outputs=_OUTPUTS):
    """{(output, input): (n_omega, n_cases) complex} for a list of named plant LTIs."""

    return {
        (o, i): np.stack([frequency_response(P, omega, o, i) for P in plants], axis=1)
        for o in outputs for i in _INPUTS
    }


def _close_one(R, k, measurement, outputs):
    """Responses with β_cmd = u − k·m closed (k: complex array broadcastable to the responses)."""
    dk = 1 + k * R[(measurement, "pitch_cmd")]
    out = {}
    for y in outputs:
        yb = R[(y, "pitch_cmd")]
        out[(y, "wind")] = R[(y, "wind")] - yb * k * R[(measurement, "wind")] / dk
        out[(y, "pitch_cmd")] = yb / dk
    return out


def _coefficients(R, output, measurement):
    """General-form A, B, C, D for y = output with the loop on ``measurement`` open."""
    yw, yb = R[(output, "wind")], R[(output, "pitch_cmd")]
    nw, nb = R[(measurement, "wind")], R[(measurement, "pitch_cmd")]
    B = np.zeros_like(yw) if output == measurement else yw * nb - yb * nw
    return yw, B, np.ones_like(yw), nb


def general_form(plant, omega, output="tower_base_my", measurement="gen_speed", closed_controller=None,
                 closed_measurement="tower_top_vel"):
    """A, B, C, D of T_{output,w} = (A + B·G)/(C + D·G) for a controller G on ``measurement``.

    plant : named LTI (inputs ``wind``, ``pitch_cmd``) or a list of them (plant cases).
    omega : frequencies, rad/s.
    closed_controller : SISO LTI already closed on ``closed_measurement`` (sequential
        closure, β_cmd = u − K·m), or None.
    Returns four complex arrays of shape (n_omega,) for one plant or (n_omega, n_cases).
    Units: A in output units per m/s, D in measurement units per rad, B their product.
    """
    single = isinstance(plant, ct.LTI)
    plants = [plant] if single else list(plant)
    if not plants or not all(isinstance(p, ct.LTI) for p in plants):
        raise TypeError("plant must be a named python-control LTI system or a non-empty list of them")
    w = np.asarray(omega, float)
    outs = tuple(dict.fromkeys((output, measurement) + ((closed_measurement,) if closed_controller is not None else ())))
    R = _plant_responses(plants, w, outs)
    if closed_controller is not None:
        R = _close_one(R, siso_response(closed_controller, w)[:, None], closed_measurement, outs)
    A, B, C, D = _coefficients(R, output, measurement)
    if single:
        return A[:, 0], B[:, 0], C[:, 0], D[:, 0]
    return A, B, C, D


def partial_loop(plant, controller, measurement="tower_top_vel"):
    """The plant with one loop closed: β_cmd = u − controller·measurement.

    Returns a named StateSpace with inputs ``wind`` and ``pitch_cmd`` (now the free input u)
    and the plant's outputs: the "plant" the other controller sees in sequential closure.
    """

    if not isinstance(plant, ct.LTI):
        raise TypeError(f"plant must be a named python-control LTI system, got {type(plant).__name__}")
    _require(plant, "plant", inputs=_INPUTS, outputs=(measurement,))
    outs = list(plant.output_labels)
    p = ct.ss(plant)[outs, list(_INPUTS)]
    p = ct.ss(p.A, p.B, p.C, p.D, inputs=["wind", "beta"], outputs=outs, name="plant")
    k = _named_siso(controller, "controller", measurement, "u_k")
    sj = ct.summing_junction(inputs=["u_ext", "-u_k"], output="beta", name="sum")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=UserWarning)
        sys = ct.interconnect([p, k, sj], inplist=["wind", "u_ext"], outlist=outs, inputs=list(_INPUTS), outputs=outs,
                              name="partial_loop")
    return sys


# ----------------------------------------------------------------------------- structure
_NAMES = ("k", "z", "omega_n", "zeta_n", "omega_d", "zeta_d", "omega_f", "zeta_f", "k_atd", "z_atd", "p_atd")
_LOG = np.array([True, True, True, False, True, False, True, False, True, True, True])
_LOWER = np.array([1e-3, 0.01, 0.05, 0.1, 0.05, 0.3, 0.3, 0.3, 1e-4, 0.05, 0.02])
_UPPER = np.array([10.0, 5.0, 10.0, 1.5, 5.0, 1.5, 5.0, 1.2, 2.0, 20.0, 20.0])


def _to_x(params):
    p = np.array([abs(params[n]) if n in ("k", "k_atd") else params[n] for n in _NAMES], float)
    return np.where(_LOG, np.log(p), p)


def _from_x(x):
    p = np.where(_LOG, np.exp(x), x)
    out = dict(zip(_NAMES, map(float, p)))
    out["k"], out["k_atd"] = -out["k"], -out["k_atd"]
    return out


def _polys(x):
    p = _from_x(x)
    wn, wd, wf = p["omega_n"], p["omega_d"], p["omega_f"]
    nb = p["k"] * np.polymul([1.0, p["z"]], np.array([1.0, 2 * p["zeta_n"] * wn, wn * wn]) / wn**2) * wd**2 * wf**2
    db = np.polymul(np.polymul([1.0, 0.0], [1.0, 2 * p["zeta_d"] * wd, wd * wd]), [1.0, 2 * p["zeta_f"] * wf, wf * wf])
    na = p["k_atd"] * np.array([1.0 / p["z_atd"], 1.0])
    da = np.array([1.0 / p["p_atd"], 1.0])
    return nb, db, na, da


def _controllers(x, v):
    nb, db, na, da = _polys(x)
    tag = f"{v:g}mps".replace(".", "p")
    cb = ct.tf(nb, db, inputs="gen_speed", outputs="pitch_cmd", name=f"QFT_pitch@{tag}")
    ca = ct.tf(na / da[0], da / da[0], inputs="tower_top_vel", outputs="pitch_cmd", name=f"QFT_ATD@{tag}")
    return cb, ca


def _rosco_start(rosco):
    """Parameters reproducing ROSCO's C = (Kp + Ki/s)·ω_f²/(s² + 2ζω_f s + ω_f²), weak ATD."""
    num, den = np.asarray(rosco.num[0][0], float), np.asarray(rosco.den[0][0], float)
    wf2 = den[-2]
    kp, ki = num[-2] / wf2, num[-1] / wf2
    wf = np.sqrt(wf2)
    zf = den[1] / (2 * wf)
    if not (kp < 0 and ki < 0):
        # ROSCO's fitted Kp turns positive at high wind speeds (a right-half-plane PI zero):
        # start from its integral gain with a left-half-plane zero at 0.2 rad/s instead
        kp = ki / 0.2
    start = dict(k=kp, z=ki / kp, omega_n=1.0, zeta_n=0.7, omega_d=1.0, zeta_d=0.7, omega_f=wf, zeta_f=zf,
                 k_atd=-0.02, z_atd=4.0, p_atd=0.3)
    return np.clip(_to_x(start), _to_x_bounds()[0], _to_x_bounds()[1])


def _to_x_bounds():
    return np.where(_LOG, np.log(_LOWER), _LOWER), np.where(_LOG, np.log(_UPPER), _UPPER)


# ----------------------------------------------------------------------------- result
@dataclass(frozen=True, eq=False)
class QFTDesign:
    """One operating point's QFT design (frozen). All changes are designed vs ROSCO (ATD off),
    in %, positive = increase; reductions are positive = less.

    pitch_controller, atd_controller : python-control TFs (β_cmd = −C_β·Ω_g − C_atd·ẋ_top).
    baseline_controller : ROSCO's PI at the same speed.
    template_speeds : wind speeds of the plant cases (m/s); nominal at ``wind_speed``.
    design_omegas : QFT design frequencies, rad/s.
    pitch_bounds / atd_bounds : :class:`loopshaping.qft.Bounds` on L0 = C_β·P'_{Ω,β} (ATD
        closed) and on L0 = C_atd·P''_{z,β} (pitch loop closed); ``*_template`` their templates.
    pitch_check / atd_check : :class:`loopshaping.check.CheckResult` on ``dense_omegas``.
    bounds_met : every bound met at every design frequency (nominal loop, exact).
    all_stable : the full interconnection is stable for every plant case.
    del_reduction, damage_reduction : predicted tower-base DEL (1 Hz, m = 4) and damage
        reduction, Dirlik on |T|²S_W, nominal case.
    promise : :class:`specdesign.spec.Promise` of the (relaxed) tower specification.
    gen_speed_sd_change, pitch_sd_change, pitch_rate_sd_change : SD changes, %.
    gain_margin_db, phase_margin_deg : nominal pitch loop C_β·P'_{Ω,β} (ATD closed).
    atd_gain_margin_db, atd_phase_margin_deg : nominal ATD loop C_atd·P''_{z,β}.
    actuator_peak_sensitivity : max over ω and cases of |1/(1 + C_β P_{Ω,β} + C_atd P_{z,β})|.
    """

    wind_speed: float
    pitch_controller: object
    atd_controller: object
    baseline_controller: object
    template_speeds: tuple
    design_omegas: np.ndarray
    dense_omegas: np.ndarray
    tower_spec: object
    speed_spec: object
    shaping: object
    promise: object
    pitch_template: object
    atd_template: object
    pitch_bounds: object
    atd_bounds: object
    pitch_check: object
    atd_check: object
    closed_loop: object
    baseline: object
    bounds_met: bool
    all_stable: bool
    del_reduction: float
    damage_reduction: float
    gen_speed_sd_change: float
    pitch_sd_change: float
    pitch_rate_sd_change: float
    pitch_rate_sd: float
    gain_margin_db: float
    phase_margin_deg: float
    atd_gain_margin_db: float
    atd_phase_margin_deg: float
    actuator_peak_sensitivity: float
    target_reduction: float
    success: bool
    message: str
    parameters: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)

    @property
    def n_states(self) -> int:
        """Total controller order (pitch + ATD states)."""
        return int(ct.ss(self.pitch_controller).nstates + ct.ss(self.atd_controller).nstates)

    @property
    def is_proper(self) -> bool:
        def proper(tf):
            return len(np.trim_zeros(tf.num[0][0], "f")) <= len(np.trim_zeros(tf.den[0][0], "f"))

        return proper(self.pitch_controller) and proper(self.atd_controller)

    def row(self) -> dict:
        """One row of :func:`design_table`."""
        return {
            "wind_speed": self.wind_speed,
            "notch_promise_del_pct": self.shaping.promise.exact_del,
            "notch_promise_damage_pct": self.shaping.promise.exact_damage,
            "promised_del_pct": self.promise.exact_del,
            "promised_damage_pct": self.promise.exact_damage,
            "predicted_del_pct": self.del_reduction,
            "predicted_damage_pct": self.damage_reduction,
            "gen_speed_sd_change_pct": self.gen_speed_sd_change,
            "pitch_sd_change_pct": self.pitch_sd_change,
            "pitch_rate_sd_change_pct": self.pitch_rate_sd_change,
            "gain_margin_db": self.gain_margin_db,
            "phase_margin_deg": self.phase_margin_deg,
            "atd_gain_margin_db": self.atd_gain_margin_db,
            "atd_phase_margin_deg": self.atd_phase_margin_deg,
            "bounds_met": self.bounds_met,
            "dense_check_passed": bool(self.pitch_check.passed and self.atd_check.passed),
            "all_stable": self.all_stable,
            "n_states": self.n_states,
        }

    def summary(self) -> str:
        r = self.row()
        return (f"QFT design at {self.wind_speed:g} m/s: tower DEL reduced {r['predicted_del_pct']:.1f} % "
                f"(notch spec promises {r['notch_promise_del_pct']:.1f} %, relaxed spec {r['promised_del_pct']:.1f} %), "
                f"gen-speed SD {r['gen_speed_sd_change_pct']:+.1f} %, "
                f"pitch SD {r['pitch_sd_change_pct']:+.1f} %, pitch-rate SD {r['pitch_rate_sd_change_pct']:+.1f} %; "
                f"pitch loop GM {r['gain_margin_db']:.1f} dB PM {r['phase_margin_deg']:.1f}°, ATD loop GM "
                f"{r['atd_gain_margin_db']:.1f} dB PM {r['atd_phase_margin_deg']:.1f}°; bounds met: {self.bounds_met}, "
                f"dense check: {r['dense_check_passed']}, all {len(self.template_speeds)} cases stable: {self.all_stable}; "
                f"{self.message}")


# ----------------------------------------------------------------------------- the design
class _Problem:
    """Everything the tuning evaluates, precomputed on the design and analysis grids."""

    def __init__(self, model, v, speeds, nominal, design_omegas, tower_shaping, speed_relax_db, max_sensitivity,
                 base):
        from . import turbine

        self.v, self.speeds, self.nom = v, speeds, nominal
        self.plants = [model.linearize(s) for s in speeds]
        self.rosco = [turbine.rosco_baseline(model, s) for s in speeds]
        self.tower_shaping = tower_shaping  # callable ω → complex shaping (notches × relaxation)
        self.speed_gain = 10 ** (speed_relax_db / 20)
        self.ms = max_sensitivity
        self.base = base
        self.wf, self.S = base.omega, base.s_wind
        self.Rf = _plant_responses(self.plants, self.wf)
        self.pss = []
        for P in self.plants:
            p = ct.ss(P)[["gen_speed", "tower_top_vel"], "pitch_cmd"]
            if np.any(np.asarray(p.D) != 0):
                raise ValueError("the plant has a direct feedthrough pitch → measurement; not supported")
            self.pss.append((np.asarray(p.A), np.asarray(p.B), np.asarray(p.C)))
        c0 = siso_response(self.rosco[nominal], self.wf)[:, None]
        T0 = {y: self._t(self.Rf, c0, 0.0, y)[:, nominal] for y in ("tower_base_my", "gen_speed", "pitch")}
        from . import spectral

        self.d0 = float(spectral.damage_rate(self.wf, np.abs(T0["tower_base_my"]) ** 2 * self.S, base.m, method=base.method))
        self.sd0 = {"gen_speed": self._sd(T0["gen_speed"]), "pitch": self._sd(T0["pitch"]),
                    "pitch_rate": self._sd(T0["pitch"] * 1j * self.wf)}
        self.set_design(design_omegas)

    # closed-loop maps from responses
    @staticmethod
    def _t(R, c, k, y):
        yw, yb = R[(y, "wind")], R[(y, "pitch_cmd")]
        ow, ob = R[("gen_speed", "wind")], R[("gen_speed", "pitch_cmd")]
        zw, zb = R[("tower_top_vel", "wind")], R[("tower_top_vel", "pitch_cmd")]
        return (yw + c * (yw * ob - yb * ow) + k * (yw * zb - yb * zw)) / (1 + c * ob + k * zb)

    def _sd(self, t):
        return float(np.sqrt(np.trapezoid(np.abs(t) ** 2 * self.S, self.wf)))

    def weights(self, omega):
        """(W_Ω, W_MyT), each (n_omega, n_cases) magnitudes at ω (rad/s)."""
        R = _plant_responses(self.plants, omega, ("gen_speed", "tower_base_my", "tower_top_vel"))
        c = np.stack([siso_response(r, omega) for r in self.rosco], axis=1)
        w_speed = np.abs(self._t(R, c, 0.0, "gen_speed")) * self.speed_gain
        w_tower = np.abs(self._t(R, c, 0.0, "tower_base_my")) * np.abs(self.tower_shaping(omega))[:, None]
        return w_speed, w_tower

    def set_design(self, omegas):
        self.wd = np.asarray(omegas, float)
        self.Rd = _plant_responses(self.plants, self.wd, ("gen_speed", "tower_base_my", "tower_top_vel"))
        self.WO, self.WM = self.weights(self.wd)

    def margins(self, x):
        """Per-spec margins in dB on the design grid, (n_specs, n_omega, n_cases)."""
        nb, db, na, da = _polys(x)
        s = 1j * self.wd[:, None]
        c = np.polyval(nb, s) / np.polyval(db, s)
        k = np.polyval(na, s) / np.polyval(da, s)
        R = self.Rd
        to = self._t(R, c, k, "gen_speed")
        tm = self._t(R, c, k, "tower_base_my")
        ob, zb = R[("gen_speed", "pitch_cmd")], R[("tower_top_vel", "pitch_cmd")]
        d = 1 + c * ob + k * zb
        with np.errstate(divide="ignore"):
            return np.stack([
                20 * np.log10(self.WO / np.abs(to)),
                20 * np.log10(self.WM / np.abs(tm)),
                20 * np.log10(self.ms * np.abs(d) / np.abs(1 + k * zb)),  # pitch loop, ATD closed
                20 * np.log10(self.ms * np.abs(d) / np.abs(1 + c * ob)),  # ATD loop, pitch closed
                20 * np.log10(self.ms * np.abs(d)),  # at the actuator
            ])

    def max_real(self, x):
        """Largest closed-loop pole real part (1/s) per case, full interconnection."""
        from scipy.signal import tf2ss

        nb, db, na, da = _polys(x)
        A1, B1, C1, D1 = tf2ss(nb, db)
        A2, B2, C2, D2 = tf2ss(na, da)
        n1, n2 = A1.shape[0], A2.shape[0]
        out = []
        for A, B, C in self.pss:
            n = A.shape[0]
            M = np.zeros((n + n1 + n2,) * 2)
            M[:n, :n] = A - B @ (D1 @ C[0:1] + D2 @ C[1:2])
            M[:n, n:n + n1] = -B @ C1
            M[:n, n + n1:] = -B @ C2
            M[n:n + n1, :n] = B1 @ C[0:1]
            M[n:n + n1, n:n + n1] = A1
            M[n + n1:, :n] = B2 @ C[1:2]
            M[n + n1:, n + n1:] = A2
            out.append(np.linalg.eigvals(M).real.max())
        return np.array(out)

    def performance(self, x):
        """(DEL reduction %, damage reduction %, SD ratios gen speed, pitch, pitch rate) nominal."""
        from . import spectral

        key = np.asarray(x, float).tobytes()
        if getattr(self, "_perf_key", None) == key:  # the objective and the constraints ask for the same x
            return self._perf
        nb, db, na, da = _polys(x)
        s = 1j * self.wf[:, None]
        c = np.polyval(nb, s) / np.polyval(db, s)
        k = np.polyval(na, s) / np.polyval(da, s)
        tm = self._t(self.Rf, c, k, "tower_base_my")[:, self.nom]
        tp = self._t(self.Rf, c, k, "pitch")[:, self.nom]
        to = self._t(self.Rf, c, k, "gen_speed")[:, self.nom]
        d = float(spectral.damage_rate(self.wf, np.abs(tm) ** 2 * self.S, self.base.m, method=self.base.method))
        ratio = d / self.d0
        self._perf_key, self._perf = key, (
            100 * (1 - ratio ** (1 / self.base.m)), 100 * (1 - ratio), self._sd(to) / self.sd0["gen_speed"],
            self._sd(tp) / self.sd0["pitch"], self._sd(tp * 1j * self.wf) / self.sd0["pitch_rate"])
        return self._perf

    def objective(self, x):
        """The tuning objective: (σ_β̇/σ_β̇,ROSCO)² + 0.1·(σ_Ω/σ_Ω,ROSCO)², nominal case."""
        _, _, gs, _, rate = self.performance(x)
        return float(rate**2 + 0.1 * gs**2)

    def _safety(self):
        # the performance specs touch their weights at ω → 0 (integral action: every design
        # reaches the same DC response), so only the margin specs get a full safety margin
        return np.where(self.wd >= 0.05, _PERF_SAFETY_DB, _DC_SAFETY_DB)[None, :, None]

    def constraints(self, x, target, min_decay):
        """Every requirement as one vector that is ≥ 0 when met: bound margins (dB) less their
        safety margin per spec, frequency and case; DEL reduction − target (pp); decay margin
        −(max Re p + min_decay) per case (1/s)."""
        g = self.margins(x)
        return np.r_[(g[:2] - self._safety()).ravel(), (g[2:] - _SAFETY_DB).ravel(), self.performance(x)[0] - target,
                     -(self.max_real(x) + min_decay)]

    def cost(self, x, target, min_decay, weight=1e3):
        """Exterior-penalty cost of the exploration: objective + 10·(target − reduction)₊²
        + weight·Σ(bound violation, dB)²; a barrier (≥ 1e10) for decay-rate violations."""
        try:
            g = self.margins(x)
            red = self.performance(x)[0]
            mr = self.max_real(x)
        except (ValueError, np.linalg.LinAlgError, FloatingPointError):
            return 1e12
        if not (np.all(np.isfinite(g)) and np.isfinite(red) and np.all(np.isfinite(mr))):
            return 1e12
        viol = np.sum(np.minimum(g[:2] - self._safety(), 0.0) ** 2) + np.sum(np.minimum(g[2:] - _SAFETY_DB, 0.0) ** 2)
        excess = np.sum(np.maximum(mr + min_decay, 0.0))
        if excess > 0:  # a barrier: never trade stability for anything
            return float(1e10 * (1 + excess))
        return float(self.objective(x) + 10 * max(target - red, 0.0) ** 2 + weight * viol)


#: Largest constraint violation a polished candidate may keep and still count as feasible
#: (dB for bounds, pp for the DEL target, 1/s for the decay rate): SLSQP's own tolerance.
_FEASIBLE_TOL = 1e-6


def _tune(prob, x0, target, min_decay, maxfev):
    """Tune from ``x0``: explore, polish, and keep the best candidate by a total order.

    Returns (x, feasible): the chosen parameters and whether they meet every constraint.

    Powell on the penalty cost explores (a derivative-free search that gets past the kinks of
    the bounds from an infeasible start) but stops wherever its line searches happen to end,
    so its end point moves with round-off. Each candidate is therefore polished by SLSQP on the
    constrained problem (objective subject to :meth:`_Problem.constraints` ≥ 0) to a KKT point,
    which moves continuously with the data. Candidates: the polished Powell end point, the
    polished start, and the unpolished Powell end point. The order that picks one is total:
    feasible (every constraint ≥ −1e-6) before infeasible; among feasible ones the smaller
    objective; among infeasible ones the smaller penalty cost; ties by candidate order.
    """
    from scipy.optimize import minimize

    lo, hi = _to_x_bounds()
    box = list(zip(lo, hi))
    x = x0
    # exterior penalty method: the bound violations cost more and more (continuation)
    for weight in (1e3, 1e5, 1e7):
        with np.errstate(all="ignore"):
            res = minimize(prob.cost, x, args=(target, min_decay, weight), method="Powell", bounds=box,
                           options={"maxfev": int(maxfev), "xtol": 1e-4, "ftol": 1e-8})
        if np.all(np.isfinite(res.x)) and res.fun <= prob.cost(x, target, min_decay, weight):
            x = np.clip(res.x, lo, hi)

    def polish(start):
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            try:
                r = minimize(prob.objective, start, method="SLSQP", bounds=box,
                             constraints=[{"type": "ineq", "fun": prob.constraints, "args": (target, min_decay)}],
                             options={"maxiter": 300, "ftol": 1e-10})
            except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                return None
        return np.clip(r.x, lo, hi) if np.all(np.isfinite(r.x)) else None

    candidates = [c for c in (polish(x), polish(np.asarray(x0, float)), x) if c is not None]

    def key(c):
        with np.errstate(all="ignore"):
            try:
                g = prob.constraints(c, target, min_decay)
                if np.all(np.isfinite(g)) and g.min() >= -_FEASIBLE_TOL:
                    return (0, prob.objective(c))
                return (1, prob.cost(c, target, min_decay, 1e7))
            except (ValueError, np.linalg.LinAlgError, FloatingPointError):
                return (2, 0.0)

    keys = [key(c) for c in candidates]
    best = min(range(len(candidates)), key=lambda i: (keys[i], i))
    return candidates[best], keys[best][0] == 0


def _sharp_frequencies(prob, enabled=True, zeta_max=0.3, spread=(0.99, 1.0, 1.01)):
    """|p|·spread for lightly damped (ζ < zeta_max) poles and zeros of every case's ROSCO
    closed-loop maps wind → gen_speed and wind → tower_base_my, inside 0.005-20 rad/s."""

    if not enabled:
        return np.zeros(0)
    out = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for P, c in zip(prob.plants, prob.rosco):
            cl = closed_loop(P, c, warn=False)
            for y in ("gen_speed", "tower_base_my"):
                sys = cl[y, "wind"]
                for r in np.r_[ct.poles(sys), ct.zeros(sys)]:
                    wn = abs(r)
                    if wn > 0 and r.imag > 0 and -r.real / wn < zeta_max:
                        out.extend(wn * np.asarray(spread))
    w = np.asarray(out)
    return np.unique(w[(w >= 0.005) & (w <= 20.0)])


def _template_speeds(model, v, offsets):
    lo, hi = model.wind_range
    speeds = sorted({float(np.clip(v + o, lo, hi)) for o in offsets} | {v})
    return tuple(speeds), speeds.index(v)


def _callable(fn, key):
    def f(omegas):
        return fn(np.asarray(omegas, float))[key]

    return f


def design_qft(model, wind_speed, target_reduction=25.0, *, speed_relax_db=(3.0, 4.5, 6.0, 8.0), **kwargs) -> QFTDesign:
    """QFT design of C_β and C_atd at ``wind_speed`` (m/s) against the fatigue-based specs.

    Parameters
    ----------
    model : :class:`specdesign.turbine.TurbineModel` (e.g. ``turbine.iea15mw()``).
    wind_speed : operating point, m/s (above rated, inside ``model.wind_range``).
    target_reduction : predicted tower-base DEL reduction (1 Hz, m = 4) vs ROSCO to reach, %.
    spec_reduction : damage reduction (%) the notch-shaped tower specification promises
        (:func:`specdesign.spec.shape_to_target`, notches above ``keep_below`` rad/s).
    template_offsets : wind-speed offsets (m/s) of the neighbouring operating points.
    design_omegas : QFT design frequencies, rad/s (default :data:`DEFAULT_DESIGN_OMEGAS`).
    dense_omegas : grid of the final check, rad/s (default 600 points, 0.005-20 rad/s).
    speed_relax_db : relaxation of the generator-speed spec in dB (≥ 0), or an increasing
        sequence tried in turn (default 3, 4.5, 6, 8 dB): the design with the smallest
        relaxation that meets every spec is returned (else the last attempt, with a warning).
    tower_relax_db, tower_relax_omega : the tower spec is relaxed by this many dB above about
        this frequency (rad/s), where ΔD% is negligible (0 to disable).
    max_sensitivity : bound on |1/(1+L)| for both loops and at the actuator (> 1).
    min_decay : required closed-loop decay rate, 1/s (poles left of −min_decay).
    keep_below : protected band of the notch specification, rad/s (power regulation).
    refine : rounds adding the dense check's failing frequencies to the design set.
    maxfev : function evaluations per tuning round.

    Returns a :class:`QFTDesign`; ``success`` is False (with a message, and a RuntimeWarning)
    when the target, a bound, the dense check or stability is not met.
    """
    ladder = np.atleast_1d(np.asarray(speed_relax_db, float))
    if ladder.ndim != 1 or ladder.size == 0 or not np.all(np.isfinite(ladder)) or np.any(ladder < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB or a sequence of them")
    design = None
    for k, relax in enumerate(ladder):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            design = _design_single(model, wind_speed, target_reduction, speed_relax_db=float(relax), **kwargs)
        if design.success:
            return design
    warnings.warn(f"design_qft at {design.wind_speed:g} m/s (speed spec relaxed up to {ladder[-1]:g} dB): {design.message}",
                  RuntimeWarning, stacklevel=2)
    return design


def _design_single(model, wind_speed, target_reduction=25.0, *, spec_reduction=15.0, template_offsets=(-1.0, -0.5, 0.5, 1.0),
                   design_omegas=None, dense_omegas=None, speed_relax_db=3.0, tower_relax_db=6.0, tower_relax_omega=1.3,
                   max_sensitivity=1.9, min_decay=0.02, keep_below=0.6, refine=2, maxfev=3000) -> QFTDesign:
    """One design with a fixed speed-spec relaxation; see :func:`design_qft`."""
    from loopshaping import qft as lqft

    from . import spec as sp
    from . import turbine

    if not isinstance(model, turbine.TurbineModel):
        raise TypeError(f"model must be a specdesign.turbine.TurbineModel (e.g. turbine.iea15mw()), got {type(model).__name__}")
    v = model._check_wind(wind_speed)
    t = float(target_reduction)
    if not 0 < t < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a DEL reduction in % strictly between 0 and 100")
    for name, val in (("speed_relax_db", speed_relax_db), ("tower_relax_db", tower_relax_db)):
        if not (np.isfinite(val) and val >= 0):
            raise ValueError(f"{name}={val!r} must be a finite relaxation ≥ 0 dB")
    positive_scalar(tower_relax_omega, "tower_relax_omega")
    if not max_sensitivity > 1:
        raise ValueError(f"max_sensitivity={max_sensitivity!r} must be > 1 (|1/(1+L)| bound)")
    positive_scalar(min_decay, "min_decay")
    offsets = np.atleast_1d(np.asarray(template_offsets, float))
    if offsets.ndim != 1 or not np.all(np.isfinite(offsets)):
        raise ValueError("template_offsets must be a 1-D array of finite wind-speed offsets in m/s")
    wd = DEFAULT_DESIGN_OMEGAS.copy() if design_omegas is None else lqft.check_grid(design_omegas, "design_omegas")
    wdense = np.logspace(np.log10(0.005), np.log10(20.0), 600) if dense_omegas is None else lqft.check_grid(dense_omegas, "dense_omegas")

    speeds, nom = _template_speeds(model, v, offsets)
    base = sp.baseline_analysis(model, v)
    relax = ()
    if tower_relax_db > 0:
        half = tower_relax_db / 2
        relax = (sp.LeadLag(tower_relax_omega, tower_relax_omega * 10 ** (half / 20)),) * 2
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        shaping = sp.shape_to_target(base, spec_reduction, keep_below=keep_below)
    tower_spec = sp.Specification(base.system, tuple(shaping.notches) + relax, name="W_tower_base_my")
    promise = sp.evaluate(tower_spec, base)
    speed_spec = sp.speed_specification(model, v, margin_db=speed_relax_db)

    prob = _Problem(model, v, speeds, nom, wd, tower_spec.shaping, speed_relax_db, max_sensitivity, base)
    # Sharp features of the specs (the lightly damped tower-mode poles and zeros of every case's
    # ROSCO loop) are design frequencies and dense-check points too: a bound that holds on
    # both sides of a narrow dip of W can still fail inside it.
    sharp = _sharp_frequencies(prob, design_omegas is None)
    if sharp.size:
        prob.set_design(np.unique(np.r_[prob.wd, sharp]))
        wdense = np.unique(np.r_[wdense, sharp[(sharp >= wdense[0]) & (sharp <= wdense[-1])]])
    x = _rosco_start(prob.rosco[nom])
    rounds = 0
    while True:
        x, feasible = _tune(prob, x, t, min_decay, maxfev)
        cb, ca = _controllers(x, v)
        pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs = _checks(prob, cb, ca, wdense)
        bad = [w for chk in (pitch_check, atd_check) for name in chk.names for w in [chk.worst(name)] if w[1] < 0]
        # more design frequencies cannot rescue a design that already fails on the ones it has
        if not bad or not feasible or rounds >= refine:
            break
        new = np.unique(np.r_[prob.wd, [w[0] for w in bad]])
        if new.size == prob.wd.size:
            break
        prob.set_design(new)
        rounds += 1

    # exact bounds on the final design frequencies, for the Nichols charts and the bound check
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lqft.BoundsWarning)
        pitch_bounds = lqft.intersect(*[lqft.bounds(pitch_t, s_) for s_ in pitch_specs])
        atd_bounds = lqft.intersect(*[lqft.bounds(atd_t, s_) for s_ in atd_specs])
    bounds_met = _bounds_met(pitch_bounds, cb, pitch_t, prob.wd) and _bounds_met(atd_bounds, ca, atd_t, prob.wd)


    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stable = [check_stability(closed_loop(P, cb, ca, warn=False), tol=0.0) for P in prob.plants]
        cl = closed_loop(prob.plants[nom], cb, ca, warn=False)
    all_stable = bool(np.all(stable))
    red, dred, gs, ps, rate = prob.performance(x)
    Rdense = _plant_responses(prob.plants, wdense, ("gen_speed", "tower_top_vel"))
    cdn, kdn = siso_response(cb, wdense)[:, None], siso_response(ca, wdense)[:, None]
    peak_in = float(np.max(1 / np.abs(1 + cdn * Rdense[("gen_speed", "pitch_cmd")] + kdn * Rdense[("tower_top_vel", "pitch_cmd")])))
    nomp = pitch_t.nominal
    problems = []
    if red < t - 0.5:
        problems.append(f"DEL reduction {red:.1f} % below the target {t:g} %")
    if not bounds_met:
        problems.append("a bound is violated at a design frequency")
    if not pitch_check.passed:
        problems.append("dense check of the pitch loop failed: " + pitch_check.summary().replace("\n", "; "))
    if not atd_check.passed:
        problems.append("dense check of the ATD loop failed: " + atd_check.summary().replace("\n", "; "))
    if not all_stable:
        problems.append(f"unstable closed loops at {[speeds[i] for i, s_ in enumerate(stable) if not s_]} m/s")
    success = not problems
    message = "all specifications met" if success else "; ".join(problems)
    if not success:
        warnings.warn(f"design_qft at {v:g} m/s: {message}", RuntimeWarning, stacklevel=2)
    return QFTDesign(
        wind_speed=v, pitch_controller=cb, atd_controller=ca, baseline_controller=prob.rosco[nom],
        template_speeds=speeds, design_omegas=prob.wd.copy(), dense_omegas=wdense, tower_spec=tower_spec,
        speed_spec=speed_spec, shaping=shaping, promise=promise, pitch_template=pitch_t, atd_template=atd_t,
        pitch_bounds=pitch_bounds, atd_bounds=atd_bounds, pitch_check=pitch_check, atd_check=atd_check, closed_loop=cl,
        baseline=base, bounds_met=bool(bounds_met), all_stable=all_stable, del_reduction=float(red),
        damage_reduction=float(dred), gen_speed_sd_change=100 * (gs - 1), pitch_sd_change=100 * (ps - 1),
        pitch_rate_sd_change=100 * (rate - 1), pitch_rate_sd=float(rate * prob.sd0["pitch_rate"]),
        gain_margin_db=float(pitch_check.gain_margin_db[nomp]), phase_margin_deg=float(pitch_check.phase_margin_deg[nomp]),
        atd_gain_margin_db=float(atd_check.gain_margin_db[nomp]), atd_phase_margin_deg=float(atd_check.phase_margin_deg[nomp]),
        actuator_peak_sensitivity=peak_in, target_reduction=t, success=success, message=message, parameters=_from_x(x),
        options=dict(spec_reduction=spec_reduction, template_offsets=tuple(offsets), speed_relax_db=speed_relax_db,
                     tower_relax_db=tower_relax_db, tower_relax_omega=tower_relax_omega, max_sensitivity=max_sensitivity,
                     min_decay=min_decay, refine_rounds=rounds),
    )


def _checks(prob, cb, ca, wdense):
    """Templates, specs (general form, callables of ω) and dense checks of both loops."""
    from loopshaping import qft as lqft
    from loopshaping.check import check as lcheck

    plants, nom = prob.plants, prob.nom

    def data(omegas):
        w = np.asarray(omegas, float)
        R = _plant_responses(plants, w, ("gen_speed", "tower_base_my", "tower_top_vel"))
        c, k = siso_response(cb, w)[:, None], siso_response(ca, w)[:, None]
        W_speed, W_tower = prob.weights(w)
        Rp = _close_one(R, k, "tower_top_vel", ("gen_speed", "tower_base_my"))  # ATD closed: C_β's plant
        Ra = _close_one(R, c, "gen_speed", ("tower_top_vel", "tower_base_my", "gen_speed"))  # pitch closed: ATD's plant
        out = {"W_speed": W_speed, "W_tower": W_tower}
        for tag, RR, meas in (("p", Rp, "gen_speed"), ("a", Ra, "tower_top_vel")):
            for y in ("gen_speed", "tower_base_my"):
                A, B, C, D = _coefficients(RR, y, meas)
                out.update({f"{tag}{y}A": A, f"{tag}{y}B": B, f"{tag}{y}C": C, f"{tag}{y}D": D})
        out["pin_A"] = 1 / (1 + k * R[("tower_top_vel", "pitch_cmd")])
        out["zero"] = np.zeros_like(out["pin_A"])
        out["one"] = np.ones_like(out["pin_A"])
        out["pin_D"] = Rp[("gen_speed", "pitch_cmd")]
        return out

    cache = {}

    def fn(w):
        key = w.tobytes()
        if key not in cache:
            cache[key] = data(w)
        return cache[key]

    def general(tag, y, weight, name):
        return lqft.Spec("general", _callable(fn, weight), name=name,
                         kind_args={k: _callable(fn, f"{tag}{y}{k}") for k in "ABCD"})

    pitch_specs = [
        general("p", "gen_speed", "W_speed", "speed"),
        general("p", "tower_base_my", "W_tower", "tower"),
        lqft.Spec("sensitivity", prob.ms, name="margin"),
        lqft.Spec("general", prob.ms, name="actuator_margin",
                  kind_args={"A": _callable(fn, "pin_A"), "B": _callable(fn, "zero"), "C": _callable(fn, "one"),
                             "D": _callable(fn, "pin_D")}),
    ]
    atd_specs = [
        general("a", "gen_speed", "W_speed", "speed"),
        general("a", "tower_base_my", "W_tower", "tower"),
        lqft.Spec("sensitivity", prob.ms, name="margin"),
    ]
    pitch_plants = [partial_loop(P, ca, "tower_top_vel")["gen_speed", "pitch_cmd"] for P in plants]
    atd_plants = [partial_loop(P, cb, "gen_speed")["tower_top_vel", "pitch_cmd"] for P in plants]
    pitch_t = lqft.Template.from_systems(pitch_plants, prob.wd, nom)
    atd_t = lqft.Template.from_systems(atd_plants, prob.wd, nom)
    pitch_check = lcheck(pitch_t, cb, pitch_specs, wdense)
    atd_check = lcheck(atd_t, ca, atd_specs, wdense)
    return pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs


def _bounds_met(bounds, controller, template, omegas):
    L0 = template.nominal_response * siso_response(controller, template.omega)
    ok = bounds.is_allowed(template.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))
    return bool(np.all(ok))


def design_schedule(model, wind_speeds=(15, 17, 19, 21, 23, 25), target_reduction=25.0, **kwargs) -> tuple:
    """:func:`design_qft` at every wind speed (m/s); returns a tuple of :class:`QFTDesign`.

    ``target_reduction`` is a number or one value per wind speed; other keywords go to
    :func:`design_qft`.
    """
    vs = np.atleast_1d(np.asarray(wind_speeds, float))
    if vs.ndim != 1 or vs.size == 0:
        raise ValueError("wind_speeds must be a non-empty 1-D sequence of wind speeds in m/s")
    targets = np.broadcast_to(np.asarray(target_reduction, float), vs.shape)
    return tuple(design_qft(model, float(v), float(tr), **kwargs) for v, tr in zip(vs, targets))


def design_table(designs) -> list:
    """Rows (dicts) of the per-wind-speed table: promised vs predicted reduction, SD changes, margins."""
    designs = list(designs)
    if not all(isinstance(d, QFTDesign) for d in designs):
        raise TypeError("designs must be QFTDesign objects (from design_qft / design_schedule)")
    return [d.row() for d in designs]


def format_table(rows) -> str:
    """Markdown table of :func:`design_table` rows (reductions and changes in %, margins in dB/deg)."""
    head = ("| v [m/s] | notch-spec promise DEL [%] | relaxed-spec promise DEL [%] | predicted DEL red. [%] | predicted damage red. [%] | gen-speed SD [%] "
            "| pitch SD [%] | pitch-rate SD [%] | GM pitch [dB] | PM pitch [deg] | GM ATD [dB] | PM ATD [deg] "
            "| bounds | dense check | stable | states |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        lines.append(
            f"| {r['wind_speed']:g} | {r['notch_promise_del_pct']:.1f} | {r['promised_del_pct']:.1f} | {r['predicted_del_pct']:.1f} | {r['predicted_damage_pct']:.1f} "
            f"| {r['gen_speed_sd_change_pct']:+.1f} | {r['pitch_sd_change_pct']:+.1f} | {r['pitch_rate_sd_change_pct']:+.1f} "
            f"| {r['gain_margin_db']:.1f} | {r['phase_margin_deg']:.1f} | {r['atd_gain_margin_db']:.1f} "
            f"| {r['atd_phase_margin_deg']:.1f} | {'yes' if r['bounds_met'] else 'NO'} | {'pass' if r['dense_check_passed'] else 'FAIL'} "
            f"| {'yes' if r['all_stable'] else 'NO'} | {r['n_states']} |")
    return "\n".join(lines)
