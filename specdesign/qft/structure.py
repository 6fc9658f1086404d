"""The fixed structures of the automatic QFT design and their parameter vector.

    C_β(s)   = k·(s + z)/s · (s² + 2ζ_n ω_n s + ω_n²)/ω_n² · ω_d²/(s² + 2ζ_d ω_d s + ω_d²)
                           · ω_f²/(s² + 2ζ_f ω_f s + ω_f²),      k < 0
    C_atd(s) = k_a·(s/z_a + 1)/(s/p_a + 1),                        k_a < 0

The tuner works on a vector x of the 11 parameters, frequencies and gains in logarithms
(:data:`LOG_SCALED`), inside [:data:`LOWER`, :data:`UPPER`] (rad/s, -, and |k| in rad per rad/s).
"""
from __future__ import annotations

import control as ct
import numpy as np

__all__ = ["PARAMETER_NAMES", "LOG_SCALED", "LOWER", "UPPER", "to_vector", "from_vector", "controller_polys",
           "controllers", "rosco_start", "vector_bounds"]

PARAMETER_NAMES = ("k", "z", "omega_n", "zeta_n", "omega_d", "zeta_d", "omega_f", "zeta_f", "k_atd", "z_atd", "p_atd")
LOG_SCALED = np.array([True, True, True, False, True, False, True, False, True, True, True])
LOWER = np.array([1e-3, 0.01, 0.05, 0.1, 0.05, 0.3, 0.3, 0.3, 1e-4, 0.05, 0.02])
UPPER = np.array([10.0, 5.0, 10.0, 1.5, 5.0, 1.5, 5.0, 1.2, 2.0, 20.0, 20.0])


def to_vector(params):
    p = np.array([abs(params[n]) if n in ("k", "k_atd") else params[n] for n in PARAMETER_NAMES], float)
    return np.where(LOG_SCALED, np.log(p), p)


def from_vector(x):
    p = np.where(LOG_SCALED, np.exp(x), x)
    out = dict(zip(PARAMETER_NAMES, map(float, p)))
    out["k"], out["k_atd"] = -out["k"], -out["k_atd"]
    return out


def controller_polys(x):
    p = from_vector(x)
    wn, wd, wf = p["omega_n"], p["omega_d"], p["omega_f"]
    nb = p["k"] * np.polymul([1.0, p["z"]], np.array([1.0, 2 * p["zeta_n"] * wn, wn * wn]) / wn**2) * wd**2 * wf**2
    db = np.polymul(np.polymul([1.0, 0.0], [1.0, 2 * p["zeta_d"] * wd, wd * wd]), [1.0, 2 * p["zeta_f"] * wf, wf * wf])
    na = p["k_atd"] * np.array([1.0 / p["z_atd"], 1.0])
    da = np.array([1.0 / p["p_atd"], 1.0])
    return nb, db, na, da


def controllers(x, v):
    nb, db, na, da = controller_polys(x)
    tag = f"{v:g}mps".replace(".", "p")
    cb = ct.tf(nb, db, inputs="gen_speed", outputs="pitch_cmd", name=f"QFT_pitch@{tag}")
    ca = ct.tf(na / da[0], da / da[0], inputs="tower_top_vel", outputs="pitch_cmd", name=f"QFT_ATD@{tag}")
    return cb, ca


def rosco_start(rosco):
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
    return np.clip(to_vector(start), vector_bounds()[0], vector_bounds()[1])


def vector_bounds():
    return np.where(LOG_SCALED, np.log(LOWER), LOWER), np.where(LOG_SCALED, np.log(UPPER), UPPER)
