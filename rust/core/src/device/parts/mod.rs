//! The parts of the ADIS16xxx family, one declaration each (see [`super::part`]).

pub mod adis16362;
pub mod adis16407;
pub mod spi_needs;

use super::part::Part;

/// Every part the emulator knows.
pub const PARTS: [&Part; 2] = [&adis16407::PART, &adis16362::PART];

/// The part called `name` (case-insensitive).
pub fn by_name(name: &str) -> Option<&'static Part> {
    PARTS.into_iter().find(|p| p.name.eq_ignore_ascii_case(name))
}

/// The names of the known parts, for messages.
pub fn names() -> String {
    PARTS.map(|p| p.name).join(", ")
}
