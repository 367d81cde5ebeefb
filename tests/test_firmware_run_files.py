"""`replay` and `report` of a C firmware's run output (`sins-fw run TRACE --firmware FW.so --out RUN`,
issue 37 item 3): the file is shown as recorded, read a block at a time, never re-emulated. The Rerun
recording is read back with Rerun's own dataframe query and compared with the file's columns; the
attitude error it holds with the one `run --firmware` computed while running (the same truth, the same
alignment: equal to the last bit)."""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import rerun as rr

from conftest import ROOT
from sins_fw import quaternion, run_output
from sins_fw.cli import main
from sins_fw.firmware_build import build_firmware
from sins_fw.firmware_run import load_globals
from sins_fw.run_output import FirmwareRunFile, load_run, recorded_profile
from sins_fw.viewer import paths
from test_viewer import assert_same_but_the_documented

REFERENCE = ROOT / "firmware_c" / "examples" / "reference"
TIMER0 = ROOT / "firmware_c" / "examples" / "timer0_burst"
PITCH_SWEEP = ROOT / "python" / "sins_fw" / "bundled_traces" / "pitch_sweep.h5"
#: The sweep is still for its first 6.03 s: 8 s hold 2 s of pitching.
UNTIL_S = "8"
#: The reference firmware's profile (tests/test_reference_chain.py): the published q̇2 row, and the
#: device's timing rules reported, not enforced: the C's frames come about 1 µs apart, under the
#: ADIS16407's burst stall, so every burst is a `stall_too_short` error event (the run exits 1,
#: its file written) while the words stay right.
REFERENCE_SET = ["--set", "firmware.quat_derivative=published", "--set", "device.timing_mode=lenient"]


def _ran(rc: int, stdout: str) -> dict:
    """The summary of a `run --firmware --json` that ran to the end (exit 1: only the stall errors)."""
    summary = json.loads(stdout)
    assert rc == 0 or (rc == 1 and set(summary["events"]["by_kind"]) == {"stall_too_short"}), summary
    return summary


pytestmark = [pytest.mark.usefixtures("cabi_library"), pytest.mark.filterwarnings("error")]


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_firmware([REFERENCE], tmp_path_factory.mktemp("ref") / "reference.so")


@pytest.fixture(scope="module")
def timer0(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return build_firmware([TIMER0], tmp_path_factory.mktemp("t0") / "timer0_burst.so")


def _run(fw: Path, globals_file: Path, trace: Path, out: Path, capsys: pytest.CaptureFixture[str]) -> dict:
    argv = ["run", str(trace), "--firmware", str(fw), "--globals", str(globals_file), "--until-s", UNTIL_S]
    rc = main([*argv, *REFERENCE_SET, "--out", str(out), "--json"])
    return _ran(rc, capsys.readouterr().out)


@pytest.fixture(scope="module")
def reference_run(reference: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict]:
    """The reference C firmware on 8 s of the pitch sweep, its output as HDF5, and its summary."""
    out = tmp_path_factory.mktemp("run") / "run.h5"
    argv = [
        "run",
        str(PITCH_SWEEP),
        "--firmware",
        str(reference),
        "--globals",
        str(REFERENCE / "globals.toml"),
    ]
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        rc = main([*argv, *REFERENCE_SET, "--until-s", UNTIL_S, "--out", str(out), "--json"])
    return out, _ran(rc, buf.getvalue())


def _store(path: Path):
    return rr.chunk.RrdReader(path).stream().collect()


def _scalars(store, entity: str, index: str = paths.TICK) -> tuple[np.ndarray, np.ndarray]:
    """(index values, scalars) of an entity's rows (one series: one value a row)."""
    table = store.reader(index=index, contents=entity).to_arrow_table()
    col = table.column(f"/{entity}:Scalars:scalars").to_pylist()
    keep = np.array([x is not None for x in col])
    idx = table.column(index).to_numpy()[keep]
    return idx, np.array([x[0] for x in col if x is not None], dtype=np.float64)


def _entities(store) -> set[str]:
    """The recording's entity paths, each with its leading ``/``."""
    return {"/" + str(p).lstrip("/") for p in store.schema().entity_paths()}


@pytest.mark.parametrize("block_rows", [run_output.FIRMWARE_BLOCK_ROWS, 97])
def test_replay_of_a_firmware_run_shows_its_globals_attitude_and_error_as_recorded(
    reference_run: tuple[Path, dict],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    block_rows: int,
):
    run, summary = reference_run
    # Read in blocks (97 rows: many blocks, each with its own piece of the trace's truth).
    monkeypatch.setattr(run_output, "FIRMWARE_BLOCK_ROWS", block_rows)
    meta, cols = load_run(run)
    assert meta["float_mode"] == "host", "the float mode the firmware was built with is recorded"
    rrd = tmp_path / "r.rrd"
    assert main(["replay", str(run), "--out", str(rrd), "--json"]) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert captured.err == ""
    assert report["re_emulated"] is False and report["truth"] is True and report["attitude"] is True
    assert report["rows"] == len(cols["t_s"]) == summary["cycles"] > 1000
    store = _store(rrd)
    entities = _entities(store)
    # Every watched global is a series of its own, with the file's values, at the file's times.
    names = [n for n in cols if n != "t_s"]
    assert {f"/{paths.firmware_global(n)}" for n in names} <= entities
    for n in names:
        _, values = _scalars(store, paths.firmware_global(n))
        assert np.array_equal(values, cols[n].astype(np.float64)), n
    ticks, _ = _scalars(store, paths.firmware_global("q0"))
    times, _ = _scalars(store, paths.firmware_global("q0"), index=paths.TIME)
    t_ns = times.astype("timedelta64[ns]").astype(np.int64)
    assert np.array_equal(t_ns, np.rint(cols["t_s"] * 1e12).astype(np.int64) // 1000)
    # The tick numbers are the times over the tick period (the file's `sample_rate_hz`: 4 ms).
    rate = float(meta["sample_rate_hz"])
    assert np.array_equal(ticks.astype(np.int64), np.rint(cols["t_s"] * rate).astype(np.int64))
    # The model run's Attitude tab: the board, the Euler angles of the firmware's quaternion, the
    # truth and the errors.
    for e in (
        paths.BOARD,
        paths.TRUTH,
        "attitude/roll/estimate",
        "attitude/pitch/truth",
        "attitude_error/total",
    ):
        assert f"/{e}" in entities, e
    q = np.stack([cols[f"q{i}"] for i in range(4)], axis=1)
    _, pitch = _scalars(store, "attitude/pitch/estimate")
    assert np.array_equal(pitch, quaternion.to_euler_deg(q)[:, 1])
    # The error against the recorded trace's truth is the one `run --firmware` computed as it ran.
    _, total = _scalars(store, "attitude_error/total")
    a = summary["attitude_error"]
    assert len(total) == a["steps_with_truth"]
    assert float(np.abs(total).max()) == a["euler"]["total"]["max_abs_deg"]
    assert float(total[-1]) == a["euler"]["total"]["final_deg"]
    # No sensor reads or budget in the file: nothing made up for them.
    assert not any(e.startswith(("/imu", "/registers", "/budget", "/bus")) for e in entities)
    # The layout: the model run's Attitude tab, then the Globals tab.
    assert rr.chunk.RrdReader(rrd).blueprints()


def test_the_same_firmware_run_file_gives_the_same_recording(
    reference_run: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    run, _ = reference_run
    outs = [tmp_path / "a.rrd", tmp_path / "b.rrd"]
    for out in outs:
        assert main(["replay", str(run), "--out", str(out)]) == 0
    assert "shown as recorded" in capsys.readouterr().out
    assert_same_but_the_documented(*outs)


def test_report_of_a_firmware_run_draws_the_attitude_error_and_the_metadata(
    reference_run: tuple[Path, dict], tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    from sins_fw.report_firmware import FirmwarePage, firmware_report_figure

    run, summary = reference_run
    png = tmp_path / "p.png"
    assert main(["report", str(run), "--out", str(png), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert report["truth"] is True and report["float_mode"] == "host" and report["re_emulated"] is False
    # The page's panels, as the CLI draws them.
    rf = FirmwareRunFile(run)
    trace, note = rf.truth()
    assert note is None
    page = FirmwarePage(rf, recorded_profile(run, rf.metadata), trace=rf.trace_path)
    for part in rf.parts(trace):
        page.add(part)
    _, axes = firmware_report_figure(page, title=run.name)
    assert set(axes.panels) == {"attitude", "error"}
    lines = {ln.get_label(): ln for ln in axes.panels["error"].get_lines()}
    total = lines["total (rotation angle)"].get_ydata()
    assert float(np.max(total)) == summary["attitude_error"]["euler"]["total"]["max_abs_deg"]
    pitch = {ln.get_label(): ln for ln in axes.panels["attitude"].get_lines()}["pitch"].get_ydata()
    meta, cols = load_run(run)
    q = np.stack([cols[f"q{i}"] for i in range(4)], axis=1)
    assert np.array_equal(pitch, quaternion.to_euler_deg(q)[:, 1])
    text = axes.metadata.texts[0].get_text()
    assert meta["firmware"] in text and "float mode: host" in text and "pitch_sweep.h5" in text
    assert "not re-emulated" in text


def test_a_firmware_run_without_attitude_columns_shows_its_globals(
    timer0: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    out = tmp_path / "run.csv"
    _run(timer0, TIMER0 / "globals.toml", PITCH_SWEEP, out, capsys)
    _, cols = load_run(out)
    names = [n for n in cols if n != "t_s"]
    rrd, png = tmp_path / "r.rrd", tmp_path / "p.png"
    assert main(["replay", str(out), "--out", str(rrd), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["attitude"] is False and report["truth"] is False and report["trace_missing"] is None
    store = _store(rrd)
    entities = _entities(store)
    assert {f"/{paths.firmware_global(n)}" for n in names} <= entities
    assert not any(e.startswith(("/world", "/attitude")) for e in entities), "no attitude made up"
    for n in names:
        assert np.array_equal(_scalars(store, paths.firmware_global(n))[1], cols[n].astype(np.float64)), n
    # The series are named by their column and unit (a CSV file: the units of the recorded globals file).
    units = FirmwareRunFile(out).units
    assert units == {g.column: g.unit for g in load_globals(TIMER0 / "globals.toml")}
    assert units["rate_x_dps"] == "°/s"
    assert main(["report", str(out), "--out", str(png)]) == 0
    assert "shown as recorded" in capsys.readouterr().out
    assert png.stat().st_size > 0
    from sins_fw.profile import load_profile
    from sins_fw.report_firmware import MAX_GLOBAL_PANELS, FirmwarePage, firmware_report_figure

    rf = FirmwareRunFile(out)
    page = FirmwarePage(rf, load_profile("reference"))
    for part in rf.parts(None):
        page.add(part)
    _, axes = firmware_report_figure(page)
    assert list(axes.panels) == names[:MAX_GLOBAL_PANELS]
    first = axes.panels[names[0]].get_lines()[0]
    assert np.array_equal(first.get_ydata(), cols[names[0]].astype(np.float64))
    if len(names) > MAX_GLOBAL_PANELS:
        assert ", ".join(names[MAX_GLOBAL_PANELS:]) in axes.metadata.texts[0].get_text()


def test_a_firmware_run_whose_trace_is_gone_is_shown_without_truth(
    reference: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    trace = tmp_path / "sweep.h5"
    shutil.copy(PITCH_SWEEP, trace)
    out = tmp_path / "out" / "run.h5"
    _run(reference, REFERENCE / "globals.toml", trace, out, capsys)
    trace.unlink()
    rrd, png = tmp_path / "r.rrd", tmp_path / "p.png"
    assert main(["replay", str(out), "--out", str(rrd)]) == 0
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1, err
    assert "cannot find its trace" in err and "recorded without the truth" in err
    entities = _entities(_store(rrd))
    assert "/world/board" in entities and "/attitude/roll/estimate" in entities
    assert not any(
        e.startswith(("/world/truth", "/attitude_error")) or e.endswith("/truth") for e in entities
    )
    assert main(["report", str(out), "--out", str(png), "--json"]) == 0
    captured = capsys.readouterr()
    report = json.loads(captured.out)
    assert report["truth"] is False and "cannot find its trace" in report["trace_missing"]
    assert "drawn without the truth" in captured.err and png.is_file()


def test_parity_of_a_firmware_run_is_refused(reference_run: tuple[Path, dict], tmp_path: Path, capsys):
    run, _ = reference_run
    out = tmp_path / "r.rrd"
    assert main(["replay", str(run), "--out", str(out), "--parity", "f64"]) == 2
    assert "shown as recorded" in capsys.readouterr().err
    assert not out.exists()


def test_a_firmware_run_with_euler_angles_only_is_posed_from_them(tmp_path: Path, capsys):
    """A firmware whose globals give roll_deg/pitch_deg/yaw_deg and no quaternion: the board is posed
    at q = from_euler(the columns), its Euler plots are the columns themselves, and its error is
    against the trace's truth (here the static trace: a firmware holding the truth's own angles has
    no error beyond the angles' float64 round trip)."""
    from fractions import Fraction

    from sins_fw.profile import load_profile
    from sins_fw.run_output import FIRMWARE_CREATED_BY, _run_metadata, firmware_run_schema, trace_reference
    from sins_fw.tablefile import write_table
    from sins_fw.traces import PhysicalTrace

    static = ROOT / "traces" / "static_60s.h5"
    truth = PhysicalTrace.load(static)
    out = tmp_path / "euler.csv"
    t = np.arange(1, 1001) * 0.004
    # The truth at the rows' times (the static board: one attitude throughout).
    euler = np.repeat(quaternion.to_euler_deg(truth.truth_q[:1]), len(t), axis=0)
    cols = {"t_s": t, "roll_deg": euler[:, 0], "pitch_deg": euler[:, 1], "yaw_deg": euler[:, 2], "n": t * 250}
    schema = firmware_run_schema(
        [("roll_deg", "°", ""), ("pitch_deg", "°", ""), ("yaw_deg", "°", ""), ("n", "1", "")]
    )
    extra = {**trace_reference(static, out), "created_by": FIRMWARE_CREATED_BY, "firmware": "fw.so"}
    write_table(out, schema, _run_metadata(load_profile("reference"), Fraction(1, 250), 0.0, extra), cols)
    rrd = tmp_path / "r.rrd"
    assert main(["replay", str(out), "--out", str(rrd), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["attitude"] is True and report["truth"] is True and report["float_mode"] is None
    store = _store(rrd)
    _, roll = _scalars(store, "attitude/roll/estimate")
    assert np.array_equal(roll, cols["roll_deg"])
    table = store.reader(index=paths.TICK, contents=paths.BOARD).to_arrow_table()
    q_xyzw = np.array(table.column(f"/{paths.BOARD}:Transform3D:quaternion").to_pylist(), dtype=np.float64)
    q = quaternion.from_euler(*np.radians(euler).T)
    assert np.allclose(q_xyzw, q[:, [1, 2, 3, 0]], rtol=0, atol=1e-7)  # stored as float32 by Rerun
    _, total = _scalars(store, "attitude_error/total")
    # to_euler then from_euler in float64: a few ulps of each angle, ~1e-14 rad (6e-13°); the error
    # angle is 2·atan2(|v|, |w|), well conditioned there. 1e-10° leaves two orders of magnitude.
    assert len(total) == len(t) and float(np.max(total)) < 1e-10
    png = tmp_path / "p.png"
    assert main(["report", str(out), "--out", str(png)]) == 0
    assert png.is_file()


def test_a_damaged_firmware_run_file_is_exit_2_naming_the_line_and_writes_nothing(
    timer0: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
):
    out = tmp_path / "run.csv"
    _run(timer0, TIMER0 / "globals.toml", PITCH_SWEEP, out, capsys)
    lines = out.read_text().splitlines(keepends=True)
    row = next(i for i, line in enumerate(lines) if line[:1].isdigit()) + 500
    cells = lines[row].split(",")
    cells[1] = "oops"
    lines[row] = ",".join(cells)
    out.write_text("".join(lines))
    for command, made in (("replay", tmp_path / "r.rrd"), ("report", tmp_path / "r.png")):
        made.write_bytes(b"an old file")
        assert main([command, str(out), "--out", str(made)]) == 2
        err = capsys.readouterr().err
        assert str(out) in err and f"line {row + 1}" in err, err
        assert "Traceback" not in err
        assert made.read_bytes() == b"an old file", "a previous output is left as it was"
