#!/usr/bin/env bash
# End to end, `rotorid identify` against the same identifier written with numpy/pandas
# (bench/numpy_identify.py: pandas.read_csv plus the vectorised identifier, trapezoid rule),
# on one 1,000,001-row response CSV (table1, 100 s at 10 kHz), all timed in turn (A B C D
# A B C D ...) in one run; prints medians (wall, and CPU: user + system of the child) and
# numpy's time over each. Three rotorid runs:
# the same identifier (--quadrature trapezoid), the default one (Adams-Moulton 5), and
# `rotorid inspect` of the same file, which reads and parses every value and identifies
# nothing: the floor any `identify` of a CSV stays above.
#
#   bash bench/identify_vs_numpy.sh [RUNS]      (default 5)
#
# Needs the release binary (built here) and Python 3 with numpy and pandas (a venv is made
# under target/bench-venv from PyPI). Files go to target/bench-data.
runs="${1:-5}"
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
py=$(venv bench-venv "numpy>=1.26,<3" "pandas>=2.0,<4")
csv=$(record csv)

"$py" - "$runs" "$rotorid" "$py" "$csv" "$data" <<'EOF'
import resource, statistics, subprocess, sys, time
runs, rotorid, py, csv, data = int(sys.argv[1]), *sys.argv[2:]
numpy = "numpy/pandas identifier, trapezoid --every 1000"
cases = {
    "rotorid identify --quadrature trapezoid --every 1000": [rotorid, "identify", csv,
        "--scenario", "table1", "--quadrature", "trapezoid", "--every", "1000",
        "--out", f"{data}/est_rs_trapezoid.csv"],
    "rotorid identify --every 1000 (default am5)": [rotorid, "identify", csv, "--scenario",
        "table1", "--every", "1000", "--out", f"{data}/est_rs.csv"],
    "rotorid inspect (reading alone: the floor)": [rotorid, "inspect", csv],
    numpy: [py, "bench/numpy_identify.py", csv, f"{data}/est_np.csv", "--every", "1000"],
}
times = {k: [] for k in cases}
cpu = {k: [] for k in cases}  # user + system seconds of the child
for k, cmd in cases.items():  # warm-up
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
for _ in range(runs):
    for k, cmd in cases.items():
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times[k].append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu[k].append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
med = {k: statistics.median(v) for k, v in times.items()}
med_cpu = {k: statistics.median(v) for k, v in cpu.items()}
for k, v in med.items():
    print(f"{k:56s} median {v:.3f} s over {runs} runs (min {min(times[k]):.3f}), "
          f"CPU {med_cpu[k]:.3f} s")
for k, v in med.items():
    if k != numpy:
        pairs = statistics.median(b / a for a, b in zip(times[k], times[numpy]))
        print(f"numpy/pandas over {k}: {med[numpy] / v:.1f}x (median of pairs {pairs:.1f}x; "
              f"CPU time {med_cpu[numpy] / med_cpu[k]:.1f}x)")
EOF
