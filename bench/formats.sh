#!/usr/bin/env bash
# Reading speed per format: `rotorid inspect FILE` (reads and checks every sample, then
# prints each channel's range) on one record of 1,000,001 rows x 6 channels (table1, 100 s
# at 10 kHz; 45.8 MiB of f64) written by each ecosystem's reference tool (bench/formats.py:
# numpy, pyarrow, scipy, h5py, npTDMS, pyuff), each paired with `rotorid inspect` of the
# same record as CSV in one farm-bench call (A B A B ...). Prints, per file: its size, the
# median wall time, file MB/s, peak memory and its ratio to the channels, and how many
# times faster than the CSV it reads (the median of the pairs).
#
#   bash bench/formats.sh [RUNS]      (default 11)
#
# Needs the release binary (built here), farm-bench (the tool library), and Python 3 (a
# venv with the reference tools is made under target/formats-venv from PyPI). Files go to
# target/bench-data.
runs="${1:-11}"
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
py=$(venv formats-venv numpy scipy h5py npTDMS pyarrow pyuff)
record csv >/dev/null
npz=$(record npz)
if [ ! -s "$data/formats/rec_58b.uff" ]; then
  "$py" bench/formats.py "$npz" "$data/formats"
fi

"$py" - "$runs" "$rotorid" "$data" <<'PY'
import os, re, subprocess, sys
runs, rotorid, data = sys.argv[1], sys.argv[2], sys.argv[3]
csv = f"{data}/table1_100s.csv"
channels = 6 * 1_000_001 * 8 / 2**20
files = ["rec.npz", "rec.parquet", "rec_v5.mat", "rec_v73.mat", "rec.tdms", "rec_10seg.tdms",
         "rec_58b.uff"]
print(f"{'file':16s} {'MB':>6s} {'wall':>7s} {'MB/s':>6s} {'peak MiB':>9s} {'/chan':>6s} "
      f"{'CSV wall':>8s} {'x CSV':>6s}")
for f in files:
    path = f"{data}/formats/{f}"
    out = subprocess.run(["farm-bench", "-n", runs, "--vs", f"{rotorid} inspect {csv}", "--",
                          rotorid, "inspect", path], check=True, capture_output=True,
                         text=True).stdout
    med = lambda label: float(re.search(rf"^{re.escape(label)}\s+\S+\s+(\S+)", out, re.M)[1])
    wall, peak, csv_wall, ratio = med("A wall s"), med("A peak MiB"), med("B wall s"), med("A/B wall")
    mb = os.path.getsize(path) / 1e6
    print(f"{f:16s} {mb:6.1f} {wall:7.3f} {mb / wall:6.0f} {peak:9.1f} {peak / channels:6.2f} "
          f"{csv_wall:8.3f} {1 / ratio:6.1f}")
PY
