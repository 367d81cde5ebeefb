//! A missed deadline, reported the same way by every processor of every board: one `overrun` event
//! (error) at the time the deadline passed, carrying how late the work ended (s) against a required
//! lateness of 0. The reference board's emulator (`emulator::run_tick`: a timer tick arriving while
//! the previous ISR still runs), the gyro-free board's acquisition node (a tick whose handler or
//! packet outlasts the period) and its C6727B (a packet handler still running when the next packet's
//! interrupt is due) all report through [`overrun`].

use crate::events::{Event, Severity};
use crate::time::{ps_to_s, Ps};

/// The `overrun` event of work that should have ended by `deadline_ps` and ended `late_ps` after
/// it; `what` says whose work (processor, tick) and what it overran.
#[cold]
pub fn overrun(deadline_ps: Ps, late_ps: Ps, what: impl Into<String>) -> Event {
    Event::rule(deadline_ps, "overrun", Severity::Error, what, ps_to_s(late_ps), 0.0)
}

/// The `overrun` event of work that started at `start_ps` and ended at `end_ps` when it had to end
/// by `deadline_ps`, or `None` when it ended in time. `who` names the processor and its tick (called
/// only for an overrun).
#[inline]
pub fn check(who: impl FnOnce() -> String, start_ps: Ps, end_ps: Ps, deadline_ps: Ps) -> Option<Event> {
    (end_ps > deadline_ps).then(|| {
        let who = who();
        let late = end_ps - deadline_ps;
        let busy = end_ps.saturating_sub(start_ps);
        let period = deadline_ps.saturating_sub(start_ps).max(1);
        overrun(
            deadline_ps,
            late,
            format!(
                "{who}: busy {:.1} µs ({:.0} % of the {:.1} µs it had), {:.1} µs past its deadline",
                busy as f64 / 1e6,
                100.0 * busy as f64 / period as f64,
                period as f64 / 1e6,
                late as f64 / 1e6
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn work_past_its_deadline_is_one_overrun_event() {
        assert!(check(|| "dsp".into(), 0, 5_000_000_000, 5_000_000_000).is_none());
        let e = check(|| "dsp packet 3".into(), 0, 6_000_000_000, 5_000_000_000).unwrap();
        assert_eq!((e.kind, e.severity, e.t_ps), ("overrun", Severity::Error, 5_000_000_000));
        assert_eq!((e.measured, e.required), (Some(1e-3), Some(0.0)));
        assert!(e.message.contains("120 %"), "{}", e.message);
    }
}
