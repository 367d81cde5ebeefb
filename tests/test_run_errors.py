"""`Run.errors()`: the aligned attitude errors every report uses, as arrays in degrees."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import ROOT
from sins_fw import quaternion as quat
from sins_fw import report
from sins_fw.errors import InputError
from sins_fw.harness import emulate


@pytest.fixture(scope="module")
def run():
    return emulate(ROOT / "traces" / "pitch_sweep.h5", "reference")


def test_errors_are_the_reports_figures(run):
    e = run.errors()
    s = report.attitude_summary(run)
    for name in ("roll", "pitch", "yaw", "total"):
        x = getattr(e, name)
        assert x.shape == (run.cycles,)
        ok = np.isfinite(x)
        assert np.abs(x[ok]).max() == s["euler"][name]["max_abs_deg"]
        assert x[ok][-1] == s["euler"][name]["final_deg"]
    # BROAD's figure is over the movement mask where the trace has one (this one has).
    assert s["broad"]["mask"] == "movement"
    inc = e.inclination[run.moving & np.isfinite(e.inclination)]
    assert np.sqrt(np.mean(inc**2)) == pytest.approx(s["broad"]["rmse_inclination_deg"], rel=1e-12)


def test_an_unknown_alignment_is_an_input_error(run):
    with pytest.raises(InputError, match="align='sideways'"):
        run.errors(align="sideways")


def test_to_euler_deg_is_to_euler_in_degrees_as_one_array():
    q = quat.from_euler(np.array([0.1, -3.0]), np.array([0.2, 1.5]), np.array([6.0, 0.5]))
    deg = quat.to_euler_deg(q)
    assert deg.shape == (2, 3)
    np.testing.assert_array_equal(deg, np.degrees(np.stack(quat.to_euler(q), axis=-1)))
