//! Property tests of the ADIS16407 as an SPI slave: random DIN words (reads, writes to every
//! register, bursts, GLOB_CMD commands, garbage), random frame timings (SCLK periods from 0 ps,
//! lengths 1…16, either polarity, gaps that may even go back in time), random CS edges and extreme
//! stimuli (±1e300, infinities, NaN) never panic, and the register file keeps its invariants after
//! every step:
//! - every readable register holds only its mask's bits (outputs: plus ND and EA);
//! - PROD_ID never changes, FLASH_CNT only through a GLOB_CMD flash update;
//! - SENS_AVG always holds a valid range and an M the range allows;
//! - a frame clocked with CS high or with a length other than 16 reads as `corrupt_word`;
//! - every frame is counted once.

use super::registers::{addr, Access, Format, REGISTERS};
use super::{Adis16407, Constant, GyroRange, ModelOptions, Physical};
use crate::bus::{FrameTiming, SpiSlave};
use crate::profile::{Device, TimingMode};
use crate::time::Ps;
use proptest::prelude::*;

/// One thing the host does to the slave.
#[derive(Debug, Clone)]
enum Op {
    /// Move CS `gap_ps` after the current time.
    Cs { low: bool, gap_ps: i64 },
    /// Clock one frame whose first edge is `gap_ps` after the current time (negative: before it).
    Frame { din: u16, gap_ps: i64, sclk_ps: Ps, bits: u8, mode: u8 },
}

/// Words a host sends: any word, reads and writes of real registers, the burst command, commands.
fn din() -> impl Strategy<Value = u16> {
    let reg = prop::sample::select(REGISTERS.iter().map(|r| r.addr).collect::<Vec<_>>());
    prop_oneof![
        3 => any::<u16>(),
        3 => reg.clone().prop_map(|a| u16::from(a) << 8),
        3 => (reg, any::<bool>(), any::<u8>())
            .prop_map(|(a, high, byte)| 0x8000 | u16::from(a | u8::from(high)) << 8 | u16::from(byte)),
        2 => Just(0x4200u16),
        1 => any::<u8>().prop_map(|cmd| 0x8000 | u16::from(addr::GLOB_CMD) << 8 | u16::from(cmd)),
    ]
}

fn op() -> impl Strategy<Value = Op> {
    // Gaps mostly of SPI scale (µs), sometimes of sample scale (ms), rarely backwards.
    let gap = prop_oneof![
        6 => 0i64..50_000_000,
        2 => 0i64..30_000_000_000,
        1 => -5_000_000i64..0,
    ];
    prop_oneof![
        1 => (any::<bool>(), gap.clone()).prop_map(|(low, gap_ps)| Op::Cs { low, gap_ps }),
        4 => (
            din(),
            gap,
            prop_oneof![3 => 250_000u64..3_000_000, 1 => 0u64..250_000, 1 => 3_000_000u64..50_000_000],
            prop_oneof![4 => Just(16u8), 1 => 1u8..=16],
            prop_oneof![4 => Just(3u8), 1 => 0u8..3],
        )
            .prop_map(|(din, gap_ps, sclk_ps, bits, mode)| Op::Frame { din, gap_ps, sclk_ps, bits, mode }),
    ]
}

/// Sensor values from ordinary to absurd.
fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        4 => -2000.0f64..2000.0,
        1 => prop_oneof![Just(1e300), Just(-1e300), Just(f64::INFINITY), Just(f64::NEG_INFINITY), Just(f64::NAN)],
        1 => any::<f64>(),
    ]
}

fn stimulus() -> impl Strategy<Value = Physical> {
    (prop::array::uniform3(value()), prop::array::uniform3(value()), value(), value()).prop_map(
        |(gyro_dps, accel_g, temp_c, supply_v)| Physical {
            gyro_dps,
            accel_g,
            temp_c,
            supply_v,
            ..Physical::powered_idle()
        },
    )
}

fn config() -> impl Strategy<Value = Device> {
    (any::<bool>(), prop::sample::select(vec![0x0402u32, 0x0202, 0x0104, 0x0400]), 0.0f64..200.0).prop_map(
        |(strict, sens_avg, reset_time_ms)| Device {
            timing_mode: if strict { TimingMode::Strict } else { TimingMode::Lenient },
            sens_avg,
            reset_time_ms,
            ..Device::default()
        },
    )
}

fn shift(t: Ps, gap: i64) -> Ps {
    t.saturating_add_signed(gap)
}

/// The invariants of the register file (see the module doc).
fn check_registers(d: &Adis16407, cfg: &Device) -> Result<(), TestCaseError> {
    for r in REGISTERS.iter().filter(|r| r.access != Access::W) {
        let w = d.peek(r.addr).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let allowed = if matches!(r.format, Format::Output(_)) { r.mask | 0xC000 } else { r.mask };
        prop_assert_eq!(w & !allowed, 0, "{} = 0x{:04X} outside its mask 0x{:04X}", r.name, w, allowed);
    }
    prop_assert_eq!(u32::from(d.peek(addr::PROD_ID).unwrap_or(0)), cfg.prod_id, "PROD_ID changed");
    let sens_avg = d.peek(addr::SENS_AVG).unwrap_or(0);
    let range = GyroRange::from_bits(sens_avg >> 8 & 7);
    prop_assert!(range.is_some(), "SENS_AVG = 0x{:04X}: no valid range", sens_avg);
    if let Some(range) = range {
        prop_assert!((sens_avg & 7) as u8 >= ModelOptions::default().min_m(range), "SENS_AVG = 0x{:04X}", sens_avg);
        prop_assert_eq!(range, d.gyro_range());
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn random_frames_never_panic_and_keep_the_registers_valid(
        cfg in config(),
        physical in stimulus(),
        ops in prop::collection::vec(op(), 1..120),
    ) {
        let mut d = Adis16407::new(&cfg).map_err(|e| TestCaseError::fail(e.to_string()))?;
        d.set_stimulus(Box::new(Constant(physical)));
        let mut t: Ps = 0;
        let mut frames = 0u64;
        // The slave powers up with CS deasserted; the host knows what it drove since.
        let mut cs_low = false;
        for op in &ops {
            let flash_cnt = d.peek(addr::FLASH_CNT).unwrap_or(0);
            let mut flash_update = false;
            match *op {
                Op::Cs { low, gap_ps } => {
                    t = shift(t, gap_ps);
                    d.set_cs(low, t);
                    cs_low = low;
                }
                Op::Frame { din, gap_ps, sclk_ps, bits, mode } => {
                    t = shift(t, gap_ps);
                    let last_edge = t.saturating_add(sclk_ps.saturating_mul(2 * u64::from(bits) - 1) / 2);
                    let timing = FrameTiming { index: 0, first_edge: t, last_edge, sclk_period: sclk_ps, bits, mode };
                    let dout = d.begin_frame(&timing);
                    d.end_frame(din, &timing);
                    frames += 1;
                    if !cs_low || bits != 16 {
                        prop_assert_eq!(u32::from(dout), cfg.corrupt_word, "frame with CS high or {} bits", bits);
                    }
                    flash_update = din >> 8 == 0x80 | u16::from(addr::GLOB_CMD) && din & 0x08 != 0;
                    t = last_edge;
                }
            }
            prop_assert_eq!(d.frames_clocked(), frames);
            let now_cnt = d.peek(addr::FLASH_CNT).unwrap_or(0);
            prop_assert!(now_cnt == flash_cnt || flash_update, "FLASH_CNT {} → {} without a flash update", flash_cnt, now_cnt);
            check_registers(&d, &cfg)?;
        }
        for e in d.events().events() {
            prop_assert!(!e.kind.is_empty() && e.kind.bytes().all(|b| b.is_ascii_lowercase() || b == b'_'), "{}", e.kind);
        }
    }
}
