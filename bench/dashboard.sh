#!/usr/bin/env bash
# The dashboard under a fleet of 50 machines (bench/dashboard.py says what is measured):
#   bash bench/dashboard.sh [--seconds 60] [--pages 3] [--idle 60] [--screenshots docs/]
# Needs nats-server, chromium and chromium-driver (Debian packages; .ci/test installs them).
# Not a test: it prints figures; run it on an otherwise idle machine.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
python3 bench/dashboard.py "$rotorid" "$@"
