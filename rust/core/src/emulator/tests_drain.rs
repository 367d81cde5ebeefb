//! The event drain: a part's own events (rule violations it finds on the wires) reach the run's
//! events through its link (`SpiSlave::drain_events`, collected by `Emulator::collect_events`).

use super::tests::costs;
use super::*;

/// The geomagnetic–gyro board with SPIBRR = 3 (LSPCLK 37.5 MHz / 4 = 9.375 MHz): the ADS8344 on
/// the acquisition chip select finds DCLK above its 2.4 MHz limit in its own frame check, and
/// that event (its message starts with "ADS8344: DCLK") is in the run's output, at the time of the
/// first frame's first edge. Without the drain of the part's events (`collect_events`' call of
/// the sensor link's slave `drain_events`) the run has none of them: this test fails.
#[test]
fn a_part_s_own_violation_reaches_the_run_s_events() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/geomag.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let profile = Profile::from_toml(&text, "geomag.toml", &["spi.spibrr=3".into()]).unwrap();
    let mut emu = Emulator::<f64, AnalogBoard, GeomagApp<f64>>::geomag(&profile, &costs()).unwrap();
    let n = 200;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
    emu.push_input(&t, vec![Physical { accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() }; n]).unwrap();
    emu.end_input();
    assert_eq!(emu.run().unwrap(), Progress::Finished);
    let out = emu.take_output();
    let from_part: Vec<&Event> =
        out.events.iter().filter(|e| e.kind == "sclk_too_fast" && e.message.starts_with("ADS8344: DCLK")).collect();
    assert!(!from_part.is_empty(), "no ADS8344 frame event in the run: {:?}", &out.events[..out.events.len().min(5)]);
    // 9.375 MHz from the SCLK period in whole ps (106 667 ps): off by at most one ps in 106 666.
    let f = from_part[0].measured.unwrap();
    assert!((f - 9.375e6).abs() <= 9.375e6 / 106_666.0, "{f}");
    assert!(out.events.windows(2).all(|w| w[0].t_ps <= w[1].t_ps), "in time order");
}
