"""The gyro-free vehicle board (issue 25) from Python: a ``synth vehicle`` trace through the board
model of ``firmware_model/gfsins.toml`` (``_core.gfsins_run``), the DSP's decoded packets, both
processors' budget per rate class and the events.

The compass's truth comes from the trace: heading (clockwise from north), pitch (nose up) and roll
(right side down) of the body's x (forward) axis from ``truth_q`` (C_b^n, ENU; the synth flight
kinematics' x forward, y left, z up), its specific force at the body's reference point
(``accel_g``), its field from ``mag_*``. The GPS rows are held from fix to fix (the receiver samples
the truth at its own epochs)."""

from __future__ import annotations

import json
import math
import os
import tomllib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw import _core
from sins_fw.errors import ProfileError, TraceError
from sins_fw.profile import ProfileValues, check_overrides, read_profile_text, resolve_profile_path
from sins_fw.tablefile import Column, Schema, write_table
from sins_fw.traces import PhysicalTrace

#: The shipped profile.
PROFILE = Path(__file__).parent / "firmware_model" / "gfsins.toml"


def has_own_schema(name_or_path: str | os.PathLike[str]) -> bool:
    """Whether the profile names a board with a schema of its own (``meta.board``): the commands
    that take ``--profile`` dispatch it here. False when the file cannot be read as TOML (the F28335
    loader then says why)."""
    try:
        text = resolve_profile_path(name_or_path).read_text(encoding="utf-8")
        meta = tomllib.loads(text).get("meta")
    except (ProfileError, OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return False
    return isinstance(meta, dict) and "board" in meta


@dataclass(frozen=True)
class GfsinsProfile(ProfileValues):
    """A checked gyro-free board profile."""

    @property
    def period_s(self) -> float:
        return 1.0 / float(self.get("node.timer_hz"))

    @property
    def start_s(self) -> float:
        """The first timer tick after power-up."""
        return float(self.get("node.start_ms")) * 1e-3


def load(
    name_or_path: str | os.PathLike[str] = PROFILE, overrides: tuple[str, ...] | list[str] = ()
) -> GfsinsProfile:
    """Load and check a gyro-free board profile (errors name the file and key: ProfileError)."""
    checked = check_overrides(overrides)
    path, text = read_profile_text(name_or_path)
    resolved = _core.gfsins_profile(text, str(path), list(checked))
    return GfsinsProfile(str(path), text, checked, tomllib.loads(resolved))


def vehicle_array(profile: GfsinsProfile) -> dict[str, Any]:
    """The ``synth vehicle`` keys that place the trace's array where ``profile`` places its parts
    (``array.lever_arm_m``, the ``array.parts`` positions in order): the trace's ``array1_*`` …
    ``array7_*`` forces are then those the profile's parts feel."""
    parts = profile.get("array.parts")
    return {
        "lever_arm_m": float(profile.get("array.lever_arm_m")),
        "array_positions_lever_arms": tuple(float(x) for part in parts for x in part["position"]),
    }


def ticks_in(trace: PhysicalTrace, profile: GfsinsProfile) -> int:
    """The node's timer ticks that fall within the trace (the first at ``node.start_ms``)."""
    end = float(trace.t_s[-1] - trace.t_s[0])
    return max(0, int(np.floor((end - profile.start_s) / profile.period_s + 1e-9)) + 1)


def compass_truth(trace: PhysicalTrace) -> np.ndarray:
    """(n, 9): heading, pitch, roll (°), specific force (g), field (gauss) at the compass (at the
    body's reference point, where the thesis's layout has its centre part: ``accel_g``)."""
    if trace.truth_q is None or trace.array_g is None:
        raise TraceError("gfsins: the trace needs truth_q and the array columns (sins-fw synth vehicle)")
    w, x, y, z = trace.truth_q.T
    # Columns of C_b^n: the body x axis in ENU, and the up components of y and z.
    xe, xn, xu = 1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y)
    yu, zu = 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)
    heading = np.mod(np.degrees(np.arctan2(xe, xn)), 360.0)
    pitch = np.degrees(np.arctan2(xu, np.hypot(yu, zu)))
    roll = np.degrees(np.arctan2(yu, zu))
    mag = trace.mag_gauss if trace.mag_gauss is not None else np.zeros((len(trace), 3))
    return np.column_stack([heading, pitch, roll, trace.accel_g, mag])


def held_gps(trace: PhysicalTrace) -> np.ndarray:
    """(n, 5): the trace's GPS rows, each fix held until the next."""
    if trace.gps is None or np.isnan(trace.gps[0, 0]):
        raise TraceError("gfsins: the trace needs a GPS stream with a fix on its first row (--gps-rate-hz)")
    has = ~np.isnan(trace.gps[:, 0])
    index = np.maximum.accumulate(np.where(has, np.arange(len(trace)), 0))
    return np.ascontiguousarray(trace.gps[index])


def run(trace: PhysicalTrace, ticks: int, profile: Path | GfsinsProfile = PROFILE) -> dict[str, Any]:
    """Run the board over ``trace`` for ``ticks`` 5 ms cycles (see ``_core.gfsins_run``); virtual
    time 0 is the trace's first sample."""
    prof = profile if isinstance(profile, GfsinsProfile) else load(profile)
    compass = compass_truth(trace)  # checks that the trace has the array columns
    assert trace.array_g is not None
    return dict(
        _core.gfsins_run(
            prof.text,
            prof.source,
            list(prof.overrides),
            np.ascontiguousarray(trace.t_s - trace.t_s[0]),
            np.ascontiguousarray(trace.array_g),
            compass,
            held_gps(trace),
            int(ticks),
        )
    )


#: Ticks the core runs per call at most (about 10 s of the board), and the wall time a call may
#: take: the caller checks for a stop (Ctrl-C, SIGTERM) between calls, so a call that ends within
#: a quarter of a second keeps the stop well within a second whatever the settings.
BLOCK_TICKS = 2000
CALL_WALL_S = 0.25
#: Rows of the trace read and pushed at a time (16 s of a 1 kHz drive: with the core's window of
#: samples and the inputs made from a chunk, ≈ 40 MB held).
CHUNK_ROWS = 1 << 14


def ticks_until(end_s: float, profile: GfsinsProfile) -> int:
    """The node's timer ticks at or before ``end_s`` (s from the trace's first sample)."""
    return max(0, int(np.floor((end_s - profile.start_s) / profile.period_s + 1e-9)) + 1)


class Stream:
    """The board run over a trace read a chunk at a time (``_core.GfsinsStream``): :meth:`parts`
    yields the per-cycle arrays block by block (as :func:`run` gives them for the whole run, plus
    ``truth_deg``: the vehicle's heading, pitch and roll at each tick, and ``events``: those of the
    block); :meth:`budget` is both processors' budget once they are all taken. Memory holds a chunk
    of the trace and a block of cycles whatever the trace's length; the caller may stop between
    blocks (each comes within about :data:`CALL_WALL_S`)."""

    def __init__(self, profile: GfsinsProfile, max_ticks: int | None = None) -> None:
        self.profile = profile
        self._core = _core.GfsinsStream(profile.text, profile.source, list(profile.overrides))
        self._limit = (1 << 62) if max_ticks is None else max(0, int(max_ticks))
        self.t0: float | None = None
        #: The trace's last time (s from its first sample) pushed so far.
        self.end_s = 0.0
        self._gps: np.ndarray | None = None  # the last fix, held into the next chunk

    def _push(self, chunk: PhysicalTrace) -> None:
        if self.t0 is None:
            self.t0 = float(chunk.t_s[0])
        compass = compass_truth(chunk)  # checks that the trace has the array columns
        assert chunk.array_g is not None
        if chunk.gps is None or (self._gps is None and np.isnan(chunk.gps[0, 0])):
            raise TraceError(
                "gfsins: the trace needs a GPS stream with a fix on its first row (--gps-rate-hz)"
            )
        g = np.array(chunk.gps, dtype=np.float64)
        if np.isnan(g[0, 0]):
            g[0] = self._gps
        has = ~np.isnan(g[:, 0])
        index = np.maximum.accumulate(np.where(has, np.arange(len(g)), 0))
        g = np.ascontiguousarray(g[index])
        self._gps = g[-1].copy()
        t = np.ascontiguousarray(chunk.t_s - self.t0)
        self._core.push(t, np.ascontiguousarray(chunk.array_g), compass, g)
        self.end_s = float(t[-1])

    def _drain(self) -> Iterator[dict[str, Any]]:
        while True:
            part = dict(self._core.run(BLOCK_TICKS, self._limit, CALL_WALL_S))
            if part["ticks"] == 0:
                if part["events"]:
                    yield part
                return
            yield part

    def parts(self, chunks: Iterable[PhysicalTrace]) -> Iterator[dict[str, Any]]:
        """Push ``chunks`` (consecutive chunks of one trace) and yield the blocks of cycles."""
        for chunk in chunks:
            if not len(chunk):
                continue
            self._push(chunk)
            yield from self._drain()
        self._core.end()
        self._limit = min(self._limit, ticks_until(self.end_s, self.profile))
        yield from self._drain()

    @property
    def ticks(self) -> int:
        """Ticks run so far."""
        return int(self._core.ticks())

    def budget(self) -> dict[str, Any]:
        """``budget``, ``stages``, ``classes``, ``period_s`` over the ticks run (as :func:`run`)."""
        return dict(self._core.budget())


class NavErrors:
    """:func:`nav_errors` gathered block by block (a streamed run): per quantity the count, the sum
    of squares and the largest magnitude; the truth GPS fixes wait until the tick that follows them."""

    def __init__(self, period_s: float) -> None:
        self.period_s = period_s
        self.fused = False
        self._fix_t = np.empty(0)
        self._fix = np.empty((0, 5))
        self._acc: dict[str, list[float]] = {}

    def add_truth(self, chunk: PhysicalTrace, t0: float) -> None:
        """The chunk's truth GPS rows (the trace's exact fixes)."""
        if chunk.gps is None:
            return
        rows = np.flatnonzero(~np.isnan(chunk.gps[:, 0]))
        self._fix_t = np.concatenate([self._fix_t, chunk.t_s[rows] - t0])
        self._fix = np.concatenate([self._fix, chunk.gps[rows]])

    def _add(self, name: str, e: np.ndarray) -> None:
        if not len(e):
            return
        a = self._acc.setdefault(name, [0.0, 0.0, 0.0])
        a[0] += len(e)
        a[1] += float(np.sum(e * e))
        a[2] = max(a[2], float(np.abs(e).max()))

    def add(self, part: dict[str, Any]) -> None:
        """One block of cycles (with ``truth_deg``)."""
        t = part["t0_s"][:, 0]
        if not len(t):
            return
        now = np.nan_to_num(part["nav_fused"][:, 0], nan=-1.0) == 1.0
        fused = np.maximum.accumulate(now | self.fused)
        self.fused = bool(fused[-1])
        truth = part["truth_deg"]
        att = part["nav_attitude_deg"]
        self._add("roll_deg", (att[:, 0] - truth[:, 2])[fused])
        self._add("pitch_deg", (att[:, 1] - truth[:, 1])[fused])
        self._add("heading_deg", (np.mod(att[:, 2] - truth[:, 0] + 180.0, 360.0) - 180.0)[fused])
        k = np.searchsorted(t, self._fix_t)
        inside = k < len(t)
        kk, g = k[inside], self._fix[inside]
        ok = fused[kk] & (t[kk] - self._fix_t[inside] < self.period_s)
        kk, g = kk[ok], g[ok]
        self._fix_t, self._fix = self._fix_t[~inside], self._fix[~inside]
        if len(kk):
            pos = part["nav_pos"][kk]
            r_e = 6_378_137.0
            dn = np.radians(pos[:, 0] - g[:, 2]) * r_e
            de = np.radians(pos[:, 1] - g[:, 3]) * r_e * np.cos(np.radians(g[:, 2]))
            self._add("horizontal_m", np.hypot(dn, de))
            self._add("vertical_m", pos[:, 2] - g[:, 4])
            course = np.radians(g[:, 1])
            v = part["nav_vel_enu"][kk]
            ve, vn = g[:, 0] * np.sin(course), g[:, 0] * np.cos(course)
            self._add("velocity_mps", np.sqrt((v[:, 0] - ve) ** 2 + (v[:, 1] - vn) ** 2 + v[:, 2] ** 2))

    def result(self) -> dict[str, dict[str, float]]:
        """As :func:`nav_errors`: per quantity ``rms`` and ``max_abs`` (empty: never fused)."""
        order = ("roll_deg", "pitch_deg", "heading_deg", "horizontal_m", "vertical_m", "velocity_mps")
        return {
            name: {"rms": math.sqrt(a[1] / a[0]), "max_abs": a[2]}
            for name in order
            if (a := self._acc.get(name)) is not None and a[0]
        }


#: The trace columns the board needs (``sins-fw synth vehicle`` writes them all).
NEEDED = "truth_q, the array columns array1…array7 and a GPS stream"


def budget_rows(out: dict[str, Any]) -> list[dict[str, Any]]:
    """The budget as rows: each processor's stages as the Rust budget gives them (names and order
    are the processors', nothing here knows them), then the processor's total; each row has
    ``processor``, ``stage`` and per rate class ``ticks``, ``peak_s``, ``mean_s``, ``peak_fraction``."""
    rows: list[dict[str, Any]] = []
    for proc, classes in out["budget"].items():
        rows += [r for r in out["stages"] if r["processor"] == proc]
        rows.append({"processor": proc, "stage": "total", **classes})
    return rows


def render_budget(out: dict[str, Any]) -> list[str]:
    """The budget table: peak and mean µs per rate class, the totals' peaks in % of the period."""
    classes = out["classes"]
    head = "".join(f"{c + ' peak':>13}{'mean':>9}" for c in classes)
    lines = [f"{'processor':<10}{'stage':<16}{head}   (µs; ticks per class: "
             + ", ".join(f"{c} {out['budget']['node'][c]['ticks']}" for c in classes) + ")"]  # fmt: skip
    for r in budget_rows(out):
        cells = "".join(
            f"{r[c]['peak_s'] * 1e6:13.3f}{r[c]['mean_s'] * 1e6:9.3f}"
            if r[c]["ticks"]
            else f"{'—':>13}{'—':>9}"
            for c in classes
        )
        lines.append(f"{r['processor']:<10}{r['stage']:<16}{cells}")
    period = out["period_s"]
    for proc, per in out["budget"].items():
        peaks = ", ".join(f"{c} {100 * per[c]['peak_fraction']:.3f} %" for c in classes if per[c]["ticks"])
        lines.append(f"{proc} peak in % of the {period * 1e3:g} ms period: {peaks}")
    return lines


# ------------------------------------------------------------------------------------- the run output

#: The ``format`` of the gyro-free board's run output.
RUN_FORMAT = "sins-fw-gfsins-run-output/1"


def _col(name: str, unit: str, what: str, kind: str = "float", nan: bool = False) -> Column:
    return Column(name, unit, what, kind, nan_allowed=nan)


#: One row per 5 ms cycle: the packet as the DSP decoded it (NaN: refused), the DSP's tilt, its
#: navigation (the columns of ``_core.GFSINS_COLUMNS``, declared in Rust), both
#: processors' time, and the bus log of the cycle (each link's activity; NaN: the link was idle).
RUN_COLUMNS: tuple[Column, ...] = (
    _col("t_s", "s", "the node's timer interrupt (virtual time; 0 is the trace's first sample)"),
    _col("sequence", "1", "packet sequence number"),
    _col(
        "flags", "1", "packet flags (bit 0 new compass, 1 new GPS fix, 2 GPS valid, 3 NMEA dropped)", "word"
    ),
    *(_col(f"a{i}_g", "g", f"A{i} as the DSP decoded it", nan=True) for i in range(1, 10)),
    _col("heading_deg", "°", "compass heading in the packet", nan=True),
    _col("compass_pitch_deg", "°", "compass pitch in the packet", nan=True),
    _col("compass_roll_deg", "°", "compass roll in the packet", nan=True),
    _col("lat_deg", "°", "GPS latitude in the packet", nan=True),
    _col("lon_deg", "°", "GPS longitude in the packet", nan=True),
    _col("alt_m", "m", "GPS altitude in the packet", nan=True),
    _col("speed_mps", "m/s", "GPS speed in the packet", nan=True),
    _col("course_deg", "°", "GPS course in the packet", nan=True),
    _col("utc_s", "s", "GPS UTC time of day in the packet", nan=True),
    _col("pitch_deg", "°", "the DSP's pitch (level formula on A7…A9)", nan=True),
    _col("roll_deg", "°", "the DSP's roll (level formula on A7…A9)", nan=True),
    *(
        # The navigation as computed (±inf too, should its state run away: nothing computed is lost).
        Column(name, unit, f"{c['meaning']} ({c['unit']})", nan_allowed=True, nonfinite_allowed=True)
        for c in _core.GFSINS_COLUMNS
        for name, unit in c["file"]
    ),
    _col("truth_pitch_deg", "°", "the trace's pitch at the tick"),
    _col("truth_roll_deg", "°", "the trace's roll at the tick"),
    _col("rate_class", "1", "budget rate class: 0 = 200 Hz, 1 = 10 Hz, 2 = 1 Hz"),
    _col("node_busy_s", "s", "the node's CPU time in the cycle"),
    _col("dsp_irq_s", "s", "the DSP's packet interrupt", nan=True),
    _col("dsp_busy_s", "s", "the DSP's packet handler time", nan=True),
    *(_col(f"spi{i}_ss_low_s", "s", f"SPI #{i}: SS low (the ADXL345 read starts)") for i in range(1, 8)),
    *(_col(f"spi{i}_ss_high_s", "s", f"SPI #{i}: SS high (the read is over)") for i in range(1, 8)),
    _col("spi8_start_s", "s", "SPI #8: DMA2 starts the packet to the DSP"),
    _col("spi8_end_s", "s", "SPI #8: SS high after the packet's last word"),
    _col("iic_start_s", "s", "I²C: START of the compass transaction started in the cycle", nan=True),
    _col("iic_end_s", "s", "I²C: its STOP", nan=True),
    _col("uart_start_s", "s", "UART: start bit of the first NMEA character handled in the cycle", nan=True),
    _col("uart_end_s", "s", "UART: stop bit of the last one", nan=True),
    _col("nmea_bytes", "1", "NMEA characters handled in the cycle"),
    _col("nmea_sentences", "1", "complete sentences handled in the cycle"),
)
RUN_SCHEMA = Schema("gyro-free board run output", RUN_FORMAT, RUN_COLUMNS)


def truth_tilt_deg(trace: PhysicalTrace, t_s: np.ndarray) -> np.ndarray:
    """(n, 2): the trace's pitch and roll (as :func:`compass_truth` defines them) held at ``t_s``."""
    c = compass_truth(trace)
    i = np.clip(np.searchsorted(trace.t_s - trace.t_s[0], t_s, side="right") - 1, 0, len(trace) - 1)
    return c[i, 1:3]


def save_metadata(profile: GfsinsProfile, extra: dict[str, str]) -> dict[str, str]:
    """The run output's metadata."""
    return {
        "sample_rate_hz": str(profile.get("node.timer_hz")),
        "profile": profile.source,
        "overrides": json.dumps(list(profile.overrides), ensure_ascii=False),
        "board": "gfsins",
        "created_by": "sins-fw run",
        **extra,
    }


def run_columns(out: dict[str, Any], truth_tilt: np.ndarray) -> dict[str, np.ndarray]:
    """The run output's columns, in file order."""
    one = {
        k: np.asarray(v)[:, 0] for k, v in out.items() if isinstance(v, np.ndarray) and v.shape[1:] == (1,)
    }
    cols: dict[str, np.ndarray] = {"t_s": one["t0_s"], "sequence": one["sequence"], "flags": one["flags"]}
    cols |= {f"a{i + 1}_g": out["accel_g"][:, i] for i in range(9)}
    cols |= dict(
        zip(("heading_deg", "compass_pitch_deg", "compass_roll_deg"), out["compass_deg"].T, strict=True)
    )
    names = ("lat_deg", "lon_deg", "alt_m", "speed_mps", "course_deg", "utc_s")
    cols |= dict(zip(names, out["gps"].T, strict=True))
    cols |= {"pitch_deg": out["tilt_deg"][:, 0], "roll_deg": out["tilt_deg"][:, 1]}
    for c in _core.GFSINS_COLUMNS:
        values = np.asarray(out[c["name"]])
        cols |= {name: values[:, i] for i, (name, _) in enumerate(c["file"])}
    cols |= {"truth_pitch_deg": truth_tilt[:, 0], "truth_roll_deg": truth_tilt[:, 1]}
    cols |= {
        "rate_class": one["class"],
        "node_busy_s": one["node_cpu_s"],
        "dsp_irq_s": one["t_irq_s"],
        "dsp_busy_s": one["t_done_s"] - one["t_irq_s"],
    }
    cols |= {f"spi{i + 1}_ss_low_s": out["spi_start_s"][:, i] for i in range(7)}
    cols |= {f"spi{i + 1}_ss_high_s": out["spi_end_s"][:, i] for i in range(7)}
    for link, pair in (("spi8", out["packet_s"]), ("iic", out["iic_s"]), ("uart", out["uart_s"])):
        cols |= {f"{link}_start_s": pair[:, 0], f"{link}_end_s": pair[:, 1]}
    cols |= {"nmea_bytes": one["nmea_bytes"], "nmea_sentences": one["nmea_sentences"]}
    return {c.name: np.ascontiguousarray(cols[c.name]) for c in RUN_COLUMNS}


def save_run(
    path: str | os.PathLike[str],
    out: dict[str, Any],
    truth_tilt: np.ndarray,
    profile: GfsinsProfile,
    extra: dict[str, str],
) -> None:
    """Write the run output (``.csv`` or ``.h5``, by extension) atomically, as the other boards' run
    output is written (tablefile: metadata header, shortest round-trip floats)."""
    write_table(path, RUN_SCHEMA, save_metadata(profile, extra), run_columns(out, truth_tilt))


def nav_errors(trace: PhysicalTrace, out: dict[str, Any]) -> dict[str, dict[str, float]]:
    """The C6727's navigation against the trace's truth, after its first fusion: attitude (roll,
    pitch, heading, °) at every tick; position (horizontal and vertical, m) and velocity (m/s) at
    the ticks that start within one period after a truth GPS row (the trace's exact fixes). Each
    as ``rms`` and ``max_abs``; empty when the navigation never fused."""
    t = out["t0_s"][:, 0]
    fused = np.maximum.accumulate(np.nan_to_num(out["nav_fused"][:, 0], nan=-1.0) == 1.0)
    if not fused.any():
        return {}
    t_tr = trace.t_s - trace.t_s[0]
    i = np.clip(np.searchsorted(t_tr, t, side="right") - 1, 0, len(trace) - 1)
    c = compass_truth(trace)[i]
    att = out["nav_attitude_deg"]
    errs: dict[str, np.ndarray] = {
        "roll_deg": att[:, 0] - c[:, 2],
        "pitch_deg": att[:, 1] - c[:, 1],
        "heading_deg": np.mod(att[:, 2] - c[:, 0] + 180.0, 360.0) - 180.0,
    }
    errs = {k: v[fused] for k, v in errs.items()}
    assert trace.gps is not None
    rows = np.flatnonzero(~np.isnan(trace.gps[:, 0]))
    period = float(np.median(np.diff(t))) if len(t) > 1 else 0.005
    k = np.searchsorted(t, t_tr[rows])
    ok = (k < len(t)) & fused[np.minimum(k, len(t) - 1)]
    k, rows = k[ok], rows[ok]
    ok = t[k] - t_tr[rows] < period
    k, rows = k[ok], rows[ok]
    if len(k):
        g = trace.gps[rows]
        pos = out["nav_pos"][k]
        r_e = 6_378_137.0
        dn = np.radians(pos[:, 0] - g[:, 2]) * r_e
        de = np.radians(pos[:, 1] - g[:, 3]) * r_e * np.cos(np.radians(g[:, 2]))
        errs["horizontal_m"] = np.hypot(dn, de)
        errs["vertical_m"] = pos[:, 2] - g[:, 4]
        course = np.radians(g[:, 1])
        v = out["nav_vel_enu"][k]
        ve, vn = g[:, 0] * np.sin(course), g[:, 0] * np.cos(course)
        errs["velocity_mps"] = np.sqrt((v[:, 0] - ve) ** 2 + (v[:, 1] - vn) ** 2 + v[:, 2] ** 2)
    return {
        name: {"rms": float(np.sqrt(np.mean(e**2))), "max_abs": float(np.abs(e).max())}
        for name, e in errs.items()
        if len(e)
    }
