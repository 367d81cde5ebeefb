//! The acquisition node: the XC3S400AN's MicroBlaze firmware (thesis §4.3.3, §4.5.1, Fig. 4.18) with
//! its PLB IP cores, driving the seven ADXL345, the HMC6343 and the GR-87 through the existing
//! part models.
//!
//! **Level of the IP cores: register access + line time.** What decides this board's timing is
//! (a) the serial lines — 7 bytes at 1.389 MHz per accelerometer (40.3 µs), 9 SCL periods per I²C
//! byte at 100 kHz, 520.8 µs per UART character, 26 × 16 bits at 9.375 MHz to the DSP — which are
//! exact here, edge for edge as the parts see them, and (b) how many PLB register accesses and CPU
//! cycles the MicroBlaze spends around them, which are counted per access at
//! `node.plb_access_cycles` [estimate] (a PLB v4.6 single read through the MicroBlaze's bus
//! interface is several clocks; no figure was read). Inside a core, the FIFOs only decide whether
//! bytes wait: xps_spi's 16-deep FIFOs hold a whole 7-byte read, the UART Lite's 16-byte RX FIFO is
//! emptied byte by byte by DMA1, so neither overflows at these rates and neither is modelled
//! further; the cores' clock-domain details (a PLB cycle here and there) are below the estimates'
//! own uncertainty. The SPI bit level and the I²C bit level already agree with the transaction
//! level the node uses (issue 25 items 1–3), so the transaction level loses nothing here.
//!
//! Each 5 ms timer interrupt (`tick`):
//! 1. enters the handler (`isr_entry_cycles`);
//! 2. loads and starts SPI #1–#7, one after the other in the order of `array.parts` (each part on
//!    the core its `link` names; SSR, 7 TX FIFO writes, CR: 9 accesses each):
//!    each core reads DATAX0…DATAZ1 of its part (0xF2 + 6 dummy bytes) under its own SS, the seven
//!    shifting at the same time ([unconfirmed]: one core per part is what makes parallel reads
//!    possible, the thesis does not say the firmware uses it);
//! 3. collects them in order, each when its transfer is over (status, 7 RX FIFO reads, SSR: 9
//!    accesses);
//! 4. polls the compass in three ticks out of every twenty (10 Hz): tick 0 writes command 0x50
//!    (post heading), tick 1 starts a 6-byte read (≥ 1 ms response delay later), tick 2 takes the
//!    bytes from the IIC core's RX FIFO; the I²C transfers run in the background on the core;
//! 5. takes the NMEA bytes DMA1 has put in memory since the last tick, checks and parses each
//!    complete sentence (GGA gives position and altitude, RMC speed and course; a fix is new when
//!    the RMC of the GGA's second arrives);
//! 6. pre-processes (selects each part's channels in turn, §4's A₁…A₉: `array.parts`) and builds the packet
//!    (frame.rs), then starts DMA2 (3 accesses), which feeds SPI #8; DMA2's completion interrupt
//!    costs one more handler entry and 2 accesses.

use super::frame::{self, GpsWords, Packet};
use super::profile::GfsinsProfile;
use super::Stages;
use crate::bus::i2c::{I2cLink, I2cTarget};
use crate::bus::{Address, FrameTiming, Link, SpiSlave};
use crate::deadline;
use crate::device::adxl345::{self, Adxl345, ErrorPreset};
use crate::device::gps::{Gps, NmeaReader};
use crate::device::hmc6343::Hmc6343;
use crate::error::Result;
use crate::events::{Event, EventLog, Severity};
use crate::profile::I2cBus;
use crate::time::{Clock, Ps};
use std::sync::{Arc, Mutex};

/// Ticks per compass poll at 10 Hz (200 Hz / 10).
const COMPASS_DIVIDER: u64 = 20;
/// HMC6343 command: post heading data.
const POST_HEADING: u8 = 0x50;
/// The multi-byte read of DATAX0…DATAZ1.
const READ_DATA: u8 = adxl345::spi::READ | adxl345::spi::MULTI_BYTE | 0x32;

/// The compass shared by the I²C link, which drives it, and the node, which takes its events out.
struct SharedCompass(Arc<Mutex<Hmc6343>>);

impl SharedCompass {
    fn part(&self) -> std::sync::MutexGuard<'_, Hmc6343> {
        // Only this thread ever holds the lock, so it cannot be poisoned by another.
        self.0.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

impl I2cTarget for SharedCompass {
    fn start(&mut self, t: Ps) {
        self.part().start(t);
    }
    fn write(&mut self, byte: u8, t: Ps) -> bool {
        self.part().write(byte, t)
    }
    fn read(&mut self, t: Ps, ack: bool) -> u8 {
        self.part().read(t, ack)
    }
    fn stop(&mut self, t: Ps) {
        self.part().stop(t);
    }
    fn hold_scl(&mut self, t: Ps) -> Ps {
        self.part().hold_scl(t)
    }
}

/// What one tick did and when (the budget's raw material and the timing test's subject).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TickTiming {
    /// The timer interrupt.
    pub t0: Ps,
    /// Each SPI core's SS↓ and SS↑ (#1–#7, whichever part sits on it).
    pub spi: [(Ps, Ps); 7],
    /// The MicroBlaze has collected the seven reads.
    pub collected: Ps,
    /// DMA2 started (the packet is ready).
    pub dma_start: Ps,
    /// The packet's last SCK edge + half a period (SS↑ on SPI #8).
    pub packet_end: Ps,
    /// CPU time spent in the tick (both handler entries, accesses, processing; waits for the SPI
    /// cores included: the firmware polls), ps.
    pub cpu_ps: Ps,
    /// Compass phase of the tick (0 write, 1 read start, 2 take; 3 otherwise).
    pub compass_phase: u8,
    /// NMEA bytes and complete sentences handled.
    pub nmea_bytes: u32,
    /// Complete sentences handled.
    pub nmea_sentences: u32,
    /// The I²C transaction the tick started (START to STOP; equal times when none).
    pub iic: (Ps, Ps),
    /// The NMEA characters handled: the first one's start bit to the last one's stop bit (equal
    /// times when none).
    pub uart: (Ps, Ps),
    /// The CPU time by stage (their sum is `cpu_ps`).
    pub stages: Stages,
}

/// The node and the parts it drives.
pub struct Node {
    cpu: Clock,
    plb: Clock,
    cfg: super::profile::Node,
    parts: Vec<Adxl345>,
    /// The SPI core of each part (0 = #1; `array.parts[].link`).
    cores: Vec<usize>,
    /// The packet's channels: (part, axis) each (`array.parts[].channels` in turn).
    channels: [(usize, usize); 9],
    /// Characters clocked on each part's SPI core since power-up (the index of its next frame).
    frames: Vec<u64>,
    iic: I2cLink,
    /// The compass's 7-bit address (`compass.address`).
    compass_address: Address,
    compass_part: Arc<Mutex<Hmc6343>>,
    /// The error model the compass part was built with.
    compass_errors: crate::device::hmc6343::ErrorModel,
    gps: Gps,
    nmea: NmeaReader,
    baud_mismatch: bool,
    /// One UART character (start, 8 data, stop bits) at the UART Lite's baud, ps.
    char_ps: Ps,
    /// The first tick's time and the tick period, ps.
    start: Ps,
    period: Ps,
    tick: u64,
    /// The end of the last tick's work: a late handler delays the next (one CPU, one handler at a time).
    busy_until: Ps,
    compass_ready: Ps,
    compass: [i16; 3],
    /// A 6-byte compass read in flight: its bytes and when they are in the core's RX FIFO.
    compass_read: Option<([u8; 6], Ps)>,
    gga: Option<(u32, [i32; 3])>,
    gps_words: GpsWords,
    gps_valid: bool,
    nmea_dropped: bool,
    events: EventLog,
}

impl std::fmt::Debug for Node {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Node").field("tick", &self.tick).field("period", &self.period).finish()
    }
}

impl Node {
    /// The node of `profile` at power-up with its parts: `array(i, t)` is the force part `i` feels
    /// (`array.parts` in order), `compass` and `gps` the other parts' stimuli. Sets the parts up as
    /// the firmware's initialisation does (before the first tick at `node.start_ms`).
    pub fn new(
        profile: &GfsinsProfile,
        array: Arc<dyn Fn(usize, Ps) -> [f64; 3] + Send + Sync>,
        compass: crate::device::hmc6343::Stimulus,
        gps: crate::device::gps::Stimulus,
    ) -> Result<Node> {
        use crate::device::{gps as g, hmc6343 as h};
        let cfg = profile.node.clone();
        let preset = ErrorPreset::by_name(&profile.array.preset).unwrap_or(&adxl345::PRESETS[0]);
        let parts: Vec<Adxl345> = (0..profile.array.parts.len())
            .map(|i| {
                let a = array.clone();
                Adxl345::new(Box::new(move |t| a(i, t)), preset, profile.array.seed + i as u64)
            })
            .collect();
        let revision = if profile.compass.revision == "earlier" { h::Revision::Earlier } else { h::Revision::Later };
        let errors = if profile.compass.errors == "ideal" { h::IDEAL } else { h::HMC6343_ERRORS };
        // One correlation time for the part and the filter (`compass.correlation_time_s`).
        let errors = h::ErrorModel { tau_s: profile.compass.correlation_time_s, ..errors };
        let hmc = Arc::new(Mutex::new(h::Hmc6343::new(revision, compass, errors, profile.compass.seed)));
        let bus = I2cBus { scl_low_ns: cfg.iic_scl_low_ns, scl_high_ns: cfg.iic_scl_high_ns };
        let address = profile.compass.address();
        let iic = I2cLink::new(&bus, vec![(address, Box::new(SharedCompass(hmc.clone())))]);
        let settings = g::Settings {
            latency_ps: profile.gps.latency_ms * 1_000_000_000,
            cep_m: profile.gps.cep_m,
            velocity_sigma_m_s: profile.gps.velocity_sigma_m_s,
            baud: profile.gps.baud,
            seed: profile.gps.seed,
            ..g::Settings::default()
        };
        let period = crate::time::PS_PER_S / cfg.timer_hz;
        let mut node = Node {
            cpu: Clock::from_hz(cfg.cpu_hz),
            plb: Clock::from_hz(cfg.plb_hz),
            baud_mismatch: cfg.uart_baud != profile.gps.baud,
            char_ps: 10 * crate::time::PS_PER_S / u64::from(cfg.uart_baud),
            cfg,
            frames: vec![0; parts.len()],
            parts,
            cores: profile.array.cores(),
            channels: profile.array.channel_parts(),
            iic,
            compass_address: Address::I2c(address),
            compass_part: hmc,
            compass_errors: errors,
            gps: Gps::new(settings, gps),
            nmea: NmeaReader::default(),
            start: profile.node.start_ms * 1_000_000_000,
            period,
            tick: 0,
            busy_until: 0,
            compass_ready: 0,
            compass: [0; 3],
            compass_read: None,
            gga: None,
            gps_words: GpsWords::default(),
            gps_valid: false,
            nmea_dropped: false,
            events: EventLog::default(),
        };
        node.set_up(profile)?;
        Ok(node)
    }

    /// The error model of the compass part (its correlation time is `compass.correlation_time_s`).
    pub fn compass_errors(&self) -> crate::device::hmc6343::ErrorModel {
        self.compass_errors
    }

    /// The power-up initialisation (setting mode's part set-up): each ADXL345 gets BW_RATE,
    /// DATA_FORMAT, FIFO_CTL and POWER_CTL (measure) from 2 ms on; the HMC6343, once its 500 ms
    /// start-up is over, gets OP mode 2 = 10 Hz in EEPROM and a reset (it reads EEPROM at reset).
    fn set_up(&mut self, profile: &GfsinsProfile) -> Result<()> {
        let a = &profile.array;
        let mut t = 2_000_000_000;
        for i in 0..self.parts.len() {
            for (reg, value) in [(0x2C, a.bw_rate), (0x31, a.data_format), (0x38, a.fifo_ctl), (0x2D, 0x08)] {
                let mut rx = [0u8; 2];
                t = self.spi(i, &[reg, value], &mut rx, t) + 1_000_000;
            }
        }
        use crate::device::hmc6343::{eeprom, STARTUP_PS};
        let hmc = self.compass_address;
        let w = self.iic.transfer(hmc, &[0xF1, u16::from(eeprom::OP_MODE_2), 0x02], &mut [], STARTUP_PS)?;
        let reset = self.iic.transfer(hmc, &[0x82], &mut [], w.end + 10_000_000_000)?;
        self.compass_ready = reset.end + STARTUP_PS;
        Ok(())
    }

    /// SCK period of a core with `ratio` PLB cycles per SCK.
    fn sck(&self, ratio: u64) -> Ps {
        self.plb.cycles_to_ps(ratio)
    }

    /// One SPI transaction of core `i` (SS↓ at `start`): `tx` out, `rx` in, bytes back to back; SS↑
    /// half a period after the last edge. Returns SS↑'s time.
    fn spi(&mut self, i: usize, tx: &[u8], rx: &mut [u8], start: Ps) -> Ps {
        let sck = self.sck(self.cfg.adxl_sck_ratio);
        let part = &mut self.parts[i];
        part.set_cs(true, start);
        let mut first = start + self.cfg.ss_setup_half_periods * sck / 2;
        let mut last = first;
        for (b, r) in tx.iter().zip(rx.iter_mut()) {
            last = first + 15 * sck / 2;
            let index = self.frames[i];
            self.frames[i] += 1;
            let timing = FrameTiming { index, first_edge: first, last_edge: last, sclk_period: sck, bits: 8, mode: 3 };
            let dout = part.begin_frame(&timing);
            part.end_frame(u16::from(*b), &timing);
            *r = (dout >> 8) as u8;
            first += 8 * sck;
        }
        let end = last + sck / 2;
        part.set_cs(false, end);
        end
    }

    /// CPU time of `n` cycles.
    fn cycles(&self, n: u64) -> Ps {
        self.cpu.cycles_to_ps(n)
    }

    /// `n` PLB register accesses from the MicroBlaze.
    fn accesses(&self, n: u64) -> Ps {
        self.cycles(n * self.cfg.plb_access_cycles)
    }

    /// The time of tick `k`.
    pub fn tick_time(&self, k: u64) -> Ps {
        self.start + k * self.period
    }

    /// The tick period, ps.
    pub fn period(&self) -> Ps {
        self.period
    }

    /// Run the next tick: the packet it sends and what it took.
    pub fn tick(&mut self) -> Result<(Packet, TickTiming)> {
        let k = self.tick;
        self.tick += 1;
        // The interrupt waits while the previous tick's handler still runs.
        let t0 = self.tick_time(k).max(self.busy_until);
        let mut timing = TickTiming { t0, compass_phase: 3, ..TickTiming::default() };
        let mut t = t0 + self.cycles(self.cfg.isr_entry_cycles);
        timing.stages.push("entry", t - t0);
        // 2. Load and start the seven cores, in the order of the parts; 3. collect them.
        let mut raw = [[0u8; 7]; 7];
        for (i, rx) in raw.iter_mut().enumerate().take(self.parts.len()) {
            t += self.accesses(9);
            let mut tx = [0u8; 7];
            tx[0] = READ_DATA;
            let end = self.spi(i, &tx, rx, t);
            timing.spi[self.cores[i]] = (t, end);
        }
        for &core in &self.cores {
            t = t.max(timing.spi[core].1) + self.accesses(9);
        }
        timing.collected = t;
        timing.stages.push("accelerometers", t - (t0 + timing.stages.total()));
        // 4. The compass.
        let mut flags = 0;
        if t0 >= self.compass_ready {
            let phase = k % COMPASS_DIVIDER;
            let hmc = self.compass_address;
            match phase {
                0 => {
                    t += self.accesses(4);
                    let tr = self.iic.transfer(hmc, &[u16::from(POST_HEADING)], &mut [], t)?;
                    timing.iic = (tr.start, tr.end);
                }
                1 => {
                    t += self.accesses(4);
                    let mut rx = [0u16; 6];
                    let tr = self.iic.transfer(hmc, &[], &mut rx, t)?;
                    timing.iic = (tr.start, tr.end);
                    self.compass_read = Some((rx.map(|w| w as u8), tr.end));
                }
                2 => {
                    if let Some((bytes, ready)) = self.compass_read.take() {
                        t = t.max(ready) + self.accesses(7);
                        self.compass = std::array::from_fn(|j| i16::from_be_bytes([bytes[2 * j], bytes[2 * j + 1]]));
                        flags |= frame::NEW_COMPASS;
                    }
                }
                _ => {}
            }
            timing.compass_phase = phase.min(3) as u8;
        }
        timing.stages.push("compass", t - timing.collected);
        // 5. The GPS bytes DMA1 has moved since the last tick.
        let bytes = self.gps.bytes_until(t);
        if self.baud_mismatch && !bytes.is_empty() {
            let what = format!(
                "UART Lite at {} baud, the receiver sends at another rate: {} characters with framing errors, dropped",
                self.cfg.uart_baud,
                bytes.len()
            );
            self.events.push(Event::new(bytes[0].1, "uart_framing_error", Severity::Warning, what));
        } else {
            for &(b, tb) in &bytes {
                if let Some(body) = self.nmea.push(b, tb) {
                    timing.nmea_sentences += 1;
                    if self.sentence(&body) {
                        flags |= frame::NEW_GPS;
                    }
                }
            }
            for e in self.nmea.drain_events() {
                self.nmea_dropped = true;
                self.events.push(e);
            }
        }
        timing.nmea_bytes = bytes.len() as u32;
        if let (Some(first), Some(last)) = (bytes.first(), bytes.last()) {
            timing.uart = (first.1 - self.char_ps, last.1);
        }
        let before_gps = t;
        t += self.cycles(
            u64::from(timing.nmea_bytes) * self.cfg.nmea_cycles_per_byte
                + u64::from(timing.nmea_sentences) * self.cfg.nmea_cycles_per_sentence,
        );
        timing.stages.push("gps", t - before_gps);
        // 6. Pre-processing: the nine channels, each part's axes in turn (`array.parts`).
        let accel = self.channels.map(|(i, ax)| i16::from_le_bytes([raw[i][1 + 2 * ax], raw[i][2 + 2 * ax]]));
        if self.gps_valid {
            flags |= frame::GPS_VALID;
        }
        if std::mem::take(&mut self.nmea_dropped) {
            flags |= frame::NMEA_DROPPED;
        }
        let packet = Packet { sequence: k as u16, flags, accel, compass: self.compass, gps: self.gps_words };
        let before_packet = t;
        t += self.cycles(self.cfg.preprocess_cycles) + self.accesses(3);
        timing.dma_start = t;
        timing.stages.push("packet", t - before_packet);
        let sck8 = self.sck(self.cfg.dsp_sck_ratio);
        let words = frame::WORDS as u64;
        let first = t + self.cfg.ss_setup_half_periods * sck8 / 2;
        // The last bit's rising edge is half a period before the end; SS↑ half a period after it.
        timing.packet_end = first + words * 16 * sck8;
        // DMA2's completion interrupt.
        let dma_irq = self.cycles(self.cfg.isr_entry_cycles) + self.accesses(2);
        timing.stages.push("dma_irq", dma_irq);
        let cpu = (t - t0) + dma_irq;
        timing.cpu_ps = cpu;
        self.busy_until = t0 + cpu;
        let end = (t0 + cpu).max(timing.packet_end);
        let packet_end = timing.packet_end;
        let who = || format!("acquisition node, tick {k} (its packet out at {:.1} µs)", (packet_end - t0) as f64 / 1e6);
        if let Some(e) = deadline::check(who, t0, end, t0 + self.period) {
            self.events.push(e);
        }
        Ok((packet, timing))
    }

    /// Handle one checked NMEA body; whether it completed a new fix.
    fn sentence(&mut self, body: &str) -> bool {
        let f: Vec<&str> = body.split(',').collect();
        let utc_ms = |s: &str| -> Option<u32> {
            let (hms, frac) = s.split_once('.').unwrap_or((s, "0"));
            if hms.len() != 6 {
                return None;
            }
            let n: u32 = hms.parse().ok()?;
            let ms: u32 = format!("{frac:0<3}")[..3].parse().ok()?;
            Some(((n / 10_000) * 3600 + (n / 100 % 100) * 60 + n % 100) * 1000 + ms)
        };
        let angle = |v: &str, hemi: &str, deg_digits: usize| -> Option<i32> {
            if v.len() <= deg_digits {
                return None;
            }
            let deg: f64 = v[..deg_digits].parse().ok()?;
            let min: f64 = v[deg_digits..].parse().ok()?;
            let x = ((deg + min / 60.0) * 1e7).round() as i32;
            Some(if hemi == "S" || hemi == "W" { -x } else { x })
        };
        match f.first().copied() {
            Some("GPGGA") if f.len() >= 10 => {
                let fix = f[6].parse::<u32>().unwrap_or(0);
                let parsed = (|| {
                    let time = utc_ms(f[1])?;
                    let lat = angle(f[2], f[3], 2)?;
                    let lon = angle(f[4], f[5], 3)?;
                    let alt: f64 = f[9].parse().ok()?;
                    Some((time, [lat, lon, (alt * 100.0).round() as i32]))
                })();
                self.gga = if fix >= 1 { parsed } else { None };
                if fix == 0 {
                    self.gps_valid = false;
                }
                false
            }
            Some("GPRMC") if f.len() >= 9 => {
                let Some(time) = utc_ms(f[1]) else { return false };
                match self.gga.take() {
                    Some((gga_time, [lat, lon, alt])) if gga_time == time && f[2] == "A" => {
                        let knots: f64 = f[7].parse().unwrap_or(0.0);
                        let course: f64 = f[8].parse().unwrap_or(0.0);
                        self.gps_words = GpsWords {
                            lat_e7: lat,
                            lon_e7: lon,
                            alt_cm: alt,
                            speed_cm_s: (knots * 1852.0 / 36.0).round().clamp(0.0, 65_535.0) as u16,
                            course_cdeg: (course * 100.0).round().rem_euclid(36_000.0) as u16,
                            utc_ms: time,
                        };
                        self.gps_valid = true;
                        true
                    }
                    _ => {
                        self.gps_valid = false;
                        false
                    }
                }
            }
            _ => false,
        }
    }

    /// Take the node's, the parts' and the links' events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        let mut out = self.events.drain();
        for p in &mut self.parts {
            out.extend(p.drain_events());
        }
        out.extend(self.iic.drain_events());
        out.extend(self.compass_part.lock().unwrap_or_else(std::sync::PoisonError::into_inner).drain_events());
        out.extend(self.gps.drain_events());
        out
    }
}
