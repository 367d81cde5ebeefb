"""Visual replay of a run in the Rerun viewer: :func:`log_run` / :func:`save_recording` send every
array with Rerun's columnar API, :func:`default_blueprint` lays the recording out. Entity paths and
timeline names: :mod:`sins_fw.viewer.paths`.

The three are loaded on first use (PEP 562): Rerun is the heaviest import of the command line, and
the commands that only serve a page (:mod:`sins_fw.viewer.serve`) or make no recording need none of
it."""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

# Rerun's own log (set before Rerun starts it; a RUST_LOG of the user's wins): warnings and errors.
os.environ.setdefault("RUST_LOG", "warn")

if TYPE_CHECKING:
    from sins_fw.viewer.layout import default_blueprint
    from sins_fw.viewer.recording import log_run, save_recording

__all__ = ["default_blueprint", "log_run", "save_recording"]


def __getattr__(name: str) -> Any:
    if name == "default_blueprint":
        from sins_fw.viewer import layout  # Rerun loads on first use (module docstring)

        return layout.default_blueprint
    if name in ("log_run", "save_recording"):
        from sins_fw.viewer import recording  # Rerun loads on first use (module docstring)

        return getattr(recording, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
