# The Debian 12 packages rocklab builds and tests with. Sourced by setup.sh (which
# installs the missing ones) and by install-peer.sh (which checks that installing the
# benchmark's peer removed none of them).
rocklab_packages=(build-essential cmake pkg-config
  libeigen3-dev libosmesa6-dev libopencv-dev libassimp-dev libvtk9-dev libhdf5-dev catch2
  libcgal-dev libcli11-dev nlohmann-json3-dev libtomlplusplus-dev libspdlog-dev libfmt-dev ffmpeg parallel
  gnuplot-nox fonts-dejavu-core  # plots (PNG + SVG): experiments/src/analysis/plot.h
  libxml2-utils)  # xmllint: the report tests parse report.html

# rocklab_missing_packages: prints the packages of rocklab_packages that are not installed.
rocklab_missing_packages() {
  local p
  for p in "${rocklab_packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || echo "$p"
  done
}
