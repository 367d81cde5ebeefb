//! The F28335 peripherals whose behaviour is not modelled yet (ADC, ePWM, eCAP, eCAN, DMA, XINTF)
//! and the flash controller's wait-state registers: their registers read and write as memory
//! holding their reset values, so that a firmware that initialises them runs; each peripheral's
//! first use is the board's to report once (`unmodelled_peripheral`). The few side effects TI's
//! own initialisation code waits on are kept (eCAN's CANES.CCE following CANMC.CCR), so that it
//! does not poll forever.
//!
//! Frames and EALLOW protection (SPRUFB0 and each peripheral's guide; TI's header-file linker
//! command file for the bases): FlashRegs 0x0A80 (SPRUFB0 "Flash and OTP", EALLOW), AdcMirror
//! 0x0B00 and AdcRegs 0x7100 (SPRU812), XintfRegs 0x0B20 (SPRU949, EALLOW), DmaRegs 0x1000
//! (SPRUFB8, EALLOW), ECanaRegs 0x6000 and ECanbRegs 0x6200 with their LAM, MOTS, MOTO and
//! mailboxes (SPRUEU1), EPwm1…6Regs 0x6800 + 0x40·(n−1) (SPRUG04; the trip-zone registers TZSEL…
//! TZFRC and HRCNFG are EALLOW), ECap1…6Regs 0x6A00 + 0x20·(n−1) (SPRUFG4).
//!
//! Reset values other than 0: ePWM TBCTL 0x0083 (counter frozen, HSPCLKDIV /2; SPRUG04), eCAP
//! ECCTL2 0x0006 (STOP_WRAP = 3; SPRUFG4), XINTF XTIMING0/6/7 0x0043FFFF, XINTCNF2 0x00010D00,
//! XBANK 0x0038 (SPRU949), Flash FBANKWAIT 0x0F0F, FOTPWAIT 0x001F, FSTDBYWAIT and FACTIVEWAIT
//! 0x01FF (SPRUFB0). [unconfirmed: from the guides' register tables, not checked against silicon.]

use std::collections::HashMap;

/// One frame of registers not modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Frame {
    /// The peripheral kind reported once (`ADC`, `ePWM`, …; `Flash` is never reported).
    pub kind: &'static str,
    /// The instance, as its clock enable is named ([`super::sysctrl::clock_bit`]).
    pub instance: &'static str,
    /// TI's register-file name.
    pub regs: &'static str,
    /// First word address and length in words.
    pub base: u32,
    /// Length in words.
    pub len: u32,
    /// TI's reference guide.
    pub guide: &'static str,
}

macro_rules! frame {
    ($kind:expr, $inst:expr, $regs:expr, $base:expr, $len:expr, $guide:expr) => {
        Frame { kind: $kind, instance: $inst, regs: $regs, base: $base, len: $len, guide: $guide }
    };
}

/// Every frame, in address order.
pub const FRAMES: &[Frame] = &[
    frame!("Flash", "Flash", "FlashRegs", 0x0A80, 0x08, "SPRUFB0"),
    frame!("ADC", "ADC", "AdcMirror", 0x0B00, 0x10, "SPRU812"),
    frame!("XINTF", "XINTF", "XintfRegs", 0x0B20, 0x20, "SPRU949"),
    frame!("DMA", "DMA", "DmaRegs", 0x1000, 0x200, "SPRUFB8"),
    frame!("eCAN", "eCAN-A", "ECanaRegs", 0x6000, 0x200, "SPRUEU1"),
    frame!("eCAN", "eCAN-B", "ECanbRegs", 0x6200, 0x200, "SPRUEU1"),
    frame!("ePWM", "ePWM1", "EPwm1Regs", 0x6800, 0x40, "SPRUG04"),
    frame!("ePWM", "ePWM2", "EPwm2Regs", 0x6840, 0x40, "SPRUG04"),
    frame!("ePWM", "ePWM3", "EPwm3Regs", 0x6880, 0x40, "SPRUG04"),
    frame!("ePWM", "ePWM4", "EPwm4Regs", 0x68C0, 0x40, "SPRUG04"),
    frame!("ePWM", "ePWM5", "EPwm5Regs", 0x6900, 0x40, "SPRUG04"),
    frame!("ePWM", "ePWM6", "EPwm6Regs", 0x6940, 0x40, "SPRUG04"),
    frame!("eCAP", "eCAP1", "ECap1Regs", 0x6A00, 0x20, "SPRUFG4"),
    frame!("eCAP", "eCAP2", "ECap2Regs", 0x6A20, 0x20, "SPRUFG4"),
    frame!("eCAP", "eCAP3", "ECap3Regs", 0x6A40, 0x20, "SPRUFG4"),
    frame!("eCAP", "eCAP4", "ECap4Regs", 0x6A60, 0x20, "SPRUFG4"),
    frame!("eCAP", "eCAP5", "ECap5Regs", 0x6A80, 0x20, "SPRUFG4"),
    frame!("eCAP", "eCAP6", "ECap6Regs", 0x6AA0, 0x20, "SPRUFG4"),
    frame!("ADC", "ADC", "AdcRegs", 0x7100, 0x20, "SPRU812"),
];

/// The frame holding `addr`, if any.
pub fn frame_of(addr: u32) -> Option<&'static Frame> {
    // FRAMES is in address order and its frames do not overlap: the last one starting at or below
    // `addr` is the only one that can hold it (a binary search: the board asks on every access).
    let k = FRAMES.partition_point(|f| f.base <= addr);
    k.checked_sub(1).map(|k| &FRAMES[k]).filter(|f| addr < f.base + f.len)
}

/// The reset value of the word at `addr` (see the module's doc).
pub fn reset_value(addr: u32) -> u16 {
    match addr {
        0x0A84 | 0x0A85 => 0x01FF, // FSTDBYWAIT, FACTIVEWAIT
        0x0A86 => 0x0F0F,          // FBANKWAIT
        0x0A87 => 0x001F,          // FOTPWAIT
        0x0B20 | 0x0B2C | 0x0B2E => 0xFFFF,
        0x0B21 | 0x0B2D | 0x0B2F => 0x0043, // XTIMING0/6/7 high words
        0x0B34 => 0x0D00,
        0x0B35 => 0x0001,                                                            // XINTCNF2
        0x0B38 => 0x0038,                                                            // XBANK
        a if (0x6800..0x6980).contains(&a) && (a - 0x6800) % 0x40 == 0 => 0x0083,    // TBCTL
        a if (0x6A00..0x6AC0).contains(&a) && (a - 0x6A00) % 0x20 == 0x15 => 0x0006, // ECCTL2
        _ => 0,
    }
}

/// Whether a write to `addr` needs EALLOW (see the module's doc).
pub fn protected(addr: u32) -> bool {
    match frame_of(addr) {
        Some(f) if matches!(f.kind, "Flash" | "XINTF" | "DMA") => true,
        Some(f) if f.kind == "ePWM" => matches!((addr - f.base) % 0x40, 0x12 | 0x14..=0x18 | 0x20),
        // eCAN's CANMC, CANBTC, CANTIOC, CANRIOC (low and high words).
        Some(f) if f.kind == "eCAN" => matches!(addr - f.base, 0x14..=0x17 | 0x2A..=0x2D),
        _ => false,
    }
}

/// The registers of the frames above, as memory.
#[derive(Debug, Clone, Default)]
pub struct Unmodelled {
    words: HashMap<u32, u16>,
    /// Kinds already reported.
    reported: Vec<&'static str>,
}

impl Unmodelled {
    /// Every register at its reset value.
    pub fn new() -> Unmodelled {
        Unmodelled::default()
    }

    /// Whether `addr` is in one of the frames.
    pub fn owns(addr: u32) -> bool {
        frame_of(addr).is_some()
    }

    /// The frame of `addr` when this is its kind's first use (never for Flash): the board reports it.
    pub fn first_use(&mut self, addr: u32) -> Option<&'static Frame> {
        let f = frame_of(addr).filter(|f| f.kind != "Flash")?;
        if self.reported.contains(&f.kind) {
            return None;
        }
        self.reported.push(f.kind);
        Some(f)
    }

    /// Read the word at `addr`.
    pub fn read(&self, addr: u32) -> u16 {
        self.words.get(&addr).copied().unwrap_or_else(|| reset_value(addr))
    }

    /// Write the word at `addr` (EALLOW is the caller's to check), with its side effects.
    pub fn write(&mut self, addr: u32, value: u16) {
        self.words.insert(addr, value);
        // eCAN: CANES.CCE (bit 4) follows CANMC.CCR (bit 12) (SPRUEU1, "Configuration mode": the
        // module grants a configuration change at once when no transfer is running).
        if let Some(f) = frame_of(addr).filter(|f| f.kind == "eCAN" && addr == f.base + 0x14) {
            let canes = f.base + 0x18;
            let cce = if value & (1 << 12) != 0 { 1 << 4 } else { 0 };
            let v = (self.read(canes) & !(1 << 4)) | cce;
            self.words.insert(canes, v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_in_address_order_and_frame_of_finds_each_word() {
        for w in FRAMES.windows(2) {
            assert!(w[0].base + w[0].len <= w[1].base, "{} overlaps or precedes {}", w[1].regs, w[0].regs);
        }
        for addr in 0..0x8000u32 {
            let linear = FRAMES.iter().find(|f| (f.base..f.base + f.len).contains(&addr));
            assert_eq!(frame_of(addr).map(|f| f.regs), linear.map(|f| f.regs), "0x{addr:04X}");
        }
    }

    #[test]
    fn reset_values_and_frames() {
        let mut u = Unmodelled::new();
        assert_eq!(u.read(0x6800), 0x0083);
        assert_eq!(u.read(0x6840), 0x0083);
        assert_eq!(u.read(0x6A15), 0x0006);
        assert_eq!((u.read(0x0B20), u.read(0x0B21)), (0xFFFF, 0x0043));
        assert_eq!(u.read(0x0A86), 0x0F0F);
        assert_eq!(u.read(0x7100), 0);
        u.write(0x7100, 0x4000);
        assert_eq!(u.read(0x7100), 0x4000);
        assert!(Unmodelled::owns(0x63FF) && !Unmodelled::owns(0x6400) && !Unmodelled::owns(0x7040));
        assert!(protected(0x0A80) && protected(0x6812) && !protected(0x6800) && protected(0x6014));
    }

    #[test]
    fn each_kind_is_reported_once() {
        let mut u = Unmodelled::new();
        assert_eq!(u.first_use(0x6800).map(|f| f.instance), Some("ePWM1"));
        assert_eq!(u.first_use(0x6840), None, "ePWM2 is the same kind");
        assert_eq!(u.first_use(0x7100).map(|f| f.kind), Some("ADC"));
        assert_eq!(u.first_use(0x0B00), None);
        assert_eq!(u.first_use(0x0A80), None, "the flash registers are not reported");
    }

    #[test]
    fn ecan_grants_a_configuration_change() {
        let mut u = Unmodelled::new();
        u.write(0x6014, 1 << 12);
        assert_eq!(u.read(0x6018) & (1 << 4), 1 << 4);
        u.write(0x6014, 0);
        assert_eq!(u.read(0x6018) & (1 << 4), 0);
    }
}
