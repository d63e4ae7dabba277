#!/usr/bin/env bash
# The test command: installs what is missing, builds in Release and runs the test suite.
# Usage: scripts/test.sh [--quick]   (every test, as CI runs them; --quick leaves out the tests
# labelled `slow`, for quick local runs)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build"

# chromium: the `browser` tests open report.html in it (headless, WebGL by SwiftShader).
"$root/scripts/install_deps.sh" chromium
"$root/scripts/build.sh" "$build"
select=()
case "${1:-}" in
  "") ;;
  --quick) select=(-LE slow) ;;
  *) echo "scripts/test.sh: unknown option '$1'; expected --quick or nothing" >&2; exit 2 ;;
esac
ctest --test-dir "$build" "${select[@]}" --output-on-failure --parallel "$(nproc)"
