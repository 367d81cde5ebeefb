"""What a firmware could do about the ADIS16407's gyro clip on the BROAD trials (benchmarks/broad_eval.md):

1. Quasi-static windows between a trial's first and last clip (|ω| and |‖f‖ − g| below a bound for a
   time): where the tilt could be re-initialised from the accelerometer after a clip.
2. The rate lost to the clip, and how much of it a reconstruction from the rate's slopes at the clip's
   ends recovers (cubic Hermite through the last unclipped sample before and the first after, slopes
   from least-squares lines over `k` samples each side): the missing angle ∫(ω − limit) and the
   reconstruction's residual, summed in magnitude over the clips; and the DCM at algorithm level (its
   BROAD set) on the clipped and on the reconstructed gyro.

Usage: python benchmarks/broad_clip_study.py ../shared/data/broad
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from sins_fw import broad_eval as be
from sins_fw.earth import G0

LIMIT_DPS = 409.55  # the 14-bit code's full scale at 0.05 °/s per LSB
QUASI_STATIC = ((10.0, 0.05, 0.5), (30.0, 0.1, 0.2), (60.0, 0.1, 0.1))  # (°/s, g, s)


def quasi_static_windows(
    t: be.Trial, first: int, last: int, rate_dps: float, acc_g: float, dur_s: float
) -> int:
    still = (np.degrees(np.linalg.norm(t.gyr, axis=1)) < rate_dps) & (
        np.abs(np.linalg.norm(t.acc, axis=1) - G0) < acc_g * G0
    )
    n = run = 0
    for s in still[first:last]:
        if s:
            run += 1
            continue
        n += run >= dur_s * t.rate_hz
        run = 0
    return n


def reconstruct(gyr: np.ndarray, rate_hz: float, k: int) -> tuple[np.ndarray, float, float]:
    """The gyro held at the limit, with each clip's samples replaced by the Hermite estimate (not below
    the limit) where `k` unclipped samples stand on both sides; the missing angle and the residual (rad,
    sums of magnitudes over the clips)."""
    lim, dt = np.radians(LIMIT_DPS), 1.0 / rate_hz
    out = np.clip(gyr, -lim, lim)
    missing = residual = 0.0
    for ax in range(3):
        w = gyr[:, ax]
        c = np.abs(w) >= lim
        i, n = 0, len(w)
        while i < n:
            if not c[i]:
                i += 1
                continue
            j = i
            while j + 1 < n and c[j + 1]:
                j += 1
            s = np.sign(w[i])
            if i >= k and j + k < n and not c[i - k : i].any() and not c[j + 1 : j + 1 + k].any():
                xa, xb = np.arange(i - k, i), np.arange(j + 1, j + 1 + k)
                pa, pb = np.polyfit(xa * dt, w[xa], 1), np.polyfit(xb * dt, w[xb], 1)
                ta, tb = (i - 1) * dt, (j + 1) * dt
                span = tb - ta
                a, b = np.polyval(pa, ta), np.polyval(pb, tb)
                u = (np.arange(i, j + 1) * dt - ta) / span
                est = (
                    (2 * u**3 - 3 * u**2 + 1) * a
                    + (u**3 - 2 * u**2 + u) * span * pa[0]
                    + (-2 * u**3 + 3 * u**2) * b
                    + (u**3 - u**2) * span * pb[0]
                )
                est = s * np.maximum(s * est, lim)
                out[i : j + 1, ax] = est
                lost = float(np.sum(w[i : j + 1] - s * lim) * dt)
                missing += abs(lost)
                residual += abs(float(np.sum(est - s * lim) * dt) - lost)
            i = j + 1
    return out, missing, residual


def main(folder: Path) -> None:
    lim = np.radians(LIMIT_DPS)
    for path in be.trial_paths([folder]):
        t = be.load_trial(path)
        hit = np.flatnonzero((np.abs(t.gyr) >= lim).any(axis=1))
        if not len(hit):
            continue
        qs = [quasi_static_windows(t, hit[0], hit[-1], *q) for q in QUASI_STATIC]
        print(
            f"{t.name}: clips {hit[0] / t.rate_hz:.1f}–{hit[-1] / t.rate_hz:.1f} s; quasi-static windows "
            + ", ".join(
                f"|ω|<{r:g}°/s |‖f‖−g|<{a:g} g ≥{d:g} s: {n}"
                for (r, a, d), n in zip(QUASI_STATIC, qs, strict=True)
            )
        )
        clipped = be.errors_deg(
            be.algorithm_quats(replace(t, gyr=np.clip(t.gyr, -lim, lim)), "dcm"), t.truth, t.moving
        )
        for k in (2, 4):
            gyr, missing, residual = reconstruct(t.gyr, t.rate_hz, k)
            e = be.errors_deg(be.algorithm_quats(replace(t, gyr=gyr), "dcm"), t.truth, t.moving)
            print(
                f"  k {k}: missing {np.degrees(missing):7.0f}°, residual {np.degrees(residual):6.0f}° "
                f"({100 * residual / max(missing, 1e-12):3.0f} %); DCM incl/head/total clipped "
                f"{clipped['inclination']:.2f}/{clipped['heading']:.2f}/{clipped['total']:.2f}, "
                "reconstructed "
                f"{e['inclination']:.2f}/{e['heading']:.2f}/{e['total']:.2f}"
            )


if __name__ == "__main__":
    main(Path(sys.argv[1]))
