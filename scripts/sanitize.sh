#!/usr/bin/env bash
# CI sanitizer job: a Debug build (RAYSIFT_DCHECK on) with ASan + UBSan runs the whole unit suite; any report aborts
# its test. Usage: scripts/sanitize.sh   (expects scripts/setup.sh's packages; build dir build-asan)
set -euo pipefail
cd "$(dirname "$0")/.."

# -O1: Debug keeps asserts and DCHECKs, -O1 keeps the suite inside CI's budget (-O0 is several times slower).
# No Python module: a CPython extension would need libasan preloaded into the interpreter; pytest runs in command (b).
# No MPI: Open MPI's own allocations at MPI_Init are reported as leaks; the mpirun tests run in command (b).
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
  -DRAYSIFT_SANITIZE=address,undefined -DRAYSIFT_BUILD_BENCH=OFF -DRAYSIFT_PYTHON=OFF -DRAYSIFT_MPI=OFF
targets=(core_tests volume_tests mesh_tests isosurface_tests features_tests sampling_tests nrr_tests apps_tests extremes_tests
         server_tests)
cmake --build build-asan -j2 --target "${targets[@]}"

# Leaks count as failures (LSan runs inside ASan); halt_on_error makes every finding fatal.
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export LSAN_OPTIONS=suppressions=$PWD/scripts/sanitize_lsan.supp:print_suppressions=0
# The browser test measures a frame rate, which a sanitizer build of the server cannot hold; it runs in command (b).
ctest --test-dir build-asan --output-on-failure -j2 --timeout 900 -LE browser
