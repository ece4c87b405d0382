#!/usr/bin/env bash
# Formats swish's C++ sources (src/, include/, tests/, tools/, examples/) with clang-format and the
# committed .clang-format.   bash tools/format.sh           rewrite the files in place
#                            bash tools/format.sh --check   list unformatted files, exit 1 if any
# GLSL shaders and the layout headers they share with C++ (shaders/*.h) are left alone: clang-format
# does not know GLSL.
set -euo pipefail
cd "$(dirname "$0")/.."
CLANG_FORMAT=${CLANG_FORMAT:-clang-format}
if ! command -v "$CLANG_FORMAT" >/dev/null; then
  echo "format: $CLANG_FORMAT not found (Debian: apt-get install clang-format; tools/setup.sh installs it)" >&2
  exit 2
fi
mapfile -t files < <(git ls-files -- 'src/*.cpp' 'src/*.hpp' 'include/*.hpp' 'tests/*.cpp' 'tests/*.hpp' \
                                      'tools/*.cpp' 'tools/*.hpp' 'examples/*.cpp')
if [ "${1:-}" = "--check" ]; then
  bad=()
  for f in "${files[@]}"; do
    if ! "$CLANG_FORMAT" --style=file --dry-run --Werror "$f" >/dev/null 2>&1; then bad+=("$f"); fi
  done
  if [ "${#bad[@]}" -gt 0 ]; then
    echo "format: ${#bad[@]} of ${#files[@]} files are not formatted (run: bash tools/format.sh):"
    printf '  %s\n' "${bad[@]}"
    exit 1
  fi
  echo "format: all ${#files[@]} files formatted"
  exit 0
fi
"$CLANG_FORMAT" --style=file -i "${files[@]}"
echo "format: formatted ${#files[@]} files"
