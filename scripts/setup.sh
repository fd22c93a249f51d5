#!/usr/bin/env bash
# Fresh Debian 12 -> working raysift. Usage: scripts/setup.sh demo|test
#   demo: install the packages the program needs, build only the `raysift` target, run `raysift demo` on the
#         bundled engine CT (full, prioritized and subsampled at the same frame time, side by side)
#   test: install every package, build everything (tests, benches), run every test, then the demo
set -euo pipefail
mode=${1:-demo}
cd "$(dirname "$0")/.."

# What the raysift program itself links; tests, benches and the shell tools come on top for `test`.
packages=(cmake g++ make pkg-config ccache zlib1g-dev
  libopenvdb-dev libboost-iostreams-dev
  libopenmesh-dev libmeshoptimizer-dev libembree-dev
  libopenimageio-dev libopencv-core-dev
  libtbb-dev nlohmann-json3-dev libcli11-dev
  libboost-dev libjpeg-dev)  # raysift serve: Boost.Beast for HTTP + WebSocket, libjpeg for JPEG frames (docs/serve.md)
case "$mode" in
  demo) build_all=OFF ;;
  test) build_all=ON  # + tests, the shell tools they call, the Python module with its test runner, Open MPI
                      # (issue 19), Chromium with a DevTools client and Node for the page's tests (issue 18)
        packages+=(libgtest-dev libopenvdb-tools openimageio-tools
                   pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-openimageio python3-matplotlib
                   libopenmpi-dev openmpi-bin chromium python3-websocket python3-pil nodejs) ;;
  *) echo "usage: scripts/setup.sh demo|test" >&2; exit 2 ;;
esac
source scripts/install_missing.sh
install_missing "${packages[@]}"

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DRAYSIFT_BUILD_TESTS=$build_all -DRAYSIFT_BUILD_BENCH=$build_all
if [ "$mode" = test ]; then
  cmake --build build -j2
  ctest --test-dir build --output-on-failure -j2
else
  cmake --build build -j2 --target raysift
fi
./build/raysift demo --scene datasets/engine_ct_scene.json -o build/demo.png --stats build/demo_stats.json
