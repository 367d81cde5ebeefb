"""Conventions every command shares: an error under --json is a JSON object on stdout; a broken
rule is named once with its count; the published solution time is compared only where it applies."""

from __future__ import annotations

import json

from conftest import run_cli


def test_json_errors_are_one_object_on_stdout(tmp_path):
    missing = tmp_path / "missing.h5"
    r = run_cli("run", str(missing), "--json")
    assert r.code == 2
    assert json.loads(r.out) == {
        "error": {"kind": "input", "exit": 2, "message": f"{missing}: no such trace file"}
    }
    assert f"{missing}: no such trace file" in r.err  # stderr says it as always


def test_json_usage_errors_are_one_object_on_stdout():
    r = run_cli("run", "--json")
    assert r.code == 2
    err = json.loads(r.out)["error"]
    assert err["kind"] == "usage" and err["exit"] == 2 and "trace" in err["message"]


def test_a_report_followed_by_a_failed_check_is_one_object():
    # budget prints its report, then exits 1: stdout stays one JSON object (the report).
    r = run_cli("budget", "--json", "--set", "spi.spibrr=1")
    assert r.code == 1
    assert "rules_broken" in json.loads(r.out)


def test_each_broken_rule_is_named_once_with_its_count():
    r = run_cli("budget", "--set", "spi.spibrr=1")
    assert r.code == 1
    line = r.err.strip().splitlines()[-1]
    # The static check and every emulated frame both break `sclk_too_fast`: one name, one total.
    assert line.count("sclk_too_fast") == 1, line
    assert "sclk_too_fast ×" in line and "sclk_burst_too_fast ×1" in line


def test_the_published_time_is_compared_only_on_the_published_configuration():
    ref = json.loads(run_cli("budget", "--json").out)["solution"]
    assert ref["published_applies"] and ref["ratio"] is not None
    r = run_cli("budget", "--json", "--profile", "wing")
    wing = json.loads(r.out)["solution"]
    assert not wing["published_applies"] and wing["ratio"] is None and wing["within_tolerance"] is None
    assert wing["published_differs"] == ["device.part = ADIS16362", "firmware.algorithm = wing"]
    text = run_cli("budget", "--profile", "wing").out
    assert "× the published" not in text and "not compared with the published 0.35 ms" in text
