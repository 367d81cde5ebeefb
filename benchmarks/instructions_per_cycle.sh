#!/usr/bin/env bash
# Instructions per emulated 8 ms cycle of the Rust core alone (no Python), counted by callgrind: a
# figure that does not depend on the machine's load, for comparing commits on a shared machine.
# Two runs (20 s and 80 s of coning input) are subtracted so that set-up and input generation cancel.
# Usage: benchmarks/instructions_per_cycle.sh [override ...]   (needs valgrind)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --quiet --profile dist -p sins-core --example pipeline
bin=${CARGO_TARGET_DIR:-target}/dist/examples/pipeline
count() {
    local out
    out=$(mktemp)
    valgrind --tool=callgrind --callgrind-out-file="$out" "$bin" "$1" "${@:2}" >/dev/null 2>&1
    callgrind_annotate "$out" | awk '/PROGRAM TOTALS/ {gsub(",", "", $1); print $1}'
    rm -f "$out"
}
for case in 'firmware.numeric="f64"' 'firmware.numeric="f64" errors.preset=adis16407' \
    'firmware.numeric="f64" errors.preset=adis16407 spi.level="bit"' \
    'firmware.numeric="c28x-f32" errors.preset=adis16407' 'firmware.numeric="iq" errors.preset=adis16407'; do
    # shellcheck disable=SC2086  # the case is a list of overrides
    short=$(count 20 $case "$@")
    long=$(count 80 $case "$@")
    # 60 s of input more = 7500 more 8 ms cycles.
    echo "$case $*: $(((long - short) / 7500)) instructions per cycle"
done
