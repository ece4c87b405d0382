#!/usr/bin/env bash
# clang-tidy over src/ and tools/ with the checks of .clang-tidy (the ones the tree keeps clean); exits
# non-zero on any finding. Needs a configured build (compile_commands.json): bash tools/build.sh first.
#
#   bash tools/tidy.sh                 every .cpp of src/ and tools/ (about 7 minutes on 2 cores)
#   bash tools/tidy.sh src/swish/gpu   only the files below the folders or files given
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${SWISH_BUILD_DIR:-build}
if [ ! -f "$BUILD_DIR/compile_commands.json" ]; then
  echo "tidy.sh: $BUILD_DIR/compile_commands.json is missing: run bash tools/build.sh first" >&2
  exit 2
fi
command -v clang-tidy >/dev/null || { echo "tidy.sh: clang-tidy is not installed (Debian: clang-tidy)" >&2; exit 2; }
paths=("$@")
[ ${#paths[@]} -gt 0 ] || paths=(src tools)
log=$(mktemp)
trap 'rm -f "$log"' EXIT
status=0
find "${paths[@]}" -name '*.cpp' | sort | xargs -P"$(nproc)" -n4 clang-tidy -p "$BUILD_DIR" --quiet >"$log" 2>/dev/null || status=$?
if grep -q "warning:\|error:" "$log"; then
  grep -A3 "warning:\|error:" "$log"
  echo "tidy.sh: $(grep -c 'warning:\|error:' "$log") finding(s)" >&2
  exit 1
fi
if [ "$status" -ne 0 ]; then
  echo "tidy.sh: clang-tidy failed (exit $status) without a finding it printed" >&2
  exit "$status"
fi
echo "tidy.sh: no findings"
