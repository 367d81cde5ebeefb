"""One name per idea across the CLI (docs/cli.md): every subcommand's parser is walked and held to the
scheme; each old spelling still works, and says once on stderr that it is deprecated."""

from __future__ import annotations

import argparse
import json

import pytest

from conftest import run_cli
from sins_fw import synth
from sins_fw.cli import build_parser
from sins_fw.cli.common import UNIT_SUFFIXES, _Formerly, walk_parsers

#: Words of an option's name that mean "a file or folder is written here", however spelled.
OUTPUT_WORDS = {"out", "output", "save", "png", "plot", "dir", "write", "dest", "file", "path", "folder"}
#: Custom types taking numbers with a unit (synth's `--attitude-deg 0,0,0`, `--rates-dps 10,20`).
NUMBER_TYPES = {"float", "triple", "floats"}


def _options() -> list[tuple[str, argparse.Action]]:
    """(command line, action) for every current option of every parser (old spellings excluded)."""
    return [
        (name, a)
        for name, p in walk_parsers(build_parser())
        for a in p._actions
        if a.option_strings and not isinstance(a, _Formerly | argparse._HelpAction)
    ]


def _formerly() -> list[tuple[str, _Formerly]]:
    return [
        (name, a) for name, p in walk_parsers(build_parser()) for a in p._actions if isinstance(a, _Formerly)
    ]


def test_every_output_option_follows_the_scheme():
    for command, a in _options():
        for opt in a.option_strings:
            if OUTPUT_WORDS.isdisjoint(opt.lstrip("-").split("-")) or opt.startswith("--no-"):
                continue
            where = f"`{command} {opt}`"
            if opt == "--out":
                assert a.metavar is not None and a.metavar.startswith("FILE"), f"{where}: metavar FILE…"
            elif opt == "--plot":
                assert a.metavar == "FILE.png", f"{where}: metavar FILE.png"
            elif opt == "--out-dir":
                assert a.metavar == "DIR", f"{where}: metavar DIR"
            else:
                assert opt.endswith("-out"), f"{where}: an output is --out, --plot, --out-dir or --WHAT-out"


def test_every_number_with_a_unit_names_the_unit():
    for command, a in _options():
        type_name = getattr(a.type, "__name__", None)
        if type_name in NUMBER_TYPES:
            assert a.option_strings[0].endswith(UNIT_SUFFIXES), (
                f"`{command} {a.option_strings[0]}` takes a number: end its name in its unit {UNIT_SUFFIXES}"
            )


def test_the_first_seed_of_a_series_of_runs_has_one_name():
    for command, a in _options():
        for opt in a.option_strings:
            if "seed" in opt:
                assert opt == "--first-seed", f"`{command} {opt}`: the first seed of --runs is --first-seed"


def test_every_command_takes_debug_after_its_name():
    for command, p in walk_parsers(build_parser()):
        assert "--debug" in p._option_string_actions, f"`{command}` has no --debug"


def test_the_old_spellings_are_the_documented_ones():
    old = {(command, a.option_strings[0], a.target.option_strings[0]) for command, a in _formerly()}
    assert old == {
        ("sins-fw replay", "--save", "--out"),
        ("sins-fw report", "--png", "--out"),
        ("sins-fw bench", "--output", "--out"),
        ("sins-fw budget", "--seconds", "--duration-s"),
        ("sins-fw spin-table", "--seed", "--first-seed"),
    }


def test_debug_after_the_subcommand_shows_the_traceback(tmp_path):
    # A missing trace is an input error: one line, and with --debug (anywhere) its traceback.
    missing = str(tmp_path / "missing.h5")
    plain = run_cli("run", missing)
    assert plain.code == 2 and "Traceback" not in plain.err
    for args in (("--debug", "run", missing), ("run", missing, "--debug")):
        r = run_cli(*args)
        assert r.code == 2 and "Traceback" in r.err, args


WARNING = "is deprecated, use"
_SPIN_TABLE = ["--runs", "1", "--duration-s", "3", "--rates-dps", "100", "--json"]


@pytest.mark.parametrize(
    ("old", "new"),
    [
        (["budget", "--seconds", "0.05", "--json"], ["budget", "--duration-s", "0.05", "--json"]),
        (["spin-table", "--seed", "3", *_SPIN_TABLE], ["spin-table", "--first-seed", "3", *_SPIN_TABLE]),
        (
            ["montecarlo", "static", "--param", "duration_s=0.5", "--runs", "1", "--workers", "1", "--json"],
            ["montecarlo", "static", "--param", "duration-s=0.5", "--runs", "1", "--workers", "1", "--json"],
        ),
    ],
)
def test_an_old_spelling_works_and_warns_once_on_stderr(old, new):
    r_old, r_new = run_cli(*old), run_cli(*new)
    assert r_old.code == r_new.code == 0, r_old.err
    assert json.loads(r_old.out) == json.loads(r_new.out)  # stdout: the same one JSON object
    assert r_old.err.count(WARNING) == 1 and WARNING not in r_new.err, r_old.err
    line = next(x for x in r_old.err.splitlines() if WARNING in x)
    assert old[1] in line or old[3].split("=")[0] in line


def test_old_output_spellings_still_write_their_file(tmp_path):
    short_trace = tmp_path / "static.h5"
    synth.generate("static", duration_s=0.5).save(short_trace)
    png, rrd = tmp_path / "r.png", tmp_path / "r.rrd"
    r = run_cli("report", str(short_trace), "--png", str(png), "--json")
    assert r.code == 0 and png.is_file() and json.loads(r.out)["png"] == str(png), r.err
    assert r.err.count("--png is deprecated, use --out") == 1
    r = run_cli("replay", str(short_trace), "--save", str(rrd), "--bus-ticks", "none", "--json")
    assert r.code == 0 and rrd.is_file() and r.err.count("--save is deprecated, use --out") == 1, r.err
    # A required option's old spelling satisfies the requirement; giving neither is a usage error.
    r = run_cli("report", str(short_trace))
    assert r.code == 2 and "--out" in r.err and "--png" not in r.err
    r = run_cli("report", str(short_trace), "--out", str(png), "--png", str(png))
    assert r.code == 2 and "not allowed" in r.err


@pytest.mark.parametrize(
    "command",
    [["montecarlo", "static", "--plot"], ["sweep", "static", "--plot"], ["report", "x.h5", "--out"]],
)
def test_a_picture_that_is_no_png_is_refused_in_one_message(tmp_path, command):
    r = run_cli(*command, str(tmp_path / "p.svg"))
    assert (
        r.code == 2 and f"{command[-1]} {tmp_path / 'p.svg'}: expected a file name ending in .png" in r.err
    ), r.err
