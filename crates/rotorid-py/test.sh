#!/usr/bin/env bash
# Build and test rotorid's Python package from this checkout: the package built once as a
# wheel (maturin builds the Rust extension, in the dev profile), installed into a virtual
# environment (created once, then reused) with the test requirements; the `rotorid`
# command for the parity tests (dev profile); then pytest on tests/. Then the ROSS tests
# (tests_ross/: rotorid's bearings in ROSS, the rotordynamics library, checked against
# its eigenvalues): the same wheel (abi3, one build serves both) in a second virtual
# environment with Python 3.13, which ross-rotordynamics needs.
# Needs the Rust toolchain and Python >= 3.10; the ROSS tests also Python 3.13 (found as
# ROTORID_ROSS_PYTHON, else `python3.13`, else pyenv's 3.13.x); everything else comes from
# PyPI.
#
#   crates/rotorid-py/test.sh [pytest arguments]     (the arguments go to tests/ only)
#
# Without Python 3.13 the ROSS tests cannot run: under CI=true (.ci/run) that is a failure,
# so CI never passes without its independent check of the frame mapping; elsewhere they
# are skipped with the reason printed, so a developer without 3.13 still runs the rest.
# ROTORID_SKIP_ROSS=1 skips them on purpose (also under CI, where it is printed).
#
# Time (2 busy cores): the ROSS environment takes ~6 min to create the first time
# (ross-rotordynamics and its dependencies from PyPI, mostly downloads) and ~2 s when it
# exists; its tests take 15-50 s, most of it importing ROSS.
#
# Environment: CARGO_TARGET_DIR (default <repo>/target) holds the build, the wheel and the
# two venvs (ROTORID_VENV and ROTORID_ROSS_VENV override their paths); PYTHON picks the
# main interpreter (default python3); ROTORID_BIN names a `rotorid` binary to use instead
# of building one.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
target="${CARGO_TARGET_DIR:-$root/target}"
venv="${ROTORID_VENV:-$target/rotorid-py-venv}"
ross_venv="${ROTORID_ROSS_VENV:-$target/rotorid-py-ross-venv}"
wheels="$target/rotorid-py-wheel"
python="${PYTHON:-python3}"
# ROSS and its pins: a new ROSS release is taken on purpose, not by surprise
ross_requirements=("ross-rotordynamics==3.1.0" "pytest>=8,<10")

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
# compiles them all again; a user's `pip install` builds in release. One wheel: the
# extension is abi3 (Python >= 3.10), so the ROSS environment installs the same file.
echo "== building the package's wheel (pip wheel crates/rotorid-py)"
rm -rf "$wheels"
MATURIN_PEP517_ARGS="${MATURIN_PEP517_ARGS:---profile dev}" CARGO_TARGET_DIR="$target" \
    "$py" -m pip wheel --quiet --disable-pip-version-check --no-deps --wheel-dir "$wheels" "$here"
wheel=("$wheels"/rotorid-*.whl)
if [ "${#wheel[@]}" -ne 1 ] || [ ! -f "${wheel[0]}" ]; then
    echo "error: expected one rotorid wheel in $wheels, found: ${wheel[*]}" >&2
    exit 1
fi
echo "== installing ${wheel[0]##*/}"
"$py" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "${wheel[0]}"

# ROTORID_BIN set by the caller (.ci/test: the binary `cargo test --workspace` just built
# for its own end-to-end tests) is used as it is; else it is built here, dev profile
if [ -z "${ROTORID_BIN:-}" ]; then
    echo "== building the rotorid command (parity tests)"
    (cd "$root" && CARGO_TARGET_DIR="$target" cargo build --quiet -p rotorid-cli)
    export ROTORID_BIN="$target/debug/rotorid"
fi
echo "== the rotorid command of the parity tests: $ROTORID_BIN"

echo "== pytest"
(cd "$here" && "$py" -m pytest -p no:cacheprovider tests "$@")

# --- the ROSS tests, in their own environment (Python 3.13) ---
# A Python 3.13 interpreter that runs (a pyenv shim for a version not selected exists but
# fails, so each candidate is tried).
find_python313() {
    local c
    for c in "${ROTORID_ROSS_PYTHON:-}" python3.13 \
        "$(pyenv root 2>/dev/null || echo "$HOME/.pyenv")"/versions/3.13*/bin/python3.13; do
        [ -n "$c" ] || continue
        if "$c" -c 'import sys; assert sys.version_info[:2] == (3, 13)' >/dev/null 2>&1; then
            command -v "$c"
            return 0
        fi
    done
    return 1
}

if [ "${ROTORID_SKIP_ROSS:-}" = 1 ]; then
    echo "== ROSS tests skipped: ROTORID_SKIP_ROSS=1"
    exit 0
fi
if ! py313="$(find_python313)"; then
    reason="no Python 3.13 (ross-rotordynamics needs it): tried \$ROTORID_ROSS_PYTHON, python3.13 and pyenv's versions/3.13*"
    if [ "${CI:-}" = true ]; then
        echo "error: the ROSS tests cannot run: $reason; install Python 3.13 or set ROTORID_ROSS_PYTHON" >&2
        exit 1
    fi
    echo "== ROSS tests SKIPPED: $reason (under CI=true this fails)"
    exit 0
fi
if [ ! -x "$ross_venv/bin/python" ]; then
    echo "== creating the ROSS environment $ross_venv with $py313 (once: ~6 min of downloads)"
    "$py313" -m venv "$ross_venv"
fi
rpy="$ross_venv/bin/python"
echo "== installing ${ross_requirements[*]} and ${wheel[0]##*/} into the ROSS environment"
"$rpy" -m pip install --quiet --disable-pip-version-check "${ross_requirements[@]}"
"$rpy" -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps "${wheel[0]}"

echo "== pytest (ROSS)"
cd "$here"
"$rpy" -m pytest -p no:cacheprovider tests_ross
