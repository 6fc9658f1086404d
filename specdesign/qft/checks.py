"""The checks a QFT design must pass: both loops' templates, specifications and dense checks.

Shared by the fixed-structure design (:mod:`specdesign.qft.design`) and the design from a
target specification's certificate (:mod:`specdesign.qft.certificate`). Units: ω in rad/s.
"""
from __future__ import annotations

import warnings

import numpy as np

from loopshaping import qft as lqft
from loopshaping.check import check as lcheck
from loopshaping.specs import controller_gain

from ..closedloop import (  # fine_pitch_lift: the qft checks' name for it (design_schedule's)
    close_responses,
    fine_pitch_lift,
    general_coefficients,
    partial_loop,
    plant_responses,
    siso_response,
)

__all__ = ["loop_checks", "bounds_met", "spec_ratio", "spec_roots", "fine_pitch_lift"]


def _callable(fn, key):
    def f(omega):
        return fn(np.asarray(omega, float))[key]

    return f


def loop_checks(prob, cb, ca, wdense):
    """Templates, specs (general form, callables of ω) and dense checks of both loops.

    Parameters
    ----------
    prob : specdesign.qft.tuner.TuningProblem
        The plant cases, their weights (:meth:`~specdesign.qft.tuner.TuningProblem.weights`),
        the design frequencies and ``max_sensitivity``.
    cb, ca : control.LTI
        Pitch controller C_β (rad per rad/s) and ATD controller C_atd (rad per m/s).
    wdense : numpy.ndarray
        Grid of the dense check, rad/s.

    Returns
    -------
    tuple
        (pitch_check, atd_check, pitch_template, atd_template, pitch_specs, atd_specs): the
        :class:`loopshaping.check.CheckResult` of each loop, its
        :class:`loopshaping.templates.Template` and its list of :class:`loopshaping.qft.Spec`.
        With ``prob.controller_bound`` the pitch loop's check includes "hf_gain", |C_β| ≤ the
        bound on its band (wdense's points there); the specs returned are the loops' own.
    """
    plants, nom = prob.plants, prob.nom

    def data(omega):
        w = np.asarray(omega, float)
        R = plant_responses(plants, w, ("gen_speed", "tower_base_my", "tower_top_vel"), method=prob.response_method)
        c, k = siso_response(cb, w)[:, None], siso_response(ca, w)[:, None]
        W_speed, W_tower = prob.weights(w)
        Rp = close_responses(R, k, "tower_top_vel", ("gen_speed", "tower_base_my"))  # ATD closed: C_β's plant
        Ra = close_responses(R, c, "gen_speed", ("tower_top_vel", "tower_base_my", "gen_speed"))  # pitch closed: ATD's plant
        out = {"W_speed": W_speed, "W_tower": W_tower}
        for tag, RR, meas in (("p", Rp, "gen_speed"), ("a", Ra, "tower_top_vel")):
            for y in ("gen_speed", "tower_base_my"):
                A, B, C, D = general_coefficients(RR, y, meas)
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
    # the controller's own high-frequency gain bound is checked with the pitch loop's specifications
    # (not a QFT bound of the loop: it is the same for every case)
    gain = [] if prob.controller_bound is None else [controller_gain(prob.controller_bound[0], prob.controller_bound[1],
                                                                     name="hf_gain")]
    pitch_check = lcheck(pitch_t, cb, pitch_specs + gain, wdense)
    atd_check = lcheck(atd_t, ca, atd_specs, wdense)
    return pitch_check, atd_check, pitch_t, atd_t, pitch_specs, atd_specs


def bounds_met(bounds, controller, template, omega):
    """Whether the nominal loop L₀ = P₀·C lies in the allowed region of every bound.

    Parameters
    ----------
    bounds : loopshaping.bounds.Bounds
        The (intersected) bounds.
    controller : control.LTI
        The controller of the loop.
    template : loopshaping.templates.Template
        The loop's template (its nominal response and frequencies, rad/s).
    omega : numpy.ndarray
        The design frequencies, rad/s (unused: the template's own are checked).

    Returns
    -------
    bool
        True when every design frequency's nominal point is allowed.
    """
    L0 = template.nominal_response * siso_response(controller, template.omega)
    with np.errstate(divide="ignore"):  # a zero loop (no ATD) lies at −∞ dB
        ok = bounds.is_allowed(template.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))
    return bool(np.all(ok))


def spec_ratio(spec_like, ref):
    """ω → W(jω)/T^ROSCO(jω): a given specification relative to ROSCO's map at the nominal speed.

    Each plant case's weight is its own ROSCO map times this ratio (a given pair's convention).

    Parameters
    ----------
    spec_like : object with ``response(omega)``
        The specification W at the nominal speed.
    ref : control.LTI
        ROSCO's closed-loop map at the nominal speed.

    Returns
    -------
    callable
        ω (rad/s) → complex ratio (-).
    """
    def f(omega):
        w = np.asarray(omega, float)
        return np.asarray(spec_like.response(w)) / siso_response(ref, w, "reference")

    return f


def spec_roots(spec_like) -> np.ndarray:
    """Poles and zeros (1/s) of a Specification's baseline and elements; none for other objects.

    The baseline's from its state space (accurate at high order): the dense checks refine their
    grid around the lightly damped ones, where a narrow dip of W could hide between points.

    Parameters
    ----------
    spec_like : object
        A :class:`specdesign.spec.Specification` (else an empty array is returned).

    Returns
    -------
    numpy.ndarray
        Finite complex roots, 1/s.
    """
    import control

    from ..spec import Specification

    if not isinstance(spec_like, Specification):
        return np.zeros(0, complex)
    with warnings.catch_warnings():  # python-control's notes on the conversion to state space
        warnings.filterwarnings("ignore", category=UserWarning, module=r"control\.")
        b = control.ss(spec_like.baseline)
        out = [np.asarray(b.poles(), complex), np.asarray(b.zeros(), complex)]
    for e in spec_like.elements:
        t = e.tf()
        out += [np.asarray(t.poles(), complex), np.asarray(t.zeros(), complex)]
    r = np.concatenate(out)
    return r[np.isfinite(r)]
