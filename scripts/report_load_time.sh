#!/usr/bin/env bash
# How long report.html takes to become interactive in headless chromium on this machine: the
# navigation's DOMContentLoaded and load events, and the moment the page's script has run
# (window.vvReport.interactiveMs: cards, tables and links work; each plot and 3D view is then set up
# when it scrolls into view), in ms from navigation start; the slowest 3D view's set-up (its data
# decoded, its geometry built), which a reader waits for when it scrolls into view; the file's size. Each figure is the median of RUNS loads (default 5), each in a fresh browser.
# Usage: scripts/report_load_time.sh REPORT_HTML [RUNS]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
[ $# -ge 1 ] && [ -f "$1" ] || { echo "usage: scripts/report_load_time.sh REPORT_HTML [RUNS]" >&2; exit 2; }
runs="${2:-5}"
page="$(mktemp --suffix=.html)"
trap 'rm -f "$page"' EXIT
# A copy whose last script writes the timings into the DOM once the page has loaded.
# Real time, not virtual: chromium dumps the DOM right after the load event.
sed 's|</body>|<script>addEventListener("load",()=>{const n=performance.getEntriesByType("navigation")[0];const p=document.createElement("pre");p.id="vv-timing";const r=window.vvReport,t=[n.domContentLoadedEventEnd,performance.now(),r?r.interactiveMs:-1];let w=0;if(r){for(const s of document.querySelectorAll(".vv-view")){if(!s.querySelector(".vv-pane"))continue;const a=performance.now();r.initView(s);w=Math.max(w,performance.now()-a)}}t.push(w);p.textContent=t.map(v=>v.toFixed(0)).join(" ");document.body.appendChild(p)})</script></body>|' \
  "$1" >"$page"
dcl=(); load=(); ready=(); view=()
for _ in $(seq "$runs"); do
  line="$("$root/scripts/headless_chromium.sh" --window-size=1280,860 --dump-dom "file://$page" 2>/dev/null | sed -n 's|.*<pre id="vv-timing">\([0-9 ]*\)</pre>.*|\1|p')"
  [ -n "$line" ] || { echo "report_load_time: no timing from chromium" >&2; exit 1; }
  read -r a b c d <<<"$line"
  dcl+=("$a"); load+=("$b"); ready+=("$c"); view+=("$d")
done
median() { printf '%s\n' "$@" | sort -n | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
echo "$(basename "$1"): $(stat -c %s "$1") bytes; median of $runs loads in headless chromium:" \
     "DOMContentLoaded $(median "${dcl[@]}") ms, load $(median "${load[@]}") ms," \
     "script done (interactive) $(median "${ready[@]}") ms;" \
     "slowest 3D view to set up once scrolled to (decode, geometry) $(median "${view[@]}") ms"
