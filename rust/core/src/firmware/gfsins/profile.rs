//! The gyro-free board's profile (`firmware_model/gfsins.toml`): the acquisition node's clocks, IP
//! core settings and cost estimates, the array, the compass, the GPS and the DSP. Every key has the
//! thesis's value as its default, or a marked choice; SCHEMA.md-style notes are in the TOML itself.

use crate::error::{Error, Result};
use crate::firmware::gfnav::{Channel, GeometryError, Inverse};
use serde::{Deserialize, Serialize};

/// The whole profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct GfsinsProfile {
    /// Name and description.
    pub meta: Meta,
    /// The acquisition node (XC3S400AN + MicroBlaze).
    pub node: Node,
    /// The accelerometer array.
    pub array: Array,
    /// The HMC6343.
    pub compass: Compass,
    /// The GR-87.
    pub gps: Gps,
    /// The TMS320C6727B.
    pub dsp: Dsp,
}

/// `[meta]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Meta {
    /// Profile name.
    pub name: String,
    /// One line.
    pub description: String,
    /// The board family member (`gfsins`): what a board dispatch keys on.
    pub board: String,
}

impl Default for Meta {
    fn default() -> Self {
        Meta {
            name: "gfsins".into(),
            description: "XC3S400AN MicroBlaze acquisition node + TMS320C6727B, 7 ADXL345, HMC6343, GR-87".into(),
            board: "gfsins".into(),
        }
    }
}

/// `[node]`: the MicroBlaze and its PLB IP cores.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Node {
    /// MicroBlaze clock, Hz (one clock with the PLB: see the TOML for the 70/75 MHz disagreement).
    pub cpu_hz: u64,
    /// PLB clock, Hz (UART Lite C_CLK_FREQ 75 000 000, thesis).
    pub plb_hz: u64,
    /// Timer interrupt rate, Hz (thesis: 200).
    pub timer_hz: u64,
    /// First timer interrupt after power-up, ms (after the parts are set up) [unconfirmed].
    pub start_ms: u64,
    /// Interrupt to the first instruction of the handler, CPU cycles [estimate].
    pub isr_entry_cycles: u64,
    /// One PLB register access from the MicroBlaze, CPU cycles [estimate].
    pub plb_access_cycles: u64,
    /// Pre-processing per tick (axis selection, packet build), CPU cycles [estimate].
    pub preprocess_cycles: u64,
    /// NMEA handling per received byte (DMA1 already moved it), CPU cycles [estimate].
    pub nmea_cycles_per_byte: u64,
    /// Parsing one complete sentence into the packet's fields, CPU cycles [estimate].
    pub nmea_cycles_per_sentence: u64,
    /// xps_spi C_SCK_RATIO of SPI #1–#7 (PLB / SCK; even) : 54 → 1.389 MHz (thesis: 1.4 MHz).
    pub adxl_sck_ratio: u64,
    /// xps_spi C_SCK_RATIO of SPI #8 to the DSP (thesis: left blank) [unconfirmed].
    pub dsp_sck_ratio: u64,
    /// SS↓ to the first SCK edge, SCK half-periods [unconfirmed: xps_spi timing diagram not read].
    pub ss_setup_half_periods: u64,
    /// I²C #1 SCL low and high phases, ns (100 kHz, thesis).
    pub iic_scl_low_ns: u32,
    /// SCL high phase, ns.
    pub iic_scl_high_ns: u32,
    /// UART Lite C_BAUD_RATE (thesis: 19 200; 8N1).
    pub uart_baud: u32,
}

impl Default for Node {
    fn default() -> Self {
        Node {
            cpu_hz: 75_000_000,
            plb_hz: 75_000_000,
            timer_hz: 200,
            start_ms: 600,
            isr_entry_cycles: 30,
            plb_access_cycles: 6,
            preprocess_cycles: 600,
            nmea_cycles_per_byte: 20,
            nmea_cycles_per_sentence: 2_000,
            adxl_sck_ratio: 54,
            dsp_sck_ratio: 8,
            ss_setup_half_periods: 1,
            iic_scl_low_ns: 5_000,
            iic_scl_high_ns: 5_000,
            uart_baud: 19_200,
        }
    }
}

/// `[array]`: the seven ADXL345.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Array {
    /// Lever arm l of the six outer parts, m (not published) [unconfirmed].
    pub lever_arm_m: f64,
    /// BW_RATE written at set-up (0x0B: 200 Hz, thesis).
    pub bw_rate: u8,
    /// DATA_FORMAT written at set-up (0x0B: full resolution, ±16 g) [unconfirmed].
    pub data_format: u8,
    /// FIFO_CTL written at set-up (0x80: stream mode, thesis).
    pub fifo_ctl: u8,
    /// The parts' error preset (`ideal`, `adxl345`).
    pub preset: String,
    /// Seed of the parts' errors (part i uses seed + i).
    pub seed: u64,
    /// The seven parts, in the order the node reads them and the trace's `array1_*`…`array7_*`
    /// columns give their forces: the SPI core each sits on, its place and its channels; the
    /// navigation's inversion is built from the same places and channels.
    pub parts: Vec<ArrayPart>,
}

/// One `[[array.parts]]` entry: an ADXL345 of the array.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrayPart {
    /// The node's SPI core it sits on (`spi1` … `spi7`; its slave select is the core's own, thesis
    /// §4.3.3): one part per core.
    pub link: String,
    /// Its place in body axes (x forward, y left, z up), in units of `array.lever_arm_m`.
    pub position: [f64; 3],
    /// Its axes whose readings the node puts in the packet, in order (`x`, `y`, `z`): the parts'
    /// channels in turn are the packet's A₁…A₉.
    pub channels: Vec<String>,
}

/// The SPI cores the array's parts may sit on (#8 carries the packet to the DSP).
pub const ARRAY_LINKS: [&str; 7] = ["spi1", "spi2", "spi3", "spi4", "spi5", "spi6", "spi7"];

/// The parts of the array: seven, one part per core, the channels one in all nine.
pub const ARRAY_PARTS: usize = 7;

/// The axis names of `array.parts[].channels`.
const AXIS_NAMES: [&str; 3] = ["x", "y", "z"];

impl Default for Array {
    fn default() -> Self {
        // The thesis's layout (algorithms.md §4): u₁…u₆ at l sensing x, y, z, x, y, z on SPI #1–#6,
        // the triaxial part at the centre on SPI #7 giving A₇…A₉.
        use crate::firmware::gfnav::array::{POSITIONS, SENSING_AXIS};
        let mut parts: Vec<ArrayPart> = (0..6)
            .map(|i| ArrayPart {
                link: ARRAY_LINKS[i].into(),
                position: POSITIONS[i],
                channels: vec![AXIS_NAMES[SENSING_AXIS[i]].into()],
            })
            .collect();
        parts.push(ArrayPart {
            link: ARRAY_LINKS[6].into(),
            position: [0.0; 3],
            channels: vec!["x".into(), "y".into(), "z".into()],
        });
        Array {
            lever_arm_m: 0.1,
            bw_rate: 0x0B,
            data_format: 0x0B,
            fifo_ctl: 0x80,
            preset: "adxl345".into(),
            seed: 1,
            parts,
        }
    }
}

impl Array {
    /// The packet's nine channels (checked profile): (part index, axis) in order.
    pub fn channel_parts(&self) -> [(usize, usize); 9] {
        let mut out = [(0, 0); 9];
        let all = self.parts.iter().enumerate().flat_map(|(p, part)| {
            part.channels.iter().map(move |c| (p, AXIS_NAMES.iter().position(|a| a == c).unwrap_or(0)))
        });
        for (o, c) in out.iter_mut().zip(all) {
            *o = c;
        }
        out
    }

    /// The nine channels' geometry (checked profile): each one's part position and axis.
    pub fn channels(&self) -> [Channel; 9] {
        self.channel_parts().map(|(p, axis)| Channel { position: self.parts[p].position, axis })
    }

    /// The SPI core (0 = `spi1`) of each part (checked profile).
    pub fn cores(&self) -> Vec<usize> {
        self.parts.iter().map(|p| ARRAY_LINKS.iter().position(|l| *l == p.link).unwrap_or(0)).collect()
    }

    /// The navigation's inversion of the nine channels (checked profile: it exists).
    pub fn inverse(&self) -> Inverse {
        Inverse::new(&self.channels(), self.lever_arm_m).unwrap_or_else(|_| {
            Inverse::new(&crate::firmware::gfnav::array::thesis_channels(), self.lever_arm_m)
                .expect("the thesis's layout is regular")
        })
    }

    fn check(&self) -> std::result::Result<(), (String, String)> {
        let bad = |key: String, why: String| Err((key, why));
        if self.parts.len() != ARRAY_PARTS {
            return bad(
                "array.parts".into(),
                format!(
                    "{} parts: expected {ARRAY_PARTS}, one on each of the node's SPI cores #1–#7",
                    self.parts.len()
                ),
            );
        }
        let mut n = 0;
        for (i, p) in self.parts.iter().enumerate() {
            let key = |k: &str| format!("array.parts[{i}].{k}");
            if !ARRAY_LINKS.contains(&p.link.as_str()) {
                return bad(key("link"), format!("`{}`: expected one of {}", p.link, ARRAY_LINKS.join(", ")));
            }
            if let Some(j) = self.parts[..i].iter().position(|q| q.link == p.link) {
                return bad(
                    key("link"),
                    format!(
                        "`{}`: array.parts[{j}] is on it already (one part per core: its own slave select)",
                        p.link
                    ),
                );
            }
            if let Some(x) = p.position.iter().find(|x| !(x.is_finite() && x.abs() <= 10.0)) {
                return bad(key("position"), format!("{x}: expected finite values of at most 10 lever arms"));
            }
            for (k, c) in p.channels.iter().enumerate() {
                if !AXIS_NAMES.contains(&c.as_str()) {
                    return bad(key("channels"), format!("`{c}`: expected x, y or z"));
                }
                if p.channels[..k].contains(c) {
                    return bad(key("channels"), format!("`{c}` twice"));
                }
            }
            n += p.channels.len();
        }
        if n != 9 {
            return bad(
                "array.parts".into(),
                format!(
                    "{n} channels in all: the packet carries nine (A₁…A₉), the unknowns A, ω̇ and the rate products"
                ),
            );
        }
        match Inverse::new(&self.channels(), self.lever_arm_m) {
            Ok(_) => Ok(()),
            Err(e) => {
                let key = match e {
                    GeometryError::AlongLever(c) => format!("array.parts[{}].channels", self.channel_parts()[c].0),
                    GeometryError::Singular(_) => "array.parts".into(),
                };
                bad(key, format!("{e} (the positions and channels of array.parts)"))
            }
        }
    }
}

/// `[compass]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Compass {
    /// Command set: `later` or `earlier` (the thesis's Table 4.3).
    pub revision: String,
    /// Error model: `hmc6343` or `ideal`.
    pub errors: String,
    /// Seed of its errors.
    pub seed: u64,
    /// The correlation time T_ec of the compass's first-order Markov errors, s: one value for the
    /// part's model (`device::hmc6343::ErrorModel::tau_s`) and the compass sub-filter's states
    /// (`gfnav::federated::Scenario::compass_tau`). The thesis's (3.40) names T_ec but gives no value
    /// [unconfirmed: 100 s, the value its chapter-5 filter was given here].
    pub correlation_time_s: f64,
    /// Its 7-bit address on the node's I²C #1 (hmc6343.md: 0x19, the EEPROM's default; the part's
    /// address is an EEPROM setting).
    pub address: u32,
}

impl Default for Compass {
    fn default() -> Self {
        Compass {
            revision: "later".into(),
            errors: "hmc6343".into(),
            seed: 2,
            correlation_time_s: 100.0,
            address: u32::from(crate::device::hmc6343::ADDRESS),
        }
    }
}

impl Compass {
    /// Its 7-bit address (checked profile).
    pub fn address(&self) -> u8 {
        self.address as u8
    }
}

/// `[gps]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Gps {
    /// The receiver's line rate (19 200 on the board; HOLUX default 4 800).
    pub baud: u32,
    /// Fix epoch to the first character, ms [unconfirmed].
    pub latency_ms: u64,
    /// Horizontal CEP, m.
    pub cep_m: f64,
    /// Velocity 1σ, m/s.
    pub velocity_sigma_m_s: f64,
    /// Noise seed.
    pub seed: u64,
}

impl Default for Gps {
    fn default() -> Self {
        Gps { baud: 19_200, latency_ms: 200, cep_m: 5.0, velocity_sigma_m_s: 0.1, seed: 3 }
    }
}

/// `[dsp]`: the C6727B as far as the packets and the timing budget need it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Dsp {
    /// SYSCLK1, the CPU clock, Hz (thesis appendix B: 25 MHz × 18 / 2).
    pub cpu_hz: u64,
    /// SPI1 (slave) SCLK ceiling, Hz (thesis: 10 MHz).
    pub spi_max_hz: u64,
    /// dMAX: one SPI word to memory, CPU cycles [estimate].
    pub dmax_word_cycles: u64,
    /// The packet interrupt to the handler's first instruction, CPU cycles [estimate].
    pub isr_entry_cycles: u64,
    /// CRC check per word, CPU cycles [estimate: table-less bitwise loop, 8 × 2 cycles per byte].
    pub crc_cycles_per_word: u64,
    /// Age of a GPS fix when its packet reaches the DSP, ms [estimate: measured on the emulated
    /// node with the default GPS settings; see the TOML].
    pub gps_age_ms: f64,
    /// Rate recovery's singular threshold |D|, rad²/s² (gfnav `RateConfig::for_noise` of the
    /// counts' quantisation: see the TOML).
    pub min_denominator: f64,
    /// Per operation the navigation executes (counted from the running code, single precision),
    /// CPU cycles: ADDSP/SUBSP latency (GCC c6x.md `fp4`).
    pub add_cycles: u64,
    /// MPYSP latency (GCC c6x.md `mpy4`).
    pub mul_cycles: u64,
    /// Division: RCPSP + 2 Newton steps + MPYSP [estimate, c6727.md].
    pub div_cycles: u64,
    /// Square root: RSQRSP + 2 Newton steps + MPYSP [estimate, c6727.md: "sqrtsp similar"].
    pub sqrt_cycles: u64,
    /// Compare (CMPxSP) and the predicated use of its result [estimate: DP compares 2, c6727.md].
    pub compare_cycles: u64,
    /// Negation or absolute value: one .S instruction on the sign bit [estimate].
    pub neg_abs_cycles: u64,
    /// INTSP (int → float) [estimate: as ADDSP, 4].
    pub int_to_float_cycles: u64,
    /// A constant loaded (MVKL/MVKH pair or a load from the constant table) [estimate].
    pub constant_cycles: u64,
    /// sin or cos: TI MATHLIB C674x report, cosdp RTS column (the double figure: no single-precision
    /// figure found) [estimate].
    pub sin_cos_cycles: u64,
    /// atan: atandp RTS [estimate, as sin_cos_cycles].
    pub atan_cycles: u64,
    /// atan2: atan2dp RTS [estimate, as sin_cos_cycles].
    pub atan2_cycles: u64,
    /// asin: asindp RTS [estimate, as sin_cos_cycles].
    pub asin_cycles: u64,
}

impl Default for Dsp {
    fn default() -> Self {
        Dsp {
            cpu_hz: 225_000_000,
            spi_max_hz: 10_000_000,
            dmax_word_cycles: 10,
            isr_entry_cycles: 40,
            crc_cycles_per_word: 32,
            gps_age_ms: 305.0,
            min_denominator: 0.47,
            add_cycles: 4,
            mul_cycles: 4,
            div_cycles: 30,
            sqrt_cycles: 30,
            compare_cycles: 2,
            neg_abs_cycles: 1,
            int_to_float_cycles: 4,
            constant_cycles: 1,
            sin_cos_cycles: 330,
            atan_cycles: 566,
            atan2_cycles: 875,
            asin_cycles: 380,
        }
    }
}

impl GfsinsProfile {
    /// The profile in `text` (read from `origin`, named in errors), checked.
    pub fn parse(text: &str, origin: &str) -> Result<GfsinsProfile> {
        GfsinsProfile::parse_with(text, origin, &[])
    }

    /// The profile in `text` with `key=value` overrides (as `--set` gives them, the F28335
    /// profile's [`apply_override`](crate::profile::apply_override)), checked.
    pub fn parse_with(text: &str, origin: &str, overrides: &[String]) -> Result<GfsinsProfile> {
        let mut table: toml::Table =
            text.parse().map_err(|e: toml::de::Error| Error::Profile(format!("{origin}: {}", e.to_string().trim())))?;
        for ov in overrides {
            crate::profile::apply_override(&mut table, ov).map_err(|e| match e {
                Error::Profile(m) => Error::Profile(format!("{origin}: {m}")),
                other => other,
            })?;
        }
        let p: GfsinsProfile = serde_path_to_error::deserialize(toml::Value::Table(table))
            .map_err(|e| Error::Profile(format!("{origin}: `{}`: {}", e.path(), e.inner().message())))?;
        p.check(origin)?;
        Ok(p)
    }

    /// The profile with every default filled in, as TOML text.
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    fn check(&self, origin: &str) -> Result<()> {
        let bad = |key: &str, why: String| Err(Error::Profile(format!("{origin}: `{key}`: {why}")));
        let n = &self.node;
        if self.meta.board != "gfsins" {
            return bad(
                "meta.board",
                format!(
                    "\"{}\": expected \"gfsins\" (the one board with a schema of its own; an F28335 \
                     board's profile has no `meta.board`)",
                    self.meta.board
                ),
            );
        }
        for (key, v) in [("node.cpu_hz", n.cpu_hz), ("node.plb_hz", n.plb_hz), ("dsp.cpu_hz", self.dsp.cpu_hz)] {
            if !(1_000_000..=1_000_000_000).contains(&v) {
                return bad(key, format!("{v}: expected 1 MHz … 1 GHz"));
            }
        }
        if !(1..=10_000).contains(&n.timer_hz) || !n.plb_hz.is_multiple_of(n.timer_hz) {
            return bad("node.timer_hz", format!("{}: expected 1…10000 Hz dividing node.plb_hz", n.timer_hz));
        }
        for (key, r) in [("node.adxl_sck_ratio", n.adxl_sck_ratio), ("node.dsp_sck_ratio", n.dsp_sck_ratio)] {
            if r < 2 || r % 2 != 0 || r > 65_536 {
                return bad(key, format!("{r}: xps_spi's C_SCK_RATIO is an even number ≥ 2"));
            }
        }
        if n.iic_scl_low_ns == 0 || n.iic_scl_high_ns == 0 {
            return bad("node.iic_scl_low_ns", "SCL phases must be positive".into());
        }
        if n.uart_baud == 0 || self.gps.baud == 0 {
            return bad("node.uart_baud", "baud rates must be positive".into());
        }
        // Cost estimates: one operation of either processor costs at most the cycles of one period
        // (a single operation longer than that overruns every tick by itself, and an unbounded one
        // would make each tick's emulated time, and the parts' samples across it, run on without
        // end); the handler as a whole may still overrun, and is reported so (`overrun`).
        let node_period = n.cpu_hz / n.timer_hz;
        for (key, v) in [
            ("node.isr_entry_cycles", n.isr_entry_cycles),
            ("node.plb_access_cycles", n.plb_access_cycles),
            ("node.preprocess_cycles", n.preprocess_cycles),
            ("node.nmea_cycles_per_byte", n.nmea_cycles_per_byte),
            ("node.nmea_cycles_per_sentence", n.nmea_cycles_per_sentence),
        ] {
            if v > node_period {
                return bad(
                    key,
                    format!(
                        "{v} cycles: more than the node's whole {} µs period ({node_period} cycles at node.cpu_hz = {}); \
                         expected 0 … {node_period}",
                        1e6 / n.timer_hz as f64,
                        n.cpu_hz
                    ),
                );
            }
        }
        if n.ss_setup_half_periods > 64 {
            return bad(
                "node.ss_setup_half_periods",
                format!("{}: expected 0 … 64 SCK half-periods", n.ss_setup_half_periods),
            );
        }
        if n.start_ms > 3_600_000 {
            return bad("node.start_ms", format!("{} ms: expected 0 … 3 600 000 ms (an hour)", n.start_ms));
        }
        if self.gps.latency_ms > 10_000 {
            return bad("gps.latency_ms", format!("{} ms: expected 0 … 10 000 ms", self.gps.latency_ms));
        }
        let d = &self.dsp;
        let dsp_period = d.cpu_hz / n.timer_hz;
        for (key, v) in [
            ("dsp.dmax_word_cycles", d.dmax_word_cycles),
            ("dsp.isr_entry_cycles", d.isr_entry_cycles),
            ("dsp.crc_cycles_per_word", d.crc_cycles_per_word),
            ("dsp.add_cycles", d.add_cycles),
            ("dsp.mul_cycles", d.mul_cycles),
            ("dsp.div_cycles", d.div_cycles),
            ("dsp.sqrt_cycles", d.sqrt_cycles),
            ("dsp.compare_cycles", d.compare_cycles),
            ("dsp.neg_abs_cycles", d.neg_abs_cycles),
            ("dsp.int_to_float_cycles", d.int_to_float_cycles),
            ("dsp.constant_cycles", d.constant_cycles),
            ("dsp.sin_cos_cycles", d.sin_cos_cycles),
            ("dsp.atan_cycles", d.atan_cycles),
            ("dsp.atan2_cycles", d.atan2_cycles),
            ("dsp.asin_cycles", d.asin_cycles),
        ] {
            if v > dsp_period {
                return bad(
                    key,
                    format!(
                        "{v} cycles: more than the DSP's whole {} µs period ({dsp_period} cycles at dsp.cpu_hz = {}); \
                         expected 0 … {dsp_period}",
                        1e6 / n.timer_hz as f64,
                        d.cpu_hz
                    ),
                );
            }
        }
        let l = self.array.lever_arm_m;
        if !(l.is_finite() && l > 0.0 && l <= 1.0) {
            return bad("array.lever_arm_m", format!("{l}: expected 0 < l ≤ 1 m"));
        }
        if self.array.bw_rate & 0xE0 != 0 {
            return bad("array.bw_rate", format!("0x{:02X}: BW_RATE is 0x00–0x1F", self.array.bw_rate));
        }
        if self.array.fifo_ctl >> 6 != 0b10 {
            let v = self.array.fifo_ctl;
            return bad("array.fifo_ctl", format!("0x{v:02X}: the board runs the FIFO in stream mode (0x80–0xBF)"));
        }
        if crate::device::adxl345::ErrorPreset::by_name(&self.array.preset).is_none() {
            return bad("array.preset", format!("`{}`: known presets: ideal, adxl345", self.array.preset));
        }
        if let Err((key, why)) = self.array.check() {
            return bad(&key, why);
        }
        // The I²C links' rule (bus/i2c.rs): 0x00–0x07 and 0x78–0x7F are reserved.
        if !(0x08..=0x77).contains(&self.compass.address) {
            return bad(
                "compass.address",
                format!(
                    "0x{:X}: expected a 7-bit address 0x08…0x77 (0x00–0x07 and 0x78–0x7F are reserved)",
                    self.compass.address
                ),
            );
        }
        if !["later", "earlier"].contains(&self.compass.revision.as_str()) {
            return bad("compass.revision", format!("`{}`: expected later or earlier", self.compass.revision));
        }
        if !["hmc6343", "ideal"].contains(&self.compass.errors.as_str()) {
            return bad("compass.errors", format!("`{}`: expected hmc6343 or ideal", self.compass.errors));
        }
        let tau = self.compass.correlation_time_s;
        if !(tau.is_finite() && (1.0..=1e5).contains(&tau)) {
            return bad("compass.correlation_time_s", format!("{tau}: expected a correlation time of 1 … 100 000 s"));
        }
        if !(d.gps_age_ms.is_finite() && (0.0..=5_000.0).contains(&d.gps_age_ms)) {
            return bad("dsp.gps_age_ms", format!("{}: expected 0 … 5000 ms", d.gps_age_ms));
        }
        if !(d.min_denominator.is_finite() && d.min_denominator >= 0.0) {
            return bad("dsp.min_denominator", format!("{}: expected a finite value ≥ 0 rad²/s²", d.min_denominator));
        }
        let spi8 = n.plb_hz / n.dsp_sck_ratio;
        if spi8 > self.dsp.spi_max_hz {
            return bad(
                "node.dsp_sck_ratio",
                format!("SPI #8 at {spi8} Hz is above the DSP SPI1 slave's {} Hz", self.dsp.spi_max_hz),
            );
        }
        Ok(())
    }
}
