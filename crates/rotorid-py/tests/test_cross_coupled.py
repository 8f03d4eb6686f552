"""The cross-coupled model from Python: Scenario keys, identify(model=...), the model
selection, notes, and the bearing coefficients handed to ROSS (docs/method.md section 1.6,
docs/ross.md; tests_ross/ checks the mapping against ROSS itself)."""

from __future__ import annotations

import json
import math

import numpy as np
import pandas as pd
import pytest
from conftest import run
from test_parity import read_estimates
from pandas.testing import assert_frame_equal

import rotorid

# rotorid::test_models::cross_coupled_rotor (docs/method.md section 1.6)
CROSS = dict(model="cross_coupled", m=14.29, kxx=1.195e6, kxz=-3e4, kzx=3e4, kzz=1.4e6,
             cxx=200.0, cxz=20.0, czx=20.0, czz=200.0, a=2.871, m_u=1e-4, d=0.15,
             alpha_deg=45.0, rpm=1200.0, dt=1e-4, duration=1.0)
COEFFS = ["cxx", "cxz", "czx", "czz", "kxx", "kxz", "kzx", "kzz"]


@pytest.fixture(scope="module")
def cross() -> rotorid.Scenario:
    return rotorid.Scenario(**CROSS)


@pytest.fixture(scope="module")
def cross_record(cross):
    return rotorid.simulate(cross, snr_db=40, seed=1)


@pytest.fixture(scope="module")
def cross_fit(cross_record, cross):
    return rotorid.identify(cross_record, cross, method="refine", model="cross_coupled")


def test_models_are_listed():
    assert rotorid.MODELS == ["jeffcott", "cross_coupled", "auto"]


def test_cross_coupled_scenario_three_ways(tmp_path, cross):
    keys = cross.to_dict()
    assert next(iter(keys)) == "model" and keys["model"] == "cross_coupled"
    assert {k: keys[k] for k in ["m", *COEFFS]} == {k: CROSS[k] for k in ["m", *COEFFS]}
    assert not {"kx", "cx", "kz", "cz"} & set(keys)
    assert_frame_equal(rotorid.simulate(rotorid.Scenario(**keys)), rotorid.simulate(cross), rtol=1e-12)
    f = tmp_path / "cross.toml"
    f.write_text("[rotor]\nmodel = \"cross_coupled\"\nm = 14.29\nkxx = 1.195e6\nkxz = -3e4\n"
                 "kzx = 3e4\nkzz = 1.4e6\ncxx = 200\ncxz = 20\nczx = 20\nczz = 200\na = 2.871\n"
                 "m_u = 1e-4\nd = 0.15\nalpha_deg = 45\n[speed]\nkind = \"constant\"\nrpm = 1200\n"
                 "[sampling]\ndt = 1e-4\nduration = 1.0\n")
    assert_frame_equal(rotorid.simulate(rotorid.Scenario.from_toml(f)), rotorid.simulate(cross), rtol=1e-12)
    assert repr(cross).startswith('Scenario(model="cross_coupled", m=14.29, kxx=1195000.0, kxz=-30000.0')
    # the cross terms change the motion: the same rotor without them is another record
    jeff = {**CROSS, "kxz": 0.0, "kzx": 0.0, "cxz": 0.0, "czx": 0.0}
    x = rotorid.simulate(cross).x
    assert np.abs(rotorid.simulate(rotorid.Scenario(**jeff)).x - x).max() > 0.05 * np.abs(x).max()


def test_cross_coupled_scenario_errors():
    with pytest.raises(ValueError, match=r"kx is a key of rotor.model = \"jeffcott\""):
        rotorid.Scenario(**{**CROSS, "kx": 1e6})
    with pytest.raises(ValueError, match=r"kxz is a key of rotor.model = \"cross_coupled\""):
        rotorid.Scenario(m=14.29, kxz=1e4)
    with pytest.raises(ValueError, match=r"\[\[200, 500\], \[500, 200\]\] N s/m is not dissipative"):
        rotorid.Scenario(**{**CROSS, "cxz": 500.0, "czx": 500.0})
    with pytest.raises(ValueError, match=r"rotor.model = \"crossed\" is not a rotor model"):
        rotorid.Scenario(model="crossed")


def test_identify_cross_coupled(cross_fit):
    res = cross_fit
    assert res.model == "cross_coupled" and res.model_selection is None
    p = res.params
    assert list(p.index[:9]) == ["m", *COEFFS]
    # every value within 4 standard errors of the truth, and the errors near the CRB
    for name in ["m", *COEFFS]:
        r = p.loc[name]
        assert r["truth"] == CROSS[name]
        assert abs(r["value"] - r["truth"]) < 4 * r["std_error"], (name, r.to_dict())
        assert 0.5 < r["std_error"] / r["crb"] < 2, (name, r.to_dict())
    assert p.loc["kxx", "unit"] == "N/m" and p.loc["czx", "unit"] == "N s/m"
    rotor = res.rotor
    assert list(rotor)[:9] == ["m", *COEFFS]
    assert all(rotor[n] == p.loc[n, "value"] for n in ["m", *COEFFS])
    assert "model=cross_coupled" in repr(res)
    assert "model <b>cross_coupled</b> (given)" in res._repr_html_()


def test_ross_kwargs_of_the_cross_coupled_model(cross_fit):
    # docs/ross.md: ROSS's y is rotorid's -z, so the cross terms change sign
    r = cross_fit.rotor
    assert cross_fit.to_ross_bearing_kwargs() == {
        "kxx": r["kxx"], "kyy": r["kzz"], "kxy": -r["kxz"], "kyx": -r["kzx"],
        "cxx": r["cxx"], "cyy": r["czz"], "cxy": -r["cxz"], "cyx": -r["czx"],
    }
    # the identified bearing feeds forward whirl: kzx > 0 > kxz here, kxy > 0 > kyx in ROSS
    kw = cross_fit.to_ross_bearing_kwargs()
    assert kw["kxy"] > 0 > kw["kyx"]


def test_auto_takes_the_cross_coupled_model(cross_record, cross):
    res = rotorid.identify(cross_record, cross, method="refine", model="auto")
    assert res.model == "cross_coupled"
    sel = res.model_selection
    assert list(sel.index) == ["jeffcott", "cross_coupled"]
    assert list(sel.columns) == ["estimated", "log_likelihood", "bic", "adequate", "noise_ratio_x",
                                 "noise_ratio_z", "converged", "identifiable", "chosen"]
    assert sel["chosen"].tolist() == [False, True]
    # BIC = -2 log L + k ln(2N), N samples per channel
    n = len(cross_record)
    assert np.allclose(sel["bic"], -2 * sel["log_likelihood"] + sel["estimated"] * math.log(2 * n), rtol=1e-12)
    assert sel.loc["cross_coupled", "estimated"] - sel.loc["jeffcott", "estimated"] == 4
    assert sel.loc["cross_coupled", "adequate"] and not sel.loc["jeffcott", "adequate"]
    assert sel.attrs["criterion"] and sel.attrs["reason"]
    assert res.notes and all(isinstance(s, str) for s in res.notes)
    assert not set(res.notes) & set(res.warnings)
    d = res.to_dict()["diagnostics"]
    assert res.notes == [x["message"] for x in d if x["severity"] == "note"]
    assert "note: " in repr(res) and "Model selection:" in res._repr_html_()


def test_auto_takes_jeffcott_on_the_papers_rotor(noisy, table1):
    res = rotorid.identify(noisy, table1, method="refine", model="auto")
    assert res.model == "jeffcott"
    assert res.model_selection["chosen"].tolist() == [True, False]
    assert list(res.params.index[:5]) == ["m", "cx", "kx", "cz", "kz"]


def test_model_option_errors(noisy, table1):
    with pytest.raises(ValueError, match="auto"):
        rotorid.identify(noisy, table1, method="modulating", model="auto")
    with pytest.raises(ValueError, match="jeffcott, cross_coupled, auto"):
        rotorid.identify(noisy, table1, model="crossed")


def test_schema_2_summaries_read_as_jeffcott(noisy, table1):
    d = rotorid.identify(noisy, table1, method="refine").to_dict()
    d["schema"] = 2
    for k in ("model", "model_selection"):
        d.pop(k, None)
    d["diagnostics"] = [{"code": "x", "message": "old warning"}]
    old = rotorid.Identification(json.dumps(d))
    assert old.model == "jeffcott" and old.model_selection is None
    assert old.warnings == ["old warning"] and old.notes == []
    assert set(old.to_ross_bearing_kwargs()) == {"kxx", "kyy", "cxx", "cyy"}


@pytest.mark.parametrize("model", ["cross_coupled", "auto"])
def test_session_takes_the_model(cross_record, model):
    # a Session given the model ends as identify does on the whole record; the knowledge
    # states no model (Jeffcott by default), so the option is what picks it
    known = rotorid.Scenario(a=2.871, m_u=1e-4, d=0.15, alpha_deg=45.0, rpm=1200.0)
    batch = rotorid.identify(cross_record, known, method="refine", model=model)
    s = rotorid.Session(known, method="refine", dt=1e-4, model=model)
    for i in range(0, len(cross_record), 2500):
        c = cross_record.iloc[i:i + 2500]
        s.push(c.x, c.z, phi=c.phi, phi_dot=c.phi_dot, phi_ddot=c.phi_ddot)
    live = s.finish()
    assert live.model == "cross_coupled"
    d, b = live.to_dict(), batch.to_dict()
    assert d["rotor"] == b["rotor"] and d["model_selection"] == b["model_selection"]


def test_modulating_and_algebraic_of_the_cross_coupled_model(cross_record, cross, tmp_path, cli):
    # the per-row identifiers of the cross-coupled model: parameters and estimates named
    # by the model, the same numbers as `rotorid identify --model cross_coupled`
    truth = dict(m_x=14.29, m_z=14.29, **{k: CROSS[k] for k in COEFFS})
    mod = rotorid.identify(cross_record, cross, method="modulating", model="cross_coupled")
    assert mod.model == "cross_coupled"
    assert list(mod.params.index) == ["m_x", "cxx", "cxz", "kxx", "kxz",
                                      "m_z", "czx", "czz", "kzx", "kzz"]
    z = (mod.params["value"] - pd.Series(truth)) / mod.params["std_error"]
    assert (z.abs() < 4).all(), z
    assert list(mod.estimates.columns) == rotorid.ESTIMATE_COLUMNS_BY_MODEL["cross_coupled"]
    assert len(mod.estimates) == 1
    assert mod.estimates["kxz"].iloc[0] == mod.params.loc["kxz", "value"]
    alg = rotorid.identify(cross_record.iloc[:1001], cross, method="algebraic",
                           model="cross_coupled")
    assert list(alg.estimates.columns) == rotorid.ESTIMATE_COLUMNS_BY_MODEL["cross_coupled"]
    assert len(alg.estimates) == 1001
    # a session streams the same estimates, chunk by chunk
    s = rotorid.Session(cross, method="algebraic", dt=1e-4, model="cross_coupled")
    head = cross_record.iloc[:1001]
    chunks = [s.push(c.x, c.z, phi=c.phi, phi_dot=c.phi_dot, phi_ddot=c.phi_ddot)
              for c in (head.iloc[i:i + 250] for i in range(0, 1001, 250))]
    live = s.finish()
    assert all(list(c.columns) == list(alg.estimates.columns) for c in chunks)
    assert_frame_equal(live.estimates, alg.estimates)
    # the command line writes the same table
    rec = tmp_path / "r.csv"
    cross_record.iloc[:1001].to_csv(rec, index=False)
    scenario = tmp_path / "s.toml"
    rotor = "\n".join(f"{k} = {CROSS[k]!r}" for k in ["m", "a", "m_u", "d", "alpha_deg", *COEFFS])
    scenario.write_text(f'[rotor]\nmodel = "cross_coupled"\n{rotor}\n'
                        '[speed]\nkind = "constant"\nrpm = 1200.0\n')
    out = tmp_path / "e.csv"
    run(cli, "identify", str(rec), "--scenario", str(scenario), "--method", "algebraic",
        "--model", "cross_coupled", "--out", str(out), "-q")
    cli = read_estimates(out)
    assert list(cli.columns) == list(alg.estimates.columns)
    np.testing.assert_array_equal(cli.to_numpy(), alg.estimates.to_numpy())
