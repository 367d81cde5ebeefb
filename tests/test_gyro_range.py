"""The gyro range (issue 27, item 7): `device.gyro_range_dps` sets SENS_AVG's range bits; the published
firmware keeps decoding for `firmware.gyro_range_dps`, and its `decode_mismatch` warning names that key."""

from __future__ import annotations

import json

from conftest import ROOT, run_cli
from sins_fw.profile import load_profile

TRACE = ROOT / "traces" / "pitch_sweep.h5"  # ±10° steps about y at up to 40 °/s: inside ±75 °/s
UNTIL_S = 30.0


def _run(*sets: str) -> dict:
    args = [a for s in sets for a in ("--set", s)]
    r = run_cli("run", str(TRACE), "--until-s", str(UNTIL_S), "--json", *args)
    assert r.code in (0, 1), r.err
    return json.loads(r.out)


def test_the_device_alias_is_sens_avg_range_bits():
    assert load_profile("reference", ["device.gyro_range_dps=75"]).get("device.sens_avg") == 0x0104


def test_matching_firmware_key_decodes_the_75_dps_range_without_mismatch():
    both = _run("device.gyro_range_dps=75", "firmware.gyro_range_dps=75")
    assert both["events"]["by_kind"] == {}, both["events"]
    # The same board at ±300 °/s with the same filter (M = 4, what ±75 requires): the two differ only
    # by the gyro quantisation, at most half an LSB of each range per sample, (0.05 + 0.0125)/2 °/s,
    # integrated over the run. The device-only run is off by tens of degrees.
    ref = _run("device.sens_avg=0x0404")
    bound = (0.05 + 0.0125) / 2 * UNTIL_S
    got, want = (r["attitude_error"]["euler"]["total"]["max_abs_deg"] for r in (both, ref))
    assert abs(got - want) <= bound, (got, want, bound)
    assert got < 2.0


def test_device_only_range_warns_naming_the_firmware_key():
    only = _run("device.gyro_range_dps=75")
    mismatch = only["events"]["by_kind"]["decode_mismatch"]
    assert mismatch["count"] > 0
    assert "set firmware.gyro_range_dps = 75" in mismatch["first_message"], mismatch["first_message"]
    assert only["attitude_error"]["euler"]["total"]["max_abs_deg"] > 10.0
