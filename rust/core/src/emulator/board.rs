//! `sins-fw board`: what a profile's registers produce, with the burst measured by running the
//! firmware's own acquisition ISR once on the emulated board (one burst model, the real one).

use super::{Emulator, Progress, Sensor};
use crate::board::analog::AnalogBoard;
use crate::device::Physical;
use crate::dsp::summary::BoardSummary;
use crate::error::Result;
use crate::events::Event;
use crate::firmware::application::{app_kind, AppKind, Application};
use crate::firmware::geomag_app::GeomagApp;
use crate::profile::{Numeric, Profile};
use crate::time::Ps;
use crate::timing::costs::CostTable;

/// The register-derived summary plus one emulated burst.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardReport {
    /// Clocks, baud, mode, frame time and the configuration's rule violations.
    pub summary: BoardSummary,
    /// First SCLK edge to last SCLK edge of one read as the firmware performs it (the ADIS16407's
    /// 15-frame burst; the geomag board's eight conversions).
    pub burst_ps: Ps,
    /// Longest last-edge-to-first-edge gap between two frames of that burst.
    pub frame_gap_ps: Ps,
    /// Events the device and SPI-A raised during that burst (stalls, SCLK limits, …).
    pub burst_events: Vec<Event>,
}

impl BoardReport {
    /// Run the firmware's first acquisition interrupt on a still board and measure its burst.
    pub fn of(profile: &Profile, costs: &CostTable) -> Result<BoardReport> {
        let summary = BoardSummary::of(profile)?;
        let mut p = profile.clone();
        // The burst does not depend on the arithmetic; f64 keeps this independent of the backend.
        p.firmware.numeric = Numeric::F64;
        let tick_s = summary.timer_period_ps as f64 * 1e-12;
        let still = Physical { accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() };
        let (t, input) = ([0.0, 2.5 * tick_s], vec![still, still]);
        // The acquisition of the profile's application (`firmware.application`), and its frames of a read.
        let (out, log, frames_per_read) = match app_kind(&p.firmware.application)? {
            AppKind::AdisBurst => {
                let mut emu = Emulator::<f64>::new(&p, costs)?;
                emu.push_input(&t, input)?;
                emu.end_input();
                let (out, log) = first_ticks(&mut emu)?;
                (out, log, summary.read_frames as usize)
            }
            AppKind::Ads8344Geomag => {
                let mut emu = Emulator::<f64, AnalogBoard, GeomagApp<f64>>::geomag(&p, costs)?;
                emu.push_input(&t, input)?;
                emu.end_input();
                let (out, log) = first_ticks(&mut emu)?;
                (out, log, summary.read_frames as usize)
            }
        };
        let frames: Vec<_> = log
            .into_iter()
            .filter_map(|r| match r {
                crate::bus::link::LinkRecord::Frame(f) => Some(f),
                _ => None,
            })
            .take(frames_per_read)
            .collect();
        let burst_ps = match (frames.first(), frames.last()) {
            (Some(a), Some(b)) => b.timing.last_edge - a.timing.first_edge,
            _ => 0,
        };
        let frame_gap_ps = frames.windows(2).map(|w| w[1].timing.first_edge - w[0].timing.last_edge).max().unwrap_or(0);
        let first_tick_end = out.budget.first().map_or(0, |b| b.end_ps);
        let burst_events = out.events.into_iter().filter(|e| e.t_ps <= first_tick_end).collect();
        Ok(BoardReport { summary, burst_ps, frame_gap_ps, burst_events })
    }
}

/// Run an emulator fed its input to the end with the bus log on: its output and the log.
fn first_ticks<S: Sensor, A: Application<S>>(
    emu: &mut Emulator<f64, S, A>,
) -> Result<(crate::output::Output, Vec<crate::bus::link::LinkRecord>)> {
    emu.enable_bus_log();
    let mut progress = emu.run()?;
    while progress != Progress::Finished {
        progress = emu.run()?;
    }
    Ok((emu.take_output(), emu.take_bus_log()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn costs() -> CostTable {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/c28x-costs.toml");
        CostTable::from_toml(&std::fs::read_to_string(path).unwrap(), "c28x-costs.toml").unwrap()
    }

    fn report(overrides: &[&str]) -> BoardReport {
        let ov: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        BoardReport::of(&Profile::from_toml("", "test", &ov).unwrap(), &costs()).unwrap()
    }

    #[test]
    fn reference_burst_is_at_least_the_320_us_of_clocking() {
        let r = report(&[]);
        // 15 frames of 16 bits at 0.75 MHz; first edge to last edge is 15×16 periods less the half
        // period before the first falling edge and after the last rising edge: at least 320 µs − 1 period.
        assert!(r.burst_ps >= 320_000_000 - 1_333_334, "{}", r.burst_ps);
        assert!(r.burst_ps < 340_000_000, "{}", r.burst_ps);
        assert!(r.frame_gap_ps > 0);
    }

    #[test]
    fn spibrr_127_burst_is_about_820_us() {
        let r = report(&["spi.spibrr=127"]);
        // 240 bits at 37.5 MHz / 128 = 819.2 µs of clocking plus the firmware's gaps.
        assert!((819_200_000 - 3_413_334..=860_000_000).contains(&r.burst_ps), "{}", r.burst_ps);
    }

    #[test]
    fn spibrr_9_burst_breaks_the_sclk_limit() {
        let r = report(&["spi.spibrr=9"]);
        assert!(r.burst_events.iter().any(|e| e.kind == "sclk_too_fast"), "{:?}", r.burst_events);
    }

    #[test]
    fn spi_held_in_reset_hangs_the_firmware() {
        let p = Profile::from_toml("", "t", &["spi.spiccr=0x4F".into()]).unwrap();
        let e = BoardReport::of(&p, &costs()).unwrap_err().to_string();
        assert!(e.contains("firmware hangs") && e.contains("reset"), "{e}");
    }
}
