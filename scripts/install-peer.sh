#!/usr/bin/env bash
# Installs the benchmark's peer, LIGGGHTS 3.8 from Debian (and mpirun), without breaking
# rocklab's build: `apt-get install liggghts` with its recommended packages installs
# ParaView, whose Python module conflicts with python3-vtk9 and removes libvtk9-dev, after
# which rocklab no longer configures. So: no recommends, a dry run first that must remove
# nothing, and afterwards a check that every package rocklab needs is still there and that
# the build still configures.
# Usage: scripts/install-peer.sh     exit 0: installed (or already there); 2: refused or broken
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$root/scripts/packages.sh"

peer_packages=()
command -v liggghts >/dev/null || peer_packages+=(liggghts)
command -v mpirun >/dev/null || peer_packages+=(openmpi-bin)
if ((${#peer_packages[@]} == 0)); then
  echo "install-peer: liggghts and mpirun are already installed" >&2
  exit 0
fi
command -v apt-get >/dev/null || { echo "install-peer: no apt-get here: install LIGGGHTS 3.8 and mpirun by hand" >&2; exit 2; }
sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-peer: needs root or sudo to install ${peer_packages[*]}" >&2; exit 2; }
  sudo_cmd="sudo"
fi

# Dry run: refuse if apt would remove anything (the ParaView conflict, or another one).
$sudo_cmd apt-get update -qq || echo "install-peer: apt-get update failed: trying the package lists as they are" >&2
plan=$(LC_ALL=C $sudo_cmd apt-get -s install --no-install-recommends "${peer_packages[@]}" 2>&1) || {
  echo "install-peer: apt-get cannot install ${peer_packages[*]}:" >&2; echo "$plan" >&2; exit 2; }
removals=$(grep '^Remv' <<<"$plan" || true)
if [ -n "$removals" ]; then
  echo "install-peer: refused: installing ${peer_packages[*]} would remove packages:" >&2
  echo "$removals" >&2
  exit 2
fi
echo "install-peer: installing $(grep -c '^Inst' <<<"$plan") packages: ${peer_packages[*]} (no recommends)" >&2
DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y --no-install-recommends "${peer_packages[@]}" >&2

# The build must survive: every package still installed, and CMake still configures.
mapfile -t missing < <(rocklab_missing_packages)
if ((${#missing[@]})); then
  echo "install-peer: rocklab's packages are gone after the install: ${missing[*]}" >&2
  echo "  repair: apt-get install --no-install-recommends ${missing[*]}" >&2
  exit 2
fi
if [ -f "$root/build/CMakeCache.txt" ] && ! cmake -S "$root" -B "$root/build" >/dev/null 2>&1; then
  echo "install-peer: rocklab no longer configures after the install (cmake -S $root -B $root/build)" >&2
  exit 2
fi
echo "install-peer: liggghts $(dpkg-query -W -f='${Version}' liggghts) installed; rocklab still configures" >&2
