#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test except the long
# `validation` ones (run those with: ctest --test-dir build -L validation).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/scripts/setup.sh"
cd "$root/build"
ctest -LE validation -j "$(nproc 2>/dev/null || echo 2)" --output-on-failure --timeout 600
