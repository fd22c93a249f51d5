#!/usr/bin/env bash
# ctest for scripts/check_includes.py: the real tree passes, and each planted violation (an upward include,
# a foreign detail/ include, a CMake DEPS list that disagrees with the layering) fails naming its file:line.
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
check="python3 $repo/scripts/check_includes.py"
$check "$repo"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
expect_failure() {  # $1: case name, $2: text the report must contain
  if out=$($check "$tmp/$1" 2>&1); then echo "FAIL: $1 passed the check"; exit 1; fi
  grep -qF -- "$2" <<<"$out" || { echo "FAIL: $1 did not report '$2':"; echo "$out"; exit 1; }
  echo "ok: $1 -> $2"
}
plant() {  # $1: case name; a minimal tree with the real CMakeLists.txt
  mkdir -p "$tmp/$1/core" "$tmp/$1/mesh/detail" "$tmp/$1/features"
  cp "$repo/CMakeLists.txt" "$tmp/$1/"
  printf '#pragma once\n' > "$tmp/$1/mesh/detail/private.h"
}

plant upward
printf '#pragma once\n#include "mesh/curvature.h"\n' > "$tmp/upward/core/bad.h"
expect_failure upward "core/bad.h:2: core/ may not include mesh/"

plant sideways
printf '#include "core/vec.h"\n\n#include "sampling/trade.h"\n' > "$tmp/sideways/features/bad.cpp"
expect_failure sideways "features/bad.cpp:3: features/ may not include sampling/"

plant detail
printf '#include "mesh/detail/private.h"\n' > "$tmp/detail/features/bad.cpp"
expect_failure detail "features/bad.cpp:1: includes mesh/detail/"

plant cmake
sed -i 's/^raysift_module(features DEPS raysift_mesh)/raysift_module(features DEPS raysift_mesh raysift_sampling)/' \
  "$tmp/cmake/CMakeLists.txt"
line=$(grep -n '^raysift_module(features' "$tmp/cmake/CMakeLists.txt" | cut -d: -f1)
expect_failure cmake "CMakeLists.txt:$line: raysift_features links ['mesh', 'sampling']"
