//! Wall-clock measurement: one warm-up run, then repetitions until a
//! count or a time budget is reached; the median is reported with the
//! repetition count.

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::time::{Duration, Instant};

/// Where timings come from: the wall clock, or a deterministic stub in
/// tests and headless replays (whose screens must not depend on timing).
pub trait Clock {
    /// Time since an arbitrary origin; never decreases.
    fn now(&self) -> Duration;
}

/// The monotonic wall clock.
#[derive(Debug, Clone, Copy)]
pub struct Wall(pub Instant);

impl Wall {
    pub fn new() -> Wall {
        Wall(Instant::now())
    }
}

impl Default for Wall {
    fn default() -> Wall {
        Wall::new()
    }
}

impl Clock for Wall {
    fn now(&self) -> Duration {
        self.0.elapsed()
    }
}

/// A stub clock: the k-th reading is `k² · tick`, so each timed call
/// takes a little longer than the one before. Reproducible, and the
/// settings measured one after another get distinct times.
#[derive(Debug, Clone)]
pub struct Ticking {
    pub tick: Duration,
    readings: Cell<u32>,
}

impl Ticking {
    pub fn new(tick: Duration) -> Ticking {
        Ticking {
            tick,
            readings: Cell::new(0),
        }
    }
}

impl Clock for Ticking {
    fn now(&self) -> Duration {
        let k = self.readings.get();
        self.readings.set(k.saturating_add(1));
        self.tick.saturating_mul(k.saturating_mul(k))
    }
}

/// How much effort a run spends per measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Plan {
    /// The reduced run of `--quick`.
    pub quick: bool,
    /// Repetitions at least (after the warm-up) ...
    pub min_reps: usize,
    /// ... and at most.
    pub max_reps: usize,
    /// Repeat until this much time was spent (once `min_reps` are done).
    pub budget: Duration,
}

impl Plan {
    pub(crate) fn new(quick: bool) -> Plan {
        if quick {
            Plan {
                quick,
                min_reps: 1,
                max_reps: 15,
                budget: Duration::from_millis(120),
            }
        } else {
            Plan {
                quick,
                min_reps: 3,
                max_reps: 51,
                budget: Duration::from_millis(800),
            }
        }
    }
}

/// The median of repeated timings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Timing {
    /// Median wall time, ms.
    pub ms: f64,
    /// Number of timed repetitions.
    pub reps: usize,
}

/// Median of `v` (NaN when empty).
pub(crate) fn median(v: &[f64]) -> f64 {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return f64::NAN;
    }
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// Time `f`: a warm-up call, then repetitions per `plan`. A warm-up that
/// alone takes longer than the budget counts as the first repetition (its
/// cold-start cost is negligible against its length). Returns the median
/// and the last call's value; the first error stops the measurement.
pub(crate) fn measure<T, E>(
    plan: &Plan,
    f: impl FnMut() -> Result<T, E>,
) -> Result<(Timing, T), E> {
    measure_with(plan, &Wall::new(), f)
}

/// [`measure`] on `clock`.
pub(crate) fn measure_with<T, E>(
    plan: &Plan,
    clock: &dyn Clock,
    mut f: impl FnMut() -> Result<T, E>,
) -> Result<(Timing, T), E> {
    let start = clock.now();
    let mut last = f()?;
    let warm = clock.now().saturating_sub(start);
    let mut samples = Vec::new();
    let mut spent = Duration::ZERO;
    if warm > plan.budget {
        samples.push(warm.as_secs_f64() * 1e3);
        spent = warm;
    }
    while samples.len() < plan.max_reps && (samples.len() < plan.min_reps || spent < plan.budget) {
        let t = clock.now();
        let value = f()?;
        let e = clock.now().saturating_sub(t);
        last = value;
        spent += e;
        samples.push(e.as_secs_f64() * 1e3);
    }
    Ok((
        Timing {
            ms: median(&samples),
            reps: samples.len(),
        },
        last,
    ))
}

/// Run `f`, turning a panic into an error message so one failing row
/// does not end the benchmark.
pub(crate) fn guarded<T>(f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(p) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(format!("panicked: {msg}"))
        }
    }
}

/// Least-squares slope of `log y` against `log x` over the positive
/// pairs: the growth exponent of `y ∝ x^k`. NaN with fewer than two points.
pub(crate) fn loglog_slope(points: &[(f64, f64)]) -> f64 {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if p.len() < 2 {
        return f64::NAN;
    }
    let n = p.len() as f64;
    let (mx, my) = (
        p.iter().map(|q| q.0).sum::<f64>() / n,
        p.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|q| (q.0 - mx).powi(2)).sum();
    let sxy: f64 = p.iter().map(|q| (q.0 - mx) * (q.1 - my)).sum();
    if sxx > 0.0 { sxy / sxx } else { f64::NAN }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_even_and_empty() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
        assert_eq!(median(&[f64::NAN, 1.0]), 1.0);
    }

    #[test]
    fn measure_counts_repetitions_and_stops_at_the_first_error() {
        let count = |plan: &Plan| {
            let mut calls = 0;
            let (t, v) = measure(plan, || {
                calls += 1;
                Ok::<_, ()>(calls)
            })
            .unwrap_or((
                Timing {
                    ms: f64::NAN,
                    reps: 0,
                },
                0,
            ));
            assert!(t.ms >= 0.0);
            (t.reps, v, calls)
        };
        // A long budget: one warm-up, then repetitions up to max_reps.
        let long = Plan {
            quick: true,
            min_reps: 3,
            max_reps: 5,
            budget: Duration::from_secs(3600),
        };
        assert_eq!(count(&long), (5, 6, 6));
        // A warm-up longer than the budget counts as the first repetition.
        let plan = Plan {
            budget: Duration::ZERO,
            ..long
        };
        assert_eq!(count(&plan), (3, 3, 3));
        let r: Result<(Timing, ()), &str> = measure(&plan, || Err("boom"));
        assert_eq!(r.err(), Some("boom"));
    }

    #[test]
    fn the_stub_clock_makes_timings_reproducible() {
        let plan = Plan::new(true);
        let time = || {
            let clock = Ticking::new(Duration::from_millis(1));
            measure_with(&plan, &clock, || Ok::<_, ()>(())).map(|(t, ())| t)
        };
        let t = time();
        assert_eq!(t, time());
        // Readings 0, 1, 4, 9, 16 ms...: the warm-up takes 1 ms, then 5, 9,
        // 13... until the 120 ms budget is spent.
        assert_eq!(t.map(|t| t.reps).ok(), Some(8));
    }

    #[test]
    fn slope_of_a_power_law() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0]
            .iter()
            .map(|&x: &f64| (x, 3.0 * x.powf(1.5)))
            .collect();
        assert!((loglog_slope(&pts) - 1.5).abs() < 1e-12);
        assert!(loglog_slope(&pts[..1]).is_nan());
    }

    #[test]
    fn panics_become_row_errors() {
        let r: Result<(), String> = guarded(|| panic!("bad row"));
        assert_eq!(r, Err("panicked: bad row".into()));
    }
}
