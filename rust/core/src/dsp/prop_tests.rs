//! Property tests of SPI-A with GPIO57 and the ADIS16407 on the link: random sequences of register
//! writes and reads (every word offset 0…0x10, valid or not, any value), GPIO57 toggles and plain
//! waits at random non-decreasing times, after the published InitSpi, never panic, and:
//! - an access to an offset with no register is a `Register` error, never a panic;
//! - every register reads back within its implemented bits, and the FIFO levels never exceed 16;
//! - a time before the previous access is a `Register` error;
//! - the transaction and the bit level give the same register reads, the same slave frames and the
//!   same events (the two levels must agree wherever both apply).

use super::spi::{SpiA, SPIBRR, SPICCR, SPICTL, SPIDAT, SPIFFCT, SPIFFRX, SPIFFTX, SPIPRI, SPIRXBUF, SPISTS, SPITXBUF};
use crate::bus::{BusLevel, SpiLink};
use crate::device::{Adis16407, ReadRecord};
use crate::dsp::DspClocks;
use crate::error::Error;
use crate::profile::Profile;
use crate::time::Ps;
use proptest::prelude::*;

/// One thing the firmware does, `dt_ps` after the previous one.
#[derive(Debug, Clone)]
enum Op {
    Write { offset: u16, value: u16, dt_ps: Ps },
    Read { offset: u16, dt_ps: Ps },
    Gpio57 { high: bool, dt_ps: Ps },
    Wait { dt_ps: Ps },
}

/// Offsets the firmware uses most, then any offset up to one past the last register.
fn offset() -> impl Strategy<Value = u16> {
    prop_oneof![
        4 => prop::sample::select(vec![SPITXBUF, SPIRXBUF, SPISTS, SPIFFTX, SPIFFRX]),
        2 => prop::sample::select(vec![SPICCR, SPICTL, SPIBRR, SPIDAT, SPIFFCT, SPIPRI]),
        1 => 0u16..=0x10,
    ]
}

/// Values: any word, and the ones that keep the peripheral doing something (released, master, TALK).
fn value_for(offset: u16) -> BoxedStrategy<u16> {
    match offset {
        SPICCR => {
            prop_oneof![2 => prop::sample::select(vec![0x00CFu16, 0x008F, 0x004F, 0x00DF, 0x00C7]), 1 => any::<u16>()]
                .boxed()
        }
        SPICTL => {
            prop_oneof![2 => prop::sample::select(vec![0x0007u16, 0x000F, 0x0005, 0x0003]), 1 => any::<u16>()].boxed()
        }
        SPITXBUF => prop_oneof![2 => Just(0x4200u16), 3 => any::<u16>()].boxed(),
        _ => any::<u16>().boxed(),
    }
}

fn dt() -> impl Strategy<Value = Ps> {
    // Polling scale (tens of ns), frame scale (µs), sample scale (ms).
    prop_oneof![4 => 0u64..200_000, 4 => 0u64..40_000_000, 1 => 0u64..5_000_000_000]
}

fn op() -> impl Strategy<Value = Op> {
    // Mostly what a polling firmware does (write SPITXBUF, poll SPISTS, read SPIRXBUF, move CS low
    // more often than high), so that frames reach the slave; then anything at any offset.
    prop_oneof![
        5 => (value_for(SPITXBUF), dt()).prop_map(|(value, dt_ps)| Op::Write { offset: SPITXBUF, value, dt_ps }),
        4 => (prop::sample::select(vec![SPISTS, SPIRXBUF, SPIFFTX, SPIFFRX]), dt())
            .prop_map(|(offset, dt_ps)| Op::Read { offset, dt_ps }),
        2 => (offset(), dt()).prop_flat_map(|(offset, dt_ps)| value_for(offset)
            .prop_map(move |value| Op::Write { offset, value, dt_ps })),
        1 => (offset(), dt()).prop_map(|(offset, dt_ps)| Op::Read { offset, dt_ps }),
        2 => (prop::bool::weighted(0.3), dt()).prop_map(|(high, dt_ps)| Op::Gpio57 { high, dt_ps }),
        1 => dt().prop_map(|dt_ps| Op::Wait { dt_ps }),
    ]
}

fn is_register(offset: u16) -> bool {
    matches!(offset, 0x0..=0x2 | 0x4 | 0x6..=0xC | 0xF)
}

/// Bits a read of each register may show.
fn readable_bits(offset: u16) -> u16 {
    match offset {
        SPICCR => 0x00DF,
        SPICTL => 0x001F,
        SPISTS => 0x00E0,
        SPIBRR => 0x007F,
        SPIFFCT => 0x00FF,
        SPIPRI => 0x0030,
        _ => 0xFFFF,
    }
}

/// What one run showed: every read (value or error text), every slave frame, every event kind.
#[derive(Debug, PartialEq)]
struct Outcome {
    reads: Vec<Result<u16, String>>,
    frames: Vec<ReadRecord>,
    events: Vec<(Ps, &'static str, String)>,
}

fn run(profile: &Profile, ops: &[Op], level: BusLevel) -> Result<Outcome, TestCaseError> {
    let fail = |e: Error| TestCaseError::fail(e.to_string());
    let clocks = DspClocks::from_profile(&profile.clocks).map_err(fail)?;
    let mut slave = Adis16407::new(&profile.device).map_err(fail)?;
    slave.set_frame_log(true);
    let spi = SpiA::new(clocks.lspclk, profile.spi.start_latency_lspclk);
    let mut link = SpiLink::new(spi, slave, level);
    link.init_from_profile(&profile.spi, 0).map_err(fail)?;
    let mut t: Ps = 0;
    let mut reads = Vec::new();
    for op in ops {
        match *op {
            Op::Write { offset, value, dt_ps } => {
                t += dt_ps;
                let r = link.write(offset, value, t);
                prop_assert_eq!(r.is_ok(), is_register(offset), "write of 0x{:X}: {:?}", offset, r);
                if let Err(e) = r {
                    prop_assert!(matches!(e, Error::Register(_)), "{}", e);
                }
            }
            Op::Read { offset, dt_ps } => {
                t += dt_ps;
                let r = link.read(offset, t);
                prop_assert_eq!(r.is_ok(), is_register(offset), "read of 0x{:X}: {:?}", offset, r);
                if let Ok(v) = r {
                    prop_assert_eq!(v & !readable_bits(offset), 0, "offset 0x{:X} reads 0x{:04X}", offset, v);
                    if offset == SPIFFTX || offset == SPIFFRX {
                        prop_assert!((v >> 8) & 0x1F <= 16, "FIFO level in 0x{:04X}", v);
                    }
                }
                reads.push(r.map_err(|e| e.to_string()));
            }
            Op::Gpio57 { high, dt_ps } => {
                t += dt_ps;
                link.set_gpio57(high, t).map_err(fail)?;
            }
            Op::Wait { dt_ps } => {
                t += dt_ps;
                link.advance(t).map_err(fail)?;
            }
        }
    }
    // Time must not go backwards: an access before the last one is an error, not a panic.
    if t > 0 {
        let r = link.read(SPISTS, t - 1);
        prop_assert!(matches!(r, Err(Error::Register(_))), "{:?}", r);
    }
    let mut events: Vec<(Ps, &'static str, String)> =
        link.drain_events().into_iter().map(|e| (e.t_ps, e.kind, e.message)).collect();
    events.extend(link.slave_mut().drain_events().into_iter().map(|e| (e.t_ps, e.kind, e.message)));
    let frames = link.slave_mut().drain_frame_log();
    Ok(Outcome { reads, frames, events })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1024))]

    #[test]
    fn random_register_traffic_never_panics_and_levels_agree(
        lospcp in 0u32..=7,
        spibrr in prop_oneof![3 => Just(49u32), 1 => 0u32..=127],
        ops in prop::collection::vec(op(), 1..150),
    ) {
        let overrides = [format!("clocks.lospcp={lospcp}"), format!("spi.spibrr={spibrr}")];
        let profile = Profile::from_toml("", "proptest", &overrides).map_err(|e| TestCaseError::fail(e.to_string()))?;
        let transaction = run(&profile, &ops, BusLevel::Transaction)?;
        let bit = run(&profile, &ops, BusLevel::Bit)?;
        prop_assert_eq!(transaction, bit);
    }
}
