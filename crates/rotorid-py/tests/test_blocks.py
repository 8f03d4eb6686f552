"""rotorid.read_blocks: a record a block of rows at a time (TDMS and Parquet streamed by
rotorid_io::stream, the other formats read whole and handed out), against rotorid.read of
the same file, and fed to a Session against rotorid.identify of the whole record."""

from __future__ import annotations

import pathlib

import numpy as np
import pandas as pd
import pytest
from pandas.testing import assert_frame_equal

import rotorid

FIXTURES = pathlib.Path(__file__).resolve().parents[2] / "rotorid-io" / "fixtures"

# the same record written by pyarrow, npTDMS, numpy and rotorid (fixtures/make.py)
FILES = ["ident.parquet", "ident.tdms", "ident.npz", "ident.csv"]


@pytest.mark.parametrize("name", FILES)
@pytest.mark.parametrize("rows", [1, 7, 1000, 10**9])
def test_blocks_are_the_record_read_whole(name, rows):
    path = FIXTURES / name
    whole = rotorid.read(path)
    blocks = list(rotorid.read_blocks(path, rows=rows))
    assert all(0 < len(b) <= rows for b in blocks)
    # each block indexed by sample number, continuing the one before
    starts = [b.index[0] for b in blocks]
    assert starts == list(range(0, len(whole), rows))
    assert all(b.attrs["units"] == whole.attrs["units"] for b in blocks)
    joined = pd.concat(blocks)
    assert_frame_equal(joined.reset_index(drop=True), whole, check_exact=True)
    assert np.array_equal(joined.index.to_numpy(), np.arange(len(whole)))


def test_channels_named_in_full_read_as_read_reads_them():
    # the channels by their full names (group/channel)
    path = FIXTURES / "ident.tdms"
    columns = "rotor/t,rotor/x,rotor/z,rotor/phi,rotor/phi_dot,rotor/phi_ddot"
    whole = rotorid.read(path, columns=columns)
    joined = pd.concat(rotorid.read_blocks(path, columns=columns, rows=100))
    assert_frame_equal(joined.reset_index(drop=True), whole, check_exact=True)


@pytest.mark.parametrize("name", ["ident.parquet", "ident.tdms"])
def test_a_session_fed_blocks_identifies_as_the_whole_record(name, table1):
    path = FIXTURES / name
    batch = rotorid.identify(rotorid.read(path), table1, method="algebraic")
    s = rotorid.Session(table1, method="algebraic")
    for b in rotorid.read_blocks(path, rows=256):
        s.push(b.x, b.z, t=b.t, phi=b.phi, phi_dot=b.phi_dot, phi_ddot=b.phi_ddot)
    live = s.finish()
    assert live.to_dict() == batch.to_dict()
    assert_frame_equal(live.estimates, batch.estimates, check_exact=True)


def test_errors_come_when_the_file_is_opened():
    with pytest.raises(ValueError, match="rows = 0 is out of range"):
        rotorid.read_blocks(FIXTURES / "ident.parquet", rows=0)
    # a channel that is not there: at the call, naming what the file has
    with pytest.raises(ValueError, match="no channel \"nope\""):
        rotorid.read_blocks(FIXTURES / "ident.tdms", columns="t,nope,z")
    with pytest.raises(FileNotFoundError):
        rotorid.read_blocks(FIXTURES / "missing.parquet")


def test_a_fault_later_in_the_file_is_raised_by_the_block_that_reaches_it():
    # nulls.parquet (pyarrow): x = [1.0, null, 3.0]; read as t, x and z, a row at a time
    it = rotorid.read_blocks(FIXTURES / "nulls.parquet", columns="x,x,x", rows=1)
    first = next(it)
    assert first.index.tolist() == [0] and first["x"].tolist() == [1.0]
    with pytest.raises(ValueError, match=r"channel \"x\".*row 1 of row group 0.*a null"):
        next(it)
