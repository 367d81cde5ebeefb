"""Writes the bad-trace corpus of this folder (run from anywhere: python make_corpus.py).

Each file is one defect; README.md maps each file to the message fragment loading it must give.
The files in handled/ load (they are valid traces) but carry something a run must report as an
event rather than pass on silently (README.md, second table).
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parent
META = "# format: sins-fw-physical-trace/1\n# sample_rate_hz: 100\n"
COLS = "t_s,gyro_x_dps,gyro_y_dps,gyro_z_dps,accel_x_g,accel_y_g,accel_z_g"
ROWS = ["0.0,0,0,0,0,0,1", "0.01,0,0,0,0,0,1", "0.02,0,0,0,0,0,1"]
RAW_META = "# format: sins-fw-raw-register-trace/1\n# sample_rate_hz: 250\n"
RAW_COLS = (
    "t_s,frame0,supply_out,xgyro_out,ygyro_out,zgyro_out,xaccl_out,yaccl_out,zaccl_out,"
    "xmagn_out,ymagn_out,zmagn_out,baro_out,baro_outl,temp_out,aux_adc"
)
RAW_ROW = ",".join(["0xFFFF", "0xC7A7", *["0x0000"] * 13])


def text(name: str, body: str) -> None:
    (HERE / name).write_bytes(body.encode("utf-8"))


def csv(name: str, header: str = COLS, rows: list[str] = ROWS, meta: str = META, end: str = "\n") -> None:
    text(name, meta + header + "\n" + "\n".join(rows) + end)


def h5(
    name: str, columns: dict[str, np.ndarray | h5py.SoftLink | h5py.ExternalLink], rate: str = "100"
) -> None:
    """An HDF5 trace; a column given as a link is written as that link instead of a dataset."""
    with h5py.File(HERE / name, "w", track_order=False) as f:
        f.attrs["format"] = "sins-fw-physical-trace/1"
        f.attrs["sample_rate_hz"] = rate
        for k, v in columns.items():
            if isinstance(v, h5py.SoftLink | h5py.ExternalLink):
                f[k] = v
            else:
                f.create_dataset(k, data=v, track_times=False)


def main() -> None:
    text("empty.csv", "")
    csv("header_only.csv", rows=[], end="")
    csv(
        "missing_column.csv", header=COLS.removesuffix(",accel_z_g"), rows=[r.rsplit(",", 1)[0] for r in ROWS]
    )
    csv("unknown_column.csv", header=COLS + ",foo", rows=[r + ",1" for r in ROWS])
    csv("wrong_unit_gyro.csv", header=COLS.replace("gyro_x_dps", "gyro_x_rads"))
    csv("wrong_unit_accel.csv", header=COLS.replace("accel_z_g", "accel_z_ms2"))
    csv("time_without_unit.csv", header=COLS.replace("t_s", "time"))
    csv("duplicate_column.csv", header=COLS.replace("gyro_z_dps", "gyro_y_dps"))
    csv("nan_value.csv", rows=[ROWS[0], "0.01,0,nan,0,0,0,1", ROWS[2]])
    csv("inf_value.csv", rows=[ROWS[0], ROWS[1], "0.02,0,0,0,0,0,inf"])
    csv("time_not_increasing.csv", rows=[ROWS[0], ROWS[1], "0.01,0,0,0,0,0,1"])
    csv("time_gap.csv", rows=[ROWS[0], ROWS[1], "0.05,0,0,0,0,0,1"])
    csv("truncated_last_row.csv", rows=[ROWS[0], ROWS[1], "0.02,0,0,0"], end="")
    csv("wrong_field_count.csv", rows=[ROWS[0], "0.01,0,0,0,0,0", ROWS[2]])
    csv("not_a_number.csv", rows=[ROWS[0], "0.01,0,0,abc,0,0,1", ROWS[2]])
    csv("empty_line_in_data.csv", rows=[ROWS[0], "", ROWS[2]])
    (HERE / "non_utf8.csv").write_bytes(
        (META + COLS + "\n" + ROWS[0] + "\n").encode() + b"0.01,0,0,0,0,0,1\xff\n"
    )
    (HERE / "binary_garbage.csv").write_bytes(bytes(range(256)) * 4)
    # Without `sample_rate_hz` the times give the rate: one row cannot.
    csv("missing_sample_rate_one_row.csv", meta="# format: sins-fw-physical-trace/1\n", rows=ROWS[:1])
    # A declared rate the times contradict: 1000 Hz times under 100 Hz; times in ms under 100 Hz.
    many = [f"{k / 1000!r},0,0,0,0,0,1" for k in range(20)]
    csv("sample_rate_mismatch.csv", rows=many)
    csv("time_in_ms.csv", rows=[f"{10 * k}.0,0,0,0,0,0,1" for k in range(20)])
    # A `;`-separated file (read) whose numbers have decimal commas (not read).
    semi = [r.replace(",", ";") for r in ROWS]
    csv("decimal_comma.csv", header=COLS.replace(",", ";"), rows=[semi[0], semi[1].replace("0.01", "0,01")])
    csv("bad_sample_rate.csv", meta="# sample_rate_hz: fast\n")
    csv("truth_incomplete.csv", header=COLS + ",truth_qw", rows=[r + ",1" for r in ROWS])
    q = ",truth_qw,truth_qx,truth_qy,truth_qz"
    csv(
        "truth_partial_nan.csv",
        header=COLS + q,
        rows=[r + s for r, s in zip(ROWS, [",1,0,0,0", ",nan,0,0,0", ",1,0,0,0"], strict=True)],
    )
    csv(
        "truth_not_unit.csv",
        header=COLS + q,
        rows=[r + s for r, s in zip(ROWS, [",1,0,0,0", ",1,0,0,0", ",1,0.1,0,0"], strict=True)],
    )
    csv(
        "moving_not_flag.csv",
        header=COLS + ",moving",
        rows=[r + s for r, s in zip(ROWS, [",0", ",1", ",2"], strict=True)],
    )
    csv(
        "raw_word_not_hex.csv",
        header=RAW_COLS,
        meta=RAW_META,
        rows=["0.0," + RAW_ROW, "0.004," + RAW_ROW.replace("0xC7A7", "0xZZ")],
    )
    csv(
        "raw_word_too_wide.csv",
        header=RAW_COLS,
        meta=RAW_META,
        rows=["0.0," + RAW_ROW.replace("0xC7A7", "0x1C7A7")],
    )
    csv("raw_format_physical_columns.csv", meta=RAW_META.replace("250", "100"))
    base = {c: np.zeros(3) for c in COLS.split(",")}
    base["t_s"] = np.array([0.0, 0.01, 0.02])
    base["accel_z_g"] = np.ones(3)
    h5("h5_missing_column.h5", {k: v for k, v in base.items() if k != "accel_z_g"})
    h5("h5_length_mismatch.h5", {**base, "gyro_y_dps": np.zeros(2)})
    h5("h5_nan_value.h5", {**base, "gyro_z_dps": np.array([0.0, 0.0, np.nan])})
    h5("h5_wrong_unit.h5", {**{k: v for k, v in base.items() if k != "t_s"}, "t_min": base["t_s"] / 60})
    good = (HERE / "h5_nan_value.h5").read_bytes()
    (HERE / "h5_truncated.h5").write_bytes(good[:600])
    (HERE / "h5_named_csv.csv").write_bytes(good)
    (HERE / "garbage.h5").write_bytes(b"\x00\x01garbage" * 50)
    (HERE / "text_named_h5.h5").write_text(META + COLS + "\n" + "\n".join(ROWS) + "\n")
    csv("time_goes_back.csv", rows=[ROWS[0], ROWS[1], "0.005,0,0,0,0,0,1"])
    # HDF5 structures a loader must not follow or cast: a column that is an external link (to a file
    # that is not there), a soft link to itself, a compound (record) dtype.
    h5("h5_external_link.h5", {**base, "gyro_x_dps": h5py.ExternalLink("elsewhere.h5", "/gyro_x_dps")})
    h5("h5_soft_link_loop.h5", {**base, "gyro_x_dps": h5py.SoftLink("/gyro_x_dps")})
    h5(
        "h5_compound_column.h5",
        {**base, "t_s": np.array([(t, 0) for t in base["t_s"]], dtype=[("t", "f8"), ("n", "i4")])},
    )
    csv("duplicate_metadata_key.csv", meta=META + "# sample_rate_hz: 200\n")
    handled()


def handled() -> None:
    """Valid 2 s traces at 100 Hz that a run must report: far beyond the sensor's range (saturation),
    and a gap (with --allow-gaps)."""
    (HERE / "handled").mkdir(exist_ok=True)
    t = [f"{k / 100!r}" for k in range(200)]
    # ±1e6 °/s and 1e3 g: far beyond the ±300 °/s and ±18 g fields, and beyond the filter's input
    # limit (2^20 units); -1e300 °/s on y.
    far = [f"{tk},1000000.0,-1e+300,0,0,0,1000.0" for tk in t]
    text("handled/far_beyond_range.csv", META + COLS + "\n" + "\n".join(far) + "\n")
    # 0.5 s without samples after t = 0.99 s (50 sample periods).
    gap = [f"{tk},0,0,0,0,0,1" for tk in t if not 0.99 < float(tk) < 1.5]
    text("handled/time_gap_2s.csv", META + COLS + "\n" + "\n".join(gap) + "\n")


if __name__ == "__main__":
    main()
