"""`sins-fw parity TRACE...`: every arithmetic backend against f64 on the same board and input."""

from __future__ import annotations

import argparse
from pathlib import Path

from sins_fw import progress
from sins_fw.cli.common import (
    add_json_option,
    add_option,
    add_profile_options,
    emit,
    exit_epilog,
    profile_from_args,
)
from sins_fw.errors import CheckFailed, TraceError
from sins_fw.parity import BACKENDS, REFERENCE, THRESHOLDS_FILE, load_thresholds, parity


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "parity",
        help="run each numeric backend on the same input and compare its attitude with f64",
        description="Run the profile once per backend (only firmware.numeric differs) and report, per "
        "backend against f64, the attitude difference (rotation angle of q_backend ⊗ q_f64⁻¹ per step): "
        f"max, RMS, final and drift rate. Exit 1 when a backend exceeds its threshold in "
        f"firmware_model/{THRESHOLDS_FILE} or the --thresholds file.",
        epilog=exit_epilog(
            f"when a backend exceeds its threshold (firmware_model/{THRESHOLDS_FILE} or --thresholds)"
        ),
    )
    p.add_argument("traces", nargs="+", type=Path, metavar="TRACE", help="physical traces, .csv or .h5")
    add_profile_options(p)
    p.add_argument(
        "--backends",
        default=None,
        help=f"comma-separated backends (f64 is always the reference); default: f64 and every backend with "
        f"a threshold in {THRESHOLDS_FILE}; known: {','.join(BACKENDS)}",
    )
    add_option(
        p,
        "--thresholds",
        type=Path,
        metavar="FILE.toml",
        help=f"the thresholds to check against, in the form of firmware_model/{THRESHOLDS_FILE} (default "
        "that file): [backends.NAME] with max_deg, rms_deg, drift_deg_per_h, or max_deg_per_h / "
        "rms_deg_per_h for limits that grow with the run's duration (docs/cli.md)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    for t in args.traces:
        if not t.is_file():
            raise TraceError(f"{t}: no such trace file")
    profile = profile_from_args(args)
    thresholds = load_thresholds(args.thresholds)
    source = args.thresholds or f"firmware_model/{THRESHOLDS_FILE}"
    backends = args.backends if args.backends is not None else [REFERENCE, *thresholds]
    results = []
    lines = [f"profile {profile.source} {' '.join(profile.overrides)}".rstrip(), f"reference {REFERENCE}"]
    for path in args.traces:
        # The bar follows the reference backend (the others run beside it).
        with progress.trace_bar(progress.wanted(args), progress.trace_span_s(path), "parity") as reached:
            r = parity(
                path,
                profile,
                backends=backends,
                thresholds=thresholds,
                on_chunk=lambda name, t, reached=reached: reached(t) if name == REFERENCE else None,
            )
        results.append(r)
        lines.append(f"{path}: {r.steps} steps, {r.duration_s:.3f} s")
        lines.append(
            f"  {'backend':<12} {'max °':>10} {'at s':>8} {'RMS °':>10} {'final °':>10} "
            f"{'drift °/h':>11}  verdict"
        )
        for b in r.backends:
            if not b.checked:
                verdict = f"not checked: no threshold in {source}"
            else:
                verdict = "ok" if b.passed else "EXCEEDS " + "; ".join(b.exceeded)
            lines.append(
                f"  {b.backend:<12} {b.max_deg:>10.3g} {b.max_at_s:>8.2f} {b.rms_deg:>10.3g} "
                f"{b.final_deg:>10.3g} {b.drift_deg_per_h:>11.3g}  {verdict}"
            )
    passed = all(r.passed for r in results)
    lines.append(
        "thresholds: "
        + "; ".join(f"{n} {t.describe()}" for n, t in thresholds.items())
        + f" (T the run's duration; {source})"
    )
    unchecked = sorted({b.backend for r in results for b in r.backends if not b.checked})
    verdict = "parity: every checked backend within its thresholds" if passed else "parity: FAILED"
    lines.append(verdict + (f" (not checked: {', '.join(unchecked)})" if unchecked else ""))
    report = {
        "profile": profile.source,
        "overrides": list(profile.overrides),
        "reference": REFERENCE,
        "thresholds": {n: vars(t) for n, t in thresholds.items()},
        "passed": passed,
        "traces": [r.to_dict() for r in results],
    }
    emit(args, report, "\n".join(lines))
    if not passed:
        breaches = [
            f"{b.backend} on {r.trace}: {'; '.join(b.exceeded)}"
            for r in results
            for b in r.backends
            if b.exceeded
        ]
        raise CheckFailed(f"parity: a backend exceeds its threshold ({source}): {' | '.join(breaches)}")
    return 0
