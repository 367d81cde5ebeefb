//! The event log shared by every model: timing violations, read-only writes, stale decodes,
//! saturation, overruns. Events are rare on a healthy run, so a plain record is cheap enough.

use crate::time::Ps;

/// How serious an event is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// Worth knowing (e.g. a write to a read-only register).
    Info,
    /// The data may be wrong (a stale decode, a saturated reading).
    Warning,
    /// A rule of the hardware was broken or a deadline missed.
    Error,
}

impl Severity {
    /// Every severity, by its number (`severity as u8`: 0 info, 1 warning, 2 error, as the C ABI
    /// gives it); Python reads their names from here (`sins_fw._core.SEVERITIES`).
    pub const ALL: [Severity; 3] = [Severity::Info, Severity::Warning, Severity::Error];

    /// Lower-case name used in reports and JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Info => "info",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// One kind of event: its stable name, the severity it is always reported with and one line of
/// meaning. [`KINDS`] lists every kind; `docs/events.md` is generated from it
/// (`python -m sins_fw.docs`) and Python reads it through the binding (`sins_fw._core.EVENT_KINDS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EventKind {
    /// Stable snake_case identifier.
    pub name: &'static str,
    /// The severity every event of this kind carries.
    pub severity: Severity,
    /// Who reports it: `device`, `link`, `mcu` (the F28335's SPI-A and static checks), `firmware`,
    /// `emulator` or `harness` (the Python side).
    pub source: &'static str,
    /// A broken SPI rule: counted as an SPI violation in run reports.
    pub spi_rule: bool,
    /// One line of meaning.
    pub meaning: &'static str,
}

const fn kind(name: &'static str, severity: Severity, source: &'static str, meaning: &'static str) -> EventKind {
    EventKind { name, severity, source, spi_rule: false, meaning }
}

const fn spi_rule(name: &'static str, severity: Severity, source: &'static str, meaning: &'static str) -> EventKind {
    EventKind { name, severity, source, spi_rule: true, meaning }
}

use Severity::{Error, Info, Warning};

/// Every event kind a run, a board check or the harness can report, grouped by the layer that
/// reports it. An event of a kind not listed here fails the core's tests (see [`Event::new`]).
pub const KINDS: &[EventKind] = &[
    // The device's SPI frame rules (data-sheet timing): each breaks one bit of `slave::Violations`.
    spi_rule(
        "sclk_too_fast",
        Error,
        "device",
        "SCLK faster than the data sheet's f_SCLK limit (static check or one frame)",
    ),
    spi_rule(
        "sclk_burst_too_fast",
        Error,
        "mcu",
        "SCLK faster than the burst-mode f_SCLK limit (static check of the SPI-A registers)",
    ),
    spi_rule("stall_too_short", Error, "device", "too little time between two frames (t_STALL)"),
    spi_rule(
        "datarate_too_short",
        Error,
        "device",
        "two frames outside a burst started closer than the frame period t_DATARATE",
    ),
    spi_rule("cs_setup", Error, "device", "CS fell too close to the first SCLK edge (t_CS)"),
    spi_rule("cs_hold", Error, "device", "CS rose too close to the last SCLK edge (t_SFS)"),
    spi_rule(
        "spi_mode",
        Error,
        "device",
        "a frame clocked in an SPI mode other than the device's: the words are read shifted by one bit",
    ),
    spi_rule("frame_length", Error, "device", "a frame of other than 16 SCLK cycles: DIN ignored, DOUT corrupt"),
    spi_rule("frame_without_cs", Error, "device", "SCLK clocked at the device with its chip select high"),
    spi_rule("device_busy", Error, "device", "a frame clocked while the device is in a software reset"),
    spi_rule(
        "read_before_startup",
        Error,
        "device",
        "a frame clocked before the part's power-on start-up ended: DIN ignored, DOUT reads 0x0000",
    ),
    spi_rule("burst_truncated", Info, "device", "CS rose before the burst shifted all its data frames out"),
    // The link between the MCU and the device.
    spi_rule("cs_changed_mid_frame", Warning, "link", "the chip-select GPIO changed while a character was shifting"),
    spi_rule(
        "spi_frame_without_cs",
        Warning,
        "link",
        "an SPI character clocked with the chip select high: the slave ignores it",
    ),
    kind("i2c_nack", Warning, "link", "an I²C byte was not acknowledged (no device at the address, or a refused byte)"),
    kind("i2c_scl_too_fast", Warning, "link", "an I²C SCL phase shorter than its mode's minimum (tLOW, tHIGH)"),
    // The F28335's SPI-A peripheral and the static checks of its registers.
    spi_rule("spi_mode_mismatch", Error, "mcu", "CLKPOLARITY/CLK_PHASE give an SPI mode other than the device's"),
    spi_rule("spi_char_length", Error, "mcu", "SPICHAR gives characters the part on the chip select is not read with (its data sheet's lengths)"),
    spi_rule(
        "spi_rx_overrun",
        Warning,
        "mcu",
        "a character ended before SPIRXBUF was read: a word is lost, OVERRUN_FLAG set",
    ),
    spi_rule(
        "spi_rx_fifo_overflow",
        Warning,
        "mcu",
        "the receive FIFO was full at the end of a character: a word is lost",
    ),
    spi_rule(
        "spi_tx_fifo_overflow",
        Warning,
        "mcu",
        "the transmit FIFO was full: a written word replaces a waiting one",
    ),
    spi_rule(
        "spi_txbuf_overwrite",
        Warning,
        "mcu",
        "SPITXBUF written while BUFFULL_FLAG = 1: a waiting word is replaced",
    ),
    spi_rule(
        "spi_spidat_write_during_transfer",
        Warning,
        "mcu",
        "SPIDAT written while a character is scheduled or shifting: ignored",
    ),
    spi_rule(
        "spi_reset_during_transfer",
        Warning,
        "mcu",
        "SPISWRESET cleared while a character was shifting: it is abandoned",
    ),
    spi_rule("spi_reset_word_lost", Warning, "mcu", "SPISWRESET cleared with a received word not yet read: it is lost"),
    spi_rule(
        "spi_not_master",
        Warning,
        "mcu",
        "SPITXBUF written with SPICTL.MASTER_SLAVE = 0: no clock, the word waits",
    ),
    spi_rule("spi_write_read_only", Info, "mcu", "a write to a read-only SPI-A register, ignored"),
    // The device's registers, commands and inputs.
    kind("write_unmapped", Warning, "device", "a write to an address with no register: ignored"),
    kind("read_only_write", Info, "device", "a write to a read-only register: ignored"),
    kind("read_unreadable", Warning, "device", "a read of an address with no readable register: DOUT reads 0x0000"),
    kind(
        "invalid_register_value",
        Warning,
        "device",
        "a register written with a value the part does not accept: the old setting stays",
    ),
    kind("sens_avg_raised", Info, "device", "SENS_AVG's filter taps below the range's minimum: raised to it"),
    kind("command_not_modelled", Warning, "device", "a command the model does not carry out (e.g. precision autonull)"),
    kind("autonull_without_data", Warning, "device", "autonull commanded before the first sample: offsets unchanged"),
    kind("autonull_saturated", Warning, "device", "autonull: a gyro bias exceeds the offset register's range"),
    kind(
        "software_reset",
        Info,
        "device",
        "the device was reset by command or fault: registers back to their reset values",
    ),
    kind(
        "sensor_overrange",
        Warning,
        "device",
        "an input beyond the rated range: outputs clip, DIAG_STAT overrange set",
    ),
    kind("supply_out_of_range", Warning, "device", "the supply voltage outside the data sheet's operating range"),
    kind("non_finite_input", Error, "device", "the stimulus or error model gave a non-finite value; NaN taken as 0"),
    kind(
        "time_reversal",
        Warning,
        "device",
        "a frame starts before the device's time: it would see samples from its future",
    ),
    kind("fault_injected", Warning, "device", "a fault of the profile's fault list started or ended"),
    // A replay of recorded burst words in place of the device model.
    kind(
        "replay_exhausted",
        Error,
        "device",
        "a burst read after every recorded burst was replayed: frames read the idle word",
    ),
    kind(
        "replay_extra_frame",
        Warning,
        "device",
        "a CS-low window longer than the recorded burst: the extra frames read the idle word",
    ),
    kind(
        "replay_unexpected_command",
        Warning,
        "device",
        "a frame other than the recorded burst command during a replay",
    ),
    // The firmware.
    kind("stale_decode", Warning, "firmware", "a gyro word outside both published ranges: the previous value kept"),
    kind(
        "decode_mismatch",
        Warning,
        "firmware",
        "the firmware decodes for another gyro range (`firmware.gyro_range_dps`) than SENS_AVG selects",
    ),
    kind("saturated_reading", Warning, "firmware", "a decoded code at the 14-bit limit"),
    kind(
        "gyro_clipped",
        Warning,
        "firmware",
        "a gyro axis at its full-scale code: the attitude update raises its reference gains (`clip_gain`)",
    ),
    kind(
        "clip_recovered",
        Info,
        "firmware",
        "no gyro clip for the recovery time (`clip_recovery_s`): the attitude update's gains are normal again",
    ),
    kind(
        "mag_reference_learned",
        Info,
        "firmware",
        "the magnetic gate learned the field's norm and dip at rest (`[firmware.mag_gate]`)",
    ),
    kind(
        "mag_rejected",
        Warning,
        "firmware",
        "the magnetic field is off its reference in norm or dip, or clipped: yaw runs on the gyro",
    ),
    kind("mag_accepted", Info, "firmware", "the magnetic field is usable for yaw again after a rejection"),
    kind(
        "mag_reference_relearned",
        Warning,
        "firmware",
        "a rejection longer than `relearn_s`: the disturbed field's norm and dip are the new reference",
    ),
    kind(
        "state_out_of_range",
        Error,
        "firmware",
        "the firmware state (quaternion norm, velocity, position) left its valid range",
    ),
    // The emulator's scheduling of the timer interrupt.
    kind(
        "overrun",
        Error,
        "emulator",
        "a processor missed its deadline: a timer tick (or, on the gyro-free board, the next packet) arrived while the previous handler was still running",
    ),
    kind("tick_lost", Error, "emulator", "a timer tick arrived while the previous one was still pending: lost"),
    kind("nested_interrupt", Warning, "emulator", "a timer tick preempted the running ISR and ran inside it"),
    kind(
        "no_data",
        Error,
        "emulator",
        "the reads have found no new sample from the part for a second (or none in a whole run): the firmware reads no data",
    ),
    // The Python harness.
    kind(
        "input_gap",
        Warning,
        "harness",
        "the trace has a gap longer than the allowed sample periods: interpolated across",
    ),
    // The gyro-free board's parts (ADXL345 on SPI).
    spi_rule(
        "cs_high_too_short",
        Error,
        "device",
        "chip select high for less than the part's time between two communications (ADXL345 tCS,DIS)",
    ),
    spi_rule(
        "fifo_pop_too_soon",
        Error,
        "device",
        "a FIFO or FIFO_STATUS read less than 5 µs after the end of the previous data read (ADXL345)",
    ),
    spi_rule("byte_frame_length", Error, "device", "a frame of other than 8 SCLK cycles at a byte-wide SPI part"),
    // I²C rules a master can break, and the HMC6343 on I²C.
    kind(
        "i2c_stretch_ignored",
        Warning,
        "link",
        "the I²C master raised SCL while a target stretched it (held it low): the target's bits may be lost",
    ),
    kind(
        "unknown_command",
        Warning,
        "device",
        "a command code the part does not know (in its selected revision): ignored",
    ),
    kind(
        "response_too_early",
        Warning,
        "device",
        "a response read before the command's response delay ended: the previous response is read",
    ),
    // NMEA 0183 from the GPS on a UART.
    kind("nmea_bad_checksum", Warning, "firmware", "an NMEA line whose checksum does not match its body: dropped"),
    kind("uart_framing_error", Warning, "link", "a UART character whose stop bit was read low: dropped"),
    kind("uart_overrun", Warning, "link", "a UART character arrived with the receive FIFO full: lost"),
    // The ADS8344 converter (geomagnetic–gyro board) and its firmware.
    spi_rule(
        "adc_acquisition_too_short",
        Error,
        "device",
        "the ADC tracked its input for less than t_ACQ before the hold edge (DCLK too fast): the sample may not settle",
    ),
    spi_rule(
        "adc_conversion_aborted",
        Warning,
        "device",
        "CS rose before the ADC's control byte or result was clocked through: no result",
    ),
    spi_rule("adc_busy_read", Warning, "device", "DCLK during an internal-clock conversion: DOUT reads 0"),
    kind("adc_input_out_of_range", Warning, "device", "an ADC input outside 0…VREF: the code clips"),
    kind(
        "adc_result_in_command_frame",
        Warning,
        "device",
        "a result bit fell in the SPI character that carried its start bit: the word-level link cannot show it (reads 0)",
    ),
    kind(
        "mag_aid_gated",
        Info,
        "firmware",
        "the magnetometer roll aid turned off (or back on): the field across the spin axis is below (above) its gate",
    ),
    kind(
        "mag_aid_axis",
        Warning,
        "firmware",
        "the magnetometer roll aid held (or on again): the spin axis's measured angle to the field differs from the \
         attitude's by more than `geomag.aid_axis_gate_deg` (less than half of it)",
    ),
    // A host-built firmware's accesses (rust/core/src/host.rs).
    kind(
        "interrupt_never_raised",
        Warning,
        "emulator",
        "the firmware enabled an interrupt (a PIEIER line, IER's DLOGINT or RTOSINT) that no modelled peripheral raises: its ISR will never run",
    ),
    kind(
        "protected_write",
        Warning,
        "mcu",
        "an EALLOW-protected register (PieVectTable, SysCtrlRegs, FlashRegs, …) written without EALLOW: ignored, as on the chip",
    ),
    // The F28335's system control and the peripherals not modelled (rust/core/src/dsp/sysctrl.rs,
    // dsp/unmodelled.rs).
    kind(
        "unmodelled_peripheral",
        Warning,
        "mcu",
        "the firmware uses a peripheral that is not modelled (ADC, ePWM, eCAP, eCAN, DMA, XINTF): its registers hold what is written, it does nothing",
    ),
    kind(
        "peripheral_clock_off",
        Warning,
        "mcu",
        "a peripheral's register accessed with its clock disabled in PCLKCR0/1/3: the write is lost, a read gives 0",
    ),
    kind(
        "watchdog_reset",
        Error,
        "mcu",
        "the watchdog reset the chip: its counter overflowed unserviced (WDKEY 0x55, 0xAA), or WDCR was written without WDCHK = 101",
    ),
    kind(
        "watchdog_interrupt",
        Info,
        "mcu",
        "the watchdog counter overflowed with SCSR.WDENINT = 1: WAKEINT (PIE INT1.8) raised instead of a reset",
    ),
    // The F28335's serial peripherals as a host-built firmware drives them (rust/core/src/dsp/sci.rs).
    kind(
        "sci_tx_line",
        Info,
        "mcu",
        "a line an SCI port transmitted (up to a newline or 128 bytes), prefixed with the port (`SCI-B> …`)",
    ),
    kind(
        "sci_misuse",
        Warning,
        "mcu",
        "an SCI register used against SPRUFZ5 (a TX FIFO full or held in reset, SCIRXBUF read empty, a read-only register written)",
    ),
    kind(
        "i2c_misuse",
        Warning,
        "mcu",
        "an I2C-A register used against SPRUG03 (a module clock outside 7-12 MHz, I2CDXR overwritten, a START in reset, a mode not modelled)",
    ),
    kind(
        "eeprom_page_wrap",
        Warning,
        "device",
        "more bytes than a serial EEPROM's page in one page write: the address wrapped to the page's start, overwriting the first bytes",
    ),
    // The wing unit (firmware/wing/app.rs).
    kind(
        "wing_zero_lengthened",
        Warning,
        "firmware",
        "firmware.alignment_s is shorter than the zero needs to average the accelerometer noise to 0.5 mg: it waits longer",
    ),
    // The gyro-free board's DSP (firmware/gfsins/dsp.rs).
    kind("packet_missing", Error, "firmware", "the C6727 got no node packet in a period, or a sequence number was skipped"),
    kind("packet_refused", Error, "firmware", "a node packet with a wrong length, sync word or CRC: dropped by the C6727"),
    // The gyro-free navigation firmware (firmware/gfnav).
    kind(
        "rate_singular",
        Warning,
        "firmware",
        "rate recovery from the accelerometer array's products is 0/0 (the products do not change): bridged by ω̇; the C6727 reports a spell of such steps once",
    ),
    kind(
        "fusion_refused",
        Warning,
        "firmware",
        "the C6727's federated fusion found sub-filter 2's covariance factor not positive: the fused estimate keeps its last value",
    ),
];

/// The table entry of `name`, if it is a known kind.
pub fn kind_of(name: &str) -> Option<&'static EventKind> {
    KINDS.iter().find(|k| k.name == name)
}

/// One event. `kind` is a stable snake_case identifier listed in [`KINDS`] (and docs/events.md);
/// `measured`/`required` carry the numbers of a timing rule (SI units: seconds, hertz).
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// Virtual time of the event.
    pub t_ps: Ps,
    /// Stable identifier, e.g. `sclk_too_fast`, `stall_too_short`, `stale_decode`.
    pub kind: &'static str,
    /// Severity of the event.
    pub severity: Severity,
    /// Human-readable explanation.
    pub message: String,
    /// Measured value of the rule, if the event is about a rule.
    pub measured: Option<f64>,
    /// Required value of the rule.
    pub required: Option<f64>,
    /// The bus frame the event is about: the link's character index since power-on, as the bus log
    /// numbers its frames (`frame_index`); `None` for an event not tied to one frame.
    pub frame: Option<u64>,
}

impl Event {
    /// An event with no rule figures. In tests and debug builds, a kind missing from [`KINDS`] or a
    /// severity other than the table's panics: the table stays the one list of what can be reported.
    pub fn new(t_ps: Ps, kind: &'static str, severity: Severity, message: impl Into<String>) -> Self {
        check_kind(kind, severity);
        Event { t_ps, kind, severity, message: message.into(), measured: None, required: None, frame: None }
    }

    /// An event about a rule, with the measured and required values.
    pub fn rule(
        t_ps: Ps,
        kind: &'static str,
        severity: Severity,
        message: impl Into<String>,
        measured: f64,
        required: f64,
    ) -> Self {
        check_kind(kind, severity);
        Event {
            t_ps,
            kind,
            severity,
            message: message.into(),
            measured: Some(measured),
            required: Some(required),
            frame: None,
        }
    }

    /// The event tied to bus frame `index` ([`Event::frame`]).
    pub fn in_frame(self, index: u64) -> Self {
        Event { frame: Some(index), ..self }
    }
}

/// Panics (tests and debug builds only) when `kind` is not in [`KINDS`] or `severity` is not its.
#[inline]
fn check_kind(kind: &str, severity: Severity) {
    if cfg!(any(test, debug_assertions)) {
        match kind_of(kind) {
            None => panic!("event kind `{kind}` is not in events::KINDS: add it there (with its meaning)"),
            Some(k) => assert_eq!(k.severity, severity, "event kind `{kind}` is reported with the table's severity"),
        }
    }
}

/// An append-only log of events.
#[derive(Debug, Clone, Default)]
pub struct EventLog {
    events: Vec<Event>,
}

impl EventLog {
    /// Record one event.
    pub fn push(&mut self, e: Event) {
        self.events.push(e);
    }
    /// All events so far, in the order they were recorded.
    pub fn events(&self) -> &[Event] {
        &self.events
    }
    /// Take the events out, leaving the log empty.
    pub fn drain(&mut self) -> Vec<Event> {
        std::mem::take(&mut self.events)
    }
    /// Number of events recorded so far (a mark for [`EventLog::tie_to_frame`]).
    pub fn len(&self) -> usize {
        self.events.len()
    }
    /// Whether no event is recorded.
    pub fn is_empty(&self) -> bool {
        self.events.is_empty()
    }
    /// Tie the events recorded since `mark` (a [`EventLog::len`]) that name no frame to bus frame
    /// `index`: what a device reports while it handles one frame.
    pub fn tie_to_frame(&mut self, mark: usize, index: u64) {
        for e in self.events.get_mut(mark..).unwrap_or_default() {
            e.frame.get_or_insert(index);
        }
    }
    /// Number of events of one kind.
    pub fn count(&self, kind: &str) -> usize {
        self.events.iter().filter(|e| e.kind == kind).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    #[test]
    fn kinds_are_unique_snake_case_with_a_meaning() {
        for (i, k) in KINDS.iter().enumerate() {
            assert!(k.name.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_'), "{}", k.name);
            assert!(!k.meaning.is_empty() && !k.meaning.ends_with('.'), "{}: one line, no full stop", k.name);
            assert!(["device", "link", "mcu", "firmware", "emulator", "harness"].contains(&k.source), "{}", k.name);
            assert!(KINDS[..i].iter().all(|o| o.name != k.name), "{} twice", k.name);
        }
    }

    #[test]
    fn severities_are_numbered_as_listed() {
        for (i, s) in Severity::ALL.iter().enumerate() {
            assert_eq!(*s as usize, i, "{}", s.as_str());
        }
    }

    #[test]
    #[should_panic(expected = "not in events::KINDS")]
    fn an_unlisted_kind_panics_in_tests() {
        let _ = Event::new(0, "no_such_kind", Severity::Info, "");
    }

    #[test]
    #[should_panic(expected = "the table's severity")]
    fn a_kind_with_another_severity_panics_in_tests() {
        let _ = Event::new(0, "overrun", Severity::Info, "");
    }

    fn sources(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                sources(&p, ext, out);
            } else if p.extension().is_some_and(|x| x == ext) && !p.ends_with("events.rs") {
                out.push(p);
            }
        }
    }

    /// Every kind of the table is reported somewhere: its name appears as a string literal in the
    /// core's sources (Rust kinds) or the Python package's (`harness` kinds), outside this file and
    /// outside test modules. The other direction (nothing reports an unlisted kind) is `Event::new`'s check.
    #[test]
    fn every_listed_kind_is_reported_somewhere() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let (mut rust, mut python) = (Vec::new(), Vec::new());
        sources(&root.join("src"), "rs", &mut rust);
        sources(&root.join("../../python/sins_fw"), "py", &mut python);
        let text = |files: &[PathBuf]| -> String {
            files
                .iter()
                .filter(|p| !p.file_name().unwrap().to_string_lossy().starts_with("tests"))
                .map(|p| {
                    let t = std::fs::read_to_string(p).unwrap();
                    // Drop the file's test module (it may name kinds without reporting them).
                    t.split("#[cfg(test)]").next().unwrap().to_string()
                })
                .collect()
        };
        let (rust, python) = (text(&rust), text(&python));
        for k in KINDS {
            let quoted = format!("\"{}\"", k.name);
            let code = if k.source == "harness" { &python } else { &rust };
            assert!(code.contains(&quoted), "event kind {} is in KINDS but nothing reports it", k.name);
        }
    }
}
