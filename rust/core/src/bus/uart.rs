//! The UART link kind (the F28335's SCI): its place in the bus layer, for the boards that need it
//! (the GPS of the gyro-free board, 19 200 baud 8N1). Not emulated yet: a profile that puts a device
//! on `sci-a` is refused (`profile::Board`).
//!
//! Shape: no clock and no select, so each side times its own bytes; the link hands the peer each
//! byte the MCU sends with its stop bit's time, and takes the peer's bytes when their stop bit has
//! passed (the SCI's receive buffer and its overrun rule are the MCU's side).

use crate::time::Ps;

/// The peer of a UART link.
pub trait UartPeer {
    /// The MCU sent `byte`; its stop bit ends at `t`.
    fn receive(&mut self, byte: u8, t: Ps);
    /// The next byte the peer sends whose stop bit ends by `t`, with that time (`None`: none yet).
    fn transmit(&mut self, t: Ps) -> Option<(u8, Ps)>;
}
