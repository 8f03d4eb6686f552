"""rotorid's bearings in ROSS: an independent check of the frame mapping (docs/ross.md).

A ROSS rotor whose translational (cylindrical) motion is rotorid's 2-DOF rotor: a short,
stiff steel shaft, one disk at mid-span, two identical bearings at the ends, each given half
of ``Identification.to_ross_bearing_kwargs()``. By symmetry translation and tilt decouple,
and the disk's gyroscopic moment acts on tilt only, so ROSS's two translational modes are
those of m q'' + C q' + K q = 0 (rotorid's equations with a = 0, m the rotor's total mass)
up to the shaft's flexibility, whose relative effect on an eigenvalue is below
k_bearings / k_shaft (``EPS`` below, 1.9e-4; measured: 6.6e-5).

ROSS's side is ROSS's own model: its assembled state-space matrix ``Rotor.A(speed)``
(mass, shaft and disk elements, bearings, gyroscopic matrix) and its unbalance response;
only the eigen-solution is numpy's (``Rotor.run_modal`` gives the same eigenvalues but
compiles its orbit code with numba for ~30 s per process). Whirl is classified in each
library's own frame by the sense in which the disk's orbit turns: rotorid's forward is
from +z towards +x (docs/method.md section 1.1), ROSS's from +x towards +y, and
``test_ross_turns_from_x_to_y`` checks that ROSS's shaft indeed turns that way (its
forward conical mode stiffens with speed). By hand, ``run_modal(...).whirl_direction()``
labels the modes as this file does (the weakly damped translational mode "Forward").

The bearings feed forward whirl (rotorid's kzx > 0 > kxz, docs/method.md section 1.6) and
are nearly isotropic, so the forward mode has about a fifth of the backward mode's damping:
a map that turned forward into backward (the reflection z -> +y, which keeps the signs of
the cross terms) swaps them, and ``test_planted_faults_fail`` checks that it and every
single sign or axis error of the mapping fail the comparison.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import ross as rs

import rotorid

# The rotor's bearings (rotorid's frame, whole support) and disk. Nearly isotropic direct
# terms, circulatory stiffness kzx = -kxz = 4e4 N/m (70 % of the threshold c w_n) and
# unequal cross damping, so that every coefficient's sign shows in the eigenvalues.
TRUTH = {
    "m": 14.29,
    "kxx": 1.195e6, "kxz": -4.0e4, "kzx": 4.0e4, "kzz": 1.21e6,
    "cxx": 200.0, "cxz": 60.0, "czx": -40.0, "czz": 200.0,
}
MUD = 1e-4 * 0.15  # m_u d [kg m]
ALPHA_DEG = 45.0
# a = 0: the ROSS rotor's translation has no gyroscopic coupling (see the module's doc)
SCENARIO = dict(model="cross_coupled", a=0.0, m_u=1e-4, d=0.15, alpha_deg=ALPHA_DEG,
                rpm=1200.0, dt=1e-4, duration=1.0, **TRUTH)

# ROSS rotor: 4 elements of 50 mm, solid steel shaft of 100 mm, disk at node 2
N_ELEMENTS = 4
DISK_NODE = 2
ELEMENT_LENGTH = 0.05  # [m]
SHAFT_DIAMETER = 0.1  # [m]
DISK_RADIUS = 0.15  # [m]: the disk's inertia, which only tilt feels
STEEL = rs.Material(name="steel_rotorid_test", rho=7810.0, E=211e9, G_s=81.2e9)
# Shaft stiffness at mid-span, simply supported (48 E I / L^3), and the bound on the
# relative effect of its flexibility on the translational eigenvalues.
_L = N_ELEMENTS * ELEMENT_LENGTH
K_SHAFT = 48 * STEEL.E * (math.pi * SHAFT_DIAMETER**4 / 64) / _L**3
EPS = (TRUTH["kxx"] + TRUTH["kzz"]) / 2 / K_SHAFT

SPEEDS = [0.0, 1200.0, 3600.0]  # [rev/min]
CROSS = {"kxy": "kxz", "kyx": "kzx", "cxy": "cxz", "cyx": "czx"}


def rad_s(rpm: float) -> float:
    return rpm * 2 * math.pi / 60


# --- rotorid's side: its equations in its frame (numpy) ---

def rotorid_matrices(p: dict[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """C and K of docs/method.md section 1.6 with a = 0, q = (x, z)."""
    c = np.array([[p["cxx"], p["cxz"]], [p["czx"], p["czz"]]])
    k = np.array([[p["kxx"], p["kxz"]], [p["kzx"], p["kzz"]]])
    return c, k


def rotorid_modes(p: dict[str, float]) -> dict[str, complex]:
    """The eigenvalues of m q'' + C q' + K q = 0 by whirl: forward when the orbit
    x = Re(X e^{lt}), z = Re(Z e^{lt}) turns from +z towards +x, i.e. Im(Z conj X) > 0."""
    c, k = rotorid_matrices(p)
    m = p["m"]
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-k / m, -c / m]])
    lam, vec = np.linalg.eig(a)
    out = {}
    for l, v in zip(lam, vec.T):
        if l.imag > 0:
            out["forward" if (v[1] * np.conj(v[0])).imag > 0 else "backward"] = complex(l)
    assert set(out) == {"forward", "backward"}, out
    return out


def steady_state(p: dict[str, float], mud: float, alpha: float, w: float) -> np.ndarray:
    """rotorid's steady unbalance response at speed w [rad/s] (docs/method.md section 2.4,
    a = 0): (X, Z) with x(t) = Re(X e^{i w t}), z(t) = Re(Z e^{i w t}) for phi = w t."""
    c, k = rotorid_matrices(p)
    d = k - w**2 * p["m"] * np.eye(2) + 1j * w * c
    f = mud * w**2 * np.array([-1j, 1.0])  # (sin th, cos th), th = w t + alpha
    return np.linalg.solve(d, f) * np.exp(1j * alpha)


def ross_kwargs(p: dict[str, float]) -> dict[str, float]:
    """ROSS's coefficients of rotorid's bearing p by the matrix form of docs/ross.md:
    K_ROSS = D K D, C_ROSS = D C D, D = diag(1, -1)."""
    c, k = rotorid_matrices(p)
    d = np.diag([1.0, -1.0])
    kr, cr = d @ k @ d, d @ c @ d
    return {"kxx": kr[0, 0], "kxy": kr[0, 1], "kyx": kr[1, 0], "kyy": kr[1, 1],
            "cxx": cr[0, 0], "cxy": cr[0, 1], "cyx": cr[1, 0], "cyy": cr[1, 1]}


# --- ROSS's side ---

def ross_rotor(m: float, bearing: dict[str, float]) -> rs.Rotor:
    """The test rotor of total mass m [kg], each end bearing half of ``bearing``."""
    shaft = [rs.ShaftElement(L=ELEMENT_LENGTH, idl=0.0, odl=SHAFT_DIAMETER, material=STEEL)
             for _ in range(N_ELEMENTS)]
    m_disk = m - sum(e.m for e in shaft)
    assert m_disk > 0
    disk = rs.DiskElement(n=DISK_NODE, m=m_disk, Id=m_disk * DISK_RADIUS**2 / 4,
                          Ip=m_disk * DISK_RADIUS**2 / 2)
    half = {name: v / 2 for name, v in bearing.items()}
    bearings = [rs.BearingElement(n=0, **half), rs.BearingElement(n=N_ELEMENTS, **half)]
    rotor = rs.Rotor(shaft, [disk], bearings)
    assert rotor.m == pytest.approx(m, rel=1e-12)
    return rotor


def ross_modes(rotor: rs.Rotor, speed: float) -> list[tuple[complex, str, float]]:
    """ROSS's vibration modes at speed [rad/s] (rigid-body axial and torsional modes left
    out), lowest first: (eigenvalue, whirl, share of the disk's translation). Whirl is
    read at node 0 (a bearing, which moves in both the cylindrical and the conical
    modes): forward when the orbit x = Re(X e^{lt}), y = Re(Y e^{lt}) turns from +x towards
    +y, i.e. Im(X conj Y) > 0."""
    lam, vec = np.linalg.eig(rotor.A(speed))
    n = rotor.number_dof
    out = []
    for l, v in zip(lam, vec.T):
        if l.imag <= 1.0:  # rigid-body modes have |l| ~ 1e-3 rad/s
            continue
        u = v[: rotor.ndof]
        x0, y0 = u[0], u[1]
        disk = np.abs(u[DISK_NODE * n: DISK_NODE * n + 2]).max()
        share = disk / np.abs(np.concatenate([u[0::n], u[1::n]])).max()
        out.append((complex(l), "forward" if (x0 * np.conj(y0)).imag > 0 else "backward", share))
    return sorted(out, key=lambda o: o[0].imag)


def ross_translational(rotor: rs.Rotor, speed: float) -> dict[str, complex]:
    """ROSS's two translational modes by whirl: the two lowest in which the disk moves as
    much as any node (the conical modes leave it still; bending is two decades higher)."""
    modes = ross_modes(rotor, speed)
    trans = [o for o in modes if o[2] > 0.99]
    assert len(trans) >= 2, modes
    assert len(trans) == 2 or trans[2][0].imag > 10 * trans[1][0].imag, trans
    out = {whirl: lam for lam, whirl, _ in trans[:2]}
    assert set(out) == {"forward", "backward"}, trans[:2]
    return out


def log_dec(lam: complex) -> float:
    return -2 * math.pi * lam.real / lam.imag


def mismatch(ours: dict[str, complex], theirs: dict[str, complex]) -> float:
    """Largest |eigenvalue difference| / |eigenvalue| over the two whirl directions."""
    return max(abs(theirs[w] - ours[w]) / abs(ours[w]) for w in ("forward", "backward"))


# --- fixtures ---

@pytest.fixture(scope="module")
def identified() -> rotorid.Identification:
    """rotorid's identification of a simulated record of the rotor (40 dB, seed 1)."""
    sc = rotorid.Scenario(**SCENARIO)
    res = rotorid.identify(rotorid.simulate(sc, snr_db=40, seed=1), sc, method="refine",
                           model="cross_coupled")
    assert res.model == "cross_coupled"
    assert res.rotor is not None, res.warnings
    return res


# --- tests ---

def test_ross_turns_from_x_to_y():
    # ROSS's forward whirl, as this file classifies it (x towards y), is the sense in which
    # its shaft turns: the gyroscopic moment raises the forward conical mode with speed and
    # lowers the backward one (the translational modes do not move).
    rotor = ross_rotor(TRUTH["m"], {"kxx": 1.2e6, "cxx": 200.0})

    def conical(speed: float) -> dict[str, float]:
        modes = [o for o in ross_modes(rotor, speed) if o[2] < 1e-3][:2]
        return {whirl: lam.imag for lam, whirl, _ in modes}

    still, fast = conical(0.0), conical(rad_s(6000))
    assert set(fast) == {"forward", "backward"}
    assert fast["forward"] > 1.3 * max(still.values())
    assert fast["backward"] < 0.8 * min(still.values())


@pytest.mark.parametrize("rpm", SPEEDS)
def test_translational_modes_match_rotorid(identified, rpm):
    # the identified rotor in both libraries: the same eigenvalues by whirl direction
    p = identified.rotor
    kw = identified.to_ross_bearing_kwargs()
    ours = rotorid_modes(p)
    theirs = ross_translational(ross_rotor(p["m"], kw), rad_s(rpm))
    assert mismatch(ours, theirs) < EPS, (ours, theirs)
    assert kw == pytest.approx(ross_kwargs(p), rel=1e-15)  # the sign table is D K D
    for w in ("forward", "backward"):
        # what the bound on the eigenvalue implies for the log decrement
        rel = EPS * (1 + abs(ours[w]) / -ours[w].real)
        assert log_dec(theirs[w]) == pytest.approx(log_dec(ours[w]), rel=rel)
    # the cross-coupling feeds forward whirl in both: its damping is the lower
    assert log_dec(ours["forward"]) < 0.3 * log_dec(ours["backward"])
    assert log_dec(theirs["forward"]) < 0.3 * log_dec(theirs["backward"])


def _faulty(kw: dict[str, float], fault: str) -> dict[str, float]:
    kw = dict(kw)
    if fault == "reflection":  # x -> x, z -> +y: the cross terms keep their signs
        for name in CROSS:
            kw[name] = -kw[name]
    elif fault == "x_y_swapped":
        for a, b in (("kxx", "kyy"), ("cxx", "cyy"), ("kxy", "kyx"), ("cxy", "cyx")):
            kw[a], kw[b] = kw[b], kw[a]
    else:
        kw[fault] = -kw[fault]
    return kw


@pytest.mark.parametrize("fault", ["reflection", "x_y_swapped", *CROSS])
def test_planted_faults_fail(identified, fault):
    # each wrong mapping misses by far more than the comparison's tolerance
    p = identified.rotor
    theirs = ross_translational(ross_rotor(p["m"], _faulty(identified.to_ross_bearing_kwargs(), fault)), 0.0)
    assert mismatch(rotorid_modes(p), theirs) > 10 * EPS


def test_identified_bearings_give_the_true_modes_in_ross(identified):
    # end to end: the bearings identified from a noisy record, put into ROSS, give the
    # eigenvalues that ROSS gives the true bearings, within the identification's
    # uncertainty (its covariance propagated to the eigenvalues by central differences;
    # the shaft's small effect is common to both and cancels). Measured: 1.7 standard
    # deviations at most.
    cov = identified.to_dict()["covariance"]
    names = ["m", *(n for n in TRUTH if n != "m")]
    idx = [cov["names"].index(n) for n in names]
    sigma = np.asarray(cov["matrix"], dtype=float)[np.ix_(idx, idx)]
    p = identified.rotor
    base = rotorid_modes(p)
    jac = {w: np.zeros((2, len(names))) for w in base}
    for j, n in enumerate(names):
        h = math.sqrt(sigma[j, j])
        up, down = rotorid_modes({**p, n: p[n] + h}), rotorid_modes({**p, n: p[n] - h})
        for w in base:
            d = (up[w] - down[w]) / (2 * h)
            jac[w][:, j] = [d.real, d.imag]
    speed = rad_s(1200)
    theirs = ross_translational(ross_rotor(p["m"], identified.to_ross_bearing_kwargs()), speed)
    truth = ross_translational(ross_rotor(TRUTH["m"], ross_kwargs(TRUTH)), speed)
    for w in ("forward", "backward"):
        std = np.sqrt(np.diag(jac[w] @ sigma @ jac[w].T))
        err = np.array([theirs[w].real - truth[w].real, theirs[w].imag - truth[w].imag])
        assert np.all(np.abs(err) < 4 * std), (w, err, std)
        # the uncertainty resolves what the test is about: forward is the weakly damped one
        assert std[0] < 0.05 * (truth["forward"].real - truth["backward"].real)


def test_steady_state_formula_is_rotorids():
    # the numpy steady state above is rotorid's model: started on it, rotorid's exact
    # simulation stays on it (a sign error in the formula would start a transient)
    sc = rotorid.Scenario(**{**SCENARIO, "rpm": 2000.0, "duration": 0.2})
    w = rad_s(2000)
    q = steady_state(TRUTH, MUD, math.radians(ALPHA_DEG), w)
    df = rotorid.simulate(sc, x0=q[0].real, z0=q[1].real, vx0=(1j * w * q[0]).real,
                          vz0=(1j * w * q[1]).real)
    t = df.t.to_numpy()
    expect_x = (q[0] * np.exp(1j * w * t)).real
    expect_z = (q[1] * np.exp(1j * w * t)).real
    scale = np.abs(q).max()
    assert np.abs(df.x.to_numpy() - expect_x).max() < 1e-8 * scale
    assert np.abs(df.z.to_numpy() - expect_z).max() < 1e-8 * scale


@pytest.mark.parametrize("rpm", [1200.0, 4500.0])
def test_unbalance_response_matches_rotorid(identified, rpm):
    # ROSS's unbalance response at the disk, unbalance m_u d at alpha - 90 deg, against
    # rotorid's steady state mapped to ROSS's frame: x_ROSS = x, y_ROSS = -z
    p = identified.rotor
    w = rad_s(rpm)
    rotor = ross_rotor(p["m"], identified.to_ross_bearing_kwargs())

    def ross_response(phase: float) -> np.ndarray:
        r = rotor.run_unbalance_response(DISK_NODE, p["mud"], phase, speed_range=np.array([w]))
        n = DISK_NODE * rotor.number_dof
        return r.forced_resp[n: n + 2, 0]

    ours = steady_state(p, p["mud"], p["alpha"], w)
    expect = np.array([ours[0], -ours[1]])
    got = ross_response(p["alpha"] - math.pi / 2)
    # off resonance the shaft's flexibility moves the response by about EPS times the
    # dynamic amplification
    tol = 10 * EPS * np.abs(expect).max()
    assert np.abs(got - expect).max() < tol, (got, expect)
    # the planted fault: the angle unshifted is 90 degrees off
    assert np.abs(ross_response(p["alpha"]) - expect).max() > 100 * tol
