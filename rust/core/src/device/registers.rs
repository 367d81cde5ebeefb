//! The ADIS16407's register map by its names (the declaration is `parts/adis16407.rs`; the types
//! are the family's, `part.rs`). Registers are 16 bits at even addresses; a write is one byte to the
//! low (even) or high (odd) address. Bits outside a register's mask read as 0 and ignore writes.

pub use super::part::{slot, Access, Format, PowerOn, RegisterDef, SLOTS};
pub use super::parts::adis16407::{addr, BURST_ORDER, REGISTERS};

/// The ADIS16407 register holding byte address `addr`, if any.
pub fn lookup(addr: u8) -> Option<&'static RegisterDef> {
    super::parts::adis16407::PART.lookup(addr)
}

/// The ADIS16407 register called `name` (case-insensitive).
pub fn by_name(name: &str) -> Option<&'static RegisterDef> {
    super::parts::adis16407::PART.by_name(name)
}
