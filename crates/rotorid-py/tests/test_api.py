"""The package's API: scenarios, simulate, read, results and their presentation."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pandas.testing import assert_frame_equal

import rotorid


def test_scenarios_three_ways(tmp_path, table1):
    keys = table1.to_dict()
    assert keys["kx"] == 1.195e6 and keys["alpha_deg"] == 45.0 and keys["rpm"] == pytest.approx(1200)
    again = rotorid.Scenario(**keys)
    assert again.origin == "Scenario()"
    assert_frame_equal(rotorid.simulate(again), rotorid.simulate(table1), rtol=1e-12)
    f = tmp_path / "rig.toml"
    f.write_text("[rotor]\na = 2.871\nm_u = 1e-4\nd = 0.15\nalpha_deg = 45\n[speed]\nkind = \"constant\"\nrpm = 1200\n")
    rig = rotorid.Scenario.from_toml(f)
    assert rig.origin == str(f)
    assert rig.to_dict() == {"model": "jeffcott", "a": 2.871, "m_u": 1e-4, "d": 0.15, "alpha_deg": 45.0,
                             "rpm": pytest.approx(1200), "phi0_deg": 0.0}
    assert rotorid.Scenario.load("table1").to_dict() == keys
    assert repr(table1) == "Scenario.table1()"
    assert repr(rig) == f"Scenario.from_toml({str(f)!r})".replace("'", '"')
    assert repr(rotorid.Scenario(a=0.0, m_u=0.0, d=0.0, alpha_deg=0.0, kx=1e6)) == \
        "Scenario(kx=1000000.0, a=0.0, m_u=0.0, d=0.0, alpha_deg=0.0)"


def test_simulate_columns_and_overrides(table1):
    df = rotorid.simulate(table1, method="newmark", duration=0.01, dt=1e-3, x0=1e-5)
    assert list(df.columns) == ["t", "x", "z", "phi", "phi_dot", "phi_ddot"]
    assert (df.dtypes == np.float64).all()
    assert df.t.tolist() == [i * 1e-3 for i in range(11)]
    assert df.x[0] == 1e-5


def test_params_estimates_and_masking(clean, table1):
    alg = rotorid.identify(clean, "table1", method="algebraic")
    assert list(alg.params.index) == ["m_x", "cx", "kx", "m_z", "cz", "kz"]
    assert list(alg.params.columns) == ["value", "std_error", "crb", "unit", "truth", "rel_error"]
    assert alg.params.loc["kx", "unit"] == "N/m"
    assert alg.params["rel_error"].abs().max() < 1e-6
    e = alg.estimates
    assert list(e.columns) == rotorid.ESTIMATE_COLUMNS and len(e) == len(clean)
    # the first three samples cannot be well conditioned: values withheld, rcond kept
    assert e.iloc[:3][["m_x", "k_z"]].isna().all().all() and (e.iloc[:3]["rcond_x"] < 1e-5).all()
    assert e.iloc[-1]["k_x"] == pytest.approx(1.195e6, rel=1e-6)
    ref = rotorid.identify(clean, table1, method="refine", unknowns=["m", "kx", "kz", "unbalance"])
    assert list(ref.params.index) == ["m", "kx", "kz", "mud", "alpha"]
    assert ref.params.loc["alpha", "unit"] == "rad"
    assert not math.isnan(ref.params.loc["kx", "crb"])
    assert len(ref.estimates) == 1
    three = rotorid.identify(clean, table1, method="refine", unknowns=["m", "kx", "kz"])
    assert three.rotor["cx"] == 10.0 and three.rotor["mud"] == 1.5e-5  # known, from the scenario


def test_repr_html_and_plot(noisy, clean, table1):
    import matplotlib

    matplotlib.use("Agg")
    res = rotorid.identify(noisy, table1, method="refine")
    html = res._repr_html_()
    assert "<table>" in html and "<td>kx</td>" in html and "N s/m" in html
    assert repr(res).startswith("<rotorid.Identification method=refine samples=10001 model=jeffcott>")
    fig = res.plot()
    assert fig.axes and fig.axes[0].get_ylabel() == "relative to truth"
    fig = rotorid.identify(clean, table1, method="algebraic").plot()
    assert [a.get_ylabel() for a in fig.axes] == ["m [kg]", "c [N s/m]", "k [N/m]"]


def test_warnings_are_the_diagnostics(table1):
    # a record at rest with no unbalance: nothing excites the rotor
    still = rotorid.Scenario(m=14.29, cx=10.0, kx=1.195e6, cz=10.0, kz=1.195e6, a=2.871, m_u=0.0,
                             d=0.15, alpha_deg=45.0, rpm=1200.0, dt=1e-4, duration=0.1)
    res = rotorid.identify(rotorid.simulate(still, snr_db=40, seed=1), still, method="refine")
    assert res.warnings and res.warnings == [d["message"] for d in res.to_dict()["diagnostics"]]


def test_read_takes_every_format_the_cli_takes(tmp_path, cli):
    """A record written as Parquet, MAT and NPZ by the CLI reads back as the CSV does, and
    `columns` picks channels by other names."""
    import subprocess

    csv = tmp_path / "r.csv"
    subprocess.run([cli, "simulate", "--scenario", "table1", "--duration", "0.05", "--out", str(csv)], check=True)
    ref = rotorid.read(csv)
    for ext in ("parquet", "mat", "npz"):
        p = tmp_path / f"r.{ext}"
        subprocess.run([cli, "simulate", "--scenario", "table1", "--duration", "0.05", "--out", str(p)], check=True)
        df = rotorid.read(p)
        assert_frame_equal(df, ref, check_exact=True)
    np.savez(tmp_path / "other.npz", time=ref["t"].to_numpy(), xx=ref["x"].to_numpy() * 1e6, zz=ref["z"].to_numpy())
    df = rotorid.read(tmp_path / "other.npz", columns="time,xx,zz")
    assert np.array_equal(df["x"].to_numpy(), ref["x"].to_numpy() * 1e6)
    with pytest.raises(ValueError, match="no channel"):
        rotorid.read(tmp_path / "other.npz")


def test_restart_gives_windows_and_is_refused_for_other_methods():
    sc = rotorid.Scenario.table1()
    df = rotorid.simulate(sc, duration=0.2)
    res = rotorid.identify(df, sc, method="algebraic", restart=0.05)
    d = res.to_dict()["algebraic"]
    assert d["restart_s"] == 0.05 and d["windows"] == 9
    with pytest.raises(ValueError, match="restart applies to method algebraic only"):
        rotorid.identify(df, sc, method="modulating", restart=0.05)


def test_rounded_stamps_are_a_note_and_jitter_is_refused():
    """Stamps printed with 6 decimals at 25.6 kHz (as pandas reads such a CSV) identify with
    the true period and a note, not a warning; 2 % jitter printed alike is refused, as by
    the CLI."""
    sc = rotorid.Scenario.table1()
    df = rotorid.simulate(sc, dt=1 / 25600, duration=0.3, snr_db=40, seed=3)
    rounded = df.copy()
    rounded["t"] = rounded["t"].round(6)
    res = rotorid.identify(rounded, sc, method="modulating")
    assert len(res.notes) == 1 and "printed to 1e-6 s" in res.notes[0], res.notes
    assert all("printed to" not in w for w in res.warnings)
    assert abs(res.to_dict()["record"]["dt_s"] * 25600 - 1) < 1e-8
    exact = rotorid.identify(df, sc, method="modulating")
    assert exact.notes == []
    rng = np.random.default_rng(1)
    n = len(df)
    jittered = df.copy()
    jittered["t"] = (np.arange(n) / 25600 + 0.02 / 25600 * rng.standard_normal(n)).round(6)
    with pytest.raises(ValueError, match="sampling is not uniform"):
        rotorid.identify(jittered, sc, method="modulating")
