"""What a controller measures: sensor noise and the 3P ripple added to the plant's outputs.

The simulated plant's outputs are exact; a turbine's controller reads them through sensors.
:class:`SensorNoise` is the measurement model :func:`specdesign.simulate.simulate` applies
between the plant and every controller it runs (the compiled LTI and scheduled controllers,
ROSCO's torque law, and callable controllers such as the MPCs and ROSCO's DISCON), so every
controller of a comparison reads the same measurements. The recorded outputs stay the plant's
(the loads are those of the true motion); only what the controllers see is perturbed.

Model (one-sided PSDs per rad/s, as everywhere in the workbench)
----------------------------------------------------------------
* **White noise** on each measured signal, Gaussian, independent between signals, sampled at
  the controller's step ``dt`` and held over it. Its density is the sensor's, fixed by the SD
  ``sd`` of its samples at ``sample_time``: S_n = sd²·sample_time/π on 0 ≤ ω ≤ π/dt (flat up
  to the Nyquist frequency of the rate it is sampled at, zero above; its variance at step dt is
  S_n·π/dt, i.e. ``sd`` at dt = ``sample_time``). :meth:`SensorNoise.psd` returns it.
* **3P ripple** in the measured generator speed: A·sin(3ψ(t) + φ), ψ(t) = Ω_r·t, with Ω_r the
  rotor speed of the run's trim (generator speed of the trim divided by ``gear_ratio``), A
  = ``ripple_3p`` (rad/s) and φ uniform on [0, 2π) per run. It stands for the azimuth-locked
  3P line OpenFAST shows in the generator speed (shear, tilt, tower shadow, rotational sampling,
  which the rotor-effective wind of the reduced model averages out); its frequency is the trim's,
  not the simulated rotor's, so that it is the same for every controller (paired runs). A line
  of amplitude A holds variance A²/2 at ω_3P = 3·Ω_r (:meth:`SensorNoise.lines`).

Seeds: each (wind speed v, seed) run draws its noise from its own generator,
``numpy.random.default_rng([NOISE_ENTROPY, seed, round(10·v), signal])`` — the same (v, seed)
pair that names the wind record (:func:`specdesign.wind.seed_for`), a stream apart from the
wind's (which is seeded by one integer), one stream per signal. Every controller run on the
same (v, seed) reads the same noise: the comparison stays paired, and a run is reproducible to
the last bit.

Defaults (:data:`IEA15MW_SENSORS`): see ``docs/sensors.md`` for the sources. The simulator's
default is no noise (``noise=None``), which keeps every earlier result bit for bit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .._checks import as_omega, positive_scalar

__all__ = ["SensorNoise", "IEA15MW_SENSORS", "NOISE_ENTROPY", "MEASURED", "RIPPLE_3P_IEA15MW"]

#: First word of every noise generator's seed (ASCII "noise"): keeps the noise streams apart from
#: any generator seeded by a single integer, as the wind records are.
NOISE_ENTROPY = 0x6E6F697365
#: The measured signals that carry white noise, as plant output names → the field holding its SD.
MEASURED = {"gen_speed": "speed_sd", "tower_top_acc": "acc_sd", "tower_top_vel": "vel_sd",
            "blade_root_my": "blade_moment_sd"}
#: Amplitude (rad/s) of the 3P line in the IEA 15 MW's generator speed in OpenFAST v5.0.0: ROSCO on
#: the monopile deck at 19 m/s, steady wind with the deck's shear, the last 60 s of 120 s, fitted
#: locked to the azimuth: 4.90e-4 rad/s, 0.06 % of the rated 0.79 rad/s (``benchmarks/sensor_3p.py``;
#: docs/sensors.md gives the run and a turbulent one, 4.19e-4 rad/s).
RIPPLE_3P_IEA15MW = 4.9e-4


@dataclass(frozen=True)
class SensorNoise:
    """The measurement model between the plant and the controllers (see the module docstring).

    Parameters
    ----------
    speed_sd : float, optional
        SD of the white noise on the measured generator speed at ``sample_time``, rad/s.
    ripple_3p : float, optional
        Amplitude of the 3P line added to the measured generator speed, rad/s (0: none).
    acc_sd : float, optional
        SD of the white noise on the tower-top fore-aft acceleration at ``sample_time``, m/s².
    vel_sd : float, optional
        SD of the white noise on the tower-top fore-aft velocity at ``sample_time``, m/s (the
        active tower damper's input).
    blade_moment_sd : float, optional
        SD of the white noise on the blade-root flapwise moment at ``sample_time``, N·m.
    sample_time : float, optional
        The step at which the SDs above are the samples' SDs, s (their densities are
        SD²·sample_time/π per rad/s; default 0.02 s, the simulator's default step).
    gear_ratio : float, optional
        Generator speed over rotor speed (-): the simulator takes the rotor speed of the 3P as
        Ω_g,trim/gear_ratio (1 for the direct-drive IEA 15 MW).
    stream : int, optional
        Another realisation of the same model for the same runs (0: the default stream).

    Examples
    --------
    >>> n = SensorNoise(speed_sd=0.005)
    >>> n.psd("gen_speed", [1.0, 200.0], dt=0.02) == [0.005**2 * 0.02 / np.pi, 0.0]  # zero above π/dt
    array([ True,  True])
    """

    speed_sd: float = 0.0
    ripple_3p: float = 0.0
    acc_sd: float = 0.0
    vel_sd: float = 0.0
    blade_moment_sd: float = 0.0
    sample_time: float = 0.02
    gear_ratio: float = 1.0
    stream: int = 0

    def __post_init__(self):
        for name in ("speed_sd", "ripple_3p", "acc_sd", "vel_sd", "blade_moment_sd"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float, np.floating, np.integer)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"{name}={v!r} must be a finite number ≥ 0 (SI units, see SensorNoise)")
        positive_scalar(self.sample_time, "sample_time")
        positive_scalar(self.gear_ratio, "gear_ratio")
        if not isinstance(self.stream, (int, np.integer)) or self.stream < 0:
            raise ValueError(f"stream={self.stream!r} must be a non-negative integer")

    @property
    def active(self) -> bool:
        """True if any signal is perturbed."""
        return any(getattr(self, f) > 0 for f in (*MEASURED.values(), "ripple_3p"))

    def sd(self, signal: str, dt: float) -> float:
        """SD of the white noise on ``signal`` sampled at step ``dt``: the same density, so
        sd·√(sample_time/dt).

        Parameters
        ----------
        signal : str
            One of :data:`MEASURED`.
        dt : float
            The sample time, s.

        Returns
        -------
        float
            The SD in the signal's SI unit (rad/s, m/s², m/s, N·m).

        Raises
        ------
        ValueError
            For a signal that is not one of :data:`MEASURED`.
        """
        if signal not in MEASURED:
            raise ValueError(f"signal={signal!r} carries no modelled noise; one of {sorted(MEASURED)}")
        return getattr(self, MEASURED[signal]) * math.sqrt(self.sample_time / positive_scalar(dt, "dt"))

    def psd(self, signal: str, omega: ArrayLike, dt: float) -> np.ndarray:
        """One-sided PSD of the white noise on ``signal`` sampled at step ``dt`` (s), per rad/s.

        Flat at SD²·sample_time/π up to the Nyquist frequency π/dt, zero above (the 3P line is
        not a density: :meth:`lines`).

        Parameters
        ----------
        signal : str
            One of :data:`MEASURED` (``"gen_speed"``: (rad/s)²/(rad/s)).
        omega : array_like
            Frequencies, rad/s (≥ 0).
        dt : float
            The controller's sample time, s.

        Returns
        -------
        numpy.ndarray
            The PSD on ``omega``.
        """
        w = as_omega(omega)
        level = self.sd(signal, dt) ** 2 * dt / math.pi
        return np.where(w <= math.pi / dt, level, 0.0)

    def lines(self, rotor_speed: float) -> tuple[float, float]:
        """The 3P line in the measured generator speed at an operating point.

        Parameters
        ----------
        rotor_speed : float
            The trim's rotor speed Ω_r, rad/s.

        Returns
        -------
        tuple of float
            (ω_3P = 3·Ω_r rad/s, its variance A²/2 in (rad/s)²).
        """
        return 3.0 * positive_scalar(rotor_speed, "rotor_speed"), 0.5 * self.ripple_3p ** 2

    def series(self, signal: str, wind_speeds: ArrayLike, seeds: ArrayLike, nsteps: int, dt: float,
               rotor_speeds: ArrayLike | None = None) -> np.ndarray:
        """The noise added to ``signal`` at every controller step of every run.

        Parameters
        ----------
        signal : str
            One of :data:`MEASURED`.
        wind_speeds : array_like
            (W,) mean wind speeds of the runs, m/s.
        seeds : array_like of int
            (S,) the runs' seeds (non-negative).
        nsteps : int
            Steps per run (at t = k·dt, k = 0 … nsteps − 1).
        dt : float
            The controller's step, s.
        rotor_speeds : array_like, optional
            (W,) the trims' rotor speeds, rad/s: needed for the 3P ripple of ``"gen_speed"``.

        Returns
        -------
        numpy.ndarray
            (W, S, nsteps) noise in the signal's SI unit (zeros if the signal has none).
        """
        vs = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
        ss = np.atleast_1d(np.asarray(seeds))
        if ss.ndim != 1 or not np.issubdtype(ss.dtype, np.integer) or np.any(ss < 0):
            raise ValueError(f"seeds={seeds!r} must be non-negative integers, one per record")
        sd = self.sd(signal, dt)
        ripple = signal == "gen_speed" and self.ripple_3p > 0
        if ripple:
            if rotor_speeds is None:
                raise ValueError("rotor_speeds (the trims' rotor speeds, rad/s) are needed for the 3P ripple")
            gs = np.atleast_1d(np.asarray(rotor_speeds, dtype=float))
            if gs.shape != vs.shape:
                raise ValueError(f"rotor_speeds must have one entry per wind speed ({vs.size}), got {gs.shape}")
        out = np.zeros((vs.size, ss.size, int(nsteps)))
        if sd == 0 and not ripple:
            return out
        t = np.arange(int(nsteps)) * dt
        code = list(MEASURED).index(signal)
        for i, v in enumerate(vs):
            for j, s in enumerate(ss):
                rng = np.random.default_rng([NOISE_ENTROPY, int(s), int(round(10.0 * v)), code, int(self.stream)])
                phase = rng.uniform(0.0, 2.0 * math.pi)  # drawn first, whatever nsteps: the same phase for any length
                if sd > 0:
                    out[i, j] = sd * rng.standard_normal(int(nsteps))
                if ripple:
                    w3, _ = self.lines(gs[i])
                    out[i, j] += self.ripple_3p * np.sin(w3 * t + phase)
        return out


#: The documented sensors of the IEA 15 MW (docs/sensors.md): generator-speed noise of 0.005 rad/s
#: (0.6 % of rated: the quantisation of a 14-bit encoder differenced at 50 Hz, 2π/(2¹⁴·0.02 s)/√12
#: = 0.0055 rad/s; an assumption, not a measurement), the 3P ripple OpenFAST shows
#: (:data:`RIPPLE_3P_IEA15MW`), an accelerometer of 100 µg/√Hz (0.0049 m/s² over the 25 Hz of a
#: 50 Hz sampling), a velocity from it by a 0.1 rad/s leaky integrator (0.002 m/s) and a strain
#: gauge of 0.1 % of the ~50 MN·m blade-root moment at rated.
IEA15MW_SENSORS = SensorNoise(speed_sd=0.005, ripple_3p=RIPPLE_3P_IEA15MW, acc_sd=0.005, vel_sd=0.002,
                              blade_moment_sd=5.0e4)
