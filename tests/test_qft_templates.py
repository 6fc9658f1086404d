"""Templates (constructors, disk uncertainty) and the Nichols plane (numbers and drawings)."""
from __future__ import annotations

import control as ct
import matplotlib
import numpy as np
import pytest

from loopshaping import nichols, qft

from test_qft_bounds import G_PUBLISHED, OMEGAS, manual_cases

matplotlib.use("Agg")
s = ct.tf("s")


def plant(k, a, b):
    return ct.tf([k], [1, a + b, a * b])


def test_from_systems_matches_python_control():
    cases, nom = manual_cases()
    t = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    assert t.responses.shape == (4, 40) and t.nominal == 10
    for i in (0, 17, 39):
        np.testing.assert_allclose(t.responses[:, i], np.squeeze(ct.frequency_response(cases[i], OMEGAS).complex), rtol=1e-12)
    np.testing.assert_allclose(t.nominal_response, 1 / ((1j * OMEGAS + 1) * (1j * OMEGAS + 30)), rtol=1e-12)
    sub = t.at([5.0, 100.0])
    np.testing.assert_array_equal(sub.responses, t.responses[[1, 3]])


def test_parameter_grid_edges_and_full_box():
    ranges = {"k": (1, 10), "a": (1, 5), "b": (20, 30)}
    edges = qft.Template.from_parameter_grid(plant, ranges, OMEGAS, n=10, edges_only=True,
                                             nominal={"k": 1, "a": 1, "b": 30})
    # A 3-D box has 8 vertices and 12 edges with 8 interior points each.
    assert edges.n_cases == 8 + 12 * 8
    interior = np.zeros(edges.n_cases, int)
    for j, (lo, hi) in enumerate(ranges.values()):
        interior += (edges.parameters[:, j] > lo) & (edges.parameters[:, j] < hi)
    assert interior.max() == 1
    np.testing.assert_array_equal(edges.parameters[edges.nominal], [1, 1, 30])
    for i in (0, 50, 103):
        k, a, b = edges.parameters[i]
        np.testing.assert_allclose(edges.responses[:, i], k / ((1j * OMEGAS + a) * (1j * OMEGAS + b)), rtol=1e-12)
    # The toolbox's 40-case template lies on four of these edges.
    cases, _ = manual_cases()
    manual = qft.Template.from_systems(cases, OMEGAS)
    d = np.abs(manual.responses[:, :, None] - edges.responses[:, None, :]).max(axis=0)
    assert d.min(axis=1).max() < 1e-12
    full = qft.Template.from_parameter_grid(plant, ranges, OMEGAS, n=4)
    assert full.n_cases == 64
    off = qft.Template.from_parameter_grid(plant, ranges, OMEGAS, n=4, nominal={"k": 2.5, "a": 2.2, "b": 25})
    assert off.n_cases == 65 and off.nominal == 64


def test_operating_points_interpolate_between_neighbours():
    Ps = [plant(1, 1, 20), plant(2, 2, 25), plant(3, 4, 30)]
    t = qft.Template.from_operating_points(Ps, OMEGAS, nominal=1, n_between=3)
    assert t.n_cases == 3 + 2 * 3
    r = [np.squeeze(ct.frequency_response(P, OMEGAS).complex) for P in Ps]
    np.testing.assert_allclose(t.nominal_response, r[1], rtol=1e-12)
    np.testing.assert_allclose(t.responses[:, 2], 0.5 * r[0] + 0.5 * r[1], rtol=1e-10)
    np.testing.assert_allclose(t.responses[:, 5], 0.75 * r[1] + 0.25 * r[2], rtol=1e-10)


def test_disk_expansion_lies_on_the_circles():
    w = np.array([1.0, 2.0])
    P = np.array([[1 + 1j, 2.0], [0.5j, -1.0]])
    t = qft.Template.from_responses(w, P, disk_radius=[0.1, 0.3])
    e = t.expanded(n_disk=12)
    assert e.shape == (2, 2 * 13)
    ring = e[:, 2:].reshape(2, 2, 12)
    dist = np.abs(ring - P[:, :, None]) / np.abs(P[:, :, None])
    np.testing.assert_allclose(dist, np.broadcast_to(np.array([0.1, 0.3])[:, None, None], dist.shape), rtol=1e-12)
    assert qft.Template.from_responses(w, P).expanded() is not None
    np.testing.assert_array_equal(qft.Template.from_responses(w, P).expanded(), P)


def test_template_validation():
    with pytest.raises(ValueError, match="increasing"):
        qft.Template.from_responses([2.0, 1.0], np.ones((2, 1)))
    with pytest.raises(ValueError, match="nominal"):
        qft.Template.from_responses([1.0], np.ones((1, 3)), nominal=3)
    with pytest.raises(ValueError, match="finite"):
        qft.Template.from_systems([1 / (s**2 + 1)], [1.0])
    with pytest.raises(ValueError, match="disk_radius"):
        qft.Template.from_responses([1.0], np.ones((1, 1)), disk_radius=-0.1)
    with pytest.raises(ValueError, match="empty"):
        qft.Template.from_systems([], [1.0])
    with pytest.raises(ValueError, match="SISO"):
        qft.Template.from_systems([ct.rss(2, 2, 1)], [1.0])
    with pytest.raises(ValueError, match="ranges"):
        qft.Template.from_parameter_grid(plant, {"k": (2, 1)}, [1.0])
    with pytest.raises(ValueError, match="not design frequencies"):
        qft.Template.from_responses([1.0, 2.0], np.ones((2, 1))).at([3.0])


def test_template_nichols_coordinates():
    cases, nom = manual_cases()
    t = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    ph, mag = nichols.template_nichols(t)
    np.testing.assert_allclose(10 ** (mag / 20) * np.exp(1j * np.deg2rad(ph)), t.responses, rtol=1e-12)
    assert np.all(np.abs(ph - ph[:, [nom]]) <= 180)


def test_m_contour_has_constant_closed_loop_gain():
    for m_db in (-3.0, 1.58, 6.0):
        ph, mag = nichols.m_contour(m_db)
        ok = ~np.isnan(mag)
        L = 10 ** (mag[ok] / 20) * np.exp(1j * np.deg2rad(ph[ok]))
        np.testing.assert_allclose(20 * np.log10(np.abs(L / (1 + L))), m_db, atol=1e-9)


def test_loop_nichols_window_and_continuity():
    w = np.logspace(-2, 3, 500)
    L = plant(1, 1, 30) * G_PUBLISHED / s
    ph, mag = nichols.loop_nichols(L, w)
    assert -360 <= ph[0] <= 0
    assert np.max(np.abs(np.diff(ph))) < 20
    Lw = np.squeeze(ct.frequency_response(L, w).complex)
    np.testing.assert_allclose(mag, 20 * np.log10(np.abs(Lw)), rtol=1e-12)
    np.testing.assert_allclose(np.exp(1j * np.deg2rad(ph)), Lw / np.abs(Lw), atol=1e-9)


def test_draw_and_plot_templates_return_labelled_axes():
    import matplotlib.pyplot as plt

    cases, nom = manual_cases()
    t = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    b = qft.intersect(qft.bounds(t, "stability", 1.2), qft.bounds(t, "input_disturbance", 0.01, band=(0, 10)))
    L0 = cases[nom] * G_PUBLISHED
    ax = nichols.draw(b, loop=L0, m_contours_db=[1.58])
    assert ax.get_xlabel() == "Open-loop phase [deg]" and ax.get_ylabel() == "Open-loop magnitude [dB]"
    labels = [h.get_label() for h in ax.get_legend().legend_handles]
    assert "nominal loop L0" in labels and "ω = 100 rad/s" in labels
    # Markers sit on the exact nominal loop values at the design frequencies.
    markers = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
    assert len(markers) == 4
    Lw = np.squeeze(ct.frequency_response(L0, OMEGAS).complex)
    got = np.array([ln.get_ydata()[0] for ln in markers])
    np.testing.assert_allclose(got, 20 * np.log10(np.abs(Lw)), rtol=1e-9)
    styles = {ln.get_linestyle() for ln in ax.get_lines() if ln.get_marker() in ("None", "")}
    assert {"-", "--"} <= styles  # solid lower and dashed upper bound curves
    fig, ax2 = plt.subplots()
    assert nichols.plot_templates(t, ax=ax2) is ax2
    assert ax2.get_xlabel() == "Plant phase [deg]" and len(ax2.get_legend().legend_handles) == 5
    plt.close("all")
