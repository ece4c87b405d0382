#!/usr/bin/env bash
# Test launcher of the sanitised build (tools/sanitize.sh sets it as CMAKE_CROSSCOMPILING_EMULATOR, so
# that CTest runs every test executable, and GoogleTest's discovery, through it).
#
# Why: the Vulkan loader dlcloses the driver (lavapipe) and the validation layer at vkDestroyInstance,
# before LeakSanitizer runs at exit, so the frames of what those keep print as "<unknown module>" and
# no suppression by module can match them. Preloading both keeps them mapped until exit: their frames
# then name their module, and tools/sanitize/lsan.supp matches them by it. The alternative,
# ASAN_OPTIONS=fast_unwind_on_malloc=0 (a full unwind at every allocation, so that each stack reaches
# the loader, which stays loaded), made lavapipe's pipeline compiles so slow that the deform
# conformance tests did not finish. AddressSanitizer's runtime must come first in LD_PRELOAD; the
# executable names the one it was linked with.
set -euo pipefail
exe=$1
asan=$(ldd "$exe" | awk '/libasan\.so/ && !p { print $3; p = 1 }')
preload=()
[ -n "$asan" ] && preload+=("$asan")
for lib in libVkLayer_khronos_validation.so libvulkan_lvp.so; do
  path=$(ldconfig -p | awk -v l="$lib" '$1 == l && !p { print $NF; p = 1 }')
  [ -n "$path" ] && preload+=("$path")
done
LD_PRELOAD="${preload[*]}${LD_PRELOAD:+ $LD_PRELOAD}" exec "$@"
