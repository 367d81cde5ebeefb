"""`sins-fw demo`: the main job on the bundled traces.

Emulates the reference profile (the published board, its firmware in C28x single precision) on
every bundled trace and prints, per trace, the attitude error against the exact truth and the
events; then the timing budget of one attitude solution against the published 0.35 ms; then the
parity of the single-precision backends against the f64 reference; and saves a Rerun recording.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from sins_fw import __version__, budget, parity, report
from sins_fw.cli.common import EVENTS_CHECK, add_json_option, check_events, emit, exit_epilog
from sins_fw.errors import CheckFailed
from sins_fw.harness import emulate
from sins_fw.profile import load_profile

#: The bundled traces, in the order the demo runs them.
TRACES = ("static_60s.h5", "pitch_sweep.h5", "coning_10hz.h5")
#: The package's ``bundled_traces`` (a link to the repository's traces/ in a checkout, a copy in a wheel).
TRACE_DIR = Path(__file__).resolve().parents[1] / "bundled_traces"
PARITY_BACKENDS = ("f64", "c28x-f32", "c28x-f32-rz")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "demo",
        help="emulate the reference board on the bundled traces and summarise",
        epilog=exit_epilog(
            f"{EVENTS_CHECK.replace('the run', 'a run')}, or a backend exceeds its parity threshold"
        ),
    )
    p.add_argument(
        "--out-dir",
        default="out/demo",
        metavar="DIR",
        help="where the Rerun recording goes (default: out/demo)",
    )
    p.add_argument("--no-recording", action="store_true", help="skip the Rerun recording")
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    profile = load_profile("reference")
    traces = [TRACE_DIR / name for name in TRACES]
    recording = None if args.no_recording else Path(args.out_dir) / "pitch_sweep.rrd"
    result: dict[str, Any] = {
        "version": __version__,
        "profile": profile.source,
        "numeric": profile.get("firmware.numeric"),
        "algorithm": profile.get("firmware.algorithm"),
        "traces": {},
    }
    lines = [
        f"sins-fw {__version__}: the reference board ({profile.get('firmware.algorithm')}, "
        f"{profile.get('firmware.numeric')}) on the bundled traces",
        "",
        "attitude (error against the exact truth, total rotation angle; the firmware starts from "
        "Q = [1, 0, 0, 0] and subtracts an earth rate its quantised gyros cannot see)",
    ]
    runs = {}
    for path in traces:
        r = emulate(path, profile)
        runs[path.name] = r
        s = report.summarise(r, trace=str(path))
        result["traces"][path.name] = {
            "cycles": s["cycles"],
            "duration_s": s["duration_s"],
            "events": s["events"]["by_kind"],
            "attitude_error": s["attitude_error"],
        }
        a = s["attitude_error"]
        e = a["euler"] if a else {}
        # The total rotation angle: Euler components flip by 180° near pitch ±90° (gimbal lock).
        worst = e["total"]["max_abs_deg"] if "total" in e else float("nan")
        final = {k: round(v["final_deg"], 4) for k, v in e.items()}
        events = ", ".join(f"{k} ×{v['count']}" for k, v in s["events"]["by_kind"].items()) or "none"
        lines.append(
            f"  {path.name:<16} {s['duration_s']:7.1f} s  {s['cycles']:6d} steps  "
            f"max error {worst:7.4f}°  final {final}  events: {events}"
        )

    b = budget.budget_report(profile)
    sol = b["solution"]
    result["budget"] = {
        "solution": sol,
        "utilisation": b["summary"]["utilisation"],
        "rules": b["rules_broken"],
    }
    parts = ", ".join(f"{k} {v * 1e6:.2f} µs" for k, v in sol["parts_s"].items())
    lines += [
        "",
        f"timing budget (published: {sol['reference_s'] * 1e3:.2f} ms per attitude solution)",
        f"  one solution   {sol['time_s'] * 1e6:.2f} µs = {sol['ratio']:.3f} × published ({parts})",
        f"  of which       {sol['spi_clocking_s'] * 1e6:.1f} µs SPI clocking from the registers, "
        f"{sol['provenance_s']['sourced_costs'] * 1e6:.1f} µs TI-sourced costs, "
        f"{sol['provenance_s']['estimates'] * 1e6:.1f} µs estimated costs",
        f"  tick load      {b['summary']['utilisation']['max'] * 100:.2f} % max; "
        f"rules broken: {', '.join(r['kind'] for r in b['rules_broken']) or 'none'}",
    ]

    lines += ["", "parity against f64 (attitude difference)"]
    result["parity"] = {}
    failed = False
    for path in traces:
        p = parity.parity(path, profile, backends=PARITY_BACKENDS)
        result["parity"][path.name] = p.to_dict()
        failed |= not p.passed
        for d in p.backends:
            verdict = "ok" if d.passed else "EXCEEDS " + "; ".join(d.exceeded)
            lines.append(
                f"  {path.name:<16} {d.backend:<12} max {d.max_deg:.5f}°  rms {d.rms_deg:.5f}°  "
                f"drift {d.drift_deg_per_h:+.4f} °/h  {verdict if d.checked else 'not checked'}"
            )

    if recording is not None:
        from sins_fw.viewer import save_recording  # Rerun is a heavy import: only for --recording

        out = recording
        out.parent.mkdir(parents=True, exist_ok=True)
        save_recording(runs["pitch_sweep.h5"], out, name="sins-fw demo: pitch sweep")
        result["recording"] = str(out)
        lines += ["", f"Rerun recording: {out} (open with `rerun {out}`)"]

    emit(args, result, "\n".join(lines))
    if failed:
        raise CheckFailed("a backend exceeded its parity threshold (see above)")
    for name, r in runs.items():
        check_events(r.events, f"the run on {name}")
    return 0
