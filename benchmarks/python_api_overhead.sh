#!/usr/bin/env bash
# What the Python API costs over the Rust core, in instructions per emulated 8 ms cycle counted by
# callgrind (independent of the machine's load): `sins_fw.emulate(trace, keep_truth=False)` on the
# benchmark's coning trace (240 s, f64, adis16407 errors, as `sins-fw bench`), run once and twice in
# one process; the difference is one warm call, split into the core's run loop (`Emulator::run`,
# inclusive) and everything else (input conversion and the core's input check, output columns,
# Python). Also prints the median minor page faults of five warm calls (getrusage): on a VM each
# costs about 1-2 µs of system time, which callgrind does not see.
# Usage: benchmarks/python_api_overhead.sh [override ...]   (needs valgrind; PYTHON defaults to .venv)
set -euo pipefail
cd "$(dirname "$0")/.."
py=${PYTHON:-.venv/bin/python}
overrides=("$@")
[ ${#overrides[@]} -eq 0 ] && overrides=('firmware.numeric="f64"' errors.preset=adis16407)
script='
import resource, sys
from sins_fw import bench
from sins_fw.harness import emulate
runs, overrides = int(sys.argv[1]), tuple(sys.argv[2:])
trace = bench.coning_trace(240.0)
for _ in range(runs):  # the first call is cold
    before = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt
    run = emulate(trace, overrides=overrides, keep_truth=False)
    faults = resource.getrusage(resource.RUSAGE_THREAD).ru_minflt - before
    print(run.cycles, faults)
    del run
'
# numpy's OpenBLAS starts worker threads whose spinning callgrind counts, differently from run to
# run (seen: 635 instructions per cycle between two runs); the emulation uses none of them.
export OPENBLAS_NUM_THREADS=1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for runs in 1 2; do
    valgrind --tool=callgrind --callgrind-out-file="$out/cg.$runs" "$py" -c "$script" "$runs" \
        "${overrides[@]}" >"$out/stdout.$runs" 2>/dev/null
    callgrind_annotate --inclusive=yes --threshold=100 "$out/cg.$runs" >"$out/annotate.$runs" 2>/dev/null
done
# Inclusive instructions of the first function whose line matches $2 in annotation $1.
inclusive() { awk -v pat="$2" 'index($0, pat) {gsub(",", "", $1); print $1; exit}' "$out/annotate.$1"; }
cycles=$(awk 'NR == 1 {print $1}' "$out/stdout.2")
total=$(($(inclusive 2 "PROGRAM TOTALS") - $(inclusive 1 "PROGRAM TOTALS")))
core=$(($(inclusive 2 "emulate::Run>::run [") - $(inclusive 1 "emulate::Run>::run [")))
# Page faults of warm calls: calls 2-6 of a plain (not valgrind) process, the median.
faults=$("$py" -c "$script" 6 "${overrides[@]}" | awk 'NR > 1 {print $2}' | sort -n | awk 'NR == 3')
echo "${overrides[*]}, 240 s coning, $cycles cycles; instructions per cycle:"
echo "  emulate() $((total / cycles)) = core run loop $((core / cycles)) + outside it $(((total - core) / cycles))"
echo "  minor page faults per call: $faults ($(awk -v f="$faults" -v c="$cycles" 'BEGIN {printf "%.2f", f / c}') per cycle)"
