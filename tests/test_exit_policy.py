"""One exit policy (README, "Exit codes"; every command's --help): exit 1 whenever a check the command
performs fails — an event of severity error in a run, a broken rule, a parity threshold — with the
outputs still written and the summary still printed; an empty selection is a usage error (2)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from conftest import ROOT
from sins_fw import synth
from sins_fw.cli import build_parser, main
from sins_fw.cli import demo as demo_cmd
from sins_fw.cli.common import check_events
from sins_fw.errors import CheckFailed
from sins_fw.profile import load_profile


def _cli(capsys, *args: object) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def short(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("trace") / "t.csv"
    synth.generate("static", duration_s=0.3).save(path)
    return path


#: Overrides whose run logs error-severity events: SCLK above the device's burst limit, and a timer
#: period shorter than one ISR (deadline overruns).
ERROR_RUNS = {"sclk_too_fast": "spi.spibrr=9", "overrun": "timer.period_us=300"}


@pytest.mark.parametrize("kind", sorted(ERROR_RUNS))
def test_run_with_error_events_exits_1_after_writing_and_summarising(capsys, tmp_path, short, kind):
    out = tmp_path / "o.h5"
    code, text, err = _cli(capsys, "run", short, "--set", ERROR_RUNS[kind], "--out", out, "--json")
    assert code == 1, err
    summary = json.loads(text)
    severities = {k: v["severity"] for k, v in summary["events"]["by_kind"].items()}
    assert "error" in severities.values(), severities
    assert out.is_file() and summary["out"] == str(out)
    assert err.startswith("sins-fw: check failed: the run logged") and "Traceback" not in err, err


def test_run_without_error_events_exits_0(capsys, tmp_path, short):
    code, _, err = _cli(capsys, "run", short, "--out", tmp_path / "o.h5")
    assert code == 0 and err == "", err


def test_report_and_replay_with_error_events_exit_1_after_writing(capsys, tmp_path, short):
    png, rrd = tmp_path / "r.png", tmp_path / "r.rrd"
    code, _, err = _cli(capsys, "report", short, "--set", "spi.spibrr=9", "--out", png)
    assert code == 1 and png.stat().st_size > 0 and "sclk_too_fast" in err, err
    code, _, err = _cli(capsys, "replay", short, "--set", "spi.spibrr=9", "--out", rrd, "--bus-ticks", "none")
    assert code == 1 and rrd.stat().st_size > 0 and "sclk_too_fast" in err, err


def test_demo_with_error_events_exits_1_after_its_summary(capsys, tmp_path, short, monkeypatch):
    # The demo runs the reference profile on the bundled traces; here a board that breaks the SPI
    # rule on one short trace.
    monkeypatch.setattr(demo_cmd, "TRACE_DIR", short.parent)
    monkeypatch.setattr(demo_cmd, "TRACES", (short.name,))
    monkeypatch.setattr(demo_cmd, "load_profile", lambda name: load_profile(name, ["spi.spibrr=9"]))
    code, text, err = _cli(capsys, "demo", "--no-recording", "--json")
    assert code == 1, err
    assert short.name in json.loads(text)["traces"]
    assert f"the run on {short.name} logged" in err, err


def test_any_event_of_severity_error_fails_whatever_its_kind():
    events = [
        {"t_s": 0.5, "kind": "saturated_reading", "severity": "warning", "message": "w"},
        {"t_s": 1.25, "kind": "a_kind_added_later", "severity": "error", "message": "state not finite"},
    ]
    with pytest.raises(CheckFailed, match=r"1 error event \(a_kind_added_later ×1\); the first at 1.25 s"):
        check_events(events)
    check_events(events[:1])


def test_board_breaking_a_rule_exits_1_with_its_report(capsys):
    code, text, err = _cli(capsys, "board", "--set", "spi.spibrr=9", "--json")
    assert code == 1
    assert any(v["kind"] == "sclk_burst_too_fast" for v in json.loads(text)["violations"])
    assert "sclk_burst_too_fast" in err
    code, _, err = _cli(capsys, "board")
    assert code == 0, err


@pytest.mark.parametrize("selection", ["", "f64", " , "])
def test_parity_with_nothing_to_compare_is_a_usage_error(capsys, selection):
    code, out, err = _cli(capsys, "parity", ROOT / "traces" / "static_60s.h5", "--backends", selection)
    assert code == 2 and out == "", err
    assert "nothing to compare" in err


def _command_parsers():
    parser = build_parser()
    (sub,) = [a for a in parser._actions if a.dest == "command"]
    for name, p in sub.choices.items():
        nested = [a for a in p._actions if hasattr(a, "choices") and isinstance(a.choices, dict)]
        yield name, p
        for action in nested:
            for inner, q in action.choices.items():
                yield f"{name} {inner}", q


def test_every_command_help_states_the_exit_policy():
    for name, p in _command_parsers():
        text = p.format_help()
        assert "Exit status: 0 success; 1 " in " ".join(text.split()), name


def test_the_readme_states_the_policy():
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert "any event of severity `error`" in readme
    assert "the output files are still written and the summary still printed" in readme
