"""The Rerun recording of a C firmware's run output (`sins-fw replay RUN.h5` of a `run --firmware
--out` file), made from the file as recorded, a block at a time: each watched global as a time
series (``firmware/<column>``, named by its column and unit), and, where the globals give the
attitude, the board's pose, the Euler angles and the attitude error against the recorded trace's
truth, logged by :class:`sins_fw.viewer.recording.Recorder` as a model run's are (the same entities,
the same Attitude tab: :func:`sins_fw.viewer.layout.default_blueprint`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import rerun as rr

from sins_fw.profile import Profile
from sins_fw.run_output import FirmwareRunFile
from sins_fw.viewer import paths
from sins_fw.viewer.layout import default_blueprint
from sins_fw.viewer.recording import FLUSH_PARTS, Recorder, _flush, _send, _seq, _series, _time


def blueprint(run: FirmwareRunFile) -> Any:
    """The layout of a firmware run's recording: the Attitude tab (when the globals give the
    attitude) and the Globals tab."""
    return default_blueprint(bus=False, firmware=series_names(run), attitude=run.has_attitude)


def series_names(run: FirmwareRunFile) -> Mapping[str, str]:
    """Each global's series name: its column, with its unit when known."""
    return {c: run.label(c) for c in run.columns}


class FirmwareRecorder:
    """Log the parts of a firmware run's file (:meth:`FirmwareRunFile.parts`) into ``rec``."""

    def __init__(self, rec: rr.RecordingStream, run: FirmwareRunFile, profile: Profile) -> None:
        self.rec = rec
        self.run = run
        self.names = series_names(run)
        self.attitude = Recorder(rec, profile) if run.has_attitude else None
        self.rows = 0
        self.parts = 0
        for column, name in self.names.items():
            _series(rec, paths.firmware_global(column), [name])

    def add(self, part: Mapping[str, Any]) -> None:
        n = len(part["cycle_step"])
        self.rows += n
        if self.attitude is not None:
            self.attitude.add(part)
        if n:
            index = [
                _time(part["cycle_t_ps"]),
                _seq(paths.CYCLE, part["cycle_tick"]),
                _seq(paths.TICK, part["cycle_tick"]),
            ]
            for column, values in part["firmware_globals"].items():
                v = np.asarray(values, dtype=np.float64)
                _send(self.rec, paths.firmware_global(column), index, rr.Scalars.columns(scalars=v))
        self.parts += 1
        if self.parts % FLUSH_PARTS == 0:
            self.rec.flush()

    def finish(self) -> None:
        if self.attitude is not None:
            self.attitude.finish(None)
        _flush(self.rec)
