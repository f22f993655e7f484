#!/usr/bin/env bash
# Prints the figure of every stability case (the rows of docs/stability.md):
#   bash scripts/stability_figures.sh            # CI cases (seconds)
#   bash scripts/stability_figures.sh all        # with the [validation] ones (minutes)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
spec="~[validation]"
[ "${1:-}" = "all" ] && spec=""
"$root/build/tests/stability_tests" $spec 2>&1 | grep '^stability-figure' | cut -d'|' -f2- || true
