//! Run the full pipeline in Rust alone (no Python) on a coning input, for profiling with perf or
//! callgrind: `cargo run --release --example pipeline -- [seconds] [override ...]`.
//! Prints emulated 8 ms cycles per second of CPU time.

use sins_core::device::Physical;
use sins_core::emulator::{Emulator, Progress};
use sins_core::numerics;
use sins_core::profile::{Numeric, Profile};
use sins_core::timing::costs::CostTable;

fn main() {
    let mut args = std::env::args().skip(1);
    let seconds: f64 = args.next().map_or(120.0, |s| s.parse().expect("seconds"));
    let overrides: Vec<String> = args.collect();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/");
    let text = std::fs::read_to_string(format!("{root}reference.toml")).unwrap();
    let profile = Profile::from_toml(&text, "reference.toml", &overrides).unwrap();
    let costs_text = std::fs::read_to_string(format!("{root}c28x-costs.toml")).unwrap();
    let costs = CostTable::from_toml(&costs_text, "c28x-costs.toml").unwrap();
    // Classical coning, 1° half-angle at 10 Hz, level.
    let n = (seconds * 819.2) as usize + 2;
    let (a, w) = (1f64.to_radians(), 2.0 * std::f64::consts::PI * 10.0);
    let t: Vec<f64> = (0..n).map(|i| i as f64 / 819.2).collect();
    let p: Vec<Physical> = t
        .iter()
        .map(|&t| {
            let r = a * w;
            let gyro_dps = [(r * (w * t).cos()).to_degrees(), (r * (w * t).sin()).to_degrees(), 0.0];
            Physical { gyro_dps, accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() }
        })
        .collect();
    let start = std::time::Instant::now();
    // The IQ backend's Q formats are the profile's `[iq]` section, set for the run's thread.
    let cycles = numerics::iq::with_formats(&profile.iq, || match profile.firmware.numeric {
        Numeric::F64 => run::<f64>(&profile, &costs, &t, p),
        Numeric::C28xF32 => run::<numerics::C28xF32Rn>(&profile, &costs, &t, p),
        Numeric::C28xF32Rz => run::<numerics::C28xF32Rz>(&profile, &costs, &t, p),
        Numeric::Iq => run::<numerics::Iq>(&profile, &costs, &t, p),
    })
    .unwrap();
    let dt = start.elapsed().as_secs_f64();
    println!(
        "{cycles} cycles in {dt:.3} s: {:.0} cycles/s, {:.3} µs/cycle",
        cycles as f64 / dt,
        dt * 1e6 / cycles as f64
    );
}

fn run<T: numerics::Scalar>(profile: &Profile, costs: &CostTable, t: &[f64], p: Vec<Physical>) -> usize {
    let mut emu = Emulator::<T>::new(profile, costs).unwrap();
    emu.push_input(t, p).unwrap();
    emu.end_input();
    // A run longer than a block (131 s) comes in several calls; the output is taken at the end.
    while emu.run().unwrap() != Progress::Finished {}
    emu.take_output().cycles.len()
}
