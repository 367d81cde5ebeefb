//! ADIS16407 (ten degrees of freedom): the declaration. Sources: data sheet Rev. C p. 1 and 10, ADI's
//! iSensor register map, `adis16407.md`; LOT_ID1/LOT_ID2/SERIAL_NUM at 0x52/0x54/0x58 from the
//! family's register `#define`s in Linux `drivers/iio/imu/adis16400.c` (which drives the 16407);
//! bit masks of GPIO_CTRL and ALM_* follow the ADIS16405.

use crate::device::encoding::Channel::{self, Accel, Aux, Baro, BaroLow, Gyro, Mag, Supply, Temp};
use crate::device::part::Access::{R, RW, W};
use crate::device::part::Format::{Bits, TwosComplement as Tc, Unsigned as U};
use crate::device::part::PowerOn::{self, Fixed};
use crate::device::part::Role::{self, *};
use crate::device::part::{f, family, out, reg, Field, Part, RegisterDef};

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
    pub const LOT_ID1: u8 = 0x52;
    pub const LOT_ID2: u8 = 0x54;
    pub const PROD_ID: u8 = 0x56;
    pub const SERIAL_NUM: u8 = 0x58;
}

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

const D14: &[Field] = &[f("data", 0, 14)];
const D13: &[Field] = &[f("data", 0, 13)];
const D12: &[Field] = &[f("data", 0, 12)];
const D8: &[Field] = &[f("data", 0, 8)];
const D16: &[Field] = &[f("data", 0, 16)];

const fn rw(name: &'static str, a: u8, power_on: PowerOn, role: Role, fields: &'static [Field]) -> RegisterDef {
    let format = if matches!(role, GyroOffset(_) | AccelOffset(_) | MagHardIron(_)) { Tc } else { U };
    reg(name, a, RW, power_on, format, role, fields)
}

const fn out3(name: &'static str, a: u8, ch: Channel, axis: u8) -> RegisterDef {
    out(name, a, ch, axis, if matches!(ch, Supply | Temp | Aux) { D12 } else { D14 })
}

/// The register map.
pub const REGISTERS: [RegisterDef; 44] = [
    reg("FLASH_CNT", addr::FLASH_CNT, R, Fixed(0), U, FlashCount, D16),
    out3("SUPPLY_OUT", addr::SUPPLY_OUT, Supply, 0),
    out3("XGYRO_OUT", addr::XGYRO_OUT, Gyro, 0),
    out3("YGYRO_OUT", addr::YGYRO_OUT, Gyro, 1),
    out3("ZGYRO_OUT", addr::ZGYRO_OUT, Gyro, 2),
    out3("XACCL_OUT", addr::XACCL_OUT, Accel, 0),
    out3("YACCL_OUT", addr::YACCL_OUT, Accel, 1),
    out3("ZACCL_OUT", addr::ZACCL_OUT, Accel, 2),
    out3("XMAGN_OUT", addr::XMAGN_OUT, Mag, 0),
    out3("YMAGN_OUT", addr::YMAGN_OUT, Mag, 1),
    out3("ZMAGN_OUT", addr::ZMAGN_OUT, Mag, 2),
    out3("BARO_OUT", addr::BARO_OUT, Baro, 0),
    out("BARO_OUTL", addr::BARO_OUTL, BaroLow, 0, D8),
    out3("TEMP_OUT", addr::TEMP_OUT, Temp, 0),
    out3("AUX_ADC", addr::AUX_ADC, Aux, 0),
    rw("XGYRO_OFF", addr::XGYRO_OFF, Fixed(0), GyroOffset(0), D13),
    rw("YGYRO_OFF", addr::YGYRO_OFF, Fixed(0), GyroOffset(1), D13),
    rw("ZGYRO_OFF", addr::ZGYRO_OFF, Fixed(0), GyroOffset(2), D13),
    rw("XACCL_OFF", addr::XACCL_OFF, Fixed(0), AccelOffset(0), D12),
    rw("YACCL_OFF", addr::YACCL_OFF, Fixed(0), AccelOffset(1), D12),
    rw("ZACCL_OFF", addr::ZACCL_OFF, Fixed(0), AccelOffset(2), D12),
    rw("XMAGN_HIC", addr::XMAGN_HIC, Fixed(0), MagHardIron(0), D14),
    rw("YMAGN_HIC", addr::YMAGN_HIC, Fixed(0), MagHardIron(1), D14),
    rw("ZMAGN_HIC", addr::ZMAGN_HIC, Fixed(0), MagHardIron(2), D14),
    rw("XMAGN_SIC", addr::XMAGN_SIC, Fixed(0x0800), MagSoftIron(0), D12),
    rw("YMAGN_SIC", addr::YMAGN_SIC, Fixed(0x0800), MagSoftIron(1), D12),
    rw("ZMAGN_SIC", addr::ZMAGN_SIC, Fixed(0x0800), MagSoftIron(2), D12),
    reg("GPIO_CTRL", addr::GPIO_CTRL, RW, Fixed(0), Bits, Plain, &[f("level", 8, 4), f("direction", 0, 4)]),
    reg(
        "MSC_CTRL",
        addr::MSC_CTRL,
        RW,
        PowerOn::MscCtrl,
        Bits,
        MscCtrl,
        &[
            f("self_test", 10, 1),
            f("g_compensation", 7, 1),
            f("origin_alignment", 6, 1),
            f("dr_enable", 2, 1),
            f("dr_polarity", 1, 1),
            f("dr_line", 0, 1),
        ],
    ),
    reg("SMPL_PRD", addr::SMPL_PRD, RW, PowerOn::SmplPrd, Bits, SmplPrd, &[f("time_base", 7, 1), f("ns", 0, 7)]),
    reg("SENS_AVG", addr::SENS_AVG, RW, PowerOn::SensAvg, Bits, SensAvg, &[f("range", 8, 3), f("m", 0, 3)]),
    reg("SLP_CNT", addr::SLP_CNT, RW, Fixed(0), U, SlpCnt, D8),
    reg("DIAG_STAT", addr::DIAG_STAT, R, Fixed(0), Bits, DiagStat, D16),
    reg("GLOB_CMD", addr::GLOB_CMD, W, Fixed(0), Bits, GlobCmd, D8),
    reg("ALM_MAG1", addr::ALM_MAG1, RW, Fixed(0), Bits, Plain, D16),
    reg("ALM_MAG2", addr::ALM_MAG2, RW, Fixed(0), Bits, Plain, D16),
    reg("ALM_SMPL1", addr::ALM_SMPL1, RW, Fixed(0), U, Plain, D8),
    reg("ALM_SMPL2", addr::ALM_SMPL2, RW, Fixed(0), U, Plain, D8),
    reg("ALM_CTRL", addr::ALM_CTRL, RW, Fixed(0), Bits, Plain, D16),
    reg("AUX_DAC", addr::AUX_DAC, RW, Fixed(0), U, Plain, D12),
    reg("LOT_ID1", addr::LOT_ID1, R, PowerOn::LotId1, U, Plain, D16),
    reg("LOT_ID2", addr::LOT_ID2, R, PowerOn::LotId2, U, Plain, D16),
    reg("PROD_ID", addr::PROD_ID, R, PowerOn::ProdId, U, Plain, D16),
    reg("SERIAL_NUM", addr::SERIAL_NUM, R, PowerOn::SerialNum, U, Plain, D16),
];

/// The ADIS16407.
pub const PART: Part = Part {
    name: "ADIS16407",
    prod_id: 0x4017,
    registers: &REGISTERS,
    burst_command: 0x4200,
    burst: &BURST_ORDER,
    accel_lsb_g: 3.333e-3,
    accel_rated_g: 18.0,
    startup_ms: 210.0,
    // [unconfirmed]: siblings 90–170 ms; Linux's ADIS16362 timeouts give 130 ms.
    reset_ms: 130.0,
    t_stall_us: family::T_STALL_US,
    t_stall_slow_us: family::T_STALL_SLOW_US,
    t_datarate_us: family::T_DATARATE_US,
    spi: family::spi(family::SCLK_MAX_HZ),
    sclk_burst_max_hz: family::SCLK_BURST_MAX_HZ,
    error_preset: "adis16407",
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_identity_registers_are_mapped_and_the_gaps_are_not() {
        for (a, name) in [(0x52, "LOT_ID1"), (0x54, "LOT_ID2"), (0x56, "PROD_ID"), (0x58, "SERIAL_NUM")] {
            assert_eq!(PART.lookup(a).map(|r| r.name), Some(name));
        }
        for a in [0x50u8, 0x5A, 0x7E] {
            assert!(PART.lookup(a).is_none(), "0x{a:02X}");
        }
        assert_eq!(PART.by_name("MSC_CTRL").unwrap().mask, 0x04C7);
        assert_eq!(PART.by_name("GPIO_CTRL").unwrap().mask, 0x0F0F);
        assert_eq!(PART.by_name("SENS_AVG").unwrap().field("range").unwrap().mask(), 0x0700);
    }
}
