//! The door every link kind offers the MCU side ([`Link`]: one transaction with an addressed
//! device and its times), the places a device is addressed by ([`Address`]), and a device built
//! for some kind of link ([`Device`]). Plain contracts over the shared vocabulary (time, errors,
//! events): the profile's link-kind registry (`profile::LinkKind`) is written in these terms, and
//! each kind's file under `bus/` implements them.

use crate::error::{Error, Result};
use crate::events::Event;
use crate::time::Ps;
use std::any::Any;

/// Where a device sits on its link: how the MCU side addresses it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Address {
    /// SPI: the GPIO number driven as the device's chip select (`GPIO57` → 57).
    ChipSelect(u8),
    /// I²C: the device's 7-bit address.
    I2c(u8),
    /// UART: the link's one peer (a UART has no addressing; the port is the link itself).
    Port,
    /// Another kind's number for a device (a channel, an identifier): for a new kind whose
    /// places are none of the above.
    Id(u32),
}

impl std::fmt::Display for Address {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Address::ChipSelect(gpio) => write!(f, "chip select GPIO{gpio}"),
            Address::I2c(a) => write!(f, "address 0x{a:02X}"),
            Address::Port => write!(f, "the port's peer"),
            Address::Id(n) => write!(f, "device {n}"),
        }
    }
}

/// What one transaction on a link took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Transfer {
    /// When the transaction began on the wires (CS↓, START, the first start bit).
    pub start: Ps,
    /// When it ended (CS↑, STOP, the last stop bit).
    pub end: Ps,
    /// Whether the device took part throughout (I²C: every byte ACKed; UART: every byte asked for
    /// came; SPI: always).
    pub complete: bool,
}

/// The narrow door common to every link kind: what the firmware's drivers need of a link.
pub trait Link {
    /// One transaction with the device at `to`, beginning at `t`: the words of `tx` go out and `rx`
    /// is filled with what comes back. SPI: one frame per word under the device's chip select
    /// (`rx.len() == tx.len()`); I²C: a write of the `tx` bytes, then, if `rx` is not empty, a
    /// repeated START and a read of `rx.len()` bytes, then STOP; UART: the `tx` bytes sent, then the
    /// next `rx.len()` bytes the peer sends. Bytes travel in the low 8 bits of each word.
    /// An address no device answers to is an error (SPI, UART: the wiring is the profile's) or a
    /// NACK (I²C: the protocol's answer, reported as an event).
    fn transfer(&mut self, to: Address, tx: &[u16], rx: &mut [u16], t: Ps) -> Result<Transfer>;
    /// Take the link's events out.
    fn drain_events(&mut self) -> Vec<Event>;
}

/// A device built for one kind of link: the kind's device trait object (`Box<dyn SpiSlave + Send>`,
/// `Box<dyn I2cTarget + Send>`, `Box<dyn UartPeer + Send>`, or a new kind's) behind one type, so the
/// part catalogue and the link kinds meet without a list of kinds. The kind takes its own back out.
pub struct Device(Box<dyn Any + Send>);

impl Device {
    /// `device` (a boxed trait object of its kind's device trait) as a [`Device`].
    pub fn new<T: ?Sized + Send + 'static>(device: Box<T>) -> Device {
        Device(Box::new(device))
    }

    /// Whether the device was built as a `Box<T>`.
    pub fn is<T: ?Sized + Send + 'static>(&self) -> bool {
        self.0.is::<Box<T>>()
    }

    /// The device as the `Box<T>` it was built as (`None`: it was built for another kind).
    pub fn take<T: ?Sized + Send + 'static>(self) -> Option<Box<T>> {
        self.0.downcast::<Box<T>>().ok().map(|b| *b)
    }
}

impl std::fmt::Debug for Device {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Device")
    }
}

/// A link's devices as its kind's trait objects `T`, each by the kind's own number for its place
/// (`place`: `None` for an address that is not a place of this kind). A device built for another
/// kind, or at another kind's place, is an error naming `link` and saying it is not `what` (the
/// kind's word for its devices: "an SPI slave").
pub fn devices_of<T: ?Sized + Send + 'static, A>(
    link: &str,
    devices: impl IntoIterator<Item = (Address, Device)>,
    what: &str,
    place: impl Fn(Address) -> Option<A>,
) -> Result<Vec<(A, Box<T>)>> {
    let mut out = Vec::new();
    for (address, device) in devices {
        match (place(address), device.take::<T>()) {
            (Some(a), Some(d)) => out.push((a, d)),
            _ => return Err(Error::Profile(format!("{link}: the device at {address} is not {what}"))),
        }
    }
    Ok(out)
}
