//! The geomagnetic–gyro board's sensor side (issue 21): the ADS8344 on SPI-A's acquisition chip
//! select, its channels driven by the analogue front end (`device::analog::FrontEnd`: the gyro on
//! CH0–CH2, the magnetometer on CH3–CH5, the temperature sensor on CH6, VREF/2 on CH7), which sees
//! the physical input streamed in chunks (rates, magnetic field, temperature of the trace).

use crate::board::input::{InputFeed, StreamStimulus};
use crate::board::sensor::{FrameSummary, Reach, Sensor};
use crate::bus::{FrameTiming, SpiSlave};
use crate::device::ads8344::{Ads8344, Ads8344Config, AnalogInputs};
use crate::device::analog::{FrontEnd, Gyro, GyroPreset, Magnetometer, MagnetometerPreset, Scene};
use crate::device::Stimulus;
use crate::error::{Error, Result};
use crate::events::Event;
use crate::profile::{Geomag, Profile};
use crate::time::{s_to_ps, Ps};

/// What the front end sees: the input stream at a time.
type SceneFn = Box<dyn FnMut(f64) -> Scene + Send>;

/// The front end, built at the first conversion (the input has arrived by then, so it settles on the
/// input's first row, not on an empty stream).
enum LazyFrontEnd {
    Waiting(Option<Box<(SceneFn, Gyro, Magnetometer, f64)>>),
    Running(Box<FrontEnd<SceneFn>>),
}

impl AnalogInputs for LazyFrontEnd {
    fn volts(&mut self, channel: usize, t: Ps) -> f64 {
        if let LazyFrontEnd::Waiting(parts) = self {
            if let Some(parts) = parts.take() {
                let (scene, gyro, mag, vref) = *parts;
                *self = LazyFrontEnd::Running(Box::new(FrontEnd::new(scene, gyro, mag, vref)));
            }
        }
        match self {
            LazyFrontEnd::Running(fe) => fe.volts(channel, t),
            LazyFrontEnd::Waiting(_) => 0.0,
        }
    }
}

/// A gyro preset by its `[geomag]` name.
pub fn gyro_preset(key: &str, name: &str) -> Result<GyroPreset> {
    [GyroPreset::SPIN1200, GyroPreset::ADXRS300].into_iter().find(|p| p.name == name).ok_or_else(|| {
        Error::Profile(format!(
            "key `{key}` = \"{name}\": expected \"spin1200\" or \"adxrs300\" (device/analog/gyro.rs)"
        ))
    })
}

/// A magnetometer preset by its `[geomag]` name.
pub fn magnetometer_preset(name: &str) -> Result<MagnetometerPreset> {
    [MagnetometerPreset::AMR].into_iter().find(|p| p.name == name).ok_or_else(|| {
        Error::Profile(format!(
            "key `geomag.magnetometer` = \"{name}\": expected \"amr\" (device/analog/magnetometer.rs)"
        ))
    })
}

/// The board's `[geomag]` section (required by the `ads8344-geomag` application).
pub fn geomag_section(profile: &Profile) -> Result<&Geomag> {
    profile.geomag.as_ref().ok_or_else(|| {
        Error::Profile(
            "key `geomag`: missing; `firmware.application` = \"ads8344-geomag\" reads its front end and constants \
             from a [geomag] table (firmware_model/geomag.toml)"
                .into(),
        )
    })
}

/// The ADS8344 and its front end, fed a physical input.
pub struct AnalogBoard {
    adc: Ads8344,
    feed: InputFeed,
    last: Option<FrameSummary>,
    second: Option<FrameSummary>,
    frames_in_cs: u32,
}

impl AnalogBoard {
    /// The board of a profile's `[geomag]` table: presets (ideal when `ideal_sensors`), the unit's
    /// errors drawn from `errors.seed`, the ADC's reference `vref_v`; the input stream empty.
    pub fn from_profile(profile: &Profile) -> Result<AnalogBoard> {
        let g = geomag_section(profile)?;
        let mut x = gyro_preset("geomag.gyro_x", &g.gyro_x)?;
        let mut yz = gyro_preset("geomag.gyro_yz", &g.gyro_yz)?;
        let mut m = magnetometer_preset(&g.magnetometer)?;
        if g.ideal_sensors {
            (x, yz, m) = (x.ideal(), yz.ideal(), m.ideal());
        }
        let h = FrontEnd::<SceneFn>::STEP_S;
        let seed = profile.errors.seed;
        let gyro = Gyro::new([x, yz, yz], seed, h);
        let mag = Magnetometer::new(m, seed, h);
        let (feed, mut stimulus): (InputFeed, StreamStimulus) = InputFeed::new();
        let scene: SceneFn = Box::new(move |t_s: f64| {
            let p = stimulus.at(0, s_to_ps(t_s));
            Scene { rate_rad_s: p.gyro_dps.map(f64::to_radians), field_gauss: p.mag_gauss, temp_c: p.temp_c }
        });
        let inputs = LazyFrontEnd::Waiting(Some(Box::new((scene, gyro, mag, g.vref_v))));
        let config = Ads8344Config { vref_v: g.vref_v, ..Ads8344Config::default() };
        Ok(AnalogBoard { adc: Ads8344::new(config, Box::new(inputs)), feed, last: None, second: None, frames_in_cs: 0 })
    }

    /// The input stream.
    pub fn feed(&self) -> &InputFeed {
        &self.feed
    }

    /// The converter.
    pub fn adc(&self) -> &Ads8344 {
        &self.adc
    }
}

impl SpiSlave for AnalogBoard {
    fn set_cs(&mut self, low: bool, t: Ps) {
        if low {
            self.frames_in_cs = 0;
        }
        self.adc.set_cs(low, t);
    }
    fn begin_frame(&mut self, timing: &FrameTiming) -> u16 {
        self.adc.begin_frame(timing)
    }
    fn bitbanged_shape(&mut self, timing: &FrameTiming) {
        self.adc.bitbanged_shape(timing);
    }
    fn end_frame(&mut self, din: u16, timing: &FrameTiming) {
        self.adc.end_frame(din, timing);
        let f = FrameSummary { t_start: timing.first_edge, t_end: timing.last_edge, sample: None };
        self.frames_in_cs += 1;
        if self.frames_in_cs == 2 {
            self.second = Some(f);
        }
        self.last = Some(f);
    }
    fn answers_as_sampled(&self) -> bool {
        self.adc.answers_as_sampled()
    }
    fn drain_events(&mut self) -> Vec<Event> {
        self.adc.drain_events()
    }
}

impl Sensor for AnalogBoard {
    fn last_frame(&self) -> Option<FrameSummary> {
        self.last
    }
    fn second_frame(&self) -> Option<FrameSummary> {
        self.second
    }
    fn reach(&self) -> Reach {
        Reach::Time { last_s: self.feed.last_time_s(), ended: self.feed.ended() }
    }
}
