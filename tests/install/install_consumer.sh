#!/usr/bin/env bash
# The installed package, as a host project sees it: `cmake --install` the build into a temporary
# prefix, configure tests/install/consumer/ (find_package(swish CONFIG)) against that prefix only, build
# examples/minimal_host.cpp there and run it on a model. Fails if the package misses a header, a library
# or a dependency, or if the consumer picks up anything from the source or build tree.
# Usage: install_consumer.sh SOURCE_DIR BUILD_DIR MODEL.swish
set -euo pipefail
src=$1 build=$2 model=$3
work=$(mktemp -d "${TMPDIR:-/tmp}/swish-install-test.XXXXXX")
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
test -f "$work/prefix/include/swish/swish.hpp" || { echo "install: include/swish/swish.hpp missing"; exit 1; }
if find "$work/prefix" -path '*/swish/core/*' | grep -q .; then
  echo "install: internal headers were installed (only include/swish/ is public)"; exit 1
fi
generator=()
if command -v ninja >/dev/null; then generator=(-G Ninja); fi
cmake -S "$src/tests/install/consumer" -B "$work/build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$work/prefix" -DSWISH_EXAMPLE_SOURCE="$src/examples/minimal_host.cpp" \
  -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON -DCMAKE_EXPORT_COMPILE_COMMANDS=ON
# The consumer must not see the source tree's internal headers.
if grep -q -F -e "$src/src" -e "$src/include" -e "$build" "$work/build/compile_commands.json"; then
  echo "consumer: compiled against the source tree, not the package"; exit 1
fi
cmake --build "$work/build"
"$work/build/minimal_host" "$model"
echo "install: find_package(swish CONFIG) -> swish::swish built and ran minimal_host"
