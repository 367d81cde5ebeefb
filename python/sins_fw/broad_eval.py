"""`sins-fw broad-eval`: the DCM firmware algorithm on the ten BROAD trials, beside the `ahrs`
package's Mahony and Madgwick on the same inputs.

Algorithm level: f64, each trial's own sample rate (2000/7 Hz), no device model; every method starts
from the orientation of the first accelerometer and magnetometer sample and is never aligned to the
truth (the dataset's rule). Errors as the dataset's example code defines them (its README):
q_err = q_est ⊗ q_truth⁻¹ (earth frame), total = 2·acos|w|, heading = 2·atan|z/w|, inclination =
2·acos√(w² + z²), RMSE over the `movement` samples with a valid truth.

Frames: the DCM works in east-north-up (its own, `[firmware.dcm]`); the `ahrs` filters keep their
earth frame (x along the horizontal field, z up), which [`ahrs_to_enu`] turns into the DCM's by one
rotation about up, measured here rather than assumed (`_ahrs_frame`). Both then hold "magnetic ENU":
the heading error includes the site's declination against the optical ENU, for every method alike.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core, metrics
from sins_fw import quaternion as quat
from sins_fw.bench import machine
from sins_fw.broad import import_broad
from sins_fw.earth import G0
from sins_fw.errors import InputError
from sins_fw.harness import emulate
from sins_fw.profile import load_profile

#: The DCM parameter set, tuned once over the ten trials (the dataset's rule): a grid over K_P
#: {0.05 … 1.5}, K_I {0 … 0.02}, w_yaw {0 … 1}, then around its best; objective the mean total RMSE
#: (benchmarks/broad_eval.md). K_I = 0 wins: these trials (≈ 3.5 min each) hold no gyro bias worth the
#: integrator's wander under motion and magnetic disturbance.
TUNED = (
    "firmware.dcm.kp=0.5",
    "firmware.dcm.ki=0",
    "firmware.dcm.w_rp=1.0",
    "firmware.dcm.w_yaw=0.2",
    "firmware.dcm.yaw_reference=magnetometer",
)
#: The dataset's tuned Mahony gains (k_P, k_I) and Madgwick β (issue 18).
MAHONY_KP, MAHONY_KI, MADGWICK_BETA = 0.74, 0.0012, 0.12
#: The dataset's published figures on these ten trials (issue 18): inclination, heading, total RMSE °.
PUBLISHED = {"mahony": (3.75, 7.84, 8.92), "madgwick": (2.70, 4.99, 5.79)}


@dataclass(frozen=True)
class Trial:
    name: str
    rate_hz: float
    gyr: np.ndarray  # rad/s
    acc: np.ndarray  # m/s²
    mag: np.ndarray  # gauss
    truth: np.ndarray  # C_b^n w.r.t. optical ENU, NaN where lost
    moving: np.ndarray


def load_trials(folder: Path) -> list[Trial]:
    """The ten trials of `folder` (sorted by name); InputError when there are not ten."""
    paths = sorted(folder.glob("*.hdf5"))
    if len(paths) != 10:
        raise InputError(f"{folder}: {len(paths)} BROAD trials (*.hdf5); expected the ten of the dataset")
    out = []
    for p in paths:
        t = import_broad(p)
        rate = 1.0 / float(np.median(np.diff(t.t_s)))
        out.append(
            Trial(
                name=p.stem,
                rate_hz=rate,
                gyr=np.radians(t.gyro_dps),
                acc=t.accel_g * G0,
                mag=t.mag_gauss,
                truth=t.truth_q,
                moving=t.moving,
            )
        )
    return out


def errors_deg(q_est: np.ndarray, q_truth: np.ndarray, moving: np.ndarray) -> dict[str, float]:
    """Inclination, heading and total RMSE (degrees) over the moving samples with a valid truth
    (sins_fw.metrics: the dataset's definitions in well-conditioned forms)."""
    a = metrics.accuracy(q_est, q_truth, moving)
    return {"inclination": a.rmse_inclination_deg, "heading": a.rmse_heading_deg, "total": a.rmse_total_deg}


def dcm_quats(trial: Trial, overrides: tuple[str, ...] = TUNED) -> np.ndarray:
    """The DCM of the reference profile with `overrides` over one trial (f64, algorithm level)."""
    p = load_profile("reference", ["firmware.algorithm=dcm", *overrides])
    return _core.dcm_orientation(
        p.text, p.source, list(p.overrides), trial.gyr, trial.acc, trial.mag, 1.0 / trial.rate_hz
    )


def initial_enu(trial: Trial) -> np.ndarray:
    """The orientation of the first accelerometer and magnetometer sample (as the DCM starts)."""
    return dcm_quats(_first(trial), TUNED)[0]


def _first(trial: Trial) -> Trial:
    return Trial(
        trial.name,
        trial.rate_hz,
        trial.gyr[:1],
        trial.acc[:1],
        trial.mag[:1],
        trial.truth[:1],
        trial.moving[:1],
    )


def _ahrs_frame(method: str) -> np.ndarray:
    """q_rot with q_ENU = q_rot ⊗ q_ahrs for `method`: a still, level sensor whose x points along the
    horizontal field is Rz(90°) in (magnetic) ENU; the filter's converged answer for it gives the rotation
    (ahrs 0.4: identity for Mahony, which works in ENU; Rz(90°) for Madgwick, north-west-up)."""
    n = 4000
    acc = np.tile([0.0, 0.0, G0], (n, 1))
    mag = np.tile([0.25, 0.0, -0.43], (n, 1))
    q_a = _filter(method, np.zeros((n, 3)), acc, mag, 100.0, None, strong=True)[-1]
    q_enu = quat.from_axis_angle([0.0, 0.0, 1.0], np.pi / 2)
    return quat.multiply(q_enu, quat.conjugate(q_a))


def _filter(
    method: str,
    gyr: np.ndarray,
    acc: np.ndarray,
    mag: np.ndarray,
    rate: float,
    q0: np.ndarray | None,
    strong: bool = False,
) -> np.ndarray:
    from ahrs.filters import Madgwick, Mahony  # the optional `bench` extra: only these filters need it

    kw: dict[str, Any] = {"gyr": gyr, "acc": acc, "mag": mag, "frequency": rate}
    if q0 is not None:
        kw["q0"] = q0
    if method == "mahony":
        return Mahony(k_P=1.0 if strong else MAHONY_KP, k_I=MAHONY_KI, **kw).Q
    return Madgwick(gain=0.5 if strong else MADGWICK_BETA, **kw).Q


def ahrs_quats(trial: Trial, method: str, q_rot: np.ndarray) -> np.ndarray:
    """The `ahrs` package's Mahony or Madgwick over one trial, from the DCM's first orientation, in ENU."""
    q0 = quat.multiply(quat.conjugate(q_rot), initial_enu(trial))
    return quat.multiply(q_rot, _filter(method, trial.gyr, trial.acc, trial.mag, trial.rate_hz, q0))


#: The whole board around the DCM: the ADIS16407 model (±300 °/s, its filter and quantisation), f64
#: arithmetic, the correct decode, the magnetometer words of the burst, the attitude levelled from the
#: accelerometer over the first second (the trials start at rest) with yaw 0 for the magnetometer to pull in.
BOARD = (
    "firmware.numeric=f64",
    "firmware.decode=correct",
    "firmware.initial_attitude=level",
    "firmware.earth_rate=false",
)


def board_errors(path: Path, overrides: tuple[str, ...] = TUNED) -> dict[str, float]:
    """The DCM through the whole board on one trial: RMSE over the moving steps."""
    run = emulate(import_broad(path), overrides=["firmware.algorithm=dcm", *BOARD, *overrides])
    if run.truth_q is None or run.moving is None:
        raise InputError(f"{path}: the run kept no truth or movement mask")
    return errors_deg(run.quat, run.truth_q, run.moving)


def evaluate(
    folder: Path, overrides: tuple[str, ...] = TUNED, baselines: bool = True, board: bool = False
) -> dict[str, Any]:
    """Per-trial RMSE of the DCM (and the ahrs baselines, and the DCM through the board) and their means."""
    trials = load_trials(folder)
    paths = sorted(folder.glob("*.hdf5"))
    methods = ["dcm", *(["mahony", "madgwick"] if baselines else []), *(["board"] if board else [])]
    frames = {m: _ahrs_frame(m) for m in ("mahony", "madgwick") if m in methods}
    rows = []
    for t, path in zip(trials, paths, strict=True):
        row: dict[str, Any] = {"trial": t.name}
        for m in methods:
            if m == "board":
                row[m] = board_errors(path, overrides)
                continue
            q = dcm_quats(t, overrides) if m == "dcm" else ahrs_quats(t, m, frames[m])
            if not np.isfinite(q).all():
                raise InputError(f"{t.name}: {m} produced a non-finite orientation")
            row[m] = errors_deg(q, t.truth, t.moving)
        rows.append(row)
    mean = {
        m: {k: float(np.mean([r[m][k] for r in rows])) for k in ("inclination", "heading", "total")}
        for m in methods
    }
    return {"overrides": list(overrides), "trials": rows, "mean": mean, "published": PUBLISHED}


def table(report: dict[str, Any]) -> str:
    methods = list(report["mean"])
    head = "trial".ljust(44) + "".join(f"{m:>24}" for m in methods)
    sub = " " * 44 + "".join(f"{'incl  head  total':>24}" for _ in methods)
    lines = [head, sub]

    def cells(r: dict[str, Any]) -> str:
        return "".join(
            f"{r[m]['inclination']:>10.2f}{r[m]['heading']:>6.2f}{r[m]['total']:>8.2f}" for m in methods
        )

    lines += [r["trial"].ljust(44) + cells(r) for r in report["trials"]]
    lines.append("mean".ljust(44) + cells(report["mean"]))
    pub = report["published"]
    lines.append(
        "published (these ten): "
        + ", ".join(f"{m} {a:.2f} / {b:.2f} / {c:.2f}" for m, (a, b, c) in pub.items())
        + " (inclination / heading / total °)"
    )
    lines.append("DCM parameters: " + " ".join(report["overrides"]))
    return "\n".join(lines)


def register(sub: argparse._SubParsersAction) -> None:
    # sins_fw.cli imports this module for its command: at module level this would import it back.
    from sins_fw.cli.common import add_json_option, exit_epilog

    p = sub.add_parser(
        "broad-eval",
        help="the DCM on the ten BROAD trials beside ahrs's Mahony and Madgwick (algorithm level, f64)",
        epilog=exit_epilog(None),
    )
    p.add_argument("folder", type=Path, help="folder of the ten BROAD trials (*.hdf5)")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=None,
        help="DCM key=value (replaces the tuned set)",
    )
    p.add_argument("--no-baselines", action="store_true", help="the DCM only (no ahrs filters)")
    p.add_argument(
        "--board", action="store_true", help="also the DCM through the whole board (ADIS16407 model)"
    )
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from sins_fw.cli.common import emit  # as in `register`: sins_fw.cli imports this module

    overrides = tuple(args.overrides) if args.overrides else TUNED
    report = evaluate(args.folder, overrides, baselines=not args.no_baselines, board=args.board)
    report["machine"] = machine()  # the benchmarks' one (sins_fw.bench)
    emit(args, report, table(report))
    return 0
