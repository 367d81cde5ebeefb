//! The I²C link kind: I2C-A (the master) and its targets, each at its 7-bit address; for the boards
//! that need it (the HMC6343 compass of the gyro-free board, at 100 kHz).
//!
//! The master times the wires from its SCL phases (`[board.i2c]`) and the protocol of i2c.md:
//! START, the address byte, data bytes with their ACK clock, a repeated START before a read, STOP,
//! and the bus-free time tBUF before the next START. Each byte takes nine SCL periods. The target
//! answers at byte level with the time of the bits it sees. An address no target answers is NACKed
//! (an `i2c_nack` event; the read bytes are the idle bus's 0xFF); SCL phases below the mode's
//! minimums (standard mode up to 100 kHz, fast mode up to 400 kHz) are reported once per
//! transaction (`i2c_scl_too_fast`, the lenient consequence of i2c.md). A target may stretch
//! SCL after a byte ([`I2cTarget::hold_scl`]); a master that does not wait breaks the rule
//! (`i2c_stretch_ignored`). The bit level (`i2c_bits.rs`) walks the same traffic on SCL and SDA.
//! Not modelled: arbitration, bus clear.

use super::{devices_of, Address, Device, Link, Transfer};
use crate::error::{Error, Result};
use crate::events::{Event, EventLog, Severity};
use crate::profile::{Board, BoardDevice, BoxedLink, Devices, I2cBus, LinkKind, Placed, Profile};
use crate::time::Ps;

/// The target (slave) side of an I²C link, at byte level.
pub trait I2cTarget {
    /// A START (or repeated START) at `t`.
    fn start(&mut self, t: Ps);
    /// The master wrote `byte` (the address byte after a START, then data) whose ninth clock rises
    /// at `t`: whether the target ACKs it.
    fn write(&mut self, byte: u8, t: Ps) -> bool;
    /// The master reads a byte whose first clock rises at `t`; `ack` is what the master answers after it.
    fn read(&mut self, t: Ps, ack: bool) -> u8;
    /// A STOP at `t`.
    fn stop(&mut self, t: Ps);
    /// Clock stretching: SCL fell at `t` after the ninth clock of a byte the target took part in;
    /// the target holds SCL low until the time returned (`t` or earlier: no stretching). Both link
    /// levels ask it at the same instant (`i2c_bits`).
    fn hold_scl(&mut self, t: Ps) -> Ps {
        t
    }
    /// Take the target's events out (the link hands them to the run's events).
    fn drain_events(&mut self) -> Vec<Event> {
        Vec::new()
    }
}

inventory::submit! {
    LinkKind {
        name: "i2c",
        links: &["i2c-a"],
        keys: &["address"],
        section: Some(("i2c", Board::defaults_of::<I2cBus>)),
        place: address,
        check: check_bus,
        fits: Device::is::<dyn I2cTarget + Send>,
        build: i2c_a,
    }
}

/// An I²C device's place: its 7-bit address (`address = 0x19`). 0x00-0x07 and 0x78-0x7F are
/// reserved [UM10204, unconfirmed here].
fn address(d: &BoardDevice) -> Placed {
    let expected = || "a 7-bit address 0x08…0x77".to_string();
    match d.keys.get("address") {
        None => Err(("address", "(missing)".into(), expected())),
        Some(v) => match v.as_integer().and_then(|a| u8::try_from(a).ok()) {
            Some(a @ 0x08..=0x77) => Ok(Address::I2c(a)),
            _ => Err(("address", v.to_string(), expected())),
        },
    }
}

/// `[board.i2c]`: phases the master can make and the fast mode allows.
fn check_bus(board: &Board) -> Result<()> {
    let i2c: I2cBus = board.section("i2c")?;
    let period = u64::from(i2c.scl_low_ns) + u64::from(i2c.scl_high_ns);
    if i2c.scl_low_ns == 0 || i2c.scl_high_ns == 0 || period < 2_500 {
        return Err(Error::Profile(format!(
            "key `board.i2c` = SCL low {} ns, high {} ns: expected phases of at least 1 ns and a period of at \
             least 2 500 ns (fast mode: 400 kHz at most, i2c.md)",
            i2c.scl_low_ns, i2c.scl_high_ns
        )));
    }
    Ok(())
}

/// I2C-A with its targets by address, at `[board.i2c]`'s SCL phases.
fn i2c_a(profile: &Profile, link: &str, devices: Devices) -> Result<BoxedLink> {
    let targets = devices_of::<dyn I2cTarget + Send, _>(link, devices, "an I²C target", |a| match a {
        Address::I2c(a) => Some(a),
        _ => None,
    })?;
    Ok(Box::new(I2cLink::new(&profile.board.section("i2c")?, targets)))
}

/// The minimum phases of one I²C mode (i2c.md, Table 10 as reproduced), ps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Mode {
    pub(crate) name: &'static str,
    pub(crate) t_low: Ps,
    pub(crate) t_high: Ps,
    pub(crate) t_buf: Ps,
}

pub(crate) const STANDARD: Mode = Mode { name: "standard mode", t_low: 4_700_000, t_high: 4_000_000, t_buf: 4_700_000 };
pub(crate) const FAST: Mode = Mode { name: "fast mode", t_low: 1_300_000, t_high: 600_000, t_buf: 1_300_000 };

/// SCL's low and high phases from `bus`, and the rules that apply: up to 100 kHz the standard
/// mode's, above it the fast mode's.
pub(super) fn phases(bus: &I2cBus) -> (Ps, Ps, Mode) {
    let (low, high) = (Ps::from(bus.scl_low_ns) * 1_000, Ps::from(bus.scl_high_ns) * 1_000);
    (low, high, if low + high >= 10_000_000 { STANDARD } else { FAST })
}

/// The master's side of an I²C link, the same at both levels (`I2cLink`, `i2c_bits::I2cBitLink`)
/// and for the F28335's I2C-A registers (`dsp::i2c`):
/// its targets by address, SCL's phases and the mode whose rules they meet, the last STOP, whether
/// it waits for a stretched SCL, its events; and what a transfer does before its bytes.
pub(crate) struct Master {
    pub(crate) targets: Vec<(u8, Box<dyn I2cTarget + Send>)>,
    /// SCL low and high phases, ps.
    pub(crate) low: Ps,
    pub(crate) high: Ps,
    pub(crate) mode: Mode,
    /// The last STOP (the bus is free tBUF after it).
    pub(crate) last_stop: Option<Ps>,
    /// Whether the master waits for a stretched SCL (a master that does not breaks the rule).
    pub(crate) honours_stretching: bool,
    pub(crate) events: EventLog,
}

impl Master {
    /// I2C-A with `targets` at their addresses, its SCL phases from `bus`.
    pub(super) fn new(bus: &I2cBus, targets: Vec<(u8, Box<dyn I2cTarget + Send>)>) -> Master {
        let (low, high, mode) = phases(bus);
        Master { targets, low, high, mode, last_stop: None, honours_stretching: true, events: EventLog::default() }
    }

    /// A master with `targets` whose SCL phases are set later ([`Master::set_phases`]).
    pub(crate) fn with_targets(targets: Vec<(u8, Box<dyn I2cTarget + Send>)>) -> Master {
        Master::new(&I2cBus::default(), targets)
    }

    /// SCL's low and high phases (ps), and the rules that apply: up to 100 kHz the standard mode's,
    /// above it the fast mode's (as [`phases`]).
    pub(crate) fn set_phases(&mut self, low: Ps, high: Ps) {
        self.low = low;
        self.high = high;
        self.mode = if low + high >= 10_000_000 { STANDARD } else { FAST };
    }

    /// A transfer to `to` asked at `t`: the target's 7-bit address and the START's time (the master
    /// waits for the bus to be free, tBUF after the last STOP); SCL phases below the mode's are
    /// reported once per transfer. An error for an address that is not I²C's or a byte that does
    /// not fit.
    pub(crate) fn begin(&mut self, to: Address, tx: &[u16], t: Ps) -> Result<(u8, Ps)> {
        let Address::I2c(address) = to else {
            return Err(Error::Config(format!("I2C-A addresses a device by its 7-bit address, not by {to}")));
        };
        if address > 0x7F || tx.iter().any(|&w| w > 0xFF) {
            return Err(Error::Config(format!("I2C-A: address 0x{address:X} or a byte of {tx:X?} does not fit")));
        }
        let (low, high) = (self.low, self.high);
        let start = self.last_stop.map_or(t, |stop| t.max(stop + self.mode.t_buf));
        if low < self.mode.t_low || high < self.mode.t_high {
            let (mode, ll, hh) = (self.mode, self.mode.t_low, self.mode.t_high);
            self.events.push(Event::new(
                start,
                "i2c_scl_too_fast",
                Severity::Warning,
                format!(
                    "I2C-A SCL low {low} ps, high {high} ps: {} needs at least {ll} ps low and {hh} ps high",
                    mode.name
                ),
            ));
        }
        Ok((address, start))
    }

    /// The link as `{:?}` shows it (both levels, as `name`): its targets' addresses and SCL's low
    /// phase (the targets themselves are trait objects).
    pub(super) fn debug_as(&self, f: &mut std::fmt::Formatter<'_>, name: &str) -> std::fmt::Result {
        let addresses: Vec<u8> = self.targets.iter().map(|(a, _)| *a).collect();
        f.debug_struct(name).field("addresses", &addresses).field("low", &self.low).finish()
    }
}

/// No target acknowledged `address` (in a read or a write): an `i2c_nack` event at `t`.
#[cold]
pub(crate) fn nack_address(events: &mut EventLog, t: Ps, address: u8, reading: bool) {
    let what =
        format!("I2C-A: no device acknowledged address 0x{address:02X} ({})", if reading { "read" } else { "write" });
    events.push(Event::new(t, "i2c_nack", Severity::Warning, what));
}

/// The target at `address` refused byte `k` (`byte`) of a write: an `i2c_nack` event at `t`.
#[cold]
pub(super) fn nack_byte(events: &mut EventLog, t: Ps, address: u8, k: usize, byte: u16) {
    let what = format!("I2C-A: device 0x{address:02X} refused byte {k} (0x{byte:02X}) of a write");
    events.push(Event::new(t, "i2c_nack", Severity::Warning, what));
}

/// I2C-A and its targets.
pub struct I2cLink {
    m: Master,
}

impl std::fmt::Debug for I2cLink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.m.debug_as(f, "I2cLink")
    }
}

impl I2cLink {
    /// I2C-A with `targets` at their addresses, its SCL phases from `bus`.
    pub fn new(bus: &I2cBus, targets: Vec<(u8, Box<dyn I2cTarget + Send>)>) -> I2cLink {
        I2cLink { m: Master::new(bus, targets) }
    }

    /// Make the master wait for a stretched SCL (the rule, the default) or time its clock on its
    /// own (breaking it: an `i2c_stretch_ignored` event each time a target holds SCL).
    pub fn set_honours_stretching(&mut self, on: bool) {
        self.m.honours_stretching = on;
    }

    /// After a byte whose ninth clock fell at `fall`: the time the bus goes on from, later by what
    /// target `i` stretches SCL beyond the low phase (see [`I2cTarget::hold_scl`]).
    fn stretched(&mut self, i: Option<usize>, fall: Ps) -> Ps {
        let Some(i) = i else { return fall };
        let m = &mut self.m;
        let release = m.targets[i].1.hold_scl(fall);
        stretch_rule(release, fall, m.low, m.honours_stretching, &mut m.events)
    }

    /// One SCL period.
    pub fn period(&self) -> Ps {
        self.m.low + self.m.high
    }

    /// The target at `address`.
    pub fn target(&self, address: u8) -> Option<&(dyn I2cTarget + Send)> {
        self.m.targets.iter().find(|(a, _)| *a == address).map(|(_, t)| t.as_ref())
    }
}

impl Link for I2cLink {
    fn transfer(&mut self, to: Address, tx: &[u16], rx: &mut [u16], t: Ps) -> Result<Transfer> {
        let (address, start) = self.m.begin(to, tx, t)?;
        let (low, high, period) = (self.m.low, self.m.high, self.period());
        let target = self.m.targets.iter().position(|(a, _)| *a == address);
        // START, then tHD;STA (one high phase) before SCL first falls; a byte is nine SCL periods.
        let mut now = start + high;
        let mut complete = true;
        let byte_out = |link: &mut I2cLink, byte: u8, now: &mut Ps| -> bool {
            let ninth_rise = *now + 8 * period + low;
            *now += 9 * period;
            let ack = match target {
                Some(i) => link.m.targets[i].1.write(byte, ninth_rise),
                None => false,
            };
            *now = link.stretched(target, *now);
            ack
        };
        if let Some(i) = target {
            self.m.targets[i].1.start(start);
        }
        let phases: [(bool, usize); 2] = [(false, tx.len()), (true, rx.len())];
        for (reading, count) in phases {
            if count == 0 && (reading || !rx.is_empty()) {
                continue;
            }
            if reading && !tx.is_empty() {
                // Repeated START: SCL rises after its low phase, tSU;STA and tHD;STA of one high phase each.
                let restart = now + low + high;
                if let Some(i) = target {
                    self.m.targets[i].1.start(restart);
                }
                now = restart + high;
            }
            let rw = u8::from(reading);
            if !byte_out(self, (address << 1) | rw, &mut now) {
                complete = false;
                nack_address(&mut self.m.events, now, address, reading);
                break;
            }
            if reading {
                for (k, r) in rx.iter_mut().enumerate() {
                    let ack = k + 1 < count;
                    let first_rise = now + low;
                    *r = u16::from(target.map_or(0xFF, |i| self.m.targets[i].1.read(first_rise, ack)));
                    now += 9 * period;
                    now = self.stretched(target, now);
                }
            } else {
                for (k, &w) in tx.iter().enumerate() {
                    if !byte_out(self, w as u8, &mut now) {
                        complete = false;
                        nack_byte(&mut self.m.events, now, address, k, w);
                        break;
                    }
                }
                if !complete {
                    break;
                }
            }
        }
        if !complete {
            rx.iter_mut().for_each(|r| *r = 0xFF);
        }
        // STOP: SCL rises after its low phase, SDA after tSU;STO (one high phase).
        let stop = now + low + high;
        if let Some(i) = target {
            self.m.targets[i].1.stop(stop);
        }
        self.m.last_stop = Some(stop);
        Ok(Transfer { start, end: stop, complete })
    }

    fn drain_events(&mut self) -> Vec<Event> {
        let mut e = self.m.events.drain();
        for (_, t) in &mut self.m.targets {
            e.extend(t.drain_events());
        }
        e
    }
}

/// The rule of a stretched SCL: the master that honours it goes on from `release` when that is
/// after its own low phase; one that does not keeps its own time and an `i2c_stretch_ignored` event
/// is reported. Returns the time the bus goes on from (the clock's fall before the next low phase).
pub(crate) fn stretch_rule(release: Ps, fall: Ps, low: Ps, honours: bool, events: &mut EventLog) -> Ps {
    if release <= fall + low {
        return fall;
    }
    if honours {
        return release - low;
    }
    events.push(Event::new(
        fall + low,
        "i2c_stretch_ignored",
        Severity::Warning,
        format!("I2C master raised SCL at {} ps while the target held it low until {release} ps", fall + low),
    ));
    fall
}

/// A target for the tests of both link levels: records every call with its time, answers reads
/// from a counter, refuses a write of 0xEE and, given a stretch, holds SCL that long after each
/// byte (recording the hold).
#[cfg(test)]
pub(crate) mod probe {
    use super::*;

    /// What a [`Probe`] saw, shared with the test.
    pub(crate) type Seen = std::sync::Arc<std::sync::Mutex<Vec<String>>>;

    pub(crate) struct Probe {
        pub seen: Seen,
        pub next: u8,
        /// `None`: the target never stretches SCL (the trait's default).
        pub stretch: Option<Ps>,
    }

    impl Probe {
        /// A probe recording into `seen`, stretching by `stretch`.
        pub(crate) fn new(seen: &Seen, stretch: Option<Ps>) -> Probe {
            Probe { seen: std::sync::Arc::clone(seen), next: 0, stretch }
        }

        fn note(&self, what: String) {
            self.seen.lock().unwrap().push(what);
        }
    }

    impl I2cTarget for Probe {
        fn start(&mut self, t: Ps) {
            self.note(format!("S@{t}"));
        }
        fn write(&mut self, byte: u8, t: Ps) -> bool {
            self.note(format!("W{byte:02X}@{t}"));
            byte != 0xEE
        }
        fn read(&mut self, t: Ps, ack: bool) -> u8 {
            self.note(format!("R{}@{t}", if ack { "A" } else { "N" }));
            self.next = self.next.wrapping_add(1);
            self.next
        }
        fn stop(&mut self, t: Ps) {
            self.note(format!("P@{t}"));
        }
        fn hold_scl(&mut self, t: Ps) -> Ps {
            let Some(stretch) = self.stretch else { return t };
            self.note(format!("H@{t}"));
            t + stretch
        }
    }
}

#[cfg(test)]
mod tests {
    use super::probe::Probe;
    use super::*;

    /// At 100 kHz (5 µs + 5 µs) a write of one register address then a read of two bytes takes:
    /// START + 5 µs hold, address+W and one byte (2 × 90 µs), repeated START (10 µs + 5 µs hold),
    /// address+R and two bytes (3 × 90 µs), STOP (10 µs): 480 µs; the master NACKs the last byte.
    /// i2c.md: "At 100 kHz one byte + ACK = 90 µs".
    #[test]
    fn a_register_read_is_timed_by_the_protocol() {
        let seen = std::sync::Arc::default();
        let probe = Probe::new(&seen, None);
        let mut link = I2cLink::new(&I2cBus::default(), vec![(0x19, Box::new(probe))]);
        let mut rx = [0u16; 2];
        let tr = link.transfer(Address::I2c(0x19), &[0x42], &mut rx, 1_000).unwrap();
        assert_eq!(rx, [1, 2]);
        assert_eq!((tr.start, tr.end, tr.complete), (1_000, 1_000 + 480_000_000, true));
        let us = 1_000_000;
        let ninth = |byte_start: Ps| 1_000 + byte_start + 8 * 10 * us + 5 * us;
        let expect = [
            "S@1000".to_string(),
            format!("W32@{}", ninth(5 * us)),
            format!("W42@{}", ninth(95 * us)),
            format!("S@{}", 1_000 + 195 * us),
            format!("W33@{}", ninth(200 * us)),
            format!("RA@{}", 1_000 + 290 * us + 5 * us),
            format!("RN@{}", 1_000 + 380 * us + 5 * us),
            format!("P@{}", 1_000 + 480 * us),
        ];
        assert_eq!(*seen.lock().unwrap(), expect);
        assert!(link.drain_events().is_empty());
        // The next START waits for the bus-free time after the STOP (standard mode: 4.7 µs).
        let tr = link.transfer(Address::I2c(0x19), &[1], &mut [], 0).unwrap();
        assert_eq!(tr.start, 1_000 + 480 * us + 4_700_000);
    }

    #[test]
    fn an_absent_address_is_nacked_and_a_fast_clock_reported() {
        let mut link = I2cLink::new(&I2cBus { scl_low_ns: 1_250, scl_high_ns: 1_250 }, vec![]);
        let mut rx = [0u16; 1];
        let tr = link.transfer(Address::I2c(0x1E), &[0x50], &mut rx, 0).unwrap();
        assert!(!tr.complete);
        assert_eq!(rx, [0xFF]);
        let events = link.drain_events();
        let kinds: Vec<&str> = events.iter().map(|e| e.kind).collect();
        // 400 kHz with equal halves: 1.25 µs low is under fast mode's 1.3 µs (i2c.md, "Derived").
        assert_eq!(kinds, ["i2c_scl_too_fast", "i2c_nack"]);
        assert!(events[1].message.contains("0x1E"), "{}", events[1].message);
        assert!(link.transfer(Address::ChipSelect(57), &[], &mut [], 0).is_err());
    }
}
