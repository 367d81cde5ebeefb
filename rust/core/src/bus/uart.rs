//! The UART link kind (the F28335's SCI): SCI-A and its one peer, for the boards that need it (the
//! GPS of the gyro-free board, 19 200 baud 8N1: gps-nmea.md).
//!
//! No clock and no select: each side times its own characters. A character is a start bit, 8 data
//! bits and a stop bit, 10 bit times (520.8 µs at 19 200 baud). The link hands the peer each byte the
//! MCU sends with its stop bit's end, back to back, and takes the peer's bytes at the end of theirs.
//! Not modelled: the SCI's receive buffer and its overrun rule (the MCU's side), parity, break.

use super::{Address, Device, Link, Transfer};
use crate::error::{Error, Result};
use crate::events::Event;
use crate::profile::{Board, BoxedLink, Devices, LinkKind, Profile, SciPort};
use crate::time::Ps;

/// The peer of a UART link.
pub trait UartPeer {
    /// The MCU sent `byte`; its stop bit ends at `t`.
    fn receive(&mut self, byte: u8, t: Ps);
    /// The next byte the peer sends after `t` with the end of its stop bit (`None`: it has nothing
    /// to send).
    fn transmit(&mut self, t: Ps) -> Option<(u8, Ps)>;
    /// Take the peer's events out (the link hands them to the run's events).
    fn drain_events(&mut self) -> Vec<Event> {
        Vec::new()
    }
}

inventory::submit! {
    LinkKind {
        name: "uart",
        links: &["sci-a"],
        keys: &[],
        section: Some(("sci", Board::defaults_of::<SciPort>)),
        place: |_| Ok(Address::Port),
        check: check_port,
        fits: Device::is::<dyn UartPeer + Send>,
        build: sci_a,
    }
}

/// `[board.sci]`: a baud rate the SCI can make.
fn check_port(board: &Board) -> Result<()> {
    let baud = board.section::<SciPort>("sci")?.baud;
    if !(300..=1_000_000).contains(&baud) {
        return Err(Error::Profile(format!("key `board.sci.baud` = {baud}: expected 300 … 1 000 000 bits per second")));
    }
    Ok(())
}

/// SCI-A with its peer, at `[board.sci]`'s baud rate.
fn sci_a(profile: &Profile, link: &str, devices: Devices) -> Result<BoxedLink> {
    let mut peer = None;
    for (address, device) in devices {
        match (address, device.take::<dyn UartPeer + Send>()) {
            (Address::Port, Some(p)) if peer.is_none() => peer = Some(p),
            _ => return Err(Error::Profile(format!("{link}: the device at {address} is not its one peer"))),
        }
    }
    Ok(Box::new(UartLink::new(&profile.board.section("sci")?, peer)))
}

/// Bit times per character: start, 8 data, 1 stop (8N1).
pub const BITS_PER_CHAR: u64 = 10;

/// SCI-A and its peer.
pub struct UartLink {
    peer: Option<Box<dyn UartPeer + Send>>,
    /// One character's line time, ps (rounded to the nearest).
    char_ps: Ps,
    /// The end of the last character the MCU sent (the next starts no earlier).
    tx_free: Ps,
}

impl std::fmt::Debug for UartLink {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("UartLink").field("peer", &self.peer.is_some()).field("char_ps", &self.char_ps).finish()
    }
}

impl UartLink {
    /// SCI-A at `port`'s baud rate with `peer` (or nothing) on the other end.
    pub fn new(port: &SciPort, peer: Option<Box<dyn UartPeer + Send>>) -> UartLink {
        let baud = u64::from(port.baud.max(1));
        let char_ps = (BITS_PER_CHAR * 1_000_000_000_000 + baud / 2) / baud;
        UartLink { peer, char_ps, tx_free: 0 }
    }

    /// One character's line time, ps.
    pub fn char_ps(&self) -> Ps {
        self.char_ps
    }
}

impl Link for UartLink {
    fn transfer(&mut self, to: Address, tx: &[u16], rx: &mut [u16], t: Ps) -> Result<Transfer> {
        if to != Address::Port {
            return Err(Error::Config(format!("SCI-A has one peer, addressed as its port, not by {to}")));
        }
        let Some(peer) = self.peer.as_mut() else {
            return Err(Error::Config("SCI-A: no device on the port (`board.devices` puts none on sci-a)".into()));
        };
        if let Some(w) = tx.iter().find(|&&w| w > 0xFF) {
            return Err(Error::Config(format!("SCI-A sends 8-bit characters: 0x{w:X} does not fit")));
        }
        let start = t.max(self.tx_free);
        let mut now = start;
        for &w in tx {
            now += self.char_ps;
            peer.receive(w as u8, now);
        }
        self.tx_free = now;
        let mut complete = true;
        for r in rx.iter_mut() {
            match peer.transmit(now) {
                Some((byte, end)) => {
                    *r = u16::from(byte);
                    now = now.max(end);
                }
                None => {
                    complete = false;
                    break;
                }
            }
        }
        Ok(Transfer { start, end: now, complete })
    }

    fn drain_events(&mut self) -> Vec<Event> {
        self.peer.as_mut().map_or_else(Vec::new, |p| p.drain_events())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Echoes each byte one character time after it arrived.
    #[derive(Default)]
    struct Echo {
        queue: std::collections::VecDeque<(u8, Ps)>,
        char_ps: Ps,
    }

    impl UartPeer for Echo {
        fn receive(&mut self, byte: u8, t: Ps) {
            let after = self.queue.back().map_or(t, |&(_, e)| e.max(t));
            self.queue.push_back((byte, after + self.char_ps));
        }
        fn transmit(&mut self, _t: Ps) -> Option<(u8, Ps)> {
            self.queue.pop_front()
        }
    }

    /// 19 200 baud 8N1: 520.8 µs per character (gps-nmea.md).
    #[test]
    fn characters_take_ten_bit_times() {
        let port = SciPort { baud: 19_200 };
        let char_ps = UartLink::new(&port, None).char_ps();
        assert_eq!(char_ps, 520_833_333);
        let mut link = UartLink::new(&port, Some(Box::new(Echo { char_ps, ..Default::default() })));
        let mut rx = [0u16; 2];
        let tr = link.transfer(Address::Port, &[b'$' as u16, b'G' as u16], &mut rx, 0).unwrap();
        assert_eq!(rx, [b'$' as u16, b'G' as u16]);
        assert_eq!((tr.end, tr.complete), (3 * char_ps, true));
        let tr = link.transfer(Address::Port, &[], &mut rx, 0).unwrap();
        assert!(!tr.complete, "nothing more to receive");
        assert!(UartLink::new(&port, None).transfer(Address::Port, &[1], &mut [], 0).is_err());
        assert!(link.transfer(Address::I2c(3), &[1], &mut [], 0).is_err());
    }
}
