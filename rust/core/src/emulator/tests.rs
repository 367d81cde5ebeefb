//! End-to-end checks of the emulated board: the published acquisition on the reference profile.

use super::*;
use crate::bus::link::LinkRecord;
use crate::time::{s_to_ps, PS_PER_S};

fn costs() -> CostTable {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/c28x-costs.toml");
    CostTable::from_toml(&std::fs::read_to_string(path).unwrap(), "c28x-costs.toml").unwrap()
}

/// A level board turning at `rate_dps` about z, sampled at 819.2 Hz, for `seconds`.
fn constant_rate(seconds: f64, rate_dps: [f64; 3]) -> (Vec<f64>, Vec<Physical>) {
    let n = (seconds * 819.2).ceil() as usize + 2;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / 819.2).collect();
    let p = Physical { gyro_dps: rate_dps, accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() };
    (t, vec![p; n])
}

fn run<T: Scalar>(profile: &Profile, seconds: f64, rate: [f64; 3]) -> Output {
    let mut emu = Emulator::<T>::new(profile, &costs()).unwrap();
    let (t, p) = constant_rate(seconds, rate);
    emu.push_input(&t, p).unwrap();
    emu.end_input();
    assert_eq!(emu.run().unwrap(), Progress::Finished);
    emu.take_output()
}

fn reference_f64() -> Profile {
    let mut p = Profile::default();
    p.firmware.numeric = crate::profile::Numeric::F64;
    p.firmware.earth_rate = false;
    p
}

#[test]
fn reference_burst_reads_are_clean_and_take_at_least_320_us() {
    let out = run::<f64>(&reference_f64(), 1.0, [0.0, 0.0, 10.0]);
    assert!(out.events.is_empty(), "{:?}", &out.events[..out.events.len().min(3)]);
    // 1 s of 4 ms ticks: ticks 1…250.
    assert_eq!(out.budget.len(), 250);
    assert_eq!(out.reads.len(), 250);
    for r in &out.reads {
        let burst = r.t_end_ps - r.t_start_ps;
        assert!(burst >= 320 * PS_PER_S / 1_000_000 - 21_333_334, "burst {burst} ps");
        // SUPPLY_OUT of a 5 V supply: 0x814 with ND set from the second read on.
        assert_eq!(r.words[1] & 0x3FFF, 0x0814);
        // +10 °/s about z = 200 LSB; ND set.
        assert_eq!(r.words[4], 0x8000 | 200, "ZGYRO_OUT");
        assert!((r.rate[2] - 10f64.to_radians()).abs() < 1e-12);
        assert!(r.age_ps <= s_to_ps(1.0 / 819.2));
    }
}

#[test]
fn half_step_schedule_integrates_a_constant_rate() {
    let out = run::<f64>(&reference_f64(), 10.0, [0.0, 0.0, 10.0]);
    // Steps every 8 ms from the third tick: (2500 - 1) / 2 steps.
    assert_eq!(out.cycles.len(), 1249);
    let last = out.cycles.last().unwrap();
    // The device's first sample is at t = 0 and the firmware starts integrating at its first read:
    // 1249 steps × 8 ms × 10 °/s.
    let want = 1249.0 * 0.008 * 10.0;
    assert!((last.euler_deg[2] - want).abs() < 1e-9, "yaw {} want {want}", last.euler_deg[2]);
}

#[test]
fn sample_age_varies_and_is_bounded_by_the_sample_period() {
    let out = run::<f64>(&reference_f64(), 2.0, [0.0; 3]);
    let ages: std::collections::BTreeSet<u64> = out.reads.iter().map(|r| r.age_ps).collect();
    assert!(ages.len() > 10, "4 ms reads against a 1.2207 ms sample clock give many ages");
    assert!(ages.iter().all(|&a| a < s_to_ps(1.0 / 819.2)));
}

#[test]
fn budget_of_one_attitude_solution_is_about_0_35_ms() {
    let out = run::<crate::numerics::C28xF32Rn>(&Profile::default(), 1.0, [1.0, 2.0, 3.0]);
    let step = out.budget.iter().find(|b| b.step).unwrap();
    let spi = step.spi_end_ps - step.spi_start_ps;
    let solution = step.euler_end_ps - step.spi_start_ps;
    assert!(spi >= s_to_ps(320e-6), "SPI {spi} ps");
    let ms = solution as f64 / 1e9;
    assert!((0.35 * 0.85..=0.35 * 1.15).contains(&ms), "solution {ms} ms");
}

#[test]
fn a_short_timer_period_overruns_and_reports_each_tick() {
    let mut p = reference_f64();
    p.timer.period_us = 300.0;
    let out = run::<f64>(&p, 0.05, [0.0; 3]);
    let overruns = out.events.iter().filter(|e| e.kind == "overrun" || e.kind == "tick_lost").count();
    assert!(overruns > 0);
    assert!(out.budget.iter().any(|b| b.overrun));
}

#[test]
fn bit_level_and_transaction_level_agree_to_the_picosecond() {
    let a = run::<f64>(&reference_f64(), 0.5, [3.0, -2.0, 1.0]);
    let mut p = reference_f64();
    p.spi.level = crate::profile::BusLevel::Bit;
    let b = run::<f64>(&p, 0.5, [3.0, -2.0, 1.0]);
    assert_eq!(a.budget, b.budget);
    assert_eq!(a.reads, b.reads);
    assert_eq!(a.cycles, b.cycles);
}

#[test]
fn spibrr_9_reports_sclk_violations_in_the_run() {
    let mut p = reference_f64();
    p.spi.spibrr = 9;
    let out = run::<f64>(&p, 0.1, [0.0; 3]);
    assert!(out.events.iter().any(|e| e.kind == "sclk_too_fast"));
}

#[test]
fn the_bus_log_covers_only_the_ticks_it_was_on_for() {
    let mut emu = Emulator::<f64>::new(&reference_f64(), &costs()).unwrap();
    let (t, p) = constant_rate(0.1, [0.0; 3]);
    // 0.1 s of input runs ticks 1…24 (a tick runs once the input covers its whole period).
    let half = t.partition_point(|&x| x < 0.05);
    emu.push_input(&t[..half], p[..half].to_vec()).unwrap();
    assert_eq!(emu.run().unwrap(), Progress::NeedInput);
    let ran = emu.take_output().budget.len();
    emu.enable_bus_log();
    emu.push_input(&t[half..], p[half..].to_vec()).unwrap();
    emu.run().unwrap();
    let log = emu.stop_bus_log();
    let out = emu.take_output();
    emu.end_input();
    emu.run().unwrap();
    assert!(emu.take_bus_log().is_empty(), "stopped: nothing more is recorded");
    // Per tick: CS low, the 15 frames of the burst, CS high.
    assert_eq!(log.len(), out.budget.len() * (BURST_FRAMES + 2), "{ran} ticks before the log");
    let frames: Vec<_> =
        log.iter().filter_map(|r| if let LinkRecord::Frame(f) = r { Some(*f) } else { None }).collect();
    assert_eq!(frames.len(), out.reads.len() * BURST_FRAMES);
    for (burst, read) in frames.chunks(BURST_FRAMES).zip(&out.reads) {
        assert_eq!(burst[0].timing.first_edge, read.t_start_ps);
        assert_eq!(burst[0].din, 0x4200, "the burst command");
        let rx: Vec<u16> = burst.iter().map(|f| f.master_rx).collect();
        assert_eq!(rx, read.words.to_vec(), "the words the firmware stored are the words on the bus");
    }
}
