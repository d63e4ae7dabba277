#!/usr/bin/env bash
# Screenshots of report.html in headless chromium: its first screen (the scene cards) and one
# scene's 3D view, as PNG files for the README and docs (report_browser_tests runs it too).
# Headless chromium's --screenshot paints nothing once the page has scrolled (to an anchor, say),
# so the 3D view is shot from a copy of the page that shows that section alone.
# Usage: scripts/report_screenshots.sh REPORT_HTML OUTPUT_DIR [SCENE]   (SCENE: contact_straight)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ $# -lt 2 ]; then
  echo "usage: scripts/report_screenshots.sh REPORT_HTML OUTPUT_DIR [SCENE]" >&2
  exit 2
fi
[ -f "$1" ] || { echo "report_screenshots: $1: no such file" >&2; exit 2; }
report="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
out="$2"
scene="${3:-contact_straight}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
grep -q "id=\"view-$scene\"" "$report" || { echo "report_screenshots: no 3D view of '$scene' in $1" >&2; exit 2; }
shoot() {  # URL PNG HEIGHT
  "$root/scripts/headless_chromium.sh" --window-size="1280,$3" --virtual-time-budget=8000 \
    --screenshot="$2" "$1" >/dev/null 2>&1
  [ -s "$2" ] || { echo "report_screenshots: chromium wrote no $2" >&2; exit 1; }
  echo "wrote $2"
}
shoot "file://$report" "$out/report_first_screen.png" 860
alone="$(mktemp --suffix=.html)"
trap 'rm -f "$alone"' EXIT
sed "s|</head>|<style>body>:not(#view-$scene):not(#vv-gl){display:none}body{margin-top:0}</style></head>|" \
  "$report" >"$alone"
shoot "file://$alone" "$out/report_3d_view.png" 560
