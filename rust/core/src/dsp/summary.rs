//! What a profile's register values produce on the board: clocks, SPI baud and mode, frame and
//! burst times, and the ADIS16407 rules the configuration breaks.
//!
//! Burst model (the published polling firmware, run on the real SPI-A model, not a formula):
//! CS is low; the firmware writes the first word to SPITXBUF at t = 0 (on a SYSCLKOUT edge). Then
//! for each of the 15 frames it polls SPISTS.INT_FLAG in a loop that reads SPISTS once every
//! `timing.poll_loop_cycles` SYSCLKOUT cycles, starting one iteration after the write; so it sees the
//! flag at the first read at or after the character's end (up to one iteration late). It then reads
//! SPIRXBUF, runs one Spi_TxReady iteration (BUFFULL_FLAG is already 0: the shifter is idle) and
//! writes the next word, `poll_loop_cycles` cycles after seeing the flag. SPI-A starts that
//! character `spi.start_latency_lspclk` LSPCLK cycles after the next LSPCLK edge. Because the
//! firmware never preloads SPITXBUF while a character shifts, the double buffer is unused and each
//! frame boundary costs this reaction time. The burst time runs from the first SPITXBUF write to the
//! end (INT_FLAG) of the 15th character.

use super::clocks::DspClocks;
use super::spi::{self, ClockScheme, Frame, SpiA, SpiWire};
use super::timer::CpuTimer;
use crate::error::Result;
use crate::events::{Event, Severity};
use crate::profile::Profile;
use crate::time::{Clock, Ps};

/// Frames of one ADIS16407 burst read: the command and 14 data words.
pub const BURST_FRAMES: u32 = 15;

/// The SPI mode the ADIS16407 requires.
pub const DEVICE_SPI_MODE: u8 = 3;

/// The character length the ADIS16407 uses.
pub const DEVICE_FRAME_BITS: u8 = 16;

/// What the registers of a profile produce.
#[derive(Debug, Clone, PartialEq)]
pub struct BoardSummary {
    /// The clock tree.
    pub clocks: DspClocks,
    /// LSPCLK cycles per SPI clock.
    pub spi_divisor: u32,
    /// SPI clock (LSPCLK / divisor), Hz.
    pub spi_baud_hz: f64,
    /// Fastest instantaneous SCLK (twice the shorter phase as a period), Hz: differs from
    /// `spi_baud_hz` when SPIBRR+1 is odd.
    pub sclk_max_hz: f64,
    /// The clock scheme.
    pub scheme: ClockScheme,
    /// Standard SPI mode of the scheme.
    pub spi_mode: u8,
    /// The mode is the device's (mode 3).
    pub mode_matches_device: bool,
    /// Bits per character.
    pub char_bits: u8,
    /// One character: bits / baud, ps.
    pub frame_ps: Ps,
    /// 15 characters back to back with no gap (the clocking alone), ps.
    pub burst_clocking_ps: Ps,
    /// One 15-frame burst read as the published firmware polls it (see the module doc), ps.
    pub burst_ps: Ps,
    /// Longest idle time between the end of one character and the start of the next in the burst, ps.
    pub frame_gap_ps: Ps,
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
        let sclk_max_hz = lsp.hz() / (2 * shape.active_cycles()) as f64;
        let frame_ps = lsp.cycles_to_ps(shape.length_cycles());
        let burst_clocking_ps = lsp.cycles_to_ps(shape.length_cycles() * BURST_FRAMES as u64);
        let (burst_ps, frame_gap_ps) =
            burst_time(&mut spi, clocks.sysclkout, profile.timing.poll_loop_cycles as u64)?;

        let mut violations = Vec::new();
        let dev = &profile.device;
        if sclk_max_hz > dev.sclk_burst_max_hz {
            violations.push(Event::rule(
                0,
                "sclk_burst_too_fast",
                Severity::Error,
                format!(
                    "SPI clock {:.0} Hz (SPIBRR = {}, LSPCLK {:.0} Hz) exceeds the ADIS16407 burst-read limit {:.0} Hz",
                    sclk_max_hz, profile.spi.spibrr, lsp.hz(), dev.sclk_burst_max_hz
                ),
                sclk_max_hz,
                dev.sclk_burst_max_hz,
            ));
        }
        if sclk_max_hz > dev.sclk_max_hz {
            violations.push(Event::rule(
                0,
                "sclk_too_fast",
                Severity::Error,
                format!(
                    "SPI clock {:.0} Hz exceeds the ADIS16407 normal-mode limit {:.0} Hz",
                    sclk_max_hz, dev.sclk_max_hz
                ),
                sclk_max_hz,
                dev.sclk_max_hz,
            ));
        }
        let spi_mode = scheme.standard_mode();
        if spi_mode != DEVICE_SPI_MODE {
            violations.push(Event::rule(
                0,
                "spi_mode_mismatch",
                Severity::Error,
                format!(
                    "CLKPOLARITY = {}, CLK_PHASE = {} is TI's \"{}\" = SPI mode {}; the ADIS16407 needs mode 3 \
                     (CLKPOLARITY = 1, CLK_PHASE = 0)",
                    u8::from(scheme.polarity),
                    u8::from(scheme.phase),
                    scheme.ti_name(),
                    spi_mode
                ),
                spi_mode as f64,
                DEVICE_SPI_MODE as f64,
            ));
        }
        if shape.bits != DEVICE_FRAME_BITS {
            violations.push(Event::rule(
                0,
                "spi_char_length",
                Severity::Error,
                format!("SPICHAR gives {}-bit characters; the ADIS16407 uses 16-bit frames", shape.bits),
                shape.bits as f64,
                DEVICE_FRAME_BITS as f64,
            ));
        }
        Ok(BoardSummary {
            clocks,
            spi_divisor: shape.divisor,
            spi_baud_hz,
            sclk_max_hz,
            scheme,
            spi_mode,
            mode_matches_device: spi_mode == DEVICE_SPI_MODE,
            char_bits: shape.bits,
            frame_ps,
            burst_clocking_ps,
            burst_ps,
            frame_gap_ps,
            timer_period_ps: timer.tick_ps(1),
            violations,
        })
    }
}

/// Run one burst on `spi` (configured, idle, at t = 0) as the published firmware polls it; return
/// (burst time, longest gap between characters).
fn burst_time(spi: &mut SpiA, sysclk: Clock, poll: u64) -> Result<(Ps, Ps)> {
    let mut wire = Unconnected;
    let mut write_cycle = 0u64;
    let mut gap = 0;
    let mut last_end: Option<Ps> = None;
    for frame in 0..BURST_FRAMES {
        let write_ps = sysclk.cycles_to_ps(write_cycle);
        spi.write(spi::SPITXBUF, 0x4200, write_ps, &mut wire)?;
        let Some(current) = spi.current_frame().copied() else {
            return Err(crate::error::Error::Config(
                "spi: the registers never start a character (SPISWRESET = 0 or not master)".into(),
            ));
        };
        if let Some(end) = last_end {
            gap = gap.max(current.start_ps - end);
        }
        let flag_ps = spi.int_flag_time().unwrap_or(current.end_ps);
        let flag_cycle = sysclk.ps_to_cycles_ceil(flag_ps);
        let iterations = flag_cycle.saturating_sub(write_cycle).div_ceil(poll).max(1);
        let seen_cycle = write_cycle + iterations * poll;
        spi.read(spi::SPIRXBUF, sysclk.cycles_to_ps(seen_cycle), &mut wire)?;
        last_end = Some(current.end_ps);
        if frame + 1 < BURST_FRAMES {
            write_cycle = seen_cycle + poll;
        }
    }
    Ok((last_end.unwrap_or(0), gap))
}
