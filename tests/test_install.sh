#!/bin/sh
# The installed mpsflow (issue 15), as a user outside the project gets it:
# `meson install --destdir` a tree, then
#   - its mpsflow runs a tutorial copied from share/mpsflow/tutorials, with
#     the installed plugin (libkineticEnergy.so) found where it was installed;
#   - two plugins of two kinds (a force and a function object,
#     tests/install/) build against its headers through its mpsflow.pc and
#     run: the fluid pushed up harder than gravity rises at a - g;
#   - a tutorial copied to a temporary folder runs its Allrun with the
#     installed mpsflow on PATH (and its ParaView picture, where ParaView is);
#   - the man page renders; every tutorial of the source tree is installed.
# argv: the build folder, the source root
build=$1; src=$2
export OMP_NUM_THREADS=1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failed=0; passed=0
check() { if eval "$2"; then echo "ok   $1"; passed=$((passed + 1)); else echo "FAIL $1 [$2]"; failed=$((failed + 1)); fi; }

root=$tmp/root
meson install -C "$build" --destdir "$root" --no-rebuild --quiet > "$tmp/log.install" 2>&1 ||
    { cat "$tmp/log.install"; exit 1; }
exe=$(find "$root" -path '*/bin/mpsflow' -type f | head -n 1)
bin=$(dirname "$exe"); prefix=$(dirname "$bin")
pc=$(find "$root" -name mpsflow.pc | head -n 1)
pkg() { PKG_CONFIG_SYSROOT_DIR=$root PKG_CONFIG_PATH=$(dirname "$pc") pkg-config "$@" mpsflow; }
plugindir=$root$(PKG_CONFIG_PATH=$(dirname "$pc") pkg-config --variable=plugindir mpsflow)
check "installed: bin/mpsflow, its helpers, mpsflow.pc" \
    "[ -x '$exe' ] && [ -x '$bin/mpsflowParaView' ] && [ -x '$bin/mpsflowRenderFrames' ] && [ -f '$pc' ]"
check "the plugin sits in pkg-config's plugindir ($plugindir)" "[ -f '$plugindir/libkineticEnergy.so' ]"
man1=$prefix/share/man/man1/mpsflow.1
check "the man page is installed" "cmp -s '$man1' '$src/driver/mpsflow.1'"
if command -v man > /dev/null; then # not on a minimal system
    check "the man page renders" "man -l '$man1' 2> /dev/null | grep -q 'runTimeModifiable'"
fi
missing=""
for t in "$src"/tutorials/*/Allrun; do
    name=$(basename "$(dirname "$t")")
    [ -x "$prefix/share/mpsflow/tutorials/$name/Allrun" ] || missing="$missing $name"
done
check "every tutorial installed (missing:${missing:- none})" "[ -z '$missing' ]"

# ---- two plugins built outside the tree ---------------------------------------
mkdir -p "$tmp/plugins"
for p in uniformPush fluidMomentum; do
    cc -std=c11 -Wall -Wextra -Werror $(pkg --cflags) -shared -fPIC -o "$tmp/plugins/lib$p.so" \
        "$src/tests/install/$p.c" > "$tmp/log.cc.$p" 2>&1
    check "lib$p.so builds with \$(pkg-config --cflags mpsflow) alone" "[ -s '$tmp/plugins/lib$p.so' ]" ||
        cat "$tmp/log.cc.$p"
done
# The dam break's column pushed up at 20 m/s^2, more than g: it leaves the
# floor at once and, touching nothing that holds it, rises at a - g.
case=$tmp/push
cp -r "$prefix/share/mpsflow/tutorials/damBreak2D" "$case"
sed -i 's/^libs .*/libs ("libkineticEnergy.so" "libuniformPush.so" "libfluidMomentum.so");/' \
    "$case/system/controlDict"
# one more function and one more force, in the blocks the tutorial has
sed -i '/^functions$/{n;a\    momentum { type fluidMomentum; }
}' "$case/system/controlDict"
sed -i '/^forces$/{n;a\    push { type uniformPush; acceleration (0 20 0); }
}' "$case/system/solverDict"
MPSFLOW_PLUGIN_PATH=$tmp/plugins "$exe" -case "$case" -l0 0.02 -endTime 0.05 > "$case/log" 2>&1
check "installed mpsflow runs the copied tutorial with the two plugins" \
    "[ \$? -eq 0 ] && [ -s '$case/postProcessing/momentum/momentum.dat' ] &&
     [ -s '$case/postProcessing/energy/kineticEnergy.dat' ]" || tail -n 20 "$case/log"
u=$(tail -n 1 "$case/postProcessing/momentum/momentum.dat")
check "the pushed column rises at a - g: mean u_y (a - g) t = 0.5095 m/s at t = 0.05 ($u)" \
    "echo '$u' | awk '{ exit !(\$1 == 0.05 && \$3 > 0.5095 * 0.98 && \$3 < 0.5095 * 1.02) }'"

# ---- the plugin example's second module: a user-written control force --------------
# plugins/regionLift (README.md there), built outside the tree like the two
# above. Its box around the column lifts it as uniformPush does (a - g);
# the box beside the column leaves it to fall (mean u_y < 0).
cc -std=c11 -Wall -Wextra -Werror $(pkg --cflags) -shared -fPIC -o "$tmp/plugins/libregionLift.so" \
    "$src/plugins/regionLift/regionLift.c" > "$tmp/log.cc.regionLift" 2>&1
check "libregionLift.so (plugins/regionLift) builds outside the tree" \
    "[ -s '$tmp/plugins/libregionLift.so' ]" || cat "$tmp/log.cc.regionLift"
for where in column beside; do
    case=$tmp/lift-$where
    cp -r "$prefix/share/mpsflow/tutorials/damBreak2D" "$case"
    sed -i 's/^libs .*/libs ("libkineticEnergy.so" "libregionLift.so" "libfluidMomentum.so");/' \
        "$case/system/controlDict"
    sed -i '/^functions$/{n;a\    momentum { type fluidMomentum; }
}' "$case/system/controlDict"
    if [ $where = column ]; then box='min (-0.1 -0.1 0); max (0.4 0.7 0);'
    else box='min (1.0 0 0); max (2.0 0.6 0);'; fi
    sed -i "/^forces\$/{n;a\    lift { type regionLift; $box acceleration (0 20 0); }
}" "$case/system/solverDict"
    MPSFLOW_PLUGIN_PATH=$tmp/plugins "$exe" -case "$case" -l0 0.02 -endTime 0.05 > "$case/log" 2>&1 ||
        tail -n 20 "$case/log"
done
u=$(tail -n 1 "$tmp/lift-column/postProcessing/momentum/momentum.dat" 2>/dev/null)
check "regionLift's box around the column: it rises at a - g, 0.5095 m/s at t = 0.05 ($u)" \
    "echo '$u' | awk '{ exit !(\$1 == 0.05 && \$3 > 0.5095 * 0.98 && \$3 < 0.5095 * 1.02) }'"
u=$(tail -n 1 "$tmp/lift-beside/postProcessing/momentum/momentum.dat" 2>/dev/null)
check "regionLift's box beside the column: no lift, the column falls ($u)" \
    "echo '$u' | awk '{ exit !(\$1 == 0.05 && \$3 < 0) }'"

# ---- a tutorial copied anywhere runs its Allrun with mpsflow on PATH --------------
mkdir -p "$tmp/run"
cp -r "$prefix/share/mpsflow/tutorials/damBreak2D" "$tmp/run/myDamBreak"
(cd "$tmp/run/myDamBreak" && PATH=$bin:$PATH ./Allrun -l0 0.02 -endTime 0.15 > log.Allrun 2>&1)
check "the copied tutorial's Allrun ran the installed mpsflow (Exec line) and validated" \
    "grep -q '^Exec   : $bin/mpsflow' '$tmp/run/myDamBreak/log.mpsflow' &&
     grep -q '^error surgeFront = ' '$tmp/run/myDamBreak/log.validate'" || cat "$tmp/run/myDamBreak/log.Allrun"
if command -v pvbatch > /dev/null; then
    check "... and saved its ParaView picture" "ls '$tmp/run/myDamBreak'/postProcessing/images/paraview_*.png > /dev/null 2>&1" ||
        tail -n 5 "$tmp/run/myDamBreak/log.paraview"
fi
(cd "$tmp/run/myDamBreak" && ./Allclean)
check "... and its Allclean leaves the case as copied" \
    "[ ! -e '$tmp/run/myDamBreak/output' ] && [ -z \"\$(ls '$tmp/run/myDamBreak' | grep '^log\.')\" ]"
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
