#!/usr/bin/env bash
# Installs the Debian 12 packages that building, testing and running swish need. Idempotent: installs
# only what is missing, and says clearly what it could not install and why.
set -euo pipefail

PACKAGES=(
  cmake ninja-build g++ pkg-config git             # build
  clang libclang-rt-14-dev                         # libFuzzer target for the model loader
  clang-format                                     # tools/format.sh and the format_check test
  clang-tidy                                       # tools/tidy.sh (the checks of .clang-tidy)
  libvulkan-dev vulkan-tools                       # Vulkan loader, headers (incl. Vulkan-Hpp), vulkaninfo
  glslang-tools spirv-tools                        # GLSL -> SPIR-V at build time, spirv-val
  vulkan-validationlayers mesa-vulkan-drivers      # validation layers, lavapipe (CPU Vulkan device)
  libeigen3-dev                                    # linear algebra
  googletest libgtest-dev libbenchmark-dev         # tests, benchmarks
  libassimp-dev assimp-testmodels                  # FBX/glTF/BVH import; CMU mocap clips
  nlohmann-json3-dev libstb-dev                    # JSON (and the glTF export built on it), PNG
  libcli11-dev                                     # command line
  libsquish-dev                                    # BC5 baseline for the VQ normal maps
  libembree-dev libtbb-dev                         # ray casts for normal-map baking; parallel loops
  slurm-wlm slurm-client munge                     # `swish bake --slurm`; the cluster tests' one-node Slurm
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  SUDO=()
elif command -v sudo >/dev/null 2>&1; then
  SUDO=(sudo)
else
  echo "setup: error: these packages are missing and this user cannot install them (not root, no sudo):" >&2
  echo "  apt-get install ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
if ! "${SUDO[@]}" apt-get update -qq || ! "${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"; then
  echo "setup: error: apt-get could not install: ${missing[*]}" >&2
  echo "  (is this Debian 12 'bookworm' with its main archive reachable?)" >&2
  exit 1
fi
echo "setup: done"
