//! Property tests of profile overrides: random `key=value` texts (every known key, near misses and
//! junk; values of every TOML type from ordinary to absurd: i64/u64 extremes, NaN, infinities,
//! subnormals, enum names, arrays) never panic. A profile they produce either is refused with a
//! `Profile` error naming a key, or builds a board: the board report and a short emulation (f64)
//! then end in `Ok` or a documented error, never a panic.

use super::Profile;
use crate::device::Physical;
use crate::emulator::{BoardReport, Emulator};
use crate::error::Error;
use crate::timing::CostTable;
use proptest::prelude::*;

fn costs() -> CostTable {
    let text = include_str!("../../../../firmware_model/c28x-costs.toml");
    CostTable::from_toml(text, "c28x-costs.toml").unwrap_or_else(|e| panic!("reference cost table: {e}"))
}

fn key() -> impl Strategy<Value = String> {
    let known = prop::sample::select(Profile::known_keys());
    prop_oneof![
        8 => known.clone(),
        1 => known.prop_map(|k| format!("{}x", k)),
        1 => "[a-z._]{0,12}",
    ]
}

fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => any::<i64>().prop_map(|v| v.to_string()),
        2 => any::<u16>().prop_map(|v| format!("0x{v:X}")),
        6 => (0u64..300).prop_map(|v| v.to_string()),
        4 => (0.0f64..5000.0).prop_map(|v| format!("{v:?}")),
        1 => any::<u64>().prop_map(|v| v.to_string()),
        3 => any::<f64>().prop_map(|v| format!("{v:?}")),
        1 => prop::sample::select(vec!["nan", "inf", "-inf", "5e-324", "1e308", "-0.0"]).prop_map(String::from),
        4 => prop::sample::select(vec![
            "true", "false", "\"rk4\"", "rotation-vector", "level", "zero", "bit", "iq", "c28x-f32-rz",
            "endpoint", "back-to-back", "nest", "drop", "flash", "lenient", "adis16407", "[0.0, 0.0, 0.0]",
            "[1, 2]", "{a = 1}", "\"\"", "",
        ])
        .prop_map(String::from),
    ]
}

fn short_input(seconds: f64) -> (Vec<f64>, Vec<Physical>) {
    let n = (seconds * 819.2) as usize;
    let t = (0..n).map(|k| k as f64 / 819.2).collect();
    let p = Physical { gyro_dps: [10.0, -5.0, 2.0], accel_g: [0.0, 0.0, 1.0], ..Physical::powered_idle() };
    (t, vec![p; n])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2048))]

    #[test]
    fn random_overrides_are_an_error_or_a_board_that_runs(
        overrides in prop::collection::vec((key(), value()).prop_map(|(k, v)| format!("{k}={v}")), 1..3),
    ) {
        let profile = match Profile::from_toml("", "proptest", &overrides) {
            Ok(p) => p,
            Err(Error::Profile(m)) => {
                prop_assert!(m.starts_with("proptest: ") || m.starts_with("override `"), "{}", m);
                return Ok(());
            }
            Err(e) => return Err(TestCaseError::fail(format!("not a profile error: {e}"))),
        };
        let costs = costs();
        // Errors are fine (a configuration the hardware cannot realise); panics are not.
        let _ = BoardReport::of(&profile, &costs);
        if let Ok(mut emu) = Emulator::<f64>::new(&profile, &costs) {
            let (t, p) = short_input(0.05);
            if emu.push_input(&t, p).is_ok() {
                emu.end_input();
                let _ = emu.run();
                let out = emu.take_output();
                for row in &out.cycles {
                    prop_assert!(row.quat.iter().all(|q| !q.is_nan()), "NaN quaternion at {} ps", row.t_ps);
                }
            }
        }
    }
}
