"""design_hinf on OpenFAST's linear model of the shipped IEA 15 MW monopile deck (19 m/s).

The fixture is `linearize_deck(iea15mw_monopile(), [19], n_azimuths=2)` with OpenFAST v5.0.0
(tests/data/openfast/, the .lin files as written; docs/openfast_linearization.md). Its plant
has, beside the rotor and the first tower fore-aft mode (1.07 rad/s, 12 % damping), the
monopile foundation's modes at 8.4 rad/s and 44.7 rad/s (0.7 % damping) in states scaled by
the foundation's stiffness. Two things refused it before: the well-posedness check, whose
PBH test compared the integrator mode with ‖[A B₂]‖ in those units, and the tower mode taken
as the least-damped pole pair (the 7.1 Hz foundation mode).
"""
from pathlib import Path

import numpy as np
import pytest

from specdesign import closedloop
from specdesign.hinf import design_hinf
from specdesign.openfast import LinearTurbine

DATA = Path(__file__).parent / "data" / "openfast"
# first tower fore-aft mode of monopile + tower + rotor-nacelle assembly, finite-element model
# with gravity (specdesign/data/iea15mw/tower_fe.json): 0.1720 Hz
TOWER_FE = 2 * np.pi * 0.1720


@pytest.fixture(scope="module")
def lt():
    return LinearTurbine.from_lin_files(sorted(DATA.glob("iea15mw_monopile_19mps.*.lin")), name="OpenFAST 19 m/s")


def test_fixture_has_the_foundation_modes(lt):
    lam = np.linalg.eigvals(np.asarray(lt.linearize(19.0).A, float))
    w = np.sort(np.abs(lam[lam.imag > 0]))
    assert w == pytest.approx([1.07, 8.38, 44.72], rel=0.01)


def test_the_tower_mode_is_the_towers_not_the_least_damped(lt):
    assert abs(closedloop.tower_pole(lt.linearize(19.0))) == pytest.approx(TOWER_FE, rel=0.02)


@pytest.mark.slow
def test_design_hinf_on_openfasts_plant(lt):
    d = design_hinf(lt, 19.0)
    assert np.isfinite(d.gamma) and d.gamma > 0
    assert d.tower_mode == pytest.approx(TOWER_FE, rel=0.02)
    # the loop on OpenFAST's plant, recomputed with the explicit closed-loop formula
    cl = closedloop.closed_loop(lt.linearize(19.0), d.pitch_controller, warn=False)
    assert np.max(np.real(cl.poles())) < 0
    assert d.predicted_del_reduction > 0
