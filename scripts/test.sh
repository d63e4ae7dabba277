#!/usr/bin/env bash
# The test command: installs what is missing, builds in Release and runs the test suite.
# Usage: scripts/test.sh [--all]   (--all also runs the tests labelled `slow`)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build"

# chromium: the `browser` tests open report.html in it (headless, WebGL by SwiftShader).
"$root/scripts/install_deps.sh" chromium
"$root/scripts/build.sh" "$build"
select=(-LE slow)
if [ "${1:-}" = "--all" ]; then select=(); fi
ctest --test-dir "$build" "${select[@]}" --output-on-failure --parallel "$(nproc)"
