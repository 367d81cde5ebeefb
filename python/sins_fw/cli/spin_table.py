"""`sins-fw spin-table`: spin rate → roll error of the geomagnetic–gyro board without and with the
magnetometer roll aid, as percentiles over a Monte Carlo of sensor units (sins_fw.spin_table)."""

from __future__ import annotations

import argparse

from sins_fw import spin_table
from sins_fw.cli.common import add_json_option, add_runs_options, emit, exit_epilog, param_type
from sins_fw.errors import ConfigError
from sins_fw.synth import Param

_RATES = param_type(Param("rates_dps", "floats", spin_table.DEFAULT_RATES_DPS, ""))
_FLOAT = param_type(Param("x", "float", 0.0, ""))


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "spin-table",
        help="spin rate → roll error without and with the magnetometer aid (Monte Carlo percentiles)",
        description="The geomagnetic–gyro board's spin-rate table: for each spin rate, the gyro-only roll "
        "error at the end of the run and the aided run's largest roll error, as p50, p95 and max over "
        "sensor units (seeds FIRST_SEED … FIRST_SEED + RUNS − 1, the same units at every rate). By default "
        "it runs the whole board (firmware_model/geomag.toml through the emulator, as `sins-fw run`: the "
        "ADS8344 read over SPI, the ads8344-geomag firmware) on a `synth spin` turntable trace per rate "
        "(the axis level, spun up from rest over 1 s); --engine chain runs the sensor chain and "
        "firmware/geomag.rs without the bus (every channel of an instant read at that instant; faster, any "
        "pitch). The events column counts the board's events over every run of the rate (the chain has "
        "none). The same options give byte-identical output.",
        epilog=exit_epilog(None),
    )
    p.add_argument(
        "--rates-dps",
        type=_RATES,
        default=spin_table.DEFAULT_RATES_DPS,
        metavar="FLOATS",
        help="spin rates, °/s, comma-separated (0 < rate ≤ 1000; default 50,100,200,500,1000)",
    )
    add_runs_options(
        p, "sensor units per rate", "the first unit's seed", default_first_seed=0, formerly="--seed"
    )
    p.add_argument(
        "--duration-s",
        type=_FLOAT,
        default=None,
        metavar="FLOAT",
        help="run length, s (default 60; ballistic: the flight less 0.1 s)",
    )
    p.add_argument(
        "--trajectory",
        choices=spin_table.TRAJECTORIES,
        default="turntable",
        help="turntable (default): the table per spin rate; ballistic: the roll error along a drag-free arc "
        "(`synth spin --trajectory ballistic`, the firmware started from the launch), per window of the "
        "flight, with the bound the aided error keeps (board only)",
    )
    p.add_argument(
        "--launch-speed-mps",
        type=_FLOAT,
        default=500.0,
        metavar="FLOAT",
        help="ballistic: launch speed (default 500)",
    )
    p.add_argument(
        "--elevation-deg",
        type=_FLOAT,
        default=45.0,
        metavar="FLOAT",
        help="ballistic: launch elevation, ° (default 45)",
    )
    p.add_argument(
        "--azimuth-deg",
        type=_FLOAT,
        default=0.0,
        metavar="FLOAT",
        help="ballistic: launch azimuth, ° clockwise from north (default 0)",
    )
    p.add_argument(
        "--ideal-sensors",
        action="store_true",
        help="ballistic: the sensors without unit errors and noise (the ADC's quantisation kept)",
    )
    p.add_argument(
        "--yaw-deg", type=_FLOAT, default=90.0, metavar="FLOAT", help="spin axis yaw, ° (default 90: north)"
    )
    p.add_argument(
        "--pitch-deg",
        type=_FLOAT,
        default=0.0,
        metavar="FLOAT",
        help="spin axis pitch, ° (default 0; the board: 0 only)",
    )
    intensity, inclination, declination = spin_table.DEFAULT_FIELD
    p.add_argument(
        "--mag-intensity-gauss",
        type=_FLOAT,
        default=intensity,
        metavar="FLOAT",
        help=f"the earth's field F, gauss (default {intensity})",
    )
    p.add_argument(
        "--mag-inclination-deg",
        type=_FLOAT,
        default=inclination,
        metavar="FLOAT",
        help=f"its inclination I, ° down (default {inclination})",
    )
    p.add_argument(
        "--mag-declination-deg",
        type=_FLOAT,
        default=declination,
        metavar="FLOAT",
        help=f"its declination D, ° east (default {declination})",
    )
    p.add_argument(
        "--engine",
        choices=spin_table.ENGINES,
        default="board",
        help="board: the emulated board (default); chain: the sensor chain and firmware without the bus",
    )
    p.add_argument(
        "--compensate",
        action="store_true",
        help="the firmware's group-delay compensation on (spin gyro's τ_g on the x rate, magnetometer lag)",
    )
    add_json_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    field = (args.mag_intensity_gauss, args.mag_inclination_deg, args.mag_declination_deg)
    if args.trajectory == "ballistic":
        rates = args.rates_dps if args.rates_dps != spin_table.DEFAULT_RATES_DPS else (1000.0,)
        if args.engine != "board":
            raise ConfigError(
                "spin-table: --trajectory ballistic runs on the board only (expected --engine board)"
            )
        arc = spin_table.arc_table(
            rates,
            runs=args.runs,
            seed=args.first_seed,
            duration_s=args.duration_s,
            launch=(args.launch_speed_mps, args.elevation_deg, args.azimuth_deg),
            field=field,
            compensate=args.compensate,
            ideal=args.ideal_sensors,
        )
        emit(args, arc, spin_table.render_arc(arc))
        return 0
    if args.ideal_sensors:
        raise ConfigError("spin-table: --ideal-sensors is for --trajectory ballistic")
    table = spin_table.spin_table(
        args.rates_dps,
        runs=args.runs,
        seed=args.first_seed,
        duration_s=60.0 if args.duration_s is None else args.duration_s,
        yaw_deg=args.yaw_deg,
        pitch_deg=args.pitch_deg,
        field=field,
        compensate=args.compensate,
        engine=args.engine,
    )
    emit(args, table, spin_table.render(table))
    return 0
