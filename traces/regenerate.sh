#!/usr/bin/env bash
# Recreate the bundled traces, byte for byte: traces/regenerate.sh [OUTDIR]  (default: this folder).
# Uses $PYTHON if set, else the repository's .venv, else python3 (sins_fw must be importable).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="${1:-$here}"
if [[ -n "${PYTHON:-}" ]]; then py="$PYTHON"
elif [[ -x "$here/../.venv/bin/python" ]]; then py="$here/../.venv/bin/python"
else py=python3; fi
mkdir -p "$out"
sins() { "$py" -m sins_fw "$@" >/dev/null; }

sins synth static --duration-s 60 --out "$out/static_60s.h5"
sins synth indexing-table --preset sweep --axis y --max-rate-dps 40 --max-accel-dps2 300 --dwell-s 6 \
    --out "$out/pitch_sweep.h5"
sins synth coning --half-angle-deg 1 --frequency-hz 10 --duration-s 360 --out "$out/coning_10hz.h5"
# The raw-register example: the words the reference firmware read in the first 10 s of the pitch sweep.
sins run "$out/pitch_sweep.h5" --until-s 10 --raw-out "$out/pitch_sweep_10s_raw.csv"
