"""The dataset's published per-trial RMSE of its tuned Madgwick and Mahony (BROAD, Laidig et al. 2021,
doi:10.3390/data6070072, CC BY 4.0): `example_code/out/results_{madgwick,mahony}_average_rmse.json` of the
dataset's repository (github.com/dlaidig/broad at 7e2f818), each trial's `tagp_parameters` entry (the
parameters tuned once over all trials: Madgwick β 0.12, Mahony k_P 0.74, k_I 0.0012): inclination, heading,
total RMSE in degrees, as published (not rounded). The figures are data, in `broad_published.json` beside
this module."""

from __future__ import annotations

import json
from importlib import resources


def _load() -> dict[str, dict[str, tuple[float, float, float]]]:
    doc = json.loads(resources.files("sins_fw").joinpath("broad_published.json").read_text(encoding="utf-8"))
    return {
        method: {trial: (float(i), float(h), float(t)) for trial, (i, h, t) in trials.items()}
        for method, trials in doc["rmse"].items()
    }


#: method → trial → (inclination, heading, total) RMSE, degrees.
PUBLISHED_PER_TRIAL: dict[str, dict[str, tuple[float, float, float]]] = _load()
