"""`make wheel` gives a wheel a user installs without a Rust toolchain.

The wheel is built as the README says (`make wheel`), installed into a fresh virtual environment
with pip (its dependencies from the index or pip's cache), and run with a PATH on which no `cargo`
or `rustc` can be found, from a folder outside the repository: the bundled profiles and traces must
come from inside the installed package.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    if shutil.which("make") is None:
        pytest.skip("make is not installed")
    work = tmp_path_factory.mktemp("wheel")
    wheels = work / "wheels"
    built = subprocess.run(
        ["make", "-s", "wheel", f"WHEEL_DIR={wheels}"], cwd=ROOT, capture_output=True, text=True, check=False
    )
    assert built.returncode == 0, built.stderr
    (wheel,) = wheels.glob("sins_fw-*-abi3-*.whl")
    env_dir = work / "venv"
    venv.create(env_dir, with_pip=True)
    bin_dir = env_dir / "bin"
    pip = subprocess.run(
        [bin_dir / "pip", "install", "-q", "--disable-pip-version-check", wheel],
        capture_output=True,
        text=True,
        check=False,
    )
    assert pip.returncode == 0, pip.stderr
    # Only the environment's own scripts and the system's basic tools: no Rust toolchain.
    path = os.pathsep.join([str(bin_dir), "/usr/bin", "/bin"])
    assert shutil.which("cargo", path=path) is None and shutil.which("rustc", path=path) is None
    env = {"PATH": path, "HOME": str(work), "LANG": "C.UTF-8"}
    return {"bin": str(bin_dir), "cwd": str(work), **{f"env_{k}": v for k, v in env.items()}}


def _sins_fw(installed: dict[str, str], *args: str) -> subprocess.CompletedProcess[str]:
    env = {k.removeprefix("env_"): v for k, v in installed.items() if k.startswith("env_")}
    return subprocess.run(
        [str(Path(installed["bin"]) / "sins-fw"), *args],
        cwd=installed["cwd"],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )


def test_the_installed_wheel_runs_the_demo_without_a_rust_toolchain(installed):
    r = _sins_fw(installed, "demo", "--out-dir", "demo-out")
    assert r.returncode == 0, r.stderr
    assert "Traceback" not in r.stderr
    for trace in ("static_60s.h5", "pitch_sweep.h5", "coning_10hz.h5"):
        assert trace in r.stdout
    assert (Path(installed["cwd"]) / "demo-out" / "pitch_sweep.rrd").stat().st_size > 0


def test_the_installed_wheel_finds_its_bundled_profiles(installed):
    for name in ("reference", "wing"):
        r = _sins_fw(installed, "board", "--profile", name)
        assert r.returncode == 0, (name, r.stderr)
    r = _sins_fw(installed, "board", "--profile", "no-such-profile")
    assert r.returncode == 2
    assert "known profiles: adis_ads8344, geomag, gfsins, i2c_eeprom, reference, wing" in r.stderr


def test_the_package_is_imported_from_the_environment_not_the_checkout(installed):
    py = Path(installed["bin"]) / "python"
    env = {k.removeprefix("env_"): v for k, v in installed.items() if k.startswith("env_")}
    r = subprocess.run(
        # broad_published reads its data file beside the module: the wheel must carry it.
        [str(py), "-c", "import sins_fw.broad_published, sins_fw.profile as p; print(p.MODEL_DIR)"],
        cwd=installed["cwd"],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 0, r.stderr
    model_dir = Path(r.stdout.strip())
    assert not model_dir.is_relative_to(ROOT) and model_dir.is_relative_to(installed["cwd"]), model_dir
