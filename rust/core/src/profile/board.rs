//! `[[board.devices]]`: which part sits on which link of the board, with its chip select (SPI) or
//! address (I²C). The reference board declares one ADIS16407 on SPI-A, chip select GPIO57.
//!
//! The F28335's links are SPI-A, I2C-A and SCI-A (UART). The device on SPI-A's GPIO57 is the sensor
//! the firmware's ISR reads; any other device is built on its link by `board::links` and reached
//! through `bus::Link`. Places are unique per link (a chip select, an address, a UART's one peer).

use super::sections::bad;
use super::Profile;
use crate::device::parts::spi_needs::{spi_needs, SpiNeeds};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The kind of a link, from its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkKind {
    /// SPI: 16-bit frames under a chip select.
    Spi,
    /// I²C: addressed byte transfers.
    I2c,
    /// UART (the F28335's SCI): asynchronous bytes.
    Uart,
}

/// The board's links by name, and their kind.
pub const LINKS: [(&str, LinkKind); 3] =
    [("spi-a", LinkKind::Spi), ("i2c-a", LinkKind::I2c), ("sci-a", LinkKind::Uart)];

/// The board's composition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Board {
    /// The devices and where each sits.
    pub devices: Vec<BoardDevice>,
    /// I2C-A's clock (`[board.i2c]`; absent: the defaults of [`I2cBus`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub i2c: Option<I2cBus>,
    /// SCI-A's line (`[board.sci]`; absent: the defaults of [`SciPort`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sci: Option<SciPort>,
}

/// I2C-A, the master's SCL phases. The defaults are 100 kHz with equal halves: the HMC6343's bus
/// rate (i2c.md, hmc6343.md); the split of the master's period into low and high is
/// [unconfirmed] (the F28335's ICCL/ICCH setting of a board that uses it is not at hand).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct I2cBus {
    /// SCL low phase, ns.
    pub scl_low_ns: u32,
    /// SCL high phase, ns.
    pub scl_high_ns: u32,
}

impl Default for I2cBus {
    fn default() -> Self {
        I2cBus { scl_low_ns: 5_000, scl_high_ns: 5_000 }
    }
}

/// SCI-A, the UART line: 8 data bits, no parity, 1 stop bit, at `baud`. The default 19 200 is the
/// GPS line of the gyro-free board (gps-nmea.md: 19200 8N1; the stop-bit count is [unconfirmed]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SciPort {
    /// Bits per second.
    pub baud: u32,
}

impl Default for SciPort {
    fn default() -> Self {
        SciPort { baud: 19_200 }
    }
}

/// One device on one link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardDevice {
    /// The part (as `device.part` names it for the sensor on SPI-A).
    pub part: String,
    /// The link it sits on (`spi-a`, `i2c-a`, `sci-a`).
    pub link: String,
    /// SPI: the GPIO the firmware drives as its chip select (`GPIO0`…`GPIO87`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chip_select: Option<String>,
    /// I²C: its 7-bit address.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub address: Option<u8>,
}

/// The chip select the acquisition ISR drives: the sensor's (GPIO57 on the F28335 boards).
pub const SENSOR_CHIP_SELECT: u8 = 57;

/// The highest GPIO number of the F28335 (GPIO0…GPIO87).
const LAST_GPIO: u8 = 87;

impl Default for Board {
    fn default() -> Self {
        Board {
            devices: vec![BoardDevice {
                part: "ADIS16407".into(),
                link: "spi-a".into(),
                chip_select: Some("GPIO57".into()),
                address: None,
            }],
            i2c: None,
            sci: None,
        }
    }
}

impl BoardDevice {
    /// The link's kind (the profile is validated: the link is one of [`LINKS`]).
    pub fn kind(&self) -> Option<LinkKind> {
        LINKS.iter().find(|(n, _)| *n == self.link).map(|&(_, k)| k)
    }

    /// The chip select's GPIO number (`"GPIO58"` → 58).
    pub fn chip_select_gpio(&self) -> Option<u8> {
        let n = self.chip_select.as_deref()?.strip_prefix("GPIO")?;
        n.parse::<u8>().ok().filter(|&g| g <= LAST_GPIO && (n == "0" || !n.starts_with('0')))
    }
}

impl Board {
    /// The device on SPI-A's chip select GPIO57 (the one the firmware's ISR reads), once the profile
    /// is validated.
    pub fn spi_device(&self) -> Option<&BoardDevice> {
        self.devices.iter().find(|d| d.link == "spi-a" && d.chip_select_gpio() == Some(SENSOR_CHIP_SELECT))
    }

    /// What the part on the acquisition chip select needs of SPI-A (its data sheet's character
    /// lengths, modes, SCLK limit), when the part is known.
    pub fn sensor_needs(&self) -> Option<SpiNeeds> {
        spi_needs(&self.spi_device()?.part)
    }

    /// SPI-A's character length against the part on the acquisition chip select: an error naming
    /// `spi.spiccr` and what the part's data sheet expects.
    pub(crate) fn validate_spi(&self, spi: &super::Spi) -> Result<()> {
        let Some(needs) = self.sensor_needs() else { return Ok(()) };
        let bits = (spi.spiccr & 0xF) as u8 + 1;
        if !needs.char_bits.contains(&bits) {
            return Err(bad(
                "spi.spiccr",
                format!("0x{:X} (SPICHAR = {}: {bits}-bit characters)", spi.spiccr, bits - 1),
                &format!("for the {} on GPIO57: {}", needs.part, needs.expects),
            ));
        }
        Ok(())
    }

    /// I2C-A's SCL phases (declared or default).
    pub fn i2c_bus(&self) -> I2cBus {
        self.i2c.unwrap_or_default()
    }

    /// SCI-A's line (declared or default).
    pub fn sci_port(&self) -> SciPort {
        self.sci.unwrap_or_default()
    }

    pub(crate) fn validate(&self, profile: &Profile) -> Result<()> {
        if self.devices.is_empty() {
            return Err(Error::Profile(
                "key `board.devices`: expected at least one device (the reference: part = \"ADIS16407\", \
                 link = \"spi-a\", chip_select = \"GPIO57\")"
                    .into(),
            ));
        }
        let mut taken: Vec<(&str, String)> = Vec::new();
        for (i, d) in self.devices.iter().enumerate() {
            let key = |field: &str| format!("board.devices[{i}].{field}");
            let names = LINKS.map(|(n, _)| format!("\"{n}\"")).join(", ");
            let Some(kind) = d.kind() else {
                return Err(bad(&key("link"), format!("\"{}\"", d.link), &format!("one of {names}")));
            };
            if d.part.trim().is_empty() {
                return Err(bad(&key("part"), "\"\"", "a part name"));
            }
            let place = match kind {
                LinkKind::Spi => {
                    if let Some(a) = d.address {
                        return Err(bad(&key("address"), a, "no address on an SPI link (a chip select)"));
                    }
                    let cs = d.chip_select.as_deref().unwrap_or("");
                    let Some(gpio) = d.chip_select_gpio() else {
                        return Err(bad(&key("chip_select"), format!("\"{cs}\""), "\"GPIO0\" … \"GPIO87\""));
                    };
                    // The ADIS16xxx part the ISR reads is configured by `[device]`; another
                    // family's part there is read by its own application (`firmware.application`).
                    let adis = crate::device::parts::by_name(&d.part).is_some();
                    let reads_adis = profile.firmware.application == "adis-burst";
                    if gpio == SENSOR_CHIP_SELECT && (adis || reads_adis) && d.part != profile.device.part {
                        return Err(bad(
                            &key("part"),
                            format!("\"{}\"", d.part),
                            &format!(
                                "the part `device.part` configures (\"{}\"): the ISR reads the device on GPIO57",
                                profile.device.part
                            ),
                        ));
                    }
                    (key("chip_select"), format!("GPIO{gpio}"))
                }
                LinkKind::I2c => {
                    if let Some(cs) = &d.chip_select {
                        return Err(bad(
                            &key("chip_select"),
                            format!("\"{cs}\""),
                            "no chip select on I²C (an address)",
                        ));
                    }
                    // 0x00-0x07 and 0x78-0x7F are reserved [UM10204, unconfirmed here].
                    match d.address {
                        Some(a @ 0x08..=0x77) => (key("address"), format!("0x{a:02X}")),
                        Some(a) => return Err(bad(&key("address"), a, "a 7-bit address 0x08…0x77")),
                        None => return Err(bad(&key("address"), "(missing)", "a 7-bit address 0x08…0x77")),
                    }
                }
                LinkKind::Uart => {
                    if d.chip_select.is_some() || d.address.is_some() {
                        let field = if d.address.is_some() { "address" } else { "chip_select" };
                        return Err(bad(&key(field), "(given)", "nothing: a UART has one peer"));
                    }
                    (key("link"), "its peer".to_string())
                }
            };
            if taken.iter().any(|(link, p)| *link == d.link && *p == place.1) {
                return Err(bad(
                    &place.0,
                    &place.1,
                    &format!("a place on `{}` no other device of `board.devices` takes", d.link),
                ));
            }
            taken.push((&d.link, place.1));
        }
        if self.spi_device().is_none() {
            return Err(bad(
                "board.devices",
                "no device on spi-a chip select GPIO57",
                &format!(
                    "the sensor the ISR reads (part = \"{}\", link = \"spi-a\", chip_select = \"GPIO57\")",
                    profile.device.part
                ),
            ));
        }
        let i2c = self.i2c_bus();
        let period = u64::from(i2c.scl_low_ns) + u64::from(i2c.scl_high_ns);
        if i2c.scl_low_ns == 0 || i2c.scl_high_ns == 0 || period < 2_500 {
            return Err(bad(
                "board.i2c",
                format!("SCL low {} ns, high {} ns", i2c.scl_low_ns, i2c.scl_high_ns),
                "phases of at least 1 ns and a period of at least 2 500 ns (fast mode: 400 kHz at most, i2c.md)",
            ));
        }
        if !(300..=1_000_000).contains(&self.sci_port().baud) {
            return Err(bad("board.sci.baud", self.sci_port().baud, "300 … 1 000 000 bits per second"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_devices(toml_devices: &str) -> Result<Profile> {
        Profile::from_toml(toml_devices, "test.toml", &[])
    }

    #[test]
    fn the_reference_declaration_is_the_default_and_validates() {
        let p = with_devices("[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\nchip_select = \"GPIO57\"\n")
            .unwrap();
        assert_eq!(p.board, Board::default());
        assert_eq!(p.board.spi_device().unwrap().part, "ADIS16407");
        Profile::from_toml(&Profile::default().to_toml(), "default", &[]).unwrap();
    }

    #[test]
    fn errors_name_the_key() {
        let spi = "[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\nchip_select = \"GPIO57\"\n";
        for (text, key) in [
            ("[board]\ndevices = []\n", "key `board.devices`"),
            (&format!("{spi}{spi}") as &str, "key `board.devices[1].chip_select` = GPIO57"),
            (&format!("{spi}address = 3\n"), "key `board.devices[0].address`"),
            ("[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\n", "key `board.devices[0].chip_select`"),
            ("[[board.devices]]\npart = \"X\"\nlink = \"sci-b\"\n", "key `board.devices[0].link` = \"sci-b\""),
            (
                &format!("{spi}[[board.devices]]\npart = \"X\"\nlink = \"i2c-a\"\naddress = 200\n"),
                "board.devices[1].address",
            ),
            (
                &format!("{spi}[[board.devices]]\npart = \"X\"\nlink = \"spi-a\"\nchip_select = \"GPIO88\"\n"),
                "board.devices[1].chip_select",
            ),
            (
                "[[board.devices]]\npart = \"X\"\nlink = \"spi-a\"\nchip_select = \"GPIO58\"\n",
                "no device on spi-a chip select GPIO57",
            ),
            (&format!("{spi}[board.i2c]\nscl_low_ns = 1000\nscl_high_ns = 1000\n"), "key `board.i2c`"),
            ("[[board.devices]]\npart = \"ADIS16407\"\nlinks = \"spi-a\"\n", "board.devices[0]"),
        ] {
            let e = with_devices(text).unwrap_err().to_string();
            assert!(e.contains(key), "{text}: {e}");
        }
    }
}
