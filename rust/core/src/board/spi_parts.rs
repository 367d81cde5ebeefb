//! The SPI parts a profile's `[[board.devices]]` places on SPI-A, each behind its GPIO chip select,
//! as the board without firmware (`host::HostBoard`, which the C firmware runtime and the Python
//! `Board` drive) holds them: one slave for the link, routed to the part whose chip select is low.
//!
//! Each part is built as the Rust boards build it: the ADIS16xxx part on the acquisition chip select
//! (GPIO57) from `[device]` with the profile's sensor errors and faults; an ADS8344 with the
//! `[geomag]` analogue front end when the profile has one (else with its inputs unconnected); any
//! other part the crate declares from its declaration (`links::known_parts`).

use crate::board::analog::AnalogBoard;
use crate::board::input::InputFeed;
use crate::board::links::known_parts;
use crate::bus::{Address, FrameTiming, RunTiming, SpiSlave};
use crate::device::error_model::ErrorModel;
use crate::device::{parts, Adis16407, Constant, Physical};
use crate::error::{Error, Result};
use crate::events::Event;
use crate::profile::{self, link_kind, Profile, SENSOR_CHIP_SELECT};
use crate::time::Ps;

/// One part on SPI-A.
pub enum SpiPart {
    /// An ADIS16xxx part (the ADIS16407, the ADIS16362): its stimulus and registers are reachable.
    Adis(Box<Adis16407>),
    /// The ADS8344 with the `[geomag]` front end, fed the board's input.
    Analog(Box<AnalogBoard>),
    /// Any other SPI part.
    Other(Box<dyn SpiSlave + Send>),
}

impl SpiPart {
    #[inline(always)]
    fn slave(&mut self) -> &mut dyn SpiSlave {
        match self {
            SpiPart::Adis(d) => d.as_mut(),
            SpiPart::Analog(d) => d.as_mut(),
            SpiPart::Other(d) => d.as_mut(),
        }
    }
}

/// The parts on SPI-A by chip select; frames and CS edges reach the selected one. There is always
/// one at least: a validated profile places a part on GPIO57.
pub struct SpiParts {
    parts: Vec<(u8, String, SpiPart)>,
    selected: usize,
}

impl std::fmt::Debug for SpiParts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let places: Vec<String> = self.parts.iter().map(|(g, n, _)| format!("{n} on GPIO{g}")).collect();
        f.debug_struct("SpiParts").field("parts", &places).field("selected", &self.selected).finish()
    }
}

impl SpiParts {
    /// The SPI-A parts of `profile`, each still and powered (see the module's doc); the first one
    /// selected. A part that is not an SPI part is a profile error naming its `board.devices` key.
    pub fn from_profile(profile: &Profile) -> Result<SpiParts> {
        let spi = link_kind("spi-a").ok_or_else(|| Error::Profile("no `spi` link kind registered".into()))?;
        let mut out = Vec::new();
        for (i, d) in profile.board.devices.iter().enumerate().filter(|(_, d)| d.link == "spi-a") {
            let Some(Address::ChipSelect(gpio)) = d.place() else { continue };
            let adis = parts::by_name(&d.part);
            let part = if gpio == SENSOR_CHIP_SELECT && adis.is_some() {
                let mut dev = Adis16407::new(&profile.device)?;
                let period_s = dev.sample_clock().period_s();
                dev.set_sensor_errors(Box::new(ErrorModel::from_profile(&profile.errors, period_s)?));
                dev.set_faults(&profile.faults);
                dev.set_stimulus(Box::new(Constant(Physical::powered_idle())));
                SpiPart::Adis(Box::new(dev))
            } else if let Some(p) = adis {
                let mut dev = Adis16407::new(&profile::Device::of_part(p))?;
                dev.set_stimulus(Box::new(Constant(Physical::powered_idle())));
                SpiPart::Adis(Box::new(dev))
            } else if d.part.eq_ignore_ascii_case("ADS8344") && profile.geomag.is_some() {
                SpiPart::Analog(Box::new(AnalogBoard::from_profile(profile)?))
            } else {
                let bad =
                    |why: String| Error::Profile(format!("key `board.devices[{i}].part` = \"{}\": {why}", d.part));
                let built = known_parts(&d.part, spi).ok_or_else(|| bad("not a part the emulator models".into()))?;
                let slave = built?.take::<dyn SpiSlave + Send>().ok_or_else(|| bad("not an SPI part".into()))?;
                SpiPart::Other(slave)
            };
            out.push((gpio, d.part.clone(), part));
        }
        Ok(SpiParts { parts: out, selected: 0 })
    }

    /// The chip selects, in declaration order.
    pub fn chip_selects(&self) -> impl Iterator<Item = u8> + '_ {
        self.parts.iter().map(|p| p.0)
    }

    /// The part on `gpio`'s name.
    pub fn part_name(&self, gpio: u8) -> Option<&str> {
        self.parts.iter().find(|p| p.0 == gpio).map(|p| p.1.as_str())
    }

    /// Route chip-select edges and frames to the part on `gpio` (false: none there).
    pub fn select(&mut self, gpio: u8) -> bool {
        match self.parts.iter().position(|p| p.0 == gpio) {
            Some(i) => {
                self.selected = i;
                true
            }
            None => false,
        }
    }

    /// The chip select of the part frames reach.
    pub fn selected(&self) -> Option<u8> {
        self.parts.get(self.selected).map(|p| p.0)
    }

    /// The ADIS16xxx part on the acquisition chip select (GPIO57), if that is one.
    pub fn sensor(&self) -> Option<&Adis16407> {
        self.parts.iter().find_map(|(g, _, p)| match p {
            SpiPart::Adis(d) if *g == SENSOR_CHIP_SELECT => Some(d.as_ref()),
            _ => None,
        })
    }

    /// Every ADIS16xxx part, mutably.
    pub fn adis_parts(&mut self) -> impl Iterator<Item = &mut Adis16407> + '_ {
        self.parts.iter_mut().filter_map(|(_, _, p)| match p {
            SpiPart::Adis(d) => Some(d.as_mut()),
            _ => None,
        })
    }

    /// The input feeds of the parts that read the board's input and have their own (the ADS8344's
    /// front end).
    pub fn own_feeds(&self) -> Vec<InputFeed> {
        self.parts
            .iter()
            .filter_map(|(_, _, p)| match p {
                SpiPart::Analog(a) => Some(a.feed().clone()),
                _ => None,
            })
            .collect()
    }
}

/// `$body` with `$d` the selected part, each kind called directly (the ADIS16xxx model's methods
/// inline into the link's frame path, as they did when the host board held that part alone).
macro_rules! on_selected {
    ($self:ident, $d:ident => $body:expr) => {
        match &mut $self.parts[$self.selected].2 {
            SpiPart::Adis($d) => $body,
            SpiPart::Analog($d) => $body,
            SpiPart::Other($d) => $body,
        }
    };
}

impl SpiSlave for SpiParts {
    #[inline]
    fn set_cs(&mut self, low: bool, t: Ps) {
        on_selected!(self, d => d.set_cs(low, t))
    }
    #[inline]
    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        on_selected!(self, d => d.begin_frame(timing))
    }
    #[inline]
    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        on_selected!(self, d => d.end_frame(din, timing))
    }
    /// The selected part checks a bit-banged frame's measured shape with its own rules (the
    /// ADIS16xxx family: [`Adis16407::bitbanged_shape`]; the ADS8344 and the ADXL345 likewise).
    fn bitbanged_shape(&mut self, timing: &FrameTiming) {
        on_selected!(self, d => d.bitbanged_shape(timing))
    }
    #[inline]
    fn run_frames(&mut self, run: &RunTiming, din: u16, dout: &mut [u16]) {
        on_selected!(self, d => d.run_frames(run, din, dout))
    }
    #[inline]
    fn answers_as_sampled(&self) -> bool {
        match &self.parts[self.selected].2 {
            SpiPart::Adis(d) => d.answers_as_sampled(),
            SpiPart::Analog(d) => d.answers_as_sampled(),
            SpiPart::Other(d) => d.answers_as_sampled(),
        }
    }
    #[inline]
    fn drain_events(&mut self) -> Vec<Event> {
        if let [(_, _, SpiPart::Adis(d))] = self.parts.as_mut_slice() {
            return d.drain_events(); // the reference board's one part: no copy
        }
        let mut out = Vec::new();
        for (_, _, p) in &mut self.parts {
            out.extend(match p {
                // The ADIS16xxx model keeps its events itself (its SpiSlave side reports none).
                SpiPart::Adis(d) => d.drain_events(),
                p => p.slave().drain_events(),
            });
        }
        out
    }
}
