#!/usr/bin/env bash
# CI fuzz job: builds the libFuzzer targets of tests/fuzz with clang-14 (ASan + UBSan, libraries instrumented for
# coverage) in build-fuzz and runs each for 60 s from its seed corpus; any crash, leak, timeout or sanitizer report
# fails the job and leaves the input in build-fuzz/findings/. Usage: scripts/fuzz.sh [seconds per target]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}

# Only this job needs clang, so its packages live here rather than in setup.sh's list.
packages=(clang-14 libclang-rt-14-dev)
source scripts/install_missing.sh
install_missing "${packages[@]}"

targets=(transfer_function scene camera light nrrd raw ply obj off)
cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-g -O1 -fsanitize-ignorelist=$PWD/scripts/fuzz_ubsan_ignore.txt" \
  -DRAYSIFT_SANITIZE=fuzzer-no-link,address,undefined -DRAYSIFT_BUILD_FUZZ=ON \
  -DRAYSIFT_BUILD_TESTS=OFF -DRAYSIFT_BUILD_BENCH=OFF -DRAYSIFT_PYTHON=OFF -DRAYSIFT_MPI=OFF
cmake --build build-fuzz -j2 --target "${targets[@]/#/fuzz_}"

# New inputs go to build-fuzz/corpus/<t> (the checked-in seeds stay read-only); two targets at a time on 2 cores.
rm -rf build-fuzz/findings && mkdir -p build-fuzz/findings
run_one() {
  local t=$1 seconds=$2
  mkdir -p "build-fuzz/corpus/$t"
  if ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
     LSAN_OPTIONS=suppressions=$PWD/scripts/sanitize_lsan.supp:print_suppressions=0 \
     "build-fuzz/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
       -artifact_prefix="build-fuzz/findings/$t-" -print_final_stats=1 \
       "build-fuzz/corpus/$t" "tests/fuzz/corpus/$t" > "build-fuzz/fuzz_$t.log" 2>&1; then
    echo "fuzz $t: ok ($(grep -o 'stat::number_of_executed_units: *[0-9]*' "build-fuzz/fuzz_$t.log" | grep -o '[0-9]*$') runs)"
  else
    echo "fuzz $t: FAILED, see build-fuzz/fuzz_$t.log and build-fuzz/findings/" >&2
    tail -40 "build-fuzz/fuzz_$t.log" >&2
    return 1
  fi
}
export -f run_one
printf '%s\n' "${targets[@]}" | xargs -P 2 -I{} bash -c 'run_one "$@"' _ {} "$seconds"
