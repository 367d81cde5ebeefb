"""`sins-fw board`: what the profile's registers produce, without running anything."""

from __future__ import annotations

import argparse
from collections import Counter

import numpy as np

from sins_fw import _core, gfsins
from sins_fw.cli.common import add_json_option, add_profile_options, emit, exit_epilog, profile_from_args
from sins_fw.errors import CheckFailed
from sins_fw.profile import cost_table_text


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "board",
        help="show the clocks, SPI baud and mode, frame and burst times the profile's registers give",
        epilog=exit_epilog("when the configuration breaks a rule of the hardware (as `budget` does)"),
    )
    add_profile_options(p)
    add_json_option(p)
    p.set_defaults(func=run)


#: Cycles of the gyro-free board `board` emulates on a vehicle at rest: 3 s, past the compass's
#: start-up (about 1 s) and through three GPS fixes.
GFSINS_SECONDS = 3.0


def run(args: argparse.Namespace) -> int:
    if gfsins.has_own_schema(args.profile):
        return _gfsins(args)
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


def _gfsins(args: argparse.Namespace) -> int:
    """The gyro-free board: both processors, the links, the parts, the rules its settings are
    checked against, and the rules the parts and links checked on a few seconds at rest."""
    prof = gfsins.load(args.profile, args.overrides)
    ticks = round(GFSINS_SECONDS / prof.period_s)
    s = _core.gfsins_board(prof.text, prof.source, list(prof.overrides), ticks)
    em = s.pop("emulated")
    # At rest the rate is constant: the navigation's rate recovery is singular by physics, not by
    # a setting (rate_singular is a report of the algorithm, not a rule of a part or link).
    broken = [e for e in em["events"] if e["severity"] != "info" and e["kind"] != "rate_singular"]
    kinds = Counter(str(e["kind"]) for e in broken)
    first = {k: next(e for e in broken if e["kind"] == k) for k in kinds}
    worst = float(np.nanmax(em["packet_s"][:, 1] - em["t0_s"][:, 0]))
    report = {
        "profile": prof.source,
        "overrides": list(prof.overrides),
        "board": "gfsins",
        **s,
        "emulated": {
            "ticks": ticks,
            "packet_out_max_s": worst,
            "period_s": em["period_s"],
            "events": [{"kind": k, "count": n, "first": first[k]} for k, n in kinds.items()],
        },
    }
    name_w = max(len(x["name"]) for x in s["links"])
    lines = [
        f"profile        {prof.source} {' '.join(prof.overrides)}".rstrip(),
        "board          gfsins: two processors, the node's packet every tick to the DSP",
    ]
    for p in s["processors"]:
        lines.append(
            f"  {p['name']:<6} {p['part']}: CPU {p['clock_hz'] / 1e6:g} MHz, bus {p['bus_hz'] / 1e6:g} MHz, "
            f"{p['tick_hz']:g} Hz packets"
        )
    lines.append("links")
    for x in s["links"]:
        rate = f"{x['rate_hz'] / 1e3:.3f} kHz" if x["kind"] != "uart" else f"{x['rate_hz']:g} baud"
        lines.append(
            f"  {x['name']:<{name_w}} {x['kind']:<5} {rate:>14}  "
            f"{x['transfer_s'] * 1e6:10.3f} µs  {x['what']}"
        )
    lines.append(
        "  (time: one 7-byte read; one 6-byte compass read with its address; one character; one packet)"
    )
    lines.append("parts")
    lines += [f"  {p['part']:<11} on {p['links']}: {p['settings']}" for p in s["parts"]]
    lines.append("rules checked (settings)")
    for r in s["rules"]:
        lines.append(
            f"  {'ok    ' if r['ok'] else 'BROKEN'} {r['rule']}: {r['measured']:g} against {r['limit']:g} "
            f"{r['unit']} ({r['source']})"
        )
    lines.append(
        f"rules checked (emulated {GFSINS_SECONDS:g} s at rest, {ticks} ticks): SPI timing and mode at each "
        "ADXL345, I²C timing, ACK and response delay at the HMC6343, UART framing, NMEA checksums, "
        "packet CRC and sequence at the C6727B, the node's tick"
    )
    lines.append(
        f"  packet out at most {worst * 1e6:.3f} µs after its tick (period {em['period_s'] * 1e6:.0f} µs)"
    )
    if kinds:
        lines += [f"  BROKEN {k} ×{n}: {first[k]['message']}" for k, n in kinds.items()]
    else:
        lines.append("  none broken")
    emit(args, report, "\n".join(lines))
    bad = [r["rule"] for r in s["rules"] if not r["ok"]]
    if bad or kinds:
        raise CheckFailed(
            "the configuration breaks rules: " + ", ".join([*bad, *(f"{k} ×{n}" for k, n in kinds.items())])
        )
    return 0
