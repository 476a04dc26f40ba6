#!/bin/sh
# Build the tree with gcc at every meson buildtype (-Werror throughout, as
# meson.build sets) and with clang: each must build without a warning.
#   tests/check_buildtypes.sh [WORKDIR]     default WORKDIR: /tmp/mpsflow-buildtypes
# Not run by ./Alltest (four more compiles); ./Alltest builds debugoptimized
# (build/), debug with the sanitizers (build-san/) and clang (build-clang/).
src=$(cd "${0%/*}/.." && pwd)
work=${1:-/tmp/mpsflow-buildtypes}
mkdir -p "$work"
status=0
for bt in plain debug debugoptimized release clang; do
    dir="$work/$bt"
    if [ "$bt" = clang ]; then
        [ -f "$dir/build.ninja" ] || CC=clang meson setup "$dir" "$src" > /dev/null || { status=1; continue; }
    else
        [ -f "$dir/build.ninja" ] || meson setup "$dir" "$src" --buildtype=$bt > /dev/null || { status=1; continue; }
    fi
    if ninja -C "$dir" > "$dir.log" 2>&1; then
        echo "ok   $bt: $(grep -c 'warning:' "$dir.log") warnings"
    else
        echo "FAIL $bt:"; grep -E "error|warning:" "$dir.log" | head -10; status=1
    fi
done
exit $status
