"""OpenFAST .lin reader: openfast-io as oracle, MBC physics, clear errors on broken files."""
import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign.openfast import LinearizationData, read_linearization
from specdesign.openfast.lin import mbc_transform, read_lin_file


@pytest.fixture(scope="module")
def sample(package_data):
    return package_data / "sample_floating_19mps.1.lin"


def test_parser_matches_openfast_io(sample):
    from openfast_io.FAST_linearization_reader import FASTLinearizationFile

    ref = FASTLinearizationFile(str(sample))
    got = read_lin_file(sample)
    for k in "ABCD":
        assert_allclose(getattr(got, k), ref[k], rtol=0, atol=0)
    assert list(got.x_desc) == ref["x_info"]["Description"]
    assert list(got.u_desc) == ref["u_info"]["Description"]
    assert list(got.y_desc) == ref["y_info"]["Description"]
    assert_allclose(got.y_op, ref["y"], rtol=1e-6)  # openfast-io keeps float32
    assert got.azimuth == pytest.approx(float(ref["Azimuth"]), rel=1e-6)
    assert got.rotor_speed == pytest.approx(0.7919) and got.wind_speed == 19.0


def test_mbc_on_sample(sample):
    raw = read_lin_file(sample)
    d = read_linearization(sample, si=False)
    assert isinstance(d, LinearizationData)
    assert_allclose(d.A, raw.A, atol=0)  # no rotating states in this file
    u = list(d.u_desc)
    coll = u.index("ED Blade [coll] pitch command, rad")
    blades = [raw.u_desc.index(f"ED Blade {b} pitch command, rad") for b in "123"]
    # collective column = sum of the three blade columns (first column of T1 is ones)
    assert_allclose(d.B[:, coll], raw.B[:, blades].sum(axis=1), rtol=1e-12, atol=1e-300)
    # and OpenFAST's own collective-pitch input is that same column
    ext = u.index("ED Extended input: collective blade-pitch command, rad")
    assert_allclose(d.B[:, coll], d.B[:, ext], rtol=1e-3, atol=1e-6 * np.abs(d.B[:, ext]).max())
    # a blade output triplet: collective row = mean of the three blade rows
    y = list(d.y_desc)
    rows = [raw.y_desc.index(f"ED RootMyc{b}, (kN-m)") for b in "123"]
    assert_allclose(d.C[y.index("ED RootMyc[coll], (kN-m)")], raw.C[rows].mean(axis=0), rtol=1e-10, atol=1e-12)
    # single rotating outputs without a triplet are kept as they are
    assert "ED BldPitch1, (deg)" in y


def test_si_conversion(sample):
    raw = read_linearization(sample, si=False)
    si = read_linearization(sample)
    i = raw.y_desc.index("ED GenSpeed, (rpm)")
    assert si.y_desc[i] == "ED GenSpeed, (rad/s)" and si.y_units[i] == "rad/s"
    assert_allclose(si.C[i], raw.C[i] * np.pi / 30)
    j = raw.y_desc.index("ED TwrBsMyt, (kN-m)")
    assert_allclose(si.D[j], raw.D[j] * 1e3)
    assert_allclose(si.y_op[i], 7.563 * np.pi / 30, rtol=1e-3)


def test_to_statespace_by_description(sample):
    d = read_linearization(sample)
    P = d.to_statespace(
        inputs={"wind": "horizontal wind speed", "pitch_cmd": "collective blade-pitch command"},
        outputs={"gen_speed": "ED GenSpeed", "tower_base_my": "TwrBsMyt"},
    )
    assert P.input_labels == ["wind", "pitch_cmd"] and P.output_labels == ["gen_speed", "tower_base_my"]
    j = d.u_desc.index("ED Extended input: collective blade-pitch command, rad")
    i = d.y_desc.index("ED TwrBsMyt, (N-m)")
    assert_allclose(P.B[:, 1], d.B[:, j])
    assert_allclose(P.C[1], d.C[i])
    with pytest.raises(ValueError, match="exactly one"):
        d.to_statespace(inputs=["pitch command"])
    with pytest.raises(ValueError, match="exactly one"):
        d.to_statespace(outputs=["no such channel"])
    small = read_linearization(sample, inputs=["horizontal wind speed"], outputs=["ED GenSpeed"])
    assert small.B.shape == (106, 1) and small.C.shape == (1, 106)


def _rotor(psi, omega, coupling):
    """Tower mode z plus three flap DOFs q_b in the rotating frame, blade b driven by
    cos(ψ_b)·z (isotropic rotor: periodic in ψ, time-invariant after MBC)."""
    kz, cz, kb, cb, a = 1.2, 0.05, 4.0, 0.3, coupling
    az = psi + 2 * np.pi * np.arange(3) / 3
    K = np.zeros((4, 4))
    Cm = np.zeros((4, 4))
    K[0, 0], Cm[0, 0] = kz, cz
    K[0, 1:] = -a  # tower driven by the sum of flaps
    for b in range(3):
        K[1 + b, 1 + b], Cm[1 + b, 1 + b] = kb, cb
        K[1 + b, 0] = -a * np.cos(az[b])
    A = np.block([[np.zeros((4, 4)), np.eye(4)], [-K, -Cm]])
    pos = ["ED tower FA", "ED Blade 1 flap", "ED Blade 2 flap", "ED Blade 3 flap"]
    desc = pos + ["First time derivative of " + p for p in pos]
    rot = np.array([False, True, True, True] * 2)
    order = np.full(8, 2)
    return A, desc, rot, order


def _mbc_A(psi, omega, coupling):
    A, desc, rot, order = _rotor(psi, omega, coupling)
    empty = np.zeros((8, 0))
    return mbc_transform(A, empty, np.zeros((0, 8)), np.zeros((0, 0)), desc, rot, order, (), np.zeros(0, bool), (), np.zeros(0, bool), psi, omega)


def test_mbc_whirl_frequencies():
    # uncoupled blades: cos/sin modes split to λ_b ± jΩ, the collective keeps λ_b
    omega = 0.79
    A_nr = _mbc_A(0.4, omega, 0.0)[0]
    lam_b = np.roots([1, 0.3, 4.0])
    lam_z = np.roots([1, 0.05, 1.2])
    expected = np.concatenate([lam_z, lam_b, lam_b + 1j * omega, lam_b - 1j * omega])
    got = np.linalg.eigvals(A_nr)
    dist = np.abs(got[:, None] - expected[None, :])
    assert np.all(dist.min(axis=0) < 1e-10) and np.all(dist.min(axis=1) < 1e-10)


def test_mbc_makes_the_isotropic_rotor_time_invariant():
    omega = 0.79
    mats = [_mbc_A(psi, omega, 0.4)[0] for psi in (0.0, 0.7, 2.1, 4.0)]
    for m in mats[1:]:
        assert_allclose(m, mats[0], atol=1e-12)
    # and the transformed descriptions name the triplet
    assert "ED Blade [cos] flap" in _mbc_A(0.0, omega, 0.4)[4]


def test_azimuth_average(sample, tmp_path):
    text = sample.read_text()
    other = tmp_path / "sample.2.lin"
    other.write_text(text.replace("Azimuth:                             0.0059 rad", "Azimuth:                             2.1000 rad"))
    one = read_linearization(sample)
    two = read_linearization([sample, other])
    shifted = read_linearization(other)
    assert_allclose(two.B, 0.5 * (one.B + shifted.B), rtol=1e-12, atol=1e-300)
    assert_allclose(two.azimuths, [0.0059, 2.1])


def _broken(sample, tmp_path, edit):
    lines = sample.read_text().splitlines(keepends=True)
    lines, bad_line = edit(lines)
    p = tmp_path / "broken.lin"
    p.write_text("".join(lines))
    return p, bad_line


def test_truncated_file_names_file_and_line(sample, tmp_path):
    p, _ = _broken(sample, tmp_path, lambda L: (L[:500], None))
    with pytest.raises(ValueError, match=r"broken\.lin:500: .*file ends early while reading matrix B"):
        read_linearization(p)


def test_bad_number_names_file_and_line(sample, tmp_path):
    def edit(L):
        k = 400  # a row of A
        L[k] = L[k].replace("0.000E+00", "0.0*0E+00", 1)
        return L, k + 1

    p, line = _broken(sample, tmp_path, edit)
    with pytest.raises(ValueError, match=rf"broken\.lin:{line}: matrix A row \d+: '0\.0\*0E\+00' is not a number"):
        read_linearization(p)


def test_short_row_and_bad_table(sample, tmp_path):
    def short_row(L):
        k = 700  # a row of D
        L[k] = " ".join(L[k].split()[:-1]) + "\n"
        return L, k + 1

    p, line = _broken(sample, tmp_path, short_row)
    with pytest.raises(ValueError, match=rf"broken\.lin:{line}: matrix D row \d+ has 9 values, expected 10"):
        read_linearization(p)

    def bad_flag(L):
        k = 22  # second state row (line 23)
        L[k] = L[k].replace(" F ", " X ", 1)
        return L, k + 1

    p, line = _broken(sample, tmp_path, bad_flag)
    with pytest.raises(ValueError, match=rf"broken\.lin:{line}: Order of continuous states: malformed row 2"):
        read_linearization(p)


def test_not_a_lin_file(tmp_path):
    p = tmp_path / "x.lin"
    p.write_text("hello\n")
    with pytest.raises(ValueError, match=r"x\.lin:1: header has no"):
        read_linearization(p)
    with pytest.raises(ValueError, match="cannot read"):
        read_linearization(tmp_path / "missing.lin")
