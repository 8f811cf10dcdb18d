//! Where an editing update's time goes: a per-thread tally of wall time by
//! [`Part`], cheap enough to stay on (one clock read at each end of a part).
//! `nudge run --profile` and `nudge bench --only latency` print it.

use std::cell::RefCell;
use std::time::Instant;

/// A part of an update. The parts do not overlap: each is timed on the
/// thread that runs the update, around work the others do not contain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Part {
    /// Constraint rows and the KKT solve of the differential update.
    Linearise,
    /// Step-reduction trials: simulations with tangents up to the last
    /// constrained time.
    Trials,
    /// Sampling across a change of the collision sequence (all its
    /// simulations, run in parallel, without tangents).
    Sampling,
    /// Simulating the accepted motion again in full, with tangents, when
    /// the trial's could not be kept.
    Resimulate,
    /// The integration error estimate after the motion changed.
    Estimate,
    /// Building the snapshot the screen draws (paths, outlines, readout).
    View,
    /// Drawing a frame.
    Render,
}

impl Part {
    pub const ALL: [Part; 7] = [
        Part::Linearise,
        Part::Trials,
        Part::Sampling,
        Part::Resimulate,
        Part::Estimate,
        Part::View,
        Part::Render,
    ];

    /// A short name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Part::Linearise => "linearise + KKT",
            Part::Trials => "step trials",
            Part::Sampling => "sampling",
            Part::Resimulate => "re-simulate",
            Part::Estimate => "error estimate",
            Part::View => "view snapshot",
            Part::Render => "render",
        }
    }

    fn index(self) -> usize {
        Part::ALL.iter().position(|p| *p == self).unwrap_or(0)
    }
}

/// Calls and wall time (ms) per part since the last [`take`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Profile {
    pub calls: [usize; 7],
    pub ms: [f64; 7],
}

impl Profile {
    /// Calls and milliseconds of one part.
    pub fn get(&self, part: Part) -> (usize, f64) {
        (self.calls[part.index()], self.ms[part.index()])
    }

    /// Add another profile's counts.
    pub fn add(&mut self, other: &Profile) {
        for k in 0..7 {
            self.calls[k] += other.calls[k];
            self.ms[k] += other.ms[k];
        }
    }
}

thread_local! {
    static TALLY: RefCell<Profile> = RefCell::new(Profile::default());
}

/// Run `f`, adding its wall time to `part`.
pub fn time<T>(part: Part, f: impl FnOnce() -> T) -> T {
    let _span = span(part);
    f()
}

/// A part being timed: its time is added when the span is dropped (on
/// every way out of the scope, early returns included).
#[must_use = "the part is timed until the span is dropped"]
pub struct Span {
    part: Part,
    start: Instant,
}

/// Start timing `part` until the returned span is dropped.
pub fn span(part: Part) -> Span {
    Span {
        part,
        start: Instant::now(),
    }
}

impl Drop for Span {
    fn drop(&mut self) {
        let ms = self.start.elapsed().as_secs_f64() * 1e3;
        TALLY.with(|t| {
            let mut t = t.borrow_mut();
            t.calls[self.part.index()] += 1;
            t.ms[self.part.index()] += ms;
        });
    }
}

/// This thread's tally since the last call, which starts a new one.
pub fn take() -> Profile {
    TALLY.with(|t| std::mem::take(&mut *t.borrow_mut()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_are_tallied_and_taken() {
        let _ = take();
        time(Part::Trials, || {
            std::thread::sleep(std::time::Duration::from_millis(2))
        });
        time(Part::Trials, || ());
        let p = take();
        let (calls, ms) = p.get(Part::Trials);
        assert_eq!(calls, 2);
        assert!(ms >= 2.0, "{ms}");
        assert_eq!(p.get(Part::Render), (0, 0.0));
        assert_eq!(take(), Profile::default());
    }
}
