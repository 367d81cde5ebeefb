//! What a profile's register values produce on the board: clocks, SPI baud and mode, frame time,
//! and the rules of the profile's part (`device.part`) the configuration breaks. The burst time comes from running the firmware's
//! own acquisition on the emulated board (`emulator::BoardReport`), not from a second burst model.

use super::clocks::DspClocks;
use super::spi::{ClockScheme, Frame, SpiA, SpiWire};
use super::timer::CpuTimer;
use crate::device::parts::spi_needs::spi_needs;
use crate::error::{Error, Result};
use crate::events::{Event, Severity};
use crate::profile::Profile;
use crate::time::Ps;

/// Frames of one ADIS16407 burst read: the command and 14 data words (other parts:
/// [`crate::device::part::Part::burst_frames`]).
pub const BURST_FRAMES: u32 = 15;

/// The SPI mode the ADIS16xxx family requires.
pub const DEVICE_SPI_MODE: u8 = crate::device::part::family::SPI_MODE;

/// The character length the ADIS16xxx family uses.
pub const DEVICE_FRAME_BITS: u8 = crate::device::part::family::FRAME_BITS;

/// What the registers of a profile produce.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardSummary {
    /// The clock tree.
    pub clocks: DspClocks,
    /// LSPCLK cycles per SPI clock.
    pub spi_divisor: u32,
    /// SPI clock (LSPCLK / divisor), Hz: the f_SCLK the part's limits judge (its full period is
    /// SPIBRR+1 LSPCLK cycles, whether or not the two phases are equal).
    pub spi_baud_hz: f64,
    /// The clock scheme.
    pub scheme: ClockScheme,
    /// Standard SPI mode of the scheme.
    pub spi_mode: u8,
    /// The part on the acquisition chip select (GPIO57), its modes and the characters of one read.
    pub part: &'static str,
    /// The SPI modes the part accepts.
    pub part_modes: &'static [u8],
    /// Characters of one read (the ADIS16xxx burst; one ADS8344 conversion).
    pub read_frames: u32,
    /// The mode is one the part on the acquisition chip select accepts.
    pub mode_matches_device: bool,
    /// Bits per character.
    pub char_bits: u8,
    /// One character: bits / baud, ps.
    pub frame_ps: Ps,
    /// The part's burst (15 characters for the ADIS16407) back to back with no gap (the clocking alone), ps.
    pub burst_clocking_ps: Ps,
    /// CPU timer 0 interrupt period, ps.
    pub timer_period_ps: Ps,
    /// The device rules the configuration breaks (`t_ps` = 0: they hold for every frame).
    pub violations: Vec<Event>,
}

/// SPI-A without anything on its pins: only the timing matters here.
struct Unconnected;

impl SpiWire for Unconnected {
    fn begin(&mut self, _frame: &Frame) {}
    fn finish(&mut self, _frame: &Frame) -> u16 {
        0
    }
}

impl BoardSummary {
    /// Compute the summary of `profile`.
    pub fn of(profile: &Profile) -> Result<BoardSummary> {
        let clocks = DspClocks::from_profile(&profile.clocks)?;
        let timer = CpuTimer::from_profile(&profile.timer, clocks.sysclkout)?;
        let mut spi = SpiA::new(clocks.lspclk, profile.spi.start_latency_lspclk);
        spi.init_from_profile(&profile.spi, 0, &mut Unconnected)?;
        let shape = spi.shape();
        let scheme = shape.scheme;
        let lsp = clocks.lspclk;
        let spi_baud_hz = lsp.hz() / shape.divisor as f64;
        let frame_ps = lsp.cycles_to_ps(shape.length_cycles());
        let dev = &profile.device;
        // The part on the acquisition chip select: an ADIS16xxx part configured by `[device]`, or a
        // part of another family with its data sheet's needs (`device::parts::spi_needs`).
        let adis = profile.board.spi_device().is_none_or(|d| crate::device::parts::by_name(&d.part).is_some());
        let needs = match profile.board.sensor_needs() {
            Some(n) => n,
            None => spi_needs(dev.part_decl()?.name).ok_or_else(|| Error::Profile("device.part: unknown".into()))?,
        };
        let name = needs.part;
        let burst_clocking_ps = lsp.cycles_to_ps(shape.length_cycles() * u64::from(needs.chars_per_read));
        // An ADIS16xxx part's limits are `[device]`'s keys (the part's figures by default).
        let (sclk_max_hz, sclk_burst_max_hz) =
            if adis { (dev.sclk_max_hz, Some(dev.sclk_burst_max_hz)) } else { (needs.sclk_max_hz, None) };

        let mut violations = Vec::new();
        if let Some(burst_max) = sclk_burst_max_hz.filter(|&m| spi_baud_hz > m) {
            violations.push(Event::rule(
                0,
                "sclk_burst_too_fast",
                Severity::Error,
                format!(
                    "SPI clock {:.0} Hz (SPIBRR = {}, LSPCLK {:.0} Hz) exceeds the {name} burst-read limit {:.0} Hz",
                    spi_baud_hz,
                    profile.spi.spibrr,
                    lsp.hz(),
                    burst_max
                ),
                spi_baud_hz,
                burst_max,
            ));
        }
        if spi_baud_hz > sclk_max_hz {
            violations.push(Event::rule(
                0,
                "sclk_too_fast",
                Severity::Error,
                format!(
                    "SPI clock {:.0} Hz exceeds the {name} {}limit {:.0} Hz",
                    spi_baud_hz,
                    if adis { "normal-mode " } else { "" },
                    sclk_max_hz
                ),
                spi_baud_hz,
                sclk_max_hz,
            ));
        }
        let spi_mode = scheme.standard_mode();
        let mode_matches_device = needs.modes.contains(&spi_mode);
        if !mode_matches_device {
            let wanted: Vec<String> = needs.modes.iter().map(|m| format!("mode {m}")).collect();
            violations.push(Event::rule(
                0,
                "spi_mode_mismatch",
                Severity::Error,
                format!(
                    "CLKPOLARITY = {}, CLK_PHASE = {} is TI's \"{}\" = SPI mode {}; the {name} needs {}{}",
                    u8::from(scheme.polarity),
                    u8::from(scheme.phase),
                    scheme.ti_name(),
                    spi_mode,
                    wanted.join(" or "),
                    if adis { " (CLKPOLARITY = 1, CLK_PHASE = 0)" } else { "" }
                ),
                spi_mode as f64,
                needs.modes[0] as f64,
            ));
        }
        if !needs.char_bits.contains(&shape.bits) {
            violations.push(Event::rule(
                0,
                "spi_char_length",
                Severity::Error,
                format!("SPICHAR gives {}-bit characters; the {name} needs {}", shape.bits, needs.expects),
                shape.bits as f64,
                needs.char_bits[0] as f64,
            ));
        }
        Ok(BoardSummary {
            clocks,
            spi_divisor: shape.divisor,
            spi_baud_hz,
            scheme,
            spi_mode,
            mode_matches_device,
            part: needs.part,
            part_modes: needs.modes,
            read_frames: needs.chars_per_read,
            char_bits: shape.bits,
            frame_ps,
            burst_clocking_ps,
            timer_period_ps: timer.tick_ps(1),
            violations,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with(overrides: &[&str]) -> BoardSummary {
        let ov: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        BoardSummary::of(&Profile::from_toml("", "test", &ov).unwrap()).unwrap()
    }

    fn kinds(s: &BoardSummary) -> Vec<&'static str> {
        s.violations.iter().map(|e| e.kind).collect()
    }

    #[test]
    fn reference_board() {
        let s = with(&[]);
        assert_eq!(s.clocks.sysclkout.hz(), 150e6);
        assert_eq!(s.clocks.lspclk.hz(), 37.5e6);
        assert_eq!((s.spi_divisor, s.spi_baud_hz), (50, 750_000.0));
        assert_eq!((s.spi_mode, s.mode_matches_device, s.char_bits), (3, true, 16));
        assert_eq!(s.frame_ps, 21_333_333);
        assert_eq!(s.burst_clocking_ps, 320_000_000);
        // Hand-computed with the module's model (LSPCLK = SYSCLKOUT/4, 8-cycle poll, latency 1):
        // frame k starts at LSPCLK cycle 1 + 804k (the end at 800 cycles, seen at the next poll 4
        // SYSCLKOUT cycles later, written 8 cycles after that = 3 LSPCLK, +1 latency), so the 15th
        // ends at cycle 1 + 14·804 + 800 = 12057: 321.52 µs; the gap is 4 LSPCLK cycles.
        assert_eq!(s.timer_period_ps, 4_000_000_000);
        assert!(s.violations.is_empty(), "{:?}", s.violations);
    }

    #[test]
    fn spibrr_below_3_is_lspclk_over_4() {
        for brr in 0..=2 {
            let s = with(&[&format!("spi.spibrr={brr}")]);
            assert_eq!((s.spi_divisor, s.spi_baud_hz), (4, 9_375_000.0));
            assert_eq!(kinds(&s), vec!["sclk_burst_too_fast", "sclk_too_fast"]);
        }
    }

    #[test]
    fn spibrr_9_breaks_the_burst_limit() {
        let s = with(&["spi.spibrr=9"]);
        assert_eq!(s.spi_baud_hz, 3_750_000.0);
        assert_eq!(kinds(&s), vec!["sclk_burst_too_fast", "sclk_too_fast"]);
        let e = &s.violations[0];
        assert_eq!((e.measured, e.required), (Some(3_750_000.0), Some(1_000_000.0)));
        // 37 is the thesis' bound (37.5 MHz / 38 ≤ 1 MHz): still fine; 36 breaks it.
        assert!(with(&["spi.spibrr=37"]).violations.is_empty());
        assert_eq!(kinds(&with(&["spi.spibrr=36"])), vec!["sclk_burst_too_fast"]);
    }

    /// The data sheet limits f_SCLK, the frequency of the full period: an odd SPIBRR+1 (unequal
    /// phases) is judged by its frequency, not by twice its shorter phase. SPIBRR = 18 at 37.5 MHz is
    /// 1.974 MHz (phases 9 + 10; twice the short phase would say 2.083 MHz): within the 2 MHz
    /// normal-mode limit, over the 1 MHz burst limit, reported as what it is. 150 MHz / 75 is exactly
    /// 2 MHz (phases 37 + 38): allowed. SPIBRR = 17 is 2.083 MHz: over both.
    #[test]
    fn odd_divisor_is_judged_by_its_full_period() {
        let s = with(&["spi.spibrr=18"]);
        assert_eq!(kinds(&s), vec!["sclk_burst_too_fast"]);
        assert_eq!(s.violations[0].measured, Some(37.5e6 / 19.0));
        assert!(s.violations[0].message.contains("1973684 Hz"), "{}", s.violations[0].message);
        let s = with(&["clocks.lospcp=0", "spi.spibrr=74"]);
        assert_eq!((s.clocks.lspclk.hz(), s.spi_baud_hz), (150e6, 2e6));
        assert_eq!(kinds(&s), vec!["sclk_burst_too_fast"]);
        let s = with(&["spi.spibrr=17"]);
        assert_eq!(kinds(&s), vec!["sclk_burst_too_fast", "sclk_too_fast"]);
        assert_eq!(s.violations[1].measured, Some(37.5e6 / 18.0));
        // SPIBRR = 37 is 37.5 MHz / 38 = 986.8 kHz: within the burst limit.
        assert!(with(&["spi.spibrr=37"]).violations.is_empty());
    }

    #[test]
    fn spibrr_127_is_slow_and_its_burst_about_820_us() {
        let s = with(&["spi.spibrr=127"]);
        assert_eq!(s.spi_baud_hz, 37.5e6 / 128.0); // 292 968.75 Hz
        assert_eq!(s.burst_clocking_ps, 819_200_000);
        // Bound from the model: the first start and each of the 14 frame boundaries cost at most
        // (2 × poll + 1) SYSCLKOUT cycles plus (latency + 1) LSPCLK cycles.
        assert!(s.violations.is_empty());
    }

    #[test]
    fn wrong_schemes_are_reported() {
        for (ccr, ctl, mode) in [(0x8F, 0x07, 1), (0x8F, 0x0F, 0), (0xCF, 0x0F, 2)] {
            let s = with(&[&format!("spi.spiccr={ccr}"), &format!("spi.spictl={ctl}")]);
            assert_eq!((s.spi_mode, s.mode_matches_device), (mode, false));
            assert_eq!(kinds(&s), vec!["spi_mode_mismatch"]);
        }
    }

    #[test]
    fn lospcp_and_pll_change_everything() {
        // 75 MHz / 75 = 1 MHz (phases of 37 and 38 cycles): exactly the burst limit, allowed.
        let s = with(&["clocks.lospcp=1", "spi.spibrr=74"]);
        assert_eq!((s.clocks.lspclk.hz(), s.spi_baud_hz), (75e6, 1e6));
        assert!(s.violations.is_empty(), "{:?}", s.violations);
        let s = with(&["clocks.crystal_hz=20000000", "clocks.lospcp=1", "spi.spibrr=49"]);
        assert_eq!((s.clocks.lspclk.hz(), s.spi_baud_hz), (50e6, 1e6));
        assert!(s.violations.is_empty(), "exactly at the 1 MHz limit is allowed");
        let s = with(&["clocks.lospcp=0", "spi.spibrr=127"]);
        assert_eq!((s.clocks.lspclk.hz(), s.spi_baud_hz), (150e6, 150e6 / 128.0));
        assert_eq!(kinds(&s), vec!["sclk_burst_too_fast"]);
        let s = with(&["clocks.pllcr=0", "clocks.divsel=1"]);
        assert_eq!(s.clocks.sysclkout.hz(), 30e6);
        assert_eq!(s.spi_baud_hz, 150_000.0);
    }
}
