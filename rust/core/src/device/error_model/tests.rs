use super::*;
use rand_distr::StandardNormal;

/// The default internal sample period, 1/819.2 s.
const DT: f64 = 1.0 / 819.2;

/// A physical input that changes every sample (rates, forces, field, temperature).
fn moving_input(k: u64) -> Physical {
    let s = k as f64 * DT;
    Physical {
        gyro_dps: [10.0 * (3.0 * s).sin(), -5.0 + s, 120.0 * (0.5 * s).cos()],
        accel_g: [0.1 * s.sin(), -0.2, -1.0 + 0.01 * s],
        mag_gauss: [0.3, -0.05 * s.cos(), 0.4],
        baro_mbar: 1013.25 - 0.01 * s,
        temp_c: 25.0 + 20.0 * (0.1 * s).sin(),
        supply_v: 5.0,
        aux_v: 1.0,
    }
}

fn run(model: &mut ErrorModel, n: u64) -> Vec<Physical> {
    (0..n)
        .map(|k| {
            let mut p = moving_input(k);
            model.apply(k, 0, &mut p);
            p
        })
        .collect()
}

fn bits(p: &Physical) -> Vec<u64> {
    let mut v: Vec<u64> = p.gyro_dps.iter().chain(&p.accel_g).chain(&p.mag_gauss).map(|x| x.to_bits()).collect();
    v.extend([p.baro_mbar, p.temp_c, p.supply_v, p.aux_v].map(f64::to_bits));
    v
}

fn model(params: &ErrorParams, seed: u64) -> ErrorModel {
    ErrorModel::new(params, seed, DT).unwrap()
}

#[test]
fn same_seed_is_bit_identical_and_other_seeds_differ() {
    let params = ErrorParams::adis16407();
    let a = run(&mut model(&params, 7), 5000);
    let b = run(&mut model(&params, 7), 5000);
    assert!(a.iter().zip(&b).all(|(x, y)| bits(x) == bits(y)));
    let c = run(&mut model(&params, 8), 5000);
    // Every gyro/accel/mag/baro value carries independent white noise: all must differ.
    let differing = a.iter().zip(&c).filter(|(x, y)| x.gyro_dps != y.gyro_dps && x.baro_mbar != y.baro_mbar).count();
    assert_eq!(differing, 5000);
}

#[test]
fn ideal_is_the_identity() {
    let mut m = ErrorModel::from_profile(&Errors::default(), DT).unwrap();
    assert!(m.is_identity());
    for k in 0..1000 {
        let mut p = moving_input(k);
        p.gyro_dps[0] = f64::INFINITY;
        p.accel_g[1] = -0.0;
        let before = bits(&p);
        m.apply(k, 0, &mut p);
        assert_eq!(bits(&p), before);
    }
    // A flicker bank of zero floor is still ideal.
    let mut params = ErrorParams::ideal();
    params.gyro.bias_instability =
        BiasInstability::Flicker { allan_floor: 0.0, tau_min_s: 1.0, tau_max_s: 10.0, terms_per_decade: 1 };
    assert!(model(&params, 1).is_identity());
    assert!(!model(&ErrorParams::adis16407(), 1).is_identity());
}

/// Per-axis white noise of the gyro only, with zero input: returns the output samples per axis.
fn gyro_samples(params: &ErrorParams, seed: u64, n: usize, k_step: u64) -> [Vec<f64>; 3] {
    let mut m = model(params, seed);
    let mut out: [Vec<f64>; 3] = Default::default();
    for i in 0..n as u64 {
        let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
        m.apply(i * k_step, 0, &mut p);
        for (axis, v) in out.iter_mut().zip(p.gyro_dps) {
            axis.push(v);
        }
    }
    out
}

#[test]
fn white_noise_sigma_is_density_times_root_fs() {
    let mut params = ErrorParams::ideal();
    params.gyro.noise_density = 2.0 / 60.0; // 2 °/√h
    let sigma = params.gyro.noise_density * (1.0 / DT).sqrt();
    assert!((sigma - 0.954).abs() < 1e-3);
    let n = 200_000;
    // Known zero mean: n·s²/σ² ~ χ²(n), so s/σ has std 1/√(2n) = 0.0016; the mean has std σ/√n.
    for axis in gyro_samples(&params, 3, n, 1) {
        let mean = axis.iter().sum::<f64>() / n as f64;
        let rms = (axis.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
        assert!((rms / sigma - 1.0).abs() < 5.0 / (2.0 * n as f64).sqrt(), "rms {rms} vs σ {sigma}");
        assert!(mean.abs() < 5.0 * sigma / (n as f64).sqrt(), "mean {mean}");
    }
}

#[test]
fn gauss_markov_variance_and_lag_one_correlation_match_theory() {
    let term = GaussMarkov { sigma: 0.5, tau_s: 10.0 * DT };
    let mut params = ErrorParams::ideal();
    params.gyro.bias_instability = BiasInstability::GaussMarkov { terms: vec![term] };
    let n = 400_000;
    // k_step > 1 exercises the exact propagation over gaps: the lag-1 correlation becomes a^step.
    for k_step in [1u64, 3] {
        let a = (-(k_step as f64) * DT / term.tau_s).exp();
        for axis in gyro_samples(&params, 11, n, k_step) {
            assert_ar1(&axis, term.sigma, a, &format!("step {k_step}"));
        }
    }
}

/// `x` (n values) is a stationary AR(1) of standard deviation `sigma` and lag-1 correlation `a`:
/// var(s²)/σ⁴ = (2/n)(1 + a²)/(1 − a²) and var(r̂₁) = (1 − a²)/n by theory; bounds are 5σ.
fn assert_ar1(x: &[f64], sigma: f64, a: f64, what: &str) {
    let n = x.len() as f64;
    let var_tol = 5.0 * (2.0 / n * (1.0 + a * a) / (1.0 - a * a)).sqrt();
    let rho_tol = 5.0 * ((1.0 - a * a) / n).sqrt();
    let power = x.iter().map(|v| v * v).sum::<f64>();
    let variance = power / n;
    let rho = x.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / power;
    let s2 = sigma * sigma;
    assert!((variance / s2 - 1.0).abs() < var_tol, "{what}: variance {variance} vs {s2}");
    assert!((rho - a).abs() < rho_tol, "{what}: lag-1 {rho} vs {a}");
}

#[test]
fn update_interval_is_the_largest_power_of_two_within_tau_over_r() {
    let r = DEFAULT_GAUSS_MARKOV_UPDATE_RATIO;
    let intervals: Vec<u64> =
        flicker_bank(0.007, 1.0, 1e5, 1).iter().map(|t| gauss_markov_update_interval(t.tau_s, DT, r)).collect();
    // τ/(R·Δt) = 8.2, 82, 819, 8192, 81920, 819200 samples (module docs numbers).
    assert_eq!(intervals, [8, 64, 512, 8192, 65536, 524288]);
    for m in [1u64, 2, 64, 1 << 20] {
        // Exactly on the bound m is allowed; a hair below it, m/2 (and never below 1).
        let tau = r * m as f64 * DT;
        assert_eq!(gauss_markov_update_interval(tau, DT, r), m);
        assert_eq!(gauss_markov_update_interval(tau * (1.0 - 1e-9), DT, r), (m / 2).max(1));
    }
    assert_eq!(gauss_markov_update_interval(1e-9, DT, r), 1);
    assert_eq!(gauss_markov_update_interval(1e300, DT, r), 1 << MAX_UPDATE_SHIFT);
    // A huge R is the per-sample process for every τ of the preset.
    assert_eq!(gauss_markov_update_interval(1e5, DT, 1e12), 1);
}

#[test]
fn hold_moves_the_structure_function_by_at_most_the_documented_bound() {
    // Module docs: with a random hold phase, D_held(s) = 2σ²·E[1 − a^N] (N = n or n + 1 updates
    // in s = (n + f)·T, P(N = n + 1) = f) is the chord of D(s) = 2σ²(1 − e^{−s/τ}), at most
    // σ²ε²/4 below it; summed over the adis16407 gyro bank that is 8.1e-9 (°/s)², 1.7e-4 of the
    // floor's Allan variance. Checked here on a dense grid of s, not from the formula.
    let floor = 0.007;
    let mut total = 0.0;
    for term in flicker_bank(floor, 1.0, 1e5, 1) {
        let m = gauss_markov_update_interval(term.tau_s, DT, DEFAULT_GAUSS_MARKOV_UPDATE_RATIO);
        let period = m as f64 * DT;
        let eps = period / term.tau_s;
        let s2 = term.sigma * term.sigma;
        let mut largest = 0.0f64;
        for i in 0..20_000 {
            let s = i as f64 * period / 997.0; // 20 intervals, 997 points each
            let (n, f) = ((s / period).floor(), (s / period).fract());
            let held = 2.0 * s2 * ((1.0 - f) * -(-n * eps).exp_m1() + f * -(-(n + 1.0) * eps).exp_m1());
            let exact = 2.0 * s2 * -(-s / term.tau_s).exp_m1();
            assert!(held <= exact * (1.0 + 1e-12), "τ {}: chord above the curve at s = {s}", term.tau_s);
            largest = largest.max(exact - held);
        }
        let bound = s2 * eps * eps / 4.0;
        // The bound is reached to within 1 % (mid-interval of the first one) and never exceeded.
        assert!(largest <= bound && largest > 0.99 * bound, "τ {}: {largest} vs {bound}", term.tau_s);
        total += bound;
    }
    assert!((total / 8.15e-9 - 1.0).abs() < 0.01, "{total}");
    assert!(total / (floor * floor) < 1.7e-4);
}

/// Gyro of an otherwise ideal sensor with the given Gauss–Markov terms and update ratio.
fn gauss_markov_only(terms: Vec<GaussMarkov>, update_ratio: f64) -> ErrorParams {
    let mut params = ErrorParams::ideal();
    params.gyro.bias_instability = BiasInstability::GaussMarkov { terms };
    params.gauss_markov_update_ratio = update_ratio;
    params
}

#[test]
fn a_fast_term_keeps_the_per_sample_process_exactly() {
    // τ = 10 Δt < 2·R·Δt: m = 1. The model's output is then today's recursion bit for bit,
    // from the term's own stream, including the exact propagation over gaps.
    let term = GaussMarkov { sigma: 0.3, tau_s: 10.0 * DT };
    assert_eq!(gauss_markov_update_interval(term.tau_s, DT, DEFAULT_GAUSS_MARKOV_UPDATE_RATIO), 1);
    let mut m = model(&gauss_markov_only(vec![term], DEFAULT_GAUSS_MARKOV_UPDATE_RATIO), 9);
    let mut rng = stream(9, SENSOR_GYRO, SOURCE_BIAS_INSTABILITY, 0);
    let mut x = [(); 3].map(|()| term.sigma * rng.sample::<f64, _>(StandardNormal));
    let mut last = 0;
    for k in (0..3000u64).map(|i| i + i / 7 * 3) {
        if k > last {
            let (decay, drive) = gauss_markov_step(&term, (k - last) as f64 * DT);
            x = x.map(|x| decay * x + drive * rng.sample::<f64, _>(StandardNormal));
        }
        last = k;
        let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
        m.apply(k, 0, &mut p);
        assert_eq!(p.gyro_dps.map(f64::to_bits), x.map(f64::to_bits), "sample {k}");
    }
}

#[test]
fn multi_rate_terms_are_stationary_and_held_between_updates() {
    // R = 1 holds each term as long as allowed (m·Δt ≤ τ), so a = e^{−mΔt/τ} = e^{−0.8} is far
    // from 1 and the AR(1) bounds are tight. The term sits at bank index 1 behind a zero term.
    for (tau_samples, m, updates) in [(5.0, 4u64, 200_000u64), (20.0, 16, 100_000)] {
        let term = GaussMarkov { sigma: 0.2, tau_s: tau_samples * DT };
        assert_eq!(gauss_markov_update_interval(term.tau_s, DT, 1.0), m);
        let params = gauss_markov_only(vec![GaussMarkov { sigma: 0.0, tau_s: 1.0 }, term], 1.0);
        let a = (-(m as f64) * DT / term.tau_s).exp();
        // Calls every sample (one update per interval), then every 3m samples (three updates
        // per call, propagated exactly in one step: the lag-1 correlation becomes a³).
        for calls_per_update in [m, 1] {
            let k_step = if calls_per_update == m { 1 } else { 3 * m };
            let a_step = if k_step == 1 { a } else { a.powi(3) };
            let n = updates as usize;
            let per_axis = gyro_samples(&params, 17, n * calls_per_update as usize, k_step);
            for axis in per_axis {
                // Held: every sample of an interval repeats the value of its update instant.
                let at_updates: Vec<f64> = axis.iter().step_by(calls_per_update as usize).copied().collect();
                for (i, v) in axis.iter().enumerate() {
                    assert_eq!(v.to_bits(), at_updates[i / calls_per_update as usize].to_bits());
                }
                // AR(1) theory at the update instants, as in the per-sample test.
                assert_ar1(&at_updates, term.sigma, a_step, &format!("m {m} step {k_step}"));
            }
        }
    }
}

#[test]
fn gaps_within_update_intervals_keep_the_realisation() {
    // The adis16407 bank alone (fastest term m = 8). Visiting only k % 8 ∈ {0, 3, 5} still
    // passes every update instant one at a time, so the values at the visited samples are
    // those of the contiguous run, bit for bit.
    let mut params = ErrorParams::ideal();
    params.gyro.bias_instability = ErrorParams::adis16407().gyro.bias_instability;
    params.accel.bias_instability = ErrorParams::adis16407().accel.bias_instability;
    let sample = |m: &mut ErrorModel, k: u64| {
        let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
        m.apply(k, 0, &mut p);
        (p.gyro_dps.map(f64::to_bits), p.accel_g.map(f64::to_bits))
    };
    let mut contiguous = model(&params, 4);
    let mut gapped = model(&params, 4);
    let n = 1 << 17; // two updates of the m = 65536 term
    let mut changes = 0;
    let mut previous = sample(&mut gapped, 0);
    let _ = sample(&mut contiguous, 0);
    for k in 1..n {
        let want = sample(&mut contiguous, k);
        if [0, 3, 5].contains(&(k % 8)) {
            let got = sample(&mut gapped, k);
            assert_eq!(got, want, "sample {k}");
            changes += usize::from(got != previous);
            previous = got;
        }
    }
    // The bank moves at every update of its fastest term (k % 8 == 0), and only then.
    assert_eq!(changes, (n as usize - 1) / 8);
}

#[test]
fn the_slow_bias_is_its_parts_sum_after_every_change() {
    // A gyro whose slow parts move (Gauss–Markov bank, a tempco and a temperature that changes
    // every 7th sample; with and without a rate random walk, which moves at every sample and would
    // hide the others), moved by single samples and gaps: after each sample the cached sum must be
    // the sum of the parts now, bit for bit.
    for rate_random_walk in [0.0, 0.01] {
        let mut params = ErrorParams::adis16407();
        params.gyro.rate_random_walk = rate_random_walk;
        let mut model = ErrorModel::new(&params, 5, DT).unwrap();
        let (mut k, mut moves) = (0, 0);
        for n in 0..5000u64 {
            k += if n % 97 == 0 { 1000 } else { 1 };
            let mut p = Physical { temp_c: 25.0 + (n / 7) as f64 * 0.01, ..Physical::powered_idle() };
            let before = model.gyro.slow_bias;
            model.apply(k, 0, &mut p);
            let g = &model.gyro;
            let parts: [f64; 3] = std::array::from_fn(|i| g.fixed_bias[i] + g.gauss_markov_sum[i] + g.rate_walk[i]);
            assert_eq!(g.slow_bias.map(f64::to_bits), parts.map(f64::to_bits), "walk {rate_random_walk}, sample {k}");
            moves += usize::from(g.slow_bias != before);
        }
        // Without the walk: a temperature change every 7 samples, an update every 8.
        assert!(moves > 1200, "walk {rate_random_walk}: the slow bias moved at only {moves} samples");
    }
}

/// The bank's update by the definition: every term, due when the move passes a multiple of its
/// interval, then the sum afresh (the reference for the due-term shortcut).
fn update_every_term(triad: &mut Triad, from: u64, to: u64) {
    for term in &mut triad.gauss_markov {
        let updates = (to >> term.shift) - (from >> term.shift);
        if updates > 0 {
            let (decay, drive) = gauss_markov_step(&term.params, DT * updates as f64 * (1u64 << term.shift) as f64);
            let w = [(); 3].map(|()| standard_normal(&mut term.rng));
            for (x, w) in term.state.iter_mut().zip(w) {
                *x = decay * *x + drive * w;
            }
        }
    }
    triad.gauss_markov_sum = sum_states(&triad.gauss_markov);
}

#[test]
fn due_terms_are_those_of_the_plain_loop_over_every_term() {
    // Banks: the adis16407 flicker bank (shifts ascending: the loop stops at the first term not
    // due) and a shuffled one with repeated shifts (not ascending: every term is looked at).
    // Moves: mostly single samples, gaps of up to 1000 samples, jumps of up to 2^21 (past
    // every interval), and restarts (k goes back, as `ErrorModel::apply` allows).
    let flicker = ErrorParams::adis16407().gyro.bias_instability;
    let shuffled = BiasInstability::GaussMarkov {
        terms: [1e3, 0.1, 50.0, 0.1, 1e5, 2e-3, 50.0]
            .map(|tau_s: f64| GaussMarkov { sigma: 0.01 * tau_s.sqrt(), tau_s })
            .to_vec(),
    };
    for (bank, ascending) in [(flicker, true), (shuffled, false)] {
        let mut errors = InertialErrors::ideal(300.0);
        errors.bias_instability = bank;
        for update_ratio in [DEFAULT_GAUSS_MARKOV_UPDATE_RATIO, 1.0] {
            let mut fast = Triad::new(&errors, 11, SENSOR_GYRO, DT, update_ratio);
            assert_eq!(fast.shifts_ascending, ascending);
            let mut plain = fast.clone();
            let mut steps = Xoshiro256PlusPlus::seed_from_u64(5);
            let (mut last, mut restarts, mut multi_updates) = (0u64, 0, 0);
            for _ in 0..200_000 {
                let k = match steps.gen_range(0..1000) {
                    0..=979 => last + 1,
                    980..=994 => last + steps.gen_range(2..1000),
                    995..=997 => last + steps.gen_range(1000..1 << 21),
                    _ => {
                        restarts += 1;
                        fast.next_update = 0;
                        steps.gen_range(0..=last)
                    }
                };
                if k > last {
                    multi_updates += usize::from(
                        (k >> fast.shortest_shift.unwrap_or(0)) - (last >> fast.shortest_shift.unwrap_or(0)) > 1,
                    );
                    fast.advance(last, k, DT);
                    update_every_term(&mut plain, last, k);
                    let states =
                        |t: &Triad| t.gauss_markov.iter().flat_map(|g| g.state.map(f64::to_bits)).collect::<Vec<_>>();
                    assert_eq!(states(&fast), states(&plain), "move {last} -> {k}");
                    assert_eq!(fast.gauss_markov_sum.map(f64::to_bits), plain.gauss_markov_sum.map(f64::to_bits));
                }
                last = k;
            }
            assert!(restarts > 100 && multi_updates > 1000, "{restarts} restarts, {multi_updates} multi-update moves");
        }
    }
}

#[test]
fn each_triad_moves_as_if_it_were_alone() {
    // The model moves both triads when either is due (`next_bias_move`): a triad's output must
    // not depend on the other's schedule. Gyro: the flicker bank (shortest interval 8 samples);
    // accelerometer: terms of intervals 2 and 32 samples, then also a rate random walk (due every
    // sample). Each is compared with a model where the other triad is ideal, over single samples,
    // gaps, jumps and restarts.
    let mut params = ErrorParams::ideal();
    params.gyro.bias_instability = ErrorParams::adis16407().gyro.bias_instability;
    let accel_terms = [3.0, 40.0].map(|m: f64| GaussMarkov { sigma: 1e-3, tau_s: m * DT * 100.0 }).to_vec();
    params.accel.bias_instability = BiasInstability::GaussMarkov { terms: accel_terms };
    let mut walking = params.clone();
    walking.accel.rate_random_walk = 1e-4;
    for params in [params, walking] {
        let mut gyro_alone = params.clone();
        gyro_alone.accel = ErrorParams::ideal().accel;
        let mut accel_alone = params.clone();
        accel_alone.gyro = ErrorParams::ideal().gyro;
        let mut models = [&params, &gyro_alone, &accel_alone].map(|p| model(p, 3));
        let mut steps = Xoshiro256PlusPlus::seed_from_u64(8);
        let (mut k, mut last_accel) = (0u64, [0u64; 3]);
        for _ in 0..100_000 {
            let moved = match steps.gen_range(0..1000) {
                0..=979 => 1,
                980..=994 => steps.gen_range(2..1000),
                995..=997 => steps.gen_range(1000..1 << 21),
                _ => 0,
            };
            k = if moved == 0 { steps.gen_range(0..=k) } else { k + moved };
            let [both, gyro, accel] = models.each_mut().map(|m| {
                let mut p = Physical { temp_c: REFERENCE_TEMP_C, ..Physical::default() };
                m.apply(k, 0, &mut p);
                (p.gyro_dps.map(f64::to_bits), p.accel_g.map(f64::to_bits))
            });
            assert_eq!(both.0, gyro.0, "gyro at sample {k}");
            assert_eq!(both.1, accel.1, "accelerometer at sample {k}");
            if params.accel.rate_random_walk > 0.0 && moved > 0 {
                assert_ne!(accel.1, last_accel, "the walk stood still at sample {k}");
            }
            last_accel = accel.1;
        }
    }
}

#[test]
fn update_ratio_is_checked_and_reaches_the_model_from_the_profile() {
    for bad_ratio in [0.5, f64::NAN, f64::INFINITY] {
        let errors = Errors { gauss_markov_update_ratio: bad_ratio, ..Errors::default() };
        let err = errors.validate().unwrap_err().to_string();
        assert!(err.contains("errors.gauss_markov_update_ratio"), "{err}");
        assert!(ErrorModel::from_profile(&errors, DT).is_err());
    }
    // R = 1e12 from the profile is the per-sample bank: the same realisation as ErrorModel::new
    // with that ratio, and another one than the default R.
    let errors = Errors { preset: "adis16407".into(), seed: 3, gauss_markov_update_ratio: 1e12 };
    let mut params = ErrorParams::adis16407();
    params.gauss_markov_update_ratio = 1e12;
    let per_sample = run(&mut ErrorModel::from_profile(&errors, DT).unwrap(), 200);
    assert_eq!(
        per_sample.iter().map(bits).collect::<Vec<_>>(),
        run(&mut model(&params, 3), 200).iter().map(bits).collect::<Vec<_>>()
    );
    let default = run(&mut model(&ErrorParams::adis16407(), 3), 200);
    assert_ne!(per_sample.iter().map(bits).collect::<Vec<_>>(), default.iter().map(bits).collect::<Vec<_>>());
}

#[test]
fn sources_have_independent_streams() {
    // white only (A), white + bias processes + constants (B), bias processes + constants (C):
    // B − C must be A's noise, so adding sources did not change the white-noise realisation.
    let mut white = ErrorParams::ideal();
    white.gyro.noise_density = 0.03;
    let mut rest = ErrorParams::ideal();
    rest.gyro.initial_bias = Spread::normal(3.0);
    rest.gyro.bias_instability = BiasInstability::GaussMarkov { terms: vec![GaussMarkov { sigma: 0.1, tau_s: 0.5 }] };
    rest.gyro.rate_random_walk = 0.01;
    let mut both = rest.clone();
    both.gyro.noise_density = white.gyro.noise_density;
    let zero = || Physical { temp_c: 25.0, ..Physical::default() };
    let (mut a, mut b, mut c) = (model(&white, 5), model(&both, 5), model(&rest, 5));
    for k in 0..2000 {
        let (mut pa, mut pb, mut pc) = (zero(), zero(), zero());
        a.apply(k, 0, &mut pa);
        b.apply(k, 0, &mut pb);
        c.apply(k, 0, &mut pc);
        for i in 0..3 {
            assert!((pb.gyro_dps[i] - pc.gyro_dps[i] - pa.gyro_dps[i]).abs() < 1e-12);
        }
    }
    assert_eq!(b.gyro_unit().bias, c.gyro_unit().bias);
}

#[test]
fn misalignment_is_a_small_angle_matrix_within_the_axis_to_axis_bound() {
    let params = ErrorParams::adis16407();
    let bound = 0.05f64.to_radians();
    let element = params.gyro.misalignment_deg.width.to_radians();
    let mut largest = 0.0f64;
    for seed in 0..200 {
        let mut only_misalignment = ErrorParams::ideal();
        only_misalignment.gyro.misalignment_deg = params.gyro.misalignment_deg;
        let mut m = model(&only_misalignment, seed);
        // Column j of M is the response to a unit rate about axis j.
        let columns: Vec<[f64; 3]> = (0..3)
            .map(|j| {
                let mut p = Physical { temp_c: 25.0, ..Physical::default() };
                p.gyro_dps[j] = 1.0;
                m.apply(j as u64, 0, &mut p);
                p.gyro_dps
            })
            .collect();
        let measured: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| columns[j][i]));
        assert_eq!(measured, m.gyro_unit().axes);
        for i in 0..3 {
            assert_eq!(measured[i][i], 1.0);
            for j in (0..3).filter(|&j| j != i) {
                assert!(measured[i][j].abs() <= element);
                // Angle between sensing axes i and j: 90° − (m_ij + m_ji) to second order.
                let (ri, rj) = (measured[i], measured[j]);
                let dot: f64 = (0..3).map(|c| ri[c] * rj[c]).sum();
                let norm = |r: [f64; 3]| r.iter().map(|x| x * x).sum::<f64>().sqrt();
                let deviation = PI / 2.0 - (dot / (norm(ri) * norm(rj))).acos();
                assert!((deviation - (measured[i][j] + measured[j][i])).abs() < 3.0 * element * element);
                assert!(deviation.abs() <= bound + 3.0 * element * element);
                largest = largest.max(deviation.abs());
            }
        }
    }
    // The pair sum is triangular on ±0.05°: P(|sum| > 0.03°) = 0.16 per pair, 600 pairs seen.
    assert!(largest > 0.03f64.to_radians(), "largest axis-pair deviation {largest} rad");
}

#[test]
fn g_sensitivity_and_temperature_effects_are_exactly_linear() {
    let mut params = ErrorParams::ideal();
    params.gyro.g_sensitivity = Spread::normal(0.05);
    params.gyro.bias_tempco = Spread::normal(0.01);
    params.accel.bias_tempco = Spread::normal(0.3e-3);
    let mut m = model(&params, 21);
    let g = m.gyro_unit().g_sensitivity;
    let c_gyro = m.gyro_unit().bias_tempco;
    let c_accel = m.accel_unit().bias_tempco;
    assert!(g.iter().flatten().all(|x| *x != 0.0));
    for (k, (force, temp)) in
        [([0.0, 0.0, -1.0], 25.0), ([0.3, -0.7, 2.5], 25.0), ([0.6, -1.4, 5.0], 40.0)].into_iter().enumerate()
    {
        let mut p = Physical { accel_g: force, temp_c: temp, ..Physical::default() };
        m.apply(k as u64, 0, &mut p);
        let dt = temp - REFERENCE_TEMP_C;
        for i in 0..3 {
            let expected = c_gyro[i] * dt + (g[i][0] * force[0] + g[i][1] * force[1] + g[i][2] * force[2]);
            assert_eq!(p.gyro_dps[i], expected, "gyro axis {i}");
            assert_eq!(p.accel_g[i], force[i] + c_accel[i] * dt, "accel axis {i}");
        }
    }
    // Doubling the force doubles the g-sensitivity output, bit for bit.
    let respond = |m: &mut ErrorModel, f: [f64; 3]| {
        let mut p = Physical { accel_g: f, temp_c: 25.0, ..Physical::default() };
        m.apply(0, 0, &mut p);
        p.gyro_dps
    };
    let once = respond(&mut m, [0.3, -0.7, 2.5]);
    let twice = respond(&mut m, [0.6, -1.4, 5.0]);
    assert_eq!(twice, once.map(|x| 2.0 * x));
}

#[test]
fn nonlinearity_is_its_fraction_of_full_scale_at_full_scale() {
    let mut params = ErrorParams::ideal();
    params.gyro.nonlinearity = Spread::fixed(0.001);
    let mut m = model(&params, 1);
    let mut p = Physical { gyro_dps: [300.0, -300.0, 150.0], temp_c: 25.0, ..Physical::default() };
    m.apply(0, 0, &mut p);
    assert!((p.gyro_dps[0] - 300.3).abs() < 1e-12);
    assert!((p.gyro_dps[1] - (-299.7)).abs() < 1e-12);
    assert!((p.gyro_dps[2] - 150.075).abs() < 1e-12);
}

#[test]
fn magnetometer_iron_and_barometer_noise() {
    let mut params = ErrorParams::ideal();
    params.mag.hard_iron_gauss = [0.01, -0.02, 0.03];
    params.mag.soft_iron = [[0.1, 0.0, 0.0], [0.0, 0.0, 0.05], [0.0, 0.0, 0.0]];
    let mut m = model(&params, 1);
    let mut p = Physical { mag_gauss: [0.2, 0.4, -0.6], ..Physical::default() };
    m.apply(0, 0, &mut p);
    let expected = [0.2 * 1.1 + 0.01, 0.4 - 0.6 * 0.05 - 0.02, -0.6 + 0.03];
    for (out, want) in p.mag_gauss.iter().zip(expected) {
        assert!((out - want).abs() < 1e-15);
    }
    let mut params = ErrorParams::ideal();
    params.baro.noise_rms_mbar = 0.027;
    let mut m = model(&params, 2);
    let n = 100_000;
    let power: f64 = (0..n)
        .map(|k| {
            let mut p = Physical { baro_mbar: 1000.0, ..Physical::default() };
            m.apply(k, 0, &mut p);
            (p.baro_mbar - 1000.0).powi(2)
        })
        .sum();
    let rms = (power / n as f64).sqrt();
    // 1000 mbar carries ~1e-13 mbar rounding, far below the 5σ bound 0.027·5/√(2n).
    assert!((rms / 0.027 - 1.0).abs() < 5.0 / (2.0 * n as f64).sqrt(), "baro rms {rms}");
    // Magnetometer white noise, per axis, with the same 5σ bound on the relative rms.
    let mut params = ErrorParams::ideal();
    params.mag.noise_rms_gauss = 1.15e-3;
    let mut m = model(&params, 3);
    let truth = [0.2, 0.4, -0.6];
    let mut power = [0.0; 3];
    for k in 0..n {
        let mut p = Physical { mag_gauss: truth, ..Physical::default() };
        m.apply(k, 0, &mut p);
        for axis in 0..3 {
            power[axis] += (p.mag_gauss[axis] - truth[axis]).powi(2);
        }
    }
    for power in power {
        let rms = (power / n as f64).sqrt();
        assert!((rms / 1.15e-3 - 1.0).abs() < 5.0 / (2.0 * n as f64).sqrt(), "magnetometer rms {rms}");
    }
}

#[test]
fn gauss_markov_allan_peak_constants() {
    let (mut best, mut at) = (0.0, 0.0);
    for i in 0..200_000 {
        let x = 1.0 + i as f64 * 1e-5;
        let v = gauss_markov_avar(1.0, 1.0, x).sqrt();
        if v > best {
            (best, at) = (v, x);
        }
    }
    assert!((best - GAUSS_MARKOV_ALLAN_PEAK).abs() < 1e-9);
    assert!((at - GAUSS_MARKOV_ALLAN_PEAK_AT).abs() < 1e-4);
    // Series and closed form meet at the switch-over x = 0.01.
    let below = gauss_markov_avar(1.0, 1.0, 0.01 * (1.0 - 1e-12));
    let closed = gauss_markov_avar(1.0, 1.0, 0.01);
    assert!((below / closed - 1.0).abs() < 1e-10);
    let gm = gauss_markov_for_allan_peak(0.007, 100.0);
    assert!((gauss_markov_avar(gm.sigma, gm.tau_s, GAUSS_MARKOV_ALLAN_PEAK_AT * 100.0).sqrt() - 0.007).abs() < 1e-12);
}

#[test]
fn flicker_bank_has_a_flat_allan_floor() {
    let floor = 0.007;
    let bank = flicker_bank(floor, 1.0, 1e5, 1);
    assert_eq!(bank.len(), 6);
    assert!((bank[5].tau_s - 1e5).abs() < 1e-6);
    // Documented accuracy: within ±1.5 % for 20 τ_min ≤ T ≤ τ_max / 5.
    for i in 0..=60 {
        let t = 20.0 * 10f64.powf(i as f64 * 3.0 / 60.0);
        let adev = bank.iter().map(|g| gauss_markov_avar(g.sigma, g.tau_s, t)).sum::<f64>().sqrt();
        assert!((adev / floor - 1.0).abs() < 0.015, "T = {t} s: {adev}");
    }
}

#[test]
fn presets_and_table() {
    assert!(ErrorParams::preset("adis16407").unwrap().validate().is_ok());
    let err = ErrorParams::preset("adis16405").unwrap_err().to_string();
    assert!(err.contains("errors.preset") && err.contains("adis16407"), "{err}");
    let rows = preset_table("adis16407").unwrap();
    let row = |q: &str| rows.iter().find(|r| r.quantity.starts_with(q)).unwrap();
    assert!((row("gyro angle random walk").value - 2.0).abs() < 1e-12);
    assert!(row("gyro angle random walk").unconfirmed);
    assert!((row("accel noise density").value - 0.5).abs() < 1e-12);
    assert!(!row("accel noise density").unconfirmed);
    // 0.5 mg/√Hz one-sided is 0.208 m/s/√h, the sibling's 0.2 m/s/√h within 4 %.
    assert!((row("accel velocity random walk").value - 0.208).abs() < 1e-3);
    assert!((row("gyro in-run bias stability").value - 0.007).abs() < 1e-15);
    assert!((row("accel in-run bias stability").value - 0.2).abs() < 1e-12);
    assert!((row("magnetometer noise").value - 1.15).abs() < 1e-12);
    assert!(rows.iter().all(|r| r.value.is_finite() && !r.source.is_empty()));
    let ideal = preset_table("ideal").unwrap();
    assert_eq!(ideal.len(), rows.len());
    assert!(ideal.iter().all(|r| !r.unconfirmed && (r.value == 0.0 || r.quantity.contains("full scale"))));
}

#[test]
fn the_adis16362_table_names_its_own_sources() {
    let rows = preset_table("adis16362").unwrap();
    let row = |q: &str| rows.iter().find(|r| r.quantity.starts_with(q)).unwrap();
    // The notes' figures, confirmed by the wing-angle notes (the numbers).
    for (q, v) in [("gyro initial bias", 3.0), ("gyro in-run bias stability", 0.007), ("gyro bias tempco", 0.01)] {
        assert!((row(q).value - v).abs() < 1e-15 && !row(q).unconfirmed && row(q).source.contains("notes"), "{q}");
    }
    assert!((row("accel velocity random walk").value - 0.12).abs() < 1e-12);
    assert!((row("accel in-run bias stability").value - 0.1).abs() < 1e-12);
    assert!((row("accel initial bias").value - 4.0).abs() < 1e-12);
    assert!((row("accel full scale").value - 1.7).abs() < 1e-15);
    assert_eq!(row("magnetometer noise").value, 0.0);
    // No row of the 16362 cites the 16407's data sheet as its own: each names the 16362's source,
    // a sibling marked unconfirmed, or a model choice.
    for r in &rows {
        assert!(!r.source.starts_with("ADIS16407 data sheet") || r.unconfirmed, "{}: {}", r.quantity, r.source);
        assert!(!r.source.contains("for the 16407"), "{}: {}", r.quantity, r.source);
    }
    assert!(rows.iter().filter(|r| r.source.to_lowercase().contains("adis16362")).count() >= 14);
}

#[test]
fn invalid_parameters_name_their_key() {
    let mut params = ErrorParams::adis16407();
    params.accel.initial_bias.width = -1.0;
    let err = ErrorModel::new(&params, 1, DT).unwrap_err().to_string();
    assert!(err.contains("errors.accel.initial_bias.width"), "{err}");
    let mut params = ErrorParams::ideal();
    params.gyro.bias_instability =
        BiasInstability::Flicker { allan_floor: 0.007, tau_min_s: 10.0, tau_max_s: 1.0, terms_per_decade: 1 };
    let err = ErrorModel::new(&params, 1, DT).unwrap_err().to_string();
    assert!(err.contains("errors.gyro.bias_instability.tau_max_s"), "{err}");
    assert!(ErrorModel::new(&ErrorParams::ideal(), 1, 0.0).is_err());
}

#[test]
fn params_round_trip_through_toml() {
    let params = ErrorParams::adis16407();
    let text = toml::to_string(&params).unwrap();
    let back: ErrorParams = toml::from_str(&text).unwrap();
    assert_eq!(back, params);
}
