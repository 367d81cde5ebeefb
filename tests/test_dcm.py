"""The DCM firmware (`firmware.algorithm = "dcm"`) through the whole board: opt-in by profile, fusing the
accelerometer, and a reference the trace cannot provide is exit 2 naming the key."""

from __future__ import annotations

import json

from conftest import run_cli

STATIC = "traces/static_60s.h5"


def test_dcm_runs_the_board_and_holds_tilt():
    # At rest the DCM's roll–pitch loop holds the tilt at the accelerometer's; yaw is open loop (no
    # reference), so only the unsensed earth rate (≤ 0.0042 °/s, below a gyro LSB) turns it: ≤ 0.25° in
    # 60 s. The tilt error is the accelerometer's quantisation and the gravity model's, well below 0.1°.
    r = run_cli("run", STATIC, "--set", "firmware.algorithm=dcm", "--json")
    assert r.code == 0, r.err
    e = json.loads(r.out)["attitude_error"]["euler"]
    assert e["roll"]["final_deg"] < 0.1 and e["pitch"]["final_deg"] < 0.1, e
    assert e["total"]["final_deg"] < 0.3, e


def test_gps_reference_without_gps_stream_exits_2_naming_the_key():
    r = run_cli("run", STATIC, "--set", "firmware.algorithm=dcm", "--set", "firmware.dcm.yaw_reference=gps")
    assert r.code == 2, r.err
    assert "firmware.dcm.yaw_reference" in r.err and "Traceback" not in r.err


def test_magnetometer_reference_on_a_part_without_one_exits_2_naming_the_key():
    r = run_cli(
        "run",
        STATIC,
        "--profile",
        "wing",
        "--set",
        "firmware.algorithm=dcm",
        "--set",
        "firmware.dcm.yaw_reference=magnetometer",
    )
    assert r.code == 2, r.err
    assert "firmware.dcm.yaw_reference" in r.err and "ADIS16362" in r.err and "Traceback" not in r.err
