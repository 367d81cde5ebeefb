"""Names declared once across the language boundary: the event kinds and output columns are the
core's tables (exported by the binding), and so are the raw-register trace's word columns (the
ADIS16407's burst list), the numeric backends, the severities and the budget's stages; the ISR
row's times are the C runtime's; docs/events.md is generated from them; the Python side
reports no kind of its own that the table lacks and holds no hand-written copy of a whole list."""

from __future__ import annotations

import ast
import re

import pytest

from conftest import ROOT
from sins_fw import _core, budget, docs, parity, traces
from sins_fw.cli import replay
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


PACKAGE = ROOT / "python" / "sins_fw"
RUNTIME = ROOT / "firmware_c" / "runtime" / "sins_fw_runtime.cpp"


def _row_times() -> list[str]:
    """The runtime's `sins_fw_row_times` initialiser."""
    text = RUNTIME.read_text(encoding="utf-8")
    init = re.search(r"sins_fw_row_times\[ROW_TIMES\]\s*=\s*\{([^}]*)\}", text)
    assert init is not None, "no sins_fw_row_times in the runtime"
    return re.findall(r'"([^"]+)"', init.group(1))


FAMILIES = {
    "numeric backends (_core.NUMERICS)": list(_core.NUMERICS),
    "severities (_core.SEVERITIES)": list(_core.SEVERITIES),
    "budget stages (_core.BUDGET_STAGES)": [s["name"] for s in _core.BUDGET_STAGES],
    "ISR row times (the runtime's sins_fw_row_times)": _row_times(),
}


def test_the_python_names_are_the_exports():
    assert (
        parity.BACKENDS
        == tuple(_core.NUMERICS)
        == replay.NUMERICS
        == ("f64", "c28x-f32", "c28x-f32-rz", "iq")
    )
    assert tuple(_core.SEVERITIES) == ("info", "warning", "error")
    assert tuple(FAMILIES["budget stages (_core.BUDGET_STAGES)"]) == budget.STAGES
    assert budget.SOLUTION_STAGES == ("cs_setup", "spi", "decode", "attitude", "euler")
    assert set(budget._BOUNDS) == set(budget.STAGES)
    assert all(
        f"budget_{c}" in {k["name"] for k in _core.OUTPUT_COLUMNS} for b in budget._BOUNDS.values() for c in b
    )


def _literals(tree: ast.AST) -> list[tuple[int, set[str]]]:
    """The tuple, list and set literals of strings in a module: (line, their strings)."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Tuple | ast.List | ast.Set):
            strings = {e.value for e in node.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)}
            if len(strings) >= 2:
                out.append((node.lineno, strings))
    return out


@pytest.mark.parametrize("family", list(FAMILIES))
def test_no_python_source_copies_a_whole_list(family: str):
    names = set(FAMILIES[family])
    assert len(names) >= 3
    copies = [
        f"{path.relative_to(ROOT)}:{line}"
        for path in sorted(PACKAGE.rglob("*.py"))
        for line, strings in _literals(ast.parse(path.read_text(encoding="utf-8")))
        if names <= strings
    ]
    assert not copies, f"{family} written out by hand in {', '.join(copies)}"
