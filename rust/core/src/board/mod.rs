//! The board the firmware runs on, below the firmware: the sensor at the other end of SPI-A (the
//! device model fed a physical input, or a replay of recorded words), that input's feed, and the
//! faults of the wiring (`dropped_burst`: CS glitches).

pub(crate) mod glitch;
pub mod input;
pub mod sensor;

pub use input::{InputFeed, StreamStimulus};
pub use sensor::{FrameSummary, Reach, Sensor, StreamedDevice};
