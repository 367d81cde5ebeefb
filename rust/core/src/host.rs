//! The board as a driver author drives it from the host, with no firmware model: SPI-A, LOSPCP and
//! the GPIO registers at their C28x addresses, the SPI parts the profile's `[[board.devices]]` places
//! on SPI-A, each behind its GPIO chip select (`board::spi_parts`: the ADIS16xxx part on GPIO57 with
//! the profile's sensor errors `errors.*` and faults `faults.*`), and virtual time that only the
//! caller moves. The Python `Board` and the C ABI (`rust/cabi`, which the C firmware runtime drives)
//! are thin wrappers of [`HostBoard`].
//!
//! - Registers are 16-bit words at C28x data addresses ([`REGISTERS`]); the GPIO registers are
//!   32-bit (two words, low word first). The GPIO (`dsp::gpio`, SPRUFB0): mux, direction, pull-ups,
//!   EALLOW protection of the control registers (a write without EALLOW is ignored, with a
//!   `protected_write` event); a GPxSET/GPxCLEAR/GPxTOGGLE word reads 0; GPxDAT reads the pins'
//!   levels. A chip select reaches its part when its pin is a GPIO output driven low; GPIO57 muxed
//!   to SPISTEA (GPBMUX2 = 1) is driven by SPI-A around each character instead. A write that asks a
//!   pin that is an input or a peripheral's to move is a `gpio_not_driven` warning (once per pin).
//!   `firmware.gpio_at_start` says how the pins are set at t = 0. SPI-A's pins GPIO54–56 driven as
//!   GPIO (a bit-banged SPI) clock the selected part with their edges, and its DOUT is on GPIO55
//!   (`board::bitbang`). LOSPCP (bits 2:0) changes LSPCLK
//!   at once.
//! - Time is whole picoseconds. A step that rounds to no time (a rounding residue of the caller's
//!   float arithmetic: below half a picosecond, or below the resolution of an f64 number of seconds
//!   at the current time) is no step; a real step back is refused.
//! - Every event is tied to the frame on the wires at its time (its SPI-A character index, as in the
//!   transaction log, and the DIN the slave sampled); a CS-edge event (`cs_hold`, `burst_truncated`)
//!   to the frame that ended last before it. An event inside a character still shifting waits until
//!   the character ends.

use crate::board::bitbang::{self, BitBang};
use crate::board::spi_parts::SpiParts;
use crate::board::InputFeed;
use crate::bus::link::{FrameRecord, LinkRecord, SpiLink};
use crate::bus::SpiSlave;
use crate::device::{Constant, Physical};
use crate::dsp::clocks::DspClocks;
use crate::dsp::gpio::{self, Gpio};
use crate::dsp::interrupts::{Blocked, Interrupts, Taken};
use crate::dsp::mcbsp::{self, McbspPorts};
use crate::dsp::serial::SerialPorts;
use crate::dsp::spi;
use crate::dsp::sysctrl::{self, SysCtrl, SysEvent};
use crate::dsp::unmodelled::{self, Unmodelled};
use crate::error::{Error, Result};
use crate::events::Event;
use crate::profile::{self, FaultKind, GpioAtStart, Profile};
use crate::time::{ps_to_s, Clock, Ps, PS_PER_S};

/// Every register the host board models: name, C28x word address, width in bits.
pub const REGISTERS: &[(&str, u32, u32)] = &[
    ("SPICCR", 0x7040, 16),
    ("SPICTL", 0x7041, 16),
    ("SPISTS", 0x7042, 16),
    ("SPIBRR", 0x7044, 16),
    ("SPIRXEMU", 0x7046, 16),
    ("SPIRXBUF", 0x7047, 16),
    ("SPITXBUF", 0x7048, 16),
    ("SPIDAT", 0x7049, 16),
    ("SPIFFTX", 0x704A, 16),
    ("SPIFFRX", 0x704B, 16),
    ("SPIFFCT", 0x704C, 16),
    ("SPIPRI", 0x704F, 16),
    ("LOSPCP", 0x701B, 16),
    ("GPADAT", 0x6FC0, 32),
    ("GPASET", 0x6FC2, 32),
    ("GPACLEAR", 0x6FC4, 32),
    ("GPATOGGLE", 0x6FC6, 32),
    ("GPBDAT", 0x6FC8, 32),
    ("GPBSET", 0x6FCA, 32),
    ("GPBCLEAR", 0x6FCC, 32),
    ("GPBTOGGLE", 0x6FCE, 32),
    ("GPCDAT", 0x6FD0, 32),
    ("GPCSET", 0x6FD2, 32),
    ("GPCCLEAR", 0x6FD4, 32),
    ("GPCTOGGLE", 0x6FD6, 32),
];

/// SPI-A's base address.
pub const SPIA_BASE: u32 = 0x7040;
/// The GPIO data registers' base address (GpioDataRegs).
pub const GPIO_DATA_BASE: u32 = 0x6FC0;
/// LOSPCP's address (SysCtrlRegs).
pub const LOSPCP: u32 = 0x701B;
/// The chip select of the ADIS16407 on the reference board.
pub const CS_GPIO: u32 = 57;

fn all_registers() -> impl Iterator<Item = &'static (&'static str, u32, u32)> {
    REGISTERS
        .iter()
        .chain(crate::dsp::interrupts::REGISTERS)
        .chain(sysctrl::REGISTERS)
        .chain(crate::dsp::sci::REGISTERS)
        .chain(crate::dsp::i2c::REGISTERS)
        .chain(mcbsp::REGISTERS)
        .chain(gpio::CTRL_REGISTERS)
}

/// A register by name: (address, width in bits). CPU timer 0's are `TIMER0TIM`, `TIMER0PRD`,
/// `TIMER0TCR`, `TIMER0TPR`, `TIMER0TPRH`; the PIE's `PIECTRL`, `PIEACK`, `PIEIER1`…, `PIEIFR1`….
pub fn register(name: &str) -> Result<(u32, u32)> {
    let upper = name.to_ascii_uppercase();
    all_registers().find(|r| r.0 == upper).map(|r| (r.1, r.2)).ok_or_else(|| {
        let names: Vec<&str> = all_registers().map(|r| r.0).collect();
        Error::Register(format!("register `{name}`: expected one of {}", names.join(", ")))
    })
}

/// The name of the register at `addr` (its low word for a 32-bit one), if modelled.
pub fn register_name(addr: u32) -> Option<&'static str> {
    all_registers().find(|r| addr >= r.1 && addr < r.1 + r.2 / 16).map(|r| r.0)
}

fn no_register(addr: u32) -> Error {
    Error::Register(format!(
        "C28x address 0x{addr:04X}: no modelled register there (modelled: SPI-A 0x7040…0x704F, SysCtrlRegs \
         PLLSTS, HISPCP, LOSPCP, PCLKCR0/1/3, LPMCR0, PLLCR, SCSR, WDCNTR, WDKEY, WDCR (0x7011…0x7029), \
         GPIO registers GPACTRL…GPCPUD 0x6F80…0x6FAD and GPADAT…GPCTOGGLE 0x6FC0…0x6FD7, CPU timers 0-2 0x0C00…0x0C17, PIE control \
         0x0CE0…0x0CF9, SCI-A/B/C 0x7050/0x7750/0x7770…+0xF, I2C-A 0x7900…0x790C and 0x7920/0x7921, McBSP-A/B 0x5000/0x5040…+0x23, the registers of ADC, ePWM, eCAP, eCAN, DMA, XINTF and FlashRegs (not modelled \
         peripherals); PieVectTable 0x0D00… is set through its vectors)"
    ))
}

/// A frame as an event is tied to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameRef {
    /// SPI-A character index since power-on (the transaction log's `index`).
    pub index: u64,
    /// The bits the slave sampled on DIN.
    pub din: u16,
}

/// An event with the frame it concerns.
#[derive(Debug, Clone, PartialEq)]
pub struct HostEvent {
    /// The event.
    pub event: Event,
    /// The frame the event names ([`Event::frame`]) when it is still known, else the frame on the
    /// wires at the event (or, for a CS edge, the frame before it).
    pub frame: Option<FrameRef>,
}

impl HostEvent {
    /// The index of the frame the event concerns: its own ([`Event::frame`]), else [`HostEvent::frame`]'s.
    pub fn frame_index(&self) -> Option<u64> {
        self.event.frame.or(self.frame.map(|f| f.index))
    }

    /// The DIN the slave sampled in that frame, when its record is known.
    pub fn din(&self) -> Option<u16> {
        self.frame.filter(|f| Some(f.index) == self.frame_index()).map(|f| f.din)
    }
}

/// What [`HostBoard::configure_spi`] set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpiSetting {
    /// SPIBRR written.
    pub spibrr: u16,
    /// The SCLK it gives, Hz (the asked one or the nearest below it).
    pub sclk_hz: f64,
    /// Whether that is exactly the SCLK asked for.
    pub exact: bool,
    /// The standard SPI mode of SPICCR.CLKPOLARITY and SPICTL.CLK_PHASE.
    pub mode: u8,
    /// LSPCLK, Hz.
    pub lspclk_hz: f64,
}

/// The board without firmware, driven from the host in virtual time.
pub struct HostBoard {
    link: SpiLink<SpiParts>,
    now: Ps,
    sysclkout: Clock,
    /// System control: the PLL, the clock prescalers and enables, the watchdog.
    sys: SysCtrl,
    /// The registers of the peripherals not modelled yet.
    other: Unmodelled,
    /// SPI-A's interrupt lines as last seen: how many times each was raised, its level.
    spi_lines: [(u64, bool); 2],
    /// Peripherals reported used with their clock off (until it is on again).
    clock_off: Vec<&'static str>,
    /// The peripheral whose clock enable [`HostBoard::clock_gate`] looked up last, and its
    /// PCLKCR register and bit.
    gate_bit: (&'static str, (u32, u16)),
    /// The watchdog reset the chip: what is said of every later access.
    in_reset: Option<String>,
    spi_profile: profile::Spi,
    t_sfs: Ps,
    /// GPIO ports A, B, C.
    gpio: Gpio,
    /// The chip select asserted on the link (its pin a GPIO output driven low), if any.
    cs_low: Option<u8>,
    /// Pins a `gpio_not_driven` warning was raised for (ports A, B, C).
    gpio_warned: [u32; 3],
    /// Transaction log not yet taken.
    log: Vec<LinkRecord>,
    /// Frames events may still be tied to (the last one at least).
    recent: Vec<FrameRecord>,
    /// Events not yet tied to their frame or not yet taken.
    pending: Vec<Event>,
    /// CPU timer 0, the PIE and the CPU's interrupt state.
    irq: Interrupts,
    /// The parts' inputs when they read a trace ([`HostBoard::with_input`]).
    feeds: Vec<InputFeed>,
    /// Timer 0's reloads when its interrupt was last taken.
    tint0_taken: u64,
    /// The interrupts being serviced, innermost last (whether each is timer 0's), and the time the
    /// last ISR of timer 0 returned (IRET): a tick before it was an overrun.
    servicing: Vec<bool>,
    tint0_free_ps: Ps,
    /// Keep the transaction log for [`HostBoard::take_log`] (not on a board reading a trace: a
    /// firmware run would keep every frame).
    keep_log: bool,
    /// SCI-A/B/C.
    serial: SerialPorts,
    /// SPI bit-banged on SPI-A's pins driven as GPIO (`board::bitbang`).
    bitbang: BitBang,
    /// McBSP-A and McBSP-B (`dsp::mcbsp`).
    mcbsp: McbspPorts,
}

impl HostBoard {
    /// The board of a profile at t = 0: SPI-A in its reset state (see [`HostBoard::init_spi`]), CS
    /// high, the device powered and still, with the profile's sensor errors and faults. The
    /// `dropped_burst` fault is refused: it acts inside the firmware's burst of a timer tick, and
    /// here the driver, not a timer, decides when frames happen.
    pub fn new(profile: &Profile) -> Result<HostBoard> {
        if profile.faults.list.iter().any(|f| f.kind == FaultKind::DroppedBurst) {
            return Err(Error::Config(
                "faults.list: a `dropped_burst` fault raises CS inside the firmware's burst of a timer tick; the \
                 host board runs no firmware (the driver moves CS), so it cannot be injected here: remove it, or \
                 run the firmware model (`emulate`, `sins-fw run`)"
                    .into(),
            ));
        }
        let mut parts = SpiParts::from_profile(profile)?;
        parts.select(CS_GPIO as u8);
        let mut gpio = Gpio::new();
        if profile.firmware.gpio_at_start == GpioAtStart::ChipSelects {
            let pins: Vec<u32> = parts.chip_selects().map(u32::from).collect();
            gpio.boot_outputs_high(&pins);
        }
        let clocks = DspClocks::from_profile(&profile.clocks)?;
        let mut link = SpiLink::from_profile(profile, parts)?;
        link.enable_log();
        let i2c = crate::board::links::i2c_targets(profile)?;
        let serial = SerialPorts::new(profile, link.spi().lspclk(), clocks.sysclkout, i2c)?;
        Ok(HostBoard {
            link,
            now: 0,
            sysclkout: clocks.sysclkout,
            sys: SysCtrl::from_profile(&profile.clocks)?,
            other: Unmodelled::new(),
            spi_lines: [(0, false); 2],
            clock_off: Vec::new(),
            gate_bit: ("", (0, 0)),
            in_reset: None,
            spi_profile: profile.spi.clone(),
            t_sfs: (profile.device.t_sfs_ns * 1e3).ceil() as Ps,
            gpio,
            cs_low: None,
            gpio_warned: [0; 3],
            log: Vec::new(),
            recent: Vec::new(),
            pending: Vec::new(),
            irq: Interrupts::new(clocks.sysclkout),
            feeds: Vec::new(),
            tint0_taken: 0,
            servicing: Vec::new(),
            tint0_free_ps: 0,
            keep_log: true,
            serial,
            bitbang: BitBang::new(),
            mcbsp: McbspPorts::new(),
        })
    }

    /// The board of a profile whose parts see a streamed input (a trace: push its rows with
    /// [`HostBoard::push_input`], time 0 is power-on) instead of being still and powered: each
    /// ADIS16xxx part, and the ADS8344's `[geomag]` front end.
    pub fn with_input(profile: &Profile) -> Result<HostBoard> {
        let mut b = HostBoard::new(profile)?;
        let mut feeds = b.link.slave().own_feeds();
        for dev in b.link.slave_mut().adis_parts() {
            let (feed, stimulus) = InputFeed::new();
            dev.set_stimulus(Box::new(stimulus));
            feeds.push(feed);
        }
        b.feeds = feeds;
        b.keep_log = false;
        Ok(b)
    }

    /// Append rows of input (times in s since power-on, strictly increasing across calls).
    pub fn push_input(&mut self, t_s: &[f64], samples: Vec<Physical>) -> Result<()> {
        let Some((last, others)) = self.feeds.split_last() else {
            return Err(Error::Input("push_input: this board reads no input stream (build it with an input)".into()));
        };
        for f in others {
            f.push(t_s, samples.clone())?;
        }
        last.push(t_s, samples)
    }

    /// No more input will come.
    pub fn end_input(&mut self) {
        self.feeds.iter().for_each(InputFeed::end);
    }

    /// The last time the input covers (ps, rounded down), and whether it has ended; None before the
    /// first row or without an input stream.
    pub fn input_until(&self) -> Option<(Ps, bool)> {
        let f = self.feeds.first()?;
        let t = f.last_time_s()?;
        Some(((t.max(0.0) * PS_PER_S as f64).floor() as Ps, f.ended()))
    }

    /// The interrupt the CPU takes now, if any, acknowledged as the CPU and the PIE do it (see
    /// [`crate::dsp::interrupts`]).
    /// Timer 0's ticks, accounted as the firmware model accounts them (`Emulator::run_tick`, the
    /// `queue` policy the PIE's latch is): a tick that came while the previous one was still pending
    /// or masked is lost, one `tick_lost` event each at its time; the tick whose ISR is taken, when
    /// it came before timer 0's previous ISR returned, is an `overrun` event at its time, measured
    /// how late the ISR starts.
    pub fn take_interrupt(&mut self) -> Option<Taken> {
        let taken = self.irq.take(self.now)?;
        let tint0 = taken.vector == crate::dsp::interrupts::TINT0_VECTOR;
        if tint0 {
            let (n, last) = self.irq.underflows();
            for k in self.tint0_taken + 1..n {
                self.pending.push(Event::new(
                    self.irq.underflow_ps(k).unwrap_or(self.now),
                    "tick_lost",
                    crate::events::Severity::Error,
                    format!("tick {k}: TINT0 arrived while the previous one was still pending: lost"),
                ));
            }
            self.tint0_taken = n;
            let tick_ps = last.unwrap_or(self.now);
            if n > 0 && tick_ps < self.tint0_free_ps {
                let late = self.now - tick_ps;
                self.pending.push(crate::deadline::overrun(
                    tick_ps,
                    late,
                    format!("tick {n}: the previous ISR ran {:.1} µs past this tick (Queue)", late as f64 / 1e6),
                ));
            }
        }
        self.servicing.push(tint0);
        Some(taken)
    }

    /// IRET: the end of the ISR being serviced.
    pub fn iret(&mut self) -> Result<()> {
        self.irq.iret()?;
        if self.servicing.pop() == Some(true) {
            self.tint0_free_ps = self.now;
        }
        Ok(())
    }

    /// The CPU's IER.
    pub fn ier(&self) -> u16 {
        self.irq.ier()
    }

    /// Set IER.
    pub fn set_ier(&mut self, value: u16) {
        self.irq.set_ier(value);
    }

    /// The CPU's IFR now.
    pub fn ifr(&mut self) -> u16 {
        self.irq.ifr(self.now)
    }

    /// Set IFR.
    pub fn set_ifr(&mut self, value: u16) {
        self.irq.set_ifr(value, self.now);
    }

    /// EINT (`masked = false`) and DINT (`true`).
    pub fn set_intm(&mut self, masked: bool) {
        self.irq.set_intm(masked);
    }

    /// INTM.
    pub fn intm(&self) -> bool {
        self.irq.intm()
    }

    /// EALLOW (`true`) and EDIS (`false`).
    pub fn set_eallow(&mut self, on: bool) {
        self.irq.set_eallow(on);
    }

    /// Set PieVectTable vector `n` to a host ISR address: ignored without EALLOW (an
    /// `protected_write` event says so).
    pub fn set_vector(&mut self, n: usize, isr: u64) -> Result<()> {
        if !self.irq.set_vector(n, isr)? {
            self.pending.push(Event::new(
                self.now,
                "protected_write",
                crate::events::Severity::Warning,
                format!(
                    "PieVectTable vector {n} (0x{:04X}) written without EALLOW: the write is ignored, as on the chip",
                    crate::dsp::interrupts::PIE_VECT_BASE as usize + 2 * n
                ),
            ));
        }
        Ok(())
    }

    /// Report an interrupt the firmware enabled that no modelled peripheral raises (`what` names it:
    /// the vector, its PIE group and line): the firmware runtime's check, when PIEIERx or IER is written
    /// (firmware_c/runtime/sins_fw_runtime.cpp, `check_pie_enable`).
    pub fn report_never_raised(&mut self, what: &str) {
        self.pending.push(Event::new(
            self.now,
            "interrupt_never_raised",
            crate::events::Severity::Warning,
            format!("the firmware enables {what}, which the emulator cannot raise (its peripheral is not modelled): its ISR will never run"),
        ));
    }

    /// PieVectTable vector `n`.
    pub fn vector(&self, n: usize) -> u64 {
        self.irq.vector(n)
    }

    /// When an interrupt may next become takeable without a register access (timer 0's next
    /// reload, when nothing masks it), ps.
    pub fn next_interrupt_ps(&self) -> Option<Ps> {
        if self.irq.blocked().is_some() {
            // A watchdog about to bite ends any loop (a reset), and its WAKEINT may be let in; an SCI
            // line's request may come when only INTM is clear.
            let serial = self.peripheral_interrupt_ps().filter(|_| !self.irq.intm());
            return [self.sys.next_event_ps(), serial].into_iter().flatten().min();
        }
        // SPI-A's flags change at the end of a character; the watchdog's WAKEINT at its overflow; an
        // SCI's at its character's end.
        let spi = self.spi_armed().then(|| self.link.spi().current_frame().map(|f| f.end_ps)).flatten();
        let serial = self.peripheral_interrupt_ps().filter(|_| !self.irq.intm());
        [self.irq.next_interrupt_ps(), spi, self.sys.next_event_ps(), serial].into_iter().flatten().min()
    }

    /// When an SCI, I2C-A or McBSP line may next be raised by itself.
    fn peripheral_interrupt_ps(&self) -> Option<Ps> {
        [self.serial.next_interrupt_ps(), self.mcbsp.next_interrupt_ps()].into_iter().flatten().min()
    }

    fn spi_armed(&self) -> bool {
        self.link.spi().interrupt_lines().iter().any(|l| l.2)
    }

    /// What keeps any interrupt from coming without a register access (None: one can come).
    pub fn interrupts_blocked(&self) -> Option<Blocked> {
        let b = self.irq.blocked().filter(|b| *b == Blocked::Intm || self.peripheral_interrupt_ps().is_none());
        if b.is_none() && self.next_interrupt_ps().is_none() && self.irq.ier() & self.irq.ifr_now() & 0x3FFF == 0 {
            let name = if self.spi_armed() { "SPIRXINTA/SPITXINTA" } else { "the interrupt" };
            return Some(Blocked::Idle { name });
        }
        b
    }

    /// Timer 0's reloads since power-on and the time of the last one; its next reload (ps).
    pub fn timer0_ticks(&mut self) -> (u64, Option<Ps>, Option<Ps>) {
        self.irq.sync(self.now);
        let (n, last) = self.irq.underflows();
        (n, last, self.irq.next_reload_ps())
    }

    /// SCI-A/B/C.
    pub fn serial(&self) -> &SerialPorts {
        &self.serial
    }

    /// SYSCLKOUT.
    pub fn sysclkout(&self) -> Clock {
        self.sysclkout
    }

    /// The earliest time after now at which the register at `addr` may read differently with no
    /// other access in between (a polling loop may skip to it): SPI-A's status changes at the next
    /// SPI-A event, timer 0's TCR at its next reload; None for a register that does not change by
    /// itself (or is not modelled); `now` for one that changes continually (TIM).
    pub fn next_change_ps(&self, addr: u32) -> Option<Ps> {
        let own = match addr {
            a if is_spi(a) => {
                let spi = self.link.spi();
                [self.link.int_flag_time(), self.link.buffull_clear_time(), spi.current_frame().map(|f| f.end_ps)]
                    .into_iter()
                    .flatten()
                    .filter(|&t| t > self.now)
                    .min()
            }
            0x0C04 | 0x0CE0..=0x0CF9 => self.irq.next_reload_ps().filter(|&t| t > self.now),
            0x0C0C => self.irq.next_reload_ps_of(1).filter(|&t| t > self.now),
            0x0C14 => self.irq.next_reload_ps_of(2).filter(|&t| t > self.now),
            0x0C00 | 0x0C01 | 0x0C08 | 0x0C09 | 0x0C10 | 0x0C11 | sysctrl::WDCNTR => Some(self.now),
            a if SerialPorts::owns(a) => self.serial.next_change_ps(a),
            a if McbspPorts::owns(a) => self.mcbsp.next_change_ps(a).filter(|&t| t > self.now),
            _ => None,
        };
        // The PLL locking (PLLSTS) and a watchdog reset change what any register reads.
        [own, self.sys.next_event_ps().filter(|&t| t > self.now)].into_iter().flatten().min()
    }

    /// Virtual time, ps.
    pub fn now(&self) -> Ps {
        self.now
    }

    /// Virtual time, s.
    pub fn now_s(&self) -> f64 {
        ps_to_s(self.now)
    }

    /// LSPCLK, Hz.
    pub fn lspclk_hz(&self) -> f64 {
        self.link.spi().lspclk().hz()
    }

    /// Move virtual time to `t` (≥ now): the device samples, characters shift, the PLL locks, the
    /// watchdog counts (a watchdog reset is an error from then on: the firmware's run ends there).
    pub fn advance_to(&mut self, t: Ps) -> Result<()> {
        if t < self.now {
            return Err(Error::Input(format!(
                "advance to {t} ps: the board is at {} ps already; virtual time only moves forward",
                self.now
            )));
        }
        self.check_reset()?;
        while let Some(next) = self.sys.next_event_ps().filter(|&n| n <= t) {
            let next = next.max(self.now);
            self.now = next;
            self.link.advance(next)?;
            if let Some(ev) = self.sys.advance(next) {
                self.apply_sys(ev)?;
            }
        }
        self.now = t;
        let r = self.link.advance(t);
        self.serial.advance(t);
        self.mcbsp.advance(t, self.link.spi().lspclk());
        self.sync();
        r
    }

    fn check_reset(&self) -> Result<()> {
        match &self.in_reset {
            Some(m) => Err(Error::Config(m.clone())),
            None => Ok(()),
        }
    }

    /// Act on what system control did: clocks changed, WAKEINT, a watchdog reset.
    fn apply_sys(&mut self, ev: SysEvent) -> Result<()> {
        match ev {
            SysEvent::Clocks(t) => {
                self.sysclkout = self.sys.sysclkout();
                self.irq.set_sysclkout(self.sysclkout, t);
                self.link.set_lspclk(self.sys.lspclk(), t)?;
                self.serial.set_lspclk(self.sys.lspclk(), t);
                self.serial.set_sysclkout(self.sysclkout);
            }
            SysEvent::Lspclk(t) => {
                self.link.set_lspclk(self.sys.lspclk(), t)?;
                self.serial.set_lspclk(self.sys.lspclk(), t);
            }
            SysEvent::WatchdogInterrupt(t) => {
                self.irq.set_pie_flag(1, 8, t);
                self.pending.push(Event::new(
                    t,
                    "watchdog_interrupt",
                    crate::events::Severity::Info,
                    "the watchdog counter overflowed with SCSR.WDENINT = 1: WAKEINT (PIE INT1.8) raised",
                ));
            }
            SysEvent::WatchdogReset(t, overflow) => {
                let why = if overflow {
                    "its counter overflowed: WDKEY was not written 0x55 then 0xAA in time (ServiceDog), and the \
                     dog was not disabled (DisableDog: WDCR = 0x0068)"
                } else {
                    "WDCR was written without WDCHK = 101 (bits 5:3): TI writes WDCR = 0x0068 or 0x0028"
                };
                let msg = format!("the watchdog reset the chip at t = {:.9} s: {why}", ps_to_s(t));
                self.pending.push(Event::new(t, "watchdog_reset", crate::events::Severity::Error, msg.clone()));
                self.in_reset = Some(msg.clone());
                return Err(Error::Config(msg));
            }
        }
        Ok(())
    }

    /// Let `cycles` SYSCLKOUT cycles pass (the CPU's time for code between register accesses).
    pub fn advance_cycles(&mut self, cycles: u64) -> Result<()> {
        let cycle = self.sysclkout.ps_to_cycles_ceil(self.now).saturating_add(cycles);
        self.advance_to(self.sysclkout.cycles_to_ps(cycle).max(self.now))
    }

    /// Let `seconds` pass; a negative step that rounds to no time is no step.
    pub fn advance_s(&mut self, seconds: f64) -> Result<()> {
        if !seconds.is_finite() {
            return Err(Error::Input(format!("advance({seconds} s): expected a finite time")));
        }
        let step = (seconds * PS_PER_S as f64).round();
        if step < 0.0 && -step > self.rounding_ps() {
            return Err(Error::Input(format!(
                "advance({seconds:e} s): a step back in time; virtual time only moves forward (a step that rounds \
                 to less than the time's resolution, {:.3} ps here, is taken as none)",
                self.rounding_ps()
            )));
        }
        self.advance_to(self.now + step.max(0.0) as Ps)
    }

    /// Move to `t_s` seconds since power-on; a time before now by less than the time's resolution
    /// (a rounding residue) is now.
    pub fn advance_to_s(&mut self, t_s: f64) -> Result<()> {
        if !(t_s.is_finite() && t_s >= 0.0) {
            return Err(Error::Input(format!("advance_to({t_s} s): expected a finite time ≥ 0 s")));
        }
        let t = (t_s * PS_PER_S as f64).round();
        let now = self.now as f64;
        if t < now {
            if now - t > self.rounding_ps() {
                return Err(Error::Input(format!(
                    "advance_to({t_s:.12} s): the board is at {:.12} s already; virtual time only moves forward",
                    self.now_s()
                )));
            }
            return Ok(());
        }
        self.advance_to(t as Ps)
    }

    /// The resolution of a time near now given as an f64 number of seconds, in ps (at least half a
    /// picosecond, the rounding of whole picoseconds).
    fn rounding_ps(&self) -> f64 {
        (self.now as f64 * f64::EPSILON).max(0.5)
    }

    /// Write a 16-bit word at a C28x address.
    pub fn write(&mut self, addr: u32, value: u16) -> Result<()> {
        let r = self.write_unsynced(addr, value);
        self.sync();
        r
    }

    fn write_unsynced(&mut self, addr: u32, value: u16) -> Result<()> {
        let now = self.now;
        self.check_reset()?;
        if !self.clock_gate(addr) {
            return Ok(());
        }
        match addr {
            LOSPCP => self.set_lospcp(value & 0x7),
            a if SysCtrl::owns(a) => self.write_sys(a, value),
            a if Unmodelled::owns(a) => self.write_other(a, value),
            a if is_spi(a) => self.link.write((a - SPIA_BASE) as u16, value, now),
            a if is_gpio(a) => self.write_gpio(a, value),
            a if Gpio::owns_ctrl(a) => self.write_gpio_ctrl(a, value),
            a if Interrupts::owns(a) => self.irq.write(a, value, now),
            a if SerialPorts::owns(a) => self.serial.write(a, value, now),
            a if McbspPorts::owns(a) => {
                self.mcbsp.write(a, value, now, self.link.spi().lspclk());
                Ok(())
            }
            a => Err(no_register(a)),
        }
    }

    /// Read the 16-bit word at a C28x address (reading SPIRXBUF clears INT_FLAG, as on the chip).
    pub fn read(&mut self, addr: u32) -> Result<u16> {
        let now = self.now;
        self.check_reset()?;
        if !self.clock_gate(addr) {
            return Ok(0);
        }
        let r = match addr {
            a if SysCtrl::owns(a) => self.sys.read(a, now),
            a if Unmodelled::owns(a) => Ok(self.read_other(a)),
            a if is_spi(a) => self.link.read((a - SPIA_BASE) as u16, now),
            a if is_gpio(a) => Ok(self.read_gpio(a)),
            a if Gpio::owns_ctrl(a) => self.gpio.read_ctrl(a),
            a if Interrupts::owns(a) => self.irq.read(a, now),
            a if SerialPorts::owns(a) => self.serial.read(a, now),
            a if McbspPorts::owns(a) => Ok(self.mcbsp.read(a, now, self.link.spi().lspclk())),
            a => Err(no_register(a)),
        };
        // Every operation that changes the board ends with a sync, so after a read that changes
        // nothing (the polling reads of SPISTS, GPxDAT, the system control registers) there is
        // nothing to move: no second sync on the hot path of a register access.
        if !reads_without_effect(addr) {
            self.sync();
        }
        r
    }

    /// Write a register by name; `value` is checked against its width (a 32-bit register is written
    /// low word first). An EALLOW-protected one (SysCtrlRegs) is written as a driver writes it,
    /// between EALLOW and EDIS.
    pub fn write_named(&mut self, name: &str, value: i64) -> Result<()> {
        let (addr, _) = register(name)?;
        let eallow = self.irq.eallow();
        if SysCtrl::owns(addr) {
            self.irq.set_eallow(true);
        }
        let r = self.write_named_as_is(name, value);
        self.irq.set_eallow(eallow);
        r
    }

    fn write_named_as_is(&mut self, name: &str, value: i64) -> Result<()> {
        let (addr, bits) = register(name)?;
        let max = (1i64 << bits) - 1;
        if !(0..=max).contains(&value) {
            return Err(Error::Register(format!(
                "{} = {value} ({}): expected 0…0x{max:X} (a {bits}-bit register)",
                name.to_ascii_uppercase(),
                hex(value)
            )));
        }
        self.write(addr, value as u16)?;
        if bits == 32 {
            self.write(addr + 1, (value >> 16) as u16)?;
        }
        Ok(())
    }

    /// Read a register by name (a 32-bit register's two words, low word first).
    pub fn read_named(&mut self, name: &str) -> Result<u32> {
        let (addr, bits) = register(name)?;
        let lo = u32::from(self.read(addr)?);
        Ok(if bits == 32 { lo | u32::from(self.read(addr + 1)?) << 16 } else { lo })
    }

    /// Drive GPIO57, the chip select (`high = false` asserts it), through GPBSET/GPBCLEAR.
    pub fn set_gpio57(&mut self, high: bool) -> Result<()> {
        self.set_gpio(CS_GPIO, high)
    }

    /// Drive a GPIO pin (0…87) through its port's SET/CLEAR register.
    pub fn set_gpio(&mut self, pin: u32, high: bool) -> Result<()> {
        if pin > 87 {
            return Err(Error::Register(format!("GPIO{pin}: the F28335 has GPIO0…GPIO87")));
        }
        let base = GPIO_DATA_BASE + 8 * (pin / 32) + if high { 2 } else { 4 };
        let bit = pin % 32;
        self.write(base + bit / 16, 1 << (bit % 16))
    }

    fn set_lospcp(&mut self, lospcp: u16) -> Result<()> {
        let lspclk = if lospcp == 0 { self.sysclkout } else { self.sysclkout.divided(2 * u64::from(lospcp)) };
        if !self.irq.eallow() {
            self.ignored_write(LOSPCP, "LOSPCP");
            return Ok(());
        }
        self.link.set_lspclk(lspclk, self.now)?;
        self.serial.set_lspclk(lspclk, self.now);
        self.sys.write(LOSPCP, lospcp, self.now)?;
        Ok(())
    }

    /// A write to an EALLOW-protected register without EALLOW: ignored, as on the chip.
    fn ignored_write(&mut self, addr: u32, name: &str) {
        self.pending.push(Event::new(
            self.now,
            "protected_write",
            crate::events::Severity::Warning,
            format!("{name} (0x{addr:04X}) written without EALLOW: the write is ignored, as on the chip"),
        ));
    }

    fn write_sys(&mut self, addr: u32, value: u16) -> Result<()> {
        if !self.irq.eallow() {
            self.ignored_write(addr, register_name(addr).unwrap_or("SysCtrlRegs"));
            return Ok(());
        }
        let now = self.now;
        if let Some(ev) = self.sys.write(addr, value, now)? {
            self.apply_sys(ev)?;
        }
        if addr == sysctrl::PCLKCR3 {
            // CPUTIMER0/1/2ENCLK gate the timers' clocks (SPRUFB0): with it off a timer stands still.
            for (n, name) in ["CPU timer 0", "CPU timer 1", "CPU timer 2"].into_iter().enumerate() {
                self.irq.set_timer_clock(n, self.sys.clock_on(name), now);
            }
        }
        Ok(())
    }

    fn report_first_use(&mut self, addr: u32, what: &str) {
        if let Some(f) = self.other.first_use(addr) {
            self.pending.push(Event::new(
                self.now,
                "unmodelled_peripheral",
                crate::events::Severity::Warning,
                format!(
                    "the firmware uses the {} ({}: {what} 0x{addr:04X}), which is not modelled: its registers read and \
                     write with their reset values ({}), but it does nothing (no conversions, outputs, transfers \
                     or interrupts); this is reported once for every {} module",
                    f.instance, f.regs, f.guide, f.kind
                ),
            ));
        }
    }

    fn read_other(&mut self, addr: u32) -> u16 {
        self.report_first_use(addr, "a read at");
        self.other.read(addr)
    }

    fn write_other(&mut self, addr: u32, value: u16) -> Result<()> {
        self.report_first_use(addr, &format!("a write of 0x{value:04X} at"));
        if unmodelled::protected(addr) && !self.irq.eallow() {
            let regs = unmodelled::frame_of(addr).map_or("a register", |f| f.regs);
            self.ignored_write(addr, regs);
            return Ok(());
        }
        self.other.write(addr, value);
        Ok(())
    }

    /// Whether the peripheral at `addr` has its clock on (PCLKCR0/1/3); when not, the access is lost
    /// and reported once (until the clock is on again).
    fn clock_gate(&mut self, addr: u32) -> bool {
        let instance = match addr {
            a if is_spi(a) => "SPI-A",
            0x0C00..=0x0C07 => "CPU timer 0",
            0x0C08..=0x0C0F => "CPU timer 1",
            0x0C10..=0x0C17 => "CPU timer 2",
            0x7050..=0x705F => "SCI-A",
            0x7750..=0x775F => "SCI-B",
            0x7770..=0x777F => "SCI-C",
            0x7900..=0x793F => "I2C-A",
            a if McbspPorts::owns(a) => McbspPorts::instance(a),
            a => match unmodelled::frame_of(a) {
                Some(f) => f.instance,
                None => return true,
            },
        };
        // The enable bit is found by the instance's name; the last one found is kept (an access is
        // most often to the peripheral of the access before it).
        let (reg, mask) = if std::ptr::eq(instance, self.gate_bit.0) {
            self.gate_bit.1
        } else {
            match sysctrl::clock_bit(instance) {
                Some(bit) => {
                    self.gate_bit = (instance, bit);
                    bit
                }
                None => return true,
            }
        };
        if self.sys.read(reg, self.now).map_or(true, |v| v & mask != 0) {
            if !self.clock_off.is_empty() {
                self.clock_off.retain(|p| *p != instance);
            }
            return true;
        }
        if !self.clock_off.contains(&instance) {
            self.clock_off.push(instance);
            let (reg, bit) = sysctrl::clock_bit(instance).unwrap_or((0, 0));
            self.pending.push(Event::new(
                self.now,
                "peripheral_clock_off",
                crate::events::Severity::Warning,
                format!(
                    "{instance} register 0x{addr:04X} accessed with its clock off ({} bit {} = 0: InitPeripheralClocks \
                     enables it): writes are lost and reads give 0 until it is on",
                    register_name(reg).unwrap_or("PCLKCR"),
                    bit.trailing_zeros()
                ),
            ));
        }
        false
    }

    /// SPI-A's interrupt lines to the PIE (SPIRXINTA INT6.1, SPITXINTA INT6.2): a line's rise (its
    /// flag set with its interrupt enabled, or enabled with its flag set) sets the PIE flag.
    fn spi_interrupts(&mut self) {
        let lines = self.link.spi().interrupt_lines();
        for (k, &(level, raises, enabled)) in lines.iter().enumerate() {
            let (seen, was) = self.spi_lines[k];
            if level && (raises > seen || !was) {
                self.irq.set_pie_flag(6, k as u8 + 1, self.now);
            }
            self.spi_lines[k] = (raises, level);
            self.irq.set_armed(6, k as u8 + 1, enabled);
        }
    }

    /// A pin's level when it is not a GPIO output: GPIO57 as SPISTEA shows the STE line; any
    /// other pin reads high (pulled up, or an undriven line, read as the link's floating level).
    fn pin_level(&self) -> impl Fn(u32) -> bool {
        let ste_low = self.link.ste_driven() && self.link.cs_asserted_by_ste();
        // GPIO55 as a GPIO input shows the selected part's DOUT in a bit-banged window.
        let somi = self.cs_low.and_then(|_| self.bitbang.somi(self.link.slave().answers_as_sampled()));
        move |pin| match pin {
            CS_GPIO => !ste_low,
            bitbang::SOMI => somi.unwrap_or(true),
            _ => true,
        }
    }

    fn write_gpio(&mut self, addr: u32, value: u16) -> Result<()> {
        let level = self.pin_level();
        let w = self.gpio.write_data(addr, value, level);
        let fresh = w.not_driven & !self.gpio_warned[w.port];
        if fresh != 0 {
            self.gpio_warned[w.port] |= fresh;
            self.warn_not_driven(addr, w.port, fresh);
        }
        if w.changed != 0 {
            self.bitbang_pins()?;
            self.route_chip_selects()?;
        }
        Ok(())
    }

    #[cold]
    fn warn_not_driven(&mut self, addr: u32, port: usize, pins: u32) {
        let reg = register_name(addr).unwrap_or("GPIO data register");
        let mut bits = pins;
        while bits != 0 {
            let bit = bits.trailing_zeros();
            bits &= bits - 1;
            let pin = 32 * port as u32 + bit;
            let port_name = ["A", "B", "C"][port];
            let mux = self.gpio.mux(pin);
            let why = match (mux, gpio::function_name(pin, mux)) {
                (0, _) => format!("an input (GP{port_name}DIR bit {bit} = 0)"),
                (m, Some(f)) => format!("muxed to {f} (its GP{port_name}MUX field = {m})"),
                (m, None) => format!("muxed to a peripheral (its GP{port_name}MUX field = {m})"),
            };
            self.pending.push(Event::new(
                self.now,
                "gpio_not_driven",
                crate::events::Severity::Warning,
                format!(
                    "{reg} written for GPIO{pin}, which is {why}: the output latch changes but the pin does not \
                     move, as on the chip (reported once per pin)"
                ),
            ));
        }
    }

    fn write_gpio_ctrl(&mut self, addr: u32, value: u16) -> Result<()> {
        if !self.gpio.write_ctrl(addr, value, self.irq.eallow())? {
            self.pending.push(Event::new(
                self.now,
                "protected_write",
                crate::events::Severity::Warning,
                format!(
                    "{} (0x{addr:04X}) written without EALLOW: the write is ignored, as on the chip (SPRUFB0: the \
                     GPIO control registers are EALLOW-protected)",
                    register_name(addr).unwrap_or("GpioCtrlRegs")
                ),
            ));
            return Ok(());
        }
        self.serial.set_i2c_pins(self.gpio.mux(32) == 1 && self.gpio.mux(33) == 1);
        self.bitbang_pins()?;
        self.route_chip_selects()
    }

    /// Tell the bit-banged master's frames how SPI-A's pins stand now (an SCLK edge clocks the
    /// selected part).
    fn bitbang_pins(&mut self) -> Result<()> {
        let sclk = self.gpio.driven(bitbang::CLK);
        let simo = self.gpio.driven(bitbang::SIMO).unwrap_or(true);
        if sclk.is_some() {
            self.link.advance(self.now)?;
        }
        self.bitbang.pins(self.now, sclk, simo, self.cs_low.is_some(), self.link.slave_mut());
        Ok(())
    }

    /// Connect the chip selects as the pins now stand: GPIO57 muxed to SPISTEA is driven by SPI-A;
    /// a part's chip select whose pin is a GPIO output driven low is asserted (the first one when
    /// several are: a contention, reported).
    fn route_chip_selects(&mut self) -> Result<()> {
        let now = self.now;
        let ste = self.gpio.mux(CS_GPIO) == 1;
        if ste != self.link.ste_driven() {
            if ste && self.cs_low.is_none() {
                self.link.slave_mut().select(CS_GPIO as u8);
            }
            self.link.set_ste_driven(ste, now)?;
        }
        let mut low = None;
        let mut others = Vec::new();
        for cs in self.link.slave().chip_selects() {
            if self.gpio.driven(u32::from(cs)) == Some(false) {
                if low.is_none() {
                    low = Some(cs);
                } else {
                    others.push(cs);
                }
            }
        }
        if low == self.cs_low {
            return Ok(());
        }
        self.bitbang.before_cs_change(self.link.slave_mut());
        if self.cs_low.is_some() {
            self.link.set_gpio57(true, now)?;
        }
        if let Some(cs) = low {
            self.link.slave_mut().select(cs);
            self.link.set_gpio57(false, now)?;
            if !others.is_empty() {
                let names: Vec<String> = others.iter().map(|g| format!("GPIO{g}")).collect();
                self.pending.push(Event::new(
                    now,
                    "cs_contention",
                    crate::events::Severity::Error,
                    format!(
                        "chip selects GPIO{cs} and {} are low together: two parts drive SPISOMIA (the emulator \
                         connects GPIO{cs}'s only)",
                        names.join(", ")
                    ),
                ));
            }
        }
        self.cs_low = low;
        Ok(())
    }

    fn read_gpio(&self, addr: u32) -> u16 {
        self.gpio.read_data(addr, self.pin_level())
    }

    /// The published InitSpi register writes of the profile, now.
    pub fn init_spi(&mut self) -> Result<()> {
        let now = self.now;
        let r = self.link.init_from_profile(&self.spi_profile, now);
        self.sync();
        r
    }

    /// Set SCLK (the asked frequency or the nearest below it SPI-A can make from LSPCLK) and/or the
    /// standard SPI mode (SPICCR.CLKPOLARITY, SPICTL.CLK_PHASE), through SPI-A's registers: SPICCR
    /// with SPISWRESET = 0, SPICTL, SPIBRR, then SPICCR with SPISWRESET as it was. Impossible
    /// requests are refused naming the register.
    pub fn configure_spi(&mut self, sclk_hz: Option<f64>, mode: Option<u8>) -> Result<SpiSetting> {
        let spiccr = self.read(SPIA_BASE + u32::from(spi::SPICCR))?;
        let spictl = self.read(SPIA_BASE + u32::from(spi::SPICTL))?;
        let mut spibrr = self.read(SPIA_BASE + u32::from(spi::SPIBRR))?;
        let lspclk = self.link.spi().lspclk();
        if let Some(f) = sclk_hz {
            spibrr = self.spibrr_for(f, lspclk)?;
        }
        let (mut ccr, mut ctl) = (spiccr, spictl);
        if let Some(m) = mode {
            let (pol, phase) = match m {
                0 => (false, true),
                1 => (false, false),
                2 => (true, true),
                3 => (true, false),
                _ => {
                    return Err(Error::Config(format!(
                        "SPI mode {m}: expected 0…3 (it sets SPICCR.CLKPOLARITY and SPICTL.CLK_PHASE)"
                    )))
                }
            };
            ccr = (ccr & !spi::SPICCR_CLKPOLARITY) | if pol { spi::SPICCR_CLKPOLARITY } else { 0 };
            ctl = (ctl & !spi::SPICTL_CLK_PHASE) | if phase { spi::SPICTL_CLK_PHASE } else { 0 };
        }
        let base = SPIA_BASE;
        self.write(base + u32::from(spi::SPICCR), ccr & !spi::SPICCR_SPISWRESET)?;
        self.write(base + u32::from(spi::SPICTL), ctl)?;
        self.write(base + u32::from(spi::SPIBRR), spibrr)?;
        self.write(base + u32::from(spi::SPICCR), ccr)?;
        let divisor = spi::baud_divisor(spibrr);
        let achieved = lspclk.hz() / f64::from(divisor);
        let scheme = self.link.spi().scheme();
        Ok(SpiSetting {
            spibrr,
            sclk_hz: achieved,
            exact: sclk_hz.is_none_or(|f| lspclk.hz() == f * f64::from(divisor)),
            mode: scheme.standard_mode(),
            lspclk_hz: lspclk.hz(),
        })
    }

    /// The SPIBRR for SCLK `f` at `lspclk`: the smallest divisor whose SCLK is not above `f`.
    fn spibrr_for(&self, f: f64, lspclk: Clock) -> Result<u16> {
        if !(f.is_finite() && f > 0.0) {
            return Err(Error::Config(format!("SCLK {f} Hz: expected a positive frequency")));
        }
        let l = lspclk.hz();
        // LSPCLK/(SPIBRR+1) ≤ f, with SPIBRR = 3…127 (0…2 give LSPCLK/4 too).
        match (4u32..=128).find(|&d| l <= f * f64::from(d)) {
            Some(d) => Ok((d - 1) as u16),
            None => Err(Error::Config(format!(
                "SCLK {f} Hz: SPIBRR would have to be {} at LSPCLK {l} Hz, but SPIBRR is 3…127 (SCLK {}…{} Hz); \
                 raise LOSPCP (now {}) to lower LSPCLK",
                (l / f).ceil() - 1.0,
                l / 128.0,
                l / 4.0,
                self.sys.lospcp()
            ))),
        }
    }

    /// One frame as a polling driver does it (an Arduino-style `transfer16`): wait `stall` (the
    /// ADIS16407 wants ≥ 9 µs between normal frames, one SCLK period inside a burst), wait until
    /// BUFFULL_FLAG reads 0, write SPITXBUF, wait for INT_FLAG, read SPIRXBUF, and return no sooner
    /// than tSFS after the frame's last SCLK edge, so that the caller may raise CS at once. In the
    /// schemes without delay (modes 1 and 3) INT_FLAG comes half an SCLK period after the last edge;
    /// with delay (modes 0 and 2) it comes at the last edge, and returning then would break tSFS.
    /// A word left in SPIRXBUF by earlier register traffic is read (discarded) first, so that
    /// INT_FLAG belongs to this frame.
    pub fn transfer(&mut self, din: u16, stall: Ps) -> Result<u16> {
        let r = self.transfer_unsynced(din, stall);
        self.sync();
        r
    }

    fn transfer_unsynced(&mut self, din: u16, stall: Ps) -> Result<u16> {
        let (sts, rxbuf, txbuf) = (spi::SPISTS, spi::SPIRXBUF, spi::SPITXBUF);
        self.now += stall;
        self.link.advance(self.now)?;
        let t = self
            .link
            .buffull_clear_time()
            .ok_or_else(|| Error::Config("SPITXBUF stays full: SPI-A is held in reset (SPICCR bit 7 = 0)".into()))?;
        self.now = self.now.max(t);
        if self.link.read(sts, self.now)? & spi::SPISTS_INT_FLAG != 0 {
            self.link.read(rxbuf, self.now)?;
        }
        self.link.write(txbuf, din, self.now)?;
        let flag = self.link.int_flag_time().ok_or_else(|| {
            Error::Config(
                "SPI-A started no character after the SPITXBUF write: is it released from reset (SPICCR bit 7), \
                 master (SPICTL bit 2), in normal (non-FIFO) mode?"
                    .into(),
            )
        })?;
        self.now = self.now.max(flag);
        let rx = self.link.read(rxbuf, self.now)?;
        self.sync();
        if let Some(le) = self.recent.last().map(|f| f.timing.last_edge) {
            self.now = self.now.max(le + self.t_sfs);
            self.link.advance(self.now)?;
        }
        Ok(rx)
    }

    /// What the ADIS16xxx parts see from now on (held constant).
    pub fn set_physical(&mut self, p: Physical) -> Result<()> {
        if !p.is_finite() {
            return Err(Error::Input("set_physical: every value must be finite".into()));
        }
        let now = self.now;
        self.link.advance(now)?;
        for dev in self.link.slave_mut().adis_parts() {
            dev.set_stimulus(Box::new(Constant(p)));
        }
        self.sync();
        Ok(())
    }

    /// An ADIS16407 register's current contents (no SPI traffic), by its even address.
    pub fn peek_device(&self, addr: i64) -> Result<u16> {
        let a = u8::try_from(addr).ok().filter(|a| *a <= 0x7F).ok_or_else(|| {
            Error::Register(format!("ADIS16407 register address {addr} ({}): expected 0…0x7F", hex(addr)))
        })?;
        let sensor = self.link.slave().sensor().ok_or_else(|| {
            Error::Register(format!(
                "peek_device: the part on GPIO57 is not an ADIS16xxx part ({})",
                self.link.slave().part_name(CS_GPIO as u8).unwrap_or("none")
            ))
        })?;
        sensor.peek(a)
    }

    /// Keep the transaction log for [`HostBoard::take_log`] from now on (`on`), or stop keeping it
    /// (what was kept stays until taken). A board reading a trace starts without it: a firmware run
    /// that wants its bus log switches it on.
    pub fn set_keep_log(&mut self, on: bool) {
        self.sync();
        self.keep_log = on;
    }

    /// The transaction log (frames and CS edges) since the last call, in time order.
    pub fn take_log(&mut self) -> Vec<LinkRecord> {
        self.sync();
        std::mem::take(&mut self.log)
    }

    /// SPI-A's, the link's and the device's events since the last call, in time order, each with
    /// its frame. Events inside a character still shifting wait until it ends.
    pub fn take_events(&mut self) -> Vec<HostEvent> {
        self.sync();
        self.pending.sort_by_key(|e| e.t_ps);
        let shifting = self.link.spi().current_frame().map(|f| f.start_ps).filter(|&s| s <= self.now);
        let split = self.pending.partition_point(|e| shifting.is_none_or(|s| e.t_ps < s));
        let ready: Vec<Event> = self.pending.drain(..split).collect();
        let out = ready.into_iter().map(|e| HostEvent { frame: self.frame_of(&e), event: e }).collect();
        if self.pending.is_empty() {
            let keep = self.recent.len().saturating_sub(1);
            self.recent.drain(..keep);
        }
        out
    }

    /// The frame an event is tied to: the one it names, else the last one on the wires at its time,
    /// else (a CS edge) the last one before it. `recent` is in the order the frames completed (one
    /// shift register: their indices, starts and ends all increase), so each is a binary search: a
    /// firmware whose every frame raises an event ties them in n log n, not n² (issue 37, item 4).
    fn frame_of(&self, e: &Event) -> Option<FrameRef> {
        let t = e.t_ps;
        let recent = &self.recent;
        let r = |f: &FrameRecord| FrameRef { index: f.index, din: f.din };
        if let Some(f) = e.frame.and_then(|i| recent.binary_search_by_key(&i, |f| f.index).ok().map(|k| &recent[k])) {
            return Some(r(f));
        }
        // The last frame started at or before t; an earlier one ended before it did, so before t too.
        let started = recent.partition_point(|f| f.start_ps <= t);
        if let Some(f) = started.checked_sub(1).map(|k| &recent[k]).filter(|f| t <= f.end_ps) {
            return Some(r(f));
        }
        if matches!(e.kind, "cs_hold" | "burst_truncated") {
            let ended = recent.partition_point(|f| f.end_ps <= t);
            return ended.checked_sub(1).map(|k| r(&recent[k]));
        }
        None
    }

    /// Move what the link logged and the events raised into this board's own lists. It runs after
    /// every register access and every step of time, so it touches nothing that is empty: the link's
    /// log is drained in place (its buffer kept, not reallocated for each frame) and an empty list of
    /// events is not appended.
    fn sync(&mut self) {
        self.spi_interrupts();
        self.link.flush_ste(self.now);
        if let Some(log) = self.link.log_mut().filter(|l| !l.is_empty()) {
            for r in log.drain(..) {
                if let LinkRecord::Frame(f) = r {
                    self.recent.push(f);
                }
                if self.keep_log {
                    self.log.push(r);
                }
            }
        }
        append(&mut self.pending, self.link.drain_events());
        append(&mut self.pending, self.link.slave_mut().drain_events());
        append(&mut self.pending, self.serial.drain(&mut self.irq));
        self.mcbsp.drain(&mut self.irq);
        if self.pending.is_empty() && self.recent.len() > 64 {
            let keep = self.recent.len() - 1;
            self.recent.drain(..keep);
        }
    }
}

/// Append `more` to `to` (nothing to do, no call, when it is empty: the common case, on every access).
#[inline(always)]
fn append(to: &mut Vec<Event>, mut more: Vec<Event>) {
    if !more.is_empty() {
        to.append(&mut more);
    }
}

/// Whether `a` is one of SPI-A's registers ([`REGISTERS`]: SPICCR…SPISTS, SPIBRR, SPIRXEMU…SPIFFCT,
/// SPIPRI): a match on the offset, not a search of the register table, as it runs on every access.
fn is_spi(a: u32) -> bool {
    matches!(a.wrapping_sub(SPIA_BASE), 0..=2 | 4 | 6..=0xC | 0xF)
}

/// Whether reading `a` changes nothing on the board (the link is at the board's time already: a
/// read of an SPI-A register but SPIRXBUF only looks): SPI-A's registers but SPIRXBUF, the GPIO
/// data and control registers, the system control registers.
fn reads_without_effect(a: u32) -> bool {
    (is_spi(a) && a != SPIA_BASE + u32::from(spi::SPIRXBUF)) || is_gpio(a) || Gpio::owns_ctrl(a) || SysCtrl::owns(a)
}

fn is_gpio(a: u32) -> bool {
    (GPIO_DATA_BASE..GPIO_DATA_BASE + 24).contains(&a)
}

fn hex(v: i64) -> String {
    if v < 0 {
        format!("-0x{:X}", v.unsigned_abs())
    } else {
        format!("0x{v:X}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_spi_is_the_register_tables_spi_a() {
        for a in 0..0x1_0000u32 {
            let by_table = (SPIA_BASE..SPIA_BASE + 16).contains(&a) && register_name(a).is_some();
            assert_eq!(is_spi(a), by_table, "0x{a:04X}");
        }
    }
}
