"""BROAD import on the ten real trials in ../shared/data/broad (never copied into the repository)."""

from __future__ import annotations

import hashlib

import h5py
import numpy as np
import pytest

from conftest import BROAD, run_cli
from sins_fw import earth
from sins_fw import quaternion as quat
from sins_fw.broad import import_broad
from sins_fw.errors import TraceError
from sins_fw.traces import PhysicalTrace

TRIALS = sorted(BROAD.glob("*.hdf5"))
pytestmark = pytest.mark.skipif(len(TRIALS) != 10, reason=f"the ten BROAD trials are not in {BROAD}")


@pytest.fixture(scope="module")
def imported() -> dict[str, tuple[PhysicalTrace, dict[str, np.ndarray]]]:
    out = {}
    for path in TRIALS:
        with h5py.File(path, "r") as f:
            raw = {k: f[k][()] for k in ("imu_gyr", "imu_acc", "imu_mag", "opt_quat", "movement")}
        out[path.name] = (import_broad(path), raw)
    return out


def test_all_ten_trials_import_with_units_converted(imported):
    assert len(imported) == 10
    for name, (trace, raw) in imported.items():
        n = len(raw["imu_gyr"])
        assert len(trace) == n and trace.gyro_dps.shape == (n, 3) and trace.truth_q.shape == (n, 4), name
        np.testing.assert_array_equal(trace.gyro_dps, np.degrees(raw["imu_gyr"]))
        np.testing.assert_array_equal(trace.accel_g, raw["imu_acc"] / earth.G0)
        np.testing.assert_array_equal(trace.mag_gauss, raw["imu_mag"] / 100.0)  # 1 gauss = 100 µT
        np.testing.assert_array_equal(trace.moving, raw["movement"])
        assert trace.metadata["sample_rate_hz"] == "2000/7" and trace.t_s[1] == 0.0035
        assert trace.t_s[-1] == (n - 1) * 7 / 2000
        trace.validate()


def test_missing_truth_rows_are_kept_as_nan(imported):
    for name, (trace, raw) in imported.items():
        lost = np.isnan(raw["opt_quat"]).any(axis=1)
        assert lost.any(), name  # every trial has some lost-marker rows
        np.testing.assert_array_equal(np.isnan(trace.truth_q).all(axis=1), lost)
        assert np.isfinite(trace.gyro_dps[lost]).all()  # the IMU samples of those rows are kept
        np.testing.assert_array_equal(trace.truth_q[~lost], raw["opt_quat"][~lost])


def test_still_samples_measure_one_g_along_the_truth_up_axis(imported):
    # Still = outside the movement phase and turning slower than 1 °/s. The accelerometer is a MEMS
    # part: its bias (tens of mg) and scale error (~1 %) allow ±5 % on |f| and a few degrees on the
    # direction; a unit mistake would be off by a factor 9.8, a conjugated quaternion by the attitude.
    g_local = earth.normal_gravity(np.radians(52.5), 34.0) / earth.G0  # Berlin
    for name, (trace, _) in imported.items():
        still = (
            ~trace.moving & (np.linalg.norm(trace.gyro_dps, axis=1) < 1.0) & np.isfinite(trace.truth_q[:, 0])
        )
        assert still.sum() > 500, name
        norm = np.linalg.norm(trace.accel_g[still], axis=1)
        assert abs(np.median(norm) / g_local - 1.0) < 0.05, (name, np.median(norm))
        up = quat.rotate(trace.truth_q[still], trace.accel_g[still])
        tilt = np.degrees(np.arccos(np.clip(up[:, 2] / np.linalg.norm(up, axis=1), -1.0, 1.0)))
        assert np.median(tilt) < 3.0, (name, np.median(tilt))


def test_truth_quaternion_is_body_to_enu_with_body_frame_rates(imported):
    # With q = C_b^n, q_k* ⊗ q_k+1 is the rotation over one sample in the body frame: 2·vec·fs ≈ ω_b.
    trace, _ = imported["06_undisturbed_fast_rotation_A.hdf5"]
    q = trace.truth_q
    k = np.flatnonzero(np.isfinite(q[:-1, 0]) & np.isfinite(q[1:, 0]) & trace.moving[:-1])
    dq = quat.multiply(quat.conjugate(q[k]), q[k + 1])
    rate = np.degrees(2.0 * dq[:, 1:] * np.sign(dq[:, :1]) * 2000 / 7)
    gyro = 0.5 * (trace.gyro_dps[k] + trace.gyro_dps[k + 1])
    for axis in range(3):
        assert np.corrcoef(rate[:, axis], gyro[:, axis])[0, 1] > 0.95
    # The navigation-frame reading (q_k+1 ⊗ q_k*) does not match: the convention matters.
    dq_nav = quat.multiply(q[k + 1], quat.conjugate(q[k]))
    assert (
        min(np.corrcoef(dq_nav[:, 1 + a] * np.sign(dq_nav[:, 0]), gyro[:, a])[0, 1] for a in range(3)) < 0.8
    )


def test_some_trials_exceed_the_adis16407_range(imported):
    peaks = {name: np.abs(trace.gyro_dps).max() for name, (trace, _) in imported.items()}
    assert sum(p > 300.0 for p in peaks.values()) >= 3, peaks
    assert peaks["06_undisturbed_fast_rotation_A.hdf5"] > 900.0


def test_provenance_is_recorded(imported):
    path = TRIALS[0]
    trace, _ = imported[path.name]
    assert trace.metadata["source_sha256"] == hashlib.sha256(path.read_bytes()).hexdigest()
    assert trace.metadata["generator"] == f"sins-fw import broad {path.name}"
    assert "01_undisturbed_slow_rotation_A" in trace.metadata["source"]


def test_cli_import_writes_the_same_trace(tmp_path, imported):
    out = tmp_path / "t.h5"
    r = run_cli("import", "broad", str(TRIALS[-1]), "--out", str(out), "--json")
    assert r.code == 0, r.err
    loaded = PhysicalTrace.load(out)
    expected, _ = imported[TRIALS[-1].name]
    for name, col in expected.columns().items():
        np.testing.assert_array_equal(loaded.columns()[name], col)


def test_a_file_that_is_not_a_broad_trial_is_explained(tmp_path):
    bad = tmp_path / "x.hdf5"
    with h5py.File(bad, "w") as f:
        f["imu_gyr"] = np.zeros((3, 3))
    with pytest.raises(TraceError, match=r"dataset `imu_acc` is missing"):
        import_broad(bad)
    r = run_cli("import", "broad", str(bad), "--out", str(tmp_path / "o.h5"))
    assert r.code == 2 and "imu_acc" in r.err and "Traceback" not in r.err
    assert not (tmp_path / "o.h5").exists()


@pytest.mark.parametrize("ext", [".csv", ".h5"])
def test_import_broad_streams_the_bytes_of_the_whole_import(tmp_path, ext):
    """Issue 24, item 11: `import broad` loaded a trial whole. It now reads, converts and writes a
    chunk at a time (broad.iter_broad): the same bytes as the whole trial saved, whether the trial
    comes in one chunk (the CLI's 65 536 rows: every trial is shorter) or in many (4 096 rows)."""
    from sins_fw.broad import iter_broad
    from sins_fw.stream import save_chunks

    path = TRIALS[1]  # 04: with breaks (lost markers: NaN truth rows)
    import_broad(path).save(tmp_path / f"whole{ext}")
    whole = (tmp_path / f"whole{ext}").read_bytes()
    r = run_cli("import", "broad", str(path), "--out", str(tmp_path / f"cli{ext}"))
    assert r.code == 0, r.err
    assert (tmp_path / f"cli{ext}").read_bytes() == whole
    chunks = list(iter_broad(path, 4096))
    assert len(chunks) == -(-len(h5py.File(path, "r")["imu_gyr"]) // 4096)
    save_chunks(tmp_path / f"chunked{ext}", chunks)
    assert (tmp_path / f"chunked{ext}").read_bytes() == whole
