//! The serial peripherals a host-built firmware reaches besides SPI-A, held together for the
//! [`crate::host::HostBoard`]: SCI-A/B/C ([`super::sci`]) and I2C-A ([`super::i2c`]) with the I²C
//! parts the profile places on it. It owns their addresses, brings them up to time, and hands their
//! PIE requests and events to the board.

use crate::bus::i2c::I2cTarget;
use crate::error::Result;
use crate::events::Event;
use crate::profile::Profile;
use crate::time::{s_to_ps, Clock, Ps};

use super::i2c::{self, I2cA};
use super::interrupts::Interrupts;
use super::sci::{self, RxFeed, Sci};

/// The serial peripherals.
#[derive(Debug)]
pub struct SerialPorts {
    sci: [Sci; 3],
    i2c: I2cA,
}

impl SerialPorts {
    /// The ports at reset, the SCIs clocked by `lspclk` with the profile's receive feeds
    /// (`[serial.*]`: an unreadable file is an error naming its key), I2C-A by `sysclkout` with the
    /// parts the profile places on `i2c-a` (`board::links::i2c_targets`).
    pub fn new(
        profile: &Profile,
        lspclk: Clock,
        sysclkout: Clock,
        i2c_targets: Vec<(u8, Box<dyn I2cTarget + Send>)>,
    ) -> Result<SerialPorts> {
        let mut sci = [Sci::new(0, lspclk), Sci::new(1, lspclk), Sci::new(2, lspclk)];
        for (port, (key, rx)) in sci.iter_mut().zip(profile.serial.ports()) {
            if !rx.rx_file.is_empty() {
                port.set_feed(RxFeed::from_file(
                    &rx.rx_file,
                    rx.rx_baud,
                    s_to_ps(rx.rx_start_s),
                    s_to_ps(rx.rx_line_period_s),
                    &format!("{key}.rx_file"),
                )?);
            }
        }
        let i2c = I2cA::new(sysclkout, i2c_targets);
        Ok(SerialPorts { sci, i2c })
    }

    /// Whether `addr` is one of their registers.
    pub fn owns(addr: u32) -> bool {
        sci::port_of(addr).is_some() || I2cA::owns(addr)
    }

    /// The name of the register at `addr` (`SCIB_SCIRXBUF`, `I2CSTR`).
    pub fn register_name(addr: u32) -> Option<&'static str> {
        sci::REGISTERS.iter().chain(i2c::REGISTERS).find(|r| r.1 == addr).map(|r| r.0)
    }

    /// Read a register at `t`.
    pub fn read(&mut self, addr: u32, t: Ps) -> Result<u16> {
        if I2cA::owns(addr) {
            return self.i2c.read(addr - i2c::BASE, t);
        }
        match sci::port_of(addr) {
            Some((p, off)) => self.sci[p].read(off, t),
            None => Err(crate::error::Error::Register(format!("C28x address 0x{addr:04X}: not a serial register"))),
        }
    }

    /// Write a register at `t`.
    pub fn write(&mut self, addr: u32, value: u16, t: Ps) -> Result<()> {
        if I2cA::owns(addr) {
            return self.i2c.write(addr - i2c::BASE, value, t);
        }
        match sci::port_of(addr) {
            Some((p, off)) => self.sci[p].write(off, value, t),
            None => Err(crate::error::Error::Register(format!("C28x address 0x{addr:04X}: not a serial register"))),
        }
    }

    /// Bring every port up to `t`.
    #[inline]
    pub fn advance(&mut self, t: Ps) {
        for s in &mut self.sci {
            s.advance(t);
        }
        self.i2c.advance(t);
    }

    /// SYSCLKOUT changes (I2C-A takes it at its next IRS 0 → 1).
    pub fn set_sysclkout(&mut self, c: Clock) {
        self.i2c.set_sysclkout(c);
    }

    /// LSPCLK changes at `t`.
    pub fn set_lspclk(&mut self, lspclk: Clock, t: Ps) {
        for s in &mut self.sci {
            s.set_lspclk(lspclk, t);
        }
    }

    /// Pass the PIE requests raised to `irq` and return the events.
    #[inline]
    pub fn drain(&mut self, irq: &mut Interrupts) -> Vec<Event> {
        let mut events = Vec::new();
        // On every register access and step of time: a quiet port (the common case) costs a check.
        for s in self.sci.iter_mut().filter(|s| !s.nothing_to_take()) {
            for (g, b, t) in s.take_requests() {
                irq.set_pie_flag(g, b, t);
            }
            let mut e = s.drain_events();
            if !e.is_empty() {
                events.append(&mut e);
            }
        }
        for (g, b, t) in self.i2c.take_requests() {
            irq.set_pie_flag(g, b, t);
        }
        for (k, armed) in self.i2c.armed().into_iter().enumerate() {
            irq.set_armed(8, k as u8 + 1, armed);
        }
        let mut e = self.i2c.drain_events();
        if !e.is_empty() {
            events.append(&mut e);
        }
        events
    }

    /// When the register at `addr` may next read differently by itself (None: not one of theirs,
    /// or no change coming).
    pub fn next_change_ps(&self, addr: u32) -> Option<Ps> {
        if I2cA::owns(addr) {
            return self.i2c.next_change_ps();
        }
        sci::port_of(addr).and_then(|(p, _)| self.sci[p].next_change_ps())
    }

    /// When a port with an interrupt enabled next changes by itself (it may raise one then).
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        self.sci.iter().filter_map(Sci::next_interrupt_ps).chain(self.i2c.next_interrupt_ps()).min()
    }

    /// Whether GPIO32/33 are muxed to SDAA/SCLA.
    pub fn set_i2c_pins(&mut self, muxed: bool) {
        self.i2c.set_pins(muxed);
    }

    /// I2C-A.
    pub fn i2c(&self) -> &I2cA {
        &self.i2c
    }

    /// SCI port `port` (0 = A).
    pub fn sci(&self, port: usize) -> &Sci {
        &self.sci[port]
    }

    /// SCI port `port`, to give it a feed.
    pub fn sci_mut(&mut self, port: usize) -> &mut Sci {
        &mut self.sci[port]
    }
}
