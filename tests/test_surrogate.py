"""GP surrogate of DEL (issue 17, part 3): specdesign.validate.surrogate against scikit-learn
itself (the oracle: the same kernel and hyper-parameters on the same scaled data), against
the look-up table on a known smooth function, and on a small real campaign."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from specdesign.validate import (
    DelData,
    compare_surrogates,
    del_data,
    fit_gp,
    fit_lut,
    run_campaign,
)

GaussianProcessRegressor = pytest.importorskip("sklearn.gaussian_process").GaussianProcessRegressor


def known(v, ti):
    """The smooth test function (MN·m): a DEL-like bowl over wind speed, growing with turbulence."""
    return 40.0 + 10.0 * np.sin(2 * np.pi * v / 12.0) + 150.0 * (ti - 0.14) * (v / 15.0) ** 2


def noisy_grid(speeds, tis, seeds, sd, rng):
    x = np.array([[v, t] for v in speeds for t in tis])
    y = known(x[:, 0], x[:, 1])[:, None] + sd * rng.standard_normal((x.shape[0], seeds))
    return x, y


def test_gp_matches_scikit_learn_with_the_same_kernel_on_the_same_scaled_data():
    rng = np.random.default_rng(1)
    x, y = noisy_grid(np.arange(6.0, 25.0, 3.0), [0.12, 0.14, 0.16], 2, 0.5, rng)
    gp = fit_gp(x, y, n_restarts=2, random_state=3)
    # the oracle: scikit-learn given the fitted kernel (no re-optimisation), inputs scaled to
    # [0, 1] by the training range, one training point per run, normalize_y
    lo, hi = x.min(axis=0), x.max(axis=0)
    ref = GaussianProcessRegressor(gp.regressor.kernel_, optimizer=None, normalize_y=True)
    ref.fit(np.repeat((x - lo) / (hi - lo), 2, axis=0), y.ravel())
    q = np.column_stack([rng.uniform(6, 24, 20), rng.uniform(0.12, 0.16, 20)])
    mean, sd = ref.predict((q - lo) / (hi - lo), return_std=True)
    p = gp.predict(q)
    np.testing.assert_allclose(p.mean, mean, rtol=0, atol=1e-10 * np.abs(mean).max())
    # scikit-learn's SD is that of one new run: the latent SD and the white noise in quadrature
    np.testing.assert_allclose(np.hypot(p.std, p.noise_sd), sd, rtol=1e-10)
    # and the fit itself is scikit-learn's own with the same kernel, restarts and seed
    k = gp.regressor.kernel  # the initial kernel
    own = GaussianProcessRegressor(k, normalize_y=True, n_restarts_optimizer=2, random_state=3)
    own.fit(np.repeat((x - lo) / (hi - lo), 2, axis=0), y.ravel())
    np.testing.assert_allclose(own.kernel_.theta, gp.regressor.kernel_.theta, rtol=0, atol=1e-12)


def test_gp_beats_the_look_up_table_on_a_smooth_function_with_noise():
    # known(v, ti) on the even speeds 4..24 m/s × I = 0.10, 0.14, 0.18, 2 seeds with noise SD
    # 0.5 MN·m; held out: the odd speeds between them at every intensity. The GP paper (DEL
    # under yaw misalignment) reports the GP's relative RMSE 17-52 percentage points below the
    # table's (e.g. 5.45-15.19 % vs 22.69-50.09 %); the table's error here is the chord of the sine
    # (up to h²/8·f'' ≈ 1.4 MN·m) plus the noise of its 2-seed means
    rng = np.random.default_rng(7)
    x, y = noisy_grid(np.arange(4.0, 25.0, 1.0), [0.10, 0.14, 0.18], 2, 0.5, rng)
    data = DelData(names=("wind_speed", "turbulence_intensity"), conditions=x, values=y, indicator="tower_del",
                   controller="known")
    held = x[x[:, 0] % 2 == 1]
    cmp = compare_surrogates(data, held, n_restarts=2)
    assert cmp.lut.shape == cmp.truth.shape == (held.shape[0],)
    assert np.isfinite([cmp.rmse_gp, cmp.rmse_lut, cmp.mae_gp, cmp.mae_lut]).all()
    assert cmp.rmse_gp < cmp.rmse_lut and cmp.mae_gp < cmp.mae_lut
    # the table is the bilinear interpolation of the training seed means (an independent check)
    tr = x[x[:, 0] % 2 == 0]
    ym = y[x[:, 0] % 2 == 0].mean(axis=1)
    row = np.flatnonzero(np.isclose(held, [9.0, 0.14]).all(axis=1))[0]
    below = ym[np.isclose(tr, [8.0, 0.14]).all(axis=1)][0]
    above = ym[np.isclose(tr, [10.0, 0.14]).all(axis=1)][0]
    assert cmp.lut[row] == pytest.approx((below + above) / 2, rel=1e-12)


@pytest.fixture(scope="module")
def campaign():
    from specdesign import simulate as sm
    from specdesign import turbine

    model = turbine.iea15mw()
    ctrls = {"ROSCO": sm.rosco_scheduled(model), "PI19": turbine.rosco_baseline(model, 19.0)}
    return run_campaign(ctrls, np.arange(13.0, 26.0, 2.0), 4, model=model, duration=200.0, transient=20.0,
                        predict=False, progress=False)


def test_surrogates_on_a_small_campaign(campaign):
    covered = []
    for name in campaign.controllers:
        for ind in ("tower_del", "gen_speed_sd", "pitch_sd"):
            data = del_data(campaign, name, ind)
            assert data.names == ("wind_speed",) and data.values.shape == (7, 4)
            np.testing.assert_array_equal(data.values, campaign.values[ind][campaign.index(name)])
            cmp = compare_surrogates(data, [15.0, 19.0, 23.0])
            assert np.isfinite([cmp.rmse_gp, cmp.rmse_lut, cmp.mae_gp, cmp.mae_lut]).all()
            # RMSE ≥ MAE always; both are errors in the indicator's unit, far below its level
            assert cmp.rmse_gp >= cmp.mae_gp and cmp.rmse_lut >= cmp.mae_lut
            covered.append(cmp.coverage)
    # the 2σ band (of a 4-seed mean) holds most held-out seed means (≈95 % if calibrated)
    assert np.mean(covered) > 0.5


def test_turbulence_and_parameter_axes(campaign):
    # the same campaign under two turbulence keys gives a second axis; a family gives a parameter
    data = del_data({"B": campaign, 0.16: campaign}, {"ROSCO": 0.0, "PI19": 1.0})
    assert data.names == ("wind_speed", "turbulence_intensity", "parameter")
    assert data.conditions.shape == (28, 3)
    assert set(data.conditions[:, 1]) == {0.14, 0.16} and set(data.conditions[:, 2]) == {0.0, 1.0}


def test_clear_errors(campaign):
    with pytest.raises(ValueError, match="at least 3"):
        fit_gp([10.0, 12.0], [[1.0], [2.0]])
    with pytest.raises(ValueError, match="at least 3"):
        fit_lut([10.0, 12.0], [[1.0], [2.0]])
    with pytest.raises(ValueError, match="NaN"):
        fit_gp([10.0, 12.0, 14.0], [[1.0], [np.nan], [2.0]])
    with pytest.raises(ValueError, match="one value"):
        fit_gp([[10.0, 0.1], [12.0, 0.1], [14.0, 0.1]], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="not in the campaign.*ROSCO"):
        del_data(campaign, "HINF")
    with pytest.raises(ValueError, match="indicator='root_del'"):
        del_data(campaign, "ROSCO", "root_del")
    with pytest.raises(ValueError, match="turbulence class"):
        del_data({"Z": campaign}, "ROSCO")
    vals = dict(campaign.values)
    vals["tower_del"] = vals["tower_del"].copy()
    vals["tower_del"][0, 2, 1] = np.nan
    broken = dataclasses.replace(campaign, values=vals)
    with pytest.raises(ValueError, match=r"NaN tower_del at \[17.0\] m/s"):
        del_data(broken, "ROSCO")
    data = del_data(campaign, "ROSCO")
    with pytest.raises(ValueError, match="not among the data's conditions"):
        compare_surrogates(data, [16.0])
    with pytest.raises(ValueError, match="outside the look-up table"):
        compare_surrogates(data, [13.0])
    with pytest.raises(ValueError, match="at least 3"):
        compare_surrogates(data, [15.0, 17.0, 19.0, 21.0, 23.0])
