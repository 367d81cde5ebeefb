//! A part of the ADIS16xxx family as data: what one part declares and the family protocol
//! (`adis.rs`, `slave.rs`) reads. The split follows ArduPilot's `SIM_ADIS.h` (the family) /
//! `SIM_ADIS16470.h` (one part) and Renode's declarative register fields.
//!
//! A part declares its register map (name, address, access, reset value, bit fields, and the role
//! the family protocol gives the register), its burst command and word list, its accelerometer
//! scale and rated range, its start-up and reset times, its SCLK limits and its error-model preset.
//! Everything else — 16-bit frames, a read answering in the next frame, byte writes, the burst read,
//! the sample clock, the Bartlett filter, ND/EA, GLOB_CMD, the timing rules — is the family's.
//! A sibling part is one file in `parts/` and one line in `parts::PARTS`.

use super::encoding::Channel;
use super::spi_timing::SpiTiming;

/// Who may access a register over SPI.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Access {
    /// Read only: writes are ignored (and reported).
    R,
    /// Write only (GLOB_CMD): a command register.
    W,
    /// Read and write.
    RW,
}

/// How a register's bits are read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    /// A sample output: ND (15), EA (14) and the channel's field.
    Output(Channel),
    /// Unsigned integer in the masked bits.
    Unsigned,
    /// Two's complement in the masked bits.
    TwosComplement,
    /// Independent control or status bits.
    Bits,
}

/// Where a register's power-on value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PowerOn {
    /// A fixed value.
    Fixed(u16),
    /// `Device::prod_id`.
    ProdId,
    /// `Device::smpl_prd`.
    SmplPrd,
    /// `Device::sens_avg`.
    SensAvg,
    /// `Device::msc_ctrl`.
    MscCtrl,
    /// `Device::lot_id1` (unit-specific).
    LotId1,
    /// `Device::lot_id2` (unit-specific).
    LotId2,
    /// `Device::serial_num` (unit-specific).
    SerialNum,
}

/// What the family protocol does with a register (beyond storing it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// Storage only.
    Plain,
    /// A sample output of `channel`; `axis` 0…2 for the triads (0 otherwise).
    Output(Channel, u8),
    /// X/Y/ZGYRO_OFF (axis): 13-bit two's complement, 0.0125 °/s.
    GyroOffset(u8),
    /// X/Y/ZACCL_OFF (axis): 12-bit two's complement, the part's accelerometer LSB.
    AccelOffset(u8),
    /// X/Y/ZMAGN_HIC (axis): hard iron.
    MagHardIron(u8),
    /// X/Y/ZMAGN_SIC (axis): soft iron.
    MagSoftIron(u8),
    /// FLASH_CNT: counts flash updates.
    FlashCount,
    /// MSC_CTRL: data ready, self-test.
    MscCtrl,
    /// SMPL_PRD: the sample clock.
    SmplPrd,
    /// SENS_AVG: range and filter.
    SensAvg,
    /// SLP_CNT: sleep.
    SlpCnt,
    /// DIAG_STAT: error flags.
    DiagStat,
    /// GLOB_CMD: commands.
    GlobCmd,
}

/// One named bit field of a register.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Field {
    /// Data-sheet name.
    pub name: &'static str,
    /// Lowest bit.
    pub lsb: u8,
    /// Width in bits.
    pub width: u8,
}

impl Field {
    /// The field's bits as a mask.
    pub const fn mask(&self) -> u16 {
        (((1u32 << self.width) - 1) << self.lsb) as u16
    }
}

/// A field, for the declarations.
pub const fn f(name: &'static str, lsb: u8, width: u8) -> Field {
    Field { name, lsb, width }
}

/// One register of a part's map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegisterDef {
    /// Data-sheet name.
    pub name: &'static str,
    /// Low-byte (even) address.
    pub addr: u8,
    /// SPI access.
    pub access: Access,
    /// Power-on value.
    pub power_on: PowerOn,
    /// The bit fields (for outputs: the data field; ND/EA are added on read).
    pub fields: &'static [Field],
    /// Bits that exist: the union of the fields (bits outside read as 0 and ignore writes).
    pub mask: u16,
    /// How the bits are read.
    pub format: Format,
    /// What the family protocol does with it.
    pub role: Role,
}

const fn mask_of(fields: &[Field]) -> u16 {
    let (mut m, mut i) = (0u16, 0);
    while i < fields.len() {
        m |= fields[i].mask();
        i += 1;
    }
    m
}

/// A register, for the declarations (its mask from its fields).
pub const fn reg(
    name: &'static str,
    addr: u8,
    access: Access,
    power_on: PowerOn,
    format: Format,
    role: Role,
    fields: &'static [Field],
) -> RegisterDef {
    RegisterDef { name, addr, access, power_on, fields, mask: mask_of(fields), format, role }
}

/// An output register of `channel` (axis `axis`): read only, power-on 0, one data field.
pub const fn out(name: &'static str, addr: u8, channel: Channel, axis: u8, data: &'static [Field]) -> RegisterDef {
    reg(name, addr, Access::R, PowerOn::Fixed(0), Format::Output(channel), Role::Output(channel, axis), data)
}

impl RegisterDef {
    /// Slot of this register in a register array ([`slot`]).
    pub fn slot(&self) -> usize {
        slot(self.addr)
    }

    /// The field called `name` (case-insensitive).
    pub fn field(&self, name: &str) -> Option<&'static Field> {
        self.fields.iter().find(|f| f.name.eq_ignore_ascii_case(name))
    }
}

/// Number of register slots: every even address a 7-bit address can name.
pub const SLOTS: usize = 64;

/// Most data words a burst carries (the frames after its command).
pub const MAX_BURST_WORDS: usize = 15;

/// Slot of an address in a register array (the 16-bit register holding byte `addr`).
pub fn slot(addr: u8) -> usize {
    usize::from(addr >> 1) & (SLOTS - 1)
}

/// The family's SPI facts (ADIS16407 data sheet; the sibling ADIS16405 timing table, [unconfirmed]
/// for each part: see `adis16407.md`, `adis16362.md`). The timing values a part may differ in are
/// fields of [`Part`].
pub mod family {
    /// SPI mode (CPOL = 1, CPHA = 1).
    pub const SPI_MODE: u8 = 3;
    /// Frame length, bits.
    pub const FRAME_BITS: u8 = 16;
    /// The part runs in its slow (low-power) sample mode with this SMPL_PRD: the 18.921 ms time base
    /// (bit 7) or NS = SMPL_PRD[6:0] ≥ 0x0A (`adis16362.md`: Linux `adis16400_set_freq`, flag
    /// `ADIS16400_HAS_SLOW_MODE`); tSTALL is then the longer [`super::Part::t_stall_slow_us`].
    pub const fn slow_mode(smpl_prd: u16) -> bool {
        smpl_prd & 0x80 != 0 || smpl_prd & 0x7F >= 0x0A
    }
    /// tCS, ns.
    pub const T_CS_NS: f64 = 48.8;
    /// tSFS, ns.
    pub const T_SFS_NS: f64 = 48.8;
    /// tSTALL, µs: the sibling ADIS16405's timing table, which the ADIS16407 and the ADIS16362 take
    /// [unconfirmed for each: `adis16407.md`].
    pub const T_STALL_US: f64 = 9.0;
    /// tSTALL in the slow sample modes, µs (the ADIS16405's table, as [`T_STALL_US`]).
    pub const T_STALL_SLOW_US: f64 = 75.0;
    /// tDATARATE, µs (the ADIS16405's table, as [`T_STALL_US`]).
    pub const T_DATARATE_US: f64 = 40.0;
    /// SCLK limit in normal mode, Hz (Linux `ADIS16400_HAS_SLOW_MODE`: 2 MHz fast mode).
    pub const SCLK_MAX_HZ: f64 = 2.0e6;
    /// SCLK limit during a burst read, Hz (Linux: 1 MHz in a burst).
    pub const SCLK_BURST_MAX_HZ: f64 = 1.0e6;

    /// A part's SPI timing: the family's mode, 16-bit frames, tCS and tSFS (no CS-high minimum is
    /// given), the part's normal-mode SCLK limit; the rules allow 1 ps for the bus's flooring of
    /// times to whole picoseconds. A part's burst limit is [`super::Part::sclk_burst_max_hz`].
    pub const fn spi(sclk_max_hz: f64) -> super::SpiTiming {
        super::SpiTiming {
            sclk_max_hz,
            cs_setup_ps: T_CS_NS * 1e3,
            cs_hold_ps: Some(T_SFS_NS * 1e3),
            cs_high_min_ps: None,
            modes: &[SPI_MODE],
            frame_bits: Some(FRAME_BITS),
            char_bits: &[FRAME_BITS],
            slack_ps: 1.0,
        }
    }
}

/// One part of the family: everything that differs from its siblings.
#[derive(Debug)]
pub struct Part {
    /// Part name as the profile's `device.part` gives it.
    pub name: &'static str,
    /// PROD_ID.
    pub prod_id: u16,
    /// The register map, in address order.
    pub registers: &'static [RegisterDef],
    /// The burst-read command word.
    pub burst_command: u16,
    /// The registers a burst shifts out after its command frame, in order.
    pub burst: &'static [u8],
    /// Accelerometer output LSB, g.
    pub accel_lsb_g: f64,
    /// Accelerometer rated range, ± g.
    pub accel_rated_g: f64,
    /// Power-on start-up time, ms.
    pub startup_ms: f64,
    /// Software-reset time, ms.
    pub reset_ms: f64,
    /// tSTALL: shortest time from the last SCLK edge of a frame to the first of the next, outside a
    /// burst, µs.
    pub t_stall_us: f64,
    /// tSTALL in the slow (low-power) sample mode ([`family::slow_mode`]), µs.
    pub t_stall_slow_us: f64,
    /// tDATARATE: shortest period of frames outside a burst (the data sheet's chip-select period of
    /// one-word reads; measured from a frame's first SCLK edge to the next one's), µs.
    pub t_datarate_us: f64,
    /// The SPI timing (its SCLK limit in normal mode; the family's other figures).
    pub spi: SpiTiming,
    /// SCLK limit during a burst read, Hz.
    pub sclk_burst_max_hz: f64,
    /// Error-model preset of `errors.preset` for this part.
    pub error_preset: &'static str,
}

impl Part {
    /// Frames of one burst read: the command and the data words.
    pub fn burst_frames(&self) -> usize {
        1 + self.burst.len()
    }

    /// The register holding byte address `addr` (even: low byte, odd: high byte), if any.
    pub fn lookup(&self, addr: u8) -> Option<&'static RegisterDef> {
        self.registers.iter().find(|r| r.addr == addr & !1)
    }

    /// The register called `name` (case-insensitive).
    pub fn by_name(&self, name: &str) -> Option<&'static RegisterDef> {
        self.registers.iter().find(|r| r.name.eq_ignore_ascii_case(name))
    }

    /// The register with role `role`.
    pub fn with_role(&self, role: Role) -> Option<&'static RegisterDef> {
        self.registers.iter().find(|r| r.role == role)
    }

    /// Position of `name` in the burst's data words.
    pub fn burst_index(&self, name: &str) -> Option<usize> {
        let a = self.by_name(name)?.addr;
        self.burst.iter().position(|&b| b == a)
    }

    /// "0x00…0x58": the range of the map's register addresses, for messages.
    pub fn address_range(&self) -> String {
        let (lo, hi) = (self.registers.first().map_or(0, |r| r.addr), self.registers.last().map_or(0, |r| r.addr));
        format!("0x{lo:02X}…0x{hi:02X}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every part's declaration keeps the family's rules: even, distinct, ordered addresses below
    /// the slot count; distinct names; fields inside 16 bits and disjoint; outputs' fields the width
    /// of their channel; the burst made of output registers; one register per protocol role.
    #[test]
    fn every_part_declaration_is_consistent() {
        for p in super::super::parts::PARTS {
            for (i, r) in p.registers.iter().enumerate() {
                assert_eq!(r.addr % 2, 0, "{} {}", p.name, r.name);
                assert!(slot(r.addr) < SLOTS && usize::from(r.addr >> 1) < SLOTS, "{} {}", p.name, r.name);
                assert_eq!(p.lookup(r.addr), Some(r));
                assert_eq!(p.lookup(r.addr + 1), Some(r), "high byte of {}", r.name);
                assert!(p.registers[..i].iter().all(|o| o.addr < r.addr && o.name != r.name), "{} {}", p.name, r.name);
                let mut seen = 0u16;
                for fl in r.fields {
                    assert!(u32::from(fl.lsb) + u32::from(fl.width) <= 16 && fl.width > 0, "{}.{}", r.name, fl.name);
                    assert_eq!(seen & fl.mask(), 0, "{}.{} overlaps", r.name, fl.name);
                    seen |= fl.mask();
                }
                if let Format::Output(ch) = r.format {
                    assert_eq!(r.mask, crate::device::encoding::field_mask(ch.bits()), "{}", r.name);
                }
                if r.role != Role::Plain {
                    assert_eq!(p.with_role(r.role), Some(r), "{}: role {:?} twice", p.name, r.role);
                }
            }
            assert!(p.burst.len() <= MAX_BURST_WORDS, "{}", p.name);
            for a in p.burst {
                assert!(matches!(p.lookup(*a).map(|r| r.format), Some(Format::Output(_))), "{} 0x{a:02X}", p.name);
            }
            assert_eq!(p.by_name("PROD_ID").map(|r| r.power_on), Some(PowerOn::ProdId), "{}", p.name);
            for role in [Role::DiagStat, Role::GlobCmd, Role::SmplPrd, Role::SensAvg, Role::MscCtrl] {
                assert!(p.with_role(role).is_some(), "{}: no {role:?}", p.name);
            }
            assert_eq!(super::super::parts::by_name(&p.name.to_lowercase()).map(|x| x.name), Some(p.name));
        }
    }
}
