#!/usr/bin/env bash
# What the machine itself gives two workers: the Rust core alone (no Python, no pool), two runs one
# after the other against the same two runs side by side, in alternating rounds. The Monte Carlo
# figure of `make bench` cannot beat this ratio; on a shared VM it moves with the neighbours' load.
# Usage: benchmarks/pair_scaling.sh [ROUNDS] [SECONDS of emulated input per run]
set -euo pipefail
cd "$(dirname "$0")/.."
rounds=${1:-5}
seconds=${2:-3000}
cargo build --quiet --profile dist -p sins-core --example pipeline
bin=${CARGO_TARGET_DIR:-target}/dist/examples/pipeline
run() { "$bin" "$seconds" 'firmware.numeric="f64"' errors.preset=adis16407 >/dev/null; }
now() { date +%s.%N; }
for _ in $(seq "$rounds"); do
    t0=$(now)
    run
    run
    t1=$(now)
    run &
    run
    wait
    t2=$(now)
    awk -v a="$t0" -v b="$t1" -v c="$t2" \
        'BEGIN { printf "one after the other %.2f s, side by side %.2f s, scaling %.2f\n", b - a, c - b, (b - a) / (c - b) }'
done
