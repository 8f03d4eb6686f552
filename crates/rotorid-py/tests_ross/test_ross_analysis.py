"""``rotorid analyze`` of a finite-element rotor (issue 27 item 6) against ROSS itself.

A two-disk ROSS rotor on anisotropic, cross-coupled bearings is exported with
``rotorid.ross.export`` and analysed by the ``rotorid`` command (``ROTORID_BIN``). ROSS's side
is its own assembled state matrix ``A(speed)`` of the 4-DOF lateral model
(``ross.utils.convert_6dof_to_4dof``; numpy's eigen-solver): ``run_campbell`` and
``run_modal`` compute the same eigenvalues but compile their orbit code with numba for ~30 s
per process, and ``run_critical_speed`` stops at a relative tolerance of 5e-3.

Checked: the damped natural frequencies of rotorid's Campbell diagram equal ROSS's lowest
ones at every fifth speed of the grid (1e-9 relative; measured 5.6e-12); at each critical
speed rotorid reports, ROSS's A has a damped natural frequency equal to that speed (1e-9),
with the same logarithmic decrement (1e-9) and the same whirl (the sense in which the
orbit of the node that moves most turns: forward from +x towards +y, ROSS's rotation).
"""

from __future__ import annotations

import json
import math
import os
import subprocess

import numpy as np
import pytest
import ross as rs
from ross.utils import convert_6dof_to_4dof

import rotorid.ross as rr

STEEL = rs.Material(name="steel_rotorid_analysis", rho=7810.0, E=211e9, G_s=81.2e9)
N_ELEMENTS = 6
DISK_NODES = (2, 4)
BEARINGS = [
    dict(n=0, kxx=1.0e6, kyy=1.4e6, kxy=2.0e4, kyx=-3.0e4, cxx=300.0, cyy=350.0, cxy=10.0, cyx=-5.0),
    dict(n=N_ELEMENTS, kxx=1.2e6, kyy=0.9e6, kxy=-1.0e4, kyx=1.5e4, cxx=250.0, cyy=280.0, cxy=0.0, cyx=0.0),
]
MODES = 4
RPM = (0.0, 12000.0, 200.0)


def rad_s(rpm: float) -> float:
    return rpm * 2 * math.pi / 60


@pytest.fixture(scope="module")
def analysed(tmp_path_factory):
    shaft = [rs.ShaftElement(L=0.1, idl=0.0, odl=0.05, material=STEEL) for _ in range(N_ELEMENTS)]
    disks = [rs.DiskElement.from_geometry(n=n, material=STEEL, width=0.04, i_d=0.05, o_d=0.25)
             for n in DISK_NODES]
    rotor = rs.Rotor(shaft, disks, [rs.BearingElement(**b) for b in BEARINGS])
    d = tmp_path_factory.mktemp("analysis")
    dofs = rr.export(rotor, d / "rotor.npz", scenario=d / "rotor.toml")
    rotorid = os.environ.get("ROTORID_BIN", "rotorid")
    grid = ":".join(str(v) for v in RPM)
    subprocess.run([rotorid, "analyze", "--scenario", str(d / "rotor.toml"), "--out", str(d / "out"),
                    "--rpm", grid, "--modes", str(MODES)], check=True, capture_output=True)
    with open(d / "out" / "analysis.json") as f:
        return convert_6dof_to_4dof(rotor), dofs, json.load(f)


def ross_modes(r4, w: float):
    """ROSS's modes at speed w: eigenvalues with Im > 0 of A(w), by frequency, and the
    displacement part of their eigenvectors."""
    lam, vec = np.linalg.eig(r4.A(speed=w))
    keep = np.where(lam.imag > 0)[0]
    order = keep[np.argsort(lam.imag[keep])]
    return lam[order], vec[: r4.ndof, order]


def whirl(u: np.ndarray) -> str:
    """forward/backward from the orbit of the node with the largest orbit (x, y, rx, ry)."""
    x, y = u[0::4], u[1::4]
    size = np.abs(x) ** 2 + np.abs(y) ** 2
    k = int(np.argmax(size))
    kappa = 2 * np.imag(x[k] * np.conj(y[k])) / size[k]
    return "forward" if kappa > 0 else "backward"


def test_campbell_frequencies_are_rosss(analysed):
    r4, dofs, a = analysed
    assert a["model"] == "finite_element" and a["modes"] == MODES
    assert dofs == [f"{n}.{k}" for n in range(N_ELEMENTS + 1) for k in ("x", "y", "rx", "ry")]
    rpm = a["campbell"]["rpm"]
    freq = np.array([m["frequency_hz"] for m in a["campbell"]["modes"]])  # modes x speeds
    worst = 0.0
    for k in range(0, len(rpm), 5):
        lam, _ = ross_modes(r4, rad_s(rpm[k]))
        ours = np.sort(freq[:, k])
        theirs = lam.imag[:MODES] / (2 * math.pi)
        worst = max(worst, float(np.max(np.abs(ours - theirs) / theirs)))
    print(f"Campbell frequencies against ROSS's A: worst relative difference {worst:.1e}")
    assert worst < 1e-9  # measured 5.6e-12


def test_critical_speeds_are_where_rosss_frequencies_meet_1x(analysed):
    r4, _, a = analysed
    crit = a["critical_speeds"]
    assert len(crit) >= 2, crit
    for c in crit:
        w = rad_s(c["rpm"])
        lam, vec = ross_modes(r4, w)
        j = int(np.argmin(np.abs(lam.imag - w)))
        assert abs(lam[j].imag - w) < 1e-9 * w, (c, lam[j])
        log_dec = -2 * math.pi * lam[j].real / lam[j].imag
        assert abs(log_dec - c["log_dec"]) < 1e-9 * abs(log_dec), (c, log_dec)
        assert whirl(vec[:, j]) == c["whirl"], c
        print(f"critical speed {c['rpm']:.3f} rpm ({c['whirl']}), ROSS's frequency there "
              f"{lam[j].imag * 60 / (2 * math.pi):.3f} rpm, log dec {c['log_dec']:.5f} / {log_dec:.5f}")
