"""`make demo` and `make test` build what `sins-fw build-firmware` needs (issue 37, item 5): the C ABI
library where the source tree's `cabi_dirs` looks for it (`cargo test` leaves its copy in
target/release/deps/ only, and `build-firmware` failed after `make test` until `cargo build --release
-p sins-cabi` was run by hand). Read from make's own database (`make -p`, nothing run)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess

import pytest

from sins_fw.firmware_paths import CABI_LIBRARY, ROOT

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")


def _database(*variables: str) -> str:
    # make test exports CABI_WITH_TESTS=1 to the tests: the database read is the default one.
    drop = ("CARGO_TARGET_DIR", "MAKEFLAGS", "MAKELEVEL", "CABI_WITH_TESTS")
    env = {k: v for k, v in os.environ.items() if k not in drop}
    # -p prints the rules read; -n -q run nothing (the target named is one without a `+` recipe).
    run = subprocess.run(
        ["make", "-p", "-n", "-q", "-f", "Makefile", ".venv/bin/python", *variables],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=env,
        check=False,
    )
    return run.stdout


def _rule(db: str, target: str) -> tuple[list[str], list[str]]:
    """A target's prerequisites and recipe lines in make's database."""
    match = re.search(rf"^{re.escape(target)}:(.*)\n((?:#.*\n)*)((?:\t.*\n)*)", db, re.MULTILINE)
    assert match is not None, f"no rule for {target}"
    return match.group(1).split(), [line.strip() for line in match.group(3).splitlines()]


def test_demo_and_test_build_the_c_abi_library_where_build_firmware_looks():
    db = _database()
    library = f"target/release/{CABI_LIBRARY}"  # cabi_dirs' folder in a source tree (no CARGO_TARGET_DIR)
    prerequisites, recipe = _rule(db, library)
    assert any(re.search(r"cargo build --release -p sins-cabi", line) for line in recipe), recipe
    assert "rust/cabi/src/lib.rs" in prerequisites and "rust/core/src/lib.rs" in prerequisites
    demo, _ = _rule(db, "demo")
    assert library in demo
    _, test_recipe = _rule(db, "test")
    assert any("$(CABI)" in line for line in test_recipe), test_recipe
    assert re.search(r"^CABI := target/release/libsins_cabi\.so$", db, re.MULTILINE)


def test_test_takes_the_library_from_the_rust_tests_build():
    """`make test` (and the tests' `make cabi`, conftest.build_cabi) take the library the Rust tests'
    build makes, so that the core is compiled once for both (`cargo build -p sins-cabi` resolves other
    features for the core's dependencies and compiled it again)."""
    _, test_recipe = _rule(_database(), "test")
    assert all("CABI_WITH_TESTS=1" in line for line in test_recipe if "$(CABI)" in line), test_recipe
    # Not in the parallel stage: its cargo would hold one of the two slots waiting on the tests' build.
    assert not any("-j2" in line and "$(CABI)" in line for line in test_recipe), test_recipe
    db = _database("CABI_WITH_TESTS=1")
    library = f"target/release/{CABI_LIBRARY}"
    prerequisites, recipe = _rule(db, library)
    assert "rust/cabi/src/lib.rs" in prerequisites and "rust/core/src/lib.rs" in prerequisites
    assert any("$(CARGO_TEST) --no-run" in line for line in recipe), recipe
    assert not any("-p sins-cabi" in line for line in recipe), recipe
    assert any("deps/$(notdir $@)" in line and "mv -f" in line for line in recipe), recipe
    assert re.search(r"^CARGO_TEST := cargo test --workspace --release$", db, re.MULTILINE)
    _, wheel_recipe = _rule(db, "wheel")
    assert not any("cargo build" in line for line in wheel_recipe), wheel_recipe
