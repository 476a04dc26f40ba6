#!/bin/sh
# How much of a run's bulk has its pressure clipped at zero, snapshot by
# snapshot: the sign of the period-2 bulk pressure oscillation of `source
# mixed` (docs/notes/mps.md, 2026-12-02 robust and 2026-12-03 courant).
#   bench/pressure_clipped.sh OUTPUT_DIR
# Prints per snapshot: time, fluid PPE unknowns (flag 0: not free surface),
# and how many of them have p <= 0. Needs h5dump (hdf5-tools).
[ -d "$1" ] || { echo "usage: $0 OUTPUT_DIR"; exit 1; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
column() { # FILE DATASET: one value a line
    h5dump -y -w0 -d "$2" "$1" | awk '/DATA/ { f = 1; next } f && /}/ { f = 0 } f' |
        tr ',' '\n' | awk 'NF { print $1 }'
}
for f in "$1"/snapshot_*.h5; do
    t=$(h5dump -a /Header/Time "$f" | awk '/\(0\)/ { print $2 }')
    column "$f" /PartType0/Flags > "$tmp/flags"
    column "$f" /PartType0/Pressure > "$tmp/p"
    paste "$tmp/flags" "$tmp/p" | awk -v t="$t" '$1 == 0 { n++; if ($2 <= 0) c++ }
        END { printf "t %s unknowns %d clipped %d\n", t, n, c }'
done
