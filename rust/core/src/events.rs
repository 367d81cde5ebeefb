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
    /// Lower-case name used in reports and JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Info => "info",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// One event. `kind` is a stable snake_case identifier (documented in docs/events.md);
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
}

impl Event {
    /// An event with no rule figures.
    pub fn new(t_ps: Ps, kind: &'static str, severity: Severity, message: impl Into<String>) -> Self {
        Event { t_ps, kind, severity, message: message.into(), measured: None, required: None }
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
        Event { t_ps, kind, severity, message: message.into(), measured: Some(measured), required: Some(required) }
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
    /// Number of events of one kind.
    pub fn count(&self, kind: &str) -> usize {
        self.events.iter().filter(|e| e.kind == kind).count()
    }
}
