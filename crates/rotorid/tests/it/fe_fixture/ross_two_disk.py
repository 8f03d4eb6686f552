"""Export the two-disk test rotor of tests/it/fe_*.rs from ROSS itself (ross-rotordynamics
3.1.0, Python 3.13): its 4-DOF lateral matrices (node-major x, y, rx, ry, via
ross.utils.convert_6dof_to_4dof), K without the bearings, and ROSS's own steady-state
unbalance response at a few speeds, into ross_two_disk.json (read by the Rust tests with
include_str!). Not run by CI; rerun by hand to regenerate:

    /path/to/venv-with-ross/bin/python ross_two_disk.py
"""

import json
import warnings
from pathlib import Path

import numpy as np

warnings.filterwarnings("ignore")
import ross as rs  # noqa: E402
from ross.utils import convert_6dof_to_4dof  # noqa: E402

steel = rs.Material(name="Steel_fe_fixture", rho=7810.0, E=211e9, G_s=81.2e9)
n_el = 10
L = 1.2 / n_el
# with proportional shaft damping (C = alpha M + beta K per element), so that every mode
# decays (the bending modes with nodes near the bearings get almost no bearing damping)
shaft = [rs.ShaftElement(L=L, idl=0.0, odl=0.05, material=steel, shear_effects=True,
                         rotary_inertia=True, gyroscopic=True, alpha=2.0, beta=2.0e-5)
         for _ in range(n_el)]
disk_nodes = [3, 7]
disks = [rs.DiskElement.from_geometry(n=n, material=steel, width=0.07, i_d=0.05, o_d=0.28)
         for n in disk_nodes]
# two anisotropic bearings with cross-coupled coefficients (N/m, N s/m)
bearing_kw = [
    dict(n=0, kxx=1.0e6, kxy=-2.0e4, kyx=1.5e4, kyy=1.4e6, cxx=300.0, cxy=20.0, cyx=-10.0, cyy=400.0),
    dict(n=n_el, kxx=1.2e6, kxy=0.0, kyx=0.0, kyy=0.9e6, cxx=350.0, cxy=0.0, cyx=0.0, cyy=250.0),
]
bearings = [rs.BearingElement(**kw) for kw in bearing_kw]
rotor = rs.Rotor(shaft, disks, bearings)
r4 = convert_6dof_to_4dof(rotor)

M = np.asarray(r4.M())
Ktot = np.asarray(r4.K(0.0))
Ctot = np.asarray(r4.C(0.0))
G = np.asarray(r4.G())
Ksdt = np.asarray(r4.Ksdt())
n = M.shape[0]
nodes = n // 4
dofs = [f"{i}.{d}" for i in range(nodes) for d in ("x", "y", "rx", "ry")]
# remove the bearings: their 2x2 matrices at (x, y) of their node
K = Ktot.copy()
C = Ctot.copy()
for kw in bearing_kw:
    i = 4 * kw["n"]
    K[i:i + 2, i:i + 2] -= [[kw["kxx"], kw["kxy"]], [kw["kyx"], kw["kyy"]]]
    C[i:i + 2, i:i + 2] -= [[kw["cxx"], kw["cxy"]], [kw["cyx"], kw["cyy"]]]
Mi = np.linalg.inv(M)
for w in (0.0, 300.0, 600.0):
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Mi @ Ktot, -Mi @ (Ctot + w * G)]])
    slowest = -np.linalg.eigvals(A).real.max()
    assert slowest > 0.5, f"every mode must decay at {w} rad/s: slowest rate {slowest}"
    print(f"w = {w} rad/s: slowest decay rate {slowest:.3f} 1/s")

modal = r4.run_modal(0.0)
wn = np.sort(np.abs(modal.wn))[:8]

# ROSS's steady-state unbalance response, on the 6-DOF rotor (lateral rows x, y, alpha,
# beta picked out), q(t) = Re(X exp(i w t)), unbalance phase from +x towards +y
unb_nodes = disk_nodes
unb_mag = [2.0e-4, 1.5e-4]  # kg m
unb_phase = [0.3, 2.0]  # rad
speeds = [150.0, 300.0, 450.0, 600.0]
resp = rotor.run_unbalance_response(unb_nodes, unb_mag, unb_phase, speed_range=speeds)
X6 = np.asarray(resp.forced_resp)
lat = [6 * i + k for i in range(nodes) for k in (0, 1, 3, 4)]
X = X6[lat, :]

out = {
    "source": "ross-rotordynamics " + rs.__version__ + " (ross_two_disk.py)",
    "dofs": dofs,
    "M": M.tolist(),
    "K": K.tolist(),
    "G": G.tolist(),
    "C": C.tolist(),
    "Ksdt": Ksdt.tolist(),
    "bearings": [{**kw, "node": kw["n"]} for kw in bearing_kw],
    "unbalances": [{"node": nd, "mud": m, "alpha": p} for nd, m, p in zip(unb_nodes, unb_mag, unb_phase)],
    "wn_at_rest": wn.tolist(),
    "steady_state": {
        "speeds": speeds,
        "re": X.real.T.tolist(),
        "im": X.imag.T.tolist(),
    },
}
Path(__file__).with_name("ross_two_disk.json").write_text(json.dumps(out, separators=(",", ":")) + "\n")
print("n =", n, "natural frequencies at rest (rad/s):", wn)
