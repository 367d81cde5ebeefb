"""`sins-fw board`: what the profile's registers produce, without running anything."""

from __future__ import annotations

import argparse
from collections import Counter

from sins_fw import _core
from sins_fw.cli.common import add_json_option, add_profile_options, emit, exit_epilog, profile_from_args
from sins_fw.errors import CheckFailed
from sins_fw.harness import cost_table_text


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "board",
        help="show the clocks, SPI baud and mode, frame and burst times the profile's registers give",
        epilog=exit_epilog("when the configuration breaks a rule of the hardware (as `budget` does)"),
    )
    add_profile_options(p)
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    profile = profile_from_args(args)
    s = _core.board_summary(profile.text, profile.source, list(profile.overrides), *cost_table_text(profile))
    report = {"profile": profile.source, "overrides": list(profile.overrides), **s}
    lines = [
        f"profile        {profile.source} {' '.join(profile.overrides)}".rstrip(),
        f"SYSCLKOUT      {s['sysclkout_hz'] / 1e6:.3f} MHz",
        f"LSPCLK         {s['lspclk_hz'] / 1e6:.3f} MHz",
        f"SPI baud       {s['spi_baud_hz'] / 1e3:.3f} kHz (LSPCLK / {s['spi_divisor']})",
        f"SPI mode       {s['spi_mode']} ({s['clock_scheme']}); the {s['part']} needs mode "
        f"{' or '.join(str(m) for m in s['part_modes'])}: "
        f"{'matches' if s['mode_matches_device'] else 'DOES NOT MATCH'}",
        f"frame          {s['char_bits']} bits, {s['frame_s'] * 1e6:.3f} µs",
        f"{'read (' + str(s['read_frames']) + ')':15}{s['burst_s'] * 1e6:.3f} µs first to last SCLK edge, "
        "as the firmware polls "
        f"({s['burst_clocking_s'] * 1e6:.3f} µs of clocking)",
        f"frame gap      {s['frame_gap_s'] * 1e6:.3f} µs longest, last to first SCLK edge",
        f"timer period   {s['timer_period_s'] * 1e6:.3f} µs",
    ]
    if s["violations"]:
        lines.append("rules broken:")
        lines += [f"  {v['kind']}: {v['message']}" for v in s["violations"]]
    else:
        lines.append("rules broken:  none")
    emit(args, report, "\n".join(lines))
    if s["violations"]:
        kinds = Counter(str(v["kind"]) for v in s["violations"])
        raise CheckFailed(
            "the configuration breaks rules: " + ", ".join(f"{k} ×{n}" for k, n in kinds.items())
        )
    return 0
