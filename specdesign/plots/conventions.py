"""One set of figure and table conventions, used by every figure of the workbench.

- **Transfer functions and spectra in SI.** A magnitude |T_{y,w}| is drawn in dB re 1 SI unit
  of the output per m/s of wind (tower-base moment: dB re 1 N·m/(m/s); generator speed:
  dB re 1 (rad/s)/(m/s)); a PSD in SI units² per rad/s; ω in rad/s. These are the quantities
  the equations use, so a number read off a figure goes into them unconverted.
- **Time series and tables in engineering units**, labelled: generator speed in rpm, pitch in
  degrees, moments in MN·m, power in MW (:data:`TIME_SERIES`).
- **Changes and reductions.** A *change* is signed, 100·(X/X_baseline − 1) %: negative means
  lower than the baseline (Table 2, comparison figures). A *reduction* is
  100·(1 − X/X_baseline) %: positive means lower (Table 3, the promise, Fig. 10). The two name
  the same number with opposite signs, and every label says which it is.
- **Standard errors** (jackknife over paired seeds) are shown only from
  :data:`MIN_SEEDS_FOR_SE` paired seeds on; with fewer the spread is not estimated.
- **Nichols charts**: open-loop magnitude in dB vs phase in degrees, the critical point
  (−180°, 0 dB) marked.
"""
from __future__ import annotations

import numpy as np

__all__ = ["SI_UNITS", "TIME_SERIES", "MIN_SEEDS_FOR_SE", "tf_magnitude_label", "show_se"]

#: SI unit of each named output of the turbine models.
SI_UNITS = {
    "tower_base_my": "N·m", "blade_root_my": "N·m", "gen_speed": "rad/s", "omega_g": "rad/s", "rotor_speed": "rad/s",
    "pitch": "rad", "power": "W", "gen_torque": "N·m", "tower_top_acc": "m/s²", "tower_top_vel": "m/s",
    "tower_top_disp": "m",
}

#: Time-series display: output → (factor from SI, unit label).
TIME_SERIES = {
    "gen_speed": (60.0 / (2.0 * np.pi), "rpm"),
    "tower_base_my": (1e-6, "MN·m"),
    "blade_root_my": (1e-6, "MN·m"),
    "power": (1e-6, "MW"),
    "pitch": (180.0 / np.pi, "deg"),
}

#: Fewest paired seeds from which a standard error is shown: the method paper's campaign size
#: (4 seeds per wind speed); a jackknife over 2 or 3 seeds says little about the spread.
MIN_SEEDS_FOR_SE = 4


def tf_magnitude_label(output: str) -> str:
    """Axis label of a wind → ``output`` transfer-function magnitude, dB re 1 SI unit per m/s.

    Parameters
    ----------
    output : str
        Output name (a key of :data:`SI_UNITS`; another name gets a generic label).

    Returns
    -------
    str
        The label, e.g. ``"magnitude (dB re 1 N·m/(m/s))"``.

    Examples
    --------
    >>> tf_magnitude_label("tower_base_my")
    'magnitude (dB re 1 N·m/(m/s))'
    >>> tf_magnitude_label("gen_speed")
    'magnitude (dB re 1 (rad/s)/(m/s))'
    """
    unit = SI_UNITS.get(output)
    if unit is None:
        return "magnitude (dB re 1 output unit/(m/s))"
    return f"magnitude (dB re 1 {'(' + unit + ')' if '/' in unit else unit}/(m/s))"


def show_se(n_seeds: int) -> bool:
    """Whether a standard error over ``n_seeds`` paired seeds is shown (:data:`MIN_SEEDS_FOR_SE`).

    Parameters
    ----------
    n_seeds : int
        Number of paired seeds behind the standard error.

    Returns
    -------
    bool
        True from :data:`MIN_SEEDS_FOR_SE` seeds on.

    Examples
    --------
    >>> show_se(2), show_se(4)
    (False, True)
    """
    return int(n_seeds) >= MIN_SEEDS_FOR_SE
