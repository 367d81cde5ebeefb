"""Visual replay: the Rerun recording (read back with Rerun's own dataframe query), the bus window of
the harness, the replay CLI, and the static PNG report."""

from __future__ import annotations

import re
import struct
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

# Rerun's dataframe query (`ChunkStore.reader`) runs on DataFusion, pinned in requirements.txt.
import rerun as rr

from conftest import ROOT, run_cli
from sins_fw import _core, synth
from sins_fw.harness import emulate
from sins_fw.metrics import attitude_errors, wrap_deg
from sins_fw.traces import PhysicalTrace
from sins_fw.viewer import paths
from sins_fw.viewer.recording import save_recording

STATIC = ROOT / "traces" / "static_60s.h5"
#: Every recording is read with warnings as errors: Rerun warns about a file it reads in a legacy
#: way (one without a footer: issue 42, item 8).
pytestmark = pytest.mark.filterwarnings("error")
WINDOW = (100, 103)
#: Frames per burst read on the reference board (the command and 14 output registers).
BURST_FRAMES = _core.READ_WORDS


@pytest.fixture(scope="module")
def trace() -> PhysicalTrace:
    return PhysicalTrace.load(STATIC)


@pytest.fixture(scope="module")
def run(trace):
    return emulate(trace, bus_window=WINDOW)


@pytest.fixture(scope="module")
def parity_run(trace):
    return emulate(trace, overrides=["firmware.numeric=f64"])


@pytest.fixture(scope="module")
def store(run, trace, parity_run, tmp_path_factory):
    path = tmp_path_factory.mktemp("rrd") / "static.rrd"
    save_recording(run, path, trace=trace, parity={"f64": parity_run}, name="static_60s.h5")
    reader = rr.chunk.RrdReader(path)
    assert reader.blueprints(), "the default layout is saved with the recording"
    # Rerun's current reader: the footer's manifest, chunks loaded on demand (it refuses, with a
    # warning, a file without a footer).
    lazy = reader.store()
    assert len(lazy) == len(list(reader.stream()))
    return reader.stream().collect()


def query(store, index: str, entity: str):
    """Rows of one entity on one timeline, as a pyarrow table (Rerun's dataframe query)."""
    return store.reader(index=index, contents=entity).to_arrow_table()


def column(table, entity: str, component: str = "Scalars:scalars") -> np.ndarray:
    return np.array(table.column(f"{entity}:{component}").to_pylist(), dtype=object)


def scalars(table, entity: str) -> np.ndarray:
    return np.array([np.asarray(x, dtype=np.float64) for x in column(table, entity)])


# --- the harness's bus window ------------------------------------------------------------------


def test_bus_window_holds_exactly_the_window_ticks_and_their_words(run):
    bus = run.bus
    ticks = WINDOW[1] - WINDOW[0] + 1
    assert len(bus["frame_index"]) == ticks * BURST_FRAMES
    assert len(bus["cs_t_ps"]) == 2 * ticks
    assert bus["cs_low"].tolist() == [True, False] * ticks
    sel = (run.read_tick >= WINDOW[0]) & (run.read_tick <= WINDOW[1])
    # The words the firmware stored are the words the master received on the bus.
    assert np.array_equal(run.read_words[sel].ravel(), bus["frame_master_rx"])
    assert np.array_equal(bus["frame_din"][::BURST_FRAMES], np.full(ticks, 0x4200))
    # Every frame lies inside the ISR of its tick.
    b = run.budget
    in_window = (b["tick"] >= WINDOW[0]) & (b["tick"] <= WINDOW[1])
    start, end = b["start_ps"][in_window], b["end_ps"][in_window]
    per_tick = bus["frame_start_ps"].reshape(ticks, BURST_FRAMES)
    assert np.all(per_tick >= start[:, None]) and np.all(per_tick <= end[:, None])


def test_bus_window_with_a_sink_is_the_same_window(trace, run):
    """The window is noted from the output as it streams past, so a sink does not lose it."""
    parts: list[dict] = []
    streamed = emulate(trace, bus_window=WINDOW, sink=parts.append)
    assert streamed.bus.keys() == run.bus.keys()
    for k, v in run.bus.items():
        assert np.array_equal(streamed.bus[k], v), k
    assert sum(len(p["budget_tick"]) for p in parts) == len(run.budget["tick"])


def test_bus_window_outside_the_run_is_an_input_error(trace):
    from sins_fw.errors import InputError

    with pytest.raises(InputError, match="bus window"):
        emulate(trace, bus_window=(10**7, 10**7 + 1))
    with pytest.raises(InputError, match="first_tick"):
        emulate(trace, bus_window=(5, 4))


# --- the recording, read back with Rerun's own API --------------------------------------------


def test_recording_has_the_documented_entities(store):
    entities = set(store.schema().entity_paths())
    expected = {
        paths.BOARD,
        paths.BOARD_BODY,
        paths.BOARD_AXES,
        paths.BOARD_ADIS,
        paths.TRUTH,
        paths.TRUTH_BODY,
        *(paths.attitude(a, w) for a in paths.ANGLES for w in ("estimate", "truth")),
        *(paths.attitude_error(a) for a in (*paths.ANGLES, "total")),
        paths.RATE_DECODED,
        paths.RATE_PHYSICAL,
        paths.ACCEL_DECODED,
        paths.ACCEL_PHYSICAL,
        paths.SAMPLE_AGE,
        paths.REGISTER_WORDS,
        paths.REGISTER_ND,
        paths.REGISTER_EA,
        paths.BUDGET_BUSY,
        paths.BUDGET_FINISH,
        paths.BUDGET_DEADLINE,
        paths.BUDGET_MARGIN,
        paths.BUS_CS,
        paths.BUS_SCLK,
        paths.BUS_FRAMES,
        paths.BUS_STALL,
        paths.BUS_STALL_MIN,
        paths.parity("f64", "euler"),
        paths.parity("f64", "angle"),
    }
    assert {"/" + e for e in expected} <= entities, sorted({"/" + e for e in expected} - entities)
    assert "/" + paths.EVENTS not in entities, "a clean run has no events entity"
    assert {c.name for c in store.schema().index_columns()} >= {
        paths.TIME,
        paths.CYCLE,
        paths.TICK,
        paths.FRAME,
    }


def test_cycle_rows_match_the_run(store, run):
    t = query(store, paths.CYCLE, paths.attitude("roll", "estimate"))
    assert t.num_rows == run.cycles
    assert np.array_equal(t.column(paths.CYCLE).to_numpy(), run.step.astype(np.int64))
    for k, angle in enumerate(paths.ANGLES):
        t = query(store, paths.CYCLE, paths.attitude(angle, "estimate"))
        assert np.array_equal(scalars(t, "/" + paths.attitude(angle, "estimate"))[:, 0], run.euler_deg[:, k])
    # Emulated time is the cycle's tick time in ns; the tick index lines the cycle up with the budget.
    t = query(store, paths.CYCLE, paths.BOARD)
    ns = t.column(paths.TIME).cast("int64").to_numpy()
    assert np.array_equal(ns, np.round(run.time_s * 1e9).astype(np.int64))
    ticks = t.column(paths.TICK).to_numpy()
    assert np.array_equal(ticks * 4_000_000, ns), "reference timer: 4 ms ticks"
    quat = np.array(t.column(f"/{paths.BOARD}:Transform3D:quaternion").to_pylist())
    assert np.allclose(quat.reshape(-1, 4), run.quat[:, [1, 2, 3, 0]].astype(np.float32), rtol=0, atol=0)


def test_truth_and_errors_match_the_run(store, run):
    err = attitude_errors(run.quat, run.truth_q)
    t = query(store, paths.CYCLE, paths.attitude_error("total"))
    assert t.num_rows == run.cycles, "the static trace has truth at every cycle"
    assert np.array_equal(scalars(t, "/" + paths.attitude_error("total"))[:, 0], err.total)
    t = query(store, paths.CYCLE, paths.attitude_error("pitch"))
    assert np.array_equal(scalars(t, "/" + paths.attitude_error("pitch"))[:, 0], err.pitch)


def test_read_rows_match_the_run(store, run, trace):
    t = query(store, paths.TICK, paths.REGISTER_WORDS)
    assert t.num_rows == len(run.read_tick)
    assert np.array_equal(t.column(paths.TICK).to_numpy(), run.read_tick.astype(np.int64))
    words = scalars(t, "/" + paths.REGISTER_WORDS)
    assert words.shape == (len(run.read_tick), 14)
    assert np.array_equal(words, run.read_words[:, 1:])
    nd = scalars(query(store, paths.TICK, paths.REGISTER_ND), "/" + paths.REGISTER_ND)
    assert np.array_equal(nd, run.read_words[:, 1:] >> 15)
    rate = scalars(query(store, paths.TICK, paths.RATE_DECODED), "/" + paths.RATE_DECODED)
    assert np.allclose(rate, np.degrees(run.read_rate), rtol=1e-15, atol=0)
    # The static board: the physical input is earth rate, constant; the decoded rate is within one
    # gyro LSB (0.05 °/s) of it.
    phys = scalars(query(store, paths.TICK, paths.RATE_PHYSICAL), "/" + paths.RATE_PHYSICAL)
    assert np.allclose(phys, trace.gyro_dps[0], atol=1e-12)
    assert np.max(np.abs(rate - phys)) <= 0.05
    age = scalars(query(store, paths.TICK, paths.SAMPLE_AGE), "/" + paths.SAMPLE_AGE)[:, 0]
    assert np.array_equal(age, run.read_age_ps * 1e-6)


def test_budget_rows_match_the_run(store, run):
    t = query(store, paths.TICK, paths.BUDGET_BUSY)
    assert t.num_rows == int(run.isr_ran.sum()) == len(run.budget["tick"])
    busy = scalars(t, "/" + paths.BUDGET_BUSY)[:, 0]
    assert np.allclose(busy, run.busy_s * 1e6, rtol=1e-12, atol=0)
    margin = scalars(query(store, paths.TICK, paths.BUDGET_MARGIN), "/" + paths.BUDGET_MARGIN)[:, 0]
    assert np.allclose(margin, run.margin_s * 1e6, rtol=1e-12, atol=0)


def test_bus_rows_match_the_bus_log(store, run):
    bus = run.bus
    frames = query(store, paths.FRAME, paths.BUS_FRAMES)
    assert frames.num_rows == len(bus["frame_index"])
    assert np.array_equal(frames.column(paths.FRAME).to_numpy(), bus["frame_index"].astype(np.int64))
    text = [x[0] for x in frames.column(f"/{paths.BUS_FRAMES}:TextLog:text").to_pylist()]
    for line, din, dout in zip(text, bus["frame_din"], bus["frame_dout"], strict=True):
        assert f"DIN 0x{din:04X}" in line and f"DOUT 0x{dout:04X}" in line
    sclk = query(store, paths.TIME, paths.BUS_SCLK)
    assert sclk.num_rows == 2 * len(bus["frame_index"]), "a state at each frame's first and last edge"
    cs = query(store, paths.TIME, paths.BUS_CS)
    states = [x[0] for x in cs.column(f"/{paths.BUS_CS}:StateChange:state").to_pylist()]
    assert states == ["CS low (selected)", "CS high"] * (WINDOW[1] - WINDOW[0] + 1)
    # Stalls: previous frame's last SCLK edge to this frame's first edge (the first frame of the log
    # has none), against one SCLK period inside a burst and t_stall (9 µs) before a command frame.
    stall = query(store, paths.FRAME, paths.BUS_STALL)
    got = scalars(stall, "/" + paths.BUS_STALL)[:, 0]
    first = bus["frame_first_edge_ps"].astype(np.float64)
    last = bus["frame_last_edge_ps"].astype(np.float64)
    assert np.array_equal(got, (first[1:] - last[:-1]) * 1e-6)
    required = scalars(query(store, paths.FRAME, paths.BUS_STALL_MIN), "/" + paths.BUS_STALL_MIN)[:, 0]
    command = bus["frame_din"][1:] == 0x4200
    assert np.all(required[command] == 9.0)
    assert np.array_equal(required[~command], bus["frame_sclk_period_ps"][1:][~command] * 1e-6)
    assert np.all(got >= required), "the reference firmware keeps both stall rules (no stall_too_short)"


def test_parity_rows_are_the_backend_differences(store, run, parity_run):
    t = query(store, paths.CYCLE, paths.parity("f64", "euler"))
    assert t.num_rows == run.cycles == parity_run.cycles
    diff = scalars(t, "/" + paths.parity("f64", "euler"))
    assert np.array_equal(diff, wrap_deg(parity_run.euler_deg - run.euler_deg))
    assert np.any(diff != 0), "f32 and f64 differ somewhere"


# --- the replay command -------------------------------------------------------------------------


@pytest.fixture(scope="module")
def short_trace(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("trace") / "static_2s.h5"
    synth.generate("static", duration_s=2.0).save(path)
    return path


def test_replay_with_overruns_logs_them_at_their_ticks_and_cycles(short_trace, tmp_path):
    out = tmp_path / "over.rrd"
    r = run_cli(
        "replay", str(short_trace), "--set", "timer.period_us=300", "--out", str(out), "--bus-ticks", "none"
    )
    assert r.code == 1 and "overrun" in r.err, r.err  # written, then the failed check
    assert not out.with_name(out.name + ".tmp").exists() and not list(tmp_path.glob(".over.rrd.*"))
    run = emulate(short_trace, overrides=["timer.period_us=300"])
    store = rr.chunk.RrdReader(out).stream().collect()
    t = query(store, paths.EVENT, paths.EVENTS)
    text = [x[0] for x in t.column(f"/{paths.EVENTS}:TextLog:text").to_pylist()]
    level = [x[0] for x in t.column(f"/{paths.EVENTS}:TextLog:level").to_pylist()]
    assert len(text) == len(run.events)
    overruns = [i for i, s in enumerate(text) if s.startswith("[overrun] ")]
    assert len(overruns) == run.events_by_kind()["overrun"] > 100
    ticks = t.column(paths.TICK).to_numpy()
    ns = t.column(paths.TIME).cast("int64").to_numpy()
    cycles = t.column(paths.CYCLE).to_numpy()
    step_ns = np.round(run.time_s * 1e9).astype(np.int64)
    for i in overruns:
        k = int(re.match(r"\[overrun\] tick (\d+):", text[i]).group(1))
        assert ticks[i] == k, text[i]
        assert ns[i] == k * 300_000, "the overrun is stamped at its tick (300 µs period)"
        assert level[i] == "ERROR"
        # The cycle under way: the first attitude step computed at or after the event.
        j = np.searchsorted(step_ns, ns[i])
        assert cycles[i] == (run.step[j] if j < run.cycles else run.step[-1] + 1)
    # The budget view has one row per ISR that ran, and the late ones end past their deadline.
    busy = query(store, paths.TICK, paths.BUDGET_MARGIN)
    assert busy.num_rows == int(run.isr_ran.sum()) < len(run.budget["tick"])
    assert np.any(scalars(busy, "/" + paths.BUDGET_MARGIN)[:, 0] < 0)


def test_replay_spawn_without_a_display_fails_cleanly(short_trace, tmp_path, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    r = run_cli("replay", str(short_trace), "--spawn")
    assert r.code == 2
    assert "cannot open the Rerun viewer" in r.err and "--out" in r.err and "Traceback" not in r.err
    out = tmp_path / "kept.rrd"
    r = run_cli("replay", str(short_trace), "--spawn", "--out", str(out))
    assert r.code == 2 and "was saved to" in r.err
    assert out.stat().st_size > 0


def test_replay_usage_errors(short_trace, tmp_path):
    r = run_cli("replay", str(short_trace))
    assert r.code == 2 and "--out" in r.err
    r = run_cli("replay", str(short_trace), "--out", str(tmp_path / "x.txt"))
    assert r.code == 2 and ".rrd" in r.err
    r = run_cli("replay", str(short_trace), "--out", str(tmp_path / "x.rrd"), "--bus-ticks", "9:3")
    assert r.code == 2 and "FIRST <= LAST" in r.err
    assert not (tmp_path / "x.rrd").exists()


# --- the static report --------------------------------------------------------------------------


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_report_png_is_drawn_from_the_run(run, tmp_path):
    from sins_fw.report_page import DPI, FIGSIZE, save_report

    out, axes = save_report(run, tmp_path / "r.png", title="static")
    assert png_size(out) == (round(FIGSIZE[0] * DPI), round(FIGSIZE[1] * DPI))
    lines = {ln.get_label(): ln for ln in axes.attitude.get_lines()}
    err = attitude_errors(run.quat, run.truth_q)
    assert np.array_equal(lines["total (rotation angle)"].get_xdata(), run.time_s)
    assert np.array_equal(lines["total (rotation angle)"].get_ydata(), err.total)
    assert np.array_equal(lines["yaw error"].get_ydata(), err.yaw)
    budget = {ln.get_label(): ln for ln in axes.budget.get_lines()}
    assert np.allclose(budget["ISR busy"].get_ydata(), run.busy_s * 1e6, rtol=1e-12, atol=0)
    assert axes.events.texts[0].get_text() == "no events"


def test_report_cli_writes_a_png(short_trace, tmp_path):
    out = tmp_path / "static.png"
    r = run_cli("report", str(short_trace), "--out", str(out), "--set", "timer.period_us=300", "--json")
    assert r.code == 1, r.err  # the page is drawn, then the overruns fail the check
    assert png_size(out) == (1100, 850)
    assert '"overrun"' in r.out


def rrd_messages(path: Path) -> tuple[list[tuple[int, bytes]], bytes]:
    """The messages of an .rrd file in Rerun's framing (a 12-byte header: ``RRF2``, the version,
    the options; then per message a little-endian u64 kind and u64 length and the payload, the
    last one the footer) and the 32 bytes after them (the footer's place, length and checksum)."""
    data = path.read_bytes()
    assert data[:4] == b"RRF2" and data[-12:-4] == b"RRF2FOOT"
    at, messages = 12, []
    while at < len(data) - 32:
        kind, n = struct.unpack_from("<QQ", data, at)
        messages.append((kind, data[at + 16 : at + 16 + n]))
        at += 16 + n
    assert at == len(data) - 32
    return messages, data[at:]


SET_STORE_INFO, ARROW_MSG, FOOTER = 1, 2, 0


def chunk_content(chunk) -> tuple[str, pa.Table]:
    """A chunk without what Rerun makes per save (its row ids, chunk id, wall-clock `log_time`)."""
    batch = chunk.to_record_batch()
    keep = [
        f.name
        for f in batch.schema
        if f.name != "log_time" and (f.metadata or {}).get(b"rerun:kind") != b"control"
    ]
    return chunk.entity_path, pa.Table.from_batches([batch]).select(keep).replace_schema_metadata(None)


def by_store(messages: list[tuple[int, bytes]], layout: bytes) -> list[tuple[int, bytes]]:
    """The messages of the recording's store in their order, then the layout's, then the footer."""
    footer = [(k, x) for k, x in messages if k == FOOTER]
    rest = [(k, x) for k, x in messages if k != FOOTER]
    return [m for m in rest if layout not in m[1][:120]] + [m for m in rest if layout in m[1][:120]] + footer


def assert_same_but_the_documented(a: Path, b: Path) -> None:
    """Issue 42, item 8: the bytes of two saves of the same input differ only where
    docs/traces.md ("Determinism") says Rerun makes them differ: the 16-byte id of each store's
    SetStoreInfo message, the layout's (blueprint's) store id, row and chunk ids and `log_time`
    (made by the SDK's blueprint stream), and so the footer that lists them. Every message of the
    recording itself (its chunks with their row and chunk ids) is the same, byte for byte."""
    rid = rr.chunk.RrdReader(a).recordings()[0].recording_id
    assert rid == rr.chunk.RrdReader(b).recordings()[0].recording_id
    layouts = [rr.chunk.RrdReader(p).blueprints()[0].recording_id.encode() for p in (a, b)]
    assert layouts[0] != layouts[1], "Rerun draws the layout's store id: this test would be too weak"
    # The recording's messages and the layout's come from two of Rerun's streams into one file: each
    # store's messages keep their order, their interleaving does not (docs/traces.md). Compared store
    # by store.
    (ma, _), (mb, _) = rrd_messages(a), rrd_messages(b)
    ma, mb = by_store(ma, layouts[0]), by_store(mb, layouts[1])
    assert [k for k, _ in ma] == [k for k, _ in mb]
    same = 0
    for (kind, x), (_, y) in zip(ma, mb, strict=True):
        if kind == FOOTER:
            continue
        if kind == SET_STORE_INFO:
            # The message's own id (field 1: a TUID of two fixed64) comes first.
            assert x[:3] == y[:3] == b"\x0a\x12\x09" and x[11] == y[11] == 0x11
            x, y = x[:3] + x[20:], y[:3] + y[20:]
        if layouts[0] in x[:120]:
            assert layouts[1] in y[:120]
            x, y = x.replace(layouts[0], b""), y.replace(layouts[1], b"")
            if kind == ARROW_MSG:
                continue  # compared below, with the ids and `log_time` set aside
        assert x == y, f"message of kind {kind} differs"
        same += kind == ARROW_MSG
    assert same == len(list(rr.chunk.RrdReader(a).stream())), "every chunk of the recording compared"
    readers = [rr.chunk.RrdReader(p) for p in (a, b)]
    bps = [[chunk_content(c) for c in r.stream(store=r.blueprints()[0])] for r in readers]
    assert len(bps[0]) == len(bps[1]) > 0
    for (pa_, ta), (pb, tb) in zip(*bps, strict=True):
        assert pa_ == pb and ta.equals(tb), pa_
    for r in readers:  # both load with the footer (warnings are errors here)
        assert len(r.store()) == same


def test_the_same_run_saves_the_same_recording(run, trace, tmp_path):
    """Issue 24, item 12 and issue 42, item 8: the recording id is derived from the run, no start
    time is sent, and the row and chunk ids are derived from the recording id: the recording's
    bytes are the same on every save; what differs is what docs/traces.md ("Determinism") exempts
    and nothing else. Another run gets another id."""
    paths_ = [tmp_path / "a.rrd", tmp_path / "b.rrd"]
    for p in paths_:
        save_recording(run, p, trace=trace, name="static_60s.h5")
    assert_same_but_the_documented(*paths_)
    readers = [rr.chunk.RrdReader(p) for p in paths_]
    ids = [[e.recording_id for e in r.recordings()] for r in readers]
    assert ids[0] == ids[1] and len(ids[0]) == 1
    contents = [[c.format() for c in r.stream()] for r in readers]  # ids included, unredacted
    assert contents[0] and contents[0] == contents[1]
    # Another run (another profile override) gets another id, and other row ids.
    other = emulate(trace, until_s=2.0)
    save_recording(other, tmp_path / "c.rrd", name="static_60s.h5")
    c = rr.chunk.RrdReader(tmp_path / "c.rrd")
    assert [e.recording_id for e in c.recordings()] != ids[0]
    assert (
        next(iter(c.stream())).to_record_batch().column(0)[0]
        != next(iter(readers[0].stream())).to_record_batch().column(0)[0]
    )


def test_replay_of_the_bundled_trace_twice_differs_only_where_documented(tmp_path):
    """Issue 42, item 8: two `replay` runs of traces/static_60s.h5 gave files of different sizes
    (5 933 766 and 5 934 649 bytes) that Rerun's current reader refused (no footer)."""
    outs = [tmp_path / n / "r.rrd" for n in ("a", "b")]
    for out in outs:
        r = run_cli("replay", str(STATIC), "--out", str(out))
        assert r.code == 0, r.err
    assert_same_but_the_documented(*outs)


def test_long_recordings_gather_an_entitys_rows_into_few_chunks(tmp_path):
    """The footer's manifest grows with the number of chunks (≈ 3.5 kB each in the writer's memory
    until the end): an entity's rows are written in chunks of at least ENTITY_CHUNK_BYTES (its last
    one aside), not one chunk per part of the emulation's output (≈ 10 s of trace), and every row is
    still there."""
    from sins_fw.viewer import recording

    trace = tmp_path / "static_300s.h5"
    synth.generate("static", duration_s=300.0).save(trace)
    out = tmp_path / "long.rrd"
    r = run_cli("replay", str(trace), "--out", str(out), "--bus-ticks", "none")
    assert r.code == 0, r.err
    sizes: dict[str, list[int]] = {}
    rows: dict[str, int] = {}
    for chunk in rr.chunk.RrdReader(out).store().stream():
        if not chunk.is_static:
            sizes.setdefault(chunk.entity_path, []).append(chunk.to_record_batch().nbytes)
            rows[chunk.entity_path] = rows.get(chunk.entity_path, 0) + chunk.num_rows
    for entity, n in sizes.items():
        assert all(b >= recording.ENTITY_CHUNK_BYTES for b in n[:-1]), (entity, n)
    reads = sizes["/" + paths.RATE_DECODED]
    # 300 s of reads (one per 4 ms tick after the first: 74 999 rows) in a few chunks; one per part
    # would be 30.
    assert rows["/" + paths.RATE_DECODED] == 74999
    assert 2 <= len(reads) <= sum(reads) // recording.ENTITY_CHUNK_BYTES + 1, reads


# --- the streamed replay -------------------------------------------------------------------------


def recorded_rows(path: Path) -> dict[str, list[str]]:
    """Every row of every entity of a recording, on the emulated-time timeline, as text, sorted: what
    two recordings hold, however their chunks are cut (the static series styling aside)."""
    store = rr.chunk.RrdReader(path).stream().collect()
    out = {}
    for entity in store.schema().entity_paths():
        table = store.reader(index=paths.TIME, contents=entity).to_arrow_table()
        # The series' static styling is joined to some rows and not others, by how the chunks fall.
        columns = {n: table.column(n) for n in table.column_names if ":SeriesLines:" not in n}
        columns[paths.TIME] = columns[paths.TIME].cast("int64")
        rows = [repr(r) for r in zip(*(c.to_pylist() for c in columns.values()), strict=True)]
        out[entity] = sorted(rows)
    return out


@pytest.mark.parametrize("overrides", [[], ["timer.period_us=300"], ["firmware.algorithm=dcm"]])
def test_replay_streams_the_recording_a_whole_run_gives(short_trace, tmp_path, overrides):
    """Issue 24, item 11: `replay` logs each part of the output as the emulation streams it (the
    recording is written part by part, the run never held whole). What it records is what the whole
    Run's recording holds, row for row on every entity: the cycle rows, truth and errors, the reads
    with their physical input, the budget, the events (with overruns: stamped with their tick and
    the cycle under way, across parts), the bus window, the parity differences and the DCM's terms.
    The trace is cut into several parts (2 s at FEED_ROWS = 8 192 rows a piece; 300 µs ticks fill
    blocks sooner)."""
    sets = [x for o in overrides for x in ("--set", o)]
    out = tmp_path / "streamed.rrd"
    r = run_cli(
        "replay", str(short_trace), *sets, "--save", str(out), "--bus-ticks", "3:5", "--parity", "f64"
    )
    overruns = "timer.period_us=300" in overrides
    assert r.code == (1 if overruns else 0), r.err
    trace = PhysicalTrace.load(short_trace)
    whole = emulate(trace, overrides=overrides, bus_window=(3, 5))
    other = emulate(trace, overrides=[*overrides, "firmware.numeric=f64"])
    save_recording(whole, tmp_path / "whole.rrd", trace=trace, parity={"f64": other})
    got, expected = recorded_rows(out), recorded_rows(tmp_path / "whole.rrd")
    assert got.keys() == expected.keys()
    for entity in expected:
        assert got[entity] == expected[entity], entity
    if overruns:
        assert len(expected["/" + paths.EVENTS]) > 100
    assert ("/" + paths.DCM_ORTHOGONALITY in expected) == ("firmware.algorithm=dcm" in overrides)


def test_replay_twice_gives_the_same_recording(short_trace, tmp_path):
    """The streamed recording's id is derived from its inputs (the trace's bytes, the profile, the
    window, the backends): the same command twice gives the same id and the same rows; another
    profile override another id."""
    ids = []
    for name, extra in (("a", []), ("b", []), ("c", ["--set", "timer.period_us=4100"])):
        out = tmp_path / name / "r.rrd"
        r = run_cli("replay", str(short_trace), *extra, "--save", str(out))
        assert r.code == 0, r.err
        ids.append([e.recording_id for e in rr.chunk.RrdReader(out).recordings()])
    assert ids[0] == ids[1] and len(ids[0]) == 1 and ids[2] != ids[0]
    assert recorded_rows(tmp_path / "a" / "r.rrd") == recorded_rows(tmp_path / "b" / "r.rrd")


#: The DCM's series: entity, `Run.dcm` key, the recorded values from it (ω in °/s).
DCM_SERIES = [
    (paths.DCM_OMEGA_P, "omega_p", np.degrees),
    (paths.DCM_OMEGA_I, "omega_i", np.degrees),
    (paths.DCM_ERROR_RP, "error_rp", np.asarray),
    (paths.DCM_ERROR_YAW, "error_yaw", np.asarray),
    (paths.DCM_ORTHOGONALITY, "orthogonality", np.asarray),
]


def test_dcm_replay_records_the_correction_terms_and_a_dcm_tab(short_trace, tmp_path, store):
    """Issue 18, item 3: a DCM replay logs ω_P, ω_I (°/s), the roll–pitch and yaw errors and
    |R·Rᵀ − I| at their entities, one row per step on the cycle timeline with the step's time and
    tick, the values of `Run.dcm` (Scalars are float64: exact), and its layout has a DCM tab. The
    RK4 recording (`store`) has neither."""
    from sins_fw.viewer.layout import default_blueprint

    out = tmp_path / "dcm.rrd"
    r = run_cli(
        "replay",
        str(short_trace),
        "--set",
        "firmware.algorithm=dcm",
        "--out",
        str(out),
        "--bus-ticks",
        "none",
    )
    assert r.code == 0, r.err
    run = emulate(short_trace, overrides=["firmware.algorithm=dcm"])
    dcm_store = rr.chunk.RrdReader(out).stream().collect()
    for entity, key, recorded in DCM_SERIES:
        t = query(dcm_store, paths.CYCLE, entity)
        assert t.num_rows == run.cycles == len(run.dcm[key]), entity
        assert np.array_equal(t.column(paths.CYCLE).to_numpy(), run.step.astype(np.int64))
        ns = t.column(paths.TIME).cast("int64").to_numpy()
        assert np.array_equal(ns, np.round(run.time_s * 1e9).astype(np.int64))
        expected = recorded(run.dcm[key]).reshape(run.cycles, -1)
        assert np.array_equal(scalars(t, "/" + entity), expected), entity
    assert np.any(run.dcm["omega_p"] != 0), "not a series of zeros"
    # The layout the replay saved shows the DCM series (its views' origins), as default_blueprint lays
    # them out only when asked.
    reader = rr.chunk.RrdReader(out)
    layout = "\n".join(chunk.format() for chunk in reader.stream(store=reader.blueprints()[0]))
    assert all(entity in layout for entity, _, _ in DCM_SERIES)
    tabs = [c.name for c in default_blueprint(bus=False, dcm=True).root_container.contents]
    assert tabs == ["Attitude", "Sensor", "Budget", "DCM"]
    assert "DCM" not in [c.name for c in default_blueprint(bus=True).root_container.contents]
    assert not [e for e in store.schema().entity_paths() if e.startswith("/dcm")]
