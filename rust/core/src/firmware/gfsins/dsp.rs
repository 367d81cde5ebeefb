//! The TMS320C6727B side as far as the navigation needs it (c6727.md): SPI1 as a slave receiving
//! the node's packets word by word, dMAX moving each word to memory and raising the packet
//! interrupt, the RTI as its time base and packet watchdog, and the handler's cycle cost.
//!
//! - **SPI1 (slave)**: SCLK comes from the node's SPI #8; the thesis's 10 MHz ceiling is checked
//!   when the profile is read. Each 16-bit word ends 16 SCLK periods after the previous one; dMAX
//!   moves it in `dmax_word_cycles` [estimate] and, after the last word of a packet, raises the
//!   interrupt (thesis l. 1363).
//! - **RTI**: a free-running counter on SYSCLK2 (= SYSCLK1 / 2, 112.5 MHz) [unconfirmed, c6727.md:
//!   RTI structure from the TMS470/570 lineage]; each packet is stamped with it, and a compare at
//!   the packet rate finds a packet that did not come (`packet_missing`).
//! - **Arithmetic**: the handler runs in IEEE double. The C67x+ flushes denormal operands and
//!   results to zero and writes NaN as 0x7FFF_FFFF ([unconfirmed] recollection of SPRU733); Rust's
//!   f64 does neither. On what this handler computes they cannot differ: every input is a count
//!   n, |n| < 2¹⁵, times a power of two (3.9 mg = 2⁻⁸ g) or a decimal scale, so each nonzero
//!   operand and result is ≥ 2⁻¹⁶ in magnitude (products ≥ 2⁻³², sums of squares likewise), far
//!   above the smallest normal double (2⁻¹⁰²²); no operation takes 0/0, ∞ or a negative square
//!   root (the sum of squares is ≥ 0, atan2(0, 0) is 0 in TI's RTS as in C99), so no NaN is made.
//!   `tilt` is generic over [`Scalar`] so a C67x backend can be put in when the navigation's
//!   filter (issue 23) reaches values where they would differ. The libraries' last bit
//!   (TI RTS atan2/sqrt against Rust's) is not modelled.
//! - **Cycle costs** (`[dsp]` keys): atan2dp from TI's MATHLIB C674x report (RTS column, approximate
//!   for the C67x+), sqrt and the rest estimates from GCC's c6x latencies; the CPU is at SYSCLK1.
//!
//! **The navigation is issue 23's.** Until it lands the handler is a pass-through: it outputs the
//! packet's values in physical units and a tilt (pitch, roll) from the centre accelerometer
//! (A₇, A₈, A₉) by the reference design's level formula, θ = atan2(−f_x, √(f_y² + f_z²)),
//! φ = atan2(f_y, f_z) — which is the attitude only when the vehicle does not accelerate.

use super::frame::{self, Packet};
use super::node::TickTiming;
use super::profile;
use crate::device::adxl345;
use crate::events::{Event, EventLog, Severity};
use crate::numerics::{QClass, Scalar};
use crate::time::{Clock, Ps};

/// What the DSP has after one packet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DspOutput {
    /// The packet interrupt, ps.
    pub t_irq: Ps,
    /// The handler's end, ps.
    pub t_done: Ps,
    /// RTI count at the interrupt.
    pub rti: u64,
    /// The packet.
    pub packet: Packet,
    /// A₁…A₉, g.
    pub accel_g: [f64; 9],
    /// Compass heading, pitch, roll, °.
    pub compass_deg: [f64; 3],
    /// GPS latitude, longitude (°), altitude (m), speed (m/s), course (°), UTC (s of the day).
    pub gps: [f64; 6],
    /// Pitch and roll from the centre accelerometer, rad.
    pub tilt: [f64; 2],
    /// Handler cycles (SYSCLK1).
    pub cycles: u64,
}

/// The tilt of a specific force (any units): pitch θ = atan2(−f_x, √(f_y² + f_z²)), roll
/// φ = atan2(f_y, f_z).
pub fn tilt<T: Scalar>(f: [T; 3]) -> [T; 2] {
    let [fx, fy, fz] = f;
    [(-fx).atan2((fy * fy + fz * fz).sqrt()).to_class(QClass::Angle), fy.atan2(fz).to_class(QClass::Angle)]
}

/// The C6727B.
#[derive(Debug)]
pub struct Dsp {
    cfg: profile::Dsp,
    cpu: Clock,
    rti: Clock,
    lsb_g: f64,
    period: Ps,
    last_irq: Option<Ps>,
    last_sequence: Option<u16>,
    events: EventLog,
}

impl Dsp {
    /// The DSP of `profile` (`lsb_g`: the accelerometer counts' scale; `period`: the packet period).
    pub fn new(profile: &profile::GfsinsProfile, period: Ps) -> Dsp {
        let cpu = Clock::from_hz(profile.dsp.cpu_hz);
        let lsb_g = adxl345::resolution(profile.array.data_format).1;
        Dsp {
            cfg: profile.dsp.clone(),
            cpu,
            rti: cpu.divided(2),
            lsb_g,
            period,
            last_irq: None,
            last_sequence: None,
            events: EventLog::default(),
        }
    }

    /// Handler cycles for a packet with `flags`.
    pub fn handler_cycles(&self, flags: u16) -> u64 {
        let c = &self.cfg;
        let mut n = c.isr_entry_cycles + c.crc_cycles_per_word * frame::WORDS as u64 + 9 * c.convert_cycles;
        // Tilt: three squares and a sum (MPYDP/ADDDP), one square root, two atan2.
        n += 3 * 10 + 2 * 7 + c.sqrtdp_cycles + 2 * c.atan2dp_cycles;
        if flags & frame::NEW_COMPASS != 0 {
            n += 3 * c.convert_cycles;
        }
        if flags & frame::NEW_GPS != 0 {
            n += 6 * c.convert_cycles;
        }
        n
    }

    /// The packet `words` clocked in by SPI1 as `timing` says (SCLK period `sck`): the output, or
    /// `None` when the packet is refused (an event says why).
    pub fn receive(&mut self, words: &[u16], timing: &TickTiming) -> Option<DspOutput> {
        let t_irq = timing.packet_end + self.cpu.cycles_to_ps(self.cfg.dmax_word_cycles);
        if let Some(last) = self.last_irq {
            // The RTI compare at the packet rate: more than one period and a half without a packet.
            if t_irq > last + self.period + self.period / 2 {
                let what = format!("C6727: no packet between {last} ps and {t_irq} ps");
                self.events.push(Event::new(t_irq, "packet_missing", Severity::Error, what));
            }
        }
        self.last_irq = Some(t_irq);
        let packet = match Packet::decode(words) {
            Ok(p) => p,
            Err(why) => {
                self.events.push(Event::new(t_irq, "packet_refused", Severity::Error, format!("C6727: {why}")));
                return None;
            }
        };
        if let Some(s) = self.last_sequence.filter(|&s| packet.sequence != s.wrapping_add(1)) {
            let what = format!("C6727: packet {} after {s}", packet.sequence);
            self.events.push(Event::new(t_irq, "packet_missing", Severity::Error, what));
        }
        self.last_sequence = Some(packet.sequence);
        let accel_g = packet.accel.map(|n| f64::from(n) * self.lsb_g);
        let [h, p, r] = packet.compass.map(|n| f64::from(n) / 10.0);
        let g = &packet.gps;
        let gps = [
            f64::from(g.lat_e7) * 1e-7,
            f64::from(g.lon_e7) * 1e-7,
            f64::from(g.alt_cm) / 100.0,
            f64::from(g.speed_cm_s) / 100.0,
            f64::from(g.course_cdeg) / 100.0,
            f64::from(g.utc_ms) / 1000.0,
        ];
        let tilt = tilt([accel_g[6], accel_g[7], accel_g[8]]);
        let cycles = self.handler_cycles(packet.flags);
        Some(DspOutput {
            t_irq,
            t_done: t_irq + self.cpu.cycles_to_ps(cycles),
            rti: self.rti.ps_to_cycles(t_irq),
            packet,
            accel_g,
            compass_deg: [h, p, r],
            gps,
            tilt,
            cycles,
        })
    }

    /// The CPU's cycles in one packet period.
    pub fn cycles_per_period(&self) -> u64 {
        self.cpu.ps_to_cycles(self.period)
    }

    /// Take the DSP's events out.
    pub fn drain_events(&mut self) -> Vec<Event> {
        self.events.drain()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The level formula: exact at the axes, and the claim that f64 meets no subnormal or NaN on
    /// the counts a packet can carry (every combination of the extreme and smallest counts).
    #[test]
    fn tilt_stays_in_normal_doubles() {
        let lsb = adxl345::LSB_G;
        assert_eq!(tilt([0.0, 0.0, 1.0]), [0.0, 0.0]);
        assert_eq!(tilt([-1.0, 0.0, 0.0])[0], std::f64::consts::FRAC_PI_2);
        let counts = [i16::MIN, -1, 0, 1, i16::MAX];
        for a in counts {
            for b in counts {
                for c in counts {
                    let f = [a, b, c].map(|n| f64::from(n) * lsb);
                    let s = f[1] * f[1] + f[2] * f[2];
                    for v in [f[0], f[1], f[2], f[1] * f[1], f[2] * f[2], s, s.sqrt()].into_iter().chain(tilt(f)) {
                        assert!(v == 0.0 || v.is_normal(), "{v} from counts {a}, {b}, {c}");
                    }
                }
            }
        }
    }
}
