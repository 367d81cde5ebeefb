//! The presets as printable rows: every value with its source and whether it is unconfirmed
//! (`sins-fw errors`).

use super::*;

/// One row of a preset table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PresetRow {
    /// What the value is (including how it is distributed over units).
    pub quantity: &'static str,
    /// The value, in `unit`.
    pub value: f64,
    /// Unit of `value`.
    pub unit: &'static str,
    /// Where the value comes from and how it was interpreted.
    pub source: &'static str,
    /// True where the spec marks the value unconfirmed for the ADIS16407, or it is a model choice.
    pub unconfirmed: bool,
}

pub(super) const SRC_16407: &str = "ADIS16407 data sheet (spec adis16407.md)";
pub(super) const SRC_16405: &str = "ADIS16405 sibling (spec adis16407.md), unconfirmed for the 16407";
pub(super) const SRC_16405_1SIGMA: &str =
    "ADIS16405 sibling, unconfirmed; ± read as 1σ normal (ADI tables give typical values as 1σ, ez.analog.com DOC-16082)";
pub(super) const SRC_NOT_IN_SPEC: &str = "not in the spec: 0 assumed";

/// The preset `name` as printable rows (every number read from [`ErrorParams::preset`]).
pub fn preset_table(name: &str) -> Result<Vec<PresetRow>> {
    let p = ErrorParams::preset(name)?;
    let annotated = name != "ideal";
    let g = &p.gyro;
    let a = &p.accel;
    let floor = |e: &InertialErrors| match &e.bias_instability {
        BiasInstability::Flicker { allan_floor, tau_min_s, tau_max_s, terms_per_decade } => {
            [*allan_floor, *tau_min_s, *tau_max_s, *terms_per_decade as f64]
        }
        _ => [0.0; 4],
    };
    let [g_floor, g_tmin, g_tmax, g_terms] = floor(g);
    let [a_floor, a_tmin, a_tmax, a_terms] = floor(a);
    let model_choice = "model choice: flicker bank (module docs), 1 term/decade";
    let rows: Vec<(&'static str, f64, &'static str, &'static str, bool)> = vec![
        ("gyro full scale (range ±300)", g.full_scale, "°/s", SRC_16407, false),
        ("gyro initial bias, 1σ", g.initial_bias.width, "°/s", SRC_16405_1SIGMA, true),
        ("gyro bias tempco, 1σ", g.bias_tempco.width, "°/s/°C", SRC_16405_1SIGMA, true),
        ("gyro scale-factor error, 1σ", g.scale_factor.width * 1e6, "ppm", SRC_NOT_IN_SPEC, true),
        ("gyro scale-factor tempco, 1σ", g.scale_tempco.width * 1e6, "ppm/°C", SRC_NOT_IN_SPEC, true),
        (
            "gyro nonlinearity (quadratic, uniform ±)",
            g.nonlinearity.width * 100.0,
            "% FS",
            "ADIS16405 sibling 0.1 % FS, unconfirmed; |deviation at full scale| ≤ it",
            true,
        ),
        (
            "gyro misalignment per element (uniform ±)",
            g.misalignment_deg.width,
            "°",
            "ADIS16407 axis-to-axis < 0.05°: two elements per pair, so pairs stay within ±0.05°",
            false,
        ),
        (
            "gyro g-sensitivity per matrix element, 1σ",
            g.g_sensitivity.width,
            "°/s/g",
            "ADIS16405 sibling (value given with MSC_CTRL[7] compensation on), unconfirmed",
            true,
        ),
        ("gyro angle random walk", g.noise_density * 60.0, "°/√h", SRC_16405, true),
        (
            "gyro per-sample noise at 819.2 SPS (derived)",
            g.noise_density * 819.2f64.sqrt(),
            "°/s",
            "N·√fs; sibling quotes ≈ 0.8 °/s rms unfiltered",
            true,
        ),
        (
            "gyro in-run bias stability (Allan floor)",
            g_floor,
            "°/s",
            "ADIS16405 sibling 0.007 °/s, unconfirmed; ADI's figure is the Allan minimum (DOC-16082)",
            true,
        ),
        ("gyro bias-instability τ min", g_tmin, "s", model_choice, true),
        ("gyro bias-instability τ max", g_tmax, "s", model_choice, true),
        ("gyro bias-instability terms per decade", g_terms, "", model_choice, true),
        ("gyro rate random walk", g.rate_random_walk, "°/s/√s", SRC_NOT_IN_SPEC, true),
        ("accel full scale", a.full_scale, "g", SRC_16407, false),
        ("accel initial bias, 1σ", a.initial_bias.width * 1e3, "mg", SRC_16405_1SIGMA, true),
        ("accel bias tempco, 1σ", a.bias_tempco.width * 1e3, "mg/°C", SRC_16405_1SIGMA, true),
        ("accel scale-factor error, 1σ", a.scale_factor.width * 1e6, "ppm", SRC_NOT_IN_SPEC, true),
        ("accel scale-factor tempco, 1σ", a.scale_tempco.width * 1e6, "ppm/°C", SRC_NOT_IN_SPEC, true),
        ("accel nonlinearity (uniform ±)", a.nonlinearity.width * 100.0, "% FS", SRC_NOT_IN_SPEC, true),
        (
            "accel misalignment per element (uniform ±)",
            a.misalignment_deg.width,
            "°",
            "assumed equal to the gyro's (spec gives no accel alignment)",
            true,
        ),
        (
            "accel noise density (one-sided, data-sheet convention)",
            a.noise_density * std::f64::consts::SQRT_2 * 1e3,
            "mg/√Hz",
            "ADIS16407 data sheet 0.5 mg/√Hz; model N = D/√2",
            false,
        ),
        (
            "accel velocity random walk (derived)",
            a.noise_density * STANDARD_GRAVITY * 60.0,
            "m/s/√h",
            "from the 16407 density; ADIS16405 sibling quotes 0.2 m/s/√h",
            false,
        ),
        (
            "accel per-sample noise at 819.2 SPS (derived)",
            a.noise_density * 819.2f64.sqrt() * 1e3,
            "mg",
            "N·√fs, white to Nyquist; the 16407's 9 mg rms is D·√(330 Hz bandwidth)",
            false,
        ),
        (
            "accel in-run bias stability (Allan floor)",
            a_floor * 1e3,
            "mg",
            "ADIS16405 sibling 0.2 mg, unconfirmed; read as the Allan minimum (DOC-16082)",
            true,
        ),
        ("accel bias-instability τ min", a_tmin, "s", model_choice, true),
        ("accel bias-instability τ max", a_tmax, "s", model_choice, true),
        ("accel bias-instability terms per decade", a_terms, "", model_choice, true),
        ("accel rate random walk", a.rate_random_walk * 1e3, "mg/√s", SRC_NOT_IN_SPEC, true),
        ("magnetometer noise per sample", p.mag.noise_rms_gauss * 1e3, "mgauss", SRC_16405, true),
        (
            "magnetometer hard iron, largest |component|",
            p.mag.hard_iron_gauss.iter().fold(0.0f64, |m, v| m.max(v.abs())) * 1e3,
            "mgauss",
            "installation-dependent: none by default",
            false,
        ),
        (
            "magnetometer soft iron, largest |S element|",
            p.mag.soft_iron.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs())),
            "",
            "installation-dependent: none by default",
            false,
        ),
        ("barometer noise per sample", p.baro.noise_rms_mbar, "mbar", SRC_16405, true),
    ];
    Ok(rows
        .into_iter()
        .map(|(quantity, value, unit, source, unconfirmed)| {
            let (source, unconfirmed) = match name {
                "adis16362" => adis16362_source(quantity).unwrap_or((source, unconfirmed)),
                _ => (source, unconfirmed),
            };
            PresetRow {
                quantity,
                value,
                unit,
                source: if annotated { source } else { "ideal preset: no error" },
                unconfirmed: annotated && unconfirmed,
            }
        })
        .collect())
}

pub(super) const SRC_WING_NOTES: &str =
    "ADIS16362 data sheet as the wing-angle notes quote it (spec adis16362.md, algorithms.md §3 corrections)";
pub(super) const SRC_16362_RECOLLECTION: &str =
    "ADIS16362 Table 1 by recollection, not re-read (spec adis16362.md): unconfirmed";

/// Where each value of the `adis16362` preset comes from, where it differs from the ADIS16407's
/// annotation (the rows not named keep it: model choices and values not in the spec). The preset is
/// [`ErrorParams::adis16362`].
pub(super) fn adis16362_source(quantity: &str) -> Option<(&'static str, bool)> {
    let row = match quantity {
        "gyro full scale (range ±300)" => ("ADIS16362 data sheet p. 11 Table 9: ±300 °/s (spec adis16362.md)", false),
        "gyro initial bias, 1σ" => (SRC_WING_NOTES, false),
        "gyro bias tempco, 1σ" => (SRC_WING_NOTES, false),
        "gyro in-run bias stability (Allan floor)" => (SRC_WING_NOTES, false),
        "gyro angle random walk" => ("ADIS16362 Table 1 by recollection (2.0 °/√h), not re-read: unconfirmed", true),
        "gyro per-sample noise at 819.2 SPS (derived)" => {
            ("N·√fs from the ARW; the recollected 0.8 °/s rms unfiltered is unconfirmed", true)
        }
        "gyro nonlinearity (quadratic, uniform ±)" => (SRC_16362_RECOLLECTION, true),
        "gyro misalignment per element (uniform ±)" => ("axis-to-axis 0.05° by recollection: unconfirmed", true),
        "gyro g-sensitivity per matrix element, 1σ" => (SRC_16362_RECOLLECTION, true),
        "accel full scale" => ("rated ±1.7 g by recollection (spec adis16362.md): unconfirmed", true),
        "accel initial bias, 1σ" => ("±4 mg by recollection, read as 1σ (spec adis16362.md): unconfirmed", true),
        "accel bias tempco, 1σ" => ("the ADIS16407's 0.3 mg/°C: not in the ADIS16362 spec, unconfirmed", true),
        "accel noise density (one-sided, data-sheet convention)" => {
            ("derived from the VRW 0.12 m/s/√h (recollection, unconfirmed), N·√2", true)
        }
        "accel velocity random walk (derived)" => (SRC_16362_RECOLLECTION, true),
        "accel per-sample noise at 819.2 SPS (derived)" => (
            "N·√fs from the VRW: 5.8 mg, against a recollected ≈ 1.5 mg rms unfiltered — the two recollected \
             figures disagree by 4×; unconfirmed",
            true,
        ),
        "accel in-run bias stability (Allan floor)" => {
            ("0.1 mg by recollection (spec adis16362.md): unconfirmed", true)
        }
        "accel misalignment per element (uniform ±)" => ("assumed equal to the gyro's: unconfirmed", true),
        "magnetometer noise per sample" | "barometer noise per sample" => {
            ("no magnetometer or barometer on the ADIS16362 (spec adis16362.md)", false)
        }
        _ => return None,
    };
    Some(row)
}
