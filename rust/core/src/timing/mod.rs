//! (filled in by the timing work)
