//! The random streams: one xoshiro256++ stream per source of each sensor (module docs: "Random
//! streams").

use super::*;

pub(super) const SOURCE_INITIAL_BIAS: u64 = 1;
pub(super) const SOURCE_BIAS_TEMPCO: u64 = 2;
pub(super) const SOURCE_SCALE_FACTOR: u64 = 3;
pub(super) const SOURCE_SCALE_TEMPCO: u64 = 4;
pub(super) const SOURCE_NONLINEARITY: u64 = 5;
pub(super) const SOURCE_MISALIGNMENT: u64 = 6;
pub(super) const SOURCE_G_SENSITIVITY: u64 = 7;
pub(super) const SOURCE_WHITE_NOISE: u64 = 8;
pub(super) const SOURCE_BIAS_INSTABILITY: u64 = 9;
pub(super) const SOURCE_RATE_RANDOM_WALK: u64 = 10;
pub(super) const SENSOR_GYRO: u64 = 0;
pub(super) const SENSOR_ACCEL: u64 = 1;
pub(super) const SENSOR_MAG: u64 = 2;
pub(super) const SENSOR_BARO: u64 = 3;

/// The generator of every stream: xoshiro256++ (Blackman & Vigna), 2^256 − 1 period, passes
/// BigCrush and PractRand; a few ns per Gaussian draw against ≈ 12 ns for ChaCha20. Nothing here
/// needs a cryptographic generator, only independent, reproducible streams.
pub(super) type StreamRng = Xoshiro256PlusPlus;

/// The SplitMix64 output function (Steele, Lea & Flood 2014): a bijection of u64 whose outputs of
/// nearby inputs are uncorrelated, so it separates streams whose keys differ in a few bits.
pub(super) fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The random stream of one source of one sensor; `index` numbers the Gauss–Markov terms of bias
/// instability, 0 for every other source (module docs: derivation).
pub(super) fn stream(seed: u64, sensor: u64, source: u64, index: u64) -> StreamRng {
    let id = sensor << 16 | source << 8 | index;
    StreamRng::seed_from_u64(splitmix64(splitmix64(seed) ^ id))
}
