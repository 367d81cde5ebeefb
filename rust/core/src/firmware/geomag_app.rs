//! The geomagnetic–gyro board's firmware (`firmware.application = "ads8344-geomag"`, issue 21): every
//! timer tick it converts the ADS8344's eight channels over SPI-A (a chip-select window per channel:
//! the control byte then three read bytes in 8-bit characters, as both published drivers do; the
//! result is the 16 bits after the null bit, `(b1·2¹⁶ + b2·2⁸ + b3) >> 7`), turns the codes into the
//! gyro's rates (compensated with the profile's calibration table), the magnetometer's field and the
//! board temperature, and every three ticks runs the three-sample rotation vector with the
//! magnetometer roll aid (`geomag.rs`) and the spin-body Euler angles.
//!
//! Channels (`[geomag]`, `device::analog::FrontEnd`): CH0–CH2 gyro x, y, z; CH3–CH5 magnetometer
//! x, y, z; CH6 temperature (0.5 V + 10 mV/°C); CH7 spare (VREF/2, read and kept in the read row).
//!
//! Output: a read row per tick (words 0…7: the eight codes; `rate`: the compensated rates, rad/s;
//! `accel`: the field, gauss), a cycle row per update (quaternion; Euler angles as roll about the
//! spin axis x, pitch, yaw in `spin_euler`'s convention; velocity zero; position the profile's
//! start), a budget row per tick, the aid's gate events and the ADC's rule events.

use super::application::{app_kind, AppKind, Application};
use super::geomag::{spin_euler, AidGains, GyroCalibration, Spin};
use super::isr::{Poller, StageCosts};
use super::{lit, Quat, Vec3};
use crate::board::analog::geomag_section;
use crate::board::{Board, Sensor};
use crate::device::ads8344::Control;
use crate::error::{Error, Result};
use crate::events::{Event, EventLog};
use crate::numerics::{QClass, Scalar};
use crate::output::{BudgetRow, CycleRow, Output, ReadRow};
use crate::profile::{Geomag, OverrunPolicy, Profile};
use crate::time::{ps_to_s, Ps};
use crate::timing::costs::IoCosts;

/// Channels converted every tick.
pub const CHANNELS: usize = 8;
/// Rate samples per attitude update (the three-sample rotation vector).
pub const SAMPLES: usize = 3;
/// Characters per conversion: the control byte and three read bytes.
pub const CHARS: usize = 4;
/// Power-down bits of the control byte: 11, external clock, no power-down between conversions.
const PD_EXTERNAL: u8 = 3;

/// The firmware's computing stages, generic over the numeric type (the timing model counts them).
pub struct GeomagLoop<T: Scalar> {
    /// Volts per ADC code.
    volts_per_code: f64,
    /// Per gyro axis: (null V, rad/s per V).
    gyro: [(T, T); 3],
    /// Magnetometer: (null V, gauss per V).
    mag: (T, T),
    cal: GyroCalibration<T>,
    /// The attitude loop.
    pub spin: Spin<T>,
    mag_n: Vec3<T>,
    /// The latest measured field, gauss (body axes).
    pub mag_b: Vec3<T>,
    /// The latest board temperature, °C.
    pub temp_c: T,
    /// The sample interval, s.
    dt: T,
}

impl<T: Scalar> GeomagLoop<T> {
    /// The stages of a profile (its `[geomag]` table; the tick period `tick_s`).
    pub fn new(profile: &Profile, tick_s: f64) -> Result<Self> {
        let g = geomag_section(profile)?;
        let x = crate::board::analog::gyro_preset("geomag.gyro_x", &g.gyro_x)?;
        let yz = crate::board::analog::gyro_preset("geomag.gyro_yz", &g.gyro_yz)?;
        let m = crate::board::analog::magnetometer_preset(&g.magnetometer)?;
        let gyro = [x, yz, yz].map(|p| {
            (T::from_f64(p.null_v, QClass::Generic), T::from_f64(1.0 / p.volts_per_dps.to_degrees(), QClass::Generic))
        });
        let axes = g.calibration;
        let q0 = initial_attitude(profile, g);
        Ok(GeomagLoop {
            volts_per_code: g.vref_v / 65536.0,
            gyro,
            mag: (T::from_f64(m.null_v, QClass::Generic), T::from_f64(1.0 / m.volts_per_gauss, QClass::Generic)),
            cal: GyroCalibration::new(&axes),
            spin: {
                let mut spin = Spin::new(q0.map(|x| T::from_f64(x, QClass::Quat)), SAMPLES as f64 * tick_s, gains(g));
                if let Some(gate) = g.aid_axis_gate_deg {
                    spin = spin.with_axis_gate(gate);
                }
                if g.cross_gyro_cutoff_hz > 0.0 {
                    spin = spin.with_cross_lag(g.cross_gyro_cutoff_hz);
                }
                match g.gyro_delay_s {
                    Some(tau) => spin.with_gyro_delay(tau),
                    None => spin,
                }
            },
            mag_n: g.field_enu_gauss.map(|x| T::from_f64(x, QClass::Nav)),
            mag_b: [lit(0.0); 3],
            temp_c: lit(25.0),
            dt: lit(tick_s),
        })
    }

    /// Decode one tick's codes: the board temperature and the field are kept, the compensated
    /// angle increments over the tick (rad) returned with the compensated rates (rad/s).
    pub fn decode(&mut self, codes: &[u16; CHANNELS]) -> (Vec3<T>, Vec3<T>) {
        let lsb: T = lit(self.volts_per_code);
        let volts = |code: u16| (T::from_f64(f64::from(code), QClass::Generic) * lsb).to_class(QClass::Generic);
        self.temp_c = ((volts(codes[6]) - lit(0.5)) * lit(100.0)).to_class(QClass::Generic);
        let measured: Vec3<T> =
            std::array::from_fn(|i| ((volts(codes[i]) - self.gyro[i].0) * self.gyro[i].1).to_class(QClass::Rate));
        self.mag_b = std::array::from_fn(|i| ((volts(codes[3 + i]) - self.mag.0) * self.mag.1).to_class(QClass::Nav));
        let rate = self.cal.compensate(&measured, self.temp_c);
        (rate, rate.map(|w| (w * self.dt).to_class(QClass::Rate)))
    }

    /// One update from three angle increments, then the aid with the latest field (its gate event,
    /// if the gate changed, at `t`; the axis check's, if any, from [`Spin::take_event`]).
    pub fn update(&mut self, dtheta: &[Vec3<T>; SAMPLES], t: Ps) -> Result<Option<Event>> {
        self.spin.propagate(dtheta)?;
        let (_, event) = self.spin.aid(&self.mag_b, &self.mag_n, t);
        Ok(event)
    }

    /// Yaw, pitch, roll (rad) of the spinning body.
    pub fn euler(&self) -> [T; 3] {
        spin_euler(&self.spin.q)
    }
}

/// The aid's gains from `[geomag]`.
fn gains(g: &Geomag) -> AidGains {
    AidGains {
        kp: g.aid_kp,
        ki: g.aid_ki,
        gate_gauss: g.aid_gate_gauss,
        mag_cutoff_hz: (g.mag_cutoff_hz > 0.0).then_some(g.mag_cutoff_hz),
    }
}

/// The start attitude: with `geomag.launch_elevation_deg` the launcher's direction (the spin axis
/// at that pitch and `launch_azimuth_deg` clockwise from north, roll 0: yaw ψ = 90° − azimuth about
/// up from east, `spin_quat`'s convention); otherwise `firmware.initial_yaw_deg` about up, level (the
/// body at rest on its mount).
fn initial_attitude(profile: &Profile, g: &Geomag) -> Quat<f64> {
    match g.launch_elevation_deg {
        Some(elevation) => {
            let azimuth = g.launch_azimuth_deg.unwrap_or(0.0);
            super::geomag::spin_quat((90.0 - azimuth).to_radians(), elevation.to_radians(), 0.0)
        }
        None => super::geomag::spin_quat(profile.firmware.initial_yaw_deg.to_radians(), 0.0, 0.0),
    }
}

/// The application: the acquisition and the loop on the board.
pub struct GeomagApp<T: Scalar> {
    lp: GeomagLoop<T>,
    stages: StageCosts,
    io: IoCosts,
    poller: Poller,
    overrun: OverrunPolicy,
    control: [u8; CHANNELS],
    samples: [Vec3<T>; SAMPLES],
    gathered: usize,
    step: u64,
    tick_s: f64,
    start_pos: [f64; 3],
    next_pending: u64,
    out: Output,
    events: EventLog,
}

impl<T: Scalar> GeomagApp<T> {
    /// The firmware of a profile on `board`, with the stage and I/O costs of the timing model.
    pub fn new<S: Sensor>(profile: &Profile, board: &Board<S>, stages: StageCosts, io: &IoCosts) -> Result<Self> {
        if app_kind(&profile.firmware.application)? != AppKind::Ads8344Geomag {
            return Err(Error::Profile(format!(
                "key `firmware.application` = \"{}\": this is the \"ads8344-geomag\" firmware's build",
                profile.firmware.application
            )));
        }
        if profile.firmware.overrun == OverrunPolicy::Nest {
            return Err(Error::Profile(
                "key `firmware.overrun` = \"nest\": the ads8344-geomag firmware does not re-enable interrupts \
                 (expected \"queue\" or \"drop\")"
                    .into(),
            ));
        }
        let tick_s = ps_to_s(board.timer.tick_ps(1));
        let nav = &profile.navigation;
        Ok(GeomagApp {
            lp: GeomagLoop::new(profile, tick_s)?,
            stages,
            io: io.clone(),
            poller: Poller::of(profile, board),
            overrun: profile.firmware.overrun,
            control: std::array::from_fn(|ch| Control::single_ended(ch, PD_EXTERNAL)),
            samples: [[lit(0.0); 3]; SAMPLES],
            gathered: 0,
            step: 0,
            tick_s,
            start_pos: [nav.latitude_deg, nav.longitude_deg, nav.height_m],
            next_pending: 1,
            out: Output::default(),
            events: EventLog::default(),
        })
    }

    /// One conversion: CS↓, the control byte and three read bytes, CS↑; returns the code and the
    /// times of CS↓ and CS↑.
    fn convert<S: Sensor>(&mut self, board: &mut Board<S>, c: &mut u64, ch: usize) -> Result<(u16, Ps, Ps)> {
        *c += u64::from(self.io.gpio_write);
        let t_cs = board.ps(*c);
        board.link.set_gpio57(false, t_cs)?;
        let poll = self.poller;
        let read_cost = u64::from(self.io.peripheral_read);
        let mut bytes = [0u32; CHARS];
        let mut seen = (*c, t_cs);
        for (i, b) in bytes.iter_mut().enumerate() {
            let ready = board.link.buffull_clear_time();
            *c = poll.until_seen(*c, ready, seen, "BUFFULL_FLAG = 0")?;
            *c += u64::from(self.io.peripheral_write);
            // 8-bit characters: SPITXBUF is sent from its top byte, SPIRXBUF holds the byte received
            // in its low bits.
            let word = if i == 0 { u16::from(self.control[ch]) << 8 } else { 0 };
            let mut read_cycle = *c;
            let rx = board.link.write_poll_read(word, board.ps(*c), |done| {
                read_cycle = poll.until_flag(read_cycle, done, "INT_FLAG = 1")? + read_cost;
                seen = (read_cycle, poll.sysclk.cycles_to_ps(read_cycle));
                Ok(seen.1)
            })?;
            *c = read_cycle + u64::from(self.io.store_word + self.io.frame_loop);
            *b = u32::from(rx & 0xFF);
        }
        *c += u64::from(self.io.gpio_write);
        let t_rise = board.ps(*c);
        board.link.set_gpio57(true, t_rise)?;
        let code = (((bytes[1] << 16) | (bytes[2] << 8) | bytes[3]) >> 7) as u16;
        Ok((code, t_cs, t_rise))
    }
}

impl<T: Scalar, S: Sensor> Application<S> for GeomagApp<T> {
    fn isr(&mut self, board: &mut Board<S>, k: u64, tick_ps: Ps, start: u64, overrun: bool) -> Result<u64> {
        let tick_cycle = board.tick_cycle(k);
        let mut c = start + self.stages.entry;
        let entry_end = c;
        let mut codes = [0u16; CHANNELS];
        let (mut t_first, mut t_last) = (0, 0);
        for (ch, code) in codes.iter_mut().enumerate() {
            let (v, t_cs, t_rise) = self.convert(board, &mut c, ch)?;
            if ch == 0 {
                t_first = t_cs;
            }
            (*code, t_last) = (v, t_rise);
        }
        let (rate, dtheta) = self.lp.decode(&codes);
        c += self.stages.decode.cycles;
        let decode_end = c;
        let mut words = [0u16; crate::output::READ_WORDS];
        words[..CHANNELS].copy_from_slice(&codes);
        self.out.reads.push(ReadRow {
            tick: k,
            t_cs_ps: t_first,
            t_start_ps: t_first,
            t_end_ps: t_last,
            words,
            rate: rate.map(|x| x.to_f64()),
            accel: self.lp.mag_b.map(|x| x.to_f64()),
            sample_index: -1,
            sample_ps: t_first,
            assumed_s: ps_to_s(tick_ps),
            age_ps: 0,
        });
        self.samples[self.gathered] = dtheta;
        self.gathered += 1;
        let step = self.gathered == SAMPLES;
        let mut ends = [decode_end; 3];
        if step {
            self.gathered = 0;
            if let Some(e) = self.lp.update(&self.samples, board.ps(c))? {
                self.events.push(e);
            }
            if let Some(e) = self.lp.spin.take_event() {
                self.events.push(e);
            }
            c += self.stages.attitude.cycles;
            ends[0] = c;
            let [yaw, pitch, roll] = self.lp.euler().map(|a| a.to_f64().to_degrees());
            c += self.stages.euler.cycles;
            ends[1] = c;
            ends[2] = c;
            self.out.cycles.push(CycleRow {
                step: self.step,
                t_ps: tick_ps,
                quat: self.lp.spin.q.map(|x| x.to_f64()),
                euler_deg: [roll, pitch, yaw],
                vel_enu: [0.0; 3],
                pos: self.start_pos,
            });
            self.step += 1;
        }
        c += self.stages.exit;
        let ends = ends.map(|e| board.ps(e));
        self.out.budget.push(BudgetRow {
            tick: k,
            tick_ps,
            start_ps: if start == tick_cycle { tick_ps } else { board.ps(start) },
            entry_end_ps: board.ps(entry_end),
            spi_start_ps: t_first,
            spi_end_ps: t_last,
            decode_end_ps: board.ps(decode_end),
            attitude_end_ps: ends[0],
            euler_end_ps: ends[1],
            nav_end_ps: ends[2],
            end_ps: board.ps(c),
            deadline_ps: board.ps(tick_cycle + board.timer.period_cycles()),
            step,
            overrun,
        });
        let _ = self.tick_s;
        Ok(c)
    }
    fn overrun(&self) -> OverrunPolicy {
        self.overrun
    }
    fn reads_per_tick(&self) -> usize {
        1
    }
    fn sampled_reads(&self) -> bool {
        false
    }
    fn next_pending(&self) -> u64 {
        self.next_pending
    }
    fn set_next_pending(&mut self, k: u64) {
        self.next_pending = k;
    }
    fn nested(&self) -> u64 {
        0
    }
    fn output(&mut self) -> &mut Output {
        &mut self.out
    }
    fn events(&mut self) -> &mut EventLog {
        &mut self.events
    }
    fn stage_costs(&self) -> &StageCosts {
        &self.stages
    }
}
