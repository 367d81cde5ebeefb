//! A link kind declared in this one file, as a new kind is: its device trait, its link, its
//! section `[board.loop]`, and its [`LinkKind`] registered with `inventory::submit!`. The only
//! other line it takes is its `mod` line in `bus/mod.rs` (here `#[cfg(test)]`: the kind exists in
//! the tests only). The test shows the profile and the board take it without an edit of theirs.

use crate::board::links::{known_parts, BoardLinks};
use crate::bus::{devices_of, Address, Device, Link, Transfer};
use crate::error::{Error, Result};
use crate::events::Event;
use crate::profile::{Board, BoardDevice, BoxedLink, Devices, LinkKind, Placed, Profile};
use crate::time::Ps;
use serde::{Deserialize, Serialize};

/// The device side of a loop link: it answers each word sent.
trait Reflector {
    fn reflect(&mut self, word: u16) -> u16;
}

/// A test part: adds its number to each word.
struct Adder(u16);

impl Reflector for Adder {
    fn reflect(&mut self, word: u16) -> u16 {
        word.wrapping_add(self.0)
    }
}

/// `[board.loop]`: the time one word takes.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct LoopSection {
    word_ns: u32,
}

impl Default for LoopSection {
    fn default() -> Self {
        LoopSection { word_ns: 1_000 }
    }
}

/// The loop link: devices by channel, one word out and one back per word.
struct LoopLink {
    devices: Vec<(u32, Box<dyn Reflector + Send>)>,
    word_ps: Ps,
}

impl Link for LoopLink {
    fn transfer(&mut self, to: Address, tx: &[u16], rx: &mut [u16], t: Ps) -> Result<Transfer> {
        let device = self.devices.iter_mut().find(|(c, _)| Address::Id(*c) == to);
        let Some((_, device)) = device else { return Err(Error::Config(format!("loop-a: no device at {to}"))) };
        for (r, w) in rx.iter_mut().zip(tx) {
            *r = device.reflect(*w);
        }
        Ok(Transfer { start: t, end: t + self.word_ps * tx.len() as Ps, complete: true })
    }
    fn drain_events(&mut self) -> Vec<Event> {
        Vec::new()
    }
}

inventory::submit! {
    LinkKind {
        name: "loop",
        links: &["loop-a"],
        keys: &["channel"],
        section: Some(("loop", Board::defaults_of::<LoopSection>)),
        place: channel,
        check: |board| board.section::<LoopSection>("loop").map(|_| ()),
        fits: Device::is::<dyn Reflector + Send>,
        build: loop_a,
    }
}

/// A device's place: `channel = 0 … 7`.
fn channel(d: &BoardDevice) -> Placed {
    let value = d.keys.get("channel");
    match value.and_then(|v| v.as_integer()) {
        Some(c @ 0..=7) => Ok(Address::Id(c as u32)),
        _ => Err(("channel", value.map_or("(missing)".into(), |v| v.to_string()), "a channel 0 … 7".into())),
    }
}

fn loop_a(profile: &Profile, link: &str, devices: Devices) -> Result<BoxedLink> {
    let word_ps = Ps::from(profile.board.section::<LoopSection>("loop")?.word_ns) * 1_000;
    let out = devices_of::<dyn Reflector + Send, _>(link, devices, "a reflector", |a| match a {
        Address::Id(c) => Some(c),
        _ => None,
    })?;
    Ok(Box::new(LoopLink { devices: out, word_ps }))
}

const SENSOR: &str = "[[board.devices]]\npart = \"ADIS16407\"\nlink = \"spi-a\"\nchip_select = \"GPIO57\"\n";

/// The profile validates the new kind's declarations and section by the kind's own words (errors
/// name the key), lists its link and keys; the board builds its link, and a transaction reaches
/// the device at its channel.
#[test]
fn a_link_kind_in_one_file_is_taken_by_the_profile_and_the_board() {
    let text = format!(
        "{SENSOR}[[board.devices]]\npart = \"ADDER\"\nlink = \"loop-a\"\nchannel = 3\n\n[board.loop]\nword_ns = 2000\n"
    );
    let profile = Profile::from_toml(&text, "loop.toml", &[]).unwrap();
    assert!(Profile::known_keys().contains(&"board.loop.word_ns".to_string()));
    assert!(Profile::from_toml(&profile.to_toml(), "again", &[]).unwrap() == profile, "it round-trips");
    let catalogue = |name: &str, kind: &LinkKind| match name {
        "ADDER" => Some(Ok(Device::new::<dyn Reflector + Send>(Box::new(Adder(5))))),
        _ => known_parts(name, kind),
    };
    let mut links = BoardLinks::from_profile(&profile, &catalogue, true).unwrap();
    assert_eq!(links.places, [("ADDER".to_string(), "loop-a".to_string(), Address::Id(3))]);
    let mut rx = [0u16; 2];
    let t = links.link("loop-a").unwrap().transfer(Address::Id(3), &[1, 2], &mut rx, 10).unwrap();
    assert_eq!((rx, t.end), ([6, 7], 10 + 4_000_000));
    // An SPI part on the loop link is refused naming the part.
    let spi_part = format!("{SENSOR}[[board.devices]]\npart = \"ADXL345\"\nlink = \"loop-a\"\nchannel = 1\n");
    let p = Profile::from_toml(&spi_part, "loop.toml", &[]).unwrap();
    let e = BoardLinks::from_profile(&p, &catalogue, true).unwrap_err().to_string();
    assert!(e.contains("key `board.devices[1].part` = \"ADXL345\""), "{e}");
    for (text, key) in [
        (
            format!("{SENSOR}[[board.devices]]\npart = \"ADDER\"\nlink = \"loop-a\"\nchannel = 9\n"),
            "key `board.devices[1].channel` = 9: expected a channel 0 … 7",
        ),
        (
            format!("{SENSOR}[[board.devices]]\npart = \"ADDER\"\nlink = \"loop-a\"\naddress = 9\n"),
            "key `board.devices[1].address`",
        ),
        (format!("{SENSOR}[[board.devices]]\npart = \"ADDER\"\nlink = \"loop-b\"\n"), "\"loop-a\""),
        (
            format!("{SENSOR}[board.loop]\nword_nss = 1\n"),
            "unknown key `board.loop.word_nss`; did you mean `board.loop.word_ns`?",
        ),
        (format!("{SENSOR}[board.loop]\nword_ns = -1\n"), "key `board.loop.word_ns`"),
    ] {
        let e = Profile::from_toml(&text, "loop.toml", &[]).unwrap_err().to_string();
        assert!(e.contains(key), "{text}: {e}");
    }
}
