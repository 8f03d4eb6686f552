"""rotorid.identify_finite_element (issue 27, docs/finite_element.md section 5) against an
independent path: a one-node finite-element rotor is the cross-coupled 2-DOF model under
x = x, y = -z (docs/finite_element.md section 2), so the same noisy record identified as
a finite-element rotor (reduced model, unit responses, finite differences) and by the
2-DOF refine (rotorid.identify(model="cross_coupled"), another code) gives the same
maximum-likelihood estimates and standard errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rotorid

M, A = 14.29, 2.871
CROSS = dict(model="cross_coupled", m=M, kxx=1.195e6, kxz=-3e4, kzx=3e4, kzz=1.4e6,
             cxx=200.0, cxz=20.0, czx=20.0, czz=200.0, a=A, m_u=1e-4, d=0.15,
             alpha_deg=45.0, rpm=1200.0, dt=1e-4, duration=0.5)


@pytest.fixture(scope="module")
def fe_scenario(tmp_path_factory):
    d = tmp_path_factory.mktemp("fe")
    np.savez(d / "m.npz", M=np.diag([M, M]), K=np.zeros((2, 2)), G=np.array([[0.0, A], [-A, 0.0]]),
             Ka=np.array([[0.0, A], [0.0, 0.0]]), dofs=np.array(["0.x", "0.y"]))
    # the start: 30-50 % off in the direct coefficients, 40 deg off in the angle
    (d / "fe.toml").write_text(
        "[rotor]\nmodel = \"finite_element\"\nmatrices = \"m.npz\"\n\n[[rotor.bearing]]\nnode = 0\n"
        "kxx = 1.6e6\nkxy = 3.0e4\nkyx = -3.0e4\nkyy = 0.9e6\ncxx = 300.0\ncxy = -20.0\n"
        "cyx = -20.0\ncyy = 120.0\n\n[[rotor.unbalance]]\nnode = 0\nm_u = 1.5e-4\nd = 0.15\n"
        "alpha_deg = -5.0\n\n[speed]\nkind = \"constant\"\nrpm = 1200.0\n")
    return d / "fe.toml"


@pytest.fixture(scope="module")
def record():
    return rotorid.simulate(rotorid.Scenario(**CROSS), snr_db=40, seed=5)


#: finite-element name, 2-DOF name, and the shift of the angle (x = x, y = -z)
PAIRS = [("bearing0.kxx", "kxx", 0.0), ("bearing0.kyy", "kzz", 0.0),
         ("bearing0.cxx", "cxx", 0.0), ("bearing0.cyy", "czz", 0.0),
         ("unbalance0.mud", "mud", 0.0), ("unbalance0.alpha", "alpha", -math.pi / 2)]


@pytest.fixture(scope="module")
def two_dof(record):
    """The 2-DOF cross-coupled refine of the record (the independent code), by parameter."""
    two = rotorid.identify(record, rotorid.Scenario(**CROSS), method="refine", model="cross_coupled",
                           unknowns=["cxx", "czz", "kxx", "kzz", "unbalance"])
    return {p["parameter"]: p for p in two.to_dict()["parameters"]}


def test_identify_finite_element_equals_the_cross_coupled_refine(fe_scenario, record, two_dof):
    fe_data = {"t": record.t.to_numpy(), "0.x": record.x.to_numpy(), "0.y": -record.z.to_numpy()}
    s = rotorid.identify_finite_element(fe_data, fe_scenario)
    assert s["model"] == "finite_element" and s["converged"] and s["identifiable"]
    assert s["adequacy"]["model_adequate"]
    ref = two_dof
    got = {p["parameter"]: p for p in s["parameters"]}
    for fe, xz, shift in PAIRS:
        a, b = got[fe], ref[xz]
        assert abs(a["value"] - (b["estimate"] + shift)) < 0.01 * a["std_error"], (fe, a, b)
        assert a["std_error"] == pytest.approx(b["std_error"], rel=0.01), fe
    # the covariance is over the unknowns, in their order, and symmetric
    names = s["covariance"]["names"]
    assert names == [p["parameter"] for p in s["parameters"]]
    c = np.array(s["covariance"]["matrix"], dtype=float)
    np.testing.assert_allclose(c, c.T, rtol=1e-12)
    np.testing.assert_allclose(np.sqrt(np.diag(c)), [got[n]["std_error"] for n in names], rtol=1e-12)


def test_identify_finite_element_refuses_by_name(fe_scenario, record):
    data = {"t": record.t.to_numpy(), "0.x": record.x.to_numpy(), "0.y": -record.z.to_numpy()}
    with pytest.raises(ValueError, match="bearing3.kxx.*bearing0 .. bearing0"):
        rotorid.identify_finite_element(data, fe_scenario, unknowns="bearing3.kxx")
    with pytest.raises(ValueError, match="initial.*moving.*rest"):
        rotorid.identify_finite_element(data, fe_scenario, initial="moving")
    with pytest.raises(ValueError, match="column \"0.q\""):
        rotorid.identify_finite_element({**data, "0.q": data["0.x"]}, fe_scenario)
    with pytest.raises(ValueError, match="modes = 3.*1 ..= 2"):
        rotorid.identify_finite_element(data, fe_scenario, modes=3)
    with pytest.raises(ValueError, match="no column t"):
        rotorid.identify_finite_element({"0.x": data["0.x"]}, fe_scenario)


def test_offsets_absorb_a_removed_dc(fe_scenario, record, two_dof):
    # the record with a constant added to each channel (a DC removed, or a gap voltage
    # subtracted, by the user's own conditioning): with offsets=True the fit reports the
    # constants within their standard errors and the 2-DOF refine's estimates on the
    # clean record (another code); without them the adequacy tests reject the fit
    shift = {"0.x": 3e-7, "0.y": -2e-7}
    data = {"t": record.t.to_numpy(), "0.x": record.x.to_numpy() + shift["0.x"],
            "0.y": -record.z.to_numpy() + shift["0.y"]}
    s = rotorid.identify_finite_element(data, fe_scenario, offsets=True)
    assert s["converged"] and s["identifiable"] and s["adequacy"]["model_adequate"], s["diagnostics"]
    assert [o["channel"] for o in s["offsets"]] == ["0.x", "0.y"]
    for o in s["offsets"]:
        assert abs(o["value"] - shift[o["channel"]]) < 4 * o["std_error"], o
    ref = two_dof
    got = {p["parameter"]: p for p in s["parameters"]}
    for fe, xz, shift_angle in PAIRS:
        a, b = got[fe], ref[xz]
        assert abs(a["value"] - (b["estimate"] + shift_angle)) < 0.5 * a["std_error"], (fe, a, b)
    plain = rotorid.identify_finite_element(data, fe_scenario)
    assert "offsets" not in plain
    assert not plain["adequacy"]["model_adequate"]
