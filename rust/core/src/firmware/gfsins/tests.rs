//! The board's checks: the node's timing against a hand computation from the link rates, the
//! channels, compass and GPS reaching the DSP, the budget's peaks per rate class, the rules that
//! can fail (overrun, wrong baud rate), the profile's errors.

use super::*;
use crate::device::{gps, hmc6343};

const MS: Ps = 1_000_000_000;

fn ideal() -> GfsinsProfile {
    let mut p = GfsinsProfile::default();
    p.array.preset = "ideal".into();
    p.compass.errors = "ideal".into();
    p.gps.cep_m = 0.0;
    p.gps.velocity_sigma_m_s = 0.0;
    p
}

/// A vehicle at rest, heading 30°, at the thesis's place; part i feels a force whose axes differ.
fn vehicle() -> Source {
    Arc::new(|_| Truth {
        array_g: std::array::from_fn(|i| {
            let k = i as f64 + 1.0;
            [0.01 * k, -0.02 * k, 0.9 + 0.01 * k]
        }),
        compass: hmc6343::Truth {
            heading_deg: 30.0,
            pitch_deg: 1.5,
            roll_deg: -2.0,
            accel_g: [0.0, 0.0, 1.0],
            mag_gauss: [0.2, 0.0, 0.4],
            temp_c: 25.0,
        },
        gps: gps::Truth { lat_deg: 28.20021, lon_deg: 112.92647, alt_m: 5.13145, speed_m_s: 22.2, course_deg: 30.0 },
    })
}

/// Tick 20 (0.7 s: the compass is still starting, no NMEA in flight) against the hand computation:
/// PLB = CPU = 75 MHz (13⅓ ns), handler entry 30 cycles = 400 ns, an access 6 cycles = 80 ns, SCK
/// 54 cycles = 720 ns. Core i starts after its 9 accesses: 400 + 720 (i + 1) ns; a 7-byte read
/// lasts ½ (SS set-up) + 6·8 + 7½ (the last byte's edges) + ½ (SS hold) = 56½ SCK = 40 680 ns.
/// Core 6 ends at 400 + 5040 + 40 680 = 46 120 ns; collecting each takes 720 ns and each core ends
/// as the previous is collected, so all are in at 46 840 ns. Then 600 cycles (8 µs) + 3 accesses:
/// DMA2 starts at 55 080 ns; 26 words × 16 bits at 8 cycles (106 666 ps floored) + ½ SCK set-up.
#[test]
fn node_timing_is_the_hand_computation() {
    let mut board = Board::new(&ideal(), vehicle()).unwrap();
    let steps: Vec<Step> = (0..21).map(|_| board.step().unwrap()).collect();
    let t = steps[20].timing;
    let ns = 1_000;
    assert_eq!(t.t0, 600 * MS + 20 * 5 * MS);
    assert_eq!((t.nmea_bytes, t.compass_phase), (0, 3), "a plain tick");
    for (i, &(start, end)) in t.spi.iter().enumerate() {
        assert_eq!(start - t.t0, (400 + 720 * (i as u64 + 1)) * ns, "core {i}");
        assert_eq!(end - start, 40_680 * ns, "core {i}");
    }
    assert_eq!(t.collected - t.t0, 46_840 * ns);
    assert_eq!(t.dma_start - t.t0, 55_080 * ns);
    assert_eq!(t.packet_end - t.dma_start, 53_333 + 26 * 16 * 106_666);
    // CPU: to DMA2's start, then DMA2's completion interrupt (entry + 2 accesses).
    assert_eq!(t.cpu_ps, (55_080 + 400 + 160) * ns);
    let out = steps[20].out.unwrap();
    assert_eq!(out.t_irq, t.packet_end + 44_444, "dMAX: 10 cycles at 225 MHz");
    assert_eq!(out.rti, (t.packet_end + 44_444) * 1125 / 10_000_000, "RTI at 112.5 MHz");
    assert!(board.drain_events().is_empty());
}

/// A₁…A₆ are the outer parts' sensing axes (x y z x y z), A₇…A₉ the centre's three; counts at
/// 3.9 mg (256/g); the compass's heading and tilt in tenths of a degree; GPS fixes once a second.
#[test]
fn readings_reach_the_dsp() {
    let (steps, _, events) = run(&ideal(), vehicle(), 600).unwrap();
    // The navigation's spell of bridged rate steps (a constant rate) is its only event.
    assert!(events.iter().all(|e| e.kind == "rate_singular"), "{events:?}");
    let last = steps.last().unwrap().out.unwrap();
    let count = |g: f64| (g * 256.0).round() as i16;
    for i in 0..6 {
        let k = i as f64 + 1.0;
        let f = [0.01 * k, -0.02 * k, 0.9 + 0.01 * k];
        assert_eq!(last.packet.accel[i], count(f[crate::firmware::gfnav::array::SENSING_AXIS[i]]), "A{}", i + 1);
    }
    assert_eq!(&last.packet.accel[6..], &[count(0.07), count(-0.14), count(0.97)]);
    assert_eq!(last.packet.compass, [300, 15, -20]);
    assert!((last.gps[0] - 28.20021).abs() < 1e-6 && (last.gps[1] - 112.92647).abs() < 1e-6, "{:?}", last.gps);
    assert!((last.gps[3] - 22.2).abs() < 0.01 && (last.gps[4] - 30.0).abs() < 0.01, "{:?}", last.gps);
    let fixes: Vec<u16> =
        steps.iter().filter(|s| s.packet.flags & frame::NEW_GPS != 0).map(|s| s.packet.sequence).collect();
    // Tick 0 (0.6 s) takes epoch 0's backlog; epoch e's RMC ends at e + 0.2 s (latency) + 190
    // characters or so (GGA, GSA, RMC) × 520.8 µs ≈ e + 0.3 s: ticks 141 + 200 (e − 1).
    assert_eq!(fixes, [0, 141, 341, 541], "one a second");
    let compass = steps.iter().filter(|s| s.packet.flags & frame::NEW_COMPASS != 0).count();
    // Ready at ≈ 1.02 s (tick 84); taken on ticks 20n + 2 from 102 to 582: 25 at 10 Hz.
    assert_eq!(compass, 25, "10 Hz from ≈ 1.02 s");
    // The pass-through's tilt: the centre's level formula.
    let [p, r] = dsp::tilt(last.accel_g[6..].try_into().unwrap());
    assert_eq!(last.tilt, [p, r]);
}

/// The budget per rate class, hand-computed from the profile's costs. Node: a plain tick is
/// 55 640 ns (above); a compass tick adds at most 7 accesses (560 ns); a GPS tick adds 20 cycles per
/// NMEA byte (≤ 10 bytes in 5 ms at 1920 characters/s) and 2000 per sentence (≤ 1: the shortest
/// is 36 characters). DSP: its peaks rise from the 200 Hz to the 10 Hz to the 1 Hz ticks.
#[test]
fn budget_peaks_per_rate_class() {
    let profile = ideal();
    let mut board = Board::new(&profile, vehicle()).unwrap();
    let mut steps: Vec<Step> = (0..800).map(|_| board.step().unwrap()).collect();
    steps.drain(..100); // tick 0 takes the first epoch's backlog; steady state from 1.1 s
    let b = Budget::of(&steps, board.node().period());
    let cyc = |n: u64| n * 40_000 / 3; // 75 MHz
    let plain = 55_640_000;
    let node = b.load[0];
    assert!(node.iter().all(|c| c.ticks > 0), "{node:?}");
    assert_eq!(node[0].peak_ps, plain);
    assert_eq!(node[1].peak_ps, plain + 560_000);
    assert!(node[2].peak_ps >= plain + cyc(2000) && node[2].peak_ps <= plain + cyc(10 * 20 + 2000) + 560_000);
    // The DSP (nav_tests.rs checks its stages): the multi-rate peaks, far inside the period.
    let d = b.load[1];
    assert!(d[0].peak_ps < d[1].peak_ps && d[0].peak_ps < d[2].peak_ps, "{d:?}");
    assert!(node[2].peak_ps < b.period_ps / 50 && d[2].peak_ps < b.period_ps / 2);
}

/// A slow SCK breaks the 5 ms period: an `overrun` event (the rule can fail).
#[test]
fn a_slow_bus_overruns_the_tick() {
    let mut p = ideal();
    p.node.adxl_sck_ratio = 8192; // 9.16 kHz: 7 bytes take 6.2 ms
    let (_, _, events) = run(&p, vehicle(), 3).unwrap();
    assert!(events.iter().any(|e| e.kind == "overrun"), "{events:?}");
}

/// The receiver at HOLUX's default 4800 baud against the UART Lite's 19 200: framing errors, no fix.
#[test]
fn a_wrong_baud_rate_gives_no_fix() {
    let mut p = ideal();
    p.gps.baud = 4800;
    let (steps, _, events) = run(&p, vehicle(), 300).unwrap();
    assert!(events.iter().any(|e| e.kind == "uart_framing_error"));
    assert!(steps.iter().all(|s| s.packet.flags & (frame::NEW_GPS | frame::GPS_VALID) == 0));
}

/// A damaged packet is refused by the DSP and the next one is counted as following a gap.
#[test]
fn the_dsp_refuses_a_damaged_packet() {
    let p = ideal();
    let mut node = Node::new(
        &p,
        Arc::new(|_, _| [0.0, 0.0, 1.0]),
        Box::new(|_| vehicle()(0).compass),
        Box::new(|_| vehicle()(0).gps),
    )
    .unwrap();
    let mut dsp = Dsp::new(&p, node.period());
    let (a, ta) = node.tick().unwrap();
    assert!(dsp.receive(&a.encode(), &ta).is_some());
    let (b, tb) = node.tick().unwrap();
    let mut w = b.encode();
    w[5] ^= 0x0100;
    assert!(dsp.receive(&w, &tb).is_none());
    let (c, tc) = node.tick().unwrap();
    assert!(dsp.receive(&c.encode(), &tc).is_some());
    let kinds: Vec<&str> = dsp.drain_events().iter().map(|e| e.kind).collect();
    assert_eq!(kinds, ["packet_refused", "packet_missing"]);
}

#[test]
fn profile_errors_name_the_key() {
    let e = GfsinsProfile::parse("[node]\nadxl_sck_ratio = 53\n", "gfsins.toml").unwrap_err().to_string();
    assert!(e.contains("gfsins.toml") && e.contains("node.adxl_sck_ratio") && e.contains("even"), "{e}");
    let e = GfsinsProfile::parse("[array]\nlever = 0.1\n", "x.toml").unwrap_err().to_string();
    assert!(e.contains("x.toml") && e.contains("lever"), "{e}");
    let e = GfsinsProfile::parse("[node]\ndsp_sck_ratio = 4\n", "x.toml").unwrap_err().to_string();
    assert!(e.contains("node.dsp_sck_ratio") && e.contains("10000000"), "{e}");
    let e = GfsinsProfile::parse("[array]\nfifo_ctl = 0x00\n", "x.toml").unwrap_err().to_string();
    assert!(e.contains("array.fifo_ctl") && e.contains("stream"), "{e}");
    let shipped = include_str!("../../../../../firmware_model/gfsins.toml");
    assert_eq!(GfsinsProfile::parse(shipped, "gfsins.toml").unwrap(), GfsinsProfile::default());
}

/// The array's and the compass's keys: errors name the key (a layout the nine channels cannot
/// invert, a part sensing along its own lever, two parts on one core, a wrong channel count, an
/// address beyond 7 bits or reserved).
#[test]
fn layout_and_address_errors_name_the_key() {
    let parts = |rows: &[&str]| format!("[array]\nparts = [\n{}\n]\n", rows.join(",\n"));
    let thesis = [
        r#"{ link = "spi1", position = [0.0, 1.0, 0.0], channels = ["x"] }"#,
        r#"{ link = "spi2", position = [0.0, 0.0, 1.0], channels = ["y"] }"#,
        r#"{ link = "spi3", position = [1.0, 0.0, 0.0], channels = ["z"] }"#,
        r#"{ link = "spi4", position = [0.0, 0.0, -1.0], channels = ["x"] }"#,
        r#"{ link = "spi5", position = [-1.0, 0.0, 0.0], channels = ["y"] }"#,
        r#"{ link = "spi6", position = [0.0, -1.0, 0.0], channels = ["z"] }"#,
        r#"{ link = "spi7", position = [0.0, 0.0, 0.0], channels = ["x", "y", "z"] }"#,
    ];
    assert_eq!(GfsinsProfile::parse(&parts(&thesis), "x.toml").unwrap().array, GfsinsProfile::default().array);
    let err = |text: String| GfsinsProfile::parse(&text, "x.toml").unwrap_err().to_string();
    let mut along = thesis;
    along[0] = r#"{ link = "spi1", position = [0.0, 1.0, 0.0], channels = ["y"] }"#;
    let e = err(parts(&along));
    assert!(e.contains("`array.parts[0].channels`") && e.contains("own lever"), "{e}");
    let mut shared = thesis;
    shared[1] = r#"{ link = "spi1", position = [0.0, 0.0, 1.0], channels = ["y"] }"#;
    let e = err(parts(&shared));
    assert!(e.contains("`array.parts[1].link`") && e.contains("array.parts[0]"), "{e}");
    let mut short = thesis;
    short[6] = r#"{ link = "spi7", position = [0.0, 0.0, 0.0], channels = ["x", "y"] }"#;
    let e = err(parts(&short));
    assert!(e.contains("`array.parts`") && e.contains("8 channels"), "{e}");
    let e = err(parts(&thesis[..6]));
    assert!(e.contains("`array.parts`") && e.contains("6 parts"), "{e}");
    let singular = include_str!("../../../../../tests/data/bad/profiles/gfsins_singular_array.toml");
    let e = err(singular.into());
    assert!(e.contains("`array.parts`") && e.contains("singular"), "{e}");
    for a in ["0x80", "0x07", "0x78"] {
        let e = err(format!("[compass]\naddress = {a}\n"));
        assert!(e.contains("`compass.address`") && e.contains("7-bit"), "{e}");
    }
}

/// The variant of tests/data/gfsins (the parts elsewhere, on other cores, the triaxial part read
/// first; the compass at 0x1E), with ideal parts: each channel is its part's axis as the profile
/// lists them, the cores start in the parts' order, and the compass answers at its address.
#[test]
fn a_variant_layout_reaches_the_dsp() {
    let text = include_str!("../../../../../tests/data/gfsins/variant.toml");
    let mut p = GfsinsProfile::parse(text, "variant.toml").unwrap();
    (p.array.preset, p.compass.errors) = ("ideal".into(), "ideal".into());
    let (steps, _, events) = run(&p, vehicle(), 600).unwrap();
    assert!(events.iter().all(|e| e.kind == "rate_singular"), "{events:?}");
    let last = steps.last().unwrap();
    let count = |g: f64| (g * 256.0).round() as i16;
    let force = |part: usize| {
        let k = part as f64 + 1.0;
        [0.01 * k, -0.02 * k, 0.9 + 0.01 * k]
    };
    let channels = [(0, 0), (0, 1), (0, 2), (1, 0), (2, 1), (3, 2), (4, 0), (5, 1), (6, 2)];
    for (c, (part, axis)) in channels.into_iter().enumerate() {
        assert_eq!(last.packet.accel[c], count(force(part)[axis]), "A{}", c + 1);
    }
    // Cores by part: spi7, spi2, spi1, spi3…spi6, started one after the other in that order.
    let starts: Vec<Ps> = [6, 1, 0, 2, 3, 4, 5].iter().map(|&core| last.timing.spi[core].0).collect();
    assert!(starts.windows(2).all(|w| w[0] < w[1]), "{starts:?}");
    assert_eq!(last.packet.compass, [300, 15, -20]);
    let compass = steps.iter().filter(|s| s.packet.flags & frame::NEW_COMPASS != 0).count();
    assert_eq!(compass, 25, "10 Hz from ≈ 1.02 s, as at 0x19");
}

/// Each processor's stages add up to its time in every tick (nothing lost or counted twice), the
/// node's in execution order; the budget's stage rows carry each class's peak of those times, and a
/// stage's peak is never above its processor's.
#[test]
fn stages_add_up_to_each_processors_time() {
    let mut board = Board::new(&ideal(), vehicle()).unwrap();
    let steps: Vec<Step> = (0..500).map(|_| board.step().unwrap()).collect();
    for s in &steps {
        assert_eq!(s.timing.stages.total(), s.timing.cpu_ps, "tick at {}", s.timing.t0);
        let out = s.out.unwrap();
        assert_eq!(s.dsp_stages().total(), out.t_done - out.t_irq);
    }
    let names: Vec<&str> = steps[0].timing.stages.iter().map(|(n, _)| n).collect();
    assert_eq!(names, ["entry", "accelerometers", "compass", "gps", "packet", "dma_irq"]);
    let b = Budget::of(&steps, board.node().period());
    assert_eq!(b.stages.iter().filter(|r| r.processor == 0).count(), 6);
    assert!(b.stages.iter().any(|r| r.processor == 1), "the DSP's rows");
    assert!(b.stages.windows(2).all(|w| w[0].processor <= w[1].processor), "the node's rows first");
    for r in &b.stages {
        for (c, class) in CLASSES.iter().enumerate() {
            let peak = steps
                .iter()
                .filter(|s| Budget::class(s) == c)
                .flat_map(|s| {
                    if r.processor == 0 { s.timing.stages } else { s.dsp_stages() }.iter().collect::<Vec<_>>()
                })
                .filter(|&(n, _)| n == r.name)
                .map(|(_, t)| t)
                .max()
                .unwrap_or(0);
            assert_eq!(r.load[c].peak_ps, peak, "{} {class}", r.name);
            assert!(r.load[c].peak_ps <= b.load[r.processor][c].peak_ps);
        }
    }
    // The compass's I²C transaction and the NMEA characters are where the node says.
    let compass = steps.iter().find(|s| s.timing.compass_phase == 0).unwrap().timing;
    assert!(compass.iic.0 >= compass.collected && compass.iic.1 > compass.iic.0);
    let gps = steps.iter().find(|s| s.timing.nmea_bytes > 0).unwrap().timing;
    let char_ps = 10 * 1_000_000_000_000 / 19_200; // 520.833 µs, floored to ps
    assert!(
        gps.uart.1 - gps.uart.0 >= u64::from(gps.nmea_bytes) * char_ps,
        "{:?} for {} bytes",
        gps.uart,
        gps.nmea_bytes
    );
}

/// `--set key=value` on the board's own schema: the value is taken, and a bad key is named.
#[test]
fn overrides_apply_and_name_a_bad_key() {
    let shipped = include_str!("../../../../../firmware_model/gfsins.toml");
    let p = GfsinsProfile::parse_with(shipped, "gfsins.toml", &["node.adxl_sck_ratio=60".into()]).unwrap();
    assert_eq!(p.node.adxl_sck_ratio, 60);
    let e = GfsinsProfile::parse_with(shipped, "gfsins.toml", &["node.sck=60".into()]).unwrap_err().to_string();
    assert!(e.contains("gfsins.toml") && e.contains("node.sck"), "{e}");
    let e = GfsinsProfile::parse_with(shipped, "gfsins.toml", &["node".into()]).unwrap_err().to_string();
    assert!(e.contains("gfsins.toml") && e.contains("key=value"), "{e}");
    assert_eq!(GfsinsProfile::parse(&p.to_toml(), "round trip").unwrap(), p);
}

#[path = "nav_tests.rs"]
mod nav_tests;

/// A DSP slow enough that its compass-filter packets outlast the 5 ms period: an `overrun` error
/// from the C6727 (the same deadline rule as the node's and the reference board's), none at the
/// thesis's 225 MHz.
#[test]
fn a_dsp_handler_longer_than_the_period_is_an_overrun() {
    let ticks = 400; // 2 s: the compass filter runs from its first reading on
    let dsp_overruns = |p: &GfsinsProfile| {
        let (_, _, events) = run(p, vehicle(), ticks).unwrap();
        events.iter().filter(|e| e.kind == "overrun" && e.message.contains("C6727")).count()
    };
    assert_eq!(dsp_overruns(&ideal()), 0);
    let mut slow = ideal();
    slow.dsp.cpu_hz = 5_000_000;
    assert!(dsp_overruns(&slow) > 0);
}

/// A cost key beyond one period of its processor is refused naming the key (2³² cycles per PLB
/// access made every tick run for hours of emulated time); one period is accepted.
#[test]
fn a_cost_beyond_one_period_is_refused_naming_the_key() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../firmware_model/gfsins.toml")).unwrap();
    for (set, key) in [
        ("node.plb_access_cycles=4294967296", "node.plb_access_cycles"),
        ("node.isr_entry_cycles=375001", "node.isr_entry_cycles"),
        ("dsp.div_cycles=1125001", "dsp.div_cycles"),
        ("gps.latency_ms=100000", "gps.latency_ms"),
        ("node.start_ms=18446744073709", "node.start_ms"),
    ] {
        let e = GfsinsProfile::parse_with(&text, "gfsins.toml", &[set.to_string()]).unwrap_err();
        assert!(e.to_string().contains(&format!("`{key}`")), "{set}: {e}");
    }
    assert!(GfsinsProfile::parse_with(&text, "gfsins.toml", &["node.plb_access_cycles=375000".into()]).is_ok());
}

/// The streamed board, fed in chunks of 37 samples, is the whole-input board step for step.
#[test]
fn the_streamed_board_is_the_whole_board() {
    let p = ideal();
    let period = 1_000_000_000; // 1 ms samples
    let truth = |k: u64| {
        let mut t = vehicle()(k * period);
        t.array_g[0][0] += 1e-3 * (k as f64 * 0.01).sin();
        t.compass.heading_deg = 30.0 + 1e-3 * k as f64;
        t
    };
    let n = 3_000u64;
    let t_ps: Vec<Ps> = (0..n).map(|k| k * period).collect();
    let rows: Vec<Truth> = (0..n).map(truth).collect();
    let samples = Samples::new(t_ps.clone(), rows.clone()).unwrap();
    let ticks = 480; // the last at 0.6 + 479 × 5 ms = 2.995 s
    let (whole, budget, events) = run(&p, samples.source(), ticks).unwrap();
    let mut s = Streamed::new(&p).unwrap();
    let (mut steps, mut streamed_events) = (Vec::new(), Vec::new());
    for (t, r) in t_ps.chunks(37).zip(rows.chunks(37)) {
        s.push(t, r).unwrap();
        steps.extend(s.run(50, ticks, std::time::Duration::from_secs(60)).unwrap().into_iter().map(|x| x.step));
        streamed_events.extend(s.drain_events());
    }
    s.end_input();
    while let Ok(more) = s.run(50, ticks, std::time::Duration::from_secs(60)) {
        if more.is_empty() {
            break;
        }
        steps.extend(more.into_iter().map(|x| x.step));
    }
    streamed_events.extend(s.drain_events());
    // By their text: the navigation is NaN until it starts (NaN ≠ NaN).
    assert_eq!(steps.len(), whole.len());
    for (a, b) in steps.iter().zip(&whole) {
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }
    assert_eq!(s.budget(), budget);
    let key = |e: &Event| (e.t_ps, e.kind, e.message.clone());
    let mut a: Vec<_> = streamed_events.iter().map(key).collect();
    let mut b: Vec<_> = events.iter().map(key).collect();
    a.sort();
    b.sort();
    assert_eq!(a, b);
}
