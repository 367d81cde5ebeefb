"""How a run's attitude estimate is put into its truth's frame before it is compared (the one
alignment every report, the Monte Carlo sweeps and ``Run.errors`` use): ``alignment.method`` of the
run summary.

* ``initial`` (the default when ``firmware.initial_attitude = zero``, the reference design): the
  firmware starts from Q = [1, 0, 0, 0], i.e. it integrates relative to the body's attitude at
  power-on, so the estimate is premultiplied by the truth at power-on (the trace's first sample);
  when that truth is missing, by the rotation that makes the first step with truth exact.
* ``heading`` (the default for ``level``, which finds roll and pitch itself): rotated about the
  navigation z axis by the heading error at the first valid movement sample (BROAD's convention).
* ``none``: compared as is.

It sits below the harness (which holds a run) and the reports (which summarise one): it reads a run
through :class:`AlignableRun`, the fields it needs.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from sins_fw import metrics
from sins_fw import quaternion as quat
from sins_fw.profile import Profile

#: The alignment methods (``auto`` picks ``initial`` or ``heading`` from the profile).
ALIGNMENTS = ("auto", "initial", "heading", "none")


class AlignableRun(Protocol):
    """What the alignment reads of a run (:class:`sins_fw.harness.Run` has it)."""

    @property
    def profile(self) -> Profile: ...
    @property
    def time_s(self) -> NDArray[np.float64]: ...
    @property
    def quat(self) -> NDArray[np.float64]: ...
    @property
    def truth_q(self) -> NDArray[np.float64] | None: ...
    @property
    def truth_q0(self) -> NDArray[np.float64] | None: ...
    @property
    def moving(self) -> NDArray[np.bool_] | None: ...


def align_run(run: AlignableRun, method: str) -> tuple[np.ndarray, dict[str, Any]]:
    """The estimate in the truth's frame and a description of the alignment (the run has truth)."""
    est, truth = run.quat, run.truth_q
    assert truth is not None
    if method == "auto":
        method = "initial" if run.profile.get("firmware.initial_attitude") == "zero" else "heading"
    if method == "initial":
        q0 = run.truth_q0
        if q0 is not None and np.isfinite(q0).all():
            return metrics.align_initial(est, q0), metrics.alignment_record("initial")
        k = int(np.argmax(np.isfinite(truth).all(axis=1)))
        start = quat.multiply(truth[k], quat.conjugate(est[k]))
        return metrics.align_initial(est, start), metrics.alignment_record("initial", k, t_s=run.time_s[k])
    if method == "heading":
        aligned, delta, row = metrics.align_heading(est, truth, run.moving)
        return aligned, metrics.alignment_record("heading", row, heading_deg=delta)
    return est, metrics.alignment_record("none")


def aligned_estimate(run: AlignableRun, align: str = "auto") -> tuple[np.ndarray, dict[str, Any]]:
    """The estimate expressed in the truth's frame (see the module doc) and how it was aligned; the
    one alignment every report (text, PNG, Rerun) uses."""
    if run.truth_q is None:
        return run.quat, {"method": "none", "row": None, "description": "no truth: not aligned"}
    return align_run(run, align)
