"""Writes one record in every binary format rotorid reads, each with its ecosystem's
reference tool, for bench/formats.sh: the channels t, x, z, phi, phi_dot, phi_ddot of
RECORD.npz (as `rotorid simulate --out RECORD.npz` writes it) become

    OUT/rec.npz          numpy.savez (stored members)
    OUT/rec.parquet      pyarrow (snappy, its default)
    OUT/rec_v5.mat       scipy.io.savemat (MAT level 5, uncompressed)
    OUT/rec_v73.mat      h5py in MATLAB's -v7.3 layout (512-byte user block, MATLAB_class)
    OUT/rec.tdms         npTDMS, one group "rotor", one segment, units in unit_string
    OUT/rec_10seg.tdms   npTDMS, the same in 10 segments
    OUT/rec_58b.uff      pyuff, binary dataset 58 per channel but t (the abscissa)

and checks that each reads back equal with the same tool.

    python bench/formats.py RECORD.npz OUT
"""
import os
import sys

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pyuff
import scipy.io
from nptdms import ChannelObject, TdmsFile, TdmsWriter

UNITS = {"t": "s", "x": "m", "z": "m", "phi": "rad", "phi_dot": "rad/s", "phi_ddot": "rad/s^2"}
MAT73_HEADER = (b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 "
                b"HDF5 schema 1.00 .").ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM"


def main():
    record, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    rec = dict(np.load(record))
    names = [k for k in UNITS if k in rec]
    np.savez(f"{out}/rec.npz", **{k: rec[k] for k in names})
    pq.write_table(pa.table({k: rec[k] for k in names}), f"{out}/rec.parquet")
    assert all(np.array_equal(pq.read_table(f"{out}/rec.parquet")[k].to_numpy(), rec[k]) for k in names)
    scipy.io.savemat(f"{out}/rec_v5.mat", {k: rec[k].reshape(-1, 1) for k in names})
    back = scipy.io.loadmat(f"{out}/rec_v5.mat")
    assert all(np.array_equal(back[k].ravel(), rec[k]) for k in names)
    with h5py.File(f"{out}/rec_v73.mat", "w", userblock_size=512) as f:
        for k in names:
            d = f.create_dataset(k, data=rec[k].reshape(1, -1))  # MATLAB n x 1
            d.attrs["MATLAB_class"] = np.bytes_("double")
    with open(f"{out}/rec_v73.mat", "r+b") as fh:
        fh.write(MAT73_HEADER)
    for path, parts in ((f"{out}/rec.tdms", 1), (f"{out}/rec_10seg.tdms", 10)):
        with TdmsWriter(path) as w:
            for part in np.array_split(np.arange(len(rec["t"])), parts):
                w.write_segment([ChannelObject("rotor", k, rec[k][part],
                                               properties={"unit_string": UNITS[k]})
                                 for k in names])
        back = TdmsFile.read(path)
        assert all(np.array_equal(back["rotor"][k][:], rec[k]) for k in names)
    t = rec["t"]
    path = f"{out}/rec_58b.uff"
    open(path, "w").close()
    sets = [pyuff.prepare_58(
        binary=1, id1=k, func_type=1, rsp_node=1, rsp_dir=1, ref_node=0, ref_dir=0,
        ord_data_type=4, num_pts=len(t), abscissa_spacing=1, abscissa_min=float(t[0]),
        abscissa_inc=float(t[1] - t[0]), abscissa_spec_data_type=17,
        abscissa_axis_units_lab="s", ordinate_spec_data_type=0,
        ordinate_axis_units_lab=UNITS[k], orddenom_spec_data_type=0,
        orddenom_axis_units_lab="NONE", z_axis_spec_data_type=0, data=rec[k], x=t)
        for k in names if k != "t"]
    pyuff.UFF(path).write_sets(sets, mode="add")
    back = pyuff.UFF(path).read_sets()
    assert all(np.array_equal(b["data"], rec[k]) for b, k in zip(back, [n for n in names if n != "t"]))


if __name__ == "__main__":
    main()
