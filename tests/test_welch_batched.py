"""welch_psd transforms every segment at once; scipy.signal.welch (its defaults: periodic Hann,
50 % overlap, segment mean removed, density scaling, one-sided) is the oracle it must equal."""
import numpy as np
import pytest
from scipy.signal import welch

from specdesign.validate import welch_psd


@pytest.mark.parametrize("shape, axis, nperseg", [
    ((6000,), -1, 1024),       # a campaign record: 600 s every 0.1 s, the default-sized segment
    ((4, 6000), -1, None),     # seeds × samples, default nperseg (1024)
    ((3, 2, 6001), -1, 1000),  # odd length, even segment
    ((777, 2), 0, 101),        # time on the first axis, odd segment
    ((5, 33), -1, 33),         # one segment covering the record, odd
    ((5, 40), 1, 17),          # odd segment, partial last hop dropped
    ((2, 50), -1, 64),         # nperseg longer than the record: clipped to the record, as scipy
])
def test_equals_scipy_welch(shape, axis, nperseg):
    dt = 0.1
    x = np.random.default_rng(sum(shape)).standard_normal(shape) + 3.0  # an offset: detrending matters
    omega, p = welch_psd(x, dt, nperseg, axis=axis)
    n = x.shape[axis]
    nps = 1024 if nperseg is None else min(nperseg, n)
    f, q = welch(x, fs=1.0 / dt, nperseg=nps, axis=axis)
    np.testing.assert_allclose(omega, 2.0 * np.pi * f, rtol=1e-12, atol=0)
    np.testing.assert_allclose(p, q / (2.0 * np.pi), rtol=1e-12, atol=0)


@pytest.mark.parametrize("nperseg", [0, -4, 2.5, True])
def test_bad_nperseg(nperseg):
    with pytest.raises(ValueError, match="nperseg"):
        welch_psd(np.ones(100), 0.1, nperseg)
