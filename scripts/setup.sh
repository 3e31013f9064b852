#!/usr/bin/env bash
# Installs the Debian 12 packages diverse needs.
#   ./scripts/setup.sh          everything: build, test, render, gallery, fuzz, MPI
#   ./scripts/setup.sh --tool   only what building and running the diverse tool needs
#                               (runs, film strips; no tests, videos, gallery or MPI)
set -euo pipefail
mode="${1:-all}"
case "$mode" in
  all | --tool) ;;
  *) echo "setup.sh: expected no argument or --tool, got '$mode'" >&2; exit 2 ;;
esac
# The tool: compiler, libraries, offscreen rendering for the film strip.
packages=(
  cmake g++ make pkg-config
  libmujoco-dev libeigen3-dev libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libpng-dev
  libosmesa6-dev fonts-dejavu-core
  libtinygltf-dev  # glTF export (src/io/gltf.h)
)
if [ "$mode" = all ]; then
  packages+=(
    libgtest-dev libgmock-dev libbenchmark-dev
    ffmpeg  # videos (diverse render)
    python3 python3-numpy python3-matplotlib  # examples/*.py (docs/guide/python.md)
    pybind11-dev python3-pybind11 python3-dev python3-pytest  # the Python module (python/) and its tests
    jq  # scripts/reproduce-table1.sh and scripts/kill-resume.sh read the runs' summary.json
    clang libclang-rt-14-dev  # fuzz/ targets and their test (docs/reference/reliability.md)
    chromium
    libopenmpi-dev openmpi-bin  # mpirun -n R diverse run (docs/guide/running-at-scale.md)
  )
  # The gallery page (web/) is built with node and npm and tested in Chromium; a node that
  # is already installed (with its own npm) is used as it is.
  command -v node >/dev/null || packages+=(nodejs)
  command -v npm >/dev/null || packages+=(npm)
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${missing[@]}"
fi
