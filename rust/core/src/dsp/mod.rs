//! (filled in by the dsp work)
