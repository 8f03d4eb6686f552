"""Issue 27's study on time responses computed by ROSS itself: the two-disk rotor of
test_ross_export.py (two anisotropic cross-coupled bearings, unbalances on both disks), a
2 s run-up from rest through the first two critical speeds (0 -> 600 rad/s; criticals near
226 and 470 rad/s) integrated by ROSS 3.1.0 (fixtures/ross_runup.py: its own assembled
matrices, Newmark at dt = 1e-5 and 5e-6 s, Richardson-extrapolated), x, y at both bearings
with 40 dB noise, several seeds. rotorid exports the rotor (rotorid.ross.export), starts
from an engineering guess (direct coefficients 30-70 % off, unbalance magnitudes 50 % off
and angles 40 deg off) and identifies every direct bearing coefficient and both unbalances
(rotorid.identify_finite_element, the reduced model). Checked: every estimate within 3
standard errors of the truth (the standard error equals the Cramer-Rao bound to 1 %:
crates/rotorid/tests/it/fe_refine.rs), the 95 % intervals cover, the residuals pass the
adequacy tests on ROSS's data; then the identified model's response at both disks (where no
probe is) against ROSS's, and the critical speeds of rotorid.ross.update's rotor against
the true rotor's."""

from __future__ import annotations

import json
import math
import os
import pathlib
import subprocess

import numpy as np
import pytest

import rotorid
import rotorid.ross as rr
from test_ross_export import BEARINGS, SPEED, UNBALANCE, two_disk_rotor

HERE = pathlib.Path(__file__).resolve().parent
FIXTURE = np.load(HERE / "fixtures" / "ross_runup.npz")
PROBES = ["0.x", "0.y", "6.x", "6.y"]
DISKS = ["2.x", "2.y", "4.x", "4.y"]
SEEDS = [1, 2, 3]
SNR_DB = 40.0
GUESS = [(1.5, 0.6, 1.4, 0.7), (0.6, 1.4, 0.7, 1.5)]  # kxx, kyy, cxx, cyy factors per bearing


def channel(name: str) -> np.ndarray:
    names = [str(c) for c in FIXTURE["channels"]]
    return FIXTURE["q"][names.index(name)]


@pytest.fixture(scope="module")
def scenario(tmp_path_factory) -> pathlib.Path:
    d = tmp_path_factory.mktemp("ross_identify")
    rotor = two_disk_rotor()
    rr.export(rotor, d / "rotor.npz", scenario=d / "truth.toml", speed=SPEED, unbalance=UNBALANCE)
    # the engineering guess: the exported scenario with its direct coefficients and
    # unbalances moved
    lines = ["[rotor]", 'model = "finite_element"', 'matrices = "rotor.npz"', ""]
    for b, f in zip(BEARINGS, GUESS):
        lines += ["[[rotor.bearing]]", f"node = {b['n']}",
                  f"kxx = {b['kxx'] * f[0]!r}", f"kyy = {b['kyy'] * f[1]!r}",
                  f"kxy = {b['kxy']!r}", f"kyx = {b['kyx']!r}",
                  f"cxx = {b['cxx'] * f[2]!r}", f"cyy = {b['cyy'] * f[3]!r}",
                  f"cxy = {b['cxy']!r}", f"cyx = {b['cyx']!r}", ""]
    for j, (node, mud, alpha) in enumerate(UNBALANCE):
        lines += ["[[rotor.unbalance]]", f"node = {node}", f"m_u = {mud * (1.5 if j == 0 else 0.6)!r}",
                  "d = 1.0", f"alpha_deg = {math.degrees(alpha) + (40.0 if j == 0 else -40.0)!r}", ""]
    lines += ["[speed]", 'kind = "ramp"', "rpm0 = 0.0", f"accel = {float(FIXTURE['accel'])!r}", "",
              "[sampling]", "dt = 1e-4", "duration = 2.0", ""]
    (d / "start.toml").write_text("\n".join(lines))
    return d / "start.toml"


def truth() -> dict[str, float]:
    t = {}
    for i, b in enumerate(BEARINGS):
        for k in ("kxx", "kyy", "cxx", "cyy"):
            t[f"bearing{i}.{k}"] = b[k]
    for j, (_, mud, alpha) in enumerate(UNBALANCE):
        t[f"unbalance{j}.mud"] = mud
        t[f"unbalance{j}.alpha"] = alpha
    return t


def noisy(seed: int) -> dict[str, np.ndarray]:
    rng = np.random.default_rng(seed)
    data = {"t": FIXTURE["t"]}
    for p in PROBES:
        y = channel(p)
        sigma = np.sqrt(np.mean(y**2)) * 10 ** (-SNR_DB / 20)
        data[p] = y + sigma * rng.standard_normal(y.size)
    return data


@pytest.fixture(scope="module")
def fits(scenario) -> dict[int, dict]:
    return {seed: rotorid.identify_finite_element(noisy(seed), scenario, initial="rest")
            for seed in SEEDS}


def test_the_fixture_is_rosss_to_well_below_the_noise():
    # the extrapolated ROSS response's own error, against the 1 % noise and the 1e-5
    # model error that would move an estimate by a fraction of its standard error
    err = FIXTURE["ross_error_rel"]
    assert np.all(err < 2e-6), err
    assert str(FIXTURE["ross_version"]).startswith("3.")


def test_refine_recovers_rosss_bearings_and_unbalances_within_three_standard_errors(fits):
    t = truth()
    covered = total = 0
    for seed, s in fits.items():
        assert s["converged"] and s["identifiable"], (seed, s["diagnostics"])
        assert s["adequacy"]["model_adequate"], (seed, s["adequacy"])
        for p in s["parameters"]:
            z = (p["value"] - t[p["parameter"]]) / p["std_error"]
            print(f"seed {seed} {p['parameter']:18} {p['value']:.6e} +- {p['std_error']:.2e}"
                  f" (truth {t[p['parameter']]:.6e}, z = {z:+.2f}, bias {p['reduction_bias_std']:.1e} std)")
            assert abs(z) < 3.0, (seed, p)
            covered += abs(z) < 1.96
            total += 1
    # 95 % intervals: at least 31 of 36 cover (binomial: P(fewer) < 3 % for a true 95 %)
    assert covered >= total - 5, f"{covered} of {total}"


def rotorid_bin() -> str:
    return os.environ.get("ROTORID_BIN", "rotorid")


def rms(v: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(v))))


@pytest.fixture(scope="module")
def summary_file(fits, scenario) -> pathlib.Path:
    p = scenario.parent / f"summary{SEEDS[0]}.json"
    p.write_text(json.dumps(fits[SEEDS[0]]))
    return p


def test_the_identified_model_predicts_rosss_response_at_the_disks(summary_file, scenario):
    # rotorid predict: the identified model's response where no probe is, against ROSS's
    out = scenario.parent / "pred.csv"
    subprocess.run([rotorid_bin(), "predict", str(summary_file), "--scenario", str(scenario),
                    "--dofs", ",".join(DISKS), "--out", str(out)], check=True, capture_output=True)
    import pandas as pd
    pred = pd.read_csv(out)
    assert len(pred) == len(FIXTURE["t"])
    np.testing.assert_allclose(pred["t"].to_numpy(), FIXTURE["t"], rtol=0, atol=1e-12)
    for d in DISKS:
        ross = channel(d)
        ours = pred[d].to_numpy()
        rel = rms(ours - ross) / rms(ross)
        band = rms(pred[f"{d}_std"].to_numpy()) / rms(ross)
        print(f"{d}: prediction - ROSS = {rel:.2e} of ROSS's RMS (the band's RMS {band:.1e})")
        assert rel < 0.02, (d, rel)


def ross_critical(rotor, guess: float) -> float:
    """ROSS's critical speed [rad/s] near `guess`: where the damped natural frequency of the
    mode nearest the running speed at `guess` (from ROSS's own run_modal) equals the speed,
    by the secant method."""
    k = int(np.argmin(np.abs(rotor.run_modal(guess).wd - guess)))

    def f(w: float) -> float:
        return float(rotor.run_modal(w).wd[k] - w)

    a, b = 0.99 * guess, 1.01 * guess
    fa, fb = f(a), f(b)
    for _ in range(20):
        c = b - fb * (b - a) / (fb - fa)
        a, fa, b, fb = b, fb, c, f(c)
        if abs(b - a) < 1e-9 * abs(b):
            break
    return b


def test_updated_rotor_has_the_true_critical_speeds_within_their_std(summary_file, scenario, fits):
    # the critical speeds, with their standard deviations, of the identified rotor
    # (rotorid analyze SUMMARY.json: the covariance carried through), and ROSS's own of
    # rotorid.ross.update's rotor against the true rotor's
    out = scenario.parent / "analysis"
    subprocess.run([rotorid_bin(), "analyze", str(summary_file), "--scenario", str(scenario),
                    "--out", str(out), "--rpm", "0:7000:10"], check=True, capture_output=True)
    a = json.loads((out / "analysis.json").read_text())
    crit = a["critical_speeds"]
    assert len(crit) >= 2, crit
    true_rotor = two_disk_rotor()
    updated = rr.update(true_rotor, fits[SEEDS[0]])
    for c in crit:
        w = c["rpm"] * math.pi / 30.0
        std = c["std_rpm"] * math.pi / 30.0
        t, u = ross_critical(true_rotor, w), ross_critical(updated, w)
        print(f"{c['whirl']}: rotorid {w:.4f} +- {std:.2e} rad/s, ROSS updated {u:.4f}, "
              f"ROSS true {t:.4f} ({(u - t) / std:+.2f} std)")
        assert std > 0
        assert abs(u - t) < 3.0 * std, (c, u, t)
        assert abs(w - t) < 3.0 * std, (c, w, t)
