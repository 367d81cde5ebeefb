"""The CLI frame: version, help, exit codes, JSON output, no tracebacks on user errors."""

from __future__ import annotations

import json
import tomllib

import sins_fw
from conftest import ROOT, run_cli


def test_version_is_the_cargo_version():
    cargo = tomllib.loads((ROOT / "Cargo.toml").read_text())["workspace"]["package"]["version"]
    r = run_cli("--version")
    assert r.code == 0
    assert r.out.strip() == f"sins-fw {cargo}"
    assert sins_fw.__version__ == cargo


def test_help_lists_commands():
    r = run_cli("--help")
    assert r.code == 0
    for name in ("demo",):
        assert name in r.out


def test_no_command_is_usage_error():
    assert run_cli().code == 2


def test_unknown_option_is_usage_error_without_traceback():
    r = run_cli("demo", "--no-such-option")
    assert r.code == 2
    assert "Traceback" not in r.err
    assert "--no-such-option" in r.err


def test_demo_json_is_one_object(tmp_path):
    r = run_cli("demo", "--json", "--out-dir", str(tmp_path))
    assert r.code == 0, r.err
    report = json.loads(r.out)
    assert report["version"] == sins_fw.__version__
    assert set(report["traces"]) == {"static_60s.h5", "pitch_sweep.h5", "coning_10hz.h5"}
    assert 0.85 <= report["budget"]["solution"]["ratio"] <= 1.15
    assert all(p["passed"] for p in report["parity"].values())
    assert (tmp_path / "pitch_sweep.rrd").stat().st_size > 0


def test_board_reference_reports_750khz_mode3():
    r = run_cli("board", "--json")
    assert r.code == 0, r.err
    s = json.loads(r.out)
    assert s["spi_baud_hz"] == 750000
    assert s["spi_mode"] == 3
    assert s["mode_matches_device"] is True
    assert s["burst_s"] >= 320e-6
    assert s["violations"] == []


def test_board_spibrr9_breaks_the_burst_sclk_rule():
    r = run_cli("board", "--set", "spi.spibrr=9", "--json")
    assert r.code == 1, r.err  # a rule broken is a failed check; the report is still printed
    s = json.loads(r.out)
    assert s["spi_baud_hz"] == 3.75e6
    assert any(v["kind"] == "sclk_burst_too_fast" for v in s["violations"])


def test_board_bad_override_exit_2_names_key():
    r = run_cli("board", "--set", "spi.spibrr=300")
    assert r.code == 2
    assert "spi.spibrr" in r.err and "Traceback" not in r.err


def test_a_rust_panic_is_an_internal_error_not_an_abort():
    import pytest

    from sins_fw import _core
    from sins_fw.errors import InternalError, SinsError

    with pytest.raises(InternalError, match="self-test panic") as e:
        _core._selftest_panic()
    assert isinstance(e.value, SinsError)
