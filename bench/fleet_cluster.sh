#!/usr/bin/env bash
# What replication costs: the fleet on a 3-node nats-server cluster (JetStream on each
# node, its own store) with every stream, bucket and consumer at 1 and then at 3 replicas:
#   bash bench/fleet_cluster.sh [MACHINES=8] [SECONDS=10] [WORKERS=2]
# For each replica count, on a fresh cluster: MACHINES recordings of SECONDS s at 10 kHz
# (table1, 40 dB; 1 s windows with the speed channels, 400 kB each) published at once by
# MACHINES `rotorid publish --rate max` processes (windows acknowledged per second, and MB
# per second, the reading of each CSV included); then WORKERS `rotorid worker`s (modulating)
# drain them (windows identified per second, from their start to the last result in
# `rotorid fleet status`). ROTORID_BIN=path uses that binary instead of building the
# release one. Needs nats-server. Not a test: it prints figures; the load average is
# printed with them (the machine is shared).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
if [ -n "${ROTORID_BIN:-}" ]; then rotorid="$ROTORID_BIN"; else source bench/common.sh; fi
machines=${1:-8}
seconds=${2:-10}
workers=${3:-2}
work=$(mktemp -d)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
now() { date +%s.%N; }

for i in $(seq 0 $((machines - 1))); do
  "$rotorid" simulate --scenario table1 --duration "$seconds" --snr-db 40 --seed "$i" \
    --out "$work/m$i.csv" -q
done

for replicas in 1 3; do
  dir="$work/r$replicas"
  mkdir -p "$dir"
  ports=() routes=() monitors=()
  for n in 0 1 2; do ports+=("$(free_port)"); routes+=("$(free_port)"); monitors+=("$(free_port)"); done
  route_list="nats://127.0.0.1:${routes[0]},nats://127.0.0.1:${routes[1]},nats://127.0.0.1:${routes[2]}"
  cpids=()
  for n in 0 1 2; do
    nats-server -js -a 127.0.0.1 -p "${ports[$n]}" -n "n$n" -m "${monitors[$n]}" -sd "$dir/n$n" \
      --cluster_name bench --cluster "nats://127.0.0.1:${routes[$n]}" --routes "$route_list" \
      >"$dir/n$n.log" 2>&1 &
    cpids+=($!)
    pids+=($!)
  done
  for n in 0 1 2; do
    until curl -sf "http://127.0.0.1:${monitors[$n]}/jsz" | grep -q '"leader"'; do sleep 0.2; done
  done
  list="nats://127.0.0.1:${ports[0]},nats://127.0.0.1:${ports[1]},nats://127.0.0.1:${ports[2]}"

  t0=$(now)
  ppids=()
  for i in $(seq 0 $((machines - 1))); do
    "$rotorid" publish "$work/m$i.csv" --nats "$list" --machine "m-$i" --replicas "$replicas" \
      2>"$dir/pub$i.log" &
    ppids+=($!)
  done
  for p in "${ppids[@]}"; do wait "$p"; done
  t1=$(now)
  bytes=$(cat "$dir"/pub*.log | sed -n 's/.* \([0-9]*\) bytes$/\1/p' | paste -sd+ | bc)
  windows=$(cat "$dir"/pub*.log | grep -c 'acknowledged$' || true)

  t2=$(now)
  wpids=()
  for w in $(seq 1 "$workers"); do
    "$rotorid" worker --nats "$list" --replicas "$replicas" --scenario table1 2>"$dir/worker$w.log" &
    wpids+=($!)
    pids+=($!)
  done
  until [ "$("$rotorid" fleet status --nats "$list" | awk '$1 ~ /^m-/ {s += $3} END {print s + 0}')" -ge "$windows" ]; do
    sleep 0.2
  done
  t3=$(now)
  for p in "${wpids[@]}"; do kill -TERM "$p"; wait "$p" || true; done
  python3 - "$replicas" "$windows" "$bytes" "$t0" "$t1" "$t2" "$t3" "$workers" <<'PY'
import sys, os
r, w, b = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
t0, t1, t2, t3 = map(float, sys.argv[4:8])
print(f"replicas {r}: published {w} windows ({b/1e6:.1f} MB) in {t1-t0:.2f} s: "
      f"{w/(t1-t0):.1f} windows/s, {b/1e6/(t1-t0):.1f} MB/s; "
      f"{sys.argv[8]} workers identified them in {t3-t2:.2f} s: {w/(t3-t2):.1f} windows/s; "
      f"load average {os.getloadavg()[0]:.1f}")
PY
  for p in "${cpids[@]}"; do kill -9 "$p" 2>/dev/null || true; wait "$p" 2>/dev/null || true; done
done
