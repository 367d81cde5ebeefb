"""Names declared once across the language boundary: the event kinds and output columns are the
core's tables (exported by the binding), and so are the raw-register trace's word columns (the
ADIS16407's burst list); docs/events.md is generated from them; the Python side
reports no kind of its own that the table lacks."""

from __future__ import annotations

import re

from conftest import ROOT
from sins_fw import _core, docs, traces
from sins_fw.harness import new_emulator
from sins_fw.profile import load_profile


def test_docs_events_md_is_generated_from_the_tables() -> None:
    committed = docs.EVENTS_MD.read_text(encoding="utf-8")
    assert committed == docs.events_md(), "docs/events.md is stale: run `make docs`"


def test_every_kind_the_python_side_reports_is_in_the_table() -> None:
    kinds = {k["name"]: k for k in _core.EVENT_KINDS}
    reported = []
    for path in sorted((ROOT / "python" / "sins_fw").rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        for m in re.finditer(r'"kind": "([a-z0-9_]+)",\s*"severity": "([a-z]+)"', text):
            reported.append((path.name, m[1], m[2]))
    assert reported, "the pattern finds the harness's events"
    for where, kind, severity in reported:
        assert kind in kinds, f"{where} reports event kind {kind!r}, which events::KINDS lacks"
        assert kinds[kind]["severity"] == severity, f"{where}: {kind} with severity {severity}"
        assert kinds[kind]["source"] == "harness", kind


def test_the_take_dict_holds_exactly_the_output_columns() -> None:
    emu = new_emulator(load_profile("reference"))
    emu.end()
    emu.run()
    taken = emu.take()
    assert list(taken) == [c["name"] for c in _core.OUTPUT_COLUMNS] + ["events"]
    assert taken["read_words"].shape[1:] == (_core.READ_WORDS,)


def test_raw_word_columns_from_the_part_are_the_documented_format() -> None:
    # RAW_WORD_COLUMNS comes from the ADIS16407's burst list in the Rust core: a change of the part's
    # declaration would change the file format, so it must match the documented column list.
    section = (ROOT / "docs" / "traces.md").read_text().split("## Raw-register trace", 1)[1]
    listed = section.split("bus order:", 1)[1].split("(registers", 1)[0]
    documented = tuple(re.findall(r"`([a-z0-9_]+)`", listed))
    assert len(documented) == _core.READ_WORDS
    assert documented == traces.RAW_WORD_COLUMNS
    assert traces.RAW_SCHEMA.names() == ["t_s", *documented]
    assert _core.PARTS[traces.RAW_PART]["burst_command"] == 0x4200  # the documented command frame
