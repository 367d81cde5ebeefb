"""The effect of resampling a recorded trace onto the ADIS16407's 819.2 SPS clock, on a coning
motion: the same analytic 10 Hz, α = 1° cone sampled at the device rate (exact instants: no
interpolation), at 1000 Hz and at BROAD's 285.7 Hz (linearly interpolated onto the device instants),
emulated with the f64 backend; the drift about the cone axis is compared with the prediction.

Linear interpolation at a uniformly distributed position u between two samples scales a sinusoid of
angular frequency ω by 1 − u(1 − u)(ωT)²/2 to second order, on average 1 − (ωT)²/12 (T: the input
sample period). The firmware sees the cone through that gain and the Bartlett filter's: its drift is
−Ω(cos α' − cos α) with sin α' = G·|H|·sin α, plus the x-rate quantisation.

Run: .venv/bin/python benchmarks/resampling_coning.py  (writes benchmarks/resampling_coning.md)
"""

from __future__ import annotations

from fractions import Fraction
from pathlib import Path

import numpy as np

from sins_fw import atomic, synth
from sins_fw import quaternion as q
from sins_fw.bench import machine_line
from sins_fw.harness import emulate

RATES = {"819.2 (device clock, exact)": "4096/5", "1000": "1000", "285.714 (BROAD)": "2000/7"}
OMEGA, ALPHA, FS, TAPS, LSB = 2 * np.pi * 10.0, np.radians(1.0), 819.2, 4, np.radians(0.05)


def predicted_drift(rate_hz: float | None) -> float:
    u = np.pi * 10.0 / FS
    gain = (np.sin(TAPS * u) / (TAPS * np.sin(u))) ** 2
    if rate_hz is not None:
        gain *= 1.0 - (OMEGA / rate_hz) ** 2 / 12.0
    alpha_seen = np.arcsin(gain * np.sin(ALPHA))
    wx = -OMEGA * (1 - np.cos(ALPHA))
    return -OMEGA * (np.cos(alpha_seen) - np.cos(ALPHA)) + (np.round(wx / LSB) * LSB - wx)


def main() -> None:
    rows = []
    for label, rate in RATES.items():
        trace = synth.generate("coning", duration_s=120.0, rate_hz=rate)
        run = emulate(trace, overrides=["firmware.numeric=f64"])
        err = q.multiply(q.conjugate(run.truth_q), run.quat)
        x = 2.0 * err[:, 1] * np.sign(err[:, 0])
        measured = np.degrees(np.polyfit(run.time_s, x, 1)[0]) * 3600
        exact = rate == "4096/5"
        predicted = np.degrees(predicted_drift(None if exact else float(Fraction(rate)))) * 3600
        rows.append((label, measured, predicted))
    lines = [
        "# Resampling a coning trace onto the device clock",
        "",
        f"Machine: {machine_line()}.",
        "Command: `.venv/bin/python benchmarks/resampling_coning.py` (120 s, 10 Hz, α = 1°, f64 backend).",
        "",
        "| input rate, Hz | drift about the cone axis, °/h | predicted, °/h |",
        "|---|---|---|",
        *[f"| {label} | {m:.2f} | {p:.2f} |" for label, m, p in rows],
        "",
        "The device clock rate needs no interpolation; the difference at the other rates is what the",
        "linear interpolation adds ((ωT)²/12 amplitude loss on average). At BROAD's rate it adds ≈ 40 %",
        "to the drift the ADIS16407's own Bartlett filter already causes.",
    ]
    atomic.write_text(Path(__file__).with_suffix(".md"), "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
