//! The `[serial.*]` sections: what arrives on the SCI ports' receive pins from outside the board
//! in a host-built firmware's run (`rust/core/src/dsp/sci.rs`), e.g. a GPS's NMEA sentences on
//! SCI-B. Absent by default: a port hears nothing.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// The three ports' receive feeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Serial {
    /// SCI-A.
    pub sci_a: SerialRx,
    /// SCI-B.
    pub sci_b: SerialRx,
    /// SCI-C.
    pub sci_c: SerialRx,
}

/// One port's receive feed: a file's bytes sent 8N1 at `rx_baud`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SerialRx {
    /// The file whose bytes arrive (empty: none). A relative path is taken from the working
    /// directory.
    pub rx_file: String,
    /// The sender's baud (8 data bits, no parity, 1 stop bit).
    pub rx_baud: u32,
    /// When the first character's start bit comes, s after power-on.
    pub rx_start_s: f64,
    /// 0: the bytes come back to back. > 0: each line (up to and with its `\n`) starts this long
    /// after the one before, as a GPS sends a sentence per epoch.
    pub rx_line_period_s: f64,
}

impl Default for SerialRx {
    fn default() -> Self {
        SerialRx { rx_file: String::new(), rx_baud: 9600, rx_start_s: 0.0, rx_line_period_s: 0.0 }
    }
}

impl Serial {
    /// Whether nothing is set (the section is then left out of the profile's text).
    pub fn is_default(&self) -> bool {
        *self == Serial::default()
    }

    /// The ports' feeds with their key prefixes, A to C.
    pub fn ports(&self) -> [(&'static str, &SerialRx); 3] {
        [("serial.sci_a", &self.sci_a), ("serial.sci_b", &self.sci_b), ("serial.sci_c", &self.sci_c)]
    }

    /// Every key, dotted (for the profile's key check).
    pub fn keys() -> Vec<String> {
        let mut out = Vec::new();
        for p in ["sci_a", "sci_b", "sci_c"] {
            for k in ["rx_file", "rx_baud", "rx_start_s", "rx_line_period_s"] {
                out.push(format!("serial.{p}.{k}"));
            }
        }
        out
    }

    /// The values against what a UART line allows; a named file must be readable.
    pub fn validate(&self) -> Result<()> {
        for (key, p) in self.ports() {
            let bad =
                |k: &str, v: String, want: &str| Err(Error::Profile(format!("key `{key}.{k}` = {v}: expected {want}")));
            if !(300..=4_000_000).contains(&p.rx_baud) {
                return bad("rx_baud", p.rx_baud.to_string(), "300…4000000 Bd");
            }
            if !(p.rx_start_s.is_finite() && p.rx_start_s >= 0.0) {
                return bad("rx_start_s", p.rx_start_s.to_string(), "a time ≥ 0 s");
            }
            if !(p.rx_line_period_s.is_finite() && p.rx_line_period_s >= 0.0) {
                return bad("rx_line_period_s", p.rx_line_period_s.to_string(), "0 (back to back) or a period > 0 s");
            }
            if !p.rx_file.is_empty() {
                if let Err(e) = std::fs::metadata(&p.rx_file).and_then(|m| {
                    if m.is_file() {
                        Ok(())
                    } else {
                        Err(std::io::Error::other("not a file"))
                    }
                }) {
                    return bad("rx_file", format!("\"{}\"", p.rx_file), &format!("a readable file ({e})"));
                }
            }
        }
        Ok(())
    }
}
