#!/usr/bin/env bash
# Build and test rotorid's Python package from this checkout: a virtual environment
# (created once, then reused), the package installed with pip (maturin builds the Rust
# extension, in the dev profile), the `rotorid` command for the parity tests (dev profile),
# then pytest.
# Needs the Rust toolchain and Python >= 3.10; everything else comes from PyPI.
#
#   crates/rotorid-py/test.sh [pytest arguments]
#
# Environment: CARGO_TARGET_DIR (default <repo>/target) holds the build and the venv
# (ROTORID_VENV overrides its path); PYTHON picks the interpreter (default python3);
# ROTORID_BIN names a `rotorid` binary to use instead of building one.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
venv="${ROTORID_VENV:-$target/rotorid-py-venv}"
python="${PYTHON:-python3}"

if [ ! -x "$venv/bin/python" ]; then
    echo "== creating the virtual environment $venv"
    "$python" -m venv "$venv"
fi
py="$venv/bin/python"

echo "== installing the test requirements"
"$py" -m pip install --quiet --disable-pip-version-check \
    "maturin==1.16.*" "pytest>=8,<10" "nbclient>=0.10,<0.12" "nbformat>=5.10,<6" \
    "ipykernel>=6.29,<8" "dask>=2024.1" "pandas>=2.0,<4" "numpy>=1.26,<3" \
    "matplotlib>=3.8,<4" "mypy>=1.18,<3" "scipy>=1.11,<2"

# The dev profile here (MATURIN_PEP517_ARGS overrides): it reuses the dependencies that
# `cargo test --workspace` compiled (optimised, see Cargo.toml) where a release build
# compiles them all again; a user's `pip install` builds in release.
echo "== building and installing the package (pip install crates/rotorid-py)"
MATURIN_PEP517_ARGS="${MATURIN_PEP517_ARGS:---profile dev}" CARGO_TARGET_DIR="$target" \
    "$py" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "$here"

# ROTORID_BIN set by the caller (.ci/test: the binary `cargo test --workspace` just built
# for its own end-to-end tests) is used as it is; else it is built here, dev profile
if [ -z "${ROTORID_BIN:-}" ]; then
    echo "== building the rotorid command (parity tests)"
    (cd "$root" && CARGO_TARGET_DIR="$target" cargo build --quiet -p rotorid-cli)
    export ROTORID_BIN="$target/debug/rotorid"
fi
echo "== the rotorid command of the parity tests: $ROTORID_BIN"

echo "== pytest"
cd "$here"
"$py" -m pytest -p no:cacheprovider tests "$@"
