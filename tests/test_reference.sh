#!/bin/sh
# docs/reference.md must be what `mpsflow reference` writes from the
# parameter tables of this tree. argv: the generated copy, the committed one.
if cmp -s "$1" "$2"; then
    echo "ok   $2 is up to date ($(grep -c '^| `' "$2") keys)"
    exit 0
fi
echo "FAIL $2 is stale: a parameter table changed. Rewrite it with"
echo "         ninja -C build reference-update"
diff -u "$2" "$1" | head -40
exit 1
