#!/usr/bin/env bash
# The unit, stability, conformance and integration suites built with AddressSanitizer and
# UndefinedBehaviorSanitizer (-O1 -g, no recovery: the first finding fails its test), run on lavapipe
# with validation on. Suppressions cover only the Vulkan driver stack (tools/sanitize/*.supp, each with
# its reason); our code has none. Every test runs through tools/sanitize/launch.sh, which keeps the driver
# and the validation layer loaded until exit so that the suppressions can name them; timeouts are 4x.
#
#   bash tools/sanitize.sh                      build into build-asan/, run the suites
#   bash tools/sanitize.sh --fuzz-runs 1000000  also: the model-loader fuzzer for that many executions
#   bash tools/sanitize.sh -R Cloth             extra arguments go to ctest
#
# Not part of tools/test.sh (a second full build; about as long again as the suite's own): run it
# before a release and after touching memory-handling code. Writes build-asan/sanitize-junit.xml.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
BUILD_DIR=${SWISH_ASAN_BUILD_DIR:-build-asan}
fuzz_runs=0
ctest_args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --fuzz-runs) fuzz_runs=$2; shift 2 ;;
    --help|-h) sed -n 2,13p "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) ctest_args+=("$1"); shift ;;
  esac
done

bash tools/setup.sh
flags="-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=undefined"
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$flags" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_CROSSCOMPILING_EMULATOR="$root/tools/sanitize/launch.sh" -DSWISH_TEST_TIMEOUT_SCALE=4 \
  -DSWISH_BUILD_BENCHMARKS=OFF -DSWISH_BUILD_FUZZERS=$([ "$fuzz_runs" -gt 0 ] && echo ON || echo OFF) >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1:detect_stack_use_after_return=1:strict_init_order=1:check_initialization_order=1${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
export LSAN_OPTIONS="suppressions=$root/tools/sanitize/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$root/tools/sanitize/ubsan.supp"
export SWISH_VALIDATION=1
if [ "${CI:-}" = "true" ]; then export SWISH_REQUIRE_GPU=1; fi
status=0
ctest --test-dir "$BUILD_DIR" -L 'unit|stability|conformance|integration' -LE fuzz --output-on-failure \
  -j"$(nproc)" --output-junit sanitize-junit.xml "${ctest_args[@]}" || status=$?

if [ "$fuzz_runs" -gt 0 ]; then
  fuzz=$BUILD_DIR/tests/fuzz/clang/fuzz_model_loader
  corpus=$BUILD_DIR/tests/fuzz/long_corpus
  mkdir -p "$corpus" "$BUILD_DIR/tests/fuzz/artifacts"
  echo "sanitize: fuzz_model_loader for $fuzz_runs executions (corpus $corpus)"
  start=$(date +%s)
  "$fuzz" -runs="$fuzz_runs" -timeout=10 -rss_limit_mb=1024 -dict=tests/fuzz/model_loader.dict \
    -artifact_prefix="$BUILD_DIR/tests/fuzz/artifacts/" -print_final_stats=1 \
    "$corpus" "$BUILD_DIR/tests/fuzz/seed_corpus" || status=$?
  echo "sanitize: fuzzing took $(( $(date +%s) - start )) s"
fi
exit $status
