#!/bin/sh
# Turns kernels/MAIN.cl into one C string, with its local #include "x.h"
# files inlined (each once), so the library carries its kernels and an
# installed binary needs no kernel files at run time.
# Usage: embed-kernels.sh KERNEL_DIR MAIN.cl SYMBOL > out.c
set -eu
dir=$1 main=$2 symbol=$3
seen=" "
expand() {
    while IFS= read -r line || [ -n "$line" ]; do
        case $line in
        '#include "'*'"')
            inc=${line#'#include "'}
            inc=${inc%'"'}
            case $seen in
            *" $inc "*) ;;
            *) seen="$seen$inc "
               expand < "$dir/$inc" ;;
            esac ;;
        *) printf '%s\n' "$line" ;;
        esac
    done
}
echo "/* Generated from $dir/$main by embed-kernels.sh: do not edit. */"
echo "const char $symbol[] ="
expand < "$dir/$main" | sed -e 's/\\/\\\\/g' -e 's/"/\\"/g' -e 's/^/"/' -e 's/$/\\n"/'
echo ";"
