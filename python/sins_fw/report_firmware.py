"""The one-page report of a C firmware's run output (`sins-fw report RUN.h5` of a `run --firmware --out`
file), drawn from the file as recorded, a block at a time (each series held in at most
:data:`sins_fw.report_page.MAX_POINTS` points): the firmware's attitude and its error against the
recorded trace's truth when its globals give the attitude (q0…q3 and/or the Euler angles), otherwise
its globals, one panel each; and what the file records of the run (the firmware, its float mode, the
trace, the profile). Nothing is re-emulated: the Rust model does not run a C firmware.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from sins_fw import quaternion
from sins_fw.atomic import save_png
from sins_fw.profile import Profile
from sins_fw.report_page import (
    ANGLE_COLORS,
    DPI,
    FIGSIZE,
    LEGEND_ROOM,
    TITLE_WIDTH,
    PageData,
    Series,
    _attitude_panel,
    _wrap,
)
from sins_fw.run_output import FirmwareRunFile

#: Globals drawn, one panel each, on the page of a firmware whose globals do not give the attitude;
#: the others are named in the metadata panel.
MAX_GLOBAL_PANELS = 6
#: Characters of a metadata line before it wraps (monospace, 8 pt: the page's width).
METADATA_WIDTH = 125


class FirmwarePage:
    """What the page of a firmware run's file plots, gathered part by part
    (:meth:`FirmwareRunFile.parts`). ``trace``: where the recorded trace was found (None: not found
    or not looked for); ``trace_note``: why it was not (one line)."""

    def __init__(
        self,
        run: FirmwareRunFile,
        profile: Profile,
        *,
        trace: Path | None = None,
        trace_note: str | None = None,
    ) -> None:
        self.run, self.profile = run, profile
        self.trace, self.trace_note = trace, trace_note
        self.rows = 0
        self.t_first: float | None = None
        self.t_last: float | None = None
        self.data = PageData(profile) if run.has_attitude else None
        self.truth_euler = [Series() for _ in range(3)]
        shown = [] if run.has_attitude else run.columns[:MAX_GLOBAL_PANELS]
        self.globals = {c: Series() for c in shown}

    def add(self, part: dict[str, Any]) -> None:
        t = part["firmware_t_s"]
        if len(t):
            self.rows += len(t)
            self.t_first = float(t[0]) if self.t_first is None else self.t_first
            self.t_last = float(t[-1])
        if self.data is not None:
            self.data.add(part)
            truth = part.get("truth_q")
            if truth is not None:
                ok = np.isfinite(truth).all(axis=1)
                deg = quaternion.to_euler_deg(truth[ok])
                for k in range(3):
                    self.truth_euler[k].add(t[ok], deg[:, k])
        for c, s in self.globals.items():
            s.add(t, np.asarray(part["firmware_globals"][c], dtype=np.float64))

    @property
    def has_truth(self) -> bool:
        return self.data is not None and self.data.worst is not None

    def metadata_lines(self) -> list[str]:
        """What the file records of the run, a line each."""
        m = self.run.metadata
        float_mode = m.get("float_mode") or "not recorded (a file written before run outputs recorded it)"
        lines = [
            f"firmware: {m.get('firmware', '(not recorded)')}; float mode: {float_mode}; "
            f"globals file: {m.get('globals', '(none)')}",
        ]
        if self.trace is not None:
            truth = "its truth compared" if self.has_truth else "it has no truth to compare with"
            lines.append(f"trace: {m.get('trace', '?')}, found at {os.path.normpath(self.trace)}: {truth}")
        elif self.trace_note is not None:
            lines.append(f"trace: not found, so no truth: {self.trace_note}")
        else:
            lines.append(
                f"trace: {m.get('trace', '(not recorded)')} (the globals give no attitude to compare)"
            )
        overrides = " ".join(self.profile.overrides)
        span = (
            f"{self.t_first:.6f} … {self.t_last:.6f} s"
            if self.t_first is not None and self.t_last is not None
            else "no rows"
        )
        lines.append(
            f"profile: {Path(self.profile.source).name} {overrides}".rstrip()
            + f"; {self.rows} ISR rows at {m.get('sample_rate_hz', '?')} Hz, {span}"
        )
        if not self.run.has_attitude and len(self.run.columns) > MAX_GLOBAL_PANELS:
            rest = self.run.columns[MAX_GLOBAL_PANELS:]
            lines.append(f"not drawn ({len(rest)} more globals): {', '.join(rest)}")
        lines.append(
            "shown as recorded: a C firmware's run is not re-emulated (the Rust model does not run it); "
            "`sins-fw run TRACE --firmware FW.so` runs it again"
        )
        return lines


@dataclass
class FirmwareReportAxes:
    """The panels of the page: by name (``attitude``, ``error``, or each global's column) and the
    metadata panel."""

    panels: dict[str, Axes]
    metadata: Axes


def _euler_panel(ax: Axes, page: FirmwarePage) -> None:
    assert page.data is not None
    run = page.run
    source = "its Euler angles" if run.has_euler else "its quaternion's Euler angles"
    for k, name in enumerate(("roll", "pitch", "yaw")):
        ax.plot(*page.data.euler[k].points(), color=ANGLE_COLORS[k], lw=0.8, label=f"{name}")
        if page.truth_euler[k].rows:
            ax.plot(
                *page.truth_euler[k].points(), color=ANGLE_COLORS[k], lw=0.8, ls=":", label=f"{name} truth"
            )
    ax.set_ylabel("attitude (°)")
    truth = " and the trace's truth (dotted)" if any(s.rows for s in page.truth_euler) else ""
    ax.set_title(_wrap(f"The firmware's attitude: {source}{truth}"), loc="left", fontsize=10)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + LEGEND_ROOM * (hi - lo))
    ax.legend(loc="upper left", fontsize=8, ncol=6)
    ax.grid(alpha=0.3)


def _global_panel(ax: Axes, page: FirmwarePage, column: str) -> None:
    ax.plot(*page.globals[column].points(), color="tab:blue", lw=0.8)
    unit = page.run.units.get(column, "")
    ax.set_ylabel(unit if unit not in ("", "1") else "")
    ax.set_title(page.run.label(column), loc="left", fontsize=9)
    ax.grid(alpha=0.3)


def firmware_report_figure(page: FirmwarePage, *, title: str = "") -> tuple[Figure, FirmwareReportAxes]:
    """The page as a matplotlib figure (time axes shared)."""
    names: list[str]
    if page.data is not None:
        names = ["attitude", "error"] if page.has_truth else ["attitude"]
        ratios = [3.0] * len(names)
    else:
        names = list(page.globals) or ["globals"]
        ratios = [1.5] * len(names)
    # The metadata panel: about a fifth of the page, whatever the number of panels above it.
    fig, axes = plt.subplots(
        len(names) + 1,
        1,
        figsize=FIGSIZE,
        dpi=DPI,
        gridspec_kw={"height_ratios": [*ratios, max(1.6, 0.3 * sum(ratios))]},
    )
    panels = dict(zip(names, axes[:-1], strict=True))
    for ax in axes[1:-1]:
        ax.sharex(axes[0])
    for ax in axes[:-2]:
        ax.tick_params(labelbottom=False)  # one time axis, under the last panel
    if page.data is not None:
        _euler_panel(panels["attitude"], page)
        if page.has_truth:
            _attitude_panel(panels["error"], page.data)
    elif page.globals:
        for c in page.globals:
            _global_panel(panels[c], page, c)
    else:
        panels["globals"].text(0.5, 0.5, "the file has no globals", ha="center", va="center")
    axes[-2].set_xlabel("emulated time (s)")
    meta = axes[-1]
    meta.axis("off")
    meta.set_title("The run, as its file records it", loc="left", fontsize=10)
    text = "\n".join(_wrap(line, METADATA_WIDTH) for line in page.metadata_lines())
    meta.text(0.0, 1.0, text, transform=meta.transAxes, va="top", ha="left", fontsize=8, family="monospace")
    head = title or "sins-fw run --firmware"
    firmware = Path(page.run.metadata.get("firmware", "?")).name
    fig.suptitle(
        _wrap(f"{head} — C firmware {firmware}, shown as recorded — {page.rows} ISR rows", TITLE_WIDTH - 10),
        fontsize=11,
    )
    fig.tight_layout()
    return fig, FirmwareReportAxes(panels, meta)


def save_firmware_report(
    page: FirmwarePage, path: str | os.PathLike[str], *, title: str = ""
) -> tuple[Path, FirmwareReportAxes]:
    """Render the page to a PNG at ``path`` (temporary file + rename)."""
    out = Path(path)
    fig, axes = firmware_report_figure(page, title=title)
    save_png(fig, out, DPI)
    return out, axes
