"""disc_coherence keeps its last results and computes the exponentials in one buffer: the
numbers must be bit for bit those of the plain expression of the docstring's quadrature."""
import numpy as np
import pytest

from specdesign import wind


def _plain(omega, u, radius):
    """The quadrature written as one expression (the code before the cache), the reference."""
    s = 0.5 * (np.polynomial.legendre.leggauss(160)[0] + 1.0)
    w_gl = np.polynomial.legendre.leggauss(160)[1]
    r = 2 * radius * s**2
    x = r / (2 * radius)
    p_r = 4 * r / (np.pi * radius**2) * (np.arccos(x) - x * np.sqrt(1 - x**2))
    weights = 0.5 * w_gl * p_r * (4 * radius * s)
    f = omega[:, None] / (2 * np.pi)
    return np.exp(-12 * np.sqrt((f * r / u) ** 2 + (0.12 * r / wind.COHERENCE_LENGTH) ** 2)) @ weights


@pytest.mark.parametrize("u, radius", [(3.0, 120.0), (19.0, 120.0), (25.0, 63.0)])
def test_cached_equals_uncached_bitwise(u, radius):
    n, dt = 6601, 0.1  # the synthesis grid of a 660 s record every 0.1 s
    omega = np.arange(1, (n - 1) // 2 + 1) * 2 * np.pi / (n * dt)
    first = wind.disc_coherence(omega, u, radius)
    again = wind.disc_coherence(omega.copy(), u, radius)  # a new array, same values: from the cache
    assert np.array_equal(first, _plain(omega, u, radius))
    assert np.array_equal(again, first)
    again[:] = 0.0  # the caller's copy: the cache is not touched
    assert np.array_equal(wind.disc_coherence(omega, u, radius), first)


def test_other_arguments_are_other_entries():
    omega = np.linspace(0.0, 3.0, 50)
    a = wind.disc_coherence(omega, 19.0, 120.0)
    b = wind.disc_coherence(omega, 19.0 + 1e-9, 120.0)
    c = wind.disc_coherence(omega[:-1], 19.0, 120.0)
    assert np.array_equal(b, _plain(omega, 19.0 + 1e-9, 120.0))
    assert np.array_equal(c, _plain(omega[:-1], 19.0, 120.0))  # a shorter grid is its own entry
    assert not np.array_equal(a, b)


def test_cache_clear_recomputes_the_same_bits():
    omega = np.linspace(0.0, 3.0, 40)
    a = wind.disc_coherence(omega, 11.0, 120.0)
    wind.disc_coherence.cache_clear()
    assert np.array_equal(wind.disc_coherence(omega, 11.0, 120.0), a)
