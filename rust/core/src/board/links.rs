//! The board's links and the devices on them, built from the profile's `[[board.devices]]`: each
//! declared link (SPI-A with a device per chip select, I2C-A with a device per address, SCI-A with
//! its peer, or a link of any other registered kind) built by its kind (`profile::LinkKind`) and
//! reached through [`Link`]. Which part a name builds is a [`Catalogue`]'s answer: [`known_parts`]
//! for the parts the crate declares, or any other (a test declares its own).

use crate::bus::i2c::I2cTarget;
use crate::bus::uart::UartPeer;
use crate::bus::{Address, Device, Link, SpiSlave};
use crate::device::{ads8344, adxl345, eeprom24, gps, hmc6343, parts, Adis};
use crate::error::{Error, Result};
use crate::events::Event;
use crate::profile::{self, link_kind, BoxedLink, Devices, LinkKind, Profile, SENSOR_CHIP_SELECT};

/// What builds a part for a link kind: `None` for a part it does not know, an error for a part
/// that cannot sit on that kind of link.
pub type Catalogue<'a> = &'a dyn Fn(&str, &LinkKind) -> Option<Result<Device>>;

/// The parts of other families than the ADIS16xxx, one arm each in [`known_parts`].
const OTHER_PARTS: &[&str] = &["ADS8344", "ADXL345", "HMC6343", "24LC256", "GR-87"];

/// The parts the crate declares: the ADIS16xxx family (`device::part`), the ADS8344 ADC and the ADXL345 on SPI, the HMC6343
/// and the 24LC256 EEPROM on I²C, the GR-87 GPS on a UART.
pub fn known_parts(name: &str, kind: &LinkKind) -> Option<Result<Device>> {
    let only = |want: &str, build: fn() -> Device| -> Option<Result<Device>> {
        Some(if kind.name == want {
            Ok(build())
        } else {
            Err(Error::Profile(format!("{name}: a part for {want} links")))
        })
    };
    // The parts of other families, one arm each.
    match name.to_ascii_uppercase().as_str() {
        "ADS8344" => {
            return only("spi", || Device::new::<dyn SpiSlave + Send>(Box::new(ads8344::Ads8344::unconnected())))
        }
        "ADXL345" => return only("spi", || Device::new::<dyn SpiSlave + Send>(Box::new(adxl345::Adxl345::at_rest()))),
        "HMC6343" => return only("i2c", || Device::new::<dyn I2cTarget + Send>(Box::new(hmc6343::Hmc6343::at_rest()))),
        "24LC256" => {
            return only("i2c", || Device::new::<dyn I2cTarget + Send>(Box::new(eeprom24::Eeprom24lc256::erased())))
        }
        "GR-87" | "GPS" => return only("uart", || Device::new::<dyn UartPeer + Send>(Box::new(gps::Gps::at_rest()))),
        _ => {}
    }
    let p = parts::by_name(name)?;
    Some(match kind.name {
        "spi" => Adis::new(&profile::Device::of_part(p)).map(|d| Device::new::<dyn SpiSlave + Send>(Box::new(d))),
        _ => Err(Error::Profile(format!("{}: an SPI part", p.name))),
    })
}

/// The devices of `[[board.devices]]` on their links.
#[derive(Default)]
pub struct BoardLinks {
    /// Each link with a device on it, by name, in the order the declaration first names them.
    links: Vec<(String, BoxedLink)>,
    /// Each device built: its part, link name and address, in declaration order.
    pub places: Vec<(String, String, Address)>,
}

impl std::fmt::Debug for BoardLinks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let names: Vec<&str> = self.links.iter().map(|(n, _)| n.as_str()).collect();
        f.debug_struct("BoardLinks").field("links", &names).field("places", &self.places).finish()
    }
}

impl BoardLinks {
    /// The declared devices, built by `catalogue`, on their links; with `skip_sensor` the device on
    /// SPI-A's GPIO57 is left out (the acquisition ISR has its own link to it: `Board::link`).
    /// A part the catalogue does not know, or one on the wrong kind of link, is a profile error
    /// naming `board.devices[i].part`.
    pub fn from_profile(profile: &Profile, catalogue: Catalogue, skip_sensor: bool) -> Result<BoardLinks> {
        let mut groups: Vec<(&'static LinkKind, String, Devices)> = Vec::new();
        let mut places = Vec::new();
        for (i, d) in profile.board.devices.iter().enumerate() {
            let kind = d.kind().ok_or_else(|| Error::Profile(format!("key `board.devices[{i}].link`: unknown")))?;
            let address = (kind.place)(d).map_err(|(key, value, expected)| {
                Error::Profile(format!("key `board.devices[{i}].{key}` = {value}: expected {expected}"))
            })?;
            if skip_sensor && d.link == "spi-a" && address == Address::ChipSelect(SENSOR_CHIP_SELECT) {
                continue;
            }
            let bad_part =
                |why: String| Error::Profile(format!("key `board.devices[{i}].part` = \"{}\": {why}", d.part));
            let built = match catalogue(&d.part, kind) {
                None => {
                    return Err(bad_part(format!(
                        "expected a known part ({}, {})",
                        parts::names(),
                        OTHER_PARTS.join(", ")
                    )))
                }
                Some(Err(e)) => return Err(bad_part(format!("cannot sit on `{}` ({e})", d.link))),
                Some(Ok(b)) => b,
            };
            if !(kind.fits)(&built) {
                return Err(bad_part(format!("the part is not built for `{}` (a {} link)", d.link, kind.name)));
            }
            places.push((d.part.clone(), d.link.clone(), address));
            match groups.iter_mut().find(|g| g.1 == d.link) {
                Some(g) => g.2.push((address, built)),
                None => groups.push((kind, d.link.clone(), vec![(address, built)])),
            }
        }
        let mut links = Vec::new();
        for (kind, name, devices) in groups {
            let link = (kind.build)(profile, &name, devices)?;
            links.push((name, link));
        }
        Ok(BoardLinks { links, places })
    }

    /// The link named `name` (`spi-a`, `i2c-a`, `sci-a`, …), when a device sits on it.
    pub fn link(&mut self, name: &str) -> Option<&mut dyn Link> {
        self.links.iter_mut().find(|(n, _)| n == name).map(|(_, l)| l.as_mut() as &mut dyn Link)
    }

    /// Take the events of every link and of the devices on it out (a placed part's rule
    /// violations reach the run's events this way).
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.links.iter_mut().flat_map(|(_, l)| l.drain_events()).collect()
    }

    /// Whether no device is built here.
    pub fn is_empty(&self) -> bool {
        self.places.is_empty()
    }
}

/// The I²C parts `profile` places on `i2c-a`, by 7-bit address: a part that is not an I²C target
/// is a profile error naming its `board.devices` key.
pub fn i2c_targets(profile: &Profile) -> Result<Vec<(u8, Box<dyn I2cTarget + Send>)>> {
    let Some(kind) = link_kind("i2c-a") else { return Ok(Vec::new()) };
    let mut out = Vec::new();
    for (i, d) in profile.board.devices.iter().enumerate().filter(|(_, d)| d.link == "i2c-a") {
        let bad = |why: String| Error::Profile(format!("key `board.devices[{i}].part` = \"{}\": {why}", d.part));
        let Some(Address::I2c(a)) = d.place() else {
            return Err(Error::Profile(format!("key `board.devices[{i}].address`: expected a 7-bit address")));
        };
        let built = known_parts(&d.part, kind).ok_or_else(|| bad("not a part the emulator models".into()))?;
        let target = built?.take::<dyn I2cTarget + Send>().ok_or_else(|| bad("not an I²C part".into()))?;
        out.push((a, target));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::FrameTiming;
    use crate::time::Ps;
    use std::sync::{Arc, Mutex};

    /// The registers of a register file, shared with the test.
    type Regs = Arc<Mutex<[u8; 128]>>;
    /// Each register file built, by part name.
    type Handles = Vec<(String, Regs)>;

    /// A register file, the test part: `name` answers on SPI (a frame `0x80 | reg` reads `reg` in
    /// the next frame's answer, `reg << 8 | value` writes it) and on I²C (a write of `reg` then reads
    /// from `reg` on). Every register starts at its part's `tag`, so an answer says who gave it.
    struct RegisterFile {
        regs: Regs,
        pending: u16,
        pointer: u8,
        first_after_start: bool,
    }

    impl RegisterFile {
        fn new(tag: u8) -> (RegisterFile, Regs) {
            let regs = Arc::new(Mutex::new([tag; 128]));
            (RegisterFile { regs: Arc::clone(&regs), pending: 0, pointer: 0, first_after_start: false }, regs)
        }
    }

    impl SpiSlave for RegisterFile {
        fn set_cs(&mut self, _low: bool, _t: Ps) {}
        fn begin_frame(&mut self, _timing: &FrameTiming) -> u16 {
            self.pending
        }
        fn end_frame(&mut self, din: u16, _timing: &FrameTiming) {
            let reg = usize::from((din >> 8) & 0x7F);
            if din & 0x8000 != 0 {
                self.pending = u16::from(self.regs.lock().unwrap()[reg]);
            } else {
                self.regs.lock().unwrap()[reg] = din as u8;
                self.pending = 0;
            }
        }
    }

    impl I2cTarget for RegisterFile {
        fn start(&mut self, _t: Ps) {
            self.first_after_start = true;
        }
        fn write(&mut self, byte: u8, _t: Ps) -> bool {
            if std::mem::take(&mut self.first_after_start) {
                return true; // the address byte (the link addressed us)
            }
            self.pointer = byte & 0x7F;
            true
        }
        fn read(&mut self, _t: Ps, _ack: bool) -> u8 {
            self.first_after_start = false;
            let v = self.regs.lock().unwrap()[usize::from(self.pointer)];
            self.pointer = (self.pointer + 1) & 0x7F;
            v
        }
        fn stop(&mut self, _t: Ps) {}
    }

    const BOARD: &str = r#"
[board]
devices = [
    { part = "ADIS16407", link = "spi-a", chip_select = "GPIO57" },
    { part = "REGFILE-A", link = "spi-a", chip_select = "GPIO58" },
    { part = "REGFILE-B", link = "spi-a", chip_select = "GPIO59" },
    { part = "REGFILE-C", link = "i2c-a", address = 0x1E },
]
"#;

    /// The test's catalogue: the crate's parts plus three register files tagged 0xA1, 0xB2, 0xC3;
    /// the register handles are kept so the test can look inside each device.
    fn catalogue(handles: &Mutex<Handles>, name: &str, kind: &LinkKind) -> Option<Result<Device>> {
        let tag = match name {
            "REGFILE-A" => 0xA1,
            "REGFILE-B" => 0xB2,
            "REGFILE-C" => 0xC3,
            _ => return known_parts(name, kind),
        };
        let (file, regs) = RegisterFile::new(tag);
        handles.lock().unwrap().push((name.to_string(), regs));
        Some(Ok(match kind.name {
            "spi" => Device::new::<dyn SpiSlave + Send>(Box::new(file)),
            "i2c" => Device::new::<dyn I2cTarget + Send>(Box::new(file)),
            _ => return Some(Err(Error::Profile("not a UART part".into()))),
        }))
    }

    fn build(text: &str) -> Result<(BoardLinks, Handles)> {
        let profile = Profile::from_toml(text, "board.toml", &[])?;
        let handles = Mutex::new(Vec::new());
        let links = BoardLinks::from_profile(&profile, &|n, k| catalogue(&handles, n, k), false)?;
        Ok((links, handles.into_inner().unwrap()))
    }

    /// Two register files on SPI-A (GPIO58, GPIO59) beside the sensor, one on I2C-A at 0x1E: each
    /// transaction reaches the device at its place (its answer carries its tag, a write lands in
    /// its registers only); a chip select nobody sits on is an error naming the wired ones, an
    /// address nobody answers is NACKed with an event.
    #[test]
    fn each_transaction_reaches_the_device_at_its_place() {
        let (mut links, handles) = build(BOARD).unwrap();
        let places: Vec<Address> = links.places.iter().map(|p| p.2).collect();
        assert_eq!(
            places,
            [Address::ChipSelect(57), Address::ChipSelect(58), Address::ChipSelect(59), Address::I2c(0x1E)]
        );
        let regs = |name: &str| Arc::clone(&handles.iter().find(|h| h.0 == name).unwrap().1);
        let spi = links.link("spi-a").unwrap();
        let mut rx = [0u16; 2];
        // Read register 5 of each SPI register file: the second frame answers.
        for (gpio, tag) in [(58, 0xA1), (59, 0xB2)] {
            spi.transfer(Address::ChipSelect(gpio), &[0x8500, 0x0000], &mut rx, u64::from(gpio) * 1_000_000_000)
                .unwrap();
            assert_eq!(rx[1], tag, "GPIO{gpio}");
        }
        // Write register 7 of the file on GPIO59 only.
        spi.transfer(Address::ChipSelect(59), &[0x075A], &mut rx[..1], 60_000_000_000).unwrap();
        assert_eq!((regs("REGFILE-A").lock().unwrap()[7], regs("REGFILE-B").lock().unwrap()[7]), (0xA1, 0x5A));
        // The ADIS16407 on GPIO57 answers a PROD_ID (0x56) read with 0x4017 in the next frame.
        let t = spi.transfer(Address::ChipSelect(57), &[0x5600, 0x0000], &mut rx, 61_000_000_000).unwrap();
        assert_eq!(rx[1], 0x4017);
        assert!(t.end > t.start && t.complete);
        let e = spi.transfer(Address::ChipSelect(60), &[0], &mut rx[..1], 62_000_000_000).unwrap_err();
        assert!(e.to_string().contains("no device on chip select GPIO60 (devices on GPIO57, GPIO58, GPIO59)"), "{e}");
        assert!(spi.transfer(Address::I2c(0x1E), &[0], &mut rx[..1], 62_000_000_000).is_err());
        // I²C: register 3 of the file at 0x1E, then an address nobody answers.
        let i2c = links.link("i2c-a").unwrap();
        regs("REGFILE-C").lock().unwrap()[3] = 0x33;
        let mut two = [0u16; 2];
        let t = i2c.transfer(Address::I2c(0x1E), &[3], &mut two, 0).unwrap();
        assert_eq!((two, t.complete), ([0x33, 0xC3], true));
        let t = i2c.transfer(Address::I2c(0x1F), &[3], &mut two, t.end).unwrap();
        assert_eq!((two, t.complete), ([0xFF, 0xFF], false));
        let events = i2c.drain_events();
        assert_eq!(events.len(), 1);
        assert_eq!(events[0].kind, "i2c_nack");
        assert!(events[0].message.contains("0x1F"), "{}", events[0].message);
        assert!(links.link("sci-a").is_none(), "no device on SCI-A");
    }

    /// The reference board's declaration leaves nothing beside the sensor's own link.
    #[test]
    fn the_reference_board_has_only_the_sensor() {
        let links = BoardLinks::from_profile(&Profile::default(), &known_parts, true).unwrap();
        assert!(links.is_empty() && links.links.is_empty());
        let all = BoardLinks::from_profile(&Profile::default(), &known_parts, false).unwrap();
        assert_eq!(all.places, [("ADIS16407".to_string(), "spi-a".to_string(), Address::ChipSelect(57))]);
    }

    /// Bad declarations: each error names the `board.devices[i]` key (the CLI exits 2 on a profile
    /// error).
    #[test]
    fn bad_declarations_name_the_key() {
        let sensor = "[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\nchip_select = \"GPIO57\"\n";
        let dev = |part: &str, link: &str, place: &str| {
            format!("[[board.devices]]\npart = \"{part}\"\nlink = \"{link}\"\n{place}\n")
        };
        for (text, key) in [
            (
                format!(
                    "{sensor}{}{}",
                    dev("REGFILE-A", "spi-a", "chip_select = \"GPIO58\""),
                    dev("REGFILE-B", "spi-a", "chip_select = \"GPIO58\"")
                ),
                "key `board.devices[2].chip_select` = GPIO58",
            ),
            (
                format!(
                    "{sensor}{}{}",
                    dev("REGFILE-A", "i2c-a", "address = 0x1E"),
                    dev("REGFILE-C", "i2c-a", "address = 0x1E")
                ),
                "key `board.devices[2].address` = 0x1E",
            ),
            (
                format!("{sensor}{}", dev("REGFILE-A", "spi-b", "chip_select = \"GPIO58\"")),
                "key `board.devices[1].link` = \"spi-b\"",
            ),
            (
                format!("{sensor}{}", dev("NOSUCHPART", "spi-a", "chip_select = \"GPIO58\"")),
                "key `board.devices[1].part` = \"NOSUCHPART\"",
            ),
            (
                format!("{sensor}{}", dev("ADIS16362", "i2c-a", "address = 0x20")),
                "key `board.devices[1].part` = \"ADIS16362\"",
            ),
            (format!("{sensor}{}", dev("REGFILE-A", "sci-a", "")), "key `board.devices[1].part` = \"REGFILE-A\""),
        ] {
            let e = build(&text).map(|_| ()).unwrap_err();
            assert!(matches!(e, Error::Profile(_)), "{text}: {e:?}");
            assert!(e.to_string().contains(key), "{text}: {e}");
        }
    }
}
