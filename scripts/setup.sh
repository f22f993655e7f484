#!/usr/bin/env bash
# Installs the Debian 12 packages rocklab needs (only those missing), then
# configures and builds a Release build in ./build. Sourced by demo.sh and test.sh.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(build-essential cmake pkg-config
  libeigen3-dev libosmesa6-dev libopencv-dev libassimp-dev libvtk9-dev libhdf5-dev catch2
  libcgal-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libspdlog-dev libfmt-dev ffmpeg parallel
  gnuplot-nox fonts-dejavu-core  # plots (PNG + SVG): experiments/src/analysis/plot.h
  libxml2-utils)  # xmllint: the report tests parse report.html

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "rocklab: installing ${#missing[@]} missing Debian packages: ${missing[*]}" >&2
  sudo_cmd=""
  [ "$(id -u)" -eq 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y --no-install-recommends "${missing[@]}" >&2
fi

jobs=$(nproc 2>/dev/null || echo 2)
cmake -S "$root" -B "$root/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$root/build" -j "$jobs"
