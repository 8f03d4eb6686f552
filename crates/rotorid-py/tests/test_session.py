"""A Session fed chunk by chunk gives what identify gives for the whole record."""

from __future__ import annotations

import pandas as pd
import pytest
from pandas.testing import assert_frame_equal

import rotorid

SPEED = ("phi", "phi_dot", "phi_ddot")


def chunks(df: pd.DataFrame, size: int):
    for start in range(0, len(df), size):
        yield df.iloc[start:start + size]


def without_grid_fit(d: dict) -> dict:
    """The summary without what only stamps give: the grid's fit and the stamps' deviation."""
    d = dict(d)
    drop = ("grid_fitted_over", "max_time_deviation_s")
    d["record"] = {k: v for k, v in d["record"].items() if k not in drop}
    return d


@pytest.mark.parametrize("method", ["algebraic", "modulating", "refine"])
def test_stamped_chunks_equal_the_batch(noisy, table1, method):
    batch = rotorid.identify(noisy, table1, method=method)
    s = rotorid.Session(table1, method=method)
    pushed = []
    for c in chunks(noisy, 1000):
        pushed.append(s.push(c.x, c.z, t=c.t, phi=c.phi, phi_dot=c.phi_dot, phi_ddot=c.phi_ddot))
    assert s.samples == len(noisy)
    live = s.finish()
    assert live.to_dict() == batch.to_dict()
    assert_frame_equal(live.estimates, batch.estimates, check_exact=True)
    if method == "algebraic":
        # the grid is fitted over the first 4096 stamps: nothing before, then all of them
        sizes = [len(p) for p in pushed]
        assert sizes[:4] == [0, 0, 0, 0] and sizes[4] == 5000 and sum(sizes) == len(noisy)
    else:
        assert all(p.empty for p in pushed)


def test_chunks_on_a_given_grid_equal_the_batch(noisy, table1):
    batch = rotorid.identify(noisy, table1, method="algebraic")
    s = rotorid.Session(table1, method="algebraic", dt=1e-4)
    first = s.push(noisy.x[:700], noisy.z[:700], **{k: noisy[k][:700] for k in SPEED})
    assert len(first) == 700  # on a given grid every sample gives its estimate at once
    for c in chunks(noisy.iloc[700:], 777):
        s.push(c.x, c.z, **{k: c[k] for k in SPEED})
    live = s.finish()
    # identical but for the grid's provenance (given, without stamps: fitted over none)
    assert without_grid_fit(live.to_dict()) == without_grid_fit(batch.to_dict())
    assert live.to_dict()["record"]["grid_fitted_over"] == 0
    assert_frame_equal(live.estimates, batch.estimates, check_exact=True)


def test_the_scenarios_profile_gives_the_speed(clean, table1):
    s = rotorid.Session(table1, method="algebraic", dt=1e-4)
    est = pd.concat([s.push(c.x, c.z) for c in chunks(clean, 500)])
    res = s.finish()
    assert res.to_dict()["record"]["speed"] == "profile"
    assert len(est) == len(clean)
    assert res.params["rel_error"].abs().max() < 1e-6


def test_start_now_and_finished_sessions(noisy, table1):
    s = rotorid.Session(table1, method="algebraic")
    head = noisy.iloc[:100]
    assert s.push(head.x, head.z, t=head.t, **{k: head[k] for k in SPEED}).empty
    assert len(s.start_now()) == 100
    s.finish()
    with pytest.raises(ValueError, match="the session is finished"):
        s.push(head.x, head.z, t=head.t)
    stamped = rotorid.Session(table1, method="algebraic")
    with pytest.raises(ValueError, match="t is missing"):
        stamped.push(head.x, head.z)


def test_errors_name_the_index_in_the_stream(noisy, table1):
    s = rotorid.Session(table1, method="algebraic", dt=1e-4)
    a = noisy.iloc[:50]
    s.push(a.x, a.z, **{k: a[k] for k in SPEED})
    b = noisy.iloc[50:60].copy()
    b.iloc[3, b.columns.get_loc("x")] = float("nan")
    with pytest.raises(ValueError, match="sample 53: x = NaN"):
        s.push(b.x, b.z, **{k: b[k] for k in SPEED})
    assert s.samples == 53  # the samples before the bad one were taken


def test_a_keyphasor_angle_alone(clean, table1):
    """phi alone: speed and acceleration from the scenario's profile (here the same)."""
    full = rotorid.Session(table1, method="algebraic", dt=1e-4)
    angle = rotorid.Session(table1, method="algebraic", dt=1e-4)
    for c in chunks(clean, 300):
        a = full.push(c.x, c.z, **{k: c[k] for k in SPEED})
        b = angle.push(c.x, c.z, phi=c.phi)
        assert_frame_equal(a, b, check_exact=True)
    assert angle.finish().to_dict() == full.finish().to_dict()
    stamped = rotorid.Session(table1, method="refine")
    for c in chunks(clean, 1000):
        stamped.push(c.x, c.z, t=c.t, phi=c.phi, phi_dot=c.phi_dot)
    assert stamped.finish().params["rel_error"].abs().max() < 1e-6
    known = rotorid.Scenario(a=2.871, m_u=1e-4, d=0.15, alpha_deg=45.0)
    s = rotorid.Session(known, method="algebraic", dt=1e-4)
    with pytest.raises(ValueError, match="phi is given without phi_dot and phi_ddot"):
        s.push(clean.x, clean.z, phi=clean.phi)
    with pytest.raises(ValueError, match="missing phi; give all three or none"):
        s.push(clean.x, clean.z, phi_dot=clean.phi_dot, phi_ddot=clean.phi_ddot)
