#!/usr/bin/env bash
# Debian's chromium, headless, as the report's browser tests and screenshots run it: no sandbox
# (CI runs as root), no GPU (WebGL by SwiftShader), nothing fetched in the background (the
# machines reach no network but Debian's), a fresh profile removed afterwards. Arguments are
# passed on, e.g. --dump-dom or --screenshot=FILE, then the page's file:// URL.
# Usage: scripts/headless_chromium.sh [chromium options] URL     (CHROMIUM overrides the binary)
set -euo pipefail
browser="${CHROMIUM:-chromium}"
if ! command -v "$browser" >/dev/null; then
  echo "headless_chromium: '$browser' not found (scripts/install_deps.sh chromium installs it)" >&2
  exit 2
fi
profile="$(mktemp -d)"
trap 'rm -rf "$profile"' EXIT
"$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --enable-unsafe-swiftshader --hide-scrollbars --user-data-dir="$profile" "$@"
