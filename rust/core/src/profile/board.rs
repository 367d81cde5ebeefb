//! `[[board.devices]]`: which part sits on which link of the board, with its chip select (SPI) or
//! address (I²C). The reference board declares one ADIS16407 on SPI-A, chip select GPIO57.
//!
//! The F28335's links are SPI-A, I2C-A and SCI-A (UART). The emulator runs SPI devices today (one per
//! board: the sensor the firmware's ISR reads); the I²C and UART kinds have their place in the
//! declaration and in `bus` (`bus::i2c`, `bus::uart`), and a declaration using them is refused with
//! the key named until a board that needs them implements them.

use super::sections::bad;
use super::Profile;
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
}

/// One device on one link.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoardDevice {
    /// The part (as `device.part` names it for the sensor on SPI-A).
    pub part: String,
    /// The link it sits on (`spi-a`, `i2c-a`, `sci-a`).
    pub link: String,
    /// SPI: the GPIO the firmware drives as its chip select.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chip_select: Option<String>,
    /// I²C: its 7-bit address.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub address: Option<u8>,
}

impl Default for Board {
    fn default() -> Self {
        Board {
            devices: vec![BoardDevice {
                part: "ADIS16407".into(),
                link: "spi-a".into(),
                chip_select: Some("GPIO57".into()),
                address: None,
            }],
        }
    }
}

impl Board {
    /// The device on SPI-A (the one the firmware's ISR reads), once the profile is validated.
    pub fn spi_device(&self) -> Option<&BoardDevice> {
        self.devices.iter().find(|d| d.link == "spi-a")
    }

    pub(crate) fn validate(&self, profile: &Profile) -> Result<()> {
        if self.devices.is_empty() {
            return Err(Error::Profile(
                "key `board.devices`: expected at least one device (the reference: part = \"ADIS16407\", \
                 link = \"spi-a\", chip_select = \"GPIO57\")"
                    .into(),
            ));
        }
        for (i, d) in self.devices.iter().enumerate() {
            let key = |field: &str| format!("board.devices[{i}].{field}");
            let names = LINKS.map(|(n, _)| format!("\"{n}\"")).join(", ");
            let Some(&(_, kind)) = LINKS.iter().find(|(n, _)| *n == d.link) else {
                return Err(bad(&key("link"), format!("\"{}\"", d.link), &format!("one of {names}")));
            };
            match kind {
                LinkKind::Spi => {
                    if d.address.is_some() {
                        return Err(bad(&key("address"), d.address.unwrap_or(0), "no address on an SPI link"));
                    }
                    let cs = d.chip_select.as_deref().unwrap_or("");
                    if cs != "GPIO57" {
                        return Err(bad(&key("chip_select"), cs, "\"GPIO57\" (the board's wiring)"));
                    }
                    if d.part != profile.device.part {
                        return Err(bad(
                            &key("part"),
                            format!("\"{}\"", d.part),
                            &format!("the part `device.part` configures (\"{}\")", profile.device.part),
                        ));
                    }
                }
                LinkKind::I2c | LinkKind::Uart => {
                    return Err(bad(
                        &key("link"),
                        format!("\"{}\"", d.link),
                        "\"spi-a\": the I²C and UART links are declared but not emulated yet",
                    ));
                }
            }
        }
        if self.devices.len() > 1 {
            return Err(bad(
                "board.devices",
                format!("{} devices", self.devices.len()),
                "one device (the sensor on SPI-A): several devices per board are not emulated yet",
            ));
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
            (&format!("{spi}{spi}") as &str, "key `board.devices` = 2 devices"),
            (&format!("{spi}address = 3\n"), "key `board.devices[0].address`"),
            ("[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\n", "key `board.devices[0].chip_select`"),
            ("[[board.devices]]\npart = \"X\"\nlink = \"sci-a\"\n", "key `board.devices[0].link` = \"sci-a\""),
            ("[[board.devices]]\npart = \"ADIS16407\"\nlinks = \"spi-a\"\n", "board.devices[0]"),
        ] {
            let e = with_devices(text).unwrap_err().to_string();
            assert!(e.contains(key), "{text}: {e}");
        }
    }
}
