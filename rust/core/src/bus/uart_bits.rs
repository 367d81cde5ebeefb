//! The UART at bit level: the line's levels for characters timed as [`UartLink`](super::uart::UartLink)
//! times them (start bit low, 8 data bits LSB first, stop bit high; 10 bit times), and a receiver
//! that finds each start bit's falling edge and samples every bit at its middle, as a UART does
//! (the MicroBlaze's UART Lite on the gyro-free board: 16-entry receive FIFO, gps-nmea.md). A stop
//! bit read low is a framing error (`uart_framing_error`: the character is dropped); a character
//! that finds the FIFO full is lost (`uart_overrun`).

use crate::events::{Event, EventLog, Severity};
use crate::time::Ps;
use std::collections::VecDeque;

/// A change of the line: its time and its new level (true = high, the idle mark).
pub type Edge = (Ps, bool);

/// The time of bit boundary `k` (0…10) of a character of `char_ps` starting at `start`.
fn boundary(start: Ps, char_ps: Ps, k: u64) -> Ps {
    start + (char_ps * k) / 10
}

/// The line's edges for `bytes`, each given with the end of its stop bit (the transaction level's
/// time), `char_ps` a character's time; the line idles high before.
pub fn drive(bytes: &[(u8, Ps)], char_ps: Ps) -> Vec<Edge> {
    let mut edges: Vec<Edge> = Vec::new();
    let mut level = true;
    for &(byte, end) in bytes {
        let start = end - char_ps;
        for k in 0..10u64 {
            let bit = match k {
                0 => false,
                9 => true,
                _ => byte & (1 << (k - 1)) != 0,
            };
            if bit != level {
                edges.push((boundary(start, char_ps, k), bit));
                level = bit;
            }
        }
    }
    edges
}

/// A UART receiver with a FIFO.
#[derive(Debug)]
pub struct Receiver {
    char_ps: Ps,
    depth: usize,
    fifo: VecDeque<(u8, Ps)>,
    events: EventLog,
}

impl Receiver {
    /// A receiver for characters of `char_ps` with a FIFO of `depth` entries.
    pub fn new(char_ps: Ps, depth: usize) -> Receiver {
        Receiver { char_ps, depth, fifo: VecDeque::new(), events: EventLog::default() }
    }

    /// Decode the line `edges` (idle high before the first): each character goes into the FIFO with
    /// the end of its stop bit.
    pub fn listen(&mut self, edges: &[Edge]) {
        let level_at = |t: Ps| edges.iter().take_while(|e| e.0 <= t).last().is_none_or(|e| e.1);
        let mut i = 0;
        while let Some(k) = edges[i..].iter().position(|e| !e.1) {
            let start = edges[i + k].0;
            let mid = |b: u64| start + (self.char_ps * (2 * b + 1)) / 20;
            let byte = (1..9u64).fold(0u8, |a, b| a | (u8::from(level_at(mid(b))) << (b - 1)));
            let end = boundary(start, self.char_ps, 10);
            if !level_at(mid(9)) {
                let what = format!("UART: stop bit of the character starting at {start} ps read low: dropped");
                self.events.push(Event::new(end, "uart_framing_error", Severity::Warning, what));
            } else if self.fifo.len() == self.depth {
                let what = format!("UART: receive FIFO full ({} entries): 0x{byte:02X} lost", self.depth);
                self.events.push(Event::new(end, "uart_overrun", Severity::Warning, what));
            } else {
                self.fifo.push_back((byte, end));
            }
            // The next start bit is a falling edge after the stop bit's middle.
            let resume = mid(9);
            i = edges.iter().position(|e| e.0 > resume).unwrap_or(edges.len());
            if i >= edges.len() {
                break;
            }
        }
    }

    /// Take the oldest character (and the end of its stop bit).
    pub fn read(&mut self) -> Option<(u8, Ps)> {
        self.fifo.pop_front()
    }

    /// Take the receiver's events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::uart::UartLink;
    use crate::bus::{Address, Link};
    use crate::device::gps::{Gps, Settings, Truth};
    use crate::profile::SciPort;

    /// The GPS's first two seconds of sentences through SCI-A (transaction level) and on the line
    /// (bit level): the receiver, reading its FIFO as it goes, gets the same bytes with the same
    /// times, at 19 200 and at 4 800 baud.
    #[test]
    fn bit_and_transaction_levels_agree() {
        for baud in [19_200, 4_800] {
            let port = SciPort { baud };
            let truth = Truth { lat_deg: 40.0, lon_deg: 116.0, alt_m: 50.0, speed_m_s: 3.0, course_deg: 90.0 };
            let gps = Gps::new(Settings { baud, ..Settings::default() }, Box::new(move |_| truth));
            let mut link = UartLink::new(&port, Some(Box::new(gps)));
            let mut rx = [0u16; 1];
            let (mut t, mut words) = (0, Vec::new());
            while t < 2_000_000_000_000 {
                let tr = link.transfer(Address::Port, &[], &mut rx, t).unwrap();
                t = tr.end;
                words.push((rx[0] as u8, t));
            }
            let mut receiver = Receiver::new(link.char_ps(), usize::MAX);
            receiver.listen(&drive(&words, link.char_ps()));
            let got: Vec<(u8, Ps)> = std::iter::from_fn(|| receiver.read()).collect();
            assert_eq!(got, words, "{baud} baud");
            assert!(receiver.drain_events().is_empty());
        }
    }

    /// A receiver at 19 200 baud on a 4 800-baud line reads stop bits low (framing errors); one
    /// whose 16-entry FIFO is not read loses the 17th character on (overruns).
    #[test]
    fn framing_and_overrun_errors_are_events() {
        let slow = 10 * 1_000_000_000_000 / 4_800;
        let fast = 10 * 1_000_000_000_000 / 19_200;
        let bytes: Vec<(u8, Ps)> = b"$GPGGA".iter().enumerate().map(|(i, &b)| (b, (i as u64 + 1) * slow)).collect();
        let mut wrong = Receiver::new(fast, 16);
        wrong.listen(&drive(&bytes, slow));
        assert!(wrong.drain_events().iter().any(|e| e.kind == "uart_framing_error"));
        let many: Vec<(u8, Ps)> = (0..20u8).map(|i| (b'A' + i, (u64::from(i) + 1) * fast)).collect();
        let mut full = Receiver::new(fast, 16);
        full.listen(&drive(&many, fast));
        let kinds: Vec<_> = full.drain_events().iter().map(|e| e.kind).collect();
        assert_eq!(kinds, ["uart_overrun"; 4]);
        assert_eq!(full.read().map(|c| c.0), Some(b'A'));
    }
}
