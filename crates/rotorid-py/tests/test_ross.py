"""to_ross_bearing_kwargs: rotorid's horizontal x is ROSS's x, its vertical z is ROSS's y."""

from __future__ import annotations

import json

import pytest

import rotorid


@pytest.mark.parametrize("method", ["modulating", "refine"])
def test_ross_mapping(noisy, table1, method):
    res = rotorid.identify(noisy, table1, method=method)
    kw = res.to_ross_bearing_kwargs()
    rotor = res.rotor
    assert kw == {"kxx": rotor["kx"], "kyy": rotor["kz"], "cxx": rotor["cx"], "cyy": rotor["cz"]}
    if method == "refine":
        p = res.params["value"]
        assert kw == {"kxx": p["kx"], "kyy": p["kz"], "cxx": p["cx"], "cyy": p["cz"]}
    assert all(abs(kw[k] / t - 1) < 0.02 for k, t in
               {"kxx": 1.195e6, "kyy": 1.195e6, "cxx": 10.0, "cyy": 10.0}.items())


def test_undetermined_values_are_refused(noisy, table1):
    d = rotorid.identify(noisy, table1, method="refine").to_dict()
    d["rotor"] = None
    for p in d["parameters"]:
        if p["parameter"] == "kz":
            p["value"] = None
    res = rotorid.Identification(json.dumps(d))
    with pytest.raises(ValueError, match="kz not determined"):
        res.to_ross_bearing_kwargs()
