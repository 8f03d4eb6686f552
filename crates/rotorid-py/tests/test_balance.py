"""rotorid.balance against independent references: numpy.linalg.lstsq for the influence
coefficients and the least-squares correction, scipy's SLSQP for the min-max correction
with limits (a different solver and algorithm than the library's Clarabel cone program),
and `rotorid balance` itself (the same balance.json)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rotorid

from conftest import run

EXAMPLE = Path(__file__).resolve().parents[3] / "docs" / "examples" / "balance"


def tables() -> tuple[pd.DataFrame, pd.DataFrame]:
    # Python's float() parses exactly, as the command's reader does (pandas' C parser need
    # not, by its version)
    exact = {c: float for c in ("speed_rpm", "re", "im", "std", "mass_kg", "radius_m", "angle_deg")}
    v = pd.read_csv(EXAMPLE / "vectors.csv", converters=exact)
    m = pd.read_csv(EXAMPLE / "masses.csv", converters=exact)
    return v, m


def reference(v: pd.DataFrame, m: pd.DataFrame, current: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """H (keys x planes) and V (keys) by numpy's least squares, and C = lstsq(H, -V)."""
    planes = list(dict.fromkeys(m.plane))
    runs = list(dict.fromkeys(m.run))
    t = np.zeros((len(runs), len(planes)), complex)
    for _, r in m.iterrows():
        t[runs.index(r.run), planes.index(r.plane)] += r.mass_kg * r.radius_m * np.exp(1j * np.radians(r.angle_deg))
    keys = list(dict.fromkeys(zip(v.sensor, v.speed_rpm)))
    h = np.zeros((len(keys), len(planes)), complex)
    cur = np.zeros(len(keys), complex)
    for k, (s, w) in enumerate(keys):
        sel = v[(v.sensor == s) & (v.speed_rpm == w)].set_index("run")
        y = np.array([sel.re[r] + 1j * sel.im[r] for r in runs])
        x = np.column_stack([np.ones(len(runs)), t])
        beta = np.linalg.lstsq(x, y, rcond=None)[0]
        h[k] = beta[1:]
        cur[k] = sel.re[current] + 1j * sel.im[current]
    c = np.linalg.lstsq(h, -cur, rcond=None)[0]
    return h, cur, c, planes


def corrections(b: rotorid.Balance) -> np.ndarray:
    c = b.corrections
    return (c.unbalance_re_kg_m + 1j * c.unbalance_im_kg_m).to_numpy()


def test_least_squares_equals_numpy_lstsq_and_the_command(cli, tmp_path):
    v, m = tables()
    for current in ("asfound", "trial12"):
        b = rotorid.balance(v, m, current=current)
        _, _, want, planes = reference(v, m, current)
        assert list(b.corrections.index) == planes
        np.testing.assert_allclose(corrections(b), want, rtol=1e-9)
        assert set(b.corrections.columns) >= {"mass_kg", "mass_kg_std", "radius_m", "angle_deg", "angle_deg_std"}
        assert (b.corrections.mass_kg_std > 0).all()
    # the command on the same files writes the same document
    out = tmp_path / "b.json"
    run(cli, "balance", "--vectors", str(EXAMPLE / "vectors.csv"), "--masses", str(EXAMPLE / "masses.csv"),
        "--current", "asfound", "--holes", "disk1=12", "--out", str(out))
    b = rotorid.balance(EXAMPLE / "vectors.csv", EXAMPLE / "masses.csv", "asfound", holes={"disk1": 12})
    got, cmd = b.to_dict(), json.loads(out.read_text())
    # the frames' names differ from the files' only in messages; the numbers are identical
    assert got == cmd
    bdf = rotorid.balance(v, m, "asfound", holes={"disk1": 12})
    assert bdf.to_dict()["corrections"] == cmd["corrections"]
    assert len(bdf.split) == 2 and set(bdf.split.plane) == {"disk1"}
    assert bdf.residual.loc[("B1X", 1800.0)].before_amplitude > 5.0
    assert bdf.influence.shape[0] == 16


def test_min_max_with_limits_equals_scipy_slsqp():
    scipy_optimize = pytest.importorskip("scipy.optimize")
    v, m = tables()
    h, cur, _, _ = reference(v, m, "trial1")
    sensors = list(dict.fromkeys(v.sensor))
    key_sensor = [s for s in sensors for _ in range(2)]
    free = rotorid.balance(v, m, "trial1", method="minmax")
    b1x = free.residual.loc["B1X"].amplitude.max()
    limits = {"B1X": 0.6 * b1x}
    b = rotorid.balance(v, m, "trial1", method="minmax", limits=limits)
    got = corrections(b)

    # SLSQP on the epigraph: minimise t subject to t^2 >= |r_k|^2 and L^2 >= |r_k|^2,
    # in units where the vectors are O(1) and the correction is O(1)
    vs = np.abs(cur).max()
    cs = vs / np.abs(h).max()

    def resid(x):
        c = (x[1::2] + 1j * x[2::2]) * cs
        return (cur + h @ c) / vs

    cons = [{"type": "ineq", "fun": lambda x, k=k: x[0] ** 2 - abs(resid(x)[k]) ** 2} for k in range(len(cur))]
    cons += [
        {"type": "ineq", "fun": lambda x, k=k: (limits[key_sensor[k]] / vs) ** 2 - abs(resid(x)[k]) ** 2}
        for k in range(len(cur)) if key_sensor[k] in limits
    ]
    ls = np.linalg.lstsq(h, -cur, rcond=None)[0] / cs
    x0 = np.concatenate([[np.abs(resid(np.r_[0, np.c_[ls.real, ls.imag].ravel()])).max() * 2],
                         np.c_[ls.real, ls.imag].ravel()])
    best = None
    for start in (x0, np.r_[x0[0] * 3, np.zeros(len(ls) * 2)]):
        r = scipy_optimize.minimize(lambda x: x[0], start, constraints=cons, method="SLSQP",
                                    options={"ftol": 1e-14, "maxiter": 1000})
        if r.success and (best is None or r.x[0] < best.x[0]):
            best = r
    assert best is not None
    want = (best.x[1::2] + 1j * best.x[2::2]) * cs
    peak_got = np.abs(cur + h @ got).max()
    peak_want = np.abs(cur + h @ want).max()
    assert abs(peak_got - peak_want) < 1e-6 * peak_want, (peak_got, peak_want)
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-4 * np.abs(want).max())
    # the limit holds
    assert b.residual.loc["B1X"].amplitude.max() <= limits["B1X"] * (1 + 1e-6)


def test_trial_plans_and_errors_name_the_frame():
    v, m = tables()
    p = rotorid.plan_trials(v, m, "asfound", fraction=0.2)
    t = p.trials
    assert list(t.index) == ["disk1", "disk2"]
    np.testing.assert_allclose(t.change_amplitude / t.current_amplitude, 0.2, rtol=1e-9)
    bad = v.copy()
    bad.loc[3, "speed_rpm"] = -1.0
    with pytest.raises(ValueError, match=r"vectors_df line 5, column 2 \(speed_rpm\): speed_rpm = -1 is out of range"):
        rotorid.balance(bad, m, "asfound")
    with pytest.raises(ValueError, match="run \"later\" has no 1X vector"):
        rotorid.balance(v, m, "later")
    with pytest.raises(TypeError, match="holes\\['disk1'\\]"):
        rotorid.balance(v, m, "asfound", holes={"disk1": "twelve"})
    # amp, phase_deg in the lag convention: the same correction
    polar = pd.DataFrame({
        "run": v.run, "speed_rpm": v.speed_rpm, "sensor": v.sensor,
        "amp": np.hypot(v.re, v.im), "phase_deg": -np.degrees(np.arctan2(v.im, v.re)), "unit": v.unit,
    })
    a = corrections(rotorid.balance(polar, m, "asfound", phase="lag"))
    np.testing.assert_allclose(a, corrections(rotorid.balance(v, m, "asfound")), rtol=1e-9)
