"""Hostile input that used to crash (exit 3) or pass silently: HDF5 links and compound columns, bad
scenario parameters, a damaged run output, a repeated metadata key, an override over a line break."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from conftest import ROOT
from sins_fw import synth
from sins_fw.cli import main
from sins_fw.errors import ConfigError, ProfileError
from sins_fw.profile import load_profile

STATIC = ROOT / "traces" / "static_60s.h5"


def _cli(capsys, *args: object) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _copy_h5(src, dst, change):
    with h5py.File(src, "r") as f, h5py.File(dst, "w") as g:
        for k, v in f.attrs.items():
            g.attrs[k] = v
        for name in f:
            g.create_dataset(name, data=f[name][:])
        change(g)


def _external(g):
    del g["gyro_x_dps"]
    g["gyro_x_dps"] = h5py.ExternalLink("elsewhere.h5", "/gyro_x_dps")


def _loop(g):
    del g["gyro_x_dps"]
    g["gyro_x_dps"] = h5py.SoftLink("/gyro_x_dps")  # a link to itself


def _compound(g):
    t = g["t_s"][:]
    del g["t_s"]
    g.create_dataset("t_s", data=np.array([(x, 0) for x in t], dtype=[("t", "f8"), ("n", "i4")]))


@pytest.mark.parametrize(
    ("change", "fragment"),
    [
        (_external, "column `gyro_x_dps` is an external link to elsewhere.h5"),
        (_loop, "column `gyro_x_dps`: the link to /gyro_x_dps does not lead to a dataset"),
        (_compound, "column `t_s`: dataset type"),
    ],
    ids=["external_link", "soft_link_loop", "compound_dtype"],
)
def test_hdf5_links_and_compound_columns_are_exit_2_naming_file_and_column(
    capsys, tmp_path, change, fragment
):
    bad = tmp_path / "bad.h5"
    _copy_h5(STATIC, bad, change)
    for args in (["run", bad], ["import", "trace", bad, "--out", tmp_path / "o.csv"]):
        code, _, err = _cli(capsys, *args)
        assert code == 2, err
        assert str(bad) in err and fragment in err and "Traceback" not in err, err
    assert not (tmp_path / "o.csv").exists()


def test_montecarlo_param_that_is_not_a_number_is_exit_2(capsys):
    code, _, err = _cli(capsys, "montecarlo", "static", "--param", "duration-s=abc", "--runs", "1")
    assert code == 2 and "duration_s" in err and "abc" in err and "Traceback" not in err, err


def test_run_output_with_a_bad_until_s_is_exit_2_naming_the_field(capsys, tmp_path):
    out = tmp_path / "o.h5"
    trace = tmp_path / "t.csv"
    synth.generate("static", duration_s=0.3).save(trace)
    assert _cli(capsys, "run", trace, "--out", out, "--until-s", "0.2")[0] == 0
    with h5py.File(out, "r+") as f:
        f.attrs["until_s"] = "abc"
    code, _, err = _cli(capsys, "replay", out, "--out", tmp_path / "r.rrd")
    assert code == 2 and "metadata `until_s` = 'abc': expected a finite number" in err and str(out) in err, (
        err
    )


@pytest.mark.parametrize(
    ("param", "value", "key"),
    [
        ("latitude_deg", 95.0, "navigation.latitude_deg"),
        ("latitude_deg", 1e6, "navigation.latitude_deg"),
        ("height_m", 1e9, "navigation.height_m"),
    ],
)
def test_synth_place_is_checked_by_the_profile_rule(capsys, tmp_path, param, value, key):
    # The same rule (and message) as the profile's key: one place.
    with pytest.raises(ProfileError) as rule:
        load_profile("reference", [f"{key}={value!r}"])
    with pytest.raises(ConfigError, match=param):
        synth.generate("static", duration_s=0.1, **{param: value})
    code, _, err = _cli(
        capsys, "synth", "static", f"--{param.replace('_', '-')}", value, "--out", tmp_path / "s.h5"
    )
    assert code == 2 and key in err and "Traceback" not in err, err
    assert str(rule.value).split("`", 2)[1] in err  # the profile's own wording of the key
    assert not (tmp_path / "s.h5").exists()


def test_a_csv_metadata_key_given_twice_is_refused_naming_it(capsys, tmp_path):
    good = tmp_path / "g.csv"
    synth.generate("static", duration_s=0.1).save(good)
    lines = good.read_text().splitlines(keepends=True)
    bad = tmp_path / "twice.csv"
    bad.write_text(lines[0] + "# sample_rate_hz: 100\n" + "".join(lines[1:]))
    code, _, err = _cli(capsys, "run", bad)
    assert code == 2 and "`sample_rate_hz` given twice" in err and str(bad) in err, err


def test_an_override_running_over_a_line_break_is_refused(capsys):
    code, _, err = _cli(capsys, "board", "--set", "spi.spibrr=49\nspi.spibrr=9")
    assert code == 2 and "line break" in err, err


# ---------------------------------------------------------------------------------------------------
# Issue 42: TOML files given as options, ports, the API's arguments
# ---------------------------------------------------------------------------------------------------

_THRESHOLDS = b"[backends.c28x-f32]\nmax_deg = 0.001\n"


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        # Before: UnicodeDecodeError (exit 3).
        (_THRESHOLDS + "# r\u00e9glage\n".encode("latin-1"), "line 3: byte 0xe9 is not UTF-8 text"),
        (b"\x00\x01\x02\x03" * 64, "binary data (NUL byte at offset 0)"),
        # Before: RecursionError (exit 3).
        (b"x = " + b"[" * 100_000 + b"]" * 100_000 + b"\n", "nested too deeply"),
        (b"x = " + b"{a = " * 50_000 + b"1" + b"}" * 50_000 + b"\n", "nested too deeply"),
    ],
    ids=["latin-1", "binary", "deep-arrays", "deep-tables"],
)
def test_parity_thresholds_that_cannot_be_read_are_exit_2_naming_the_file(
    capsys, tmp_path, content, fragment
):
    bad = tmp_path / "ci.toml"
    bad.write_bytes(content)
    code, out, err = _cli(capsys, "parity", STATIC, "--thresholds", bad)
    assert code == 2 and out == "", err
    assert f"{bad}: " in err and fragment in err and "Traceback" not in err, err


def test_a_globals_file_that_is_not_utf8_is_exit_2(tmp_path):
    from sins_fw.errors import InputError
    from sins_fw.firmware_run import load_globals

    bad = tmp_path / "globals.toml"
    bad.write_bytes('[[global]]\nname = "caf\u00e9"\n'.encode("latin-1"))
    with pytest.raises(InputError, match="not UTF-8"):
        load_globals(bad)
    bad.write_bytes(b"x = " + b"[" * 100_000 + b"]" * 100_000 + b"\n")
    with pytest.raises(InputError, match="nested too deeply"):
        load_globals(bad)


@pytest.mark.parametrize(
    ("option", "value", "fragment"),
    [
        ("--port", "70000", "70000: expected a TCP port number, 0…65535"),
        ("--port", "-1", "-1: expected a TCP port number"),
        ("--port", "http", "'http': expected a TCP port number"),
        ("--grpc-port", "65536", "65536: expected a TCP port number"),
        ("--grpc-port", "9e3", "'9e3': expected a TCP port number"),
    ],
)
def test_replay_serve_with_a_bad_port_is_exit_2_naming_the_option(capsys, option, value, fragment):
    # Before: 70000 or -1 reached socket.bind: OverflowError (exit 3).
    with pytest.raises(SystemExit) as e:
        main(["replay", str(STATIC), "--serve", option, value])
    err = capsys.readouterr().err
    assert e.value.code == 2 and f"argument {option}" in err and fragment in err, err


def test_replay_serve_on_a_port_in_use_or_twice_the_same_is_exit_2_naming_the_option(capsys):
    import socket

    with socket.socket() as held:
        held.bind(("127.0.0.1", 0))
        held.listen()
        port = held.getsockname()[1]
        code, _, err = _cli(capsys, "replay", STATIC, "--serve", "--port", port, "--grpc-port", 0)
        assert code == 2 and f"--port {port}: cannot listen on 127.0.0.1:{port}" in err, err
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        free = probe.getsockname()[1]
    code, _, err = _cli(capsys, "replay", STATIC, "--serve", "--port", free, "--grpc-port", free)
    assert code == 2 and f"--grpc-port {free}: cannot listen" in err, err


@pytest.mark.parametrize(
    ("columns", "fragment"),
    [
        # Before: accepted, one of the two maps silently dropped.
        ("t_s=t_s,gyro_x_dps=t_s", "--columns maps both `t_s` and `gyro_x_dps` to `t_s`"),
        # A gyro column read as the time (the file's own t_s renamed away).
        ("t_s=gyro_x_dps,gyro_x_dps=t_s", "maps `t_s` to `gyro_x_dps`, which is a `gyro` column by its name"),
        ("accel_z_g=gyro_z_dps,gyro_z_dps=accel_z_g", "which is a `gyro` column by its name"),
    ],
)
def test_columns_that_read_one_quantity_as_another_are_refused(capsys, tmp_path, columns, fragment):
    trace = tmp_path / "t.csv"
    synth.generate("static", duration_s=0.2).save(trace)
    code, _, err = _cli(capsys, "run", trace, "--columns", columns)
    assert code == 2 and str(trace) in err and fragment in err, err


def test_columns_that_swap_axes_of_one_quantity_are_accepted(capsys, tmp_path):
    trace = tmp_path / "t.csv"
    synth.generate("static", duration_s=0.2).save(trace)
    code, _, err = _cli(capsys, "run", trace, "--columns", "gyro_x_dps=gyro_y_dps,gyro_y_dps=gyro_x_dps")
    assert code == 0, err


def test_a_library_warning_is_one_line_without_its_source_line(capsys):
    # Before: numpy's RuntimeWarning came with the file, line and the source line that raised it.
    import warnings

    from sins_fw import cli

    with warnings.catch_warnings():
        warnings.simplefilter("always")
        warnings.showwarning = cli._show_warning
        np.mean(np.array([]))  # RuntimeWarning: Mean of empty slice
    err = capsys.readouterr().err
    assert err.startswith("sins-fw: warning: RuntimeWarning (") and "Mean of empty slice" in err, err
    assert err.count("\n") <= 2 and "np.mean" not in err, err
