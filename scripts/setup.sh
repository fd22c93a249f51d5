#!/usr/bin/env bash
# Fresh Debian 12 -> working raysift. Usage: scripts/setup.sh demo|test
#   demo: install missing packages, configure, build, summarise and render the bundled engine CT
#   test: install missing packages, configure, build, run every test (ctest)
set -euo pipefail
mode=${1:-demo}
cd "$(dirname "$0")/.."

packages=(cmake g++ make pkg-config ccache zlib1g-dev
  libopenvdb-dev libboost-iostreams-dev libopenvdb-tools
  libopenmesh-dev libmeshoptimizer-dev libembree-dev
  libopenimageio-dev libopencv-core-dev openimageio-tools
  libtbb-dev libgtest-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
fi

cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j2

case "$mode" in
  demo)
    ./build/raysift info datasets/engine_ct.vdb
    ./build/raysift render --scene datasets/engine_ct_scene.json --shading phong -o build/demo.png --stats build/demo_stats.json
    echo "demo: wrote build/demo.png (stats: build/demo_stats.json)"
    ;;
  test)
    ctest --test-dir build --output-on-failure -j2
    ;;
  *)
    echo "usage: scripts/setup.sh demo|test" >&2
    exit 2
    ;;
esac
