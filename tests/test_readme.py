"""The README must be true: every `$ command` in it runs, and its Python example works."""

from __future__ import annotations

import re
import shlex

from conftest import ROOT, run_cli

README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_readme_gives_the_two_commands():
    assert "make demo" in README and "make test" in README


def test_every_shell_command_in_readme_runs():
    # A command whose exit status is not 0 says so: `$ sins-fw ...  # exit 1: why`.
    commands = re.findall(r"^\s+\$ (sins-fw .*?)(?:\s+# exit (\d).*)?$", README, flags=re.M)
    assert commands, "the README tour shows commands"
    for line, code in commands:
        argv = shlex.split(line)[1:]
        r = run_cli(*argv)
        assert r.code == int(code or 0), f"`{line}` failed: {r.err}"


def test_python_examples_in_readme_run():
    blocks = re.findall(r"```python\n(.*?)```", README, flags=re.S)
    assert blocks
    for block in blocks:
        exec(compile(block, "README.md", "exec"), {})
