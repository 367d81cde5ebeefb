//! The parts' declarations: the ADIS16xxx family's, one [`Part`] each (see [`super::part`]), and
//! the SPI timing of the parts of other families (`adxl345`, `ads8344`: their models live in
//! `device/`).

pub mod adis16362;
pub mod adis16407;
pub mod ads8344;
pub mod adxl345;
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
