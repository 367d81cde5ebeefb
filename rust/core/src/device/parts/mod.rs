//! The parts of the ADIS16xxx family, one declaration each (see [`super::part`]).

pub mod adis16362;
pub mod adis16407;
