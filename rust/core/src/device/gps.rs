//! The GPS receiver (HOLUX GR-87, SiRF-based) as a UART peer: NMEA 0183 v2.2 sentences GGA, GSA,
//! RMC, VTG at 1 Hz, 19 200 baud 8N1 on the gyro-free board. Formats, checksums, rates and
//! accuracy from `gps-nmea.md` (HOLUX GR-213U/GR-213/GR-89 manuals; no GR-87 document was found, so
//! every module-specific figure is [unconfirmed for GR-87]).
//!
//! - **Sentences**: `$GP…*hh` CR LF, checksum the XOR of the characters between `$` and `*`; empty
//!   fields written `,,`; RMC and VTG without the mode field (SiRF v2.2); GGA's DGPS station `0000`.
//! - **Timing**: one fix per second at the epoch (UTC whole seconds); its sentences start after the
//!   receiver's latency (`latency_ps`, 200 ms by default [unconfirmed]: gps-nmea.md's "about one
//!   report period" at 5 Hz) and go out back to back, one character per 10 bit times.
//! - **Errors**: white horizontal position noise of 1σ = CEP / 1.1774 per axis (CEP 5 m, GR-213
//!   without SA, the best of 5–25 m), vertical 1.5 × that [unconfirmed], velocity 0.1 m/s (GR-213).
//! - **Faults**: a corrupted sentence (one character flipped after the checksum is computed), a
//!   lost fix (status V, fix 0, empty position fields [unconfirmed for GR-87]), a cold start (no fix
//!   for 42 s, GR-89/GR-213 "cold start 42 s averaged").
//! - **Receiving side**: [`NmeaReader`] assembles lines from bytes and checks each checksum; a bad
//!   one is an event (`nmea_bad_checksum`), never a panic.

use crate::bus::uart::{UartPeer, BITS_PER_CHAR};
use crate::events::{Event, EventLog, Severity};
use crate::time::{Ps, PS_PER_S};
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::VecDeque;
use std::fmt::Write as _;

/// The vehicle's true state at a time, as the receiver's antenna sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    /// Latitude, ° (north positive).
    pub lat_deg: f64,
    /// Longitude, ° (east positive).
    pub lon_deg: f64,
    /// Altitude above mean sea level, m.
    pub alt_m: f64,
    /// Speed over ground, m/s.
    pub speed_m_s: f64,
    /// Course over ground, ° true.
    pub course_deg: f64,
}

/// What the receiver's antenna sees over time.
pub type Stimulus = Box<dyn FnMut(Ps) -> Truth + Send>;

/// A fault of the receiver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// The sentence `index` (0 GGA, 1 GSA, 2 RMC, 3 VTG) of epoch `epoch` goes out with one
    /// character flipped (its checksum no longer matches).
    CorruptSentence {
        /// Epoch (seconds since power-on).
        epoch: u64,
        /// Which sentence of the epoch.
        index: usize,
    },
    /// No fix from epoch `from` to `to` (excluded).
    LostFix {
        /// First epoch without a fix.
        from: u64,
        /// First epoch with a fix again.
        to: u64,
    },
    /// A cold start at epoch `at`: no fix for [`COLD_START_S`] seconds.
    ColdStart {
        /// The epoch of the restart.
        at: u64,
    },
}

/// Time to first fix after a cold start, s (GR-89, GR-213: "cold start 42 s averaged").
pub const COLD_START_S: u64 = 42;

/// The receiver's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// Epoch to sentence start, ps ([unconfirmed]).
    pub latency_ps: Ps,
    /// UTC seconds of the day at power-on.
    pub utc_s: u64,
    /// UTC date at power-on: day, month, two-digit year.
    pub date: (u8, u8, u8),
    /// Horizontal CEP, m (GR-213: 5–25 m without SA).
    pub cep_m: f64,
    /// Velocity 1σ, m/s (GR-213: 0.1 m/s).
    pub velocity_sigma_m_s: f64,
    /// Line rate, baud (19 200 on the board; HOLUX default 4 800).
    pub baud: u32,
    /// Noise seed.
    pub seed: u64,
    /// Faults.
    pub faults: Vec<Fault>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            latency_ps: 200_000_000_000,
            utc_s: 16 * 3600 + 12 * 60 + 29,
            date: (12, 5, 98),
            cep_m: 5.0,
            velocity_sigma_m_s: 0.1,
            baud: 19_200,
            seed: 0,
            faults: Vec::new(),
        }
    }
}

/// Metres per degree of latitude (WGS-84 mean, for the noise only).
const M_PER_DEG: f64 = 111_320.0;
/// Knots per m/s.
const KNOTS_PER_M_S: f64 = 3600.0 / 1852.0;
/// The satellites the GSA and GGA report (the HOLUX example's seven).
const SATELLITES: [u8; 7] = [7, 2, 26, 27, 9, 4, 15];

/// The checksum of a sentence body (the characters between `$` and `*`).
pub fn checksum(body: &str) -> u8 {
    body.bytes().fold(0, |a, b| a ^ b)
}

/// `body` as a sentence: `$body*hh` CR LF.
pub fn sentence(body: &str) -> String {
    format!("${body}*{:02X}\r\n", checksum(body))
}

/// The body of a line (`$…*hh`, CR LF optional) if its checksum matches, else why not.
pub fn check(line: &str) -> Result<&str, String> {
    let line = line.trim_end_matches(['\r', '\n']);
    let rest = line.strip_prefix('$').ok_or_else(|| format!("no `$` at the start of {line:?}"))?;
    let (body, sum) = rest.rsplit_once('*').ok_or_else(|| format!("no `*` checksum in {line:?}"))?;
    let want = u8::from_str_radix(sum, 16).map_err(|_| format!("checksum {sum:?} is not two hex digits"))?;
    match checksum(body) {
        got if got == want && sum.len() == 2 => Ok(body),
        got => Err(format!("checksum {sum} does not match the body's {got:02X} in {line:?}")),
    }
}

fn ddmm(deg: f64, width: usize) -> (String, bool) {
    let a = deg.abs();
    let mut d = a.trunc();
    let mut m = ((a - d) * 60.0 * 10_000.0).round() / 10_000.0;
    if m >= 60.0 {
        d += 1.0;
        m -= 60.0;
    }
    (format!("{:0w$}{:07.4}", d as u32, m, w = width), deg >= 0.0)
}

/// One fix as the receiver reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fix {
    /// Epoch, s since power-on.
    pub epoch: u64,
    /// The reported state (None: no fix).
    pub state: Option<Truth>,
}

/// The sentences of one epoch: GGA, GSA, RMC, VTG (each with CR LF).
pub fn sentences(fix: &Fix, settings: &Settings) -> [String; 4] {
    let tod = (settings.utc_s + fix.epoch) % 86_400;
    let days = (settings.utc_s + fix.epoch) / 86_400;
    let (d, mo, y) = settings.date;
    // Day roll-over without a calendar: only the day of the month moves (runs are hours long).
    let date = format!("{:02}{mo:02}{y:02}", u64::from(d) + days);
    let time = format!("{:02}{:02}{:02}.000", tod / 3600, tod / 60 % 60, tod % 60);
    let sats: Vec<String> = SATELLITES.iter().map(|s| format!("{s:02}")).collect();
    let (gga, gsa, rmc, vtg) = match fix.state {
        Some(s) => {
            let (lat, north) = ddmm(s.lat_deg, 2);
            let (lon, east) = ddmm(s.lon_deg, 3);
            let (ns, ew) = (if north { "N" } else { "S" }, if east { "E" } else { "W" });
            let knots = s.speed_m_s * KNOTS_PER_M_S;
            let kmh = s.speed_m_s * 3.6;
            let course = s.course_deg.rem_euclid(360.0);
            (
                format!("GPGGA,{time},{lat},{ns},{lon},{ew},1,{:02},1.0,{:.1},M,,,,0000", SATELLITES.len(), s.alt_m),
                format!("GPGSA,A,3,{},{},1.8,1.0,1.5", sats.join(","), ",".repeat(12 - SATELLITES.len() - 1)),
                format!("GPRMC,{time},A,{lat},{ns},{lon},{ew},{knots:.2},{course:.2},{date},,"),
                format!("GPVTG,{course:.2},T,,M,{knots:.2},N,{kmh:.1},K"),
            )
        }
        None => (
            format!("GPGGA,{time},,,,,0,00,,,M,,,,0000"),
            format!("GPGSA,A,1,{},,,", ",".repeat(11)),
            format!("GPRMC,{time},V,,,,,,,{date},,"),
            "GPVTG,,T,,M,,N,,K".to_string(),
        ),
    };
    [gga, gsa, rmc, vtg].map(|b| sentence(&b))
}

/// The GPS receiver.
pub struct Gps {
    settings: Settings,
    stimulus: Stimulus,
    rng: Xoshiro256PlusPlus,
    char_ps: Ps,
    /// The next epoch to write.
    next_epoch: u64,
    /// Bytes on their way out, with the end of each one's stop bit.
    queue: VecDeque<(u8, Ps)>,
    /// The end of the last byte scheduled.
    line_free: Ps,
    events: EventLog,
}

impl std::fmt::Debug for Gps {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Gps").field("settings", &self.settings).field("next_epoch", &self.next_epoch).finish()
    }
}

impl Gps {
    /// A receiver powered at time 0 seeing `stimulus`.
    pub fn new(settings: Settings, stimulus: Stimulus) -> Gps {
        let rng = Xoshiro256PlusPlus::seed_from_u64(settings.seed);
        let baud = u64::from(settings.baud.max(1));
        let char_ps = (BITS_PER_CHAR * PS_PER_S + baud / 2) / baud;
        Gps {
            settings,
            stimulus,
            rng,
            char_ps,
            next_epoch: 0,
            queue: VecDeque::new(),
            line_free: 0,
            events: EventLog::default(),
        }
    }

    /// A receiver standing still at the HOLUX example's place (37°23.2475′ N, 121°58.3416′ W), no
    /// noise: what a board declaration builds.
    pub fn at_rest() -> Gps {
        let truth = Truth {
            lat_deg: 37.0 + 23.2475 / 60.0,
            lon_deg: -(121.0 + 58.3416 / 60.0),
            alt_m: 9.0,
            speed_m_s: 0.0,
            course_deg: 0.0,
        };
        Gps::new(Settings { cep_m: 0.0, velocity_sigma_m_s: 0.0, ..Settings::default() }, Box::new(move |_| truth))
    }

    /// Take the receiver's events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }

    /// The fix of `epoch`: the truth at the epoch with the noise, or none in a fault.
    fn fix(&mut self, epoch: u64) -> Fix {
        let truth = (self.stimulus)(epoch * PS_PER_S);
        let no_fix = self.settings.faults.iter().any(|f| match *f {
            Fault::LostFix { from, to } => (from..to).contains(&epoch),
            Fault::ColdStart { at } => (at..at + COLD_START_S).contains(&epoch),
            Fault::CorruptSentence { .. } => false,
        });
        let mut n = || self.rng.sample::<f64, _>(StandardNormal);
        let (e, nn, u, v) = (n(), n(), n(), n());
        if no_fix {
            return Fix { epoch, state: None };
        }
        let sigma = self.settings.cep_m / 1.1774;
        let lat = truth.lat_deg + sigma * nn / M_PER_DEG;
        let lon = truth.lon_deg + sigma * e / (M_PER_DEG * truth.lat_deg.to_radians().cos().max(1e-6));
        let speed = (truth.speed_m_s + self.settings.velocity_sigma_m_s * v).max(0.0);
        Fix {
            epoch,
            state: Some(Truth {
                lat_deg: lat,
                lon_deg: lon,
                alt_m: truth.alt_m + 1.5 * sigma * u,
                speed_m_s: speed,
                ..truth
            }),
        }
    }

    /// Write the sentences of the next epoch onto the line.
    fn write_epoch(&mut self) {
        let epoch = self.next_epoch;
        self.next_epoch += 1;
        let fix = self.fix(epoch);
        let t0 = epoch * PS_PER_S + self.settings.latency_ps;
        if fix.state.is_none() {
            let what = format!("GPS: no fix at epoch {epoch} s (lost fix or cold start)");
            self.events.push(Event::new(t0, "fault_injected", Severity::Warning, what));
        }
        let mut start = t0.max(self.line_free);
        for (i, s) in sentences(&fix, &self.settings).into_iter().enumerate() {
            let mut bytes = s.into_bytes();
            if self.settings.faults.contains(&Fault::CorruptSentence { epoch, index: i }) {
                // Flip a bit of the first character after `$GP`: the checksum no longer matches.
                bytes[3] ^= 0x01;
                let what = format!("GPS: sentence {i} of epoch {epoch} s corrupted");
                self.events.push(Event::new(t0, "fault_injected", Severity::Warning, what));
            }
            for b in bytes {
                start += self.char_ps;
                self.queue.push_back((b, start));
            }
        }
        self.line_free = start;
    }

    /// Every byte whose stop bit ends at or before `t`, in order (the line as a listener would log it).
    pub fn bytes_until(&mut self, t: Ps) -> Vec<(u8, Ps)> {
        while self.next_epoch * PS_PER_S + self.settings.latency_ps <= t {
            self.write_epoch();
        }
        let n = self.queue.iter().take_while(|(_, e)| *e <= t).count();
        self.queue.drain(..n).collect()
    }
}

impl UartPeer for Gps {
    fn receive(&mut self, _byte: u8, _t: Ps) {
        // The receiver's input (SiRF commands) is not modelled: what the MCU sends is ignored.
    }

    fn transmit(&mut self, t: Ps) -> Option<(u8, Ps)> {
        while self.queue.is_empty() || self.next_epoch * PS_PER_S + self.settings.latency_ps <= t {
            self.write_epoch();
            if self.queue.len() > 1 << 16 {
                break;
            }
        }
        self.queue.pop_front()
    }
    fn drain_events(&mut self) -> Vec<Event> {
        Gps::drain_events(self)
    }
}

/// The receiving side's sentence assembler: bytes in, checked sentence bodies out; a bad checksum
/// or an over-long line is an event, never a panic.
#[derive(Debug, Default)]
pub struct NmeaReader {
    line: Vec<u8>,
    events: EventLog,
}

/// Longest line kept, bytes (NMEA's 82 with room for receivers that exceed it).
const MAX_LINE: usize = 256;

impl NmeaReader {
    /// Feed one byte received at `t`; a complete line with a good checksum comes back as its body.
    pub fn push(&mut self, byte: u8, t: Ps) -> Option<String> {
        if byte == b'$' {
            self.line.clear();
        }
        if byte != b'\n' {
            if self.line.len() < MAX_LINE {
                self.line.push(byte);
            }
            return None;
        }
        let line = String::from_utf8_lossy(&self.line).into_owned();
        self.line.clear();
        match check(&line) {
            Ok(body) => Some(body.to_string()),
            Err(why) => {
                let mut what = String::from("NMEA line dropped: ");
                let _ = write!(what, "{why}");
                self.events.push(Event::new(t, "nmea_bad_checksum", Severity::Warning, what));
                None
            }
        }
    }

    /// Take the reader's events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }
}

/// The lines a receiver with `settings` seeing `stimulus` writes in its first `seconds` seconds,
/// each with the end time of its last character (for the binding and the NMEA parser tests).
pub fn lines(settings: Settings, stimulus: Stimulus, seconds: u64) -> Vec<(Ps, String)> {
    let mut gps = Gps::new(settings, stimulus);
    let mut out = Vec::new();
    let mut line = Vec::new();
    for (b, t) in gps.bytes_until(seconds * PS_PER_S) {
        line.push(b);
        if b == b'\n' {
            out.push((t, String::from_utf8_lossy(&line).into_owned()));
            line.clear();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::uart::UartLink;
    use crate::bus::{Address, Link};
    use crate::profile::SciPort;

    /// gps-nmea.md's verified HOLUX examples: the checksum rule reproduces each one, and the model
    /// writes the GGA, RMC and VTG of the example's fix character for character.
    #[test]
    fn checksums_and_formats_are_the_holux_examples() {
        for line in [
            "$GPGGA,161229.487,3723.2475,N,12158.3416,W,1,07,1.0,9.0,M,,,,0000*18",
            "$GPGSA,A,3,07,02,26,27,09,04,15,,,,,,1.8,1.0,1.5*33",
            "$GPRMC,161229.487,A,3723.2475,N,12158.3416,W,0.13,309.62,120598,,*10",
            "$GPVTG,309.62,T,,M,0.13,N,0.2,K*6E",
            "$GPGLL,3723.2475,N,12158.3416,W,161229.487,A*2C",
        ] {
            assert!(check(line).is_ok(), "{line}");
        }
        let truth = Truth {
            lat_deg: 37.0 + 23.2475 / 60.0,
            lon_deg: -(121.0 + 58.3416 / 60.0),
            alt_m: 9.0,
            speed_m_s: 0.13 / KNOTS_PER_M_S,
            course_deg: 309.62,
        };
        let s = sentences(&Fix { epoch: 0, state: Some(truth) }, &Settings::default());
        assert_eq!(s[0], "$GPGGA,161229.000,3723.2475,N,12158.3416,W,1,07,1.0,9.0,M,,,,0000*13\r\n");
        assert_eq!(s[1], "$GPGSA,A,3,07,02,26,27,09,04,15,,,,,,1.8,1.0,1.5*33\r\n");
        assert_eq!(s[2], "$GPRMC,161229.000,A,3723.2475,N,12158.3416,W,0.13,309.62,120598,,*1B\r\n");
        assert_eq!(s[3], "$GPVTG,309.62,T,,M,0.13,N,0.2,K*6E\r\n");
        for line in s.iter().chain(sentences(&Fix { epoch: 5, state: None }, &Settings::default()).iter()) {
            assert!(check(line).is_ok() && line.len() <= 82, "{line}");
        }
    }

    /// Through SCI-A at 19 200 baud: the first epoch's four sentences arrive 200 ms after it, one
    /// character per 520.83 µs, back to back; the reader passes them and drops a corrupted one with
    /// an event; a cold start gives 42 s of sentences without a fix.
    #[test]
    fn sentences_arrive_on_the_uart_at_their_time() {
        let settings = Settings {
            faults: vec![Fault::CorruptSentence { epoch: 1, index: 2 }, Fault::ColdStart { at: 3 }],
            ..Settings::default()
        };
        let gps = Gps::new(settings, Box::new(|_| Gps::at_rest().fix(0).state.unwrap()));
        let mut link = UartLink::new(&SciPort::default(), Some(Box::new(gps)));
        let char_ps = link.char_ps();
        assert_eq!(char_ps, 520_833_333);
        let mut reader = NmeaReader::default();
        let mut bodies = Vec::new();
        let mut rx = [0u16; 1];
        let mut t = 0;
        let mut first_end = None;
        while bodies.len() < 4 * 50 - 1 {
            let tr = link.transfer(Address::Port, &[], &mut rx, t).unwrap();
            first_end.get_or_insert(tr.end);
            t = tr.end;
            if let Some(b) = reader.push(rx[0] as u8, t) {
                bodies.push(b);
            }
        }
        assert_eq!(first_end, Some(200_000_000_000 + char_ps), "the `$` of GGA ends one character after 200 ms");
        let events = reader.drain_events();
        assert_eq!(events.len(), 1);
        assert_eq!(events[0].kind, "nmea_bad_checksum");
        assert!(bodies[6].starts_with("GPVTG") && bodies[7].starts_with("GPGGA,161231"), "epoch 1 lost its RMC");
        let no_fix = bodies.iter().filter(|b| b.starts_with("GPRMC") && b.contains(",V,")).count();
        assert_eq!(no_fix, usize::try_from(COLD_START_S).unwrap());
    }

    /// The noise: same seed, same sentences; horizontal scatter of 1σ = CEP/1.1774 per axis
    /// (within 10 %: 2000 fixes give a sample σ within ≈ 1.6 % at 1σ, so 10 % is 6 of those).
    #[test]
    fn position_noise_has_the_cep() {
        let still = |_| Truth { lat_deg: 40.0, lon_deg: 116.0, alt_m: 50.0, speed_m_s: 0.0, course_deg: 0.0 };
        let settings = Settings { seed: 9, ..Settings::default() };
        assert_eq!(lines(settings.clone(), Box::new(still), 5), lines(settings.clone(), Box::new(still), 5));
        let mut gps = Gps::new(settings, Box::new(still));
        let n = 2000;
        let dn: Vec<f64> = (0..n).map(|k| (gps.fix(k).state.unwrap().lat_deg - 40.0) * M_PER_DEG).collect();
        let sigma = (dn.iter().map(|d| d * d).sum::<f64>() / n as f64).sqrt();
        assert!((sigma / (5.0 / 1.1774) - 1.0).abs() < 0.1, "north σ {sigma} m");
    }
}
