"""Reading a user's own files (issue 27, item 1): units named in the header or by option, a column
map, the rate from the times (checked against a declared one), `;`-separated files, and warnings
for units that read but look wrong. Each test here failed before: such a file was refused (a unit
or a name it did not know, a missing rate, a `;` header) or read silently in the wrong unit."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from conftest import ROOT, run_cli
from sins_fw.errors import TraceError, TraceWarning
from sins_fw.traces import G0, PhysicalTrace, ReadOptions


def _motion(n: int = 600, rate: float = 100.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (s), body rates (°/s) and specific force (g) of a board turning about x at 30 °/s:
    gravity turns through 180° in the body over 6 s (the exact kinematics of a pure rotation)."""
    t = np.arange(n) / rate
    theta = np.radians(30.0) * t
    w = np.zeros((n, 3))
    w[:, 0] = 30.0
    f = np.stack([np.zeros(n), np.sin(theta), np.cos(theta)], axis=1)
    return t, w, f


def _csv(path: Path, header: list[str], cols: list[np.ndarray], meta: str = "", sep: str = ",") -> Path:
    rows = np.stack(cols, axis=1)
    lines = [sep.join(repr(float(x)) for x in row) for row in rows]
    path.write_text(meta + sep.join(header) + "\n" + "\n".join(lines) + "\n")
    return path


def _columns(t: np.ndarray, w: np.ndarray, f: np.ndarray) -> list[np.ndarray]:
    return [t, *w.T, *f.T]


def _load_quiet(path: Path, **kw) -> PhysicalTrace:
    with warnings.catch_warnings():
        warnings.simplefilter("error", TraceWarning)
        return PhysicalTrace.load(path, **kw)


def test_units_named_in_the_header_are_converted(tmp_path):
    t, w, f = _motion()
    header = ["t_ms", *(f"gyro_{a}_rad_s" for a in "xyz"), *(f"accel_{a}_m_s2" for a in "xyz")]
    path = _csv(tmp_path / "si.csv", header, _columns(t * 1000, np.radians(w), f * G0))
    trace = _load_quiet(path)
    assert trace.metadata["sample_rate_hz"] == "100"  # from the times (no metadata line)
    np.testing.assert_allclose(trace.t_s, t, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(trace.gyro_dps, w, rtol=1e-15)
    np.testing.assert_allclose(trace.accel_g, f, rtol=1e-15, atol=1e-16)
    assert "gyro_x_dps from `gyro_x_rad_s` in rad_s" in trace.metadata["read_as"]


def test_a_rate_from_the_times_is_written_as_every_other_writer_writes_it(tmp_path):
    """819.2 Hz from the times is `819.2` in the metadata, as synth, the bundled traces and a run's
    output write it (the times' rate was `4096/5` before: the same value in a second spelling)."""
    t, w, f = _motion(rate=819.2)
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    trace = _load_quiet(_csv(tmp_path / "r.csv", header, _columns(t, w, f)))
    assert trace.metadata["sample_rate_hz"] == "819.2"


def test_units_by_option_override_the_names(tmp_path):
    t, w, f = _motion()
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}" for a in "xyz")]
    path = _csv(tmp_path / "x.csv", header, _columns(t, np.radians(w), f * G0))
    trace = _load_quiet(path, read=ReadOptions(units="gyro=rad/s,accel=m/s2"))
    np.testing.assert_allclose(trace.gyro_dps, w, rtol=1e-15)
    np.testing.assert_allclose(trace.accel_g, f, rtol=1e-15, atol=1e-16)
    with pytest.raises(
        TraceError,
        match=r"column `accel_x` has no recognised unit: expected `accel_x_g`.*"
        r"--units accel=UNIT",
    ):
        PhysicalTrace.load(path)
    with pytest.raises(TraceError, match=r"--units: unknown unit `furlong/s` for `gyro`; expected one of"):
        PhysicalTrace.load(path, read=ReadOptions(units="gyro=furlong/s"))


def test_a_column_map_reads_other_names_and_leaves_the_rest_out(tmp_path):
    t, w, f = _motion()
    header = ["time", "wx", "wy", "wz", "ax", "ay", "az", "status"]
    path = _csv(tmp_path / "m.csv", header, [*_columns(t, w, f), np.ones_like(t)])
    columns = "t_s=time,gyro_x_dps=wx,gyro_y_dps=wy,gyro_z_dps=wz,accel_x=ax,accel_y=ay,accel_z=az"
    trace = _load_quiet(path, read=ReadOptions(columns=columns, units={"accel": "g"}))
    np.testing.assert_array_equal(trace.gyro_dps, w)
    np.testing.assert_array_equal(trace.accel_g, f)
    assert "left out: status" in trace.metadata["read_as"]
    with pytest.raises(TraceError, match=r"--columns maps `gyro_x_dps` to `omega`, which is not a column"):
        PhysicalTrace.load(path, read=ReadOptions(columns="gyro_x_dps=omega"))


def test_a_semicolon_separated_file_is_read(tmp_path):
    t, w, f = _motion(n=50)
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    comma = _load_quiet(_csv(tmp_path / "c.csv", header, _columns(t, w, f)))
    semi = _load_quiet(_csv(tmp_path / "s.csv", header, _columns(t, w, f), sep=";"))
    tab = _load_quiet(_csv(tmp_path / "t.csv", header, _columns(t, w, f), sep="\t"))
    for other in (semi, tab):
        np.testing.assert_array_equal(other.t_s, comma.t_s)
        np.testing.assert_array_equal(other.gyro_dps, comma.gyro_dps)


def test_a_declared_rate_is_checked_against_the_times(tmp_path):
    t, w, f = _motion(n=50)
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    path = _csv(tmp_path / "r.csv", header, _columns(t, w, f), meta="# sample_rate_hz: 819.2\n")
    with pytest.raises(TraceError, match=r"`sample_rate_hz` is 819.2 Hz but the times give 100 Hz"):
        PhysicalTrace.load(path)
    # 4 % off (a nominal rate against a real clock) is accepted: the declared one is kept.
    ok = _csv(tmp_path / "ok.csv", header, _columns(t, w, f), meta="# sample_rate_hz: 104\n")
    assert _load_quiet(ok).metadata["sample_rate_hz"] == "104"


def test_accelerations_in_m_s2_under_g_columns_warn(tmp_path):
    t, w, f = _motion()
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    path = _csv(tmp_path / "a.csv", header, _columns(t, w, f * G0))
    with pytest.warns(TraceWarning, match=r"is 9.807 g, .* the accel columns look like m/s²; .*accel=m/s2"):
        PhysicalTrace.load(path)
    path = _csv(
        tmp_path / "b.csv", ["t_s", *header[1:4], *(f"accel_{a}_m_s2" for a in "xyz")], _columns(t, w, f)
    )
    with pytest.warns(TraceWarning, match=r"is 1 m/s² \(read in m_s2\).* look like g"):
        PhysicalTrace.load(path)


def test_rates_in_the_wrong_unit_warn(tmp_path):
    t, w, f = _motion()
    dps = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    path = _csv(tmp_path / "r.csv", dps, _columns(t, np.radians(w), f))
    # 165°: gravity turns 180° in 6 s, seen between the centres of the first and last 0.5 s segments.
    with pytest.warns(TraceWarning, match=r"turned through 165° in all .* look like rad/s; .*gyro=rad/s"):
        PhysicalTrace.load(path)
    rad = ["t_s", *(f"gyro_{a}_rad_s" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    path = _csv(tmp_path / "d.csv", rad, _columns(t, 2 * w, f))  # 60 °/s written in a rad/s column
    with pytest.warns(TraceWarning, match=r"a rate of 3438 °/s \(read in rad_s\) .* look like °/s"):
        PhysicalTrace.load(path)


def test_times_in_milliseconds_without_a_rate_warn(tmp_path):
    t, w, f = _motion(n=50)
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    path = _csv(tmp_path / "ms.csv", header, _columns(t * 1000, w, f))
    with pytest.warns(
        TraceWarning, match=r"sample rate of 0.1 Hz .* look like milliseconds \(100 Hz in ms\)"
    ):
        PhysicalTrace.load(path)


def test_the_project_s_own_traces_and_a_broad_trial_give_no_warning():
    """No false alarm: the bundled traces (a pitch sweep, coning) and a real recording with fast
    rotation read without a warning (the gyro turning check and the gravity check both pass)."""
    for path in sorted((ROOT / "traces").glob("*.h5")):
        _load_quiet(path)
    broad = Path("/work/shared/data/broad/06_undisturbed_fast_rotation_A.hdf5")
    if not broad.exists():
        pytest.skip("BROAD data not present")
    from sins_fw.broad import import_broad

    trace = import_broad(broad)
    with warnings.catch_warnings():
        warnings.simplefilter("error", TraceWarning)
        import tempfile

        with tempfile.TemporaryDirectory() as d:
            trace.save(Path(d) / "b.h5")
            PhysicalTrace.load(Path(d) / "b.h5")


def test_the_cli_reads_with_units_and_columns_and_shows_warnings(tmp_path):
    t, w, f = _motion(n=300)
    header = ["time", "wx", "wy", "wz", "ax", "ay", "az"]
    path = _csv(tmp_path / "own.csv", header, _columns(t * 1000, np.radians(w), f * G0))
    out = tmp_path / "own.h5"
    r = run_cli(
        "import",
        "trace",
        str(path),
        "--out",
        str(out),
        "--units",
        "t=ms,gyro=rad/s,accel=m/s2",
        "--columns",
        "t=time,gyro_x=wx,gyro_y=wy,gyro_z=wz,accel_x=ax,accel_y=ay,accel_z=az",
    )
    assert r.code == 0, r.err
    trace = _load_quiet(out)
    np.testing.assert_allclose(trace.gyro_dps, w, rtol=1e-15)
    assert trace.metadata["sample_rate_hz"] == "100"
    r = run_cli(
        "run",
        str(path),
        "--units",
        "t=ms,gyro=rad/s",
        "--columns",
        "t=time,gyro_x=wx,gyro_y=wy,gyro_z=wz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az",
    )
    assert r.code == 0, r.err
    assert "sins-fw: warning: " in r.err and "look like m/s²" in r.err, r.err
    assert "Traceback" not in r.err
    assert math.isfinite(len(r.out))


def test_run_says_which_latitude_the_earth_rate_assumes(tmp_path):
    """Issue 27, item 3: a trace without a place (BROAD's, a user's) is compensated for the earth rate
    at the profile's latitude; the summary says so and how to change it or switch it off."""
    import json

    from sins_fw.synth import generate

    trace = generate("static", duration_s=1.0)
    assert "latitude_deg" in trace.metadata
    placed = tmp_path / "placed.h5"
    trace.save(placed)
    trace.metadata.pop("latitude_deg")
    nowhere = tmp_path / "nowhere.h5"
    trace.save(nowhere)

    r = run_cli("run", str(nowhere))
    assert r.code == 0, r.err
    line = next(x for x in r.out.splitlines() if x.startswith("earth rate"))
    assert "latitude 40.84° assumed (the profile's navigation.latitude_deg)" in line
    assert "--set navigation.latitude_deg=DEG" in line and "--set firmware.earth_rate=false" in line
    r = run_cli("run", str(nowhere), "--json")
    field = json.loads(r.out)["earth_rate"]
    assert field["compensated"] is True and field["latitude_deg"] == 40.84
    assert field["trace_latitude_deg"] is None and "assumed" in field["note"]

    for args in ((str(placed),), (str(nowhere), "--set", "firmware.earth_rate=false")):
        r = run_cli("run", *args, "--json")
        assert r.code == 0, r.err
        assert json.loads(r.out)["earth_rate"]["note"] is None
        assert "earth rate" not in run_cli("run", *args).out


def test_a_gap_that_is_a_time_unit_says_so(tmp_path):
    """Three rows in ms under a declared 100 Hz: too few steps to check the rate, so the first step
    is a 'gap of 10 s', which now names the time unit that fits (it said only 'gap of 10 s')."""
    t, w, f = _motion(n=3)
    header = ["t_s", *(f"gyro_{a}_dps" for a in "xyz"), *(f"accel_{a}_g" for a in "xyz")]
    path = _csv(tmp_path / "ms.csv", header, _columns(t * 1000, w, f), meta="# sample_rate_hz: 100\n")
    with pytest.raises(
        TraceError,
        match=r"gap of 10 s .*--allow-gaps\); the times look like milliseconds "
        r"\(100 Hz in ms\): name the column `t_ms` or give --units t=ms",
    ):
        PhysicalTrace.load(path)


def test_a_run_of_a_file_read_with_units_and_columns_replays_and_reports(tmp_path):
    """A run records how it read its trace (``trace_units``, ``trace_columns``); `replay` and `report`
    of its output read the trace the same way. Before, both failed on the file's header ("wx")."""
    t, w, f = _motion(n=300)
    header = ["time", "wx", "wy", "wz", "ax", "ay", "az"]
    path = _csv(tmp_path / "own.csv", header, _columns(t * 1000, np.radians(w), f))
    saved = tmp_path / "run.h5"
    read = [
        "--units",
        "t=ms,gyro=rad/s",
        "--columns",
        "t=time,gyro_x=wx,gyro_y=wy,gyro_z=wz,accel_x_g=ax,accel_y_g=ay,accel_z_g=az",
    ]
    r = run_cli("run", str(path), *read, "--out", str(saved))
    assert r.code == 0, r.err
    r = run_cli("replay", str(saved), "--out", str(tmp_path / "r.rrd"), "--bus-ticks", "none")
    assert r.code == 0 and (tmp_path / "r.rrd").is_file(), r.err
    r = run_cli("report", str(saved), "--out", str(tmp_path / "r.png"))
    assert r.code == 0 and (tmp_path / "r.png").is_file(), r.err
