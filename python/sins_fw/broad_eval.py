"""`sins-fw broad-eval`: the fusing firmware algorithms (the DCM, the VQF-class filter) on any set of
BROAD trials, at algorithm level and through the whole board, beside the dataset's published per-trial
Madgwick and Mahony (and, on request, the `ahrs` package's filters on the same inputs).

Algorithm level: the profile's numeric type (f64 unless `--numeric`), each trial's own sample rate
(2000/7 Hz), no device model; every method starts from the orientation of the first accelerometer and
magnetometer sample and is never aligned to the truth (the dataset's rule). Errors as the dataset's
example code defines them (its README): q_err = q_est ⊗ q_truth⁻¹ (earth frame), total = 2·acos|w|,
heading = 2·atan|z/w|, inclination = 2·acos√(w² + z²), RMSE over the `movement` samples with a valid truth.

Frames: the firmware works in east-north-up; the `ahrs` filters keep their earth frame (x along the
horizontal field, z up), which [`ahrs_to_enu`] turns into ENU by one rotation about up, measured here
rather than assumed (`_ahrs_frame`). All hold "magnetic ENU": the heading error includes the site's
declination against the optical ENU, for every method alike (the published baselines too).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core, metrics
from sins_fw import quaternion as quat
from sins_fw.broad import import_broad
from sins_fw.broad_published import PUBLISHED_PER_TRIAL
from sins_fw.earth import G0
from sins_fw.errors import InputError
from sins_fw.harness import emulate
from sins_fw.profile import load_profile

#: The firmware algorithms broad-eval runs, in order.
ALGORITHMS = ("dcm", "vqf")

#: One parameter set per algorithm, tuned once over the ten shared trials (the dataset's rule; grids and
#: figures in benchmarks/broad_eval.md). `--set` adds to it (a key given again wins).
TUNED: dict[str, tuple[str, ...]] = {
    "dcm": (
        "firmware.dcm.kp=0.5",
        "firmware.dcm.ki=0",
        "firmware.dcm.w_rp=1.0",
        "firmware.dcm.w_yaw=0.2",
        "firmware.dcm.yaw_reference=magnetometer",
        "firmware.dcm.lag_compensation=true",
        "firmware.dcm.full_range=true",
        "firmware.dcm.clip_gain=4",
        "firmware.dcm.clip_recovery_s=3",
    ),
    # The motion bias estimate (a simplified form of the method's) made the ten worse (mean inclination
    # 4.79° with it, 0.92° without): off in the shipped set, see benchmarks/broad_eval.md.
    "vqf": ("firmware.vqf.motion_bias=false",),
}
#: The dataset's tuned Mahony gains (k_P, k_I) and Madgwick β (its `tagp_parameters`).
MAHONY_KP, MAHONY_KI, MADGWICK_BETA = 0.74, 0.0012, 0.12
#: The dataset's published figures on the ten shared trials (the means of PUBLISHED_PER_TRIAL over them):
#: inclination, heading, total RMSE °.
PUBLISHED = {"mahony": (3.75, 7.84, 8.92), "madgwick": (2.70, 4.99, 5.79)}
#: The three error figures, in table order.
FIGURES = ("inclination", "heading", "total")
#: The ADIS16407's gyro clips at its 14-bit code: 0x1FFF or 0x2000 in X/Y/Z GYRO_OUT (burst words 2…4).
_GYRO_WORDS = slice(2, 5)
_FULL_SCALE_CODES = (0x1FFF, 0x2000)
#: A trial "clips" through the board when a gyro word is at full scale in at least this fraction of its
#: movement steps. Measured on the ten (benchmarks/broad_eval.md): 06, 21 and 28 clip in 14–18 % of their
#: movement (swings of 900–1400 °/s, tens of clips a minute), the others in at most 0.7 % (single taps and
#: jerks of 20–30 ms); any bound between those splits the ten alike.
CLIPPED_FRACTION = 0.01


@dataclass(frozen=True)
class Trial:
    name: str
    path: Path
    rate_hz: float
    gyr: np.ndarray  # rad/s
    acc: np.ndarray  # m/s²
    mag: np.ndarray  # gauss
    truth: np.ndarray  # C_b^n w.r.t. optical ENU, NaN where lost
    moving: np.ndarray


def trial_paths(sources: list[Path]) -> list[Path]:
    """The BROAD trial files of `sources` (each a folder, whose *.hdf5 are taken sorted by name, or a
    .hdf5 file), in the order given; InputError for a missing path, an empty folder or a repeated trial."""
    if not sources:
        raise InputError("broad-eval: no folder or trial file given; expected at least one")
    out: list[Path] = []
    for s in sources:
        if s.is_dir():
            found = sorted(s.glob("*.hdf5"))
            if not found:
                raise InputError(f"{s}: no BROAD trials (*.hdf5) in this folder; expected at least one")
            out += found
        elif s.is_file():
            out.append(s)
        else:
            raise InputError(
                f"{s}: no such folder or trial file; expected a folder of BROAD trials or a .hdf5"
            )
    names = [p.stem for p in out]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError(f"broad-eval: trial {twice[0]} given more than once; expected each trial once")
    return out


def load_trial(path: Path) -> Trial:
    t = import_broad(path)
    rate = 1.0 / float(np.median(np.diff(t.t_s)))
    return Trial(
        name=path.stem,
        path=path,
        rate_hz=rate,
        gyr=np.radians(t.gyro_dps),
        acc=t.accel_g * G0,
        mag=t.mag_gauss,
        truth=t.truth_q,
        moving=t.moving,
    )


def load_trials(folder: Path) -> list[Trial]:
    """The trials of `folder` (sorted by name)."""
    return [load_trial(p) for p in trial_paths([folder])]


def errors_deg(q_est: np.ndarray, q_truth: np.ndarray, moving: np.ndarray) -> dict[str, float]:
    """Inclination, heading and total RMSE (degrees) over the moving samples with a valid truth
    (sins_fw.metrics: the dataset's definitions in well-conditioned forms)."""
    a = metrics.accuracy(q_est, q_truth, moving)
    return {"inclination": a.rmse_inclination_deg, "heading": a.rmse_heading_deg, "total": a.rmse_total_deg}


def settings(algorithm: str, extra: tuple[str, ...] = ()) -> list[str]:
    """The profile overrides of `algorithm`'s shipped BROAD set, then `extra`."""
    if algorithm not in TUNED:
        raise InputError(f"broad-eval: algorithm {algorithm!r}; expected one of {', '.join(ALGORITHMS)}")
    return [f"firmware.algorithm={algorithm}", *TUNED[algorithm], *extra]


def algorithm_quats(
    trial: Trial, algorithm: str = "dcm", extra: tuple[str, ...] = (), numeric: str = "f64"
) -> np.ndarray:
    """`algorithm` of the reference profile with its BROAD set and `extra` over one trial (algorithm level,
    in `numeric`)."""
    p = load_profile("reference", [*settings(algorithm, extra), f"firmware.numeric={numeric}"])
    return _core.attitude_orientation(
        p.text, p.source, list(p.overrides), trial.gyr, trial.acc, trial.mag, 1.0 / trial.rate_hz
    )


def dcm_quats(trial: Trial, overrides: tuple[str, ...] = ()) -> np.ndarray:
    """The DCM at algorithm level, f64 (its BROAD set, then `overrides`)."""
    return algorithm_quats(trial, "dcm", overrides)


def initial_enu(trial: Trial) -> np.ndarray:
    """The orientation of the first accelerometer and magnetometer sample (as the firmware starts)."""
    return algorithm_quats(_first(trial), "dcm")[0]


def clipped_gyro(trial: Trial, limit_dps: float) -> Trial:
    """`trial` with each gyro axis held within ±`limit_dps`: the saturation alone, without the rest of the
    board (its filter, quantisation, update rate, and the clip flags the firmware reads there)."""
    if not limit_dps > 0:
        raise InputError(f"broad-eval: --clip-dps {limit_dps}; expected a rate above 0 °/s")
    lim = np.radians(limit_dps)
    return replace(trial, gyr=np.clip(trial.gyr, -lim, lim))


def _first(trial: Trial) -> Trial:
    return Trial(
        trial.name,
        trial.path,
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
    """The `ahrs` package's Mahony or Madgwick over one trial, from the firmware's first orientation (ENU)."""
    q0 = quat.multiply(quat.conjugate(q_rot), initial_enu(trial))
    return quat.multiply(q_rot, _filter(method, trial.gyr, trial.acc, trial.mag, trial.rate_hz, q0))


#: The whole board around the algorithm: the ADIS16407 model (±300 °/s rated, clipping at its 14-bit
#: code, its filter and quantisation), the correct decode, the magnetometer words of the burst, the
#: attitude levelled from the accelerometer over the first second (the trials start at rest) with yaw 0
#: for the magnetometer to pull in.
BOARD = (
    "firmware.decode=correct",
    "firmware.initial_attitude=level",
    "firmware.earth_rate=false",
)


@dataclass(frozen=True)
class BoardRun:
    errors: dict[str, float]
    #: Per step: time (s), the error angles (°) of each figure, and whether a gyro word of the step's
    #: reads was at full scale.
    time_s: np.ndarray
    total_deg: np.ndarray
    inclination_deg: np.ndarray
    heading_deg: np.ndarray
    clipped: np.ndarray
    moving: np.ndarray
    events: dict[str, int]

    @property
    def clip_fraction(self) -> float:
        """The fraction of the movement steps with a gyro word at full scale."""
        n = int(self.moving.sum())
        return float((self.clipped & self.moving).sum() / n) if n else 0.0

    def recovery(self) -> dict[str, float] | None:
        """The total error (°) at the last clipped step, its largest value after it and at the end, and
        that step's time (s); None when no step clipped."""
        hit = np.flatnonzero(self.clipped)
        if not len(hit):
            return None
        after = self.total_deg[hit[-1] :]
        return {
            "last_clip_s": float(self.time_s[hit[-1]]),
            "at_last_clip_deg": float(after[0]),
            "max_after_deg": float(np.nanmax(after)),
            "end_deg": float(after[np.isfinite(after)][-1]) if np.isfinite(after).any() else float("nan"),
        }


def board_run(
    path: Path,
    algorithm: str = "dcm",
    extra: tuple[str, ...] = (),
    numeric: str = "f64",
    until_s: float | None = None,
) -> BoardRun:
    """`algorithm` through the whole board on one trial (its BROAD set, then `extra`, in `numeric`)."""
    run = emulate(
        import_broad(path),
        overrides=[*settings(algorithm, extra), *BOARD, f"firmware.numeric={numeric}"],
        until_s=until_s,
    )
    if run.truth_q is None or run.moving is None:
        raise InputError(f"{path}: the run kept no truth or movement mask")
    errors = errors_deg(run.quat, run.truth_q, run.moving)
    e = run.errors("none")
    codes = run.read_words[:, _GYRO_WORDS] & 0x3FFF
    read_clipped = np.isin(codes, _FULL_SCALE_CODES).any(axis=1)
    # A step is clipped when a read of its tick (or of the tick before: the update takes both ends) is.
    clipped = np.zeros(len(run.step), dtype=bool)
    step_ticks = run.budget["tick"][run.budget["step"].astype(bool)]
    clipped_ticks = np.unique(run.read_tick[read_clipped])
    if len(step_ticks) >= len(run.step):
        ticks = step_ticks[-len(run.step) :]
        clipped = np.isin(ticks, clipped_ticks) | np.isin(ticks - 1, clipped_ticks)
    kinds: dict[str, int] = {}
    for ev in run.events:
        kinds[ev["kind"]] = kinds.get(ev["kind"], 0) + 1
    return BoardRun(
        errors=errors,
        time_s=run.time_s,
        total_deg=e.total,
        inclination_deg=e.inclination,
        heading_deg=e.heading,
        clipped=clipped,
        moving=np.asarray(run.moving, dtype=bool),
        events=kinds,
    )


def board_errors(
    path: Path, algorithm: str = "dcm", extra: tuple[str, ...] = (), numeric: str = "f64"
) -> dict[str, float]:
    """`algorithm` through the whole board on one trial: RMSE over the moving steps."""
    return board_run(path, algorithm, extra, numeric).errors


def evaluate(
    sources: list[Path] | Path,
    algorithms: tuple[str, ...] = ALGORITHMS,
    extra: tuple[str, ...] = (),
    *,
    ahrs: bool = False,
    board: bool = False,
    numeric: str = "f64",
    clip_dps: float | None = None,
) -> dict[str, Any]:
    """Per-trial RMSE of each algorithm (algorithm level; through the board with `board`), the dataset's
    published per-trial figures where the trial has them, the `ahrs` filters with `ahrs`; and the means
    of each column over the trials (published: over the trials that have them)."""
    paths = trial_paths([sources] if isinstance(sources, Path) else list(sources))
    for a in algorithms:
        settings(a)
    if clip_dps is not None and not clip_dps > 0:
        raise InputError(f"broad-eval: --clip-dps {clip_dps}; expected a rate above 0 °/s")
    methods = [
        *algorithms,
        *([f"{a}@clipped" for a in algorithms] if clip_dps is not None else []),
        *([f"{a}@board" for a in algorithms] if board else []),
        *(["mahony-ahrs", "madgwick-ahrs"] if ahrs else []),
    ]
    frames = {m: _ahrs_frame(m.split("-")[0]) for m in methods if m.endswith("-ahrs")}
    rows = []
    for path in paths:
        t = load_trial(path)
        row: dict[str, Any] = {"trial": t.name}
        for m in methods:
            if m.endswith("@board"):
                r = board_run(path, m.split("@")[0], extra, numeric)
                row[m] = r.errors
                row[f"{m}:events"] = r.events
                row[f"{m}:clip_fraction"] = r.clip_fraction
                row[f"{m}:recovery"] = r.recovery()
                row["clip_fraction"] = r.clip_fraction  # the part's: alike for every algorithm
                continue
            if m.endswith("-ahrs"):
                q = ahrs_quats(t, m.split("-")[0], frames[m])
            elif m.endswith("@clipped"):
                assert clip_dps is not None
                q = algorithm_quats(clipped_gyro(t, clip_dps), m.split("@")[0], extra, numeric)
            else:
                q = algorithm_quats(t, m, extra, numeric)
            if not np.isfinite(q).all():
                raise InputError(f"{t.name}: {m} produced a non-finite orientation")
            row[m] = errors_deg(q, t.truth, t.moving)
        for pub, per_trial in PUBLISHED_PER_TRIAL.items():
            if t.name in per_trial:
                row[f"{pub}-published"] = dict(zip(FIGURES, per_trial[t.name], strict=True))
        rows.append(row)
    columns = [*methods, *(f"{p}-published" for p in PUBLISHED_PER_TRIAL)]
    mean = _means(rows, columns)
    # Through the board: the means over the trials the part clips and over the others, every column over
    # the same trials (where the clip costs the error, and what the published methods did on them).
    subsets: dict[str, Any] = {}
    if board:
        for name, pick in (
            ("clipped", lambda f: f >= CLIPPED_FRACTION),
            ("unclipped", lambda f: f < CLIPPED_FRACTION),
        ):
            chosen = [r for r in rows if pick(r["clip_fraction"])]
            subsets[name] = {"trials": [r["trial"] for r in chosen], "mean": _means(chosen, columns)}
    return {
        "algorithms": list(algorithms),
        "settings": {a: settings(a, extra)[1:] for a in algorithms},
        "numeric": numeric,
        "clip_dps": clip_dps,
        "trials": rows,
        "columns": [c for c in columns if c in mean],
        "mean": mean,
        "subsets": subsets,
        "published_trials": sum(all(f"{p}-published" in r for p in PUBLISHED_PER_TRIAL) for r in rows),
    }


def _means(rows: list[dict[str, Any]], columns: list[str]) -> dict[str, dict[str, float]]:
    """Each column's mean of each figure over the rows that have it."""
    mean: dict[str, dict[str, float]] = {}
    for m in columns:
        have = [r[m] for r in rows if m in r]
        if have:
            mean[m] = {k: float(np.mean([h[k] for h in have])) for k in FIGURES}
    return mean


def _num(v: float, width: int) -> str:
    """`v` right-aligned in `width` characters, always after a space (one decimal fewer from 100°)."""
    return f"{v:>{width}.2f}" if abs(v) < 10 ** (width - 4) else f"{v:>{width}.1f}"


def table(report: dict[str, Any]) -> str:
    methods = report["columns"]
    width = 20
    head = "trial".ljust(44) + "".join(f"{m:>{width}}" for m in methods)
    sub = " " * 44 + "".join(f"{'incl  head total':>{width}}" for _ in methods)
    lines = [head, sub]

    def cells(r: dict[str, Any]) -> str:
        out = ""
        for m in methods:
            if m in r:
                out += _num(r[m]["inclination"], 8) + _num(r[m]["heading"], 6) + _num(r[m]["total"], 6)
            else:
                out += f"{'—':>{width}}"
        return out

    def clip(r: dict[str, Any]) -> str:
        return f" {100 * r['clip_fraction']:5.1f} % clipped" if "clip_fraction" in r else ""

    lines += [r["trial"].ljust(44) + cells(r) + clip(r) for r in report["trials"]]
    lines.append(f"mean of {len(report['trials'])}".ljust(44) + cells(report["mean"]))
    for name, sub in report.get("subsets", {}).items():
        if sub["trials"]:
            label = f"mean of {len(sub['trials'])} {name}"
            lines.append(label.ljust(44) + cells(sub["mean"]))
    if report.get("subsets"):
        lines.append(
            f"clipped: a gyro word at full scale in ≥ {100 * CLIPPED_FRACTION:g} % of the movement steps "
            "through the board (the part's, alike for every algorithm)"
        )
    recover = [
        (r["trial"], m, r[f"{m}:recovery"])
        for r in report["trials"]
        for m in methods
        if r.get(f"{m}:recovery") is not None
    ]
    if recover:
        lines.append("after the last clipped step, total error °: at it / largest after / at the end")
        lines += [
            f"  {t[:40]:<40} {m:<12} {v['last_clip_s']:7.1f} s {v['at_last_clip_deg']:7.2f} "
            f"{v['max_after_deg']:7.2f} {v['end_deg']:7.2f}"
            for t, m, v in recover
        ]
    lines.append(
        f"published: the dataset's tuned Madgwick (β {MADGWICK_BETA}) and Mahony (k_P {MAHONY_KP}, k_I "
        f"{MAHONY_KI}), per trial, on {report['published_trials']} of these trials (their mean over those)"
    )
    if report.get("clip_dps") is not None:
        lines.append(
            f"@clipped: algorithm level on the recording's gyro held within ±{report['clip_dps']:g} °/s "
            "(no clip flags: the saturation alone)"
        )
    lines.append(f"numeric: {report['numeric']}")
    for a, s in report["settings"].items():
        lines.append(f"{a}: " + " ".join(s))
    return "\n".join(lines)
