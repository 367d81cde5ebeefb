"""The gyro-free board's Rerun recording (``sins-fw replay TRACE --profile gfsins.toml``): the
DSP's tilt against the truth, the array's nine channels and the compass as the DSP decoded them,
both processors' time per cycle, the events, and one bus lane per link of the board for a window of
ticks (each SPI core's read of its ADXL345, the compass's I²C transactions, the NMEA characters on
the UART, the packet on SPI #8 to the DSP). Logged with the helpers and paths of
:mod:`sins_fw.viewer.recording`."""

from __future__ import annotations

from typing import Any

import numpy as np
import rerun as rr
import rerun.blueprint as rrb
from numpy.typing import NDArray

from sins_fw.viewer import paths
from sins_fw.viewer.recording import SEVERITY_LEVEL, _flush, _send, _seq, _series, _time

PS = 1e12


def _ps(t_s: NDArray[Any]) -> NDArray[np.uint64]:
    return np.round(np.asarray(t_s, dtype=np.float64) * PS).astype(np.uint64)


def blueprint(*, bus: bool) -> rrb.Blueprint:
    """Tabs Attitude (tilt against truth, events), Sensors (array, compass), Budget (both
    processors), and Bus (every link's lane) when a bus window was recorded."""
    attitude = rrb.Vertical(
        *(
            rrb.TimeSeriesView(name=f"{a.capitalize()}: DSP and truth (°)", origin=f"attitude/{a}")
            for a in ("pitch", "roll")
        ),
        rrb.TimeSeriesView(name="Tilt error (°), DSP − truth", origin="attitude_error"),
        rrb.TextLogView(origin=paths.EVENTS, name="Events"),
        name="Attitude",
    )
    sensors = rrb.Vertical(
        rrb.TimeSeriesView(name="A1…A9 as the DSP decoded them (g)", origin=paths.GFSINS_ARRAY),
        rrb.TimeSeriesView(name="Compass heading in the packet (°)", origin=paths.GFSINS_COMPASS),
        name="Sensors",
    )
    budget = rrb.Vertical(
        rrb.TimeSeriesView(name="Acquisition node: CPU time per cycle (µs)", origin=paths.GFSINS_NODE_BUSY),
        rrb.TimeSeriesView(name="C6727B: packet handler per cycle (µs)", origin=paths.GFSINS_DSP_BUSY),
        rrb.TextLogView(origin=paths.EVENTS, name="Events"),
        name="Budget",
    )
    tabs: list[rrb.Container] = [attitude, sensors, budget]
    if bus:
        tabs.append(
            rrb.Vertical(
                rrb.StateTimelineView(
                    name="Links: SPI #1–#7 (ADXL345), IIC #1 (HMC6343), UART (GR-87), SPI #8 (to the DSP)",
                    contents=[paths.bus_lane(link) for link in paths.GFSINS_LINKS],
                ),
                name="Bus",
            )
        )
    return rrb.Blueprint(
        rrb.Tabs(*tabs, active_tab=0),
        rrb.TimePanel(timeline=paths.TIME, expanded=True),
        collapse_panels=False,
    )


def bus_lanes(
    out: dict[str, Any], window: tuple[int, int], compass_address: int
) -> dict[str, tuple[NDArray[np.uint64], list[str]]]:
    """Each link's state changes in the ticks ``window`` (first, last; 1 is the first tick), as
    (times in ps, states): what the link carries from each change to the next, ``idle`` between;
    an I²C transaction names the address it was sent to (the profile's ``compass.address``)."""
    first, last = window
    rows = np.arange(first - 1, min(last, len(out["sequence"])))
    lanes: dict[str, tuple[list[int], list[str]]] = {link: ([], []) for link in paths.GFSINS_LINKS}

    def span(link: str, a: float, b: float, what: str) -> None:
        if np.isnan(a) or np.isnan(b):
            return
        t, s = lanes[link]
        t += [int(_ps(np.array([a]))[0]), int(_ps(np.array([b]))[0])]
        s += [what, "idle"]

    for r in rows:
        seq = int(out["sequence"][r, 0])
        for i in range(7):
            span(
                f"spi{i + 1}",
                out["spi_start_s"][r, i],
                out["spi_end_s"][r, i],
                "read DATAX0…DATAZ1 (0xF2 + 6 bytes)",
            )
        phase = int(out["compass_phase"][r, 0])
        span(
            "iic1",
            *out["iic_s"][r],
            f"0x{compass_address:02X} "
            + ("write 0x50 (post heading)" if phase == 0 else "read 6 bytes (heading, pitch, roll)"),
        )
        n = int(out["nmea_bytes"][r, 0])
        span(
            "uart",
            *out["uart_s"][r],
            f"NMEA: {n} characters, {int(out['nmea_sentences'][r, 0])} sentences complete",
        )
        span("spi8", *out["packet_s"][r], f"packet {seq}: 26 words, flags 0x{int(out['flags'][r, 0]):04X}")
    result = {}
    for link, (t, s) in lanes.items():
        order = np.argsort(np.asarray(t, dtype=np.uint64), kind="stable")
        result[link] = (np.asarray(t, dtype=np.uint64)[order], [s[i] for i in order])
    return result


class Recorder:
    """The run logged block by block as the board streams it (``sins_fw.gfsins.Stream.parts``):
    each block's series, events and its ticks of the bus window go out as they come, so that
    memory holds a block whatever the run's length. The ticks are numbered across blocks (1 is
    the first)."""

    def __init__(self, rec: rr.RecordingStream, window: tuple[int, int] | None, compass_address: int) -> None:
        self.rec = rec
        self.window = window
        self.compass_address = compass_address
        self.ticks = 0
        self.events = 0
        #: Bus transactions logged so far.
        self.logged = 0
        self._declared = False

    def _declare(self) -> None:
        if self._declared:
            return
        self._declared = True
        for angle in ("pitch", "roll"):
            for what, colour in (("estimate", (66, 135, 245)), ("truth", (120, 120, 120))):
                _series(self.rec, paths.attitude(angle, what), [f"{angle} {what}"], [colour])
            _series(self.rec, paths.attitude_error(angle), [f"{angle} error"])
        _series(self.rec, paths.GFSINS_ARRAY, [f"A{i}" for i in range(1, 10)])
        _series(self.rec, paths.GFSINS_COMPASS, ["heading"])
        _series(self.rec, paths.GFSINS_NODE_BUSY, ["node CPU (µs)"])
        _series(self.rec, paths.GFSINS_DSP_BUSY, ["DSP handler (µs)"])

    def add(self, out: dict[str, Any], truth_tilt_deg: NDArray[Any]) -> None:
        """One block of cycles (the arrays of ``sins_fw.gfsins.run`` for these ticks, their
        ``events``) and the trace's pitch and roll at each of its ticks."""
        self._declare()
        rec, first = self.rec, self.ticks
        n = len(out["sequence"])
        t = _ps(out["t0_s"][:, 0])
        if n:
            index = [_time(t), _seq(paths.TICK, np.arange(first + 1, first + n + 1))]
            tilt = out["tilt_deg"]
            for i, angle in enumerate(("pitch", "roll")):
                for what, values in (("estimate", tilt[:, i]), ("truth", truth_tilt_deg[:, i])):
                    _send(rec, paths.attitude(angle, what), index, rr.Scalars.columns(scalars=values))
                error = tilt[:, i] - truth_tilt_deg[:, i]
                _send(rec, paths.attitude_error(angle), index, rr.Scalars.columns(scalars=error))
            _send(rec, paths.GFSINS_ARRAY, index, rr.Scalars.columns(scalars=out["accel_g"]))
            _send(rec, paths.GFSINS_COMPASS, index, rr.Scalars.columns(scalars=out["compass_deg"][:, 0]))
            node = out["node_cpu_s"][:, 0] * 1e6
            _send(rec, paths.GFSINS_NODE_BUSY, index, rr.Scalars.columns(scalars=node))
            busy = (out["t_done_s"][:, 0] - out["t_irq_s"][:, 0]) * 1e6
            _send(rec, paths.GFSINS_DSP_BUSY, index, rr.Scalars.columns(scalars=busy))
        events = out["events"]
        if events:
            et = _ps(np.array([e["t_s"] for e in events]))
            tick = first + np.clip(np.searchsorted(t, et, side="right"), 1, max(n, 1))
            seq = np.arange(self.events, self.events + len(events))
            ev_index = [_time(et), _seq(paths.TICK, tick), _seq(paths.EVENT, seq)]
            text = [f"[{e['kind']}] {e['message']}" for e in events]
            level = [SEVERITY_LEVEL.get(e["severity"], rr.TextLogLevel.INFO) for e in events]
            _send(rec, paths.EVENTS, ev_index, rr.TextLog.columns(text=text, level=level))
            self.events += len(events)
        if self.window is not None and n:
            # The window's ticks in this block, numbered within it.
            lo, hi = max(self.window[0], first + 1), min(self.window[1], first + n)
            if lo <= hi:
                for link, (lt, states) in bus_lanes(
                    out, (lo - first, hi - first), self.compass_address
                ).items():
                    if len(lt):
                        tick = first + np.clip(np.searchsorted(t, lt, side="right"), 1, n)
                        _send(
                            rec,
                            paths.bus_lane(link),
                            [_time(lt), _seq(paths.TICK, tick)],
                            rr.StateChange.columns(state=states),
                        )
                        self.logged += len(states) // 2
        self.ticks += n

    def finish(self) -> int:
        """Write what waits; the number of bus transactions logged."""
        _flush(self.rec)
        return self.logged


def record(
    rec: rr.RecordingStream,
    out: dict[str, Any],
    truth_tilt_deg: NDArray[Any],
    window: tuple[int, int] | None,
    compass_address: int,
) -> int:
    """Log a whole run of the board (``sins_fw.gfsins.run``'s output; the trace's tilt at each
    tick; the profile's ``compass.address``) into ``rec``; returns the number of bus transactions
    logged."""
    recorder = Recorder(rec, window, compass_address)
    recorder.add(out, truth_tilt_deg)
    return recorder.finish()
