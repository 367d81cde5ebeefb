//! The compute-time model and the per-cycle budget.

pub mod costs;

pub use costs::CostTable;
pub mod stages;
pub use stages::{stage_costs, StageCost, StageCosts};
