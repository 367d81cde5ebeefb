//! The 24LC256 serial EEPROM (Microchip 24AA256/24LC256/24FC256, data sheet DS20001203) as an I²C
//! target: 32 768 bytes, the part TI's 2833x I²C EEPROM example talks to (a control byte 1010 A2 A1 A0
//! R/W̄, then a two-byte word address). Facts from the data sheet (sections named):
//!
//! - **Addressing** (§5.0 "Device addressing"): control code 1010, chip select A2 A1 A0: 7-bit
//!   addresses 0x50…0x57 (the profile's `address`, 0x50 with A2…A0 tied low). The first byte after the
//!   control byte is the address high byte (only its 7 low bits are used: a 15-bit address), the
//!   second the low byte.
//! - **Byte and page write** (§6.1, §6.2): data bytes after the two address bytes go to a 64-byte page
//!   buffer; on each byte the 6 low address bits increment, the upper ones do not: a write past the end
//!   of its page wraps to the page's start, overwriting what was sent before (the data sheet's note: the
//!   application must prevent it; here an `eeprom_page_wrap` event says it happened). The STOP starts
//!   the internally timed write cycle; a write of no data byte (the address only) starts none.
//! - **Write cycle** (§1.0 AC characteristics, "TWC write cycle time (byte or page)" 5 ms max; §7.0
//!   "Acknowledge polling"): for tWR after the STOP the part does not acknowledge its control byte
//!   (either R/W̄), so a master polls with a START and the control byte until it is ACKed. The model
//!   takes the data sheet's maximum, 5 ms ([`T_WR_PS`]; the data sheet gives no typical figure).
//! - **Reads** (§8.0): a current-address read returns the byte at the address pointer and increments it;
//!   a random read sets the pointer with a write of the two address bytes, then a repeated START and a
//!   read; a sequential read goes on while the master ACKs, the pointer rolling over from 0x7FFF to
//!   0x0000. After a write, the pointer is the address after the last byte written.
//! - A START before the STOP of a write (a repeated START after data bytes) abandons the data: no
//!   write cycle (the cycle is started by the STOP only, §6.1).
//!
//! Not modelled: the write-protect pin (WP tied low), the 400 kHz limit below 2.5 V (24AA256),
//! endurance.

use crate::bus::i2c::I2cTarget;
use crate::events::{Event, EventLog, Severity};
use crate::time::Ps;

/// The array's size in bytes (256 Kbit).
pub const SIZE: usize = 32_768;
/// The page buffer's size, bytes (§6.2).
pub const PAGE: usize = 64;
/// Write cycle time tWR (TWC), the data sheet's maximum: 5 ms.
pub const T_WR_PS: Ps = 5_000_000_000;

/// Where the part is in a transaction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// Waiting for a START.
    Idle,
    /// The control byte comes next.
    Control,
    /// The address high byte comes next.
    AddressHigh,
    /// The address low byte comes next.
    AddressLow,
    /// Data bytes to the page buffer.
    Data,
    /// The part transmits (a read).
    Reading,
    /// The part ignores the rest of the transaction (it did not acknowledge).
    Ignored,
}

/// A 24LC256.
#[derive(Debug, Clone)]
pub struct Eeprom24lc256 {
    mem: Vec<u8>,
    phase: Phase,
    /// The address pointer (15 bits).
    pointer: u16,
    /// The address high byte of the write under way.
    high: u8,
    /// Data bytes received this write: (address, byte), in the order they came.
    buffer: Vec<(u16, u8)>,
    /// A wrap past the page's end was reported for this write.
    wrapped: bool,
    /// The internal write cycle runs until this time.
    busy_until: Ps,
    events: EventLog,
}

impl Default for Eeprom24lc256 {
    fn default() -> Self {
        Eeprom24lc256::erased()
    }
}

impl Eeprom24lc256 {
    /// A part fresh from the factory: every byte 0xFF, no write cycle running.
    pub fn erased() -> Eeprom24lc256 {
        Eeprom24lc256 {
            mem: vec![0xFF; SIZE],
            phase: Phase::Idle,
            pointer: 0,
            high: 0,
            buffer: Vec::new(),
            wrapped: false,
            busy_until: 0,
            events: EventLog::default(),
        }
    }

    /// The byte at `address` (no bus traffic).
    pub fn peek(&self, address: u16) -> u8 {
        self.mem[usize::from(address) % SIZE]
    }

    /// Whether the internal write cycle is still running at `t`.
    pub fn busy(&self, t: Ps) -> bool {
        t < self.busy_until
    }

    /// The end of the last write cycle started.
    pub fn write_cycle_end(&self) -> Ps {
        self.busy_until
    }
}

impl I2cTarget for Eeprom24lc256 {
    fn start(&mut self, _t: Ps) {
        // A repeated START abandons a write's data (only a STOP starts the write cycle).
        self.buffer.clear();
        self.wrapped = false;
        self.phase = Phase::Control;
    }

    fn write(&mut self, byte: u8, t: Ps) -> bool {
        match self.phase {
            Phase::Control => {
                if self.busy(t) {
                    // §7.0: no acknowledge during the write cycle.
                    self.phase = Phase::Ignored;
                    return false;
                }
                self.phase = if byte & 1 == 1 { Phase::Reading } else { Phase::AddressHigh };
                true
            }
            Phase::AddressHigh => {
                self.high = byte & 0x7F;
                self.phase = Phase::AddressLow;
                true
            }
            Phase::AddressLow => {
                self.pointer = u16::from(self.high) << 8 | u16::from(byte);
                self.phase = Phase::Data;
                true
            }
            Phase::Data => {
                let page = self.pointer & !(PAGE as u16 - 1);
                if self.buffer.len() == PAGE && !self.wrapped {
                    self.wrapped = true;
                    self.events.push(Event::new(
                        t,
                        "eeprom_page_wrap",
                        Severity::Warning,
                        format!(
                            "24LC256: more than {PAGE} data bytes in one page write (page 0x{page:04X}): the address \
                             wraps to the page's start and the first bytes sent are overwritten (data sheet §6.2)"
                        ),
                    ));
                }
                self.buffer.push((self.pointer, byte));
                self.pointer = page | ((self.pointer + 1) & (PAGE as u16 - 1));
                true
            }
            // A byte written to a part that is transmitting, or after it refused: not acknowledged.
            Phase::Reading | Phase::Ignored | Phase::Idle => false,
        }
    }

    fn read(&mut self, _t: Ps, _ack: bool) -> u8 {
        if self.phase != Phase::Reading {
            return 0xFF; // the part does not drive SDA: the pull-up's level
        }
        let b = self.mem[usize::from(self.pointer)];
        self.pointer = (self.pointer + 1) % SIZE as u16;
        b
    }

    fn stop(&mut self, t: Ps) {
        if self.phase == Phase::Data && !self.buffer.is_empty() {
            for &(a, b) in &self.buffer {
                self.mem[usize::from(a)] = b;
            }
            self.busy_until = t + T_WR_PS;
        }
        self.buffer.clear();
        self.wrapped = false;
        self.phase = Phase::Idle;
    }

    fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: u8 = 0xA0; // 0x50 << 1, write
    const R: u8 = 0xA1;

    fn page_write(e: &mut Eeprom24lc256, address: u16, data: &[u8], t: Ps) {
        e.start(t);
        assert!(e.write(W, t));
        assert!(e.write((address >> 8) as u8, t));
        assert!(e.write(address as u8, t));
        for &b in data {
            assert!(e.write(b, t));
        }
        e.stop(t);
    }

    fn random_read(e: &mut Eeprom24lc256, address: u16, n: usize, t: Ps) -> Option<Vec<u8>> {
        e.start(t);
        if !e.write(W, t) {
            e.stop(t);
            return None;
        }
        e.write((address >> 8) as u8, t);
        e.write(address as u8, t);
        e.start(t);
        assert!(e.write(R, t));
        let out = (0..n).map(|k| e.read(t, k + 1 < n)).collect();
        e.stop(t);
        Some(out)
    }

    #[test]
    fn a_page_is_written_at_the_stop_and_acknowledge_polling_waits_t_wr() {
        let mut e = Eeprom24lc256::erased();
        page_write(&mut e, 0x0140, &[1, 2, 3, 4], 1_000);
        // During tWR the control byte is not acknowledged, in a read set-up as in a write.
        assert_eq!(random_read(&mut e, 0x0140, 4, 1_000 + T_WR_PS - 1), None);
        assert_eq!(random_read(&mut e, 0x0140, 4, 1_000 + T_WR_PS), Some(vec![1, 2, 3, 4]));
        assert_eq!(e.peek(0x0144), 0xFF);
        assert!(e.drain_events().is_empty());
    }

    #[test]
    fn a_write_past_the_page_end_wraps_to_its_start_with_an_event() {
        let mut e = Eeprom24lc256::erased();
        // 3 bytes from 0x7E: 0x7E, 0x7F, then 0x40 (the page 0x40…0x7F wraps), not 0x80.
        page_write(&mut e, 0x007E, &[0xA, 0xB, 0xC], 0);
        assert_eq!([e.peek(0x7E), e.peek(0x7F), e.peek(0x40), e.peek(0x80)], [0xA, 0xB, 0xC, 0xFF]);
        // 65 bytes into one page: the 65th overwrites the first.
        let data: Vec<u8> = (0..65).collect();
        page_write(&mut e, 0x0100, &data, T_WR_PS);
        assert_eq!((e.peek(0x0100), e.peek(0x0101), e.peek(0x013F)), (64, 1, 63));
        let ev = e.drain_events();
        assert_eq!(ev.iter().map(|x| x.kind).collect::<Vec<_>>(), ["eeprom_page_wrap"]);
    }

    #[test]
    fn an_address_only_write_starts_no_cycle_and_reads_roll_over() {
        let mut e = Eeprom24lc256::erased();
        e.start(0);
        e.write(W, 0);
        e.write(0xFF, 0); // only 7 bits: 0x7F
        e.write(0xFF, 0);
        e.stop(0);
        assert!(!e.busy(0));
        e.start(0);
        assert!(e.write(R, 0));
        assert_eq!((e.read(0, true), e.read(0, false)), (0xFF, 0xFF));
        assert_eq!(e.pointer, 0x0001);
        // A repeated START after data bytes abandons them.
        e.start(0);
        e.write(W, 0);
        e.write(0, 0);
        e.write(0, 0);
        e.write(0x55, 0);
        e.start(0);
        e.stop(0);
        assert_eq!((e.peek(0), e.busy(0)), (0xFF, false));
    }
}
