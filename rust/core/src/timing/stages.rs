//! Compute time of each firmware stage: the firmware's own generic code is run once with the
//! operation-counting numeric type, and the counts are priced with the cost table of the profile's
//! backend and code location. Nothing here is a hand tally: change the algorithm and the counts follow.
//! This layer sits above the firmware (it runs the firmware's code); the ISR takes the result as
//! plain data ([`StageCosts`], declared beside it in `firmware::isr`).

use crate::error::Result;
use crate::firmware::application::{app_kind, AppKind};
use crate::firmware::geomag_app::GeomagLoop;
use crate::firmware::isr::{StageCost, StageCosts};
use crate::firmware::schedule::{interpolate, MAX_SAMPLES};
use crate::firmware::{Firmware, GpsFix, Vec3};
use crate::numerics::counter::{count, count_as, snapshot, Counted, OpCounts};
use crate::profile::{CodeLocation, Numeric, Profile, Schedule};
use crate::timing::costs::{ArithCosts, CostTable, InstructionCosts, InterruptCosts};

/// One line of a stage's price: a number of operations of one kind at the unit cost of one entry of
/// the cost table. The budget report shows these lines so that every cycle can be traced to a count
/// and a table entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CostTerm {
    /// What is counted (an `OpCounts` field, or the interrupt step).
    pub op: &'static str,
    /// How many times it runs per stage execution.
    pub count: u64,
    /// The cost-table entry that prices it, `section.key` (e.g. `float.add`).
    pub key: &'static str,
    /// Cycles of one operation, from that entry.
    pub unit_cycles: u32,
    /// Whether the code-location factor applies (code the firmware runs; not the hardware's own
    /// context save or IRET).
    pub scaled: bool,
}

/// Cycles of a list of terms: the scaled ones summed, times the code-location factor, rounded up,
/// plus the unscaled ones.
pub fn price_terms(terms: &[CostTerm], factor: f64) -> u64 {
    let sum = |scaled: bool| -> u64 {
        terms.iter().filter(|t| t.scaled == scaled).map(|t| t.count * u64::from(t.unit_cycles)).sum()
    };
    (sum(true) as f64 * factor).ceil() as u64 + sum(false)
}

/// The price lines of a stage's operation counts with one backend's arithmetic costs; `section` is
/// the table section those costs come from (`float` or `iq`, see [`arith_for`]).
pub fn arith_terms(
    counts: &OpCounts,
    section: ArithSection,
    arith: &ArithCosts,
    instr: &InstructionCosts,
) -> [CostTerm; 23] {
    let c = counts;
    let k = |float: &'static str, iq: &'static str| match section {
        ArithSection::Float => float,
        ArithSection::Iq => iq,
    };
    let term = |op, count, key, unit_cycles| CostTerm { op, count, key, unit_cycles, scaled: true };
    [
        term("adds", c.adds, k("float.add", "iq.add"), arith.add),
        term("subs", c.subs, k("float.add", "iq.add"), arith.add),
        term("muls", c.muls, k("float.mul", "iq.mul"), arith.mul),
        term("divs", c.divs, k("float.div", "iq.div"), arith.div),
        term("sqrts", c.sqrts, k("float.sqrt", "iq.sqrt"), arith.sqrt),
        term("sins", c.sins, k("float.sin", "iq.sin"), arith.sin),
        term("coss", c.coss, k("float.cos", "iq.cos"), arith.cos),
        term("atans", c.atans, k("float.atan", "iq.atan"), arith.atan),
        term("atan2s", c.atan2s, k("float.atan2", "iq.atan2"), arith.atan2),
        term("asins", c.asins, k("float.asin", "iq.asin"), arith.asin),
        term("abs", c.abs, k("float.abs", "iq.abs"), arith.abs),
        term("negs", c.negs, k("float.neg", "iq.neg"), arith.neg),
        term("comparisons", c.comparisons, k("float.compare", "iq.compare"), arith.compare),
        term("int_to_float", c.int_to_float, k("float.int_to_float", "iq.int_to_float"), arith.int_to_float),
        term("constants", c.constants, k("float.constant", "iq.constant"), arith.constant),
        term("int_muls", c.int_muls, k("float.mul_i32", "iq.mul_i32"), arith.mul_i32),
        // The integer, memory and control work (the same prices on every backend).
        term("int_ops", c.int_ops, "instructions.int", instr.int),
        term("loads", c.loads, "instructions.load", instr.load + instr.data_wait),
        term("stores", c.stores, "instructions.store", instr.store),
        term("cond_branches", c.cond_branches, "instructions.cond_branch", instr.cond_branch),
        term("branches", c.branches, "instructions.branch", instr.branch),
        term("calls", c.calls, "instructions.call", instr.call),
        term("returns", c.returns, "instructions.ret", instr.ret),
    ]
}

/// The price lines of the interrupt entry: the hardware context save (not subject to the code
/// location) and the compiler's prologue.
pub fn entry_terms(i: &InterruptCosts) -> [CostTerm; 2] {
    [
        CostTerm {
            op: "context_save",
            count: 1,
            key: "interrupt.hw_context_save",
            unit_cycles: i.hw_context_save,
            scaled: false,
        },
        CostTerm { op: "prologue", count: 1, key: "interrupt.c_prologue", unit_cycles: i.c_prologue, scaled: true },
    ]
}

/// The price lines of the interrupt exit: epilogue and PIE acknowledge (code), IRET (hardware).
pub fn exit_terms(i: &InterruptCosts) -> [CostTerm; 3] {
    [
        CostTerm { op: "epilogue", count: 1, key: "interrupt.c_epilogue", unit_cycles: i.c_epilogue, scaled: true },
        CostTerm { op: "pie_ack", count: 1, key: "interrupt.pie_ack", unit_cycles: i.pie_ack, scaled: true },
        CostTerm { op: "iret", count: 1, key: "interrupt.iret", unit_cycles: i.iret, scaled: false },
    ]
}

/// Price operation counts with a backend's arithmetic costs, the instruction costs and the
/// code-location factor.
pub fn price(counts: &OpCounts, arith: &ArithCosts, instr: &InstructionCosts, factor: f64) -> u64 {
    // The section only names the entries; the cycles do not depend on it.
    price_terms(&arith_terms(counts, ArithSection::Float, arith, instr), factor)
}

/// Which arithmetic section of the cost table prices a backend.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArithSection {
    /// `[float]`: the C28x FPU.
    Float,
    /// `[iq]`: IQmath.
    Iq,
}

/// The section of the cost table that prices a backend: FPU for the float backends (f64 is priced as
/// the target's f32, the arithmetic the reference firmware ran), IQmath for `iq`.
pub fn arith_section(numeric: Numeric) -> ArithSection {
    match numeric {
        Numeric::Iq => ArithSection::Iq,
        Numeric::F64 | Numeric::C28xF32 | Numeric::C28xF32Rz => ArithSection::Float,
    }
}

/// The arithmetic costs of a backend (the section [`arith_section`] names).
pub fn arith_for(numeric: Numeric, table: &CostTable) -> &ArithCosts {
    match arith_section(numeric) {
        ArithSection::Iq => &table.iq,
        ArithSection::Float => &table.float,
    }
}

/// The code-location factor of a profile.
pub fn location_factor(profile: &Profile, table: &CostTable) -> f64 {
    match profile.firmware.code_location {
        CodeLocation::Ram => table.memory.ram_factor,
        CodeLocation::Flash => table.memory.flash_factor,
    }
}

/// Representative inputs for counting: a slowly turning, level board. The counts of the reference
/// algorithms do not depend on the values except through the branches of the published decode and
/// Euler tables; these inputs take the common branches (positive and negative in-range codes, a
/// first-quadrant attitude).
const WORDS: [u16; 6] = [0x0014, 0x3FF6, 0x0008, 0x0003, 0x3FFD, 0x012C];
const RATES: [[f64; 3]; 3] = [[0.010, -0.005, 0.020], [0.011, -0.004, 0.021], [0.012, -0.003, 0.022]];

/// Count and price every stage of the profile's firmware (the fixed-point firmware's operations for
/// `iq`, see [`count_as`]).
pub fn stage_costs(profile: &Profile, table: &CostTable) -> Result<StageCosts> {
    let iq = arith_section(profile.firmware.numeric) == ArithSection::Iq;
    match app_kind(&profile.firmware.application)? {
        AppKind::AdisBurst => count_as(iq, || counted_stage_costs(profile, table)),
        AppKind::Ads8344Geomag => count_as(iq, || geomag_stage_costs(profile, table)),
    }
}

/// The counting inputs of the geomagnetic–gyro firmware: gyro codes about ±100 °/s off null, a field
/// of (0.2, −0.1, 0.4) gauss, 25 °C, VREF/2 (codes at VREF = 5 V).
const GEOMAG_CODES: [u16; 8] = [34_000, 31_500, 33_100, 35_389, 31_457, 38_011, 9_830, 32_768];

/// The geomagnetic–gyro firmware's stages (`firmware/geomag_app.rs`): decode is one tick's codes
/// (volts, rates, compensation, field, temperature), attitude the three-sample rotation vector with
/// the roll aid, Euler the spin-body angles; no navigation, no interpolation.
fn geomag_stage_costs(profile: &Profile, table: &CostTable) -> Result<StageCosts> {
    let mut lp = GeomagLoop::<Counted>::new(profile, profile.timer.period_us * 1e-6)?;
    let (d, decode) = count(|| lp.decode(&GEOMAG_CODES));
    let dtheta = [d.1; 3];
    let (r, attitude) = count(|| lp.update(&dtheta, 0));
    r?;
    let (_, euler) = count(|| lp.euler());
    Ok(priced_stages(profile, table, [decode, attitude, euler, OpCounts::default(), OpCounts::default()]))
}

/// A stage's operations priced at `arith` with the code-location `factor`.
fn priced(counts: OpCounts, arith: &ArithCosts, instructions: &InstructionCosts, factor: f64) -> StageCost {
    StageCost { counts, cycles: price(&counts, arith, instructions, factor) }
}

/// The stages of a profile's firmware from their operations (decode, attitude, Euler, navigation,
/// interpolation), priced at the profile's arithmetic and code location, with the interrupt's entry
/// and exit.
fn priced_stages(profile: &Profile, table: &CostTable, counts: [OpCounts; 5]) -> StageCosts {
    let arith = arith_for(profile.firmware.numeric, table);
    let factor = location_factor(profile, table);
    let [decode, attitude, euler, navigation, interpolation] =
        counts.map(|c| priced(c, arith, &table.instructions, factor));
    StageCosts {
        entry: price_terms(&entry_terms(&table.interrupt), factor),
        exit: price_terms(&exit_terms(&table.interrupt), factor),
        decode,
        attitude,
        euler,
        navigation,
        interpolation,
    }
}

/// X/Y/Z MAGN_OUT of the counting inputs: 0.25, −0.05, −0.4 gauss (positive and negative codes).
const MAG_WORDS: [u16; 3] = [0x01F4, 0x3F9C, 0x3CE0];
/// X/Y/ZTEMP_OUT: 37.5 °C, 37.6 °C, 24.6 °C.
const TEMP_WORDS: [u16; 3] = [0x005C, 0x005D, 0x0FFD];
/// The GPS fix of the counting inputs (a board with a GPS moving at 20 m/s, course 30°).
const GPS_FIX: GpsFix = GpsFix { t_s: 0.0, latency_s: 0.0, ground_speed_mps: 20.0, course_deg: 30.0 };

/// The counting firmware of a profile at its representative inputs, ready for an update. It has a
/// GPS (whether or not the algorithm uses it).
struct Counting {
    fw: Firmware<Counted>,
    /// The rates of one update.
    rates: Vec<Vec3<Counted>>,
    /// The specific force.
    f_b: Vec3<Counted>,
}

fn counting_firmware(profile: &Profile) -> Result<Counting> {
    let mut fw = Firmware::<Counted>::new(profile)?;
    fw.attitude_to_costliest();
    fw.push_gps(&[GPS_FIX])?;
    fw.receive_gps(GPS_FIX.available_s());
    let lit = |x: f64| Counted(x);
    let rates: Vec<Vec3<Counted>> = (0..fw.rates_per_update()).map(|i| RATES[i % 3].map(lit)).collect();
    Ok(Counting { fw, rates, f_b: [lit(0.1), lit(-0.2), lit(9.8)] })
}

/// Decode one burst: the six inertial words, X/Y/Z MAGN_OUT when the algorithm takes the field and
/// X/Y/ZTEMP_OUT when it compensates the temperature.
fn decode_burst(fw: &mut Firmware<Counted>) {
    fw.decode(&WORDS);
    if fw.uses_magnetometer() {
        fw.decode_magnetometer(&MAG_WORDS);
    }
    if fw.uses_temperature() {
        fw.decode_temperature(&TEMP_WORDS);
    }
}

/// The operations of the attitude update's parts, in order, when the algorithm has parts (the DCM:
/// `rate`, `errors`, `pi`, `increment`, `matrix_update`, `renormalise`, `quaternion`), each priced
/// like a stage; the update's operations outside them (e.g. the earth-rate correction's rates) are
/// `other`. Empty for the algorithms without parts. The same counting as [`stage_costs`].
pub fn attitude_parts(profile: &Profile, table: &CostTable) -> Result<Vec<(&'static str, StageCost)>> {
    count_as(arith_section(profile.firmware.numeric) == ArithSection::Iq, || {
        let arith = arith_for(profile.firmware.numeric, table);
        let factor = location_factor(profile, table);
        let Counting { mut fw, rates, .. } = counting_firmware(profile)?;
        decode_burst(&mut fw);
        let mut marks: Vec<(&'static str, OpCounts)> = Vec::new();
        let (result, total) =
            count(|| fw.update_attitude_marked(&rates, Some(&mut |name| marks.push((name, snapshot())))));
        result?;
        let mut parts = Vec::with_capacity(marks.len() + 1);
        let mut before = OpCounts::default();
        for (name, at) in marks.iter().copied() {
            parts.push((name, at - before));
            before = at;
        }
        let rest = total - parts.iter().fold(OpCounts::default(), |a, (_, c)| a + *c);
        if !parts.is_empty() && rest.total() > 0 {
            parts.push(("other", rest));
        }
        Ok(parts.into_iter().map(|(n, counts)| (n, priced(counts, arith, &table.instructions, factor))).collect())
    })
}

fn counted_stage_costs(profile: &Profile, table: &CostTable) -> Result<StageCosts> {
    let Counting { mut fw, rates, f_b } = counting_firmware(profile)?;
    let lit = |x: f64| Counted(x);

    let (_, decode) = count(|| decode_burst(&mut fw));
    let (attitude, attitude_counts) = count(|| fw.update_attitude(&rates));
    attitude?;
    let (_, euler) = count(|| fw.euler());
    // The target's navigation computes the earth rates itself (the emulated firmware reuses the
    // attitude update's, an emulation shortcut).
    fw.forget_earth_rates();
    let (_, navigation) = count(|| fw.navigate(&f_b));
    // The `endpoint` schedule's interpolation of the samples between an update's two ends.
    let (_, interpolation) = count(|| {
        if profile.firmware.schedule == Schedule::Endpoint {
            let mut inner = [[lit(0.0); 3]; MAX_SAMPLES - 2];
            let interior = &mut inner[..fw.rates_per_update() - 2];
            interpolate(&RATES[0].map(lit), &RATES[2].map(lit), interior);
        }
    });

    let navigation = if profile.firmware.navigation { navigation } else { OpCounts::default() };
    Ok(priced_stages(profile, table, [decode, attitude_counts, euler, navigation, interpolation]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> CostTable {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/c28x-costs.toml");
        CostTable::from_toml(&std::fs::read_to_string(path).unwrap(), "c28x-costs.toml").unwrap()
    }

    /// The op counts of one reference RK4 step are a property of the published code: pinned here so
    /// that any change to the algorithm's operation order is deliberate.
    #[test]
    fn rk4_step_counts_are_pinned() {
        let p = Profile::default();
        let s = stage_costs(&p, &table()).unwrap();
        let c = s.attitude.counts;
        // Pinned from the first run of this test (see the commit); any change must be explained.
        assert_eq!((c.adds + c.subs, c.muls, c.divs, c.sqrts), PINNED_RK4, "{c:?}");
        assert!(s.attitude.cycles > 0);
    }

    const PINNED_RK4: (u64, u64, u64, u64) = (113, 167, 12, 1);

    fn dcm_profile(yaw: crate::profile::YawReference) -> Profile {
        let mut p = Profile::default();
        p.firmware.algorithm = "dcm".into();
        p.firmware.dcm.yaw_reference = yaw;
        p.firmware.dcm.centripetal = true;
        p
    }

    /// The DCM's parts in the budget: the matrix update as published (27 multiplications, 18 additions,
    /// on every backend's count), and the parts add up to the attitude stage, operation by operation.
    #[test]
    fn dcm_parts_price_the_published_matrix_update_and_add_up_to_the_stage() {
        let t = table();
        for yaw in [crate::profile::YawReference::Magnetometer, crate::profile::YawReference::Gps] {
            let mut p = dcm_profile(yaw);
            for numeric in [Numeric::C28xF32, Numeric::Iq] {
                p.firmware.numeric = numeric;
                let stage = stage_costs(&p, &t).unwrap().attitude;
                let parts = attitude_parts(&p, &t).unwrap();
                let names: Vec<_> = parts.iter().map(|(n, _)| *n).collect();
                assert_eq!(
                    names,
                    ["rate", "errors", "pi", "increment", "matrix_update", "renormalise", "quaternion"],
                    "{yaw:?} {numeric:?}"
                );
                let m = parts[4].1.counts;
                assert_eq!((m.muls, m.adds), (27, 18), "{m:?}");
                let sum = parts.iter().fold(OpCounts::default(), |a, (_, c)| a + c.counts);
                assert_eq!(sum, stage.counts, "{yaw:?} {numeric:?}");
                assert!(parts
                    .iter()
                    .all(|(_, c)| c.cycles > 0
                        && c.cycles == price(&c.counts, arith_for(numeric, &t), &t.instructions, 1.0)));
            }
        }
        // The open-loop algorithms have no parts.
        assert!(attitude_parts(&Profile::default(), &t).unwrap().is_empty());
    }

    /// The three MAGN_OUT decodes are charged to every burst's decode when the DCM takes the field
    /// (float: per word one I32TOF32 and one MPYF32 by the LSB).
    #[test]
    fn magnetometer_decode_is_charged_when_the_dcm_uses_it() {
        let t = table();
        let plain = stage_costs(&dcm_profile(crate::profile::YawReference::Gps), &t).unwrap().decode;
        let with_mag = stage_costs(&dcm_profile(crate::profile::YawReference::Magnetometer), &t).unwrap().decode;
        assert!(with_mag.cycles > plain.cycles, "{with_mag:?} vs {plain:?}");
        let d = with_mag.counts - plain.counts;
        assert_eq!((d.int_to_float, d.muls), (3, 3), "{d:?}");
        assert_eq!(plain, stage_costs(&Profile::default(), &t).unwrap().decode);
    }

    /// The published decode's integer work as its C executes it on the counting words (channels 1
    /// and 4 negative, the others positive): the call with its argument; per channel the mask loop's
    /// load, AND, store and pass, the range loop's pass, the load and first test; the positive
    /// channels' jump over the negative branch; the negative ones' second test, XOR, ADD and store.
    #[test]
    fn the_published_decode_counts_its_integer_work() {
        let t = table();
        let d = stage_costs(&Profile::default(), &t).unwrap().decode;
        let c = d.counts;
        assert_eq!((c.int_ops, c.loads, c.stores), (1 + 6 * (3 + 2 + 1) + 2 * 3, 12, 6 + 2), "{c:?}");
        assert_eq!((c.cond_branches, c.branches, c.calls, c.returns), (6 * 3 + 2, 4, 1, 1), "{c:?}");
        // Priced from [instructions]: 211 cycles beside the 54 of the arithmetic.
        let i = &t.instructions;
        let work = c.int_ops * u64::from(i.int)
            + c.loads * u64::from(i.load + i.data_wait)
            + c.stores * u64::from(i.store)
            + c.cond_branches * u64::from(i.cond_branch)
            + c.branches * u64::from(i.branch)
            + c.calls * u64::from(i.call)
            + c.returns * u64::from(i.ret);
        assert_eq!((work, d.cycles), (211, 211 + 54));
    }

    #[test]
    fn counts_are_deterministic() {
        let p = Profile::default();
        assert_eq!(stage_costs(&p, &table()).unwrap(), stage_costs(&p, &table()).unwrap());
    }

    #[test]
    fn iq_costs_more_than_float_with_the_same_counts() {
        let t = table();
        let f = stage_costs(&Profile::default(), &t).unwrap();
        let mut p = Profile::default();
        p.firmware.numeric = Numeric::Iq;
        let q = stage_costs(&p, &t).unwrap();
        assert_eq!(f.attitude.counts, q.attitude.counts);
        assert!(q.attitude.cycles > f.attitude.cycles);
    }

    #[test]
    fn decode_counts_follow_the_backend_firmware() {
        let t = table();
        let float = stage_costs(&Profile::default(), &t).unwrap().decode.counts;
        // Published code per channel: I32TOF32, MPYF32 by the LSB, MPYF32 by π/180 or g.
        assert_eq!((float.int_to_float, float.muls, float.int_muls), (6, 12, 0), "{float:?}");
        let mut p = Profile::default();
        p.firmware.numeric = Numeric::Iq;
        let iq = stage_costs(&p, &t).unwrap().decode.counts;
        // IQ: one _IQmpyI32 by the folded constant.
        assert_eq!((iq.int_to_float, iq.muls, iq.int_muls), (0, 0, 6), "{iq:?}");
        assert_eq!(float.subs, iq.subs, "the same negative-code branches");
    }

    /// Every profile variant whose price the budget explains: both arithmetic sections, both code
    /// locations.
    fn variants() -> Vec<Profile> {
        let mut out = Vec::new();
        for numeric in [Numeric::C28xF32, Numeric::Iq] {
            for location in [CodeLocation::Ram, CodeLocation::Flash] {
                let mut p = Profile::default();
                p.firmware.numeric = numeric;
                p.firmware.code_location = location;
                out.push(p);
            }
        }
        out
    }

    #[test]
    fn price_lines_add_up_to_the_stage_cycles_and_cover_every_counted_op() {
        let t = table();
        for p in variants() {
            let s = stage_costs(&p, &t).unwrap();
            let f = location_factor(&p, &t);
            let section = arith_section(p.firmware.numeric);
            let arith = arith_for(p.firmware.numeric, &t);
            for stage in [s.decode, s.attitude, s.euler, s.navigation, s.interpolation] {
                let terms = arith_terms(&stage.counts, section, arith, &t.instructions);
                assert_eq!(price_terms(&terms, f), stage.cycles);
                // No operation kind the counter tallies is left unpriced.
                assert_eq!(terms.iter().map(|t| t.count).sum::<u64>(), stage.counts.total());
            }
            assert_eq!(price_terms(&entry_terms(&t.interrupt), f), s.entry);
            assert_eq!(price_terms(&exit_terms(&t.interrupt), f), s.exit);
        }
    }

    #[test]
    fn every_price_line_names_an_entry_of_the_table_with_its_value() {
        let text =
            std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/c28x-costs.toml"))
                .unwrap();
        let raw: toml::Table = toml::from_str(&text).unwrap();
        let t = table();
        let counts = stage_costs(&Profile::default(), &t).unwrap().attitude.counts;
        let lines = [
            arith_terms(&counts, ArithSection::Float, &t.float, &t.instructions).to_vec(),
            arith_terms(&counts, ArithSection::Iq, &t.iq, &t.instructions).to_vec(),
            entry_terms(&t.interrupt).to_vec(),
            exit_terms(&t.interrupt).to_vec(),
        ];
        for term in lines.concat() {
            let (section, key) = term.key.split_once('.').unwrap();
            let value = raw[section][key].as_integer().unwrap();
            assert_eq!(value, i64::from(term.unit_cycles), "{}", term.key);
        }
    }

    #[test]
    fn flash_is_slower_than_ram() {
        let t = table();
        let ram = stage_costs(&Profile::default(), &t).unwrap();
        let mut p = Profile::default();
        p.firmware.code_location = CodeLocation::Flash;
        let flash = stage_costs(&p, &t).unwrap();
        assert!(flash.attitude.cycles > ram.attitude.cycles);
        assert_eq!(flash.attitude.counts, ram.attitude.counts);
    }
}
