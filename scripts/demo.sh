#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default demo scene end to end.
# Outputs go to ./out/demo (or the directory given as the first argument); the
# last line printed is the path of its report.html, the page to open.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
out="${1:-$root/out/demo}"
status=0
"$root/build/app/rocklab" demo --overwrite --out "$out" || status=$?
if [ -f "$out/report.html" ]; then
  echo "report: $(cd "$out" && pwd)/report.html"
fi
exit "$status"
