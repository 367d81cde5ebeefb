//! The F28335's general-purpose I/O: the control registers (`GpioCtrlRegs` at 0x6F80: mux,
//! direction, pull-ups, input qualification) and the data registers (`GpioDataRegs` at 0x6FC0:
//! GPxDAT, GPxSET, GPxCLEAR, GPxTOGGLE) of ports A (GPIO0–31), B (GPIO32–63) and C (GPIO64–87).
//!
//! Source: TI SPRUFB0, *TMS320x2833x System Control and Interrupts Reference Guide*, chapter
//! "General-Purpose Input/Output (GPIO)" (register map, reset values, EALLOW protection), with the
//! facts as /work's `spec/f28335-peripherals.md` §1 and §3 carry them (register offsets from TI's
//! `DSP2833x_Gpio.h`):
//! - Every GPIO register is 32 bits, two words, low word first.
//! - GPxMUX1/2: two bits per pin (MUX1 = the port's pins 0–15, MUX2 = 16–31); 0 = GPIO, 1–3 = a
//!   peripheral function. GPxDIR: 1 = output. GPxPUD: 1 = pull-up **disabled**. GPxQSEL1/2 and
//!   GPxCTRL: input qualification (stored; a pin's level is taken as qualified at once).
//! - Reset: every mux 0 (GPIO), every pin an input, GPAPUD = 0x0000_0FFF (pull-ups off on the
//!   ePWM pins GPIO0–11, on elsewhere), everything else 0 [unconfirmed, SPRUFB0].
//! - The control registers are EALLOW-protected: a write with ST1.EALLOW = 0 is ignored (reads
//!   are not affected). The data registers are not protected.
//! - GPxSET/GPxCLEAR/GPxTOGGLE: a 1 sets, clears or inverts the pin's output latch, a 0 changes
//!   nothing; they read 0. A GPxDAT write loads the latch (every bit written); a GPxDAT read
//!   returns the pin's level, not the latch, for inputs and outputs alike (so `GPxDAT.bit.n = v`,
//!   a read-modify-write, copies the levels of the port's input pins into their latches). A latch
//!   written while its pin is an input or a peripheral's takes effect when the pin becomes a GPIO
//!   output [unconfirmed].
//!
//! This file keeps the registers and says which pins are driven how; what drives a pin that is not
//! a GPIO output (a peripheral, a part on the board, a pull-up) is the board's answer
//! ([`Gpio::read_data`] asks it).

use crate::error::{Error, Result};

/// GpioCtrlRegs' base address.
pub const CTRL_BASE: u32 = 0x6F80;
/// GpioDataRegs' base address.
pub const DATA_BASE: u32 = 0x6FC0;
/// The highest GPIO number (GPIO0…GPIO87).
pub const LAST_PIN: u32 = 87;

/// The control registers: name, C28x word address, width in bits (SPRUFB0's GPIO register map).
pub const CTRL_REGISTERS: &[(&str, u32, u32)] = &[
    ("GPACTRL", 0x6F80, 32),
    ("GPAQSEL1", 0x6F82, 32),
    ("GPAQSEL2", 0x6F84, 32),
    ("GPAMUX1", 0x6F86, 32),
    ("GPAMUX2", 0x6F88, 32),
    ("GPADIR", 0x6F8A, 32),
    ("GPAPUD", 0x6F8C, 32),
    ("GPBCTRL", 0x6F90, 32),
    ("GPBQSEL1", 0x6F92, 32),
    ("GPBQSEL2", 0x6F94, 32),
    ("GPBMUX1", 0x6F96, 32),
    ("GPBMUX2", 0x6F98, 32),
    ("GPBDIR", 0x6F9A, 32),
    ("GPBPUD", 0x6F9C, 32),
    ("GPCMUX1", 0x6FA6, 32),
    ("GPCMUX2", 0x6FA8, 32),
    ("GPCDIR", 0x6FAA, 32),
    ("GPCPUD", 0x6FAC, 32),
];

/// The words of the control frame modelled (0x6F80…0x6FAD).
const CTRL_WORDS: usize = 0x2E;
/// Offsets (from a port's control base: A 0x00, B 0x10, C 0x20) of the mux, direction and pull-up
/// registers.
const MUX1: usize = 0x06;
const DIR: usize = 0x0A;
const PUD: usize = 0x0C;

/// The pins each port has: A and B 32, C 24 (GPIO64–87).
const PORT_PINS: [u32; 3] = [0xFFFF_FFFF, 0xFFFF_FFFF, 0x00FF_FFFF];

/// What a data-register write did, for the board to act on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataWrite {
    /// The port written (0 = A, 1 = B, 2 = C).
    pub port: usize,
    /// The port's pins whose output latch the write changed.
    pub changed: u32,
    /// The port's pins the write asked to drive (a 1 to SET/CLEAR/TOGGLE, or a DAT bit different
    /// from the pin's level) that are not GPIO outputs: the pin does not move.
    pub not_driven: u32,
}

/// GPIO ports A, B and C: control registers and output latches.
#[derive(Debug, Clone)]
pub struct Gpio {
    ctrl: [u16; CTRL_WORDS],
    latch: [u32; 3],
}

impl Default for Gpio {
    fn default() -> Self {
        Gpio::new()
    }
}

impl Gpio {
    /// The GPIO as reset leaves it: every pin a GPIO input, pull-ups on but on GPIO0–11, the
    /// latches 0.
    pub fn new() -> Gpio {
        let mut ctrl = [0u16; CTRL_WORDS];
        ctrl[PUD] = 0x0FFF; // GPAPUD = 0x0000_0FFF
        Gpio { ctrl, latch: [0; 3] }
    }

    /// Whether `addr` is a word of a modelled control register.
    #[inline]
    pub fn owns_ctrl(addr: u32) -> bool {
        (CTRL_BASE..CTRL_BASE + CTRL_WORDS as u32).contains(&addr) && ctrl_register(addr).is_some()
    }

    /// Whether `addr` is a word of a data register (GPADAT…GPCTOGGLE).
    pub fn owns_data(addr: u32) -> bool {
        (DATA_BASE..DATA_BASE + 24).contains(&addr)
    }

    fn word32(&self, offset: usize) -> u32 {
        u32::from(self.ctrl[offset]) | u32::from(self.ctrl[offset + 1]) << 16
    }

    /// The mux value of `pin` (0 = GPIO, 1–3 = a peripheral).
    pub fn mux(&self, pin: u32) -> u8 {
        let (port, bit) = ((pin / 32) as usize, pin % 32);
        let reg = self.word32(port * 0x10 + MUX1 + if bit < 16 { 0 } else { 2 });
        ((reg >> (2 * (bit % 16))) & 3) as u8
    }

    /// Whether `pin` is a GPIO output (mux 0, GPxDIR 1): the pin shows its latch.
    pub fn is_output(&self, pin: u32) -> bool {
        let (port, bit) = ((pin / 32) as usize, pin % 32);
        self.mux(pin) == 0 && self.word32(port * 0x10 + DIR) >> bit & 1 == 1
    }

    /// Whether `pin`'s pull-up is on (GPxPUD bit 0).
    pub fn pull_up(&self, pin: u32) -> bool {
        let (port, bit) = ((pin / 32) as usize, pin % 32);
        self.word32(port * 0x10 + PUD) >> bit & 1 == 0
    }

    /// `pin`'s output latch.
    pub fn latch(&self, pin: u32) -> bool {
        self.latch[(pin / 32) as usize] >> (pin % 32) & 1 == 1
    }

    /// What the board drives `pin` to as a GPIO output: `Some(latch)`, or `None` when the pin is an
    /// input or a peripheral's.
    pub fn driven(&self, pin: u32) -> Option<bool> {
        self.is_output(pin).then(|| self.latch(pin))
    }

    /// Make `pins` GPIO outputs with their latches high (what a board's boot code leaves the chip
    /// selects as before the firmware's `main`; see `firmware.gpio_at_start`).
    pub fn boot_outputs_high(&mut self, pins: &[u32]) {
        for &pin in pins.iter().filter(|&&p| p <= LAST_PIN) {
            let (port, bit) = ((pin / 32) as usize, pin % 32);
            let o = port * 0x10 + DIR + (bit / 16) as usize;
            self.ctrl[o] |= 1 << (bit % 16);
            self.latch[port] |= 1 << bit;
        }
    }

    /// Read a control-register word (reads are not protected).
    pub fn read_ctrl(&self, addr: u32) -> Result<u16> {
        ctrl_register(addr).ok_or_else(|| no_ctrl(addr))?;
        Ok(self.ctrl[(addr - CTRL_BASE) as usize])
    }

    /// Write a control-register word; `eallow` is ST1.EALLOW. Returns `false` when the write was
    /// ignored (no EALLOW: the registers are protected, SPRUFB0). Bits of pins a port does not have
    /// (GPIO88–95) read 0.
    pub fn write_ctrl(&mut self, addr: u32, value: u16, eallow: bool) -> Result<bool> {
        let &(_, base, _) = ctrl_register(addr).ok_or_else(|| no_ctrl(addr))?;
        if !eallow {
            return Ok(false);
        }
        let o = (addr - CTRL_BASE) as usize;
        let port = o / 0x10;
        let high_word = addr != base;
        let reg = o % 0x10 - usize::from(high_word);
        // Port C has 24 pins: GPCDIR/GPCPUD bits 24–31 and GPCMUX2's pins 88–95 do not exist.
        let mask: u16 = match (port, reg, high_word) {
            (2, DIR | PUD, true) => 0x00FF,
            (2, r, true) if r == MUX1 + 2 => 0,
            _ => 0xFFFF,
        };
        self.ctrl[o] = value & mask;
        Ok(true)
    }

    /// Read a data-register word: GPxDAT gives each pin's level (`level(pin)` for a pin that is not
    /// a GPIO output, the latch for one that is); SET/CLEAR/TOGGLE read 0.
    pub fn read_data(&self, addr: u32, level: impl Fn(u32) -> bool) -> u16 {
        let (port, kind, high_word) = data_word(addr);
        if kind != 0 {
            return 0;
        }
        let levels = self.levels(port, level);
        (if high_word { levels >> 16 } else { levels }) as u16
    }

    /// The 32 pin levels of `port`.
    fn levels(&self, port: usize, level: impl Fn(u32) -> bool) -> u32 {
        let mut out = 0u32;
        let mut pins = PORT_PINS[port];
        while pins != 0 {
            let bit = pins.trailing_zeros();
            pins &= pins - 1;
            let pin = 32 * port as u32 + bit;
            if self.driven(pin).unwrap_or_else(|| level(pin)) {
                out |= 1 << bit;
            }
        }
        out
    }

    /// Write a data-register word; `level(pin)` is the level of a pin that is not a GPIO output
    /// (a DAT write that only writes back the level read asks nothing of such a pin).
    pub fn write_data(&mut self, addr: u32, value: u16, level: impl Fn(u32) -> bool) -> DataWrite {
        let (port, kind, high_word) = data_word(addr);
        let bits = if high_word { u32::from(value) << 16 } else { u32::from(value) } & PORT_PINS[port];
        let word = if high_word { 0xFFFF_0000 } else { 0x0000_FFFF } & PORT_PINS[port];
        let before = self.latch[port];
        let (after, asked) = match kind {
            0 => {
                let levels = self.levels(port, &level);
                ((before & !word) | bits, (bits ^ levels) & word)
            }
            1 => (before | bits, bits),
            2 => (before & !bits, bits),
            _ => (before ^ bits, bits),
        };
        self.latch[port] = after;
        let mut not_driven = 0;
        let mut pins = asked;
        while pins != 0 {
            let bit = pins.trailing_zeros();
            pins &= pins - 1;
            if !self.is_output(32 * port as u32 + bit) {
                not_driven |= 1 << bit;
            }
        }
        DataWrite { port, changed: before ^ after, not_driven }
    }
}

/// The control register holding `addr`: (name, base address, width).
fn ctrl_register(addr: u32) -> Option<&'static (&'static str, u32, u32)> {
    CTRL_REGISTERS.iter().find(|r| addr >= r.1 && addr < r.1 + r.2 / 16)
}

fn no_ctrl(addr: u32) -> Error {
    Error::Register(format!(
        "C28x address 0x{addr:04X}: not a GPIO control register (GpioCtrlRegs: GPACTRL 0x6F80 … GPBPUD 0x6F9C, \
         GPCMUX1 0x6FA6 … GPCPUD 0x6FAC)"
    ))
}

/// A data-register word: (port, kind 0 DAT 1 SET 2 CLEAR 3 TOGGLE, high word).
fn data_word(addr: u32) -> (usize, u32, bool) {
    let off = addr - DATA_BASE;
    ((off / 8) as usize, (off % 8) / 2, off % 2 == 1)
}

/// The name of GPIO `pin`'s function at mux value `mux` where the emulator gives it one (the
/// peripherals' pins of the F28335's pin-mux table: SPRS439 / SPRUFB0; spec §3).
pub fn function_name(pin: u32, mux: u8) -> Option<&'static str> {
    Some(match (pin, mux) {
        (16, 1) | (54, 1) => "SPISIMOA",
        (17, 1) | (55, 1) => "SPISOMIA",
        (18, 1) | (56, 1) => "SPICLKA",
        (19, 1) | (57, 1) => "SPISTEA",
        (28, 1) => "SCIRXDA",
        (29, 1) => "SCITXDA",
        (32, 1) => "SDAA",
        (33, 1) => "SCLA",
        (62, 1) => "SCIRXDC",
        (63, 1) => "SCITXDC",
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gpbmux2_57(value: u16) -> (u32, u16) {
        // GPIO57 is bit 9 of GPBMUX2's pins 48–63: bits 18–19, the high word's bits 2–3.
        (0x6F99, value << 2)
    }

    /// Reset values (SPRUFB0): mux 0, inputs, GPAPUD = 0x0FFF.
    #[test]
    fn reset_state() {
        let g = Gpio::new();
        assert_eq!(g.read_ctrl(0x6F8C).unwrap(), 0x0FFF);
        assert_eq!(g.read_ctrl(0x6F8D).unwrap(), 0);
        assert!(!g.pull_up(5) && g.pull_up(12) && g.pull_up(57));
        assert!((0..=LAST_PIN).all(|p| g.mux(p) == 0 && !g.is_output(p)));
        assert!(g.read_ctrl(0x6FA0).is_err(), "0x6FA0 is reserved");
    }

    /// A protected write without EALLOW changes nothing; with it, the mux and direction take.
    #[test]
    fn eallow_protects_the_control_registers() {
        let mut g = Gpio::new();
        let (a, v) = gpbmux2_57(1);
        assert!(!g.write_ctrl(a, v, false).unwrap());
        assert_eq!(g.mux(57), 0);
        assert!(g.write_ctrl(a, v, true).unwrap());
        assert_eq!((g.mux(57), g.mux(56), g.mux(58)), (1, 0, 0));
        assert_eq!(function_name(57, g.mux(57)), Some("SPISTEA"));
        // GPBDIR bit 25 (GPIO57): the high word's bit 9.
        assert!(g.write_ctrl(0x6F9B, 1 << 9, true).unwrap());
        assert!(!g.is_output(57), "muxed to SPISTEA, not a GPIO output");
        g.write_ctrl(a, 0, true).unwrap();
        assert!(g.is_output(57));
    }

    /// SET/CLEAR/TOGGLE act on the latch and read 0; DAT reads the pin level; a write asking an input
    /// pin to move is reported, a read-modify-write of DAT is not.
    #[test]
    fn data_registers() {
        let mut g = Gpio::new();
        g.write_ctrl(0x6F9B, 1 << 9, true).unwrap(); // GPIO57 an output
        let high = |_| true;
        assert_eq!(g.write_data(0x6FCB, 1 << 9, high).changed, 1 << 25); // GPBSET high word: GPIO57
        let w = g.write_data(0x6FCD, 1 << 9, high); // GPBCLEAR high word: GPIO57
        assert_eq!((w.port, w.changed, w.not_driven), (1, 1 << 25, 0));
        assert_eq!(g.read_data(0x6FC9, high) >> 9 & 1, 0, "GPIO57 low");
        assert_eq!(g.read_data(0x6FC9, high) >> 10 & 1, 1, "GPIO58, an input, reads its level");
        assert_eq!(g.read_data(0x6FCD, high), 0, "CLEAR reads 0");
        // GPIO58 is an input: a SET asks it to move, and it does not.
        let w = g.write_data(0x6FCB, 1 << 10, high);
        assert_eq!(w.not_driven, 1 << 26);
        assert!(g.latch(58) && g.driven(58).is_none());
        // DAT written back as read: nothing asked of the inputs.
        let v = g.read_data(0x6FC9, high);
        let w = g.write_data(0x6FC9, v & !(1 << 9), high);
        assert_eq!(w.not_driven, 0);
        // TOGGLE.
        let w = g.write_data(0x6FCF, 1 << 9, high);
        assert_eq!(w.changed, 1 << 25);
        assert_eq!(g.driven(57), Some(true));
    }
}
