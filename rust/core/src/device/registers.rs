//! The ADIS16407 register map as one table: address, valid bits, format, access and power-on value.
//! Registers are 16 bits at even addresses; a write is one byte to the low (even) or high (odd)
//! address. Bits outside a register's mask read as 0 and ignore writes.

use super::encoding::Channel;
use crate::profile::Device;

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
}

/// One register of the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RegisterDef {
    /// Data-sheet name.
    pub name: &'static str,
    /// Low-byte (even) address.
    pub addr: u8,
    /// Bits that exist (for outputs: the data field; ND/EA are added on read).
    pub mask: u16,
    /// How the bits are read.
    pub format: Format,
    /// SPI access.
    pub access: Access,
    /// Power-on value.
    pub power_on: PowerOn,
}

impl RegisterDef {
    /// The power-on value of this register for a device profile.
    pub fn power_on_value(&self, cfg: &Device) -> u16 {
        let v = match self.power_on {
            PowerOn::Fixed(v) => v,
            // The profile validates these to 16 bits.
            PowerOn::ProdId => cfg.prod_id as u16,
            PowerOn::SmplPrd => cfg.smpl_prd as u16,
            PowerOn::SensAvg => cfg.sens_avg as u16,
            PowerOn::MscCtrl => cfg.msc_ctrl as u16,
        };
        v & self.mask
    }

    /// Slot of this register in a register array ([`slot`]).
    pub fn slot(&self) -> usize {
        usize::from(self.addr >> 1)
    }
}

/// Register addresses (low byte).
pub mod addr {
    #![allow(missing_docs)]
    pub const FLASH_CNT: u8 = 0x00;
    pub const SUPPLY_OUT: u8 = 0x02;
    pub const XGYRO_OUT: u8 = 0x04;
    pub const YGYRO_OUT: u8 = 0x06;
    pub const ZGYRO_OUT: u8 = 0x08;
    pub const XACCL_OUT: u8 = 0x0A;
    pub const YACCL_OUT: u8 = 0x0C;
    pub const ZACCL_OUT: u8 = 0x0E;
    pub const XMAGN_OUT: u8 = 0x10;
    pub const YMAGN_OUT: u8 = 0x12;
    pub const ZMAGN_OUT: u8 = 0x14;
    pub const BARO_OUT: u8 = 0x16;
    pub const BARO_OUTL: u8 = 0x18;
    pub const TEMP_OUT: u8 = 0x1A;
    pub const AUX_ADC: u8 = 0x1C;
    pub const XGYRO_OFF: u8 = 0x1E;
    pub const YGYRO_OFF: u8 = 0x20;
    pub const ZGYRO_OFF: u8 = 0x22;
    pub const XACCL_OFF: u8 = 0x24;
    pub const YACCL_OFF: u8 = 0x26;
    pub const ZACCL_OFF: u8 = 0x28;
    pub const XMAGN_HIC: u8 = 0x2A;
    pub const YMAGN_HIC: u8 = 0x2C;
    pub const ZMAGN_HIC: u8 = 0x2E;
    pub const XMAGN_SIC: u8 = 0x30;
    pub const YMAGN_SIC: u8 = 0x32;
    pub const ZMAGN_SIC: u8 = 0x34;
    pub const GPIO_CTRL: u8 = 0x36;
    pub const MSC_CTRL: u8 = 0x38;
    pub const SMPL_PRD: u8 = 0x3A;
    pub const SENS_AVG: u8 = 0x3C;
    pub const SLP_CNT: u8 = 0x3E;
    pub const DIAG_STAT: u8 = 0x40;
    pub const GLOB_CMD: u8 = 0x42;
    pub const ALM_MAG1: u8 = 0x44;
    pub const ALM_MAG2: u8 = 0x46;
    pub const ALM_SMPL1: u8 = 0x48;
    pub const ALM_SMPL2: u8 = 0x4A;
    pub const ALM_CTRL: u8 = 0x4C;
    pub const AUX_DAC: u8 = 0x4E;
    pub const PROD_ID: u8 = 0x56;
}

/// Number of register slots (even addresses 0x00…0x56).
pub const SLOTS: usize = 0x58 / 2;

/// The output registers in burst order (address order 0x02…0x1C).
pub const BURST_ORDER: [u8; 14] = [
    addr::SUPPLY_OUT,
    addr::XGYRO_OUT,
    addr::YGYRO_OUT,
    addr::ZGYRO_OUT,
    addr::XACCL_OUT,
    addr::YACCL_OUT,
    addr::ZACCL_OUT,
    addr::XMAGN_OUT,
    addr::YMAGN_OUT,
    addr::ZMAGN_OUT,
    addr::BARO_OUT,
    addr::BARO_OUTL,
    addr::TEMP_OUT,
    addr::AUX_ADC,
];

const fn out(name: &'static str, addr: u8, ch: Channel, mask: u16) -> RegisterDef {
    RegisterDef { name, addr, mask, format: Format::Output(ch), access: Access::R, power_on: PowerOn::Fixed(0) }
}

const fn ctl(
    name: &'static str,
    addr: u8,
    mask: u16,
    format: Format,
    access: Access,
    power_on: PowerOn,
) -> RegisterDef {
    RegisterDef { name, addr, mask, format, access, power_on }
}

use Access::{R, RW, W};
use Format::{Bits, TwosComplement as Tc, Unsigned as U};
use PowerOn::Fixed;

/// The register map (ADIS16407 data sheet and ADI's iSensor register map; bit masks of control
/// registers from the fields the spec names; the unnamed bits of GPIO_CTRL, ALM_* follow ADIS16405).
pub const REGISTERS: [RegisterDef; 41] = [
    ctl("FLASH_CNT", addr::FLASH_CNT, 0xFFFF, U, R, Fixed(0)),
    out("SUPPLY_OUT", addr::SUPPLY_OUT, Channel::Supply, 0x0FFF),
    out("XGYRO_OUT", addr::XGYRO_OUT, Channel::Gyro, 0x3FFF),
    out("YGYRO_OUT", addr::YGYRO_OUT, Channel::Gyro, 0x3FFF),
    out("ZGYRO_OUT", addr::ZGYRO_OUT, Channel::Gyro, 0x3FFF),
    out("XACCL_OUT", addr::XACCL_OUT, Channel::Accel, 0x3FFF),
    out("YACCL_OUT", addr::YACCL_OUT, Channel::Accel, 0x3FFF),
    out("ZACCL_OUT", addr::ZACCL_OUT, Channel::Accel, 0x3FFF),
    out("XMAGN_OUT", addr::XMAGN_OUT, Channel::Mag, 0x3FFF),
    out("YMAGN_OUT", addr::YMAGN_OUT, Channel::Mag, 0x3FFF),
    out("ZMAGN_OUT", addr::ZMAGN_OUT, Channel::Mag, 0x3FFF),
    out("BARO_OUT", addr::BARO_OUT, Channel::Baro, 0x3FFF),
    out("BARO_OUTL", addr::BARO_OUTL, Channel::BaroLow, 0x00FF),
    out("TEMP_OUT", addr::TEMP_OUT, Channel::Temp, 0x0FFF),
    out("AUX_ADC", addr::AUX_ADC, Channel::Aux, 0x0FFF),
    ctl("XGYRO_OFF", addr::XGYRO_OFF, 0x1FFF, Tc, RW, Fixed(0)),
    ctl("YGYRO_OFF", addr::YGYRO_OFF, 0x1FFF, Tc, RW, Fixed(0)),
    ctl("ZGYRO_OFF", addr::ZGYRO_OFF, 0x1FFF, Tc, RW, Fixed(0)),
    ctl("XACCL_OFF", addr::XACCL_OFF, 0x0FFF, Tc, RW, Fixed(0)),
    ctl("YACCL_OFF", addr::YACCL_OFF, 0x0FFF, Tc, RW, Fixed(0)),
    ctl("ZACCL_OFF", addr::ZACCL_OFF, 0x0FFF, Tc, RW, Fixed(0)),
    ctl("XMAGN_HIC", addr::XMAGN_HIC, 0x3FFF, Tc, RW, Fixed(0)),
    ctl("YMAGN_HIC", addr::YMAGN_HIC, 0x3FFF, Tc, RW, Fixed(0)),
    ctl("ZMAGN_HIC", addr::ZMAGN_HIC, 0x3FFF, Tc, RW, Fixed(0)),
    ctl("XMAGN_SIC", addr::XMAGN_SIC, 0x0FFF, U, RW, Fixed(0x0800)),
    ctl("YMAGN_SIC", addr::YMAGN_SIC, 0x0FFF, U, RW, Fixed(0x0800)),
    ctl("ZMAGN_SIC", addr::ZMAGN_SIC, 0x0FFF, U, RW, Fixed(0x0800)),
    // [11:8] line levels, [3:0] line directions.
    ctl("GPIO_CTRL", addr::GPIO_CTRL, 0x0F0F, Bits, RW, Fixed(0)),
    // [10] self-test, [7] g-compensation, [6] origin alignment, [2] DR enable, [1] DR polarity, [0] DR line.
    ctl("MSC_CTRL", addr::MSC_CTRL, 0x04C7, Bits, RW, PowerOn::MscCtrl),
    // [7] time base, [6:0] NS.
    ctl("SMPL_PRD", addr::SMPL_PRD, 0x00FF, Bits, RW, PowerOn::SmplPrd),
    // [10:8] range, [2:0] M.
    ctl("SENS_AVG", addr::SENS_AVG, 0x0707, Bits, RW, PowerOn::SensAvg),
    ctl("SLP_CNT", addr::SLP_CNT, 0x00FF, U, RW, Fixed(0)),
    ctl("DIAG_STAT", addr::DIAG_STAT, 0xFFFF, Bits, R, Fixed(0)),
    ctl("GLOB_CMD", addr::GLOB_CMD, 0x00FF, Bits, W, Fixed(0)),
    ctl("ALM_MAG1", addr::ALM_MAG1, 0xFFFF, Bits, RW, Fixed(0)),
    ctl("ALM_MAG2", addr::ALM_MAG2, 0xFFFF, Bits, RW, Fixed(0)),
    ctl("ALM_SMPL1", addr::ALM_SMPL1, 0x00FF, U, RW, Fixed(0)),
    ctl("ALM_SMPL2", addr::ALM_SMPL2, 0x00FF, U, RW, Fixed(0)),
    ctl("ALM_CTRL", addr::ALM_CTRL, 0xFFFF, Bits, RW, Fixed(0)),
    ctl("AUX_DAC", addr::AUX_DAC, 0x0FFF, U, RW, Fixed(0)),
    ctl("PROD_ID", addr::PROD_ID, 0xFFFF, U, R, PowerOn::ProdId),
];

/// Slot → index into [`REGISTERS`] (`NONE` where no register lives), built at compile time.
const INDEX: [u8; SLOTS] = build_index();
const NONE: u8 = u8::MAX;

const fn build_index() -> [u8; SLOTS] {
    let mut index = [NONE; SLOTS];
    let mut i = 0;
    while i < REGISTERS.len() {
        index[(REGISTERS[i].addr >> 1) as usize] = i as u8;
        i += 1;
    }
    index
}

/// Slot of an address in a register array (the 16-bit register holding byte `addr`).
pub fn slot(addr: u8) -> usize {
    usize::from(addr >> 1)
}

/// The register holding byte address `addr` (even: low byte, odd: high byte), if any.
pub fn lookup(addr: u8) -> Option<&'static RegisterDef> {
    let i = *INDEX.get(slot(addr))?;
    REGISTERS.get(usize::from(i))
}

/// The register called `name` (case-insensitive).
pub fn by_name(name: &str) -> Option<&'static RegisterDef> {
    REGISTERS.iter().find(|r| r.name.eq_ignore_ascii_case(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_is_consistent() {
        for (i, r) in REGISTERS.iter().enumerate() {
            assert_eq!(r.addr % 2, 0, "{}", r.name);
            assert_eq!(lookup(r.addr), Some(r));
            assert_eq!(lookup(r.addr + 1), Some(r), "high byte of {}", r.name);
            assert!(REGISTERS[..i].iter().all(|o| o.addr != r.addr && o.name != r.name), "{}", r.name);
            if let Format::Output(ch) = r.format {
                assert_eq!(r.mask, crate::device::encoding::field_mask(ch.bits()), "{}", r.name);
            }
        }
        for a in [0x50u8, 0x52, 0x54, 0x58, 0x7F] {
            assert!(lookup(a).is_none(), "0x{a:02X}");
        }
        let outputs: Vec<u8> =
            REGISTERS.iter().filter(|r| matches!(r.format, Format::Output(_))).map(|r| r.addr).collect();
        assert_eq!(outputs, BURST_ORDER);
    }

    #[test]
    fn power_on_values_from_profile() {
        let cfg = Device::default();
        let v = |n: &str| by_name(n).unwrap().power_on_value(&cfg);
        assert_eq!(v("PROD_ID"), 0x4017);
        assert_eq!(v("smpl_prd"), 0x0001);
        assert_eq!(v("SENS_AVG"), 0x0402);
        assert_eq!(v("MSC_CTRL"), 0x0006);
        assert_eq!(v("XMAGN_SIC"), 0x0800);
        assert_eq!(v("XGYRO_OFF"), 0);
    }
}
