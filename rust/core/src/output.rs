//! What a run produces: one row per attitude step, per burst read and per timer tick, and the
//! events. Rows are plain data; the binding turns each column into a numpy array.

use crate::events::Event;
use crate::time::Ps;

/// One attitude step's output (what the firmware would send out every T).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleRow {
    /// Step index (0 = first step after alignment).
    pub step: u64,
    /// Virtual time of the tick that completed the step.
    pub t_ps: Ps,
    /// Q = [q0, q1, q2, q3], body → navigation.
    pub quat: [f64; 4],
    /// Roll, pitch, yaw, degrees (the firmware's extraction).
    pub euler_deg: [f64; 3],
    /// Velocity east, north, up, m/s.
    pub vel_enu: [f64; 3],
    /// Latitude (°), longitude (°), height (m).
    pub pos: [f64; 3],
}

/// One attitude step's drift-cancellation terms (the algorithms that have them: the DCM; no rows
/// for the others).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectionRow {
    /// The step (as [`CycleRow::step`]).
    pub step: u64,
    /// ω_P, rad/s, body axes.
    pub omega_p: [f64; 3],
    /// ω_I, rad/s, body axes.
    pub omega_i: [f64; 3],
    /// The roll–pitch error vector, body axes.
    pub error_rp: [f64; 3],
    /// The yaw error vector, body axes.
    pub error_yaw: [f64; 3],
    /// |R·Rᵀ − I| (largest element) after renormalisation.
    pub orthogonality: f64,
}

/// One attitude step of the wing-angle unit (`firmware.algorithm = "wing"`; no rows for the other
/// algorithms): the hinge angle and the axis it is measured about.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WingRow {
    /// The step (as [`CycleRow::step`]).
    pub step: u64,
    /// α, degrees, from the zero pose; NaN while no axis is estimated (during the zero acquisition and
    /// the first motion).
    pub alpha_deg: f64,
    /// The estimated hinge axis, unit, IMU axes at the zero pose (a·up ≥ 0); NaN while none.
    pub axis: [f64; 3],
    /// Where the axis comes from: 0 none yet, 1 dynamic (B2, integrated motion), 2 static (B1, rest poses).
    pub axis_source: u64,
    /// The step was detected at rest (the filter's rest recalibration ran).
    pub at_rest: bool,
}

/// One burst read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReadRow {
    /// Timer tick of the read.
    pub tick: u64,
    /// CS falling edge of the burst (the firmware's GPIO57 write): what a raw-register trace records.
    pub t_cs_ps: Ps,
    /// First SCLK edge of the burst.
    pub t_start_ps: Ps,
    /// Last SCLK edge of the burst.
    pub t_end_ps: Ps,
    /// The words SPIRXBUF gave (frame 0: the command frame's don't-care word).
    pub words: [u16; READ_WORDS],
    /// Decoded ω_ib^b, rad/s (the firmware's values as f64).
    pub rate: [f64; 3],
    /// Decoded f^b, m/s².
    pub accel: [f64; 3],
    /// Device sample the burst carried (−1: none, e.g. before the first sample); in a replay, the
    /// row of the recorded burst.
    pub sample_index: i64,
    /// True time of that sample (device clock); in a replay, the recorded timestamp of the burst.
    pub sample_ps: Ps,
    /// The time the firmware assumes the sample belongs to, s.
    pub assumed_s: f64,
    /// Age of the sample at the burst's first data frame.
    pub age_ps: Ps,
}

/// One timer tick's budget: when each part of the ISR ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BudgetRow {
    /// Tick index (tick k arrives at k × period).
    pub tick: u64,
    /// Arrival of the tick.
    pub tick_ps: Ps,
    /// First ISR cycle (later than the tick after an overrun).
    pub start_ps: Ps,
    /// End of the interrupt entry (context save and prologue).
    pub entry_end_ps: Ps,
    /// First SCLK edge of the first burst.
    pub spi_start_ps: Ps,
    /// CS high after the last burst.
    pub spi_end_ps: Ps,
    /// End of the decode.
    pub decode_end_ps: Ps,
    /// End of the attitude update (= decode end when no step ran).
    pub attitude_end_ps: Ps,
    /// End of the Euler extraction.
    pub euler_end_ps: Ps,
    /// End of the navigation.
    pub nav_end_ps: Ps,
    /// End of the ISR (after the exit).
    pub end_ps: Ps,
    /// The next tick: the deadline of this one.
    pub deadline_ps: Ps,
    /// This tick completed an attitude step.
    pub step: bool,
    /// This tick arrived while the previous ISR was running.
    pub overrun: bool,
}

impl BudgetRow {
    /// A tick that did not run (dropped or lost): every time is the tick's arrival.
    pub fn skipped(tick: u64, tick_ps: Ps) -> BudgetRow {
        BudgetRow {
            tick,
            tick_ps,
            start_ps: tick_ps,
            entry_end_ps: tick_ps,
            spi_start_ps: tick_ps,
            spi_end_ps: tick_ps,
            decode_end_ps: tick_ps,
            attitude_end_ps: tick_ps,
            euler_end_ps: tick_ps,
            nav_end_ps: tick_ps,
            end_ps: tick_ps,
            deadline_ps: tick_ps,
            step: false,
            overrun: true,
        }
    }
}

/// Everything a run produced since the output was last taken.
#[derive(Debug, Clone, Default)]
pub struct Output {
    /// One row per attitude step.
    pub cycles: Vec<CycleRow>,
    /// One row per burst read.
    pub reads: Vec<ReadRow>,
    /// One row per timer tick.
    pub budget: Vec<BudgetRow>,
    /// One row per attitude step of an algorithm with drift-cancellation terms (the DCM).
    pub corrections: Vec<CorrectionRow>,
    /// Events of every model, in time order.
    pub events: Vec<Event>,
    /// One row per attitude step of the wing-angle unit.
    pub wing: Vec<WingRow>,
}

impl Output {
    /// Append another chunk's output (rows and events keep their order).
    pub fn append(&mut self, other: Output) {
        self.cycles.extend(other.cycles);
        self.reads.extend(other.reads);
        self.budget.extend(other.budget);
        self.corrections.extend(other.corrections);
        self.events.extend(other.events);
        self.wing.extend(other.wing);
    }
}

/// The SPIRXBUF words a read row holds: the burst command's frame and the ADIS16407's 14 data words.
pub const READ_WORDS: usize = 15;

/// One output column as the binding hands it to Python (`sins_fw._core.OUTPUT_COLUMNS`): a field of
/// [`CycleRow`], [`ReadRow`], [`BudgetRow`], [`CorrectionRow`] or [`WingRow`] under its table's prefix, in the order
/// `Emulator.take` returns them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    /// Key in `Emulator.take`'s dict: `cycle_`, `read_`, `budget_`, `dcm_` or `wing_` and the row's field.
    pub name: &'static str,
    /// Unit of its values.
    pub unit: &'static str,
    /// One line of meaning.
    pub meaning: &'static str,
    /// Its columns in the run output file (`sins-fw run --out`), one per component, with their
    /// units; empty when the file does not hold it.
    pub file: &'static [(&'static str, &'static str)],
}

const fn col(name: &'static str, unit: &'static str, meaning: &'static str) -> Column {
    Column { name, unit, meaning, file: &[] }
}

const fn filed(
    name: &'static str,
    unit: &'static str,
    meaning: &'static str,
    file: &'static [(&'static str, &'static str)],
) -> Column {
    Column { name, unit, meaning, file }
}

/// Every output column, in the binding's order.
pub const COLUMNS: &[Column] = &[
    col("cycle_step", "1", "attitude step index (0 = first step after alignment)"),
    filed(
        "cycle_t_ps",
        "ps",
        "virtual time of the tick that completed the step (0 = power-on = first trace sample)",
        &[("t_s", "s")],
    ),
    filed(
        "cycle_quat",
        "1",
        "firmware quaternion Q = [q0, q1, q2, q3] (C_b^n, ENU)",
        &[("q0", "1"), ("q1", "1"), ("q2", "1"), ("q3", "1")],
    ),
    filed(
        "cycle_euler_deg",
        "°",
        "roll, pitch, yaw: the firmware's Euler extraction",
        &[("roll_deg", "°"), ("pitch_deg", "°"), ("yaw_deg", "°")],
    ),
    filed(
        "cycle_vel_enu",
        "m/s",
        "velocity east, north, up",
        &[("vel_e_mps", "m/s"), ("vel_n_mps", "m/s"), ("vel_u_mps", "m/s")],
    ),
    filed(
        "cycle_pos",
        "°, °, m",
        "latitude, longitude, height",
        &[("lat_deg", "°"), ("lon_deg", "°"), ("height_m", "m")],
    ),
    col("read_tick", "1", "timer tick of the burst read"),
    col("read_t_cs_ps", "ps", "CS falling edge of the burst: what a raw-register trace records"),
    col("read_t_start_ps", "ps", "first SCLK edge of the burst"),
    col("read_t_end_ps", "ps", "last SCLK edge of the burst"),
    col("read_words", "16-bit word", "the READ_WORDS words SPIRXBUF gave (frame 0: the command frame's answer)"),
    col("read_rate", "rad/s", "decoded ω_ib^b (the firmware's values as f64)"),
    col("read_accel", "m/s²", "decoded f^b (the firmware's values as f64)"),
    col("read_sample_index", "1", "device sample the burst carried (−1: none); in a replay, the recorded burst's row"),
    col("read_sample_ps", "ps", "true time of that sample (device clock); in a replay, the recorded timestamp"),
    col("read_assumed_s", "s", "the time the firmware assumes the sample belongs to"),
    col("read_age_ps", "ps", "age of the sample at the burst's first data frame"),
    col("budget_tick", "1", "timer tick index (tick k arrives at k × period)"),
    col("budget_tick_ps", "ps", "arrival of the tick"),
    col("budget_start_ps", "ps", "first ISR cycle (later than the tick after an overrun)"),
    col("budget_entry_end_ps", "ps", "end of the interrupt entry (context save and prologue)"),
    col("budget_spi_start_ps", "ps", "first SCLK edge of the first burst"),
    col("budget_spi_end_ps", "ps", "CS high after the last burst"),
    col("budget_decode_end_ps", "ps", "end of the decode"),
    col("budget_attitude_end_ps", "ps", "end of the attitude update (= decode end when no step ran)"),
    col("budget_euler_end_ps", "ps", "end of the Euler extraction"),
    col("budget_nav_end_ps", "ps", "end of the navigation"),
    col("budget_end_ps", "ps", "end of the ISR (after the exit)"),
    col("budget_deadline_ps", "ps", "the next tick: the deadline of this one"),
    col("budget_step", "0/1", "this tick completed an attitude step"),
    col("budget_overrun", "0/1", "this tick arrived while the previous ISR was running"),
    col(
        "dcm_step",
        "1",
        "DCM only (no rows for the other algorithms): the attitude step of the row (in the run output file, the row of that step)",
    ),
    filed(
        "dcm_omega_p",
        "rad/s",
        "DCM: the proportional correction ω_P = K_P·e, body axes",
        &[("dcm_omega_p_x_rad_s", "rad/s"), ("dcm_omega_p_y_rad_s", "rad/s"), ("dcm_omega_p_z_rad_s", "rad/s")],
    ),
    filed(
        "dcm_omega_i",
        "rad/s",
        "DCM: the integrator ω_I, body axes",
        &[("dcm_omega_i_x_rad_s", "rad/s"), ("dcm_omega_i_y_rad_s", "rad/s"), ("dcm_omega_i_z_rad_s", "rad/s")],
    ),
    filed(
        "dcm_error_rp",
        "1",
        "DCM: the roll–pitch error ĝ × r₃ (centripetal-compensated), body axes",
        &[("dcm_error_rp_x", "1"), ("dcm_error_rp_y", "1"), ("dcm_error_rp_z", "1")],
    ),
    filed(
        "dcm_error_yaw",
        "1",
        "DCM: the yaw error (magnetometer or GPS course), body axes",
        &[("dcm_error_yaw_x", "1"), ("dcm_error_yaw_y", "1"), ("dcm_error_yaw_z", "1")],
    ),
    filed(
        "dcm_orthogonality",
        "1",
        "DCM: |R·Rᵀ − I| (largest element) after renormalisation",
        &[("dcm_orthogonality", "1")],
    ),
    col(
        "wing_step",
        "1",
        "wing unit only (no rows for the other algorithms): the attitude step of the row (in the run output file, the row of that step)",
    ),
    filed(
        "wing_alpha_deg",
        "°",
        "wing: the hinge angle α from the zero pose (NaN until an axis is estimated)",
        &[("wing_alpha_deg", "°")],
    ),
    filed(
        "wing_axis",
        "1",
        "wing: the estimated hinge axis, unit, IMU axes at the zero pose, a·up ≥ 0 (NaN until estimated)",
        &[("wing_axis_x", "1"), ("wing_axis_y", "1"), ("wing_axis_z", "1")],
    ),
    filed(
        "wing_axis_source",
        "1",
        "wing: where the axis comes from: 0 none yet, 1 dynamic (B2, integrated motion), 2 static (B1, rest poses)",
        &[("wing_axis_source", "1")],
    ),
    filed("wing_at_rest", "0/1", "wing: the step was detected at rest (rest recalibration ran)", &[("wing_at_rest", "0/1")]),
];

/// The gyro-free board's navigation columns (`sins_fw._core.GFSINS_COLUMNS`): keys of
/// `_core.gfsins_run`'s dict (one row per 5 ms cycle, NaN until the C6727's navigation starts or
/// when a packet was refused) and their columns in the board's run output file.
pub const GFSINS_COLUMNS: &[Column] = &[
    filed(
        "nav_rate",
        "rad/s",
        "ω_ib^b recovered from the accelerometer array (body axes of the array: x forward, y left, z up)",
        &[("rate_x_rad_s", "rad/s"), ("rate_y_rad_s", "rad/s"), ("rate_z_rad_s", "rad/s")],
    ),
    filed(
        "nav_bridged",
        "0…7",
        "axes whose rate was bridged by ω̇ (bit 0 x, 1 y, 2 z): the products did not change",
        &[("rate_bridged", "1")],
    ),
    filed(
        "nav_attitude_deg",
        "°",
        "the navigation's roll (right side down), pitch (nose up), heading (clockwise from north)",
        &[("nav_roll_deg", "°"), ("nav_pitch_deg", "°"), ("nav_heading_deg", "°")],
    ),
    filed(
        "nav_vel_enu",
        "m/s",
        "the navigation's velocity east, north, up",
        &[("nav_vel_e_mps", "m/s"), ("nav_vel_n_mps", "m/s"), ("nav_vel_u_mps", "m/s")],
    ),
    filed(
        "nav_pos",
        "°, °, m",
        "the navigation's latitude, longitude, height",
        &[("nav_lat_deg", "°"), ("nav_lon_deg", "°"), ("nav_height_m", "m")],
    ),
    filed("nav_fused", "−1/0/1", "the fusion on this packet: −1 not run, 0 refused, 1 done", &[("nav_fused", "1")]),
    filed("dsp_flushes", "1", "denormals flushed by the C6727's navigation since power-up", &[("dsp_flushes", "1")]),
];

/// Whether `names` are the names of [`COLUMNS`], in order: lets the binding check its column list
/// against this table at compile time.
pub const fn is_column_list(names: &[&str]) -> bool {
    if names.len() != COLUMNS.len() {
        return false;
    }
    let mut i = 0;
    while i < names.len() {
        let (a, b) = (names[i].as_bytes(), COLUMNS[i].name.as_bytes());
        if a.len() != b.len() {
            return false;
        }
        let mut j = 0;
        while j < a.len() {
            if a[j] != b[j] {
                return false;
            }
            j += 1;
        }
        i += 1;
    }
    true
}

/// One stage of a tick's budget: the part of the ISR between two of [`BudgetRow`]'s times, named by
/// their columns in [`COLUMNS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BudgetStage {
    /// The stage's name (`spi`, `attitude`, …).
    pub name: &'static str,
    /// The column of its start.
    pub start: &'static str,
    /// The column of its end.
    pub end: &'static str,
    /// Part of one attitude solution as the thesis timed it: burst read, decode, update and Euler
    /// (reference-design.md's 0.35 ms; `sins-fw budget` compares their sum with it).
    pub solution: bool,
}

const fn stage(name: &'static str, start: &'static str, end: &'static str, solution: bool) -> BudgetStage {
    BudgetStage { name, start, end, solution }
}

/// The stages of a tick in the ISR's order, each starting where the one before it ends (Python reads
/// them through the binding: `sins_fw._core.BUDGET_STAGES`).
pub const BUDGET_STAGES: &[BudgetStage] = &[
    stage("entry", "budget_start_ps", "budget_entry_end_ps", false),
    stage("cs_setup", "budget_entry_end_ps", "budget_spi_start_ps", true),
    stage("spi", "budget_spi_start_ps", "budget_spi_end_ps", true),
    stage("decode", "budget_spi_end_ps", "budget_decode_end_ps", true),
    stage("attitude", "budget_decode_end_ps", "budget_attitude_end_ps", true),
    stage("euler", "budget_attitude_end_ps", "budget_euler_end_ps", true),
    stage("navigation", "budget_euler_end_ps", "budget_nav_end_ps", false),
    stage("exit", "budget_nav_end_ps", "budget_end_ps", false),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// The stages cover the ISR from its first cycle to its end without a gap, through budget
    /// columns of the table.
    #[test]
    fn the_budget_stages_chain_through_budget_columns() {
        assert_eq!(BUDGET_STAGES.first().map(|s| s.start), Some("budget_start_ps"));
        assert_eq!(BUDGET_STAGES.last().map(|s| s.end), Some("budget_end_ps"));
        for w in BUDGET_STAGES.windows(2) {
            assert_eq!(w[0].end, w[1].start, "{} → {}", w[0].name, w[1].name);
        }
        for s in BUDGET_STAGES {
            for c in [s.start, s.end] {
                assert!(COLUMNS.iter().any(|k| k.name == c && k.unit == "ps"), "{}: {c}", s.name);
            }
        }
    }
}
