#!/bin/bash
# The serve page's tests (docs/serve-page.md): ctest labels `web` (Node) and `browser` (headless Chromium against
# `raysift serve`, < 60 s). For .ci/run: skipped with a message, exit 0, where Chromium is not installed.
# Usage: scripts/browser_test.sh [BUILD_DIR]
set -euo pipefail
build=${1:-build}
if ! command -v chromium >/dev/null && ! command -v chromium-browser >/dev/null; then
  echo "browser_test: chromium is not installed; skipped (README command (b) installs it)"
  exit 0
fi
cmake --build "$build" --target raysift
ctest --test-dir "$build" -L 'web|browser' --output-on-failure
