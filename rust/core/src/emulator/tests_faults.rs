//! Each injected fault through the whole board: what the firmware then reads, what it computes (the
//! published code has no error handling), and the events that say what happened and when.

use super::tests::{costs, reference_f64};
use super::*;
use crate::device::{encode, Channel, GyroRange};
use crate::time::s_to_ps;

/// The reference board (f64, no earth rate) with `faults` (a TOML array) on `input(t)`, 819.2 rows/s.
fn run_with(faults: &str, extra: &[&str], seconds: f64, input: impl Fn(f64) -> Physical) -> Output {
    let mut overrides = vec!["firmware.numeric=\"f64\"".to_string(), "firmware.earth_rate=false".to_string()];
    overrides.push(format!("faults.list={faults}"));
    overrides.extend(extra.iter().map(|s| s.to_string()));
    let p = Profile::from_toml("", "faults-test", &overrides).unwrap();
    assert_eq!((p.firmware.numeric, p.firmware.earth_rate), (reference_f64().firmware.numeric, false));
    let mut emu = Emulator::<f64>::new(&p, &costs()).unwrap();
    let n = (seconds * 819.2).ceil() as usize + 2;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / 819.2).collect();
    let rows = t.iter().map(|&t| input(t)).collect();
    emu.push_input(&t, rows).unwrap();
    emu.end_input();
    assert_eq!(emu.run().unwrap(), Progress::Finished);
    emu.take_output()
}

fn level(rate_dps: [f64; 3]) -> impl Fn(f64) -> Physical {
    move |_| Physical { gyro_dps: rate_dps, accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() }
}

fn count(out: &Output, kind: &str) -> usize {
    out.events.iter().filter(|e| e.kind == kind).count()
}

/// The `fault_injected` events: (time, message).
fn injected(out: &Output) -> Vec<(Ps, String)> {
    out.events.iter().filter(|e| e.kind == "fault_injected").map(|e| (e.t_ps, e.message.clone())).collect()
}

const FIELD: u16 = 0x3FFF;
const ND: u16 = 0x8000;
const EA: u16 = 0x4000;

/// Rotation angle between two quaternions, degrees.
fn angle_deg(a: [f64; 4], b: [f64; 4]) -> f64 {
    let dot: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
    2.0 * dot.abs().min(1.0).acos().to_degrees()
}

#[test]
fn a_stuck_axis_keeps_its_word_and_the_attitude_misses_the_turn() {
    // Yaw rate ramping at 100 °/s per s: the z gyro register freezes from 1.0 s to 1.5 s.
    let ramp =
        |t: f64| Physical { gyro_dps: [0.0, 0.0, 100.0 * t], accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() };
    let fault = "[{kind=\"stuck_axis\", channel=\"gyro_z\", start_s=1.0, duration_s=0.5}]";
    let out = run_with(fault, &[], 2.0, ramp);
    let healthy = run_with("[]", &[], 2.0, ramp);
    let events = injected(&out);
    assert_eq!(events.len(), 1);
    assert_eq!(events[0].0, s_to_ps(1.0));
    assert!(events[0].1.starts_with("stuck_axis at 1 s for 0.5 s, channel gyro_z"), "{}", events[0].1);
    let frozen = u16::from_str_radix(events[0].1.rsplit("0x").next().unwrap(), 16).unwrap();
    let (start, end) = (s_to_ps(1.0), s_to_ps(1.5));
    let inside: Vec<&ReadRow> = out.reads.iter().filter(|r| (start..end).contains(&r.sample_ps)).collect();
    assert!(inside.len() >= 120, "0.5 s of 4 ms reads");
    for r in &inside {
        assert_eq!(r.words[4], ND | frozen, "ZGYRO_OUT frozen; ND still sets with every sample");
        assert_eq!(r.rate[2], inside[0].rate[2]);
    }
    // X and Y keep updating (zero here), and z moves on after the window.
    assert!(inside.iter().all(|r| r.words[2] == ND && r.words[3] == ND));
    let after = out.reads.iter().find(|r| r.sample_ps >= end + s_to_ps(0.01)).unwrap();
    assert!(after.words[4] & FIELD > frozen + 900, "≈ 1000 LSB (50 °/s) above the frozen word");
    // The firmware integrates the frozen rate: it misses ∫(100 t − 100·1) dt over the window =
    // 12.5°. The filter delay cancels (frozen and live values lag alike); what remains is the window
    // edge falling between reads: at most one 4 ms read period × the 50 °/s jump at its end, 0.2°,
    // plus one LSB (0.05 °/s) over 0.5 s, 0.025°.
    let miss = angle_deg(out.cycles.last().unwrap().quat, healthy.cycles.last().unwrap().quat);
    assert!((miss - 12.5).abs() <= 0.225, "missed {miss}°");
}

#[test]
fn a_spike_shows_in_the_samples_it_hits_and_the_published_decode_drops_a_clipped_one() {
    let fault = "[{kind=\"spike\", channel=\"gyro_x\", start_s=1.0, magnitude=100.0, samples=4}]";
    let out = run_with(fault, &[], 1.5, level([0.0; 3]));
    // The first sample at or after 1.0 s is k = 820 (820 × 5/4096 s); four samples: 820…823.
    let spiked: Vec<&ReadRow> = out.reads.iter().filter(|r| (820..=823).contains(&r.sample_index)).collect();
    assert!(!spiked.is_empty(), "4 samples span 4.9 ms > one 4 ms read period");
    for r in &out.reads {
        let want = if (820..=823).contains(&r.sample_index) { ND | 2000 } else { ND };
        assert_eq!(r.words[2], want, "XGYRO_OUT of sample {}: 100 °/s = 2000 LSB", r.sample_index);
    }
    assert_eq!(injected(&out).len(), 1);
    assert_eq!(injected(&out)[0].0, s_to_ps(1.0));
    assert!(out.cycles.last().unwrap().euler_deg[0].abs() > 0.1, "the spike is integrated into roll");

    // 500 °/s clips at 0x1FFF, sets the overrange flag (EA from then on: DIAG_STAT is never read);
    // the published decode finds 0x1FFF outside both of its ranges and keeps the previous value.
    let fault = "[{kind=\"spike\", channel=\"gyro_y\", start_s=1.0, magnitude=500.0, samples=4}]";
    let out = run_with(fault, &[], 1.5, level([0.0; 3]));
    let healthy = run_with("[]", &[], 1.5, level([0.0; 3]));
    let first = out.reads.iter().position(|r| (820..=823).contains(&r.sample_index)).unwrap();
    assert_eq!(out.reads[first].words[3], ND | EA | 0x1FFF);
    assert!(out.reads[first..].iter().all(|r| r.words[1..].iter().all(|w| w & EA != 0)));
    assert!(out.reads[..first].iter().all(|r| r.words[1..].iter().all(|w| w & EA == 0)));
    assert!(count(&out, "stale_decode") >= 1 && count(&out, "saturated_reading") >= 1);
    assert_eq!(out.cycles, healthy.cycles, "the stale value (0) was used: nothing changed");
}

#[test]
fn a_dropped_burst_reads_the_floating_line_or_the_device_in_normal_mode() {
    // CS high from after frame 3 to the end of the burst: the rest reads the floating line (0xFFFF).
    let fault = "[{kind=\"dropped_burst\", start_s=1.0, after_frame=3}]";
    let out = run_with(fault, &[], 1.1, level([0.0, 0.0, 10.0]));
    let glitched: Vec<&ReadRow> = out.reads.iter().filter(|r| r.words[4] == 0xFFFF).collect();
    assert_eq!(glitched.len(), 1);
    let g = glitched[0];
    assert_eq!(g.tick, 250, "the first burst at or after 1.0 s (tick 250 arrives at 1.000 s)");
    assert_eq!(&g.words[1..4], &[ND | 0x0814, ND, ND]);
    assert!(g.words[4..].iter().all(|&w| w == 0xFFFF));
    // 0xFFFF is −1 LSB, inside the published negative range: taken as −0.05 °/s and −3.333 mg.
    assert_eq!(g.rate[2], (-0.05f64).to_radians());
    let next = out.reads.iter().find(|r| r.tick == 251).unwrap();
    assert_eq!(next.words[4], ND | 200, "the next burst is whole again");
    assert_eq!(count(&out, "burst_truncated"), 1);
    assert_eq!(count(&out, "spi_frame_without_cs"), 11, "frames 4…14");
    let events = injected(&out);
    assert_eq!(events.len(), 1);
    assert!(events[0].1.contains("dropped_burst") && events[0].1.contains("after frame 3 of the burst of tick 250"));
    // The device saw frames 0…3 only (t_end_ps is frame 3's last edge); CS rose when the firmware
    // had read frame 3's word: INT_FLAG half an SCLK period (0.67 µs) after the last edge, then at
    // most one poll iteration (0.26 µs), the read and the store (measured: 1.26 µs).
    let after_frame_3 = events[0].0 - g.t_end_ps;
    assert!(after_frame_3 > 0 && after_frame_3 < s_to_ps(2e-6), "{after_frame_3} ps");

    // A 0.1 µs glitch: CS is low again before the next frame, so the device takes frames 4… as
    // normal-mode commands: each breaks the 9 µs stall; under lenient the data stay what the device
    // gives: the idle word, then FLASH_CNT (0) read by the pipelined 0x0000 commands.
    let fault = "[{kind=\"dropped_burst\", start_s=1.0, after_frame=3, glitch_us=0.1, duration_s=0.0}]";
    let out = run_with(fault, &["device.timing_mode=\"lenient\""], 1.1, level([0.0, 0.0, 10.0]));
    let g = out.reads.iter().find(|r| r.tick == 250).unwrap();
    assert!(g.words[4..].iter().all(|&w| w == 0x0000), "{:04X?}", g.words);
    assert_eq!(g.rate[2], 0.0);
    assert_eq!(count(&out, "burst_truncated"), 1);
    assert_eq!(count(&out, "spi_frame_without_cs"), 0);
    assert_eq!(count(&out, "stall_too_short"), 11);
    // Every later burst is whole.
    assert!(out.reads.iter().filter(|r| r.tick > 250).all(|r| r.words[4] == ND | 200));
}

#[test]
fn a_sensor_reset_makes_the_device_busy_then_it_samples_again() {
    let out = run_with("[{kind=\"sensor_reset\", start_s=1.0}]", &[], 1.3, level([0.0, 0.0, 10.0]));
    let (reset, back) = (s_to_ps(1.0), s_to_ps(1.13));
    let events = injected(&out);
    assert_eq!(events.len(), 1);
    assert_eq!(events[0], (reset, "sensor_reset at 1 s".to_string()));
    assert_eq!(out.events.iter().find(|e| e.kind == "software_reset").map(|e| e.t_ps), Some(reset));
    // Bursts of ticks 250…282 (1.000…1.128 s) fall in the 130 ms reset: every frame reads corrupt_word.
    let busy: Vec<&ReadRow> = out.reads.iter().filter(|r| (reset..back).contains(&r.t_start_ps)).collect();
    assert_eq!(busy.len(), 33);
    assert!(busy.iter().all(|r| r.words == [0xFFFF; 15]));
    assert_eq!(count(&out, "device_busy"), 33 * 15);
    assert!(busy.iter().all(|r| r.rate[2] == (-0.05f64).to_radians()), "garbage decoded as −1 LSB");
    // Sampling restarts at 1.13 s with a fresh filter (primed by its first sample).
    let after: Vec<&ReadRow> = out.reads.iter().filter(|r| r.t_start_ps >= back).collect();
    assert!(after.iter().all(|r| r.words[4] == ND | 200 && r.sample_ps >= back), "{:04X?}", after[0].words);
}

#[test]
fn diag_flags_set_ea_in_every_word_which_the_published_decode_masks_off() {
    let fault = "[{kind=\"diag_flags\", start_s=1.0, duration_s=0.1, flags=0x0008}]";
    let out = run_with(fault, &[], 1.5, level([1.0, -2.0, 3.0]));
    let healthy = run_with("[]", &[], 1.5, level([1.0, -2.0, 3.0]));
    let from = s_to_ps(1.0);
    for r in &out.reads {
        let ea = r.words[1..].iter().all(|w| w & EA != 0);
        assert_eq!(ea, r.sample_ps >= from, "EA from the first flagged sample on (never read: sticky)");
    }
    assert_eq!(injected(&out).len(), 1);
    assert_eq!(out.cycles, healthy.cycles);
}

#[test]
fn a_supply_out_of_range_shows_in_supply_out_and_the_diag_flags() {
    let fault = "[{kind=\"supply_out_of_range\", start_s=1.0, duration_s=0.5, volts=4.5}]";
    let out = run_with(fault, &[], 2.0, level([1.0, -2.0, 3.0]));
    let healthy = run_with("[]", &[], 2.0, level([1.0, -2.0, 3.0]));
    let low = encode(Channel::Supply, 4.5, GyroRange::Dps300).unwrap().code;
    let (start, end) = (s_to_ps(1.0), s_to_ps(1.5));
    for r in &out.reads {
        let supply = if (start..end).contains(&r.sample_ps) { low } else { 0x0814 };
        assert_eq!(r.words[1] & 0x0FFF, supply);
        assert_eq!(r.words[1] & EA != 0, r.sample_ps >= start, "VDD < 4.75 V: DIAG_STAT bit 0, sticky");
    }
    let e: Vec<&Event> = out.events.iter().filter(|e| e.kind == "supply_out_of_range").collect();
    assert_eq!(e.len(), 1);
    assert_eq!((e[0].measured, e[0].required), (Some(4.5), Some(4.75)));
    assert_eq!(injected(&out).len(), 1);
    assert_eq!(out.cycles, healthy.cycles, "the firmware never looks at the supply");
}

#[test]
fn a_fault_after_the_end_of_the_run_is_never_injected() {
    let out = run_with("[{kind=\"sensor_reset\", start_s=50.0}]", &[], 0.5, level([0.0; 3]));
    assert!(out.events.is_empty(), "{:?}", out.events);
}
