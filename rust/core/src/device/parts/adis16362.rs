//! ADIS16362 (six degrees of freedom, the wing-angle unit's IMU): the declaration. Sources
//! (`adis16362.md`): data sheet Rev. 0 p. 11 (burst read, output registers, scales); Linux
//! `drivers/iio/imu/adis16400.c` (register addresses, PROD_ID, burst command, reset time, bit
//! meanings of MSC_CTRL, SLP_CNT, DIAG_STAT, GLOB_CMD). The rest of the data sheet was not at hand:
//! the reset values of the control registers, the start-up time and the control-register widths
//! taken from the ADIS16407 are [unconfirmed], each a profile key or a field here.

use crate::device::encoding::Channel::{self, Accel, Aux, Gyro, Supply, Temp};
use crate::device::part::Access::{R, RW, W};
use crate::device::part::Format::{Bits, TwosComplement as Tc, Unsigned as U};
use crate::device::part::PowerOn::{self, Fixed};
use crate::device::part::Role::*;
use crate::device::part::{f, family, out, reg, Field, Part, RegisterDef};

const D14: &[Field] = &[f("data", 0, 14)];
const D13: &[Field] = &[f("data", 0, 13)];
const D12: &[Field] = &[f("data", 0, 12)];
const D8: &[Field] = &[f("data", 0, 8)];
const D16: &[Field] = &[f("data", 0, 16)];

const fn out3(name: &'static str, a: u8, ch: Channel, axis: u8) -> RegisterDef {
    out(name, a, ch, axis, if matches!(ch, Supply | Temp | Aux) { D12 } else { D14 })
}

/// The register map (0x18 and 0x26…0x30 are unused on this part).
pub const REGISTERS: [RegisterDef; 35] = [
    reg("FLASH_CNT", 0x00, R, Fixed(0), U, FlashCount, D16),
    out3("SUPPLY_OUT", 0x02, Supply, 0),
    out3("XGYRO_OUT", 0x04, Gyro, 0),
    out3("YGYRO_OUT", 0x06, Gyro, 1),
    out3("ZGYRO_OUT", 0x08, Gyro, 2),
    out3("XACCL_OUT", 0x0A, Accel, 0),
    out3("YACCL_OUT", 0x0C, Accel, 1),
    out3("ZACCL_OUT", 0x0E, Accel, 2),
    out3("XTEMP_OUT", 0x10, Temp, 0),
    out3("YTEMP_OUT", 0x12, Temp, 1),
    out3("ZTEMP_OUT", 0x14, Temp, 2),
    out3("AUX_ADC", 0x16, Aux, 0),
    reg("XGYRO_OFF", 0x1A, RW, Fixed(0), Tc, GyroOffset(0), D13),
    reg("YGYRO_OFF", 0x1C, RW, Fixed(0), Tc, GyroOffset(1), D13),
    reg("ZGYRO_OFF", 0x1E, RW, Fixed(0), Tc, GyroOffset(2), D13),
    reg("XACCL_OFF", 0x20, RW, Fixed(0), Tc, AccelOffset(0), D12),
    reg("YACCL_OFF", 0x22, RW, Fixed(0), Tc, AccelOffset(1), D12),
    reg("ZACCL_OFF", 0x24, RW, Fixed(0), Tc, AccelOffset(2), D12),
    reg("GPIO_CTRL", 0x32, RW, Fixed(0), Bits, Plain, &[f("level", 8, 2), f("direction", 0, 2)]),
    reg(
        "MSC_CTRL",
        0x34,
        RW,
        PowerOn::MscCtrl,
        Bits,
        MscCtrl,
        &[
            f("memory_test", 11, 1),
            f("self_test", 10, 1),
            f("negative_self_test", 9, 1),
            f("positive_self_test", 8, 1),
            f("g_compensation", 7, 1),
            f("origin_alignment", 6, 1),
            f("dr_enable", 2, 1),
            f("dr_polarity", 1, 1),
            f("dr_line", 0, 1),
        ],
    ),
    reg("SMPL_PRD", 0x36, RW, PowerOn::SmplPrd, Bits, SmplPrd, &[f("time_base", 7, 1), f("ns", 0, 7)]),
    reg("SENS_AVG", 0x38, RW, PowerOn::SensAvg, Bits, SensAvg, &[f("range", 8, 3), f("m", 0, 3)]),
    reg("SLP_CNT", 0x3A, RW, Fixed(0), Bits, SlpCnt, &[f("power_down", 8, 1), f("count", 0, 8)]),
    reg("DIAG_STAT", 0x3C, R, Fixed(0), Bits, DiagStat, D16),
    reg("GLOB_CMD", 0x3E, W, Fixed(0), Bits, GlobCmd, D8),
    reg("ALM_MAG1", 0x40, RW, Fixed(0), Bits, Plain, D16),
    reg("ALM_MAG2", 0x42, RW, Fixed(0), Bits, Plain, D16),
    reg("ALM_SMPL1", 0x44, RW, Fixed(0), U, Plain, D8),
    reg("ALM_SMPL2", 0x46, RW, Fixed(0), U, Plain, D8),
    reg("ALM_CTRL", 0x48, RW, Fixed(0), Bits, Plain, D16),
    reg("AUX_DAC", 0x4A, RW, Fixed(0), U, Plain, D12),
    reg("LOT_ID1", 0x52, R, PowerOn::LotId1, U, Plain, D16),
    reg("LOT_ID2", 0x54, R, PowerOn::LotId2, U, Plain, D16),
    reg("PROD_ID", 0x56, R, PowerOn::ProdId, U, Plain, D16),
    reg("SERIAL_NUM", 0x58, R, PowerOn::SerialNum, U, Plain, D16),
];

/// The ADIS16362.
pub const PART: Part = Part {
    name: "ADIS16362",
    prod_id: 0x3FEA,
    registers: &REGISTERS,
    // Data sheet p. 11: a read of GLOB_CMD's address; SUPPLY_OUT … AUX_ADC, 11 words (Linux declares
    // 14, most likely a driver artefact: adis16362.md).
    burst_command: 0x3E00,
    burst: &[0x02, 0x04, 0x06, 0x08, 0x0A, 0x0C, 0x0E, 0x10, 0x12, 0x14, 0x16],
    // Data sheet p. 11 Table 9 (Linux IIO_G_TO_M_S_2(333)).
    accel_lsb_g: 0.333e-3,
    // [unconfirmed]: recollection of Table 1, ±1.7 g.
    accel_rated_g: 1.7,
    // [unconfirmed]: the ADIS16407's 210 ms.
    startup_ms: 210.0,
    // Linux adis16362_timeouts: 130 ms.
    reset_ms: 130.0,
    t_stall_us: family::T_STALL_US,
    t_stall_slow_us: family::T_STALL_SLOW_US,
    t_datarate_us: family::T_DATARATE_US,
    spi: family::spi(family::SCLK_MAX_HZ),
    sclk_burst_max_hz: family::SCLK_BURST_MAX_HZ,
    error_preset: "adis16362",
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_burst_carries_the_eleven_outputs_in_address_order() {
        let names: Vec<&str> = PART.burst.iter().map(|&a| PART.lookup(a).unwrap().name).collect();
        assert_eq!(names.first(), Some(&"SUPPLY_OUT"));
        assert_eq!(names.last(), Some(&"AUX_ADC"));
        assert_eq!(PART.burst_frames(), 12);
        assert_eq!(PART.burst_index("XGYRO_OUT"), Some(1));
        assert_eq!(PART.burst_index("XACCL_OUT"), Some(4));
        assert!(PART.lookup(0x18).is_none() && PART.lookup(0x2A).is_none());
        assert_eq!(PART.by_name("MSC_CTRL").unwrap().mask, 0x0FC7);
    }
}
