"""Lifetime DEL (specdesign.validate.lifetime_del, issue 16 part 2).

Expected numbers come from independent computations written out here: scipy.stats.weibull_min's
CDF for the bin probabilities, explicit loops over bins and deleted seeds for the lifetime DEL
and its jackknife SE, and specdesign.validate.paired_change (the per-speed statistics the
tables use) for a one-bin climate, where the lifetime change must be the per-speed change.
"""
from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest
from scipy.stats import weibull_min

from specdesign.validate import Campaign, LifetimeDEL, lifetime, paired_change, weibull_bins, wind_climate

matplotlib.use("Agg")

SPEEDS = np.arange(13.0, 25.1, 2.0)  # what the workbench simulates today (above rated)


def synthetic(seed=0, n_seeds=4, m=4.0, speeds=SPEEDS):
    """Two controllers × speeds × seeds of positive DELs (N·m); the second ~10 % lower."""
    rng = np.random.default_rng(seed)
    base = 1e7 * (1 + 0.1 * (speeds[:, None] - 13.0)) * rng.uniform(0.8, 1.2, (speeds.size, n_seeds))
    des = base * rng.uniform(0.85, 0.95, base.shape)
    d = np.stack([base, des])
    return Campaign(("rosco", "designed"), speeds.copy(), np.arange(n_seeds), 600.0, 0.1, m, {"tower_del": d},
                    np.zeros((2, speeds.size)), np.zeros(3), {}, {})


# ----------------------------------------------------------------------------- climate
@pytest.mark.parametrize("k, v_ave", [(2.0, 10.0), (2.0, 8.5), (2.0, 7.5), (2.2, 9.0)])
def test_weibull_bins_match_scipy_cdf_differences(k, v_ave):
    c = weibull_bins(k, v_ave)
    a = v_ave / math.gamma(1 + 1 / k)  # Weibull scale from the mean speed
    dist = weibull_min(c=k, scale=a)
    edges = np.clip(np.concatenate([c.centres - 1.0, [c.centres[-1] + 1.0]]), 3.0, 25.0)
    np.testing.assert_allclose(c.centres, np.arange(3.0, 25.1, 2.0))
    np.testing.assert_allclose(c.probabilities, np.diff(dist.cdf(edges)), rtol=1e-12, atol=1e-15)
    assert c.probabilities.sum() == pytest.approx(dist.cdf(25.0) - dist.cdf(3.0), rel=1e-12)
    assert abs(dist.mean() - v_ave) < 1e-9


def test_weibull_bins_with_scale():
    c = weibull_bins(2.2, scale=11.29, cut_in=4.0, cut_out=24.0)
    dist = weibull_min(c=2.2, scale=11.29)
    assert c.centres[0] == 4.0 and c.centres[-1] == 24.0
    assert c.probabilities[1] == pytest.approx(dist.cdf(7.0) - dist.cdf(5.0), rel=1e-12)


@pytest.mark.parametrize("kw, name", [
    (dict(k=-1.0), "k"), (dict(mean_speed=0.0), "mean_speed"), (dict(mean_speed=10.0, scale=11.0), "scale"),
    (dict(cut_in=25.0, cut_out=3.0), "cut_out"), (dict(bin_width=3.0), "bin_width"), (dict(bin_width=np.nan), "bin_width"),
])
def test_weibull_bins_bad_inputs(kw, name):
    with pytest.raises(ValueError, match=name):
        weibull_bins(**kw)


@pytest.mark.parametrize("centres, probs, name", [
    ([13.0, 15.0], [0.5, -0.1], "probabilities"), ([13.0, 15.0], [0.7, 0.4], "probabilities"),
    ([13.0, 15.0], [0.1, np.nan], "probabilities"), ([13.0, 13.0], [0.1, 0.1], "centres"),
    ([13.0, -1.0], [0.1, 0.1], "centres"), ([13.0, 15.0], [0.1], "probabilities"),
])
def test_wind_climate_bad_inputs(centres, probs, name):
    with pytest.raises(ValueError, match=name):
        wind_climate(centres, probs)


def test_wind_climate_accepts_sum_one_within_tolerance():
    c = wind_climate([15.0, 13.0], [0.5, 0.5 + 5e-10])
    assert c.centres.tolist() == [13.0, 15.0] and c.probabilities[0] == 0.5 + 5e-10


# ----------------------------------------------------------------------------- lifetime DEL
def hand_lifetime(d, p, m, idx):
    """(Σ_b p_b mean_{s in idx} d_bs^m / Σ_b p_b)^{1/m} by explicit loops."""
    e = 0.0
    for b in range(d.shape[0]):
        e += p[b] * sum(d[b, s] ** m for s in idx) / len(idx)
    return (e / sum(p)) ** (1 / m)


def test_lifetime_against_hand_computation():
    camp = synthetic()
    climate = weibull_bins()  # 3..25 m/s, the campaign covers 13..25
    r = lifetime(camp, climate)
    assert isinstance(r, LifetimeDEL)
    p = [climate.probabilities[list(climate.centres).index(v)] for v in SPEEDS]
    S = 4
    for c in range(2):
        d = camp.values["tower_del"][c]
        full = hand_lifetime(d, p, 4.0, range(S))
        assert r.del_life[c, 0] == pytest.approx(full, rel=1e-12)
        reps = [hand_lifetime(d, p, 4.0, [s for s in range(S) if s != i]) for i in range(S)]
        se = math.sqrt((S - 1) / S * sum((x - np.mean(reps)) ** 2 for x in reps))
        assert r.se[c, 0] == pytest.approx(se, rel=1e-10)
    # paired change and its jackknife SE (seed deleted from both controllers)
    db, dd = camp.values["tower_del"]
    chg = 100 * (hand_lifetime(dd, p, 4.0, range(S)) / hand_lifetime(db, p, 4.0, range(S)) - 1)
    reps = [100 * (hand_lifetime(dd, p, 4.0, k) / hand_lifetime(db, p, 4.0, k) - 1)
            for k in ([s for s in range(S) if s != i] for i in range(S))]
    assert r.change[1, 0] == pytest.approx(chg, rel=1e-12)
    assert r.change_se[1, 0] == pytest.approx(math.sqrt((S - 1) / S * np.sum((np.array(reps) - np.mean(reps)) ** 2)),
                                              rel=1e-10)
    assert r.change[0, 0] == 0.0 and r.change_se[0, 0] == 0.0
    # damage shares: the baseline's sum to 1, the designed one's to (DEL ratio)^m
    assert r.damage_share[0, 0].sum() == pytest.approx(1.0, rel=1e-12)
    assert r.damage_share[1, 0].sum() == pytest.approx((1 + chg / 100) ** 4, rel=1e-12)
    b = 3
    assert r.damage_share[0, 0, b] == pytest.approx(
        p[b] * np.mean(db[b] ** 4) / sum(p[i] * np.mean(db[i] ** 4) for i in range(SPEEDS.size)), rel=1e-12)


def test_missing_bins_reported_in_record_and_summary():
    climate = weibull_bins()
    r = lifetime(synthetic(), climate)
    assert r.missing_speeds.tolist() == [3.0, 5.0, 7.0, 9.0, 11.0]
    np.testing.assert_allclose(r.missing_probability, climate.probabilities[:5])
    assert r.covered_probability + r.missing_probability.sum() == pytest.approx(climate.probabilities.sum())
    text = r.summary()
    assert "MISSING bins" in text and "3, 5, 7, 9, 11 m/s" in text
    assert f"{r.missing_probability.sum():.4g}" in text
    assert "designed" in text and "change vs rosco" in text


def test_no_missing_bins_when_the_campaign_covers_the_climate():
    r = lifetime(synthetic(), (SPEEDS, np.full(SPEEDS.size, 0.1)))
    assert r.missing_speeds.size == 0 and "MISSING" not in r.summary()


def test_one_bin_lifetime_change_is_the_per_speed_paired_change():
    camp = synthetic(speeds=np.array([19.0]), n_seeds=6)
    r = lifetime(camp, wind_climate([17.0, 19.0], [0.2, 0.3]))
    pc = paired_change(camp.values["tower_del"][1, 0], camp.values["tower_del"][0, 0], m=4.0)
    assert r.change[1, 0] == pytest.approx(pc.change[0], rel=1e-12)
    assert r.change_se[1, 0] == pytest.approx(pc.se[0], rel=1e-12)
    assert r.wind_speeds.tolist() == [19.0] and r.missing_speeds.tolist() == [17.0]


def test_availability_scales_only_del_total():
    camp = synthetic()
    a, b = lifetime(camp, weibull_bins()), lifetime(camp, weibull_bins(), availability=0.9)
    np.testing.assert_allclose(a.del_life, b.del_life)
    np.testing.assert_allclose(b.del_total, a.del_total * 0.9 ** 0.25, rtol=1e-12)
    # referred to every hour of the lifetime: (Σ p_b E_b)^{1/m} = DEL_life·(Σ p_b)^{1/m}
    np.testing.assert_allclose(a.del_total, a.del_life * a.covered_probability ** 0.25, rtol=1e-12)


@pytest.mark.parametrize("kw, name", [
    (dict(controllers=["nope"]), "controllers"), (dict(channels=("gen_speed",)), "channels"),
    (dict(m=3.0), "m="), (dict(availability=1.5), "availability"), (dict(availability=0.0), "availability"),
    (dict(baseline="nope"), "baseline"),
])
def test_lifetime_bad_inputs(kw, name):
    with pytest.raises(ValueError, match=name):
        lifetime(synthetic(), weibull_bins(), **kw)


def test_lifetime_refuses_speeds_off_the_bin_centres_and_bad_climates():
    with pytest.raises(ValueError, match="wind_climate"):
        lifetime(synthetic(), weibull_bins(cut_in=4.0, cut_out=24.0))
    with pytest.raises(ValueError, match="wind_climate"):
        lifetime(synthetic(), 3.0)
    with pytest.raises(ValueError, match="probabilities"):
        lifetime(synthetic(), (SPEEDS, np.ones(SPEEDS.size)))
    with pytest.raises(TypeError, match="campaign"):
        lifetime({"tower_del": 1}, weibull_bins())


def test_bootstrap_se_is_close_to_the_jackknife():
    # both estimate the same sampling SD; with 40 seeds they agree to within sampling noise
    camp = synthetic(n_seeds=40)
    j = lifetime(camp, weibull_bins())
    b = lifetime(camp, weibull_bins(), method="bootstrap", n_boot=400)
    assert b.method == "bootstrap" and j.change[1, 0] == b.change[1, 0]
    assert 0.7 < b.change_se[1, 0] / j.change_se[1, 0] < 1.4


def test_repeated_bin_is_refused():
    camp = synthetic(speeds=np.array([13.0, 13.0000001]))
    with pytest.raises(ValueError, match="repeat a bin"):
        lifetime(camp, weibull_bins())


def test_unstable_controller_gives_nan_and_is_named():
    camp = synthetic()
    camp.values["tower_del"][1, 2] = np.nan
    camp.unstable[1, 2] = True
    r = lifetime(camp, weibull_bins())
    assert np.isnan(r.del_life[1, 0]) and np.isfinite(r.del_life[0, 0])
    assert r.unstable["designed"] == [17.0]
    assert "UNSTABLE: designed at 17 m/s" in r.summary()


def test_lifetime_of_a_tiny_real_campaign():
    """ROSCO vs ROSCO + the paper's ATD, 13-25 m/s, 4 seeds × 120 s: the record against the runs' DELs."""
    import dataclasses

    import control

    from specdesign import simulate as sm, turbine
    from specdesign.validate import run_campaign

    model = turbine.iea15mw()
    rosco = sm.rosco_scheduled(model)
    atd = control.tf([-0.014187, -0.014187 * 4.357], [1, 0.3276])  # the paper's C_ATD (as in test_validate)
    ctrls = {"ROSCO": rosco, "ATD": dataclasses.replace(rosco, atd=tuple(atd for _ in rosco.pitch), name="ATD")}
    camp = run_campaign(ctrls, SPEEDS, seeds=range(1, 5), model=model, duration=120.0, transient=30.0,
                        predict=False, progress=False)
    climate = weibull_bins()
    r = lifetime(camp, climate)
    p = climate.probabilities[5:]  # bins 13..25 m/s
    for c in range(2):
        assert r.del_life[c, 0] == pytest.approx(hand_lifetime(camp.values["tower_del"][c], p, 4.0, range(4)), rel=1e-12)
    assert r.missing_speeds.tolist() == [3.0, 5.0, 7.0, 9.0, 11.0]
    assert np.all(np.isfinite(r.se)) and r.se[0, 0] > 0 and r.change_se[1, 0] > 0


# ----------------------------------------------------------------------------- figure
def test_damage_figure_labels_and_legend():
    import matplotlib.pyplot as plt

    from specdesign.plots.validation import plot_lifetime_damage

    r = lifetime(synthetic(), weibull_bins())
    ax = plot_lifetime_damage(r)
    assert "(m/s)" in ax.get_xlabel() and "(%)" in ax.get_ylabel()
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(texts) == 2 and texts[0].startswith("rosco") and texts[1].startswith("designed")
    assert "%" in texts[1]
    assert "bins not simulated: 3, 5, 7, 9, 11 m/s" in ax.get_title()
    heights = [p.get_height() for p in ax.patches]
    assert len(heights) == 2 * SPEEDS.size
    assert sum(heights[:SPEEDS.size]) == pytest.approx(100.0)  # the baseline's shares
    with pytest.raises(ValueError, match="channel"):
        plot_lifetime_damage(r, "gen_speed")
    plt.close("all")


# ----------------------------------------------------------------------------- Table 2's lifetime column
def test_table2_lifetime_column_is_lifetime_and_the_energy_change():
    from specdesign.validate import INDICATORS, table2

    rng = np.random.default_rng(3)
    speeds = np.arange(3.0, 25.1, 2.0)  # every bin of weibull_bins(): cut-in to cut-out
    c0 = synthetic(seed=1, n_seeds=5, speeds=speeds)
    values = {k: rng.uniform(0.5, 1.5, c0.values["tower_del"].shape) for k in INDICATORS}
    values["tower_del"] = 1e7 * values["tower_del"]  # N·m
    camp = Campaign(c0.controllers, speeds, c0.seeds, 600.0, 0.1, 4.0, values, np.zeros((2, speeds.size)),
                    np.zeros(3), {}, {})
    climate = weibull_bins(k=2.2, scale=11.29)
    plain = table2(camp, "designed", "rosco")
    t = table2(camp, "designed", "rosco", climate=climate)
    assert t.columns == plain.columns + ("Lifetime",)
    np.testing.assert_array_equal(t.values()[:, :-1], plain.values())  # the per-speed and Mean columns unchanged
    life = lifetime(camp, climate, baseline="rosco")
    rows = {label: vals for label, vals in zip([r[0] for r in t.rows], t.values())}
    assert rows["Tower base DEL"][-1] == pytest.approx(life.change[1, 0], rel=1e-12)
    # mean power: the energy over the bins, hand-summed
    p = climate.probabilities
    pw = values["mean_power"].mean(axis=-1)
    assert rows["Mean power"][-1] == pytest.approx(100 * (np.sum(p * pw[1]) / np.sum(p * pw[0]) - 1), rel=1e-12)
    # a standard deviation: the lifetime variance Σ p_b·mean_s SD² / Σ p_b, hand-summed
    var = [sum(pb * np.mean(values["pitch_sd"][c, b] ** 2) for b, pb in enumerate(p)) / p.sum() for c in (0, 1)]
    assert rows["Pitch activity (SD)"][-1] == pytest.approx(100 * (math.sqrt(var[1] / var[0]) - 1), rel=1e-12)
    assert f"{life.change[1, 0]:+.2f} ± {life.change_se[1, 0]:.2f} %" in t.note and "MISSING" not in t.note
    # a campaign short of bins (13-25 m/s): the note names the missing ones
    part = Campaign(camp.controllers, speeds[5:], camp.seeds, 600.0, 0.1, 4.0, {k: v[:, 5:] for k, v in values.items()},
                    np.zeros((2, 7)), np.zeros(3), {}, {})
    assert "MISSING bins (not simulated, excluded): 3, 5, 7, 9, 11 m/s" in table2(part, "designed", "rosco",
                                                                                 climate=climate).note


def test_lifetime_of_the_linear_predictions_by_hand():
    c = synthetic(seed=4)
    rng = np.random.default_rng(5)
    pred = 1e7 * rng.uniform(1.0, 2.0, (2, SPEEDS.size))  # N·m, per controller and speed
    c = Campaign(c.controllers, c.wind_speeds, c.seeds, 600.0, 0.1, 4.0, c.values, pred, np.zeros(3), {}, {})
    climate = weibull_bins()
    r = lifetime(c, climate)
    p = climate.probabilities[5:]  # bins 13..25 m/s
    hand = [(sum(pb * d**4 for pb, d in zip(p, pred[i])) / p.sum()) ** 0.25 for i in range(2)]
    np.testing.assert_allclose(r.predicted_del_life[:, 0], hand, rtol=1e-12)
    assert r.predicted_change[1, 0] == pytest.approx(100 * (hand[1] / hand[0] - 1), rel=1e-12)
    assert "linear prediction" in r.summary()
    # without predictions (NaN, as a campaign run with predict=False holds): NaN, not in the summary
    none = Campaign(c.controllers, c.wind_speeds, c.seeds, 600.0, 0.1, 4.0, c.values, np.full((2, SPEEDS.size), np.nan),
                    np.zeros(3), {}, {})
    r0 = lifetime(none, climate)
    assert np.all(np.isnan(r0.predicted_del_life)) and "linear prediction" not in r0.summary()
