"""`python -m sins_fw` runs the CLI."""

from sins_fw.cli import entry

entry()
