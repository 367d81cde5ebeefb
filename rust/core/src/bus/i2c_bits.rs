//! The I²C link at bit level: the same traffic as [`I2cLink`](super::i2c::I2cLink) walked on the two
//! open-drain wires. The master drives SCL and SDA phase by phase from its SCL phases; each line is
//! the wired-AND of what the master and the target drive; the target side is a decoder that sees only
//! the lines: a START is SDA falling while SCL is high, a STOP SDA rising while SCL is high, a bit is
//! SDA at an SCL rise, the ninth clock carries the receiver's ACK (SDA low) or NACK. The decoder
//! matches the address byte against the targets' addresses and hands the target the same calls at
//! the same times as the transaction level (`start`, `write` at the ninth rise, `read` at the first
//! rise, `stop`, `hold_scl` at the ninth fall), so that the two levels agree word for word and time
//! for time (the tests below run both on the same traffic).
//!
//! Choices at this level, stated: a target's ACK and its data bits are put on SDA at the SCL rise
//! that samples them (its set-up time tSU;DAT is not modelled); the `ack` a target is handed with a
//! read byte is the master-receiver's plan (it knows how many bytes it reads), not yet on the wire;
//! a master that does not wait for a stretched SCL keeps its own clock (the contention is the
//! `i2c_stretch_ignored` event).

use super::i2c::{nack_address, nack_byte, stretch_rule, I2cTarget, Master};
use super::{Address, Link, Transfer};
use crate::error::Result;
use crate::events::{Event, EventLog};
use crate::profile::I2cBus;
use crate::time::Ps;

/// One change of the wires: time, SCL, SDA (true = high).
pub type Level = (Ps, bool, bool);

/// What the target side has seen on the lines.
#[derive(Debug, Default)]
struct Decoder {
    /// Between a START and a STOP.
    active: bool,
    /// Time of the last START (or repeated START).
    start_at: Ps,
    /// The target the address byte matched, this transaction.
    selected: Option<usize>,
    /// SCL rises seen in the current byte (0…9).
    count: u8,
    /// The byte assembled from SDA.
    byte: u8,
    /// The byte being received is the address byte.
    address_phase: bool,
    /// The selected target shifts bytes out (the address's R/W bit was 1).
    transmitting: bool,
    /// The byte the target shifts out.
    out: u8,
    /// The master-receiver ACKed the last byte.
    master_acked: bool,
    /// The target's part of the transaction is over (until a START or STOP).
    done: bool,
    /// What the target drives on SDA (true: released).
    sda: bool,
    /// How long the target holds SCL after the last byte (`hold_scl`'s answer).
    hold: Option<Ps>,
}

/// The two wires, the master's drives and the target side's decoder.
struct Wires<'a> {
    targets: &'a mut [(u8, Box<dyn I2cTarget + Send>)],
    master_scl: bool,
    master_sda: bool,
    scl: bool,
    sda: bool,
    dec: Decoder,
    /// The `ack` the master-receiver will give after the byte it is clocking.
    plan_ack: bool,
    trace: &'a mut Vec<Level>,
}

impl Wires<'_> {
    fn settle(&mut self, t: Ps) {
        let (scl, sda) = (self.master_scl, self.master_sda && self.dec.sda);
        let (was_scl, was_sda) = (self.scl, self.sda);
        if (scl, sda) == (was_scl, was_sda) {
            return;
        }
        self.scl = scl;
        self.sda = sda;
        self.trace.push((t, scl, sda));
        let d = &mut self.dec;
        if scl && was_scl && !sda && was_sda {
            // START or repeated START.
            *d = Decoder {
                active: true,
                start_at: t,
                selected: d.selected,
                address_phase: true,
                sda: true,
                ..Decoder::default()
            };
        } else if scl && was_scl && sda && !was_sda {
            if let Some(i) = d.selected.take() {
                self.targets[i].1.stop(t);
            }
            d.active = false;
        } else if scl && !was_scl && d.active {
            if d.count < 8 && !d.transmitting {
                d.byte = (d.byte << 1) | u8::from(sda);
            }
            if d.count == 8 && d.transmitting {
                d.master_acked = !sda;
            }
            d.count += 1;
        } else if !scl && was_scl && d.active {
            if d.count == 8 && d.transmitting {
                d.sda = true; // the master-receiver answers on SDA
            } else if d.count == 9 {
                d.sda = true;
                d.hold = d.selected.map(|i| self.targets[i].1.hold_scl(t));
                if d.address_phase {
                    d.address_phase = false;
                    d.transmitting = d.selected.is_some() && d.byte & 1 == 1;
                } else if d.transmitting && !d.master_acked {
                    // A NACK ends the target's transmission: it leaves SDA to the master's STOP.
                    d.transmitting = false;
                    d.done = true;
                }
                d.count = 0;
                d.byte = 0;
            }
        }
    }

    /// The target side's part just before SCL rises at `t`: a transmitting target puts its next
    /// bit on SDA; a receiving one answers the ninth clock with ACK or NACK.
    fn before_rise(&mut self, t: Ps) {
        let d = &mut self.dec;
        if !d.active {
            return;
        }
        if d.transmitting && d.count < 8 {
            let i = d.selected.expect("a transmitting target is selected");
            if d.count == 0 {
                d.out = self.targets[i].1.read(t, self.plan_ack);
            }
            d.sda = d.out & (0x80 >> d.count) != 0;
        } else if !d.transmitting && !d.done && d.count == 8 {
            let ack = if d.address_phase {
                d.selected = self.targets.iter().position(|(a, _)| *a == d.byte >> 1);
                d.selected.is_some_and(|i| {
                    self.targets[i].1.start(d.start_at);
                    self.targets[i].1.write(d.byte, t)
                })
            } else {
                d.selected.is_some_and(|i| self.targets[i].1.write(d.byte, t))
            };
            d.sda = !ack;
        }
        self.settle(t);
    }

    fn set_sda(&mut self, t: Ps, high: bool) {
        self.master_sda = high;
        self.settle(t);
    }

    /// SCL released at `t`: the target acts, the line rises; returns SDA as the master samples it.
    fn rise(&mut self, t: Ps) -> bool {
        self.before_rise(t);
        self.master_scl = true;
        self.settle(t);
        self.sda
    }

    fn fall(&mut self, t: Ps) {
        self.master_scl = false;
        self.settle(t);
    }
}

/// I2C-A at bit level.
pub struct I2cBitLink {
    m: Master,
    trace: Vec<Level>,
}

impl std::fmt::Debug for I2cBitLink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.m.debug_as(f, "I2cBitLink")
    }
}

impl I2cBitLink {
    /// I2C-A with `targets` at their addresses, its SCL phases from `bus` (as `I2cLink::new`).
    pub fn new(bus: &I2cBus, targets: Vec<(u8, Box<dyn I2cTarget + Send>)>) -> I2cBitLink {
        I2cBitLink { m: Master::new(bus, targets), trace: Vec::new() }
    }

    /// As `I2cLink::set_honours_stretching`.
    pub fn set_honours_stretching(&mut self, on: bool) {
        self.m.honours_stretching = on;
    }

    /// The wire changes of the last transaction: (time, SCL, SDA).
    pub fn trace(&self) -> &[Level] {
        &self.trace
    }
}

impl Link for I2cBitLink {
    fn transfer(&mut self, to: Address, tx: &[u16], rx: &mut [u16], t: Ps) -> Result<Transfer> {
        let (address, start) = self.m.begin(to, tx, t)?;
        let (low, high, honours) = (self.m.low, self.m.high, self.m.honours_stretching);
        self.trace.clear();
        let events = &mut self.m.events;
        let mut w = Wires {
            targets: &mut self.m.targets,
            master_scl: true,
            master_sda: true,
            scl: true,
            sda: true,
            dec: Decoder { sda: true, ..Decoder::default() },
            plan_ack: false,
            trace: &mut self.trace,
        };
        w.trace.push((start, true, true));
        // START, tHD;STA (one high phase), SCL falls.
        w.set_sda(start, false);
        let mut now = start + high;
        w.fall(now);
        // After a ninth clock: the target's stretch, by the rule.
        let after_byte = |w: &mut Wires, now: Ps, events: &mut EventLog| {
            let hold = w.dec.hold.take().unwrap_or(now);
            stretch_rule(hold, now, low, honours, events)
        };
        // The master writes `byte`: eight bits, then the ninth clock with SDA released; the ACK.
        let byte_out = |w: &mut Wires, byte: u8, now: &mut Ps, events: &mut EventLog| -> bool {
            for k in 0..8 {
                w.set_sda(*now, byte & (0x80 >> k) != 0);
                w.rise(*now + low);
                *now += low + high;
                w.fall(*now);
            }
            w.set_sda(*now, true);
            let ack = !w.rise(*now + low);
            *now += low + high;
            w.fall(*now);
            *now = after_byte(w, *now, events);
            ack
        };
        let mut complete = true;
        let phases: [(bool, usize); 2] = [(false, tx.len()), (true, rx.len())];
        for (reading, count) in phases {
            if count == 0 && (reading || !rx.is_empty()) {
                continue;
            }
            if reading && !tx.is_empty() {
                // Repeated START: SDA released while SCL is low, SCL rises, SDA falls one high phase later.
                w.set_sda(now, true);
                w.rise(now + low);
                let restart = now + low + high;
                w.set_sda(restart, false);
                now = restart + high;
                w.fall(now);
            }
            if !byte_out(&mut w, (address << 1) | u8::from(reading), &mut now, events) {
                complete = false;
                nack_address(events, now, address, reading);
                break;
            }
            if reading {
                for (k, r) in rx.iter_mut().enumerate() {
                    let ack = k + 1 < count;
                    w.plan_ack = ack;
                    w.set_sda(now, true);
                    let mut byte = 0u8;
                    for _ in 0..8 {
                        byte = (byte << 1) | u8::from(w.rise(now + low));
                        now += low + high;
                        w.fall(now);
                    }
                    *r = u16::from(byte);
                    w.set_sda(now, !ack);
                    w.rise(now + low);
                    now += low + high;
                    w.fall(now);
                    now = after_byte(&mut w, now, events);
                }
            } else {
                for (k, &b) in tx.iter().enumerate() {
                    if !byte_out(&mut w, b as u8, &mut now, events) {
                        complete = false;
                        nack_byte(events, now, address, k, b);
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
        // STOP: SDA low while SCL is low, SCL rises, SDA rises one high phase later.
        w.set_sda(now, false);
        w.rise(now + low);
        let stop = now + low + high;
        w.set_sda(stop, true);
        self.m.last_stop = Some(stop);
        Ok(Transfer { start, end: stop, complete })
    }

    fn drain_events(&mut self) -> Vec<Event> {
        self.m.events.drain()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::i2c::probe::{Probe, Seen};
    use crate::bus::i2c::I2cLink;
    use std::sync::Arc;

    type Outcome = (Vec<String>, Vec<(Vec<u16>, Transfer)>, Vec<(&'static str, Ps)>);

    /// Run `traffic` (address, bytes written, bytes read, start time) through one level.
    fn run(bits: bool, bus: &I2cBus, stretch: Ps, honours: bool, traffic: &[(u8, Vec<u16>, usize, Ps)]) -> Outcome {
        let seen: Seen = Arc::default();
        let probe = Probe::new(&seen, Some(stretch));
        let targets: Vec<(u8, Box<dyn I2cTarget + Send>)> = vec![(0x19, Box::new(probe))];
        let mut link: Box<dyn Link> = if bits {
            let mut l = I2cBitLink::new(bus, targets);
            l.set_honours_stretching(honours);
            Box::new(l)
        } else {
            let mut l = I2cLink::new(bus, targets);
            l.set_honours_stretching(honours);
            Box::new(l)
        };
        let mut out = Vec::new();
        for (address, tx, n, t) in traffic {
            let mut rx = vec![0u16; *n];
            let tr = link.transfer(Address::I2c(*address), tx, &mut rx, *t).unwrap();
            out.push((rx, tr));
        }
        let events = link.drain_events().iter().map(|e| (e.kind, e.t_ps)).collect();
        let seen = seen.lock().unwrap().clone();
        (seen, out, events)
    }

    /// The two levels agree word for word and time for time: every call the target sees with its
    /// time, every byte read, every transaction's start, end and completeness, every event, on the
    /// same traffic (writes, register reads with a repeated START, a read alone, an absent address,
    /// a refused byte, back-to-back transactions held off by tBUF), at 100 kHz and at a fast-mode
    /// clock below the minimum phases, without and with clock stretching (a master that waits and
    /// one that does not).
    #[test]
    fn bit_and_transaction_levels_agree() {
        let traffic = vec![
            (0x19, vec![0x50], 0, 1_000),
            (0x19, vec![0x50], 6, 2_000_000_000),
            (0x19, vec![], 2, 0),
            (0x19, vec![0xF1, 0x05, 0x02], 0, 5_000_000_000),
            (0x1E, vec![0x40], 3, 6_000_000_000),
            (0x19, vec![0x01, 0xEE, 0x02], 1, 7_000_000_000),
            (0x19, vec![0xE1, 0x04], 1, 0),
        ];
        for bus in [I2cBus::default(), I2cBus { scl_low_ns: 1_250, scl_high_ns: 1_250 }] {
            for (stretch, honours) in [(0, true), (30_000_000, true), (30_000_000, false)] {
                let trans = run(false, &bus, stretch, honours, &traffic);
                let bits = run(true, &bus, stretch, honours, &traffic);
                assert_eq!(trans, bits, "{bus:?}, stretch {stretch} ps, honoured: {honours}");
                assert!(trans.0.len() > 40);
                let ignored = trans.2.iter().filter(|e| e.0 == "i2c_stretch_ignored").count();
                assert_eq!(ignored > 0, stretch > 0 && !honours);
            }
        }
        // A stretch of 30 µs beyond the 5 µs low phase delays what follows each byte by 25 µs: a
        // one-byte write (address, byte) ends 2 × 25 µs later.
        let one = |stretch| run(true, &I2cBus::default(), stretch, true, &traffic[..1]).1[0].1;
        assert_eq!(one(30_000_000).end - one(0).end, 2 * 25_000_000);
    }

    /// On the wires: a START is SDA falling with SCL high, a STOP SDA rising with SCL high, and
    /// nowhere else does SDA change while SCL is high; the address byte 0x32 (0x19 + W) is on SDA
    /// at its eight rises and the target's ACK at the ninth.
    #[test]
    fn the_wires_show_start_address_ack_stop() {
        let seen: Seen = Arc::default();
        let probe = Probe::new(&seen, Some(0));
        let mut link = I2cBitLink::new(&I2cBus::default(), vec![(0x19, Box::new(probe))]);
        link.transfer(Address::I2c(0x19), &[0x50], &mut [], 0).unwrap();
        let tr = link.trace();
        let mut starts_stops = Vec::new();
        let mut sampled = Vec::new();
        for w in tr.windows(2) {
            let ((_, scl0, sda0), (t, scl1, sda1)) = (w[0], w[1]);
            if scl0 && scl1 && sda0 != sda1 {
                starts_stops.push((t, if sda1 { "P" } else { "S" }));
            }
            if !scl0 && scl1 {
                sampled.push(u8::from(sda1));
            }
        }
        assert_eq!(starts_stops, [(0, "S"), (195_000_000, "P")]);
        let address: u8 = sampled[..8].iter().fold(0, |a, b| (a << 1) | b);
        assert_eq!((address, sampled[8]), (0x32, 0), "address + W, then ACK (SDA low)");
        assert_eq!(sampled.len(), 9 + 9 + 1, "two bytes and the STOP's clock");
    }
}
