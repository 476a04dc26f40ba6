#!/bin/sh
# Fuzz the libFuzzer targets of tests/fuzz, one after another (clang from
# Debian: clang and libclang-rt-14-dev, installed here if missing).
#
#   bench/fuzz.sh [SECONDS] [TARGET ...]    default: 600 s each, every target
#
# Targets: dict_parse, dict_roundtrip, case, mesh. Each runs at nice 19 on
# one core from its committed corpus (tests/fuzz/corpus/TARGET) into a
# work corpus in build-fuzz/fuzz-work/TARGET; crashes, leaks and sanitizer
# reports land in build-fuzz/fuzz-work/TARGET/artifacts. The closing table
# gives executions, coverage (libFuzzer's edges and features) and findings.
# To keep what was found for CI, merge the work corpus into the committed
# one:  build-fuzz/tests/fuzz/fuzz_T -merge=1 tests/fuzz/corpus/T build-fuzz/fuzz-work/T/corpus
cd "${0%/*}/.." || exit 1
secs=${1:-600}
[ $# -gt 0 ] && shift
targets=${*:-dict_parse dict_roundtrip case mesh}
for p in clang libclang-rt-14-dev; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" ||
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "$p" > /dev/null
done
[ -f build-fuzz/build.ninja ] || CC=clang meson setup build-fuzz --buildtype=debugoptimized \
    -Dfuzz=true -Db_sanitize=address,undefined -Db_lundef=false \
    -Dc_args='-fsanitize=fuzzer-no-link -fno-sanitize-recover=all' > /dev/null || exit 1
ninja -C build-fuzz $(for t in $targets; do printf 'tests/fuzz/fuzz_%s ' "$t"; done) > /dev/null || exit 1
export OMP_NUM_THREADS=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
printf '%-16s %10s %8s %8s %9s %s\n' target executions edges features findings seconds
for t in $targets; do
    work=build-fuzz/fuzz-work/$t
    mkdir -p "$work/corpus" "$work/artifacts"
    # MPI keeps allocations for the life of the process: no leak check for
    # the case reader, which starts it.
    leaks=1; [ "$t" = case ] && leaks=0
    LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0" \
    ASAN_OPTIONS=detect_leaks=$leaks nice -n 19 build-fuzz/tests/fuzz/fuzz_$t \
        -max_total_time="$secs" -timeout=20 -rss_limit_mb=2560 -max_len=8192 \
        -print_final_stats=1 -artifact_prefix="$work/artifacts/" \
        "$work/corpus" "tests/fuzz/corpus/$t" > "$work/log" 2>&1
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log")
    last=$(grep -E '^#[0-9]+' "$work/log" | tail -1)
    edges=$(echo "$last" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
    features=$(echo "$last" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
    found=$(ls "$work/artifacts" | wc -l)
    printf '%-16s %10s %8s %8s %9s %s\n' "$t" "${execs:-?}" "${edges:-?}" "${features:-?}" "$found" "$secs"
done
