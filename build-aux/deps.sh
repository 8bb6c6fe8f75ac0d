#!/bin/sh
# Installs the Debian 12 packages skysweep needs to build, test and run.
# Why each one: README.md, "Dependencies".
set -eu
packages="build-essential autoconf automake libtool pkg-config bc
  ocl-icd-opencl-dev opencl-c-headers pocl-opencl-icd clinfo
  libgdal-dev gdal-bin
  libgeographiclib-dev libinih-dev libjson-c-dev
  libopenimageio-dev openimageio-tools
  libvtk9-dev xvfb xauth
  libopenmpi-dev openmpi-bin
  python3-venv"
missing=""
for p in $packages; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
        missing="$missing $p"
done
[ -z "$missing" ] && exit 0
if [ "$(id -u)" -ne 0 ]; then
    echo "skysweep needs these Debian packages:$missing" >&2
    echo "run as root: apt-get update && apt-get install -y$missing" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
# shellcheck disable=SC2086
apt-get install -y -qq $missing >/dev/null
