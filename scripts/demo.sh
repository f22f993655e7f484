#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default demo scene end to end.
# Outputs go to ./out/demo (or the directory given as the first argument).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
"$root/build/app/rocklab" demo --overwrite --out "${1:-$root/out/demo}"
