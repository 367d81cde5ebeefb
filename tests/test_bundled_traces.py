"""The bundled traces: small, valid, long enough together, and recreated byte for byte by
traces/regenerate.sh."""

from __future__ import annotations

import os
import re
import subprocess
import sys

from conftest import ROOT
from sins_fw.traces import PhysicalTrace, RawRegisterTrace

TRACES = ROOT / "traces"
FILES = ("static_60s.h5", "pitch_sweep.h5", "coning_10hz.h5")
#: The raw-register example: the reference firmware's reads over the first 10 s of the pitch sweep.
RAW = "pitch_sweep_10s_raw.csv"
RAW_COMMAND = f"run pitch_sweep.h5 --until-s 10 --raw-out {RAW}"


def test_bundled_traces_are_small_valid_and_long_enough():
    total = 0.0
    for name in FILES:
        path = TRACES / name
        assert path.stat().st_size < 1_000_000, name
        trace = PhysicalTrace.load(path)
        assert trace.metadata["sample_rate_hz"] == "819.2" and trace.truth_q is not None
        total += trace.duration_s
    assert total >= 600.0, total  # the later parity test needs ≥ 10 min of emulated time
    raw = RawRegisterTrace.load(TRACES / RAW)
    assert (TRACES / RAW).stat().st_size < 1_000_000
    # 10 s of 4 ms ticks, one burst each; the generator names the command that made it.
    assert len(raw) == 2500 and raw.metadata["sample_rate_hz"] == "250"
    assert raw.metadata["generator"] == f"sins-fw {RAW_COMMAND}"


def test_readme_commands_are_the_ones_in_regenerate_sh():
    readme = (TRACES / "README.md").read_text()
    script = (TRACES / "regenerate.sh").read_text().replace("\\\n    ", "")
    for name in FILES:
        command = re.search(rf"`sins-fw (synth [^`]*) --out {re.escape(name)}`", readme).group(1)
        assert f'sins {command} --out "$out/{name}"' in script, name
    assert f"`sins-fw {RAW_COMMAND}`" in readme
    assert 'sins run "$out/pitch_sweep.h5" --until-s 10 --raw-out "$out/pitch_sweep_10s_raw.csv"' in script


def test_regenerate_sh_recreates_the_files_byte_for_byte(tmp_path):
    env = dict(os.environ, PYTHON=sys.executable)
    subprocess.run(["bash", str(TRACES / "regenerate.sh"), str(tmp_path)], check=True, env=env, timeout=600)
    for name in (*FILES, RAW):
        assert (tmp_path / name).read_bytes() == (TRACES / name).read_bytes(), name
