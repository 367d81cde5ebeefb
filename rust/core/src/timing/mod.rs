//! The compute-time model and the per-cycle budget.

pub mod costs;

pub use costs::CostTable;
pub mod stages;
pub use crate::firmware::isr::{StageCost, StageCosts};
pub use stages::stage_costs;
