//! Device-level tests: the slave is driven through `SpiSlave` with hand-built `FrameTiming`s.

use super::encoding::{decode, sign_extend, Channel, GyroRange};
use super::registers::{addr, BURST_ORDER};
use super::*;
use crate::bus::transaction::TimingOf;
use crate::bus::{FrameTiming, RunTiming, SpiSlave};
use crate::profile::{Device, TimingMode};
use crate::time::{Clock, Ps, PS_PER_S};

const NS: Ps = 1_000;
const US: Ps = 1_000_000;
const MS: Ps = 1_000_000_000;
/// One period of the default 819.2 SPS clock, ps (exact).
const PERIOD: Ps = 1_220_703_125;
/// SCLK periods as the bus floors them: 0.75 MHz (reference design), 3.75 MHz, 1.5 MHz.
const SCLK_750K: Ps = 1_333_333;
const SCLK_3M75: Ps = 266_666;
const SCLK_1M5: Ps = 666_666;

/// A hand-driven SPI master: frames of 16 mode-3 cycles, fixed gaps, CS margins of 100 ns.
///
/// The gap between frames outside a burst keeps both rules of the (sibling) timing table: the stall
/// (last edge to next first edge) ≥ tSTALL = 9 µs and the frame period (first edge to next first
/// edge) ≥ tDATARATE = 40 µs: 41 µs less the frame's span, at least 16 µs (ADI's evaluation tool's
/// gap). Burst frames are 2 µs apart (inside a burst only one SCLK period is required).
struct Host {
    t: Ps,
    sclk: Ps,
    gap: Ps,
    burst_gap: Ps,
    mode: u8,
    burst_cmd: u16,
    last_edge: Ps,
}

impl Host {
    fn new(t: Ps, sclk: Ps) -> Host {
        let gap = (41 * US).saturating_sub(sclk * 31 / 2).max(16 * US);
        Host { t, sclk, gap, burst_gap: 2 * US, mode: 3, burst_cmd: 0x4200, last_edge: 0 }
    }

    fn timing(&self) -> FrameTiming {
        // First falling edge to 16th rising edge: 15.5 periods.
        FrameTiming {
            index: 0,
            first_edge: self.t,
            last_edge: self.t + self.sclk * 31 / 2,
            sclk_period: self.sclk,
            bits: 16,
            mode: self.mode,
        }
    }

    fn frame_with_gap(&mut self, d: &mut Adis16407, din: u16, gap: Ps) -> u16 {
        let tm = self.timing();
        let dout = d.begin_frame(&tm);
        d.end_frame(din, &tm);
        self.last_edge = tm.last_edge;
        self.t = tm.last_edge + gap;
        dout
    }

    fn frame(&mut self, d: &mut Adis16407, din: u16) -> u16 {
        let gap = self.gap;
        self.frame_with_gap(d, din, gap)
    }

    fn cs_low(&mut self, d: &mut Adis16407) {
        d.set_cs(true, self.t);
        self.t += 100 * NS;
    }

    fn cs_high(&mut self, d: &mut Adis16407) {
        let t = self.last_edge + 100 * NS;
        d.set_cs(false, t);
        self.t = self.t.max(t + 100 * NS);
    }

    /// Read one register in its own CS window (two frames: command, then a dummy read).
    fn read(&mut self, d: &mut Adis16407, a: u8) -> u16 {
        self.cs_low(d);
        self.frame(d, u16::from(a) << 8);
        let w = self.frame(d, 0x0000);
        self.cs_high(d);
        w
    }

    /// Write a whole register (two byte frames, low first).
    fn write(&mut self, d: &mut Adis16407, a: u8, value: u16) {
        self.cs_low(d);
        self.frame(d, 0x8000 | u16::from(a) << 8 | (value & 0xFF));
        self.frame(d, 0x8000 | u16::from(a + 1) << 8 | (value >> 8));
        self.cs_high(d);
    }

    /// A burst: the command and 14 data frames, CS held low. Returns the 15 DOUT words.
    fn burst(&mut self, d: &mut Adis16407) -> [u16; 15] {
        self.cs_low(d);
        let mut out = [0u16; 15];
        let gap = self.burst_gap;
        out[0] = self.frame_with_gap(d, self.burst_cmd, gap);
        for w in out.iter_mut().skip(1) {
            *w = self.frame_with_gap(d, 0x0000, gap);
        }
        self.cs_high(d);
        self.t += self.gap;
        out
    }
}

/// The tests check the rules' consequences, so they run the part in `strict` mode whatever the
/// profile default.
fn strict() -> Device {
    Device { timing_mode: crate::profile::TimingMode::Strict, ..Device::default() }
}

fn device() -> Adis16407 {
    Adis16407::new(&strict()).unwrap()
}

fn device_with(f: impl FnOnce(&mut Device)) -> Adis16407 {
    let mut cfg = strict();
    f(&mut cfg);
    Adis16407::new(&cfg).unwrap()
}

fn still(f: impl FnOnce(&mut Physical)) -> Box<Constant> {
    let mut p = Physical::powered_idle();
    f(&mut p);
    Box::new(Constant(p))
}

fn timing_events(d: &Adis16407) -> usize {
    ["sclk_too_fast", "stall_too_short", "cs_setup", "cs_hold", "spi_mode", "frame_length"]
        .iter()
        .map(|k| d.events().count(k))
        .sum()
}

fn field(word: u16, bits: u32) -> i32 {
    sign_extend(word, bits)
}

#[test]
fn prod_id_two_frame_read() {
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.cs_low(&mut d);
    let first = h.frame(&mut d, 0x5600);
    let second = h.frame(&mut d, 0x0000);
    h.cs_high(&mut d);
    assert_eq!(first, 0x0000, "first frame: nothing asked for yet (dout_after_write pattern)");
    assert_eq!(second, 0x4017);
    assert_eq!(d.peek(addr::PROD_ID).unwrap(), 0x4017);
    assert_eq!(d.peek_name("prod_id").unwrap(), 0x4017);
    let rec = d.last_frame().unwrap();
    assert_eq!((rec.index, rec.din, rec.dout, rec.register), (1, 0x0000, 0x4017, Some(addr::PROD_ID)));
    assert_eq!((rec.sample_index, rec.violations), (None, Violations::default()));
    assert_eq!(timing_events(&d), 0);
}

#[test]
fn pipeline_holds_across_cs_high_and_write_gives_fixed_dout() {
    let mut d = device_with(|c| c.dout_after_write = 0xA5A5);
    let mut h = Host::new(MS, SCLK_750K);
    h.cs_low(&mut d);
    h.frame(&mut d, 0x5600);
    h.cs_high(&mut d);
    h.t += 3 * MS;
    h.cs_low(&mut d);
    assert_eq!(h.frame(&mut d, 0x8000 | 0x4400 | 0x12), 0x4017, "the read answered across a 3 ms CS-high gap");
    assert_eq!(h.frame(&mut d, 0x4400), 0xA5A5, "DOUT after a write frame");
    assert_eq!(h.frame(&mut d, 0x0000), 0x0012, "ALM_MAG1 low byte written, read back");
    h.cs_high(&mut d);
    assert_eq!(timing_events(&d), 0);
}

#[test]
fn smpl_prd_and_sens_avg_write_then_read_back() {
    let mut d = device();
    d.set_stimulus(still(|p| p.gyro_dps = [10.0, -10.0, 0.0]));
    let mut h = Host::new(MS, SCLK_750K);
    assert_eq!(h.read(&mut d, addr::SMPL_PRD), 0x0001);
    assert_eq!(h.read(&mut d, addr::SENS_AVG), 0x0402);
    h.write(&mut d, addr::SMPL_PRD, 0x0003);
    assert_eq!(h.read(&mut d, addr::SMPL_PRD), 0x0003);
    assert_eq!(d.sample_clock().hz(), 409.6);

    h.t = 20 * MS;
    assert_eq!(field(h.read(&mut d, addr::XGYRO_OUT), 14), 200, "10 °/s at 0.05 °/s");
    // ±150 keeps M = 2; the next sample uses the 0.025 °/s LSB.
    h.write(&mut d, addr::SENS_AVG, 0x0202);
    assert_eq!(h.read(&mut d, addr::SENS_AVG), 0x0202);
    assert_eq!(d.gyro_range(), GyroRange::Dps150);
    h.t += 5 * MS;
    assert_eq!(field(h.read(&mut d, addr::XGYRO_OUT), 14), 400);
    assert_eq!(field(h.read(&mut d, addr::YGYRO_OUT), 14), -400);
    // ±75 with M = 2 is raised to M = 4 [unconfirmed rule], with an event.
    h.write(&mut d, addr::SENS_AVG, 0x0102);
    assert_eq!(h.read(&mut d, addr::SENS_AVG), 0x0104);
    assert_eq!((d.gyro_range(), d.filter_m()), (GyroRange::Dps75, 4));
    assert_eq!(d.events().count("sens_avg_raised"), 1);
    h.t += 50 * MS;
    assert_eq!(field(h.read(&mut d, addr::XGYRO_OUT), 14), 800);
    // An invalid range code keeps the range.
    h.write(&mut d, addr::SENS_AVG, 0x0304);
    assert_eq!(h.read(&mut d, addr::SENS_AVG), 0x0104);
    assert_eq!(d.events().count("invalid_register_value"), 1);
    assert_eq!(timing_events(&d), 0);
}

#[test]
fn read_only_registers_ignore_writes() {
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.write(&mut d, addr::PROD_ID, 0x1234);
    h.write(&mut d, addr::XGYRO_OUT, 0x0FFF);
    assert_eq!(d.peek(addr::PROD_ID).unwrap(), 0x4017);
    assert_eq!(d.events().count("read_only_write"), 4, "two bytes each");
    assert!(d.peek(addr::GLOB_CMD).is_err());
    assert!(d.peek(0x50).is_err());
    assert!(d.peek(0x05).is_err());
}

/// The published oscilloscope frame: SUPPLY_OUT = 0xC7A7 at 4.737 V (ND = 1, EA = 1: VDD < 4.75 V).
#[test]
fn burst_at_750_khz_matches_the_published_frame() {
    let mut d = device();
    d.set_stimulus(still(|p| {
        p.supply_v = 4.737;
        p.gyro_dps = [300.0, 0.05, -300.0];
        p.accel_g = [18.0, -18.0, -0.1];
        p.temp_c = 25.0;
    }));
    d.set_frame_log(true);
    let mut h = Host::new(10 * MS, SCLK_750K);
    let w = h.burst(&mut d);
    assert_eq!(w[1], 0xC7A7);
    assert_eq!(&w[2..8], &[0xD770, 0xC001, 0xE890, 0xD519, 0xEAE7, 0xFFE2]);
    assert_eq!(decode(Channel::Temp, w[13], GyroRange::Dps300).value, 25.0);
    assert_eq!(timing_events(&d), 0);
    let log = d.drain_frame_log();
    assert_eq!(log.len(), 15);
    assert!(log.iter().all(|r| r.violations.is_empty()));
    let regs: Vec<u8> = log[1..].iter().map(|r| r.register.unwrap()).collect();
    assert_eq!(regs, BURST_ORDER);
    // Every data word holds sample 8 (at 9.765625 ms), aged from each frame's first edge.
    for r in &log[1..] {
        assert!(r.in_burst);
        assert_eq!(r.sample_index, Some(8));
        assert_eq!(r.sample_age_ps, Some(r.t_start - 8 * PERIOD));
    }
    // The whole burst: 15 frames of 15.5 SCLK periods plus 14 gaps of 2 µs.
    assert_eq!(log[14].t_end - log[0].t_start, 14 * (SCLK_750K * 31 / 2 + 2 * US) + SCLK_750K * 31 / 2);

    // A second burst before the next sample (10.986 ms): ND = 0 in every word, EA still set.
    let again = h.burst(&mut d);
    assert!(h.t < 9 * PERIOD);
    assert!(again[1..].iter().all(|w| w & 0x8000 == 0), "{again:04X?}");
    assert!(again[1..].iter().all(|w| w & 0x4000 != 0));
    let data_bits = |w: &[u16]| w.iter().map(|x| x & 0x3FFF).collect::<Vec<_>>();
    assert_eq!(data_bits(&again[1..]), data_bits(&w[1..]));
    // After the next sample ND is back.
    h.t = 11 * MS;
    let third = h.burst(&mut d);
    assert!(third[1..].iter().all(|w| w & 0x8000 != 0));
}

#[test]
fn burst_at_3_75_mhz_violates_every_frame() {
    for mode in [TimingMode::Strict, TimingMode::Lenient] {
        let mut d = device_with(|c| c.timing_mode = mode);
        d.set_frame_log(true);
        let mut h = Host::new(10 * MS, SCLK_3M75);
        let w = h.burst(&mut d);
        let log = d.drain_frame_log();
        assert!(log.iter().all(|r| r.violations == Violations::SCLK_TOO_FAST), "{mode:?}");
        assert_eq!(d.events().count("sclk_too_fast"), 15);
        assert_eq!(timing_events(&d), 15);
        let e = &d.events().events()[0];
        assert_eq!(e.required, Some(2.0e6), "the command frame is held to the normal-mode limit");
        assert!((e.measured.unwrap() - 3.75e6).abs() < 20.0);
        assert_eq!(d.events().events()[1].required, Some(1.0e6), "data frames: the burst limit");
        match mode {
            TimingMode::Strict => assert!(w[1..].iter().all(|&x| x == 0xFFFF), "{w:04X?}"),
            TimingMode::Lenient => assert_eq!(w[1], 0x8814, "5.0 V, ND set, data correct"),
        }
    }
}

#[test]
fn burst_at_1_5_mhz_breaks_only_the_burst_limit() {
    let mut d = device();
    let mut h = Host::new(10 * MS, SCLK_1M5);
    let w = h.burst(&mut d);
    assert_eq!(d.events().count("sclk_too_fast"), 14);
    assert_eq!(w[0], 0x0000, "command frame within 2 MHz: its DOUT is not corrupted");
    assert!(w[1..].iter().all(|&x| x == 0xFFFF));
}

#[test]
fn stall_rules() {
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.cs_low(&mut d);
    h.gap = 5 * US;
    h.frame(&mut d, 0x5600);
    let dout = h.frame(&mut d, 0x0000);
    h.cs_high(&mut d);
    assert_eq!(dout, 0xFFFF, "strict: the frame after a 5 µs stall reads corrupt");
    let e = &d.events().events()[0];
    assert_eq!(e.kind, "stall_too_short");
    assert!((e.measured.unwrap() - 5e-6).abs() < 1e-12 && (e.required.unwrap() - 9e-6).abs() < 1e-12);

    // Inside a burst one SCLK period is enough: 1.5 µs passes, 1.0 µs (< 1.333 µs) does not.
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.burst_gap = 1500 * NS;
    h.burst(&mut d);
    assert_eq!(timing_events(&d), 0);
    h.burst_gap = 1000 * NS;
    h.burst(&mut d);
    assert_eq!(d.events().count("stall_too_short"), 14, "every data frame; the command frame had a legal gap");
}

/// tDATARATE (40 µs, the sibling ADIS16405's, from the part's declaration): frames outside a burst
/// must start at least that far apart, whatever their stall. ADI's evaluation tool's pattern (1 MHz,
/// 16 µs gaps: a 31.5 µs period) keeps tSTALL but breaks it; a 41 µs period passes; the reference
/// board's burst (one CS window, 2 µs between frames) is not held to it, nor is its command frame
/// after the previous burst. In the slow sample mode (SMPL_PRD NS ≥ 0x0A) tSTALL is 75 µs.
#[test]
fn data_rate_and_slow_mode_stall() {
    const SCLK_1M: Ps = 1_000_000;
    let mut d = device();
    assert_eq!(d.layout.part.t_datarate_us, 40.0);
    let mut h = Host::new(MS, SCLK_1M);
    h.gap = 16 * US;
    let w = h.read(&mut d, addr::PROD_ID);
    assert_eq!(w, 0xFFFF, "strict: the frame 31.5 µs after the previous one reads corrupt");
    let e = &d.events().events()[0];
    assert_eq!((e.kind, d.events().events().len()), ("datarate_too_short", 1));
    assert!((e.measured.unwrap() - 31.5e-6).abs() < 1e-12 && (e.required.unwrap() - 40e-6).abs() < 1e-12);
    assert!(e.message.contains("31.500 µs") && e.message.contains("tDATARATE is 40.000 µs"), "{}", e.message);

    let mut d = device();
    let mut h = Host::new(MS, SCLK_1M);
    h.gap = 41 * US - SCLK_1M * 31 / 2;
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0x4017);
    h.burst(&mut d);
    h.burst(&mut d);
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0x4017);
    assert!(d.events().events().is_empty(), "{:?}", d.events().events());

    // Slow sample mode: the 41 µs period keeps tDATARATE, but its 25.5 µs stall breaks tSTALL = 75 µs.
    let mut d = device();
    let mut h = Host::new(MS, SCLK_1M);
    h.gap = 100 * US;
    h.write(&mut d, addr::SMPL_PRD, 0x000A);
    h.gap = 41 * US - SCLK_1M * 31 / 2;
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0xFFFF);
    let kinds: Vec<&str> = d.events().events().iter().map(|e| e.kind).collect();
    assert_eq!(kinds, ["stall_too_short"]);
    assert_eq!(d.events().events()[0].required, Some(75e-6));
    h.gap = 76 * US;
    h.t += 51 * US; // the next frame 76.5 µs after the last
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0x4017);
    assert_eq!(d.events().events().len(), 1);
}

#[test]
fn cs_setup_hold_and_polarity() {
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    d.set_cs(true, h.t);
    h.t += 20 * NS;
    assert_eq!(h.frame(&mut d, 0x5600), 0xFFFF);
    assert!(d.last_frame().unwrap().violations.contains(Violations::CS_SETUP));
    // CS↑ 10 ns after the last edge: tSFS broken; the next frame's DOUT is corrupt (strict).
    d.set_cs(false, h.last_edge + 10 * NS);
    assert!(d.last_frame().unwrap().violations.contains(Violations::CS_HOLD));
    h.t += MS;
    h.cs_low(&mut d);
    assert_eq!(h.frame(&mut d, 0x5600), 0xFFFF);
    assert!(d.last_frame().unwrap().violations.is_empty(), "the frame itself broke no rule");
    assert_eq!(h.frame(&mut d, 0x0000), 0x4017, "and the one after is clean");
    h.cs_high(&mut d);
    assert_eq!((d.events().count("cs_setup"), d.events().count("cs_hold")), (1, 1));

    // Every mode but 3 is reported per frame (mode 2 = CPOL 1, CPHA 0 idles high like mode 3).
    for spi_mode in [0, 1, 2] {
        for mode in [TimingMode::Strict, TimingMode::Lenient] {
            let mut d = device_with(|c| c.timing_mode = mode);
            let mut h = Host::new(MS, SCLK_750K);
            h.mode = spi_mode;
            h.cs_low(&mut d);
            h.frame(&mut d, 0x5600);
            let w = h.frame(&mut d, 0x0000);
            h.cs_high(&mut d);
            assert_eq!(d.events().count("spi_mode"), 2, "mode {spi_mode}");
            assert_eq!(w, if mode == TimingMode::Strict { 0xFFFF } else { 0x4017 });
        }
    }
}

#[test]
fn frames_without_cs_or_of_wrong_length() {
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    assert_eq!(h.frame(&mut d, 0x5600), 0xFFFF);
    assert_eq!(d.events().count("frame_without_cs"), 1);
    h.cs_low(&mut d);
    assert_eq!(h.frame(&mut d, 0x0000), 0x0000, "the CS-high frame asked for nothing");
    let mut tm = h.timing();
    tm.bits = 8;
    assert_eq!(d.begin_frame(&tm), 0xFFFF);
    d.end_frame(0x5600, &tm);
    assert_eq!(d.events().count("frame_length"), 1);
}

#[test]
fn read_sees_latest_sample_with_its_age() {
    let mut d = device();
    d.set_frame_log(true);
    let mut h = Host::new(0, SCLK_750K);
    let mut ages = std::collections::BTreeSet::new();
    for i in 0..200u64 {
        h.t = 4 * MS * (i + 1) + 1234 * NS;
        h.read(&mut d, addr::ZGYRO_OUT);
    }
    for r in d.drain_frame_log().iter().filter(|r| r.register == Some(addr::ZGYRO_OUT)) {
        // Sample k is at k·1.220703125 ms; the read sees the latest one at or before its first edge.
        let k = (r.t_start as u128 * 4096 / 5_000_000_000_000) as u64;
        assert_eq!(r.sample_index, Some(k));
        let age = r.sample_age_ps.unwrap();
        assert_eq!(age, r.t_start - k * PERIOD);
        assert!(age < PERIOD);
        ages.insert(age);
    }
    // A 4 ms read period is 3.2768 sample periods: the age keeps changing from read to read.
    assert!(ages.len() > 100, "{} distinct ages", ages.len());
    // A read exactly at a sample instant sees that sample (age 0).
    let mut d = device();
    let mut h = Host::new(5 * PERIOD - 50 * US, SCLK_750K);
    h.cs_low(&mut d);
    h.frame(&mut d, 0x0400);
    h.t = 5 * PERIOD;
    h.frame(&mut d, 0x0000);
    assert_eq!((d.last_frame().unwrap().sample_index, d.last_frame().unwrap().sample_age_ps), (Some(5), Some(0)));
}

#[test]
fn sample_clock_timing() {
    let mut d = device();
    d.advance_to(10 * crate::time::PS_PER_S);
    assert_eq!(d.latest_sample(), Some(SampleStamp { index: 8192, t: 10 * crate::time::PS_PER_S }));
    assert_eq!(d.next_sample().t - d.latest_sample().unwrap().t, PERIOD);
    // +1000 ppm: 8192 × 1.001 = 8200.19 samples in 10 s.
    let mut d = device_with(|c| c.clock_ppb = 1_000_000);
    d.advance_to(10 * crate::time::PS_PER_S);
    assert_eq!(d.latest_sample().unwrap().index, 8200);
    // First sample at 500 µs.
    let mut d = device_with(|c| c.first_sample_us = 500.0);
    d.advance_to(500 * US - 1);
    assert_eq!(d.latest_sample(), None);
    d.advance_to(500 * US);
    assert_eq!(d.latest_sample(), Some(SampleStamp { index: 0, t: 500 * US }));
    assert_eq!(d.next_sample().t, 500 * US + PERIOD);
}

#[test]
fn data_ready_honours_every_msc_ctrl_write_and_reset_mid_run() {
    // MSC_CTRL rewritten between samples (random line, polarity and enable bits), with the odd software
    // reset: the record must always be the latest sample taken with data ready enabled, on the pin
    // and polarity in force when it was taken (the device keeps the pin from MSC_CTRL's last write).
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(16_407);
    let mut d = device();
    let (mut t, mut expected, mut seen) = (0, None, None);
    let mut msc = d.peek(addr::MSC_CTRL).unwrap();
    let (mut enabled, mut disabled, mut resets) = (0, 0, 0);
    for step in 0..3000 {
        t += rng.gen_range(0..3 * PERIOD);
        d.advance_to(t);
        let latest = d.latest_sample();
        if latest != seen {
            if let (Some(l), true) = (latest, msc & 4 != 0) {
                let line = if msc & 1 == 0 { DataReadyLine::Dio1 } else { DataReadyLine::Dio2 };
                expected = Some(DataReady { t: l.t, sample_index: l.index, line, active_high: msc & 2 != 0 });
            }
            seen = latest;
        }
        assert_eq!(d.last_data_ready(), expected, "step {step}, t = {t} ps, MSC_CTRL = 0x{msc:04X}");
        if step % 250 == 249 {
            d.write_byte(addr::GLOB_CMD, 0x80, t);
            (expected, seen) = (None, None);
            resets += 1;
        } else {
            d.write_byte(addr::MSC_CTRL, rng.gen_range(0..8), t);
        }
        msc = d.peek(addr::MSC_CTRL).unwrap();
        assert_eq!(d.last_data_ready(), expected, "step {step}: right after the write");
        if msc & 4 != 0 {
            enabled += 1
        } else {
            disabled += 1
        }
    }
    assert!(enabled > 1000 && disabled > 1000 && resets == 12, "{enabled} enabled, {disabled} disabled");
}

#[test]
fn data_ready_follows_msc_ctrl() {
    let mut d = device();
    d.advance_to(3 * PERIOD + 7);
    let dr = d.last_data_ready().unwrap();
    assert_eq!(dr, DataReady { t: 3 * PERIOD, sample_index: 3, line: DataReadyLine::Dio1, active_high: true });
    d.write_byte(addr::MSC_CTRL, 0x03, 3 * PERIOD + 10);
    d.advance_to(10 * PERIOD);
    assert_eq!(d.last_data_ready(), Some(dr), "MSC_CTRL[2] = 0: no data ready");
    d.write_byte(addr::MSC_CTRL, 0x05, 10 * PERIOD + 10);
    d.advance_to(11 * PERIOD);
    let dr = d.last_data_ready().unwrap();
    assert_eq!((dr.sample_index, dr.line, dr.active_high), (11, DataReadyLine::Dio2, false));
}

#[test]
fn smpl_prd_change_restarts_the_period_from_the_write() {
    let mut d = device();
    let t = 2 * PERIOD + 100 * US;
    d.write_byte(addr::SMPL_PRD, 0x80, t);
    assert_eq!(d.next_sample(), SampleStamp { index: 3, t: t + 18_921 * US });
    assert_eq!(d.peek(addr::SMPL_PRD).unwrap(), 0x0080);
}

#[test]
fn bartlett_step_at_device_level() {
    let mut d = device();
    d.set_stimulus(Box::new(FnStimulus(|k: u64, _t: Ps| {
        let mut p = Physical::powered_idle();
        p.gyro_dps[0] = if k >= 100 { 8.0 } else { 0.0 };
        p
    })));
    // N = 4: the step response climbs the cumulative triangle 1, 3, 6, 10, 13, 15, 16 (/16).
    let expect = [0, 10, 30, 60, 100, 130, 150, 160, 160];
    for (j, e) in expect.iter().enumerate() {
        d.advance_to((99 + j as u64) * PERIOD);
        assert_eq!(field(d.peek(addr::XGYRO_OUT).unwrap(), 14), *e, "sample {}", 99 + j);
    }
}

#[test]
fn nd_clears_per_register_on_normal_reads() {
    let mut d = device();
    let mut h = Host::new(2 * MS, SCLK_750K);
    assert!(h.read(&mut d, addr::XGYRO_OUT) & 0x8000 != 0);
    assert!(h.read(&mut d, addr::XGYRO_OUT) & 0x8000 == 0);
    assert!(h.read(&mut d, addr::YGYRO_OUT) & 0x8000 != 0);
}

#[test]
fn autonull_removes_a_constant_bias() {
    for (range_bits, lsb) in [(0x0402u16, 0.05), (0x0104, 0.0125)] {
        let bias = [1.234, -0.777, 0.3333];
        let mut d = device();
        d.set_stimulus(still(|p| p.gyro_dps = bias));
        let mut h = Host::new(MS, SCLK_750K);
        h.write(&mut d, addr::SENS_AVG, range_bits);
        h.t = 100 * MS;
        let before = field(h.read(&mut d, addr::XGYRO_OUT), 14);
        assert_eq!(before, (1.234f64 / lsb).round() as i32);
        h.cs_low(&mut d);
        h.frame(&mut d, 0xC201);
        h.cs_high(&mut d);
        for (i, b) in bias.iter().enumerate() {
            let off = sign_extend(d.peek(addr::XGYRO_OFF + 2 * i as u8).unwrap(), 13);
            assert_eq!(off, -(b / 0.0125f64).round() as i32);
        }
        h.t += 10 * MS;
        for a in [addr::XGYRO_OUT, addr::YGYRO_OUT, addr::ZGYRO_OUT] {
            // Residual bias ≤ half the 0.0125 °/s offset LSB: within one output LSB in every range.
            let code = field(h.read(&mut d, a), 14);
            assert!(code.abs() <= 1, "range 0x{range_bits:04X}: 0x{a:02X} reads {code}");
            assert!(
                (d.filtered().gyro_dps[0] + f64::from(sign_extend(d.peek(addr::XGYRO_OFF).unwrap(), 13)) * 0.0125)
                    .abs()
                    <= 0.00625
            );
        }
    }
}

#[test]
fn an_offset_written_between_samples_acts_from_the_next_sample_on() {
    // The part applies the offsets when it computes a sample: a sample taken before the write keeps
    // the old offset even when it is read after the write (the model encodes lazily, at the read).
    let mut d = device();
    d.set_stimulus(still(|p| p.gyro_dps = [1.0, 0.0, 0.0]));
    d.advance_to(10 * MS);
    let sample = d.latest_sample().unwrap();
    let t_write = sample.t + PERIOD / 4;
    d.write_register(addr::XGYRO_OFF, 80, t_write); // +1.0 °/s
    assert_eq!(d.latest_sample(), Some(sample), "no sample between the write and the peek");
    assert_eq!(field(d.peek(addr::XGYRO_OUT).unwrap(), 14), 20, "1 °/s at 0.05 °/s per LSB, old offset");
    d.advance_to(sample.t + PERIOD);
    assert_eq!(field(d.peek(addr::XGYRO_OUT).unwrap(), 14), 40, "the next sample has the new offset");
}

#[test]
fn calibration_registers_act_on_outputs() {
    let mut d = device();
    d.set_stimulus(still(|p| p.mag_gauss = [0.25, 0.0, 0.0]));
    let mut h = Host::new(MS, SCLK_750K);
    h.write(&mut d, addr::XGYRO_OFF, 80); // +1.0 °/s
    h.write(&mut d, addr::YGYRO_OFF, 0x1FB0); // −80 → −1.0 °/s
    h.write(&mut d, addr::XACCL_OFF, 300); // +0.9999 g
    h.write(&mut d, addr::XMAGN_HIC, super::encoding::to_field(-100, 14)); // −0.05 gauss
    h.write(&mut d, addr::XMAGN_SIC, 0x0C00); // 150 %
    h.t += 10 * MS;
    assert_eq!(field(h.read(&mut d, addr::XGYRO_OUT), 14), 20);
    assert_eq!(field(h.read(&mut d, addr::YGYRO_OUT), 14), -20);
    assert_eq!(field(h.read(&mut d, addr::XACCL_OUT), 14), 300);
    assert_eq!(field(h.read(&mut d, addr::XMAGN_OUT), 14), 600, "(0.25 − 0.05) × 1.5 = 0.3 gauss");
    // Factory restore clears them (SIC back to 0x800).
    h.write(&mut d, addr::GLOB_CMD, 0x0002);
    assert_eq!(d.peek(addr::XGYRO_OFF).unwrap(), 0);
    assert_eq!(d.peek(addr::XMAGN_SIC).unwrap(), 0x0800);
    h.t += 10 * MS;
    assert_eq!(field(h.read(&mut d, addr::XMAGN_OUT), 14), 500);
}

#[test]
fn flash_update_and_software_reset() {
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.write(&mut d, addr::SMPL_PRD, 0x0005);
    h.write(&mut d, addr::GLOB_CMD, 0x0008);
    assert_eq!(h.read(&mut d, addr::FLASH_CNT), 1);
    h.write(&mut d, addr::SMPL_PRD, 0x0007);
    h.write(&mut d, addr::XGYRO_OFF, 0x0011);
    h.cs_low(&mut d);
    h.frame(&mut d, 0xC280);
    h.cs_high(&mut d);
    let reset_at = h.last_edge;
    assert_eq!(d.busy_until(), reset_at + 130 * MS);
    // During the reset every frame reads the corrupt word and is reported.
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0xFFFF);
    assert_eq!(d.events().count("device_busy"), 2);
    h.t = d.busy_until();
    assert_eq!(h.read(&mut d, addr::SMPL_PRD), 0x0005, "the flashed value comes back");
    assert_eq!(h.read(&mut d, addr::XGYRO_OFF), 0x0000, "unflashed change lost");
    assert_eq!(h.read(&mut d, addr::FLASH_CNT), 1);
    assert_eq!(d.latest_sample().unwrap().t, reset_at + 130 * MS, "sampling restarts when the reset ends");
    // Without a flash update, a reset restores the power-on defaults.
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.write(&mut d, addr::SENS_AVG, 0x0206);
    h.write(&mut d, addr::GLOB_CMD, 0x0080);
    h.t = d.busy_until() + MS;
    assert_eq!(h.read(&mut d, addr::SENS_AVG), 0x0402);
    assert_eq!(d.filter_m(), 2);
}

#[test]
fn overrange_and_supply_flags() {
    let mut d = device();
    d.set_stimulus(still(|p| p.gyro_dps = [500.0, 0.0, 0.0]));
    // Reads from 1.5 ms: no sample (1.22, 2.44 ms) falls between them.
    let mut h = Host::new(1500 * US, SCLK_750K);
    let w = h.read(&mut d, addr::XGYRO_OUT);
    assert_eq!(w, 0xDFFF, "ND, EA, clipped at +8191");
    assert_eq!(h.read(&mut d, addr::YGYRO_OUT) & 0x4000, 0x4000, "EA on every output");
    assert_eq!(h.read(&mut d, addr::DIAG_STAT), 0x0010, "overrange: bit 4");
    assert_eq!(d.peek(addr::DIAG_STAT).unwrap(), 0, "cleared by the read");
    d.set_stimulus(still(|p| p.supply_v = 5.3));
    h.t = 21 * PERIOD + 50 * US;
    // The filter's history still held 500 °/s for the first samples after the change: sticky bit 4.
    assert_eq!(h.read(&mut d, addr::DIAG_STAT), 0x0012);
    // Both reads between samples 25 and 26.
    h.t = 25 * PERIOD + 50 * US;
    assert_eq!(h.read(&mut d, addr::DIAG_STAT), 0x0002, "VDD > 5.25 V: bit 1");
    assert_eq!(h.read(&mut d, addr::SUPPLY_OUT) & 0x4000, 0x0000, "DIAG_STAT read: EA clear until the next sample");
}

#[test]
fn every_axis_beyond_its_rated_range_sets_the_overrange_flag() {
    // Each gyro and accel axis alone, of either sign, at its rated limit (±300 °/s, ±18 g) and just
    // beyond it (the fields clip only further out, at 409.6 °/s and 27.3 g): beyond it DIAG_STAT
    // bit 4 sets and one event names the value; at the limit nothing happens.
    for axis in 0..6 {
        let limit = if axis < 3 { 300.0 } else { 18.0 };
        for sign in [1.0, -1.0] {
            for (value, beyond) in [(sign * limit, false), (sign * (limit + 0.25), true)] {
                let mut d = device();
                d.set_stimulus(still(|p| match axis {
                    0..=2 => p.gyro_dps[axis] = value,
                    _ => p.accel_g[axis - 3] = value,
                }));
                d.advance_to(3 * PERIOD);
                let what = format!("axis {axis} at {value}");
                assert_eq!(d.peek(addr::DIAG_STAT).unwrap() & 0x0010 != 0, beyond, "{what}");
                assert_eq!(d.events().count("sensor_overrange"), usize::from(beyond), "{what}");
            }
        }
    }
}

#[test]
fn burst_details() {
    // CS↑ ends a burst early; DIN during a burst is ignored.
    let mut d = device();
    let mut h = Host::new(MS, SCLK_750K);
    h.cs_low(&mut d);
    h.frame_with_gap(&mut d, 0x4200, 2 * US);
    h.frame_with_gap(&mut d, 0xBA05, 2 * US);
    h.frame_with_gap(&mut d, 0x5600, 2 * US);
    h.cs_high(&mut d);
    assert!(!d.in_burst());
    assert_eq!(d.events().count("burst_truncated"), 1);
    assert_eq!(d.peek(addr::SMPL_PRD).unwrap(), 0x0001, "the write inside the burst was ignored");
    h.t += 20 * US;
    h.cs_low(&mut d);
    assert_eq!(h.frame(&mut d, 0x5600), 0x0000, "no pending read after a burst");
    assert_eq!(h.frame(&mut d, 0x0000), 0x4017);
    // A configurable burst command (sibling parts use 0x3E00).
    let mut d = device_with(|c| c.burst_command = 0x3E00);
    let mut h = Host::new(MS, SCLK_750K);
    h.burst_cmd = 0x3E00;
    let w = h.burst(&mut d);
    assert_eq!(w[1], 0x8814);
}

#[test]
fn nan_stimulus_is_reported_and_zeroed() {
    let mut d = device();
    d.set_stimulus(still(|p| p.gyro_dps[1] = f64::NAN));
    d.advance_to(0);
    assert_eq!(d.events().count("non_finite_input"), 1);
    assert_eq!(d.peek(addr::YGYRO_OUT).unwrap() & 0x3FFF, 0);
}

#[test]
fn profile_errors_are_reported() {
    assert!(Adis16407::new(&Device { sens_avg: 0x0302, ..Device::default() }).is_err());
    let opts = ModelOptions { diag_overrange_bit: 16, ..ModelOptions::default() };
    assert!(Adis16407::with_options(&Device::default(), opts).is_err());
    // ±75 with M = 2 at power-on is raised like a write.
    let d = device_with(|c| c.sens_avg = 0x0102);
    assert_eq!((d.peek(addr::SENS_AVG).unwrap(), d.filter_m()), (0x0104, 4));
}

#[test]
fn slice_stimulus_drives_the_samples_in_order() {
    // Gyro x = k LSB at sample k; with M = 0 (no filtering) the output code is the sample index.
    let rows: Vec<Physical> =
        (0..50).map(|k| Physical { gyro_dps: [k as f64 * 0.05, 0.0, 0.0], ..Physical::powered_idle() }).collect();
    let mut d = device();
    d.write_register(addr::SENS_AVG, 0x0400, 0);
    d.set_stimulus(Box::new(SliceStimulus::new(rows, 0).unwrap()));
    for k in [1u64, 2, 17, 49] {
        d.advance_to(k * PERIOD + 1);
        assert_eq!(field(d.peek(addr::XGYRO_OUT).unwrap(), 14), k as i32);
    }
    d.advance_to(60 * PERIOD);
    assert_eq!(field(d.peek(addr::XGYRO_OUT).unwrap(), 14), 49, "the last row is held");
}

#[test]
fn a_frame_before_the_device_time_is_reported() {
    let mut d = device();
    d.advance_to(10 * MS);
    let mut h = Host::new(5 * MS, SCLK_750K);
    h.read(&mut d, addr::PROD_ID);
    assert_eq!(d.events().count("time_reversal"), 2, "both frames start before 10 ms");
}

/// Throughput of the device alone: an 8 ms cycle holds 6.55 samples and two 15-frame bursts.
#[test]
#[ignore = "benchmark: cargo test -p sins-core --release --lib device::tests::bench -- --ignored --nocapture"]
fn bench_device_throughput() {
    let mut d = device();
    d.set_stimulus(Box::new(FnStimulus(|k: u64, _t: Ps| {
        let mut p = Physical::powered_idle();
        p.gyro_dps = [k as f64 * 1e-3, 1.0, -2.0];
        p
    })));
    let samples = 10_000_000u64;
    let start = std::time::Instant::now();
    d.advance_to(samples * PERIOD);
    let per_sample = start.elapsed().as_secs_f64() / samples as f64;

    let mut d = device();
    let mut h = Host::new(0, SCLK_750K);
    let cycles = 1_000_000u64;
    let start = std::time::Instant::now();
    for c in 0..cycles {
        h.t = c * 8 * MS + MS;
        std::hint::black_box(h.burst(&mut d));
        h.t = c * 8 * MS + 5 * MS;
        std::hint::black_box(h.burst(&mut d));
    }
    let per_cycle = start.elapsed().as_secs_f64() / cycles as f64;
    println!(
        "device: {:.1} ns per sample, {:.1} ns per 8 ms cycle (6.55 samples + 30 frames)",
        per_sample * 1e9,
        per_cycle * 1e9
    );
    assert_eq!(timing_events(&d), 0);
}

/// The timings of frames from `h.t` on, each followed by its gap, as `h` clocks them, numbered
/// from 0 as a run's frames are ([`RunTiming::of_starts`]).
fn timings_from(h: &Host, gaps: &[Ps]) -> Vec<FrameTiming> {
    let mut t = h.t;
    gaps.iter()
        .enumerate()
        .map(|(i, &gap)| {
            let tm = FrameTiming { index: i as u64, ..Host { t, ..*h }.timing() };
            t = tm.last_edge + gap;
            tm
        })
        .collect()
}

/// The words the device answers to `timings`, one frame at a time (DIN 0): what a run must equal.
fn frames_one_by_one(device: &mut Adis16407, timings: &[FrameTiming]) -> Vec<u16> {
    timings
        .iter()
        .map(|tm| {
            let w = device.begin_frame(tm);
            device.end_frame(0, tm);
            w
        })
        .collect()
}

/// Frames of one shape (first edges increasing) as a run's formula and starts: timed by a clock of
/// 1 ps per cycle, a frame starts on the cycle of its first edge, so the run's frames are `timings`.
pub(crate) fn ps_run(timings: &[FrameTiming]) -> (TimingOf, Vec<u64>) {
    let first = timings[0];
    let edges = (0, first.last_edge - first.first_edge);
    let of = TimingOf::with_edges(edges, &Clock::from_hz(PS_PER_S), first.sclk_period, first.bits, first.mode);
    let starts: Vec<u64> = timings.iter().map(|t| t.first_edge).collect();
    let run = RunTiming::of_starts(of, &starts);
    assert!(timings.iter().enumerate().all(|(i, t)| run.frame(i) == *t), "the run times every frame as given");
    (of, starts)
}

/// A run of frames (`SpiSlave::run_frames`, as the link hands over a burst's data frames) leaves the
/// device as the same frames one by one do: the words, the latest record, the counters, the events,
/// the frame log, and what a later read and burst see. Cases: a clean burst; samples inside the run;
/// a short stall inside it (strict and lenient); more frames than the burst has; a software reset
/// inside it; the frame log on; SCLK too fast for a burst.
#[test]
fn a_run_of_frames_equals_the_frames_one_by_one() {
    struct Case {
        name: &'static str,
        sclk: Ps,
        gaps: Vec<Ps>,
        lenient: bool,
        reset_s: Option<f64>,
        log: bool,
        /// Frames the short path answers from the start of the run.
        clean: usize,
    }
    let even = |n: usize, gap: Ps| vec![gap; n];
    let mut stalled = even(14, 2 * US);
    stalled[6] = 100 * NS;
    // Just after the 8th sample (9.766 ms): the runs of 2 µs gaps, the read and the burst after them
    // end before the 9th (10.986 ms), so the new-data flags they leave show in that burst.
    let t0 = 9_800 * US;
    // At 750 kHz the command frame ends at t0 + 100 ns + 15.5 periods; the run starts 2 µs later.
    let run_start = t0 + 100 * NS + SCLK_750K * 31 / 2 + 2 * US;
    let cases = [
        Case {
            name: "clean",
            sclk: SCLK_750K,
            gaps: even(14, 2 * US),
            lenient: false,
            reset_s: None,
            log: false,
            clean: 14,
        },
        Case {
            name: "samples inside",
            sclk: SCLK_750K,
            gaps: even(14, 400 * US),
            lenient: false,
            reset_s: None,
            log: false,
            clean: 14,
        },
        Case {
            name: "stall strict",
            sclk: SCLK_750K,
            gaps: stalled.clone(),
            lenient: false,
            reset_s: None,
            log: false,
            clean: 7,
        },
        Case {
            name: "stall lenient",
            sclk: SCLK_750K,
            gaps: stalled,
            lenient: true,
            reset_s: None,
            log: false,
            clean: 7,
        },
        Case {
            name: "past the burst",
            sclk: SCLK_750K,
            gaps: even(17, 2 * US),
            lenient: false,
            reset_s: None,
            log: false,
            clean: 14,
        },
        Case {
            name: "reset inside",
            sclk: SCLK_750K,
            gaps: even(14, 2 * US),
            lenient: false,
            reset_s: Some((run_start + 5 * (SCLK_750K * 31 / 2 + 2 * US) + US) as f64 * 1e-12),
            log: false,
            // Frame 5 starts 1 µs before the reset, frame 6 finds the part resetting.
            clean: 6,
        },
        Case {
            name: "log",
            sclk: SCLK_750K,
            gaps: even(14, 2 * US),
            lenient: false,
            reset_s: None,
            log: true,
            clean: 0,
        },
        Case {
            name: "sclk too fast",
            sclk: SCLK_1M5,
            gaps: even(14, 2 * US),
            lenient: true,
            reset_s: None,
            log: false,
            clean: 0,
        },
    ];
    for case in cases {
        let make = || {
            let mut d = device_with(|c| {
                if case.lenient {
                    c.timing_mode = crate::profile::TimingMode::Lenient;
                }
            });
            d.set_stimulus(still(|p| p.gyro_dps = [10.0, -20.0, 30.0]));
            if let Some(s) = case.reset_s {
                let ov = [format!("faults.list=[{{kind=\"sensor_reset\", start_s={s:e}}}]")];
                d.set_faults(&crate::profile::Profile::from_toml("", "test", &ov).unwrap().faults);
            }
            d.set_frame_log(case.log);
            let mut h = Host::new(t0, case.sclk);
            h.cs_low(&mut d);
            h.frame_with_gap(&mut d, 0x4200, 2 * US);
            assert_eq!(h.t, t0 + 100 * NS + case.sclk * 31 / 2 + 2 * US, "{}", case.name);
            (d, h)
        };
        let ((mut one, mut h1), (mut run, mut h2), (mut short, _)) = (make(), make(), make());
        let timings = timings_from(&h1, &case.gaps);
        let words = frames_one_by_one(&mut one, &timings);
        let (of, starts) = ps_run(&timings);
        let run_timing = RunTiming::of_starts(of, &starts);
        let mut run_words = vec![0u16; timings.len()];
        run.run_frames(&run_timing, 0, &mut run_words);
        let mut short_words = vec![0u16; timings.len()];
        assert_eq!(short.clean_burst_frames(&run_timing, 0, 0, &mut short_words), case.clean, "{}", case.name);
        assert_eq!(run_words, words, "{}", case.name);
        assert_eq!(run.last_frame(), one.last_frame(), "{}", case.name);
        assert_eq!(run.frames_clocked(), one.frames_clocked(), "{}", case.name);
        assert_eq!(run.in_burst(), one.in_burst(), "{}", case.name);
        assert_eq!(format!("{run:?}"), format!("{one:?}"), "{}", case.name);
        assert_eq!(run.drain_frame_log(), one.drain_frame_log(), "{}", case.name);
        assert_eq!(run.drain_events(), one.drain_events(), "{}", case.name);
        // What comes after sees the same device.
        for (d, h) in [(&mut one, &mut h1), (&mut run, &mut h2)] {
            let last = timings.last().unwrap().last_edge;
            (h.t, h.last_edge) = (last + 2 * US, last);
            h.cs_high(d);
            h.t += 50 * US;
        }
        assert_eq!(h2.read(&mut run, addr::DIAG_STAT), h1.read(&mut one, addr::DIAG_STAT), "{}", case.name);
        assert_eq!(h2.burst(&mut run), h1.burst(&mut one), "{}", case.name);
        assert_eq!(run.drain_events(), one.drain_events(), "{}", case.name);
    }
}

/// The stall rule decides a run of frames as it decides them one by one, at its boundary: runs
/// timed by random LSPCLKs whose closest starts leave stalls (of ⌊d·N/D⌋ or one more ps, see
/// `TimingOf::min_stall`) right at the burst's limit of one SCLK period, strict and lenient, with
/// samples inside some runs. The device after the run (words, records, counters, events, what a
/// later burst sees) is the one the frames one by one leave. Seen: runs whose bound clears them at
/// once, runs it does not clear though no stall is short, and runs with short stalls.
#[test]
fn a_run_checks_its_stalls_as_the_frames_one_by_one() {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(62);
    let (mut cleared, mut not_cleared_but_clean, mut short) = (0, 0, 0);
    for trial in 0..1_000 {
        let lenient = trial % 2 == 1;
        let lspclk = Clock::new(rng.gen_range(20_000_000..80_000_000), rng.gen_range(1..4));
        // SCLK phases of at least 0.52 µs (the burst's SCLK limit is 1 MHz); a character of 16 cycles.
        let half = lspclk.ps_to_cycles_ceil(520_000) + rng.gen_range(0..20);
        let (span, gap) = (31 * half, 2 * half + rng.gen_range(0..3));
        let bound = lspclk.cycles_to_ps(gap);
        // The limit a whole ps either side of the bound: short is `stall + 1 < sclk_period`.
        let sclk_period = bound + rng.gen_range(0..4);
        let timing = TimingOf::with_edges((0, span), &lspclk, sclk_period, 16, 3);
        let t0 = 9_800 * US + rng.gen_range(0..PERIOD);
        let make = || {
            let mut d = device_with(|c| {
                if lenient {
                    c.timing_mode = TimingMode::Lenient;
                }
            });
            d.set_stimulus(still(|p| p.gyro_dps = [10.0, -20.0, 30.0]));
            let mut h = Host::new(t0, SCLK_750K);
            h.cs_low(&mut d);
            h.frame_with_gap(&mut d, 0x4200, 2 * US);
            (d, h)
        };
        let ((mut one, mut h1), (mut run, mut h2)) = (make(), make());
        // The first frame a clean stall after the command.
        let mut starts = vec![lspclk.ps_to_cycles_ceil(h1.t + sclk_period) + rng.gen_range(0..50)];
        for _ in 1..14 {
            let spacing = span + gap + if rng.gen_bool(0.7) { 0 } else { rng.gen_range(1..3) };
            starts.push(starts[starts.len() - 1] + spacing);
        }
        let run_timing = RunTiming::of_starts(timing, &starts);
        let frames: Vec<FrameTiming> = (0..14).map(|i| run_timing.frame(i)).collect();
        let words = frames_one_by_one(&mut one, &frames);
        let mut run_words = [0u16; 14];
        run.run_frames(&run_timing, 0, &mut run_words);
        let name = format!("trial {trial}: {lspclk:?}, {half} cycles a phase, bound {bound} ps, SCLK {sclk_period} ps");
        assert_eq!(run_words.to_vec(), words, "{name}");
        assert_eq!(run.last_frame(), one.last_frame(), "{name}");
        assert_eq!(format!("{run:?}"), format!("{one:?}"), "{name}");
        let events = one.drain_events();
        assert_eq!(run.drain_events(), events, "{name}");
        let min_stall = run_timing.min_stall();
        let short_stalls = events.iter().filter(|e| e.kind == "stall_too_short");
        match (min_stall.is_some_and(|b| b + 1 >= sclk_period), short_stalls.count()) {
            (true, 0) => cleared += 1,
            (true, _) => panic!("{name}: the bound {min_stall:?} cleared a run with a short stall"),
            (false, 0) => not_cleared_but_clean += 1,
            (false, _) => short += 1,
        }
        for (d, h) in [(&mut one, &mut h1), (&mut run, &mut h2)] {
            let last = frames[13].last_edge;
            (h.t, h.last_edge) = (last + 2 * US, last);
            h.cs_high(d);
            h.t += 50 * US;
        }
        assert_eq!(h2.burst(&mut run), h1.burst(&mut one), "{name}");
    }
    assert!(cleared > 300 && not_cleared_but_clean > 20 && short > 300, "{cleared} {not_cleared_but_clean} {short}");
}

#[test]
fn is_finite_finds_any_non_finite_value_and_passes_the_largest_finite_ones() {
    let with = |i: usize, x: f64| {
        let mut p = Physical::powered_idle();
        *p.values_mut().nth(i).unwrap() = x;
        p
    };
    for i in 0..13 {
        assert_eq!(with(i, f64::MAX).values()[i], f64::MAX, "values and values_mut agree on value {i}");
        assert!(with(i, f64::MAX).is_finite() && with(i, -f64::MAX).is_finite(), "value {i}");
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(!with(i, x).is_finite(), "value {i} = {x}");
        }
    }
}

/// The ADIS16362 on the family protocol, as its declaration says: PROD_ID 0x3FEA; the burst command
/// 0x3E00 shifts out the 11 words SUPPLY_OUT … AUX_ADC (X/Y/ZTEMP_OUT where the ADIS16407 has its
/// magnetometer), the accelerometers in 0.333 mg; the frame after the burst is a command frame again;
/// 0x4200 is a plain read there (of ALM_MAG2), not a burst.
#[test]
fn the_adis16362_answers_its_own_map_and_burst() {
    let part = &super::parts::adis16362::PART;
    let cfg = Device { timing_mode: TimingMode::Strict, ..Device::of_part(part) };
    let mut d = Adis::new(&cfg).unwrap();
    d.set_stimulus(still(|p| {
        p.accel_g = [0.0, -0.5, 1.0];
        p.gyro_dps = [10.0, 0.0, 0.0];
        p.temp_c = 25.0 + 0.136 * 10.0;
    }));
    let mut h = Host::new(10 * MS, SCLK_750K);
    h.burst_cmd = 0x3E00;
    assert_eq!(h.read(&mut d, 0x56), 0x3FEA);
    h.cs_low(&mut d);
    let gap = h.burst_gap;
    let mut words = [0u16; 13];
    words[0] = h.frame_with_gap(&mut d, 0x3E00, gap);
    for w in words.iter_mut().skip(1) {
        *w = h.frame_with_gap(&mut d, 0x0000, 10 * US);
    }
    h.cs_high(&mut d);
    let code = |w: u16, bits| sign_extend(w & super::encoding::field_mask(bits), bits);
    assert_eq!(code(words[2], 14), 200, "XGYRO: 10 °/s at 0.05");
    assert_eq!(code(words[5], 14), 0, "XACCL");
    assert_eq!(code(words[6], 14), -1502, "YACCL: −0.5 g at 0.333 mg");
    assert_eq!(code(words[7], 14), 3003, "ZACCL: 1 g at 0.333 mg");
    for (i, w) in words[8..11].iter().enumerate() {
        assert_eq!(code(*w, 12), 10, "TEMP axis {i}: 1.36 °C above 25 °C at 0.136");
    }
    assert_eq!(words[12], cfg.dout_after_write as u16, "frame 12 follows the 11-word burst: a command frame");
    let records: Vec<_> = d.last_frame().into_iter().collect();
    assert!(!records[0].in_burst);
    assert_eq!(d.events().count("burst_truncated"), 0);
    // 0x4200 reads ALM_MAG2 (0x42) on this part: its next frame answers with the register.
    h.write(&mut d, 0x42, 0x1234);
    assert_eq!(h.read(&mut d, 0x42), 0x1234);
}

/// The three identity registers are mapped (they read the profile's unit values, not 0 with an
/// event) and a read of an unmapped address names the part's register addresses.
#[test]
fn lot_and_serial_numbers_read_back_and_peek_names_the_map() {
    let mut d = device_with(|c| {
        c.lot_id1 = 0x1111;
        c.lot_id2 = 0x2222;
        c.serial_num = 0x0345;
    });
    let mut h = Host::new(10 * MS, SCLK_750K);
    assert_eq!(h.read(&mut d, 0x52), 0x1111);
    assert_eq!(h.read(&mut d, 0x54), 0x2222);
    assert_eq!(h.read(&mut d, 0x58), 0x0345);
    assert_eq!(d.events().count("read_unreadable"), 0);
    assert_eq!(d.peek(0x52).unwrap(), 0x1111);
    let e = d.peek(0x50).unwrap_err().to_string();
    assert!(e.contains("no ADIS16407 register at address 0x50") && e.contains("0x52") && e.contains("0x58"), "{e}");
}

/// Read PROD_ID through the F28335's SPI-A at `level` with the profile overrides `ov` (lenient timing,
/// so that the words are what the wires carry): the two words the master receives and the device's
/// events. Frames 50 µs apart, each in its own CS window.
fn prod_id_through_the_link(ov: &[&str], level: crate::profile::BusLevel) -> (Vec<u16>, Vec<crate::events::Event>) {
    let (rx, events, _) = prod_id_logged(ov, level);
    (rx, events)
}

/// [`prod_id_through_the_link`] and the link's log (frames: words and the times shown to the part).
fn prod_id_logged(
    ov: &[&str],
    level: crate::profile::BusLevel,
) -> (Vec<u16>, Vec<crate::events::Event>, Vec<crate::bus::LinkRecord>) {
    use crate::bus::SpiLink;
    use crate::dsp::spi::{SPIRXBUF, SPITXBUF};
    let mut ov: Vec<String> = ov.iter().map(|s| s.to_string()).collect();
    ov.push("device.timing_mode=\"lenient\"".into());
    let mut p = crate::profile::Profile::from_toml("", "test", &ov).unwrap();
    p.spi.level = level;
    let mut link = SpiLink::from_profile(&p, Adis16407::new(&p.device).unwrap()).unwrap();
    link.init_from_profile(&p.spi, 0).unwrap();
    link.enable_log();
    let mut t = MS;
    let mut rx = Vec::new();
    for din in [0x5600, 0x0000] {
        link.set_gpio57(false, t).unwrap();
        link.write(SPITXBUF, din, t + US).unwrap();
        let flag = link.int_flag_time().unwrap();
        rx.push(link.read(SPIRXBUF, flag).unwrap());
        link.set_gpio57(true, flag + US).unwrap();
        t = flag + 50 * US;
    }
    (rx, link.slave_mut().drain_events(), link.take_log())
}

/// The ADIS16407 (it does not answer as sampled: the link shifts its words in modes 0, 1, 2) in all
/// four SPI modes: the transaction and bit levels agree word for word, time for time and event for
/// event.
#[test]
fn the_adis_in_every_spi_mode_reads_alike_at_both_link_levels() {
    use crate::profile::BusLevel;
    for (spiccr, spictl, mode) in [(0xCF, 0x07, 3), (0xCF, 0x0F, 2), (0x8F, 0x07, 1), (0x8F, 0x0F, 0)] {
        let ov = [format!("spi.spiccr={spiccr}"), format!("spi.spictl={spictl}")];
        let ov = [ov[0].as_str(), ov[1].as_str()];
        let transaction = prod_id_logged(&ov, BusLevel::Transaction);
        let bit = prod_id_logged(&ov, BusLevel::Bit);
        assert_eq!(transaction, bit, "mode {mode}");
        assert_eq!(transaction.2.len(), 6, "mode {mode}: two CS windows of one frame");
    }
}

/// A master clocking in another SPI mode than the part's mode 3 gets shifted words, and the part
/// reports every such frame at run time, at both link levels. The mapping follows f28335.md's table
/// (TI's SPI guide): CLKPOLARITY 1 with CLK_PHASE 0 ("falling edge without delay", SPICTL 0x07) is
/// mode 3, the reference board's; CLKPOLARITY 1 with CLK_PHASE 1 (SPICTL 0x0F) is mode 2, which
/// idles high like mode 3 and so passed the old polarity-only check unreported.
#[test]
fn a_wrong_spi_mode_is_reported_per_frame_at_both_link_levels() {
    use crate::profile::BusLevel;
    for level in [BusLevel::Transaction, BusLevel::Bit] {
        let (rx, events) = prod_id_through_the_link(&[], level);
        assert_eq!(rx[1], 0x4017, "{level:?}: mode 3 reads PROD_ID");
        assert!(events.is_empty(), "{level:?}: {events:?}");
        for (spiccr, spictl, mode) in [(0xCF, 0x0F, 2), (0x8F, 0x07, 1), (0x8F, 0x0F, 0)] {
            let ov = [format!("spi.spiccr={spiccr}"), format!("spi.spictl={spictl}")];
            let (rx, events, log) = prod_id_logged(&[&ov[0], &ov[1]], level);
            // Each event names its frame, as the link's log numbers it, and has that frame's first edge.
            let frames: Vec<_> = log
                .iter()
                .filter_map(|r| match r {
                    crate::bus::LinkRecord::Frame(f) => Some((f.index, f.timing.first_edge)),
                    _ => None,
                })
                .collect();
            let tied: Vec<_> = events.iter().map(|e| (e.frame.unwrap(), e.t_ps)).collect();
            assert_eq!(tied, frames, "{level:?} mode {mode}");
            // (In mode 1 the part also samples DIN one bit late: it reads another register.)
            if mode != 1 {
                assert_eq!(rx[1], 0x4017 >> 1, "{level:?} mode {mode}: shifted by one bit");
            }
            let kinds: Vec<&str> = events.iter().map(|e| e.kind).collect();
            assert_eq!(kinds, ["spi_mode", "spi_mode"], "{level:?} mode {mode}");
            assert_eq!((events[0].measured, events[0].required), (Some(f64::from(mode)), Some(3.0)));
            assert!(events[0].message.contains(&format!("SPI mode {mode}")), "{}", events[0].message);
        }
    }
}

/// SCLK is judged by its full period (SPIBRR+1 LSPCLK cycles), at both link levels: SPIBRR 18 at
/// LSPCLK 37.5 MHz is 1.974 MHz (phases of 9 and 10 cycles; twice the short phase would say
/// 2.083 MHz) and passes the 2 MHz limit; 150 MHz / 75 is exactly 2 MHz and passes; SPIBRR 17 is
/// 2.083 MHz and is reported with that frequency.
#[test]
fn sclk_is_judged_by_its_full_period_at_both_link_levels() {
    use crate::profile::BusLevel;
    for level in [BusLevel::Transaction, BusLevel::Bit] {
        for ov in [&["spi.spibrr=18"][..], &["clocks.lospcp=0", "spi.spibrr=74"]] {
            let (rx, events) = prod_id_through_the_link(ov, level);
            assert_eq!(rx[1], 0x4017, "{level:?} {ov:?}");
            assert!(events.is_empty(), "{level:?} {ov:?}: {events:?}");
        }
        let (_, events) = prod_id_through_the_link(&["spi.spibrr=17"], level);
        let kinds: Vec<&str> = events.iter().map(|e| e.kind).collect();
        assert_eq!(kinds, ["sclk_too_fast", "sclk_too_fast"], "{level:?}");
        let f = events[0].measured.unwrap();
        assert!((f - 37.5e6 / 18.0).abs() < 1.0, "{level:?}: {f} Hz");
        assert!(events[0].message.contains("SCLK 2.083333 MHz"), "{}", events[0].message);
    }
}

/// The power-on start-up (adis16407.md: 210 ms). A part powered at time 0 (`device.powered_before_ms
/// = 0`) read 17 µs later answers 0x0000, ignores the command and reports `read_before_startup`; read
/// after its 210 ms it answers, with samples taken from then on. The default profile's part had been
/// powered long enough: ready at time 0.
#[test]
fn a_read_before_the_power_on_startup_reads_zero_and_is_reported() {
    let cfg = Device { powered_before_ms: 0.0, ..Device::default() };
    let mut d = Adis::new(&cfg).unwrap();
    assert_eq!(d.ready_at(), 210 * MS);
    let mut h = Host::new(17 * US, SCLK_750K);
    h.cs_low(&mut d);
    let first = h.frame(&mut d, u16::from(addr::PROD_ID) << 8);
    let second = h.frame(&mut d, 0x0000);
    h.cs_high(&mut d);
    assert_eq!((first, second), (0x0000, 0x0000));
    assert_eq!(d.events().count("read_before_startup"), 2);
    let e = d.events().events().iter().find(|e| e.kind == "read_before_startup").unwrap();
    assert!(e.message.contains("after its 210.000 ms start-up"), "{}", e.message);
    assert_eq!(d.latest_sample(), None, "no sample during the start-up");
    // After the start-up the part answers, and its first sample is the start-up's end.
    h.t = 210 * MS + 5 * MS;
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0x4017);
    assert_eq!(d.latest_sample().map(|s| (s.index, s.t)), Some((4, 210 * MS + 4 * PERIOD)));
    assert_eq!(d.events().count("read_before_startup"), 2);
    // Powered 200 ms before time 0: ready 10 ms in. The default: ready at once.
    let d = Adis::new(&Device { powered_before_ms: 200.0, ..Device::default() }).unwrap();
    assert_eq!(d.ready_at(), 10 * MS);
    let mut d = device();
    assert_eq!(d.ready_at(), 0);
    let mut h = Host::new(17 * US, SCLK_750K);
    assert_eq!(h.read(&mut d, addr::PROD_ID), 0x4017);
    assert_eq!(d.events().count("read_before_startup"), 0);
}
