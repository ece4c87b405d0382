#!/usr/bin/env bash
# A self-contained copy of the GPU checks, to run on a machine that has a Vulkan driver but not this
# build: a device lab, a render backend's CI, a rented GPU. It holds the conformance and integration
# suites, bench_deform and bench_replay (when built), the swish program, the default model and scene
# with the scene's clips, the non-system shared libraries they link (the Vulkan loader aside: the
# target's own is used), the Khronos validation layer, and run.sh, which runs them all on the device
# it is given and writes the results into one folder.
#
#   bash tools/bundle.sh OUT_DIR [BUILD_DIR]      (BUILD_DIR: build/)
#   OUT_DIR/run.sh [DEVICE] [RESULTS_DIR]         on the target; DEVICE as SWISH_DEVICE (name or index)
#
# The binaries are this machine's (x86-64, glibc of Debian 12 or newer on the target). Without a
# Vulkan loader on the target, copy one in beside them (lib/libvulkan.so.1).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=${1:?usage: tools/bundle.sh OUT_DIR [BUILD_DIR]}
build=${2:-build}
[ -x "$build/swish" ] || { echo "bundle: $build/swish is not built (bash tools/build.sh first)" >&2; exit 1; }
mkdir -p "$out/bin" "$out/lib" "$out/layers" "$out/source/assets/scenes" "$out/clips"
out=$(cd "$out" && pwd)

bins=("$build/swish")
for f in "$build"/tests/conformance_test_* "$build"/tests/integration_test_* "$build"/tests/bench_deform \
  "$build"/tests/bench_replay; do
  [ -x "$f" ] && [ -f "$f" ] && bins+=("$f")
done
for f in "${bins[@]}"; do strip -o "$out/bin/$(basename "$f")" "$f"; done

# Shared libraries, except the C/C++ runtime and the Vulkan loader, which the target has.
for f in "${bins[@]}"; do ldd "$f"; done | awk '/=> \// { print $3 }' | sort -u |
  grep -v -E '/(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt|ld-linux[^/]*|libvulkan)\.so' |
  while read -r lib; do cp -L "$lib" "$out/lib/" && strip "$out/lib/$(basename "$lib")"; done

# The validation layer, its manifest pointing at the library beside it.
layer=$(ldconfig -p | awk '$1 == "libVkLayer_khronos_validation.so" && !p { print $NF; p = 1 }')
manifest=/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json
if [ -n "$layer" ] && [ -f "$manifest" ]; then
  strip -o "$out/layers/libVkLayer_khronos_validation.so" "$layer"
  sed 's#"library_path": *"[^"]*"#"library_path": "./libVkLayer_khronos_validation.so"#' "$manifest" \
    >"$out/layers/VkLayer_khronos_validation.json"
else
  echo "bundle: no validation layer here (vulkan-validationlayers): the bundle runs without it" >&2
fi

# The default model and scene (the benchmarks and the replay read them from SWISH_SOURCE_DIR), the
# scene's clips beside them and the scene pointed at them
mkdir -p "$out/source/assets/default"
cp assets/default/default.swish "$out/source/assets/default/"
scene=assets/scenes/football.json
grep -o '"file": *"[^"]*"' "$scene" | sed 's/.*"\([^"]*\)"$/\1/' | sort -u | while read -r clip; do
  cp "$clip" "$out/clips/"
done
# (relative to the scene file, so that the bundle can move)
sed 's#"file": *"[^"]*/\([^/"]*\)"#"file": "../../../clips/\1"#' "$scene" >"$out/source/$scene"

cat >"$out/run.sh" <<'EOF'
#!/usr/bin/env bash
# Runs the bundle's GPU checks on DEVICE (SWISH_DEVICE: a name substring or an index; default: the
# device swish picks) and writes everything into RESULTS_DIR (default: ./results): each suite's JUnit
# XML and log (validation layer on; a validation message fails the test), bench_deform and bench_replay
# as JSON (validation off), and the default scene's replay report.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
device=${1:-}
results=$(mkdir -p "${2:-results}" && cd "${2:-results}" && pwd)
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export VK_LAYER_PATH="$here/layers" SWISH_REQUIRE_GPU=1 SWISH_SOURCE_DIR="$here/source"
export SWISH_DEFAULT_MODEL="$here/source/assets/default/default.swish"
[ -n "$device" ] && export SWISH_DEVICE="$device"
[ -f "$here/layers/VkLayer_khronos_validation.json" ] || export SWISH_VALIDATION=0
status=0
"$here/bin/swish" devices | tee "$results/devices.txt" || status=1
for t in "$here"/bin/conformance_test_* "$here"/bin/integration_test_*; do
  name=$(basename "$t")
  "$t" --gtest_output="xml:$results/$name.xml" >"$results/$name.log" 2>&1 && r=passed || { r=FAILED; status=1; }
  echo "$name: $r ($(grep -c '^\[       OK \]' "$results/$name.log") tests passed)"
done
# (Not BM_EmptyDispatch/1: one dispatch per submit, its minimum time takes a fast GPU minutes of submits.)
for b in bench_deform bench_replay; do
  [ -x "$here/bin/$b" ] || continue
  SWISH_VALIDATION=0 "$here/bin/$b" --benchmark_filter=-BM_EmptyDispatch/1/ --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true --benchmark_out="$results/$b.json" --benchmark_out_format=json \
    >"$results/$b.log" 2>&1 || status=1
  echo "$b: $results/$b.json"
done
SWISH_VALIDATION=0 "$here/bin/swish" replay "$here/source/assets/scenes/football.json" --out "$results/replay" \
  --quiet >"$results/replay.log" 2>&1 || status=1
echo "replay: $results/replay/report.md"
exit $status
EOF
chmod +x "$out/run.sh"
echo "bundle: $out ($(du -sh "$out" | cut -f1)); on the target: $out/run.sh [DEVICE] [RESULTS_DIR]"
