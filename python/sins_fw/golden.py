"""Golden outputs: sha256 hashes of the f64 backend's per-step output and read words on the bundled
traces, checked in as tests/golden/hashes.toml (a byte-exact regression check, like ArduPilot's
replay checker). Each array is hashed as its little-endian bytes in C order: ``quat`` (N×4 float64),
``euler_deg`` (N×3 float64), ``velocity_enu`` (N×3 float64), ``position`` (N×3 float64: latitude °,
longitude °, height m) and ``read_words`` (M×15 uint16, every burst's SPIRXBUF words).

    python -m sins_fw.golden [FILE]     regenerate FILE (default tests/golden/hashes.toml), print old → new

The hashes hold for one platform: the f64 backend uses the system's libm for sin/cos/atan2/sqrt, so
another C library or CPU may differ in the last bit (a hash mismatch, not a physical difference).
"""

from __future__ import annotations

import hashlib
import sys
import tomllib
from pathlib import Path

import numpy as np

from sins_fw.atomic import write_text
from sins_fw.harness import Run, emulate

ROOT = Path(__file__).resolve().parents[2]
GOLDEN_FILE = ROOT / "tests" / "golden" / "hashes.toml"
#: The bundled traces the golden file covers.
TRACES = ("static_60s", "pitch_sweep", "coning_10hz")
#: The profile of the golden runs: the reference with the exact arithmetic.
OVERRIDES = ("firmware.numeric=f64",)
_ARRAYS = {
    "quat": "<f8",
    "euler_deg": "<f8",
    "velocity_enu": "<f8",
    "position": "<f8",
    "read_words": "<u2",
}


def run_hashes(run: Run) -> dict[str, str | int]:
    """sha256 (hex) of each golden array of a run, with the step and read counts."""
    out: dict[str, str | int] = {"steps": run.cycles, "reads": len(run.read_words)}
    for name, dtype in _ARRAYS.items():
        data = np.ascontiguousarray(getattr(run, name), dtype=np.dtype(dtype)).tobytes()
        out[name] = hashlib.sha256(data).hexdigest()
    return out


def golden_run(trace: str) -> Run:
    """The golden run of one bundled trace."""
    return emulate(ROOT / "traces" / f"{trace}.h5", "reference", overrides=OVERRIDES)


def load(path: Path = GOLDEN_FILE) -> dict[str, dict[str, str | int]]:
    """The checked-in hashes per trace (empty when the file does not exist)."""
    if not path.is_file():
        return {}
    return tomllib.loads(path.read_text(encoding="utf-8")).get("traces", {})


def render(hashes: dict[str, dict[str, str | int]]) -> str:
    """The golden file's text."""
    lines = [
        "# Golden outputs: sha256 of the little-endian bytes (C order) of the f64 backend's per-step",
        "# output on each bundled trace (profile `reference` with firmware.numeric = f64). Arrays: quat",
        "# (steps×4 float64), euler_deg (steps×3 float64), velocity_enu (steps×3 float64), position",
        "# (steps×3 float64: latitude °, longitude °, height m), read_words (reads×15 uint16).",
        "# Regenerate with `make golden` (python -m sins_fw.golden); see python/sins_fw/golden.py.",
    ]
    for trace, h in hashes.items():
        lines += ["", f"[traces.{trace}]"]
        for key, value in h.items():
            lines.append(f"{key} = {value}" if isinstance(value, int) else f'{key} = "{value}"')
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    path = Path(args[0]) if args else GOLDEN_FILE
    old = load(path)
    new = {trace: run_hashes(golden_run(trace)) for trace in TRACES}
    for trace, h in new.items():
        before = old.get(trace, {})
        for key, value in h.items():
            was = before.get(key, "(none)")
            mark = "  " if was == value else "→ "
            print(
                f"{mark}{trace}.{key}: {was} → {value}" if was != value else f"{mark}{trace}.{key}: {value}"
            )
    write_text(path, render(new))
    changed = sum(1 for t, h in new.items() for k, v in h.items() if old.get(t, {}).get(k) != v)
    print(f"wrote {path}: {changed} value(s) changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
