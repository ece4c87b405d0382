#!/usr/bin/env bash
# The main job: install what is missing, build, and run swish on the embedded default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
BUILD_DIR=${SWISH_BUILD_DIR:-build}
# With no arguments: the default 22-character scene, report under ./replay-out/.
exec "$BUILD_DIR/swish" replay "$@"
