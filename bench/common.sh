# Sourced by the bench scripts: from the repository's root, builds the release binary and
# sets `target`, `data` (target/bench-data, created) and `rotorid`; `venv DIR PACKAGE...`
# makes a venv under target with those PyPI packages unless it exists and prints its
# python; `record EXT` writes the benchmark record (table1, 100 s at 10 kHz: 1,000,001
# rows) as data/table1_100s.EXT unless it exists and prints its path.
set -euo pipefail
shopt -s inherit_errexit
cd "$(dirname "${BASH_SOURCE[0]}")/.."
target="${CARGO_TARGET_DIR:-$PWD/target}"
data="$target/bench-data"
mkdir -p "$data"
cargo build --release -q -p rotorid-cli
rotorid="$target/release/rotorid"

venv() {
  local dir="$target/$1"
  shift
  if [ ! -x "$dir/bin/python" ]; then
    python3 -m venv "$dir"
    "$dir/bin/pip" install -q --disable-pip-version-check "$@"
  fi
  echo "$dir/bin/python"
}

record() {
  local file="$data/table1_100s.$1"
  if [ ! -s "$file" ]; then
    "$rotorid" simulate --scenario table1 --duration 100 --out "$file" >&2
  fi
  echo "$file"
}
