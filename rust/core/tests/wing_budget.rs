//! The wing unit's 12-state filter in the F28335's timing budget (firmware_model/wing.toml): its
//! operations counted with the counting type and priced with the profile's cost table, beside the
//! reference stages the ISR runs in one update tick.

use sins_core::firmware::dcm;
use sins_core::firmware::wing::{FilterConfig, Mode, WingFilter, WingZero};
use sins_core::numerics::counter::count;
use sins_core::numerics::{Counted, QClass, Scalar};
use sins_core::profile::Profile;
use sins_core::timing::costs::CostTable;
use sins_core::timing::stages::{arith_for, location_factor, price, stage_costs};

fn model(name: &str) -> (String, String) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/");
    let path = format!("{dir}{name}");
    (std::fs::read_to_string(&path).unwrap(), path)
}

#[test]
fn the_wing_filter_fits_the_tick() {
    let (text, path) = model("wing.toml");
    let profile = Profile::from_toml(&text, &path, &[]).unwrap();
    let (costs_text, costs_path) = model(&profile.timing.costs);
    let table = CostTable::from_toml(&costs_text, &costs_path).unwrap();
    let arith = arith_for(profile.firmware.numeric, &table);
    let factor = location_factor(&profile, &table);

    let c = |x: f64, class| Counted::from_f64(x, class);
    // A consistent zero: the IMU tilted by q_wr, at rest (f^b = g · third row of C_b^w).
    let q: [f64; 4] = {
        let q = [0.99, 0.1, -0.05, 0.02];
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.map(|x| x / n)
    };
    let t = dcm(&q);
    let g = 9.80665;
    let zero = WingZero {
        q_wr: q.map(|x| c(x, QClass::Quat)),
        up_r: t[2].map(|x| c(x, QClass::Quat)),
        gyro_mean: [c(0.05, QClass::Rate), c(-0.03, QClass::Rate), c(0.02, QClass::Rate)],
    };
    let axis = [c(0.3, QClass::Quat), c(0.9, QClass::Quat), c(0.3, QClass::Quat)];
    let step_s = 0.008;
    let mut filter = WingFilter::new(&zero, axis, FilterConfig::adis16362(step_s, g, Mode::Full)).unwrap();
    let f = [c(0.98, QClass::Accel), c(-1.96, QClass::Accel), c(9.5, QClass::Accel)];
    // At rest (after the detector's 0.5 s): the rest measurements run too; then moving.
    let still = zero.gyro_mean;
    let f_rest = t[2].map(|x| c(x * g, QClass::Accel));
    for _ in 0..100 {
        filter.step(&still, &f_rest);
    }
    let (out, rest_ops) = count(|| filter.step(&still, &f_rest));
    assert!(out.at_rest, "the counting run must reach the rest branch");
    let moving = [c(0.4, QClass::Rate), c(-0.2, QClass::Rate), c(0.3, QClass::Rate)];
    let (out, moving_ops) = count(|| filter.step(&moving, &f));
    assert!(!out.at_rest);
    let moving_cycles = price(&moving_ops, arith, &table.instructions, factor);
    let rest_cycles = price(&rest_ops, arith, &table.instructions, factor);
    let wing = moving_cycles.max(rest_cycles);

    // The board's own costing (timing::stages, what `sins-fw budget` shows) counts the wing unit's update
    // from its costliest state (AttitudeUpdate::to_costliest): at least the filter's step at rest.
    let s = stage_costs(&profile, &table).unwrap();
    assert!(
        s.attitude.cycles >= rest_cycles,
        "attitude stage {} < the filter at rest {rest_cycles}",
        s.attitude.cycles
    );
    // The ISR's other stages in one update tick.
    let reference = s.entry + s.exit + s.decode.cycles + s.euler.cycles + s.navigation.cycles;
    let sysclk_hz = 150e6;
    let tick = (profile.timer.period_us * 1e-6 * sysclk_hz) as u64;
    eprintln!(
        "wing filter step ({:?}): {moving_cycles} cycles moving, {rest_cycles} at rest = {:.2} % of the {tick}-cycle \
         tick ({:.1} µs); other stages {reference} cycles ({:.2} %); together {:.2} %",
        profile.firmware.numeric,
        100.0 * wing as f64 / tick as f64,
        wing as f64 / sysclk_hz * 1e6,
        100.0 * reference as f64 / tick as f64,
        100.0 * (wing + reference) as f64 / tick as f64
    );
    // The SPI burst (11 words at 0.75 MHz: 11 · 16 / 0.75 MHz + tSTALL gaps ≈ 0.33 ms = 50 000 cycles,
    // the ISR waits for it) must fit beside them.
    let spi = 50_000;
    assert!(wing + reference + spi < tick, "wing {wing} + reference {reference} + SPI {spi} ≥ tick {tick}");
}
