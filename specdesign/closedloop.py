"""Closed-loop maps wind → output for a pitch controller and an optional tower-damping loop.

Sign convention (WORKBENCH.md): the pitch command is

    β_cmd = −C_β·Ω_g − C_atd·z,

C_β the pitch controller on generator speed Ω_g (ROSCO's PI with its speed filter, see
:func:`specdesign.turbine.rosco_baseline`) and C_atd the active tower damping (ATD)
controller on the tower-motion measurement z (``tower_top_vel`` by default). Both are
negative feedback; L = C_β·P_{Ω,β} is the loop QFT shapes. The generator-torque input is held
constant (zero deviation), as above rated.

Closing the loops by hand gives, with Δ = 1 + C_β P_{Ω,β} + C_atd P_{z,β},

    T_{y,w} = [P_{y,w} + C_β(P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w}) + C_atd(P_{y,w}P_{z,β} − P_{y,β}P_{z,w})] / Δ

(Eq. 4 of the paper is y = Ω_g without ATD, Eq. 5 y = MyT). :func:`closed_loop` builds the
same system with ``control.interconnect``; the tests check the two agree.
"""
from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ._checks import as_omega, as_psd, positive_scalar

__all__ = [
    "ClosedLoopUnstableWarning",
    "closed_loop_poles",
    "closed_loop_matrices",
    "loop_parts",
    "hidden_origin_poles",
    "unstable_poles",
    "unstable_message",
    "closed_loop",
    "check_stability",
    "frequency_response",
    "siso_response",
    "t_output_wind",
    "t_gen_speed_wind",
    "t_tower_wind",
    "output_psd",
    "closed_loop_del",
    "LoopMaps",
    "loop_maps",
]


class ClosedLoopUnstableWarning(UserWarning):
    """A closed loop has poles with non-negative real part."""


def _named_siso(sys, name, inp, out):
    import control

    if isinstance(sys, (int, float)):
        sys = control.tf([float(sys)], [1.0])
    if not isinstance(sys, control.LTI):
        raise TypeError(f"{name} must be a python-control LTI system (tf or ss), got {type(sys).__name__}")
    if sys.ninputs != 1 or sys.noutputs != 1:
        raise ValueError(f"{name} must be SISO, got {sys.noutputs} outputs × {sys.ninputs} inputs")
    ss = control.ss(sys)
    return control.ss(ss.A, ss.B, ss.C, ss.D, inputs=[inp], outputs=[out], name=name)


def _require(sys, name, inputs=(), outputs=()):
    missing = [s for s in inputs if s not in sys.input_labels] + [s for s in outputs if s not in sys.output_labels]
    if missing:
        raise ValueError(
            f"{name} lacks the named signals {missing}; it has inputs {sys.input_labels} and outputs "
            f"{sys.output_labels} (build it with specdesign.turbine or name them with control's inputs=/outputs=)"
        )


def closed_loop(plant, pitch_controller, atd_controller=None, atd_measurement="tower_top_vel", *, warn=True):
    """Close the pitch (and optional ATD) loop around ``plant`` with ``control.interconnect``.

    plant: named LTI with inputs ``wind`` and ``pitch_cmd`` (others, e.g. ``gen_torque``, held
    at zero) and outputs including ``gen_speed`` and, with ATD, ``atd_measurement``.
    pitch_controller: SISO LTI C_β (gen_speed rad/s → pitch rad); atd_controller: SISO LTI
    C_atd (measurement → pitch rad) or None. Returns a StateSpace with input ``wind`` and
    outputs all plant outputs plus ``pitch_cmd``; warns :class:`ClosedLoopUnstableWarning`
    when unstable (``warn=False`` to skip the check).
    """
    import control

    if not isinstance(plant, control.LTI):
        raise TypeError(f"plant must be a named python-control LTI system, got {type(plant).__name__}")
    needed = ["gen_speed"] + ([atd_measurement] if atd_controller is not None else [])
    _require(plant, "plant", inputs=("wind", "pitch_cmd"), outputs=needed)
    p = control.ss(plant)[list(plant.output_labels), ["wind", "pitch_cmd"]]
    p = control.ss(p.A, p.B, p.C, p.D, inputs=["wind", "pitch_cmd"], outputs=list(plant.output_labels), name="plant")
    systems = [p, _named_siso(pitch_controller, "pitch_controller", "gen_speed", "u_pitch")]
    terms = ["-u_pitch"]
    if atd_controller is not None:
        systems.append(_named_siso(atd_controller, "atd_controller", atd_measurement, "u_atd"))
        terms.append("-u_atd")
    systems.append(control.summing_junction(inputs=terms, output="pitch_cmd", name="pitch_sum"))
    outlist = list(plant.output_labels) + ["pitch_cmd"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=UserWarning)  # unused-signal notices for plant outputs
        sys = control.interconnect(systems, inplist=["wind"], outlist=outlist, inputs=["wind"], outputs=outlist, name="closed_loop")
    if warn:
        check_stability(sys, "closed loop")
    return sys


def check_stability(sys, name="system", tol=0.0):
    """True when every pole of ``sys`` has real part < −tol (1/s); otherwise warn
    :class:`ClosedLoopUnstableWarning` naming ``name`` and listing the offending poles, and return False.
    """
    poles = np.asarray(sys.poles())
    bad = poles[poles.real >= -tol]
    if bad.size:
        listing = ", ".join(f"{z.real:.4g}{z.imag:+.4g}j" for z in np.sort_complex(bad))
        warnings.warn(f"{name} is unstable: poles with Re ≥ {-tol:g} 1/s: {listing}", ClosedLoopUnstableWarning, stacklevel=2)
        return False
    return True


def frequency_response(sys, omega, output, input="wind"):
    """Complex frequency response of ``sys[output, input]`` at s = jω (omega in rad/s).

    ``sys`` is a named python-control LTI system; units are those of the output per unit input.
    """
    import control

    w = as_omega(omega, "omega")
    if not isinstance(sys, control.LTI):
        raise TypeError(f"sys must be a python-control LTI system, got {type(sys).__name__}")
    _require(sys, "sys", inputs=(input,), outputs=(output,))
    i = sys.input_labels.index(input)
    o = sys.output_labels.index(output)
    return np.asarray(sys(1j * w, squeeze=False))[o, i, :]


def _response(P, omega, output, input):
    """P is an LTI plant or a mapping {(output, input): complex array on omega}."""
    if isinstance(P, Mapping):
        try:
            r = np.asarray(P[(output, input)], dtype=complex)
        except KeyError:
            raise ValueError(f"P has no response for (output, input) = {(output, input)!r}; keys: {sorted(P)}") from None
        if r.shape != omega.shape:
            raise ValueError(f"P[{(output, input)!r}] has shape {r.shape}, expected {omega.shape} to match omega")
        return r
    return frequency_response(P, omega, output, input)


def siso_response(sys, omega, name="controller"):
    """Complex response at s = jω (omega in rad/s) of one SISO element of a loop.

    ``sys``: a SISO python-control LTI, a real scalar gain, None (an open loop: 0), or a
    complex array already evaluated on ``omega``. An integrator at ω = 0 gives inf without a
    warning: callers such as :func:`t_output_wind` take the limit there.
    """
    import control

    w = np.asarray(omega, dtype=float)
    if sys is None:
        return np.zeros(w.shape, complex)
    if isinstance(sys, (int, float)):
        return np.full(w.shape, complex(sys))
    if isinstance(sys, control.LTI):
        if sys.ninputs != 1 or sys.noutputs != 1:
            raise ValueError(f"{name} must be SISO, got {sys.noutputs}x{sys.ninputs}")
        with warnings.catch_warnings(), np.errstate(divide="ignore", invalid="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            if isinstance(sys, control.TransferFunction):
                s = 1j * w
                return np.polyval(sys.num[0][0], s) / np.polyval(sys.den[0][0], s)
            return np.asarray(sys(1j * w, squeeze=False))[0, 0, :].reshape(w.shape)
    c = np.asarray(sys, dtype=complex)
    if c.shape != w.shape:
        raise ValueError(f"{name} as a frequency response must have shape {w.shape} to match omega, got {c.shape}")
    return c


def t_output_wind(P, C, omega, output, atd_controller=None, atd_measurement="tower_top_vel"):
    """Closed-loop response wind → ``output`` at jω by the explicit formula (module docstring).

    P: named plant LTI or a mapping {(output, input): response}; C: pitch controller (LTI or its
    complex response on omega), sign β = −C·Ω_g; atd_controller likewise on
    ``atd_measurement``. omega in rad/s. Returns a complex array (output units per m/s).
    Where C is infinite (an integrator evaluated at ω = 0; |C| > 1e15 counts as infinite,
    since a state-space evaluation returns a huge finite number there) the limit C → ∞ is
    returned, (P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w})/P_{Ω,β}.
    """
    w = as_omega(omega, "omega")
    c = siso_response(C, w, "C")
    infinite = ~np.isfinite(c) | (np.abs(np.nan_to_num(c, nan=np.inf)) > 1e15)
    c = np.where(infinite, 0.0, c)
    p_yw, p_yb = _response(P, w, output, "wind"), _response(P, w, output, "pitch_cmd")
    p_ow, p_ob = _response(P, w, "gen_speed", "wind"), _response(P, w, "gen_speed", "pitch_cmd")
    num = p_yw + c * (p_yw * p_ob - p_yb * p_ow)
    den = 1 + c * p_ob
    if atd_controller is not None:
        k = siso_response(atd_controller, w, "atd_controller")
        p_zw, p_zb = _response(P, w, atd_measurement, "wind"), _response(P, w, atd_measurement, "pitch_cmd")
        num = num + k * (p_yw * p_zb - p_yb * p_zw)
        den = den + k * p_zb
    out = num / den
    if infinite.any():
        out[infinite] = ((p_yw * p_ob - p_yb * p_ow) / p_ob)[infinite]
    return out


def t_gen_speed_wind(P, C, omega, **atd):
    """Eq. (4): T_{Ω,w} = P_{Ω,w}/(1 + C·P_{Ω,β}) at jω ((rad/s) per (m/s)); see :func:`t_output_wind`."""
    return t_output_wind(P, C, omega, "gen_speed", **atd)


def t_tower_wind(P, C, omega, **atd):
    """Corrected Eq. (5): T_{MyT,w} = [P_{MyT,w} + C(P_{MyT,w}P_{Ω,β} − P_{MyT,β}P_{Ω,w})]/(1 + C·P_{Ω,β})
    at jω (N·m per m/s); see :func:`t_output_wind`."""
    return t_output_wind(P, C, omega, "tower_base_my", **atd)


def output_psd(sys, omega, wind_psd, output, input="wind"):
    """One-sided output PSD S_y = |T_{y,w}(jω)|²·S_W(ω) (output units² per rad/s).

    sys: closed-loop (or open-loop) named LTI; wind_psd: S_W on omega ((m/s)² per rad/s).
    """
    w = as_omega(omega, "omega")
    s_w = as_psd(wind_psd, w.size, "wind_psd")
    return np.abs(frequency_response(sys, w, output, input)) ** 2 * s_w


def closed_loop_del(sys, omega, wind_psd, m, output="tower_base_my", method="dirlik", input="wind"):
    """Damage-equivalent load at 1 Hz of ``output`` from its spectrum |T|²·S_W (a RANGE, output units).

    S-N curve N(S) = (S_ref/S)^m with S the cycle range; m the Wöhler exponent; method one of
    :func:`specdesign.spectral.damage_rate`'s ("dirlik", "narrowband", "tovo_benasciutti", ...).
    """
    from .spectral import del_spectral

    m = positive_scalar(m, "m")
    w = as_omega(omega, "omega")
    return float(del_spectral(w, output_psd(sys, w, wind_psd, output, input), m, method))


@dataclass(frozen=True)
class LoopMaps:
    """Open- and closed-loop wind maps on one grid (the paper's Fig. 1), complex arrays.

    omega (rad/s); gen_open / gen_closed: P_{Ω,w} and T_{Ω,w} ((rad/s) per (m/s));
    tower_open / tower_closed: P_{MyT,w} and T_{MyT,w} (N·m per m/s); controller: C_β(jω)
    (rad per rad/s); loop: L = C_β·P_{Ω,β} (-).
    """

    omega: np.ndarray
    gen_open: np.ndarray
    gen_closed: np.ndarray
    tower_open: np.ndarray
    tower_closed: np.ndarray
    controller: np.ndarray
    loop: np.ndarray


def loop_maps(plant, pitch_controller, omega, atd_controller=None, atd_measurement="tower_top_vel") -> LoopMaps:
    """Evaluate :class:`LoopMaps` for ``plant`` (named LTI) and controllers on ``omega`` (rad/s)."""
    w = as_omega(omega, "omega")
    c = siso_response(pitch_controller, w, "pitch_controller")
    atd = dict(atd_controller=atd_controller, atd_measurement=atd_measurement)
    return LoopMaps(
        omega=w,
        gen_open=frequency_response(plant, w, "gen_speed"),
        gen_closed=t_gen_speed_wind(plant, pitch_controller, w, **atd),
        tower_open=frequency_response(plant, w, "tower_base_my"),
        tower_closed=t_tower_wind(plant, pitch_controller, w, **atd),
        controller=c,
        loop=c * frequency_response(plant, w, "gen_speed", "pitch_cmd"),
    )


def loop_parts(model, controller, wind_speed):
    """The linearised loop at ``wind_speed`` (m/s) as :func:`specdesign.simulate.simulate` runs it.

    Returns ``(G, rows, K)``: ``G`` the plant's linearisation (``control.StateSpace``, inputs
    wind, pitch_cmd, gen_torque by position, deviations from trim), ``rows`` the indices of
    (gen_speed, tower_top_vel) among its outputs, and ``K`` the continuous 1×2 controller on
    them, β = −K·[Ω_g, ẋ_top] = −C_β·Ω_g − C_atd·ẋ_top. A ScheduledController is blended at the
    trim pitch of ``wind_speed`` (as :func:`specdesign.validate.closed_loop_response` blends it),
    its locals' integrators summed into one (:func:`specdesign.simulate.split_integrator`).
    ``model``: TurbineModel or KernelPlant with a linearisation.
    """
    import control

    from .simulate import ScheduledController, _as_lti, turbine_plant

    plant = turbine_plant(model)
    if plant.linearize is None:
        raise ValueError(f"plant {plant.name!r} has no linearisation: its closed-loop poles are unknown")
    G = control.ss(plant.linearize(wind_speed))
    names = list(plant.output_names)
    rows = [names.index("gen_speed"), names.index("tower_top_vel")]
    if isinstance(controller, ScheduledController):
        b0 = plant.trim(wind_speed)[1]
        K = controller.schedule_pitch.size
        w = [float(np.interp(b0, controller.schedule_pitch, np.eye(K)[q])) for q in range(K)]
        parts = [(w[q], controller.local(q)) for q in range(K) if w[q] != 0]
        # blend as the simulator runs the locals: the integrators (split_integrator) summed into
        # one, so two locals integrating the same error leave no spurious pole at s = 0
        cb = _blend([(wq, c) for wq, (c, _) in parts])
        ca = _blend([(wq, a) for wq, (_, a) in parts if a is not None])
    else:
        cb, ca = control.ss(_as_lti(controller, "controller")), control.ss([], [], [], [[0.0]])
    K2 = control.ss([], [], [], [[1.0, 1.0]]) * control.append(cb, ca)  # [C_β, C_atd]: 1×2
    return G, rows, K2


def closed_loop_matrices(model, controller, wind_speed, *, parts=None):
    """``(A, b)`` of the linearised closed loop at ``wind_speed`` (m/s): states [plant;
    controller] (:func:`loop_parts`, or its result ``parts``), ``b`` the column of the wind
    input (m/s)."""
    G, rows, K = loop_parts(model, controller, wind_speed) if parts is None else parts
    A, B, C, D = (np.asarray(x, dtype=float) for x in (G.A, G.B, G.C, G.D))
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (K.A, K.B, K.C, K.D))
    nk = Ak.shape[0] if K.nstates else 0
    Ak, Bk, Ck = Ak.reshape(nk, nk), Bk.reshape(nk, 2), Ck.reshape(1, nk)
    bw, bu = B[:, 0], B[:, 1]
    cm, dmw, dmu = C[rows], D[rows, 0], D[rows, 1]
    den = 1.0 + float(Dk[0] @ dmu)  # u = −K·(cm x + dmw w + dmu u): solved for u
    if abs(den) < 1e-12:
        raise ValueError("the loop is ill-posed: 1 + K(∞)·P(∞) = 0 (the controller cancels the plant's feedthrough)")
    ux, uc, uw = -(Dk[0] @ cm) / den, -Ck[0] / den, -float(Dk[0] @ dmw) / den
    mx, mc, mw = cm + np.outer(dmu, ux), np.outer(dmu, uc), dmw + dmu * uw
    Acl = np.block([[A + np.outer(bu, ux), np.outer(bu, uc)], [Bk @ mx, Ak + Bk @ mc]])
    return Acl, np.concatenate([bw + bu * uw, Bk @ mw])


#: Relative size (of the largest |pole|) under which a closed-loop pole counts as s = 0.
ORIGIN_TOL = 1e-9


def closed_loop_poles(model, controller, wind_speed) -> np.ndarray:
    """Poles (1/s) of the linearised turbine at ``wind_speed`` (m/s) closed by ``controller``.

    ``model``: TurbineModel or :class:`specdesign.simulate.KernelPlant` with a linearisation;
    ``controller``: anything :func:`specdesign.simulate.simulate` runs with a linear form (LTI,
    Controller, ScheduledController: blended at the trim pitch of ``wind_speed``, as
    :func:`specdesign.validate.closed_loop_response` blends it); β = −C_β·Ω_g − C_atd·ẋ_top.
    """
    return np.linalg.eigvals(closed_loop_matrices(model, controller, wind_speed)[0])


def hidden_origin_poles(A, b, poles=None) -> np.ndarray:
    """Boolean mask over ``poles`` (default: the eigenvalues of ``A``): poles at s = 0 (within
    :data:`ORIGIN_TOL`) whose mode the input ``b`` cannot excite (PBH test: left eigenvector
    ⟂ b), i.e. a conserved quantity such as ∫ẋ_top − x_top when an ATD controller integrates
    the tower-top velocity (a 1×2 H∞ controller split into its SISO pitch and ATD parts does).
    Such a mode neither grows nor responds to the wind: it is no instability."""
    import scipy.linalg

    lam, wl = scipy.linalg.eig(A, left=True, right=False)
    if poles is None:
        poles = lam
    scale = max(1.0, float(np.max(np.abs(lam), initial=0.0)))
    at0 = np.abs(lam) <= ORIGIN_TOL * scale
    nb = float(np.linalg.norm(b))
    hidden0 = at0 & (np.abs(wl.conj().T @ b) <= 1e-8 * np.linalg.norm(wl, axis=0) * max(nb, 1e-300))
    out = np.zeros(np.size(poles), bool)
    # match the given poles to the eigenvalues just computed (the same ones, maybe reordered)
    for z in lam[hidden0]:
        cand = np.flatnonzero(~out & (np.abs(np.asarray(poles) - z) <= ORIGIN_TOL * scale))
        if cand.size:
            out[cand[0]] = True
    return out


def unstable_poles(model, controller, wind_speed, *, parts=None) -> np.ndarray:
    """The closed-loop poles with Re ≥ 0 (1/s), sorted; empty when the loop is stable.

    A pole at s = 0 (within :data:`ORIGIN_TOL`) counts as unstable (the response to the wind
    would drift), unless the wind cannot excite its mode (:func:`hidden_origin_poles`).
    ``parts``: :func:`loop_parts` of the same arguments, if already at hand."""
    A, b = closed_loop_matrices(model, controller, wind_speed, parts=parts)
    p = np.linalg.eigvals(A)
    scale = max(1.0, float(np.max(np.abs(p), initial=0.0)))
    cand = (p.real >= 0) | (np.abs(p) <= ORIGIN_TOL * scale)
    if np.any(cand & (np.abs(p) <= ORIGIN_TOL * scale)):
        cand &= ~hidden_origin_poles(A, b, p)
    return np.sort_complex(p[cand])


def unstable_message(controller, wind_speed, poles) -> str:
    """One line naming the controller, the wind speed and its unstable poles."""
    name = getattr(controller, "name", None) or type(controller).__name__
    listing = ", ".join(f"{z.real:.4g}{z.imag:+.4g}j" for z in poles)
    return f"controller {name!r} destabilises the linearised turbine at {wind_speed:g} m/s (closed-loop poles {listing})"


def _blend(weighted):
    """Σ w·C as one state-space system with a single integrator: Σ w·r/s + Σ w·C_r."""
    import control

    from .simulate import split_integrator

    r, rest = 0.0, control.ss([], [], [], [[0.0]])
    for wq, c in weighted:
        rq, cr = split_integrator(c)
        r, rest = r + wq * rq, rest + wq * control.ss(cr)
    return rest + control.ss(control.tf([r], [1.0, 0.0])) if r != 0 else rest
