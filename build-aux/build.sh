#!/bin/sh
# Configures (once) and builds skysweep in the source tree. Extra arguments
# go to ./configure the first time.
set -eu
cd "$(dirname "$0")/.."
if [ ! -f Makefile ] || [ configure.ac -nt Makefile ] || [ Makefile.am -nt Makefile ]; then
    autoreconf -fi >/dev/null
    ./configure -q "$@"
fi
make -j"$(nproc)" >/dev/null
