//! Replaying the words a physical run read gives the firmware exactly those words: the same
//! attitude, bit for bit, in every backend and schedule.

use super::tests::costs;
use super::*;
use crate::time::ps_to_s;

/// A moving, noisy board (sinusoidal rates on every axis, varying specific force), 819.2 rows/s.
fn moving(seconds: f64) -> (Vec<f64>, Vec<Physical>) {
    let n = (seconds * 819.2) as usize;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / 819.2).collect();
    let p = t
        .iter()
        .map(|&t| {
            let w = |f: f64, a: f64| a * (2.0 * std::f64::consts::PI * f * t).sin();
            Physical {
                gyro_dps: [w(1.3, 40.0), w(0.7, -25.0) + 3.0, w(2.1, 90.0)],
                accel_g: [w(0.5, 0.2), w(0.9, -0.1), 1.0 + w(1.7, 0.05)],
                ..Physical::powered_idle()
            }
        })
        .collect();
    (t, p)
}

fn physical<T: Scalar>(profile: &Profile, seconds: f64) -> Output {
    let mut emu = Emulator::<T>::new(profile, &costs()).unwrap();
    let (t, p) = moving(seconds);
    emu.push_input(&t, p).unwrap();
    emu.end_input();
    assert_eq!(emu.run().unwrap(), Progress::Finished);
    emu.take_output()
}

/// Replay the reads of `recorded` (timestamps: their CS falling edges), fed in chunks of `chunk`.
fn replay<T: Scalar>(profile: &Profile, recorded: &[ReadRow], chunk: usize) -> Output {
    let mut emu = Emulator::<T, ReplaySlave>::replay(profile, &costs()).unwrap();
    let mut out = Output::default();
    for rows in recorded.chunks(chunk) {
        let t: Vec<f64> = rows.iter().map(|r| ps_to_s(r.t_cs_ps)).collect();
        let words: Vec<[u16; 15]> = rows.iter().map(|r| r.words).collect();
        emu.push_words(&t, &words).unwrap();
        assert_eq!(emu.run().unwrap(), Progress::NeedInput);
        out.append(emu.take_output());
    }
    emu.end_input();
    assert_eq!(emu.run().unwrap(), Progress::Finished);
    out.append(emu.take_output());
    out
}

fn profile(overrides: &[&str]) -> Profile {
    let ov: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Profile::from_toml("", "replay-test", &ov).unwrap()
}

/// The replayed run equals the physical one in everything the firmware computes and in every time
/// of its ISRs; its reads carry the recorded words, the recorded row and timestamp.
fn check_replay<T: Scalar>(p: &Profile, seconds: f64) {
    let original = physical::<T>(p, seconds);
    let replayed = replay::<T>(p, &original.reads, 97);
    assert!(!original.cycles.is_empty());
    assert_eq!(replayed.cycles, original.cycles, "attitude, Euler and navigation bit for bit");
    assert_eq!(replayed.budget, original.budget, "the same ISRs at the same times");
    assert_eq!(replayed.reads.len(), original.reads.len());
    for (i, (r, o)) in replayed.reads.iter().zip(&original.reads).enumerate() {
        assert_eq!((r.tick, r.t_cs_ps, r.t_start_ps, r.t_end_ps), (o.tick, o.t_cs_ps, o.t_start_ps, o.t_end_ps));
        assert_eq!(r.words, o.words);
        assert_eq!((r.rate, r.accel, r.assumed_s), (o.rate, o.accel, o.assumed_s));
        assert_eq!((r.sample_index, r.sample_ps), (i as i64, o.t_cs_ps), "the recorded row and timestamp");
        assert_eq!(r.age_ps, o.t_start_ps - o.t_cs_ps);
    }
    // The firmware's own events (stale decodes, …) recur; nothing of the device's, nothing of the replay's.
    let firmware_kinds = |out: &Output| -> Vec<(Ps, &'static str)> {
        out.events
            .iter()
            .filter(|e| ["stale_decode", "decode_mismatch", "saturated_reading"].contains(&e.kind))
            .map(|e| (e.t_ps, e.kind))
            .collect()
    };
    assert_eq!(firmware_kinds(&replayed), firmware_kinds(&original));
    assert!(replayed.events.iter().all(|e| !e.kind.starts_with("replay_")), "{:?}", replayed.events);
}

#[test]
fn replayed_words_give_the_same_attitude_bit_for_bit() {
    let adis = "errors.preset=\"adis16407\"";
    check_replay::<f64>(&profile(&["firmware.numeric=\"f64\"", adis]), 3.0);
    check_replay::<crate::numerics::C28xF32Rn>(&profile(&[adis, "errors.seed=3"]), 3.0);
    check_replay::<f64>(&profile(&["firmware.numeric=\"f64\"", "firmware.schedule=\"back-to-back\"", adis]), 1.0);
    let iq = profile(&["firmware.numeric=\"iq\"", adis]);
    crate::numerics::iq::with_formats(&iq.iq, || check_replay::<crate::numerics::Iq>(&iq, 1.0)).unwrap();
}

#[test]
fn the_horizon_is_the_recorded_bursts() {
    let p = profile(&["firmware.numeric=\"f64\"", "firmware.schedule=\"back-to-back\""]);
    let mut emu = Emulator::<f64, ReplaySlave>::replay(&p, &costs()).unwrap();
    assert_eq!(emu.run().unwrap(), Progress::NeedInput);
    // Three bursts per tick: 7 bursts run two ticks, the seventh waits for more.
    let t: Vec<f64> = (1..=7).map(|i| i as f64 * 0.004).collect();
    emu.push_words(&t, &[[0x8000; 15]; 7]).unwrap();
    assert_eq!(emu.run().unwrap(), Progress::NeedInput);
    assert_eq!(emu.take_output().budget.len(), 2);
    // After the end a partial tick's bursts are not read.
    emu.end_input();
    assert_eq!(emu.run().unwrap(), Progress::Finished);
    let out = emu.take_output();
    assert!(out.budget.is_empty() && out.events.is_empty(), "{:?}", out.events);
}

#[test]
fn a_replay_refuses_faults_and_bad_rows() {
    let p = profile(&["faults.list=[{kind=\"sensor_reset\", start_s=1.0}]"]);
    let e = Emulator::<f64, ReplaySlave>::replay(&p, &costs()).err().unwrap().to_string();
    assert!(e.contains("faults.list") && e.contains("sensor_reset") && e.contains("bypasses the device model"), "{e}");
    let mut emu = Emulator::<f64, ReplaySlave>::replay(&profile(&[]), &costs()).unwrap();
    let e = emu.push_words(&[0.004, -0.5], &[[0; 15]; 2]).unwrap_err().to_string();
    assert!(e.contains("row 1") && e.contains("≥ 0"), "{e}");
}
