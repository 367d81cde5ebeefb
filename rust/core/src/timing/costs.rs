//! The cycle-cost table (`firmware_model/c28x-costs.toml`): SYSCLKOUT cycles per operation class.
//! The numbers and their sources live in the TOML file; this module only types and checks them.

use crate::error::{Error, Result};
use serde::Deserialize;

/// Interrupt entry and exit costs.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InterruptCosts {
    /// Automatic context save before the first ISR instruction.
    pub hw_context_save: u32,
    /// Compiler-generated ISR prologue.
    pub c_prologue: u32,
    /// Compiler-generated ISR epilogue.
    pub c_epilogue: u32,
    /// IRET.
    pub iret: u32,
    /// Acknowledging the PIE group.
    pub pie_ack: u32,
}

/// Register and memory access costs of the acquisition code.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IoCosts {
    /// A GPIO data write (chip select).
    pub gpio_write: u32,
    /// A peripheral register read.
    pub peripheral_read: u32,
    /// A peripheral register write.
    pub peripheral_write: u32,
    /// A function call and its return.
    pub call_return: u32,
    /// A store of one received word into the firmware's array.
    pub store_word: u32,
    /// The burst loop's own overhead per frame (increment, compare, branch).
    pub frame_loop: u32,
}

/// Costs of the arithmetic operation classes of one numeric backend.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArithCosts {
    /// Addition or subtraction.
    pub add: u32,
    /// Multiplication.
    pub mul: u32,
    /// Negation.
    pub neg: u32,
    /// Absolute value.
    pub abs: u32,
    /// Comparison and conditional branch.
    pub compare: u32,
    /// Division.
    pub div: u32,
    /// Square root.
    pub sqrt: u32,
    /// Sine.
    pub sin: u32,
    /// Cosine.
    pub cos: u32,
    /// Arc tangent.
    pub atan: u32,
    /// Four-quadrant arc tangent.
    pub atan2: u32,
    /// Arc sine.
    pub asin: u32,
    /// Integer to the backend's type.
    pub int_to_float: u32,
    /// The backend's type to integer.
    pub float_to_int: u32,
    /// Loading a constant.
    pub constant: u32,
    /// An integer times a value of the backend's type (`_IQmpyI32`; on float counted as its conversion
    /// and multiplication instead).
    pub mul_i32: u32,
    /// Changing Q format (fixed point only).
    #[serde(default)]
    pub requantise: u32,
}

/// The integer, memory and control instructions of compiled C (`[instructions]`): what the firmware
/// does beside its arithmetic (the model's counted work, [`crate::numerics::counter::Work`], and the
/// build's LLVM pass pricing a host-built C firmware's blocks: one table for both).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InstructionCosts {
    /// An integer add, subtract, logic, shift, compare or extension.
    pub int: u32,
    /// A 32-bit integer multiplication.
    pub mul: u32,
    /// A 64-bit integer multiplication (RTS).
    pub mul64: u32,
    /// A 32-bit integer division or remainder (RTS).
    pub div: u32,
    /// A 64-bit integer division or remainder (RTS).
    pub div64: u32,
    /// A conditional move.
    pub select: u32,
    /// A load from data memory, per 32 bits.
    pub load: u32,
    /// A store to data memory, per 32 bits.
    pub store: u32,
    /// The data memory's wait states per load.
    pub data_wait: u32,
    /// An unconditional branch.
    pub branch: u32,
    /// A conditional branch.
    pub cond_branch: u32,
    /// A call (LCR).
    pub call: u32,
    /// A return (LRETR).
    pub ret: u32,
    /// A block copy's set-up.
    pub block_copy_setup: u32,
}

/// Code-location factors.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MemoryCosts {
    /// Multiplier for code in zero-wait-state RAM.
    pub ram_factor: f64,
    /// Multiplier for code in flash with wait states.
    pub flash_factor: f64,
}

/// The whole cost table.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CostTable {
    /// Interrupt entry and exit.
    pub interrupt: InterruptCosts,
    /// Register and memory access.
    pub io: IoCosts,
    /// Single-precision FPU arithmetic (also used to cost the f64 reference as if it ran on the target).
    pub float: ArithCosts,
    /// IQmath fixed-point arithmetic.
    pub iq: ArithCosts,
    /// Integer, memory and control instructions.
    pub instructions: InstructionCosts,
    /// Code-location factors.
    pub memory: MemoryCosts,
}

impl CostTable {
    /// Parse and check a cost table; `source` names the file in errors.
    pub fn from_toml(text: &str, source: &str) -> Result<CostTable> {
        let table: CostTable =
            toml::from_str(text).map_err(|e| Error::Profile(format!("{source}: {}", e.message())))?;
        for (key, v) in
            [("memory.ram_factor", table.memory.ram_factor), ("memory.flash_factor", table.memory.flash_factor)]
        {
            if !(v.is_finite() && (0.1..=100.0).contains(&v)) {
                return Err(Error::Profile(format!("{source}: key `{key}` = {v}: expected a factor in 0.1…100")));
            }
        }
        Ok(table)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/c28x-costs.toml");

    #[test]
    fn shipped_table_parses() {
        let text = std::fs::read_to_string(FILE).unwrap();
        let t = CostTable::from_toml(&text, "c28x-costs.toml").unwrap();
        assert_eq!(t.interrupt.hw_context_save, 14);
        assert_eq!(t.float.div, 24);
        assert_eq!(t.iq.div, 62);
        assert_eq!((t.instructions.call, t.instructions.ret), (4, 8));
    }

    #[test]
    fn unknown_key_is_named() {
        let text = std::fs::read_to_string(FILE).unwrap().replace("iret = 8", "iret = 8\nirett = 1");
        let e = CostTable::from_toml(&text, "c.toml").unwrap_err().to_string();
        assert!(e.contains("c.toml") && e.contains("irett"), "{e}");
    }
}
