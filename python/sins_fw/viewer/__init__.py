"""Visual replay of a run in the Rerun viewer: :func:`log_run` / :func:`save_recording` send every
array with Rerun's columnar API, :func:`default_blueprint` lays the recording out. Entity paths and
timeline names: :mod:`sins_fw.viewer.paths`."""

import os

# Rerun's own log (set before Rerun starts it; a RUST_LOG of the user's wins): warnings and errors.
os.environ.setdefault("RUST_LOG", "warn")

from sins_fw.viewer.layout import default_blueprint
from sins_fw.viewer.recording import log_run, save_recording

__all__ = ["default_blueprint", "log_run", "save_recording"]
