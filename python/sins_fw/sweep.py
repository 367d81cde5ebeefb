"""Parameter sweeps and the tables and pictures of Monte Carlo results.

A sweep runs every scenario × grid point × seed (:mod:`sins_fw.montecarlo` jobs on any engine). A
grid point is a set of profile overrides: the product of ``--grid KEY=VALUES`` options, or a list
of ``--point "KEY=VALUE ..."`` options (both: their product). ``errors.seed`` in a grid gives the
seeds, the realisations of each point, instead of ``--runs``.

Results are one tidy table, a row per run (:func:`run_table`), and the percentiles of each error per
scenario and grid point (:func:`percentile_table`), written as Parquet or HDF5 plus CSV
(:func:`write_tables`), and drawn (:func:`plot_sweep`, :func:`plot_bands`).
"""

from __future__ import annotations

import contextlib
import csv
import io
import itertools
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sins_fw.atomic import atomic_path, kept_error_file, save_png
from sins_fw.errors import InputError
from sins_fw.montecarlo import ALPHA_ERRORS, ERRORS, PERCENTILES, Distribution, Outcome
from sins_fw.profile import Profile

#: A table: column name → values (strings, ints or floats), every column the same length.
Table = dict[str, list[Any]]
#: Output formats by suffix; every one also writes CSV beside it.
FORMATS = (".parquet", ".h5", ".hdf5", ".csv")
SEED_KEY = "errors.seed"


# ---------------------------------------------------------------------------------------------------
# Grids
# ---------------------------------------------------------------------------------------------------


def parse_values(text: str, where: str) -> list[str]:
    """``9,49,127`` or ``1..200`` (integers, both ends included) or a mix: the values as texts."""
    out: list[str] = []
    for part in (p.strip() for p in text.split(",")):
        if not part:
            raise InputError(f"{where}: an empty value in `{text}`")
        lo, sep, hi = part.partition("..")
        if sep:
            try:
                a, b = int(lo), int(hi)
            except ValueError:
                raise InputError(f"{where}: `{part}`: a range is two integers, e.g. 1..200") from None
            if b < a:
                raise InputError(f"{where}: `{part}`: the range is empty (the end is below the start)")
            out.extend(str(v) for v in range(a, b + 1))
        else:
            out.append(part)
    return out


def parse_grid(items: Sequence[str]) -> dict[str, list[str]]:
    """``--grid KEY=VALUES`` options as key → values (a key given twice is refused)."""
    grid: dict[str, list[str]] = {}
    for item in items:
        key, sep, values = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InputError(f"--grid `{item}`: expected KEY=VALUES, e.g. spi.spibrr=9,49,127")
        if key in grid:
            raise InputError(f"--grid {key}: given twice")
        grid[key] = parse_values(values, f"--grid {key}")
    return grid


def parse_point(text: str) -> tuple[str, ...]:
    """``--point "KEY=VALUE KEY=VALUE"`` as overrides."""
    items = tuple(text.split())
    for item in items:
        if "=" not in item or item.startswith("="):
            raise InputError(f"--point `{text}`: `{item}` is not KEY=VALUE")
    return items


def seeds_of(values: Sequence[str]) -> list[int]:
    try:
        return [int(v) for v in values]
    except ValueError:
        raise InputError(f"--grid {SEED_KEY}: seeds are integers, got {', '.join(values)}") from None


def grid_points(
    profile: Profile, grid: dict[str, list[str]], listed: Sequence[tuple[str, ...]] = ()
) -> list[tuple[str, ...]]:
    """The grid points (each validated against the profile): the product of the grid's keys (seeds
    excluded) with the listed points."""
    keys = [k for k in grid if k != SEED_KEY]
    product = [
        tuple(f"{k}={v}" for k, v in zip(keys, combo, strict=True))
        for combo in itertools.product(*(grid[k] for k in keys))
    ]
    points = [(*a, *b) for a in (listed or [()]) for b in product]
    for point in points:
        if any(item.partition("=")[0].strip() == SEED_KEY for item in point):
            raise InputError(f"--point {' '.join(point)}: give seeds with --grid {SEED_KEY}=… or --runs")
        profile.with_overrides(*point)  # a wrong key or value is refused before anything runs
    return points


def point_keys(points: Sequence[tuple[str, ...]]) -> list[str]:
    """The keys that vary over the points, in order of appearance."""
    keys = dict.fromkeys(item.partition("=")[0] for point in points for item in point)
    return list(keys)


# ---------------------------------------------------------------------------------------------------
# Tables
# ---------------------------------------------------------------------------------------------------


def _point_text(point: tuple[str, ...]) -> str:
    return " ".join(point) or "(profile as given)"


def run_table(outcomes: Sequence[Outcome]) -> Table:
    """One row per run: scenario, grid point (as text and one column per key), seed, the errors at
    the end, the solved and true angles, and the fingerprint of the software that computed it."""
    keys = point_keys([o.key[1] for o in outcomes])
    table: Table = {"scenario": [], "point": [], **{k: [] for k in keys}, "seed": []}
    for name in ERRORS:
        table[f"error_{name}_deg"] = []
    for kind in ("solved", "truth"):
        for angle in ERRORS[:3]:
            table[f"{kind}_{angle}_deg"] = []
    wing = any(_has_alpha(o) for o in outcomes)
    if wing:  # the wing unit's α errors (montecarlo.ALPHA_ERRORS)
        for name in ALPHA_ERRORS:
            table[f"alpha_error_{name}_deg"] = []
    table |= {"sins_fw_version": [], "core_build": [], "platform": []}
    for o in outcomes:
        case, point, seed = o.key
        values = dict(item.partition("=")[::2] for item in point)
        table["scenario"].append(case)
        table["point"].append(_point_text(point))
        for k in keys:
            table[k].append(values.get(k, ""))
        table["seed"].append(seed)
        for name, v in zip(ERRORS, o.final_error_deg, strict=True):
            table[f"error_{name}_deg"].append(float(v))
        for angle, s, t in zip(ERRORS[:3], o.solved_deg, o.truth_deg, strict=True):
            table[f"solved_{angle}_deg"].append(float(s))
            table[f"truth_{angle}_deg"].append(float(t))
        if wing:
            for name, v in zip(ALPHA_ERRORS, o.alpha_error_deg, strict=True):
                table[f"alpha_error_{name}_deg"].append(float(v))
        table["sins_fw_version"].append(o.fingerprint.version)
        table["core_build"].append(o.fingerprint.core)
        table["platform"].append(o.fingerprint.platform)
    return table


def _has_alpha(o: Outcome) -> bool:
    """The outcome is the wing unit's (its figures are α's, NaN where it gave none)."""
    return o.wing


def percentile_table(outcomes: Sequence[Outcome]) -> Table:
    """Per scenario, grid point and error: the number of runs and the percentiles at the end (for the
    wing unit, its α errors: ``alpha_final``, ``alpha_static_max``, ``alpha_dynamic_max``)."""
    keys = point_keys([o.key[1] for o in outcomes])
    table: Table = {"scenario": [], "point": [], **{k: [] for k in keys}, "error": [], "runs": []}
    for p in PERCENTILES:
        table[f"p{p:g}_deg"] = []
    groups: dict[tuple[str, tuple[str, ...]], list[Outcome]] = {}
    for o in outcomes:
        groups.setdefault(o.key[:2], []).append(o)
    for (case, point), rows in groups.items():
        values = dict(item.partition("=")[::2] for item in point)
        finals = np.array([o.final_error_deg for o in rows], dtype=np.float64)
        names: tuple[str, ...] = ERRORS
        if all(_has_alpha(o) for o in rows):  # the wing unit: α, not an attitude
            alpha = np.array([o.alpha_error_deg for o in rows], dtype=np.float64)
            full = [i for i in range(len(ALPHA_ERRORS)) if np.isfinite(alpha[:, i]).any()]
            finals, names = alpha[:, full], tuple(f"alpha_{ALPHA_ERRORS[i]}" for i in full)
        for i, name in enumerate(names):
            table["scenario"].append(case)
            table["point"].append(_point_text(point))
            for k in keys:
                table[k].append(values.get(k, ""))
            table["error"].append(name)
            # α over the runs that gave one (an attitude error is NaN only without truth: kept)
            column = finals[:, i] if names is ERRORS else finals[np.isfinite(finals[:, i]), i]
            table["runs"].append(len(column))
            for p, v in zip(PERCENTILES, np.percentile(column, PERCENTILES), strict=True):
                table[f"p{p:g}_deg"].append(float(v))
    return table


def check_output(path: str | os.PathLike[str], option: str = "--out") -> Path:
    """Refuse an output location before anything runs: a known suffix, not a folder."""
    out = Path(path)
    if out.suffix.lower() not in FORMATS:
        raise InputError(f"{option} {out}: expected a file ending in {', '.join(FORMATS)}")
    if out.is_dir():
        raise InputError(f"{option} {out}: is a folder; expected a file name")
    if out.parent.exists() and not out.parent.is_dir():
        raise InputError(f"{option} {out}: {out.parent} is not a folder")
    return out


def _csv_text(table: Table) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(table)
    for row in zip(*table.values(), strict=True):
        # repr: the shortest text that reads back as the same float.
        w.writerow([repr(v) if isinstance(v, float) else v for v in row])
    return buf.getvalue()


def _write_parquet(tmp: Path, table: Table) -> None:
    # pyarrow and h5py are heavy imports: only for the output format asked for.
    import pyarrow as pa
    import pyarrow.parquet as pq  # as pyarrow: only for Parquet output

    pq.write_table(pa.table(table), tmp)


def _write_hdf5(tmp: Path, tables: dict[str, Table]) -> None:
    import h5py  # a heavy import: only for HDF5 output

    # Through kept_error_file: HDF5 crashes the interpreter closing a file after a failed write (a
    # full disk); the failure is raised once h5py has closed the file cleanly.
    with kept_error_file(tmp) as sink, h5py.File(sink, "w") as f:
        for name, table in tables.items():
            group = f.create_group(name)
            for column, values in table.items():
                if values and isinstance(values[0], str):
                    group.create_dataset(column, data=values, dtype=h5py.string_dtype())
                else:
                    group.create_dataset(column, data=np.asarray(values))


def write_tables(path: str | os.PathLike[str], outcomes: Sequence[Outcome]) -> list[Path]:
    """Write the run table at ``path`` (Parquet, HDF5 or CSV by suffix) and the percentile table
    beside it (``STEM-percentiles`` in the same format; in an HDF5 file, its group ``percentiles``),
    each also as CSV. The files are written together: each to a temporary file first, and renamed
    into place only once every one of them is complete (a failure, a full disk included, leaves all
    of them as they were). Returns the files written."""
    out = check_output(path)
    runs, pct = run_table(outcomes), percentile_table(outcomes)
    files = table_files(out)
    with contextlib.ExitStack() as stack:
        tmps = [stack.enter_context(atomic_path(f)) for f in files]
        suffix = out.suffix.lower()
        if suffix == ".parquet":
            with _failing(tmps[0]):
                _write_parquet(tmps[0], runs)
            with _failing(tmps[1]):
                _write_parquet(tmps[1], pct)
        elif suffix in (".h5", ".hdf5"):
            with _failing(tmps[0]):
                _write_hdf5(tmps[0], {"runs": runs, "percentiles": pct})
        for tmp, table in zip(tmps[-2:], (runs, pct), strict=True):
            with _failing(tmp):
                tmp.write_text(_csv_text(table), encoding="utf-8", newline="\n")
    return files


@contextlib.contextmanager
def _failing(tmp: Path) -> Iterator[None]:
    """A failed write to ``tmp`` names it (a library's OSError may name no file), so that the
    atomic_path it belongs to reports its destination and no other."""
    try:
        yield
    except OSError as e:
        if e.filename is None:
            raise OSError(e.errno, e.strerror or str(e), str(tmp)) from None
        raise


def table_files(path: str | os.PathLike[str]) -> list[Path]:
    """Every file :func:`write_tables` writes for ``path``, in order: the run table, (Parquet) its
    percentile table, and the CSV copies of both (a CSV ``path`` is its own copy)."""
    out = Path(path)
    stem = out.with_suffix("")
    files = [out]
    if out.suffix.lower() == ".parquet":
        files.append(Path(f"{stem}-percentiles.parquet"))
    if out.suffix.lower() != ".csv":
        files.append(stem.with_suffix(".csv"))
    return [*files, Path(f"{stem}-percentiles.csv")]


# ---------------------------------------------------------------------------------------------------
# Pictures
# ---------------------------------------------------------------------------------------------------

#: The errors drawn: the rotation between estimate and truth, and its split into heading and tilt.
DRAWN = ("total", "heading", "inclination")


def _pyplot() -> Any:
    # matplotlib is a heavy import (and needs its Agg backend set first): only when a plot is drawn.
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after the backend is set

    return plt


def plot_bands(dists: dict[str, Distribution], path: str | os.PathLike[str], title: str) -> Path:
    """Per case: the total, heading and inclination errors over time as percentile bands (p5–p95,
    p25–p75, median) and a histogram of each at the end."""
    plt = _pyplot()
    n = len(dists)
    fig, axes = plt.subplots(n, 4, figsize=(15, 2.8 * n + 0.6), squeeze=False)
    colours = dict(zip(DRAWN, ("C0", "C1", "C2"), strict=True))
    for row, (name, d) in zip(axes, dists.items(), strict=True):
        for ax, what in zip(row[:3], DRAWN, strict=True):
            series = d.error_series_deg[:, :, ERRORS.index(what)]
            p5, p25, p50, p75, p95 = np.nanpercentile(series, PERCENTILES, axis=0)
            ax.fill_between(d.t_s, p5, p95, color=colours[what], alpha=0.2, lw=0, label="p5–p95")
            ax.fill_between(d.t_s, p25, p75, color=colours[what], alpha=0.4, lw=0, label="p25–p75")
            ax.plot(d.t_s, p50, color=colours[what], lw=1.2, label="median")
            ax.set_title(f"{name}: {what} error", fontsize=9)
            ax.set_xlabel("time, s", fontsize=8)
            ax.set_ylabel("degrees", fontsize=8)
            ax.set_ylim(bottom=0.0)
            ax.tick_params(labelsize=7)
            ax.legend(fontsize=7, loc="upper left", frameon=False)
        hist = row[3]
        for what in DRAWN:
            values = d.errors(what)
            hist.hist(
                values[np.isfinite(values)], bins="auto", histtype="step", color=colours[what], label=what
            )
        hist.set_title(f"{name}: errors at the end, {len(d.seeds)} runs", fontsize=9)
        hist.set_xlabel("degrees", fontsize=8)
        hist.set_ylabel("runs", fontsize=8)
        hist.tick_params(labelsize=7)
        hist.legend(fontsize=7, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_png(fig, path, dpi=110)


def plot_sweep(outcomes: Sequence[Outcome], path: str | os.PathLike[str], title: str) -> Path:
    """Per scenario (rows) and error (columns): the error at the end at each grid point, median with
    p25–p75 (thick) and p5–p95 (thin) bars."""
    plt = _pyplot()
    pct = percentile_table(outcomes)
    scenarios = list(dict.fromkeys(pct["scenario"]))
    points = list(dict.fromkeys(pct["point"]))
    fig, axes = plt.subplots(
        len(scenarios), len(DRAWN), figsize=(5 * len(DRAWN), 3.2 * len(scenarios) + 1.2), squeeze=False
    )
    keys = point_keys([o.key[1] for o in outcomes])
    # One key varies: its values on the axis, its name below; else each point's overrides.
    labels = [p.partition("=")[2] for p in points] if len(keys) == 1 else points
    rows = list(zip(*pct.values(), strict=True))
    col = {name: i for i, name in enumerate(pct)}
    for axrow, scenario in zip(axes, scenarios, strict=True):
        for ax, what in zip(axrow, DRAWN, strict=True):
            sel = [r for r in rows if r[col["scenario"]] == scenario and r[col["error"]] == what]
            x = np.array([points.index(r[col["point"]]) for r in sel])
            p = {q: np.array([r[col[f"p{q:g}_deg"]] for r in sel]) for q in PERCENTILES}
            ax.vlines(x, p[5.0], p[95.0], color="C0", lw=1.0)
            ax.vlines(x, p[25.0], p[75.0], color="C0", lw=4.0)
            ax.plot(x, p[50.0], "o", color="C1", ms=4, label="median")
            ax.set_title(f"{scenario}: {what} error at the end", fontsize=9)
            ax.set_ylabel("degrees", fontsize=8)
            tilt = 30 if len(points) > 4 and len(keys) != 1 else 0
            ax.set_xticks(
                range(len(points)), labels, rotation=tilt, ha="right" if tilt else "center", fontsize=7
            )
            ax.set_xlim(-0.5, len(points) - 0.5)
            if len(keys) == 1:
                ax.set_xlabel(keys[0], fontsize=8)
            ax.tick_params(axis="y", labelsize=7)
            ax.set_ylim(bottom=0.0)
    fig.suptitle(title + "\nbars: p5–p95 (thin), p25–p75 (thick); dots: median", fontsize=10)
    fig.tight_layout()
    return save_png(fig, path, dpi=110)
