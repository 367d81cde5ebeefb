//! The compute-time model and the per-cycle budget.

pub mod costs;

pub use costs::CostTable;
