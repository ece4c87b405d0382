#!/usr/bin/env bash
# The main job: install what is missing, build, and run swish on the embedded default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
BUILD_DIR=${SWISH_BUILD_DIR:-build}
exec "$BUILD_DIR/swish" frames "$@"
