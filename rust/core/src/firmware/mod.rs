//! (filled in by the firmware work)
