//! `[[board.devices]]`: which part sits on which link of the board, with its place there (a chip
//! select on SPI, an address on I²C). The reference board declares one ADIS16407 on SPI-A, chip
//! select GPIO57.
//!
//! The link kinds are not listed here: each kind's file under `bus/` declares a [`LinkKind`] (its
//! link names, the keys that place a device on it, its `[board.<section>]`, how its link is built)
//! and registers it with `inventory::submit!`; the profile validates the declarations against the
//! registered kinds, and `board::links` builds them. The device on SPI-A's GPIO57 is the sensor
//! the firmware's ISR reads; any other device is built on its link and reached through `bus::Link`.
//! Places are unique per link.

use super::sections::bad;
use super::Profile;
use crate::bus::door::{Address, Device, Link};
use crate::device::parts::spi_needs::{spi_needs, SpiNeeds};
use crate::error::{Error, Result};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// A kind of link (SPI, I²C, UART, …), declared in its own file under `bus/` and registered there:
/// `inventory::submit! { LinkKind { … } }`. What the profile and the board need of the kind, so
/// that neither lists the kinds (a new kind is its file and its `mod` line in `bus/mod.rs`).
pub struct LinkKind {
    /// The kind's name ("spi", "i2c", "uart"), as messages give it.
    pub name: &'static str,
    /// The board's links of this kind, as `board.devices[].link` names them (`spi-a`).
    pub links: &'static [&'static str],
    /// The keys beside `part` and `link` that place a device on such a link (`chip_select`).
    pub keys: &'static [&'static str],
    /// The kind's section `[board.<name>]` and its keys with their defaults (`None`: no section).
    pub section: Option<Section>,
    /// The device's place on its link from its declaration's keys; the error is the key (one of
    /// `keys`), the value given and what was expected.
    pub place: fn(&BoardDevice) -> Placed,
    /// Check the kind's section of the board (an error names its key).
    pub check: fn(&Board) -> Result<()>,
    /// Whether a built device is one of this kind's (its device trait object).
    pub fits: fn(&Device) -> bool,
    /// The link named `link` with its devices at their places.
    pub build: fn(&Profile, &str, Devices) -> Result<BoxedLink>,
}

inventory::collect!(LinkKind);

/// A device's place on its link ([`LinkKind::place`]), or why not: the key, the value given and
/// what was expected.
pub type Placed = std::result::Result<Address, (&'static str, String, String)>;

/// A kind's section: its name under `board.` and its keys with their defaults.
pub type Section = (&'static str, fn() -> toml::Table);

/// The devices of one link at their places, as the board hands them to [`LinkKind::build`].
pub type Devices = Vec<(Address, Device)>;

/// A built link.
pub type BoxedLink = Box<dyn Link + Send>;

/// The registered link kinds, by name (the registry's order is the linker's).
pub fn link_kinds() -> Vec<&'static LinkKind> {
    let mut kinds: Vec<&'static LinkKind> = inventory::iter::<LinkKind>.into_iter().collect();
    kinds.sort_by_key(|k| k.name);
    kinds
}

/// The kind of the link named `link` (`None`: no registered kind has it).
pub fn link_kind(link: &str) -> Option<&'static LinkKind> {
    inventory::iter::<LinkKind>.into_iter().find(|k| k.links.contains(&link))
}

/// Every link name of the registered kinds, sorted.
pub fn link_names() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = link_kinds().iter().flat_map(|k| k.links.iter().copied()).collect();
    names.sort_unstable();
    names
}

/// The board's composition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Board {
    /// The devices and where each sits.
    pub devices: Vec<BoardDevice>,
    /// The link kinds' sections as given (`[board.i2c]`, `[board.sci]`: [`LinkKind::section`]),
    /// read by their kinds ([`Board::section`]); an unknown section is refused by the key check.
    #[serde(flatten)]
    pub sections: toml::Table,
}

/// I2C-A's section `[board.i2c]` (the I²C kind's, `bus/i2c.rs`), the master's SCL phases. The defaults are 100 kHz with equal halves: the HMC6343's bus
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

/// SCI-A's section `[board.sci]` (the UART kind's, `bus/uart.rs`), the UART line: 8 data bits, no parity, 1 stop bit, at `baud`. The default 19 200 is the
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
pub struct BoardDevice {
    /// The part (as `device.part` names it for the sensor on SPI-A).
    pub part: String,
    /// The link it sits on (a name of a registered kind's [`LinkKind::links`]).
    pub link: String,
    /// Its place on the link, in its kind's keys ([`LinkKind::keys`]: `chip_select = "GPIO58"` on
    /// SPI, `address = 0x19` on I²C, none on a UART).
    #[serde(flatten)]
    pub keys: toml::Table,
}

/// The chip select the acquisition ISR drives: the sensor's (GPIO57 on the F28335 boards).
pub const SENSOR_CHIP_SELECT: u8 = 57;

impl Default for Board {
    fn default() -> Self {
        Board {
            devices: vec![BoardDevice {
                part: "ADIS16407".into(),
                link: "spi-a".into(),
                keys: toml::Table::from_iter([("chip_select".to_string(), toml::Value::from("GPIO57"))]),
            }],
            sections: toml::Table::new(),
        }
    }
}

impl BoardDevice {
    /// The link's kind (`None`: no registered kind has the link).
    pub fn kind(&self) -> Option<&'static LinkKind> {
        link_kind(&self.link)
    }

    /// Its place on its link (`None`: an unknown link or a bad place; the validated profile has
    /// none).
    pub fn place(&self) -> Option<Address> {
        (self.kind()?.place)(self).ok()
    }
}

impl Board {
    /// The device on SPI-A's chip select GPIO57 (the one the firmware's ISR reads), once the profile
    /// is validated.
    pub fn spi_device(&self) -> Option<&BoardDevice> {
        self.devices.iter().find(|d| d.link == "spi-a" && d.place() == Some(Address::ChipSelect(SENSOR_CHIP_SELECT)))
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

    /// The section `[board.<name>]` as `T` (absent: `T::default()`); an error names the key.
    pub fn section<T: DeserializeOwned + Default>(&self, name: &str) -> Result<T> {
        let Some(value) = self.sections.get(name) else { return Ok(T::default()) };
        serde_path_to_error::deserialize(value.clone()).map_err(|e| {
            let path = e.path().to_string();
            let key = if path == "." { format!("board.{name}") } else { format!("board.{name}.{path}") };
            Error::Profile(format!("key `{key}`: {}", e.inner().to_string().trim()))
        })
    }

    /// Every registered kind's section keys with their defaults, dotted (`board.i2c.scl_low_ns`).
    pub(crate) fn section_keys() -> Vec<String> {
        let mut out = Vec::new();
        for kind in link_kinds() {
            if let Some((name, defaults)) = kind.section {
                out.extend(defaults().into_iter().map(|(k, _)| format!("board.{name}.{k}")));
            }
        }
        out
    }

    /// A section's defaults as a table (for [`LinkKind::section`]).
    pub fn defaults_of<T: Serialize + Default>() -> toml::Table {
        toml::Value::try_from(T::default()).ok().and_then(|v| v.as_table().cloned()).unwrap_or_default()
    }

    pub(crate) fn validate(&self, profile: &Profile) -> Result<()> {
        if self.devices.is_empty() {
            return Err(Error::Profile(
                "key `board.devices`: expected at least one device (the reference: part = \"ADIS16407\", \
                 link = \"spi-a\", chip_select = \"GPIO57\")"
                    .into(),
            ));
        }
        let mut taken: Vec<(&str, Address)> = Vec::new();
        for (i, d) in self.devices.iter().enumerate() {
            let key = |field: &str| format!("board.devices[{i}].{field}");
            let Some(kind) = d.kind() else {
                let names: Vec<String> = link_names().iter().map(|n| format!("\"{n}\"")).collect();
                return Err(bad(&key("link"), format!("\"{}\"", d.link), &format!("one of {}", names.join(", "))));
            };
            if d.part.trim().is_empty() {
                return Err(bad(&key("part"), "\"\"", "a part name"));
            }
            if let Some(k) = d.keys.keys().find(|k| !kind.keys.contains(&k.as_str())) {
                let expected = match kind.keys {
                    [] => format!("no key beside `part` and `link` on `{}` (a {} link)", d.link, kind.name),
                    keys => format!("`{}` on `{}` (a {} link)", keys.join("`, `"), d.link, kind.name),
                };
                return Err(bad(&key(k), "(given)", &expected));
            }
            let place = (kind.place)(d).map_err(|(k, value, expected)| bad(&key(k), value, &expected))?;
            // The ADIS16xxx part the ISR reads is configured by `[device]`; another family's part
            // there is read by its own application (`firmware.application`).
            if d.link == "spi-a" && place == Address::ChipSelect(SENSOR_CHIP_SELECT) {
                let adis = crate::device::parts::by_name(&d.part).is_some();
                let reads_adis = profile.firmware.application == "adis-burst";
                if (adis || reads_adis) && d.part != profile.device.part {
                    return Err(bad(
                        &key("part"),
                        format!("\"{}\"", d.part),
                        &format!(
                            "the part `device.part` configures (\"{}\"): the ISR reads the device on GPIO57",
                            profile.device.part
                        ),
                    ));
                }
            }
            if taken.iter().any(|(link, p)| *link == d.link && *p == place) {
                let (field, value) = match place {
                    Address::ChipSelect(gpio) => ("chip_select", format!("GPIO{gpio}")),
                    Address::I2c(a) => ("address", format!("0x{a:02X}")),
                    Address::Port => ("link", "its peer".to_string()),
                    Address::Id(n) => ("link", n.to_string()),
                };
                let field = kind.keys.first().copied().unwrap_or(field);
                return Err(bad(
                    &key(field),
                    value,
                    &format!("a place on `{}` no other device of `board.devices` takes", d.link),
                ));
            }
            taken.push((&d.link, place));
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
        for kind in link_kinds() {
            (kind.check)(self)?;
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
