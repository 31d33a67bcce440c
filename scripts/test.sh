#!/usr/bin/env bash
# Sets up (Debian packages), builds, and runs every test: unit, integration and hardware-in-loop
# (the `hil` label needs root for a private network namespace: ../shared/scripts/netns-run).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh
ctest --test-dir "${ROMO_BUILD_DIR:-build}" --output-on-failure -j "$(nproc)" "$@"
