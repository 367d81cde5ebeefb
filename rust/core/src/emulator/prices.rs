//! Every compute stage's price as the budget report shows it: one call for the binding
//! ([`price_list`]), so the timing model's internals stay behind the emulator.

use crate::firmware::isr::{StageCost, StageCosts};
use crate::firmware::update_period_s;
use crate::numerics::counter::OpCounts;
use crate::profile::Profile;
use crate::timing::costs::CostTable;
use crate::timing::stages::{
    arith_for, arith_section, arith_terms, attitude_parts, entry_terms, exit_terms, location_factor, ArithSection,
    CostTerm,
};

/// One stage's price: its cycles, the operations counted (none for the interrupt's entry and
/// exit) and the terms that price them.
#[derive(Debug, Clone, PartialEq)]
pub struct StagePrice {
    /// `entry`, `decode`, `attitude`, `euler`, `navigation`, `interpolation` or `exit`.
    pub name: &'static str,
    /// SYSCLKOUT cycles.
    pub cycles: u64,
    /// The operations the stage executes (`None`: the interrupt's entry and exit, priced per step).
    pub counts: Option<OpCounts>,
    /// Each term: a count at one cost-table entry's unit cost.
    pub terms: Vec<CostTerm>,
    /// The stage's parts, in order, each priced like a stage (the DCM's attitude update:
    /// `timing::stages::attitude_parts`); empty for the others.
    pub parts: Vec<StagePrice>,
}

/// The prices of every compute stage of a profile's firmware.
#[derive(Debug, Clone, PartialEq)]
pub struct PriceList {
    /// The attitude step T, s.
    pub update_period_s: f64,
    /// The code-location factor applied to the scaled terms.
    pub code_location_factor: f64,
    /// The cost-table section of the backend's arithmetic: `float` or `iq`.
    pub arith_section: &'static str,
    /// The stages, in the ISR's order.
    pub stages: Vec<StagePrice>,
}

/// The price list of `stages` (an emulator's [`super::Emulator::stage_costs`]) for `profile` and `costs`.
pub fn price_list(profile: &Profile, costs: &CostTable, stages: &StageCosts) -> PriceList {
    let numeric = profile.firmware.numeric;
    let section = arith_section(numeric);
    let arith = arith_for(numeric, costs);
    let mut list = vec![StagePrice {
        name: "entry",
        cycles: stages.entry,
        counts: None,
        terms: entry_terms(&costs.interrupt).to_vec(),
        parts: Vec::new(),
    }];
    for (name, stage) in [
        ("decode", stages.decode),
        ("attitude", stages.attitude),
        ("euler", stages.euler),
        ("navigation", stages.navigation),
        ("interpolation", stages.interpolation),
    ] {
        let price = |name, stage: &StageCost, parts| StagePrice {
            name,
            cycles: stage.cycles,
            counts: Some(stage.counts),
            terms: arith_terms(&stage.counts, section, arith, &costs.instructions).to_vec(),
            parts,
        };
        // The profile was validated when the emulator was built: its parts count as its stages did.
        let parts = if name == "attitude" { attitude_parts(profile, costs).unwrap_or_default() } else { Vec::new() };
        let parts = parts.iter().map(|(n, c)| price(n, c, Vec::new())).collect();
        list.push(price(name, &stage, parts));
    }
    list.push(StagePrice {
        name: "exit",
        cycles: stages.exit,
        counts: None,
        terms: exit_terms(&costs.interrupt).to_vec(),
        parts: Vec::new(),
    });
    PriceList {
        // Validated when the emulator was built, as above.
        update_period_s: update_period_s(profile).unwrap_or(f64::NAN),
        code_location_factor: location_factor(profile, costs),
        arith_section: match section {
            ArithSection::Float => "float",
            ArithSection::Iq => "iq",
        },
        stages: list,
    }
}
