"""rotorid.ross.export and update against ROSS itself (issue 27): a two-disk rotor on two
anisotropic bearings exported, its matrices read back by numpy and by rotorid's own reader
(Rust), compared with ROSS's public ``M()``, ``K()`` minus the bearings (assembled here from
the coefficients given to ROSS), ``G()`` and ``Ksdt()`` of its 4-DOF lateral model
(``ross.utils.convert_6dof_to_4dof``); the scenario parsed by rotorid's scenario parser; the
frame convention (dy/dz = -rx, dx/dz = +ry) checked on the exported stiffness; ``update``
checked against a rotor built directly with the new coefficients."""

from __future__ import annotations

import math

import numpy as np
import pytest
import ross as rs
from ross.utils import convert_6dof_to_4dof

import rotorid
import rotorid.ross as rr

STEEL = rs.Material(name="steel_rotorid_export", rho=7810.0, E=211e9, G_s=81.2e9)
N_ELEMENTS = 6
DISK_NODES = (2, 4)
BEARINGS = [  # anisotropic, cross-coupled, at the two ends
    dict(n=0, kxx=1.0e6, kyy=1.4e6, kxy=2.0e4, kyx=-3.0e4, cxx=300.0, cyy=350.0, cxy=10.0, cyx=-5.0),
    dict(n=N_ELEMENTS, kxx=1.2e6, kyy=0.9e6, kxy=-1.0e4, kyx=1.5e4, cxx=250.0, cyy=280.0, cxy=0.0, cyx=0.0),
]
SPEED = 300.0  # rad/s, where the bearings are evaluated (constant here)
UNBALANCE = [(2, 1.0e-4, 0.3), (4, 2.0e-4, -1.2)]  # (node, m_u d [kg m], phase [rad])


def two_disk_rotor(bearings=BEARINGS, **kw) -> rs.Rotor:
    shaft = [rs.ShaftElement(L=0.1, idl=0.0, odl=0.05, material=STEEL) for _ in range(N_ELEMENTS)]
    disks = [rs.DiskElement.from_geometry(n=n, material=STEEL, width=0.04, i_d=0.05, o_d=0.25)
             for n in DISK_NODES]
    return rs.Rotor(shaft, disks, [rs.BearingElement(**b) for b in bearings], **kw)


@pytest.fixture(scope="module")
def rotor() -> rs.Rotor:
    return two_disk_rotor()


@pytest.fixture(scope="module")
def exported(rotor, tmp_path_factory):
    d = tmp_path_factory.mktemp("export")
    (d / "model").mkdir()
    dofs = rr.export(rotor, d / "model" / "rotor.npz", scenario=d / "rotor.toml", speed=SPEED,
                     unbalance=UNBALANCE)
    return d, dofs


def bearing_matrices(n_dof: int, bearings=BEARINGS) -> tuple[np.ndarray, np.ndarray]:
    """K_b and C_b of the bearings on the 4-DOF lateral model (x, y, rx, ry per node), from
    the coefficients given to ROSS (the issue's contract)."""
    kb, cb = np.zeros((n_dof, n_dof)), np.zeros((n_dof, n_dof))
    for b in bearings:
        i = 4 * b["n"]
        kb[i:i + 2, i:i + 2] += [[b["kxx"], b["kxy"]], [b["kyx"], b["kyy"]]]
        cb[i:i + 2, i:i + 2] += [[b["cxx"], b["cxy"]], [b["cyx"], b["cyy"]]]
    return kb, cb


def test_the_matrices_are_rosss_without_the_bearings(rotor, exported):
    d, dofs = exported
    r4 = convert_6dof_to_4dof(rotor)
    n = r4.ndof
    assert n == 4 * (N_ELEMENTS + 1)
    assert dofs == [f"{node}.{k}" for node in range(N_ELEMENTS + 1) for k in ("x", "y", "rx", "ry")]
    kb, cb = bearing_matrices(n)
    f = np.load(d / "model" / "rotor.npz")
    assert sorted(f.files) == ["G", "K", "Ka", "M", "dofs"]  # no shaft damping in this rotor
    assert list(f["dofs"]) == dofs and f["dofs"].dtype.kind == "U"
    scale = np.abs(r4.K(SPEED, speed=SPEED)).max()
    np.testing.assert_array_equal(f["M"], r4.M(SPEED, speed=SPEED))  # massless bearings
    np.testing.assert_allclose(f["K"], r4.K(SPEED, speed=SPEED) - kb, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(f["G"], r4.G())
    np.testing.assert_array_equal(f["Ka"], r4.Ksdt())
    # ROSS's C at the speed is the bearings' alone: the exported file has no C
    np.testing.assert_allclose(r4.C(SPEED, speed=SPEED), cb, rtol=0, atol=1e-9)
    # the same arrays through rotorid's own reader (Rust)
    back = rotorid._rotorid.read_fe_matrices(str(d / "model" / "rotor.npz"))
    assert back["dofs"] == dofs and back["C"] is None
    for k in ("M", "K", "G", "Ka"):
        np.testing.assert_array_equal(back[k], f[k], err_msg=k)


def test_rotations_follow_the_contract(exported):
    """A rigid tilt with dy/dz = -rx and dx/dz = +ry strains no shaft element: it is in the
    null space of the exported K (to rounding); with either sign flipped it is not."""
    d, dofs = exported
    k = np.load(d / "model" / "rotor.npz")["K"]
    z = 0.1 * np.arange(N_ELEMENTS + 1)
    a = 1e-3

    def tilt(sy, sx, rx, ry):
        return np.concatenate([[sx * a * zi, sy * a * zi, rx * a, ry * a] for zi in z])

    scale = np.abs(k).max() * a
    assert np.abs(k @ tilt(-1, 0, 1, 0)).max() < 1e-9 * scale  # about +x: y = -a z, rx = a
    assert np.abs(k @ tilt(0, 1, 0, 1)).max() < 1e-9 * scale  # about +y: x = +a z, ry = a
    assert np.abs(k @ tilt(1, 0, 1, 0)).max() > 1e-3 * scale
    assert np.abs(k @ tilt(0, -1, 0, 1)).max() > 1e-3 * scale


def test_the_scenario_loads_through_rotorids_parser(exported):
    d, dofs = exported
    fe = rotorid.load_finite_element(d / "rotor.toml")
    assert fe.dofs == dofs
    assert fe.matrices.endswith("model/rotor.npz")
    assert len(fe.bearings) == 2
    for got, want in zip(fe.bearings, BEARINGS):
        assert got["node"] == want["n"]
        for k in rr.BEARING_COEFFICIENTS:
            assert got[k] == want[k], k
    assert [(u["node"], u["mud"]) for u in fe.unbalances] == [(n, m) for n, m, _ in UNBALANCE]
    for u, (_, _, phase) in zip(fe.unbalances, UNBALANCE):
        assert u["alpha"] == pytest.approx(phase, abs=1e-15)
    np.testing.assert_array_equal(fe.M, np.load(d / "model" / "rotor.npz")["M"])
    assert fe.C is None and fe.Ka is not None


def test_speed_dependent_bearings_are_taken_at_the_speed_given(tmp_path):
    b0 = dict(BEARINGS[0], kxx=[1.0e6, 2.0e6], kyy=[1.4e6, 1.4e6], cxx=[300.0, 500.0], cyy=[350.0, 350.0],
              kxy=[0.0, 0.0], kyx=[0.0, 0.0], cxy=[0.0, 0.0], cyx=[0.0, 0.0], frequency=[0.0, 1000.0])
    r = two_disk_rotor([b0, BEARINGS[1]])
    rr.export(r, tmp_path / "r.npz", scenario=tmp_path / "r.toml", speed=400.0)
    fe = rotorid.load_finite_element(tmp_path / "r.toml")
    k = r.bearing_elements[0].K(400.0, speed=400.0)
    c = r.bearing_elements[0].C(400.0, speed=400.0)
    assert fe.bearings[0]["kxx"] == k[0, 0] and 1.0e6 < k[0, 0] < 2.0e6
    assert fe.bearings[0]["cxx"] == c[0, 0]


def test_what_rotorid_cannot_hold_is_refused(tmp_path):
    with pytest.raises(ValueError, match=r"bearing0 .* has mass coefficients"):
        rr.export(two_disk_rotor([dict(BEARINGS[0], mxx=1.0), BEARINGS[1]]), tmp_path / "m.npz")
    with pytest.raises(ValueError, match=r"unbalance at node 9: the rotor has nodes 0 \.\. 6"):
        rr.export(two_disk_rotor(), tmp_path / "u.npz", unbalance=[(9, 1e-4, 0.0)])
    # the scenario parser's own check: a bearing without stiffness in y
    rr.export(two_disk_rotor([dict(BEARINGS[0], kyy=0.0), BEARINGS[1]]), tmp_path / "k.npz",
              scenario=tmp_path / "k.toml")
    with pytest.raises(ValueError, match=r"k\.toml:\d+: rotor\.bearing\[0\]\.kyy = 0 is out of range"):
        rotorid.load_finite_element(tmp_path / "k.toml")


def test_update_gives_the_rotor_built_with_the_identified_coefficients(rotor):
    identified = {"bearing0.kxx": 1.1e6, "bearing0.cyy": 420.0, "bearing1.kyy": 0.95e6,
                  "unbalance0.mud": 1e-4, "unbalance0.alpha": 0.3}
    new = rr.update(rotor, identified, speed=SPEED)
    want_bearings = [dict(BEARINGS[0], kxx=1.1e6, cyy=420.0), dict(BEARINGS[1], kyy=0.95e6)]
    want = two_disk_rotor(want_bearings)
    for w in (0.0, SPEED):
        np.testing.assert_allclose(new.A(speed=w), want.A(speed=w), rtol=1e-12, atol=1e-9)
    # a summary's parameter rows give the same rotor
    rows = {"parameters": [{"parameter": k, "value": v} for k, v in identified.items()]}
    np.testing.assert_array_equal(rr.update(rotor, rows, speed=SPEED).K(0), new.K(0))
    with pytest.raises(ValueError, match=r"bearing2\.kxx is not a parameter of this rotor"):
        rr.update(rotor, {"bearing2.kxx": 1e6})
    with pytest.raises(ValueError, match=r"bearing0\.kxx = nan is not determined"):
        rr.update(rotor, {"bearing0.kxx": math.nan})
