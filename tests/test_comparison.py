"""The blade-root DEL indicator of campaigns (issue 17 part 4) and the comparison figure."""
import numpy as np
import pytest

from specdesign import turbine
from specdesign.fatigue import del_rainflow
from specdesign.validate import INDICATORS, indicators, paired_change, run_campaign
from specdesign.fatigue import BLADE_M


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


@pytest.fixture(scope="module")
def campaign(model):
    ctrls = {"ROSCO": turbine.rosco_baseline(model, 19.0), "ROSCO stiff": turbine.rosco_baseline(model, 17.0)}
    return run_campaign(ctrls, [19.0], [3, 4, 5], model=model, duration=60.0, transient=10.0, predict=False,
                        keep_series=True, volterra=1, progress=False)


def test_blade_del_is_rainflow_of_the_simulated_blade_moment(campaign):
    # oracle: fatigue.del_rainflow (ASTM rainflow, 1 Hz) of the kept blade_root_my records, m = 10
    assert "blade_del" in INDICATORS and BLADE_M == 10.0
    for i, name in enumerate(campaign.controllers):
        r = campaign.series[name]
        x = r["blade_root_my"][0]
        hand = np.array([del_rainflow(row, 10.0, r.duration) for row in x])
        np.testing.assert_allclose(campaign.values["blade_del"][i, 0], hand, rtol=1e-12)
        # not the tower's exponent: with m = 4 the same records give another DEL
        assert not np.allclose(hand, [del_rainflow(row, 4.0, r.duration) for row in x], rtol=1e-3)


def test_blade_del_pools_by_damage_with_its_own_exponent(campaign):
    # the seed-pooled DEL of the summed blade damage, (mean DEL^10)^(1/10), whatever the campaign's m = 4
    a, b = (campaign.values["blade_del"][i, 0] for i in (1, 0))
    hand = 100.0 * (np.mean(a**10) ** 0.1 / np.mean(b**10) ** 0.1 - 1.0)
    ch = campaign.change("ROSCO stiff", "ROSCO", "blade_del")
    assert ch.change[0] == pytest.approx(hand, rel=1e-12)
    assert paired_change(a, b, "blade_del").change[0] == pytest.approx(hand, rel=1e-12)
    assert np.isfinite(ch.se[0]) and ch.se[0] > 0


def test_volterra_indicators_carry_the_blade_del(campaign):
    vb = campaign.volterra_values["blade_del"]
    assert vb.shape == campaign.values["blade_del"].shape and np.all(np.isfinite(vb))
    # first order about the trim: the same magnitude as the simulation's DEL on the same wind
    np.testing.assert_allclose(vb, campaign.values["blade_del"], rtol=0.5)


def test_indicators_without_a_blade_channel_are_nan_and_bad_shapes_refused():
    t = np.arange(600) * 0.1
    s = {"tower_base_my": np.sin(t), "gen_speed": 0.8 + 0.01 * np.sin(t), "power": np.full(600, 15e6),
         "pitch": np.zeros(600)}
    assert np.isnan(indicators(s, 0.1).blade_del)
    # a sine of amplitude A: one full cycle of range 2A per period, so DEL = 2A (n/N_eq)^(1/m) by hand
    s["blade_root_my"] = 3.0 * np.sin(2 * np.pi * 0.5 * t)  # 30 periods in 60 s
    assert float(indicators(s, 0.1).blade_del) == pytest.approx(6.0 * (30 / 60.0) ** 0.1, rel=5e-3)  # end half cycles
    s["blade_root_my"] = np.zeros(599)
    with pytest.raises(ValueError, match="blade_root_my"):
        indicators(s, 0.1)


def test_comparison_figure_labels(campaign):
    from specdesign.plots.conventions import MIN_SEEDS_FOR_SE
    from specdesign.plots.validation import plot_comparison

    ch = {"ROSCO stiff": {k: campaign.change("ROSCO stiff", "ROSCO", k) for k in ("tower_del", "blade_del")}}
    ax = plot_comparison(ch)
    assert [a.get_xlabel() for a in ax] == ["mean wind speed (m/s; controllers side by side)"] * 2
    assert "blade-root DEL" in ax[1].get_ylabel() and "(%)" in ax[1].get_ylabel() and "negative: lower" in ax[1].get_ylabel()
    n = ch["ROSCO stiff"]["tower_del"].n_seeds
    # a standard error only from MIN_SEEDS_FOR_SE paired seeds on (the figure conventions)
    want = "ROSCO stiff" if n >= MIN_SEEDS_FOR_SE else f"ROSCO stiff ({n} seeds: no SE)"
    assert [t.get_text() for t in ax[0].get_legend().get_texts()] == [want]
    y = ax[1].lines[0].get_ydata()
    assert y[0] == pytest.approx(ch["ROSCO stiff"]["blade_del"].change[0])
    # wind speeds are categories: one controller sits at the group positions 0, 1, ... labelled in m/s
    speeds = ch["ROSCO stiff"]["tower_del"].wind_speeds
    assert list(ax[0].lines[0].get_xdata()) == list(range(len(speeds)))
    assert [t.get_text() for t in ax[0].get_xticklabels()] == [f"{v:g}" for v in speeds]
    with pytest.raises(ValueError, match="changes"):
        plot_comparison({})
