#!/usr/bin/env bash
# The whole test suite: install what is missing, build, run every CTest test (unit, conformance,
# stability, e2e, fuzz, cluster: the last starts a one-node Slurm cluster of its own, as root). GPU tests run on the Vulkan device chosen by SWISH_DEVICE (name substring or
# index; default: the first discrete GPU, else lavapipe). Writes a JUnit report to build/junit.xml.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
BUILD_DIR=${SWISH_BUILD_DIR:-build}
# Inside CI a missing Vulkan device is a failure, not a skip.
if [ "${CI:-}" = "true" ]; then export SWISH_REQUIRE_GPU=1; fi
export SWISH_VALIDATION=${SWISH_VALIDATION:-1}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" --output-junit junit.xml "$@"
