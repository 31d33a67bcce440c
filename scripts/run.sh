#!/usr/bin/env bash
# Sets up (Debian packages), builds, and runs romo's main job on its embedded default.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh
exec ./build/tools/romo run "$@"
