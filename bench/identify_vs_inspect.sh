#!/usr/bin/env bash
# End to end, `rotorid identify` (the algebraic method, every check on, the adequacy
# verdict included) against `rotorid inspect` of the same file (reading and parsing every
# value, identifying nothing: the floor), on a 1,000,001-row response CSV
# (`rotorid simulate` of the paper's rotor at 1200 rpm, 100 s at 10 kHz, the paper's
# Newmark integrator), both single processes as a user runs them, timed in turn (A B A B
# ...) in one run; prints medians (wall, and CPU: user + system of the child) and the
# ratio identify / inspect, of the medians and pair by pair.
#
#   bash bench/identify_vs_inspect.sh [RUNS]      (default 11)
#
# Needs the release binary (built here). The file goes to target/bench-data.
runs="${1:-11}"
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
csv="$data/table1_100s_newmark.csv"
if [ ! -s "$csv" ]; then
  "$rotorid" simulate --scenario table1 --method newmark --duration 100 --out "$csv" >&2
fi

python3 - "$runs" "$rotorid" "$csv" <<'EOF'
import resource, statistics, subprocess, sys, time
runs, rotorid, csv = int(sys.argv[1]), sys.argv[2], sys.argv[3]
identify = "rotorid identify FILE --scenario table1 --every 1000 --out /dev/null -q"
inspect = "rotorid inspect FILE"
cases = {
    identify: [rotorid, "identify", csv, "--scenario", "table1", "--every", "1000",
               "--out", "/dev/null", "-q"],
    inspect: [rotorid, "inspect", csv],
}
times = {k: [] for k in cases}
cpu = {k: [] for k in cases}  # user + system seconds of the child
for cmd in cases.values():  # warm-up (the page cache)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
for _ in range(runs):
    for k, cmd in cases.items():
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        times[k].append(time.perf_counter() - t0)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu[k].append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
for k in cases:
    print(f"{k:62s} median {statistics.median(times[k]):.3f} s over {runs} runs "
          f"(min {min(times[k]):.3f}, max {max(times[k]):.3f}), "
          f"CPU {statistics.median(cpu[k]):.3f} s")
pairs = statistics.median(a / b for a, b in zip(times[identify], times[inspect]))
ratio = statistics.median(times[identify]) / statistics.median(times[inspect])
print(f"identify / inspect: {ratio:.2f}x (median of pairs {pairs:.2f}x; "
      f"CPU {statistics.median(cpu[identify]) / statistics.median(cpu[inspect]):.2f}x)")
EOF
