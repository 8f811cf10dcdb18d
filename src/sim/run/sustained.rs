//! Two moving bodies in sustained contact: a box riding a struck box, a
//! tower's upper boxes knocked off together (docs/design.md §4).
//!
//! Two bodies falling together under gravity have no relative
//! acceleration: face on face, their gap stays within nanometres of the
//! root, neither closing (no impact) nor clearing (no re-arming). The
//! conservative advancement bounds each body's own motion (`|v| + ω r`
//! over a gap of nanometres), so it steps nanoseconds at a time and runs
//! out of iterations: `EventSearchStalled`. (Diagnosed on the tower of
//! five struck at its middle box: box3 on box4 woken at rest, gap −1e-9 m
//! (the skin), relative normal rate 0, steps of 7e-9 s; struck at the
//! second box, both flying at 1.4 m/s, gap 6e-9 m, separating at 4e-4 m/s,
//! steps of 7e-9 s.)
//!
//! Such a search is creeping in a sustained contact. It stops once it has
//! crept [`CREEP_STEPS`] steps in a row inside the contact band without
//! the contact approaching (or, failing that, at the end of its iteration
//! budget), and the contact ends as a *push*: at that time the pair takes a
//! micro-collision impulse (`sim::rest`, rule 3) that leaves the contact
//! separating at the pair's floor `v_min` (the larger rest speed of the
//! two), with friction as at any impact. It is an event like any other
//! (`Event::micro`), adds at most `½ μ v_min²` of energy (`μ` the pair's
//! reduced mass, below either mass) and, with the pair separating at
//! `v_min` at least, the search clears the contact in a bounded number of
//! steps; gravity brings a body riding on a supported one back within
//! `2 v_min / g`, as a micro-collision hop. A frozen party is anchored as
//! at any slow contact. Two bodies already separating faster than `v_min`
//! (a fast spin at a nanometre gap) take no impulse: the contact is a graze,
//! and the pair's search resumes just past it, as at any graze (bounded by
//! the graze guard).
//!
//! A body against an obstacle creeps the same way: scissors spinning at
//! 60 rad/s, a handle's corner at the coatrack's base 6e-13 m outside the
//! skin and separating at 1.2e-5 m/s, advanced 4e-12 s a step and ran
//! out of iterations (73 ms for one sampled world, lost to an error). It
//! is pushed the same way, with the body's rest speed as the floor. Only
//! with no floor (`rest_speed = 0`) does a stall stop the run with
//! `EventSearchStalled`, naming the two and the time.
//!
//! [`CREEP_STEPS`]: crate::sim::events::CREEP_STEPS

use super::*;

impl Sim<'_> {
    /// The micro-collision floor of a pair: the larger rest speed of its
    /// bodies (`sim::rest`).
    pub(super) fn pair_floor(&self, pair: &Pair) -> f64 {
        std::iter::once(pair.a)
            .chain(pair.b_body())
            .map(|i| self.rest_thresholds(i).0)
            .fold(0.0, f64::max)
    }

    /// A pair's search stalled at `t`: with a micro-collision floor, the
    /// contact there (pushed apart if slower than the floor, passed as a
    /// graze if not); otherwise the error.
    pub(super) fn stall(
        &self,
        world: &World<'_, '_>,
        pair: &Pair,
        t: f64,
    ) -> Result<(f64, crate::geometry::Contact), SimError> {
        if self.pair_floor(pair) > 0.0
            && let Some((c, _)) = world.contact(pair, t, f64::INFINITY)
        {
            return Ok((t, c));
        }
        Err(SimError::EventSearchStalled {
            a: self.scene.bodies[pair.a].name.clone(),
            b: self.party_name(pair.b),
            t,
        })
    }
}
