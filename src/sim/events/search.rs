//! The time-of-impact search of one pair over a window: contact queries,
//! conservative advancement with Newton probes, and the safeguarded
//! Newton–bisection refinement of the root.

use super::{CREEP_STEPS, Pair, Tolerances, World};
use crate::geometry::{Contact, PartContacts, Placement};
use crate::math::Vec3;
use crate::sim::state::{BodyState, Side};
use crate::sim::trajectory::{Counters, Party};

impl World<'_, '_> {
    /// Contact of a pair at time `t`, with the relative normal velocity at
    /// the witness points (negative when approaching).
    pub fn contact(&self, pair: &Pair, t: f64, max_distance: f64) -> Option<(Contact, f64)> {
        let sa = self.state(Party::Body(pair.a), t);
        let sb = self.state(pair.b, t);
        self.contact_with(pair, &sa, &sb, max_distance)
    }

    /// [`World::contact`] taken at a sinking corner deeper than its
    /// witness, or when the witness does not approach (`events::sinking`),
    /// for the search.
    fn contact_sinking(&self, pair: &Pair, t: f64, slack: f64) -> Option<(Contact, f64)> {
        let sa = self.state(Party::Body(pair.a), t);
        let sb = self.state(pair.b, t);
        let found = self.contact_with(pair, &sa, &sb, f64::INFINITY)?;
        Some(self.sinking(pair, &sa, found, slack))
    }

    /// Every part pair's contact within `max_distance` (one contact query).
    pub(super) fn part_contacts_at(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        max_distance: f64,
    ) -> PartContacts {
        Counters::bump(&self.traj.counters.collisions, 1);
        self.placed(pair, sa, sb, |a, b| a.part_contacts(b, max_distance))
    }

    /// `query` of the pair's two parties placed for contact queries (an
    /// obstacle's placement is the simulation's).
    pub(super) fn placed<R>(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        query: impl FnOnce(&Placement, &Placement) -> R,
    ) -> R {
        let pa = self.pose(Party::Body(pair.a), sa);
        let a = Placement::new(self.geometry(Party::Body(pair.a)), &pa);
        match pair.b {
            // A body pivoting or sliding on a face beside other parts of
            // the obstacle is searched against those only (`sim::pivot`,
            // `sim::rest::face`).
            Party::Obstacle(o) => {
                let on = self.traj.tracks[pair.a].segments.last().and_then(|s| {
                    let pivot = s.pivot.as_deref().map(|pv| {
                        let far = pv.lean.map_or(pv.part, |l| l.part);
                        (pv.obstacle, [pv.part, far])
                    });
                    let slide = s
                        .slide
                        .and_then(|sl| Some((sl.obstacle, [sl.face?.part; 2])));
                    pivot.or(slide).filter(|(on, _)| *on == o)
                });
                match on {
                    Some((_, parts)) => query(&a, &self.obstacles[o].without(&parts)),
                    None => query(&a, &self.obstacles[o]),
                }
            }
            Party::Body(_) => {
                let pb = self.pose(pair.b, sb);
                query(&a, &Placement::new(self.geometry(pair.b), &pb))
            }
        }
    }

    /// The closest of `contacts` (the first of equals, as [`contact`]
    /// picks it), with its relative normal velocity (negative when
    /// approaching).
    pub(super) fn closest(
        contacts: &[Contact],
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
    ) -> Option<(Contact, f64)> {
        let c = *contacts
            .iter()
            .min_by(|x, y| x.distance.total_cmp(&y.distance))?;
        Some((c, Self::normal_rate(&c, sa, sb)))
    }

    pub(super) fn normal_rate(c: &Contact, sa: &Option<BodyState>, sb: &Option<BodyState>) -> f64 {
        let va = sa.map(|s| s.velocity_at(&c.point_a)).unwrap_or_default();
        let vb = sb.map(|s| s.velocity_at(&c.point_b)).unwrap_or_default();
        c.normal.dot(&(va - vb))
    }

    pub(super) fn contact_with(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        max_distance: f64,
    ) -> Option<(Contact, f64)> {
        Counters::bump(&self.traj.counters.collisions, 1);
        let c = self.placed(pair, sa, sb, |a, b| a.contact(b, max_distance))?;
        Some((c, Self::normal_rate(&c, sa, sb)))
    }

    /// Axis-aligned box containing body `i` over `[t0, t1]`.
    pub fn sweep_box(&self, i: usize, t0: f64, t1: f64) -> (Vec3, Vec3) {
        let a = self.traj.state(i, t0, Side::Post);
        let b = self.traj.state(i, t1, Side::Post);
        let dt = t1 - t0;
        let d = &self.traj.dynamics[i];
        let g = self.traj.gravity.norm();
        let accel = g + self.slide_decel(i, t0) + d.drag_k.unwrap_or(0.0) * (a.v.norm() + g * dt);
        let pad = d.reach + accel * dt * dt / 8.0 + 1e-9;
        let lo = a.x.inf(&b.x).add_scalar(-pad);
        let hi = a.x.sup(&b.x).add_scalar(pad);
        (lo, hi)
    }

    /// Safeguarded Newton–bisection on `E(t) = distance + skin` in
    /// `[lo, hi]` with `E(lo) > 0 ≥ E(hi)`.
    pub(super) fn refine(
        &self,
        pair: &Pair,
        skin: f64,
        mut lo: f64,
        mut hi: f64,
        tol: f64,
    ) -> Option<(f64, Contact)> {
        let mut t = hi;
        let mut best: Option<(f64, Contact)> = None;
        for _ in 0..200 {
            let (c, rate) = self.contact_sinking(pair, t, 10.0 * tol)?;
            let e = c.distance + skin;
            if e.abs() <= tol {
                return Some((t, c));
            }
            if e > 0.0 {
                lo = t;
            } else {
                hi = t;
                best = Some((t, c));
            }
            if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(1.0) {
                break;
            }
            let tn = if rate != 0.0 { t - e / rate } else { f64::NAN };
            t = if tn > lo && tn < hi {
                tn
            } else {
                0.5 * (lo + hi)
            };
        }
        best.or_else(|| {
            self.contact_sinking(pair, hi, 10.0 * tol)
                .map(|(c, _)| (hi, c))
        })
    }

    /// The first time in `[t0, t1]` at which the pair's event function
    /// crosses zero while approaching, by conservative advancement: from a
    /// gap `e` and a speed bound `a + b τ`, no contact can happen before
    /// the `τ` solving `a τ + b τ² = e`.
    ///
    /// # Errors
    /// The time reached when the search ran out of iterations without
    /// deciding (see [`super::SimError::EventSearchStalled`]), or, when the
    /// scene has a micro-collision floor (`rest_speed > 0`: every pair's
    /// floor is then positive, `sim::rest::thresholds`), crept
    /// [`CREEP_STEPS`] steps in a row inside the contact band without the
    /// contact approaching.
    pub fn find_impact(
        &self,
        pair: &Pair,
        t0: f64,
        t1: f64,
        tol: &Tolerances,
    ) -> Result<Option<(f64, Contact)>, f64> {
        let mut skin = if pair.armed { 0.0 } else { tol.arm };
        let hit = 10.0 * tol.root;
        let mut t = t0.max(pair.hold);
        if t > t1 {
            return Ok(None);
        }
        let mut last_positive: Option<f64> = None;
        // Whether a Newton probe has landed short of the root: the gap
        // closes ever slower (a convex approach, a corner turning in), so
        // Newton from above never brackets it, while the certified steps'
        // quadratic bound converges as fast. Probe again only near it.
        let mut short = false;
        // Steps in a row inside the contact band, not approaching.
        let mut creep = 0;
        for _ in 0..10_000 {
            let sa = self.state(Party::Body(pair.a), t);
            let sb = self.state(pair.b, t);
            let ba = self.bounds(Party::Body(pair.a), &sa, t);
            let bb = self.bounds(pair.b, &sb, t);
            let rem = t1 - t;
            let reach = Self::reach_in(&ba, &bb, rem) + hit + skin;
            // One query serves both the closest contact and the
            // separating planes of every part pair.
            let planes = self.part_contacts_at(pair, &sa, &sb, reach);
            let Some(found) = Self::closest(&planes, &sa, &sb) else {
                return Ok(None);
            };
            // (A witness within ten arm distances: the contact query's gap
            // is off by a few 1e-9 m where a face lies nearly flush.)
            let (c, rate) = if found.0.distance <= 10.0 * tol.arm {
                self.sinking(pair, &sa, found, hit)
            } else {
                found
            };
            if c.distance > tol.arm {
                // Separated by more than the arm distance: the event is armed
                // again for the rest of the search.
                skin = 0.0;
            }
            let e = c.distance + skin;
            if e <= hit && rate < 0.0 {
                if e.abs() <= tol.root {
                    return Ok(Some((t, c)));
                }
                if e < 0.0 {
                    return Ok(match last_positive {
                        Some(lo) => self.refine(pair, skin, lo, t, tol.root),
                        None => Some((t, c)),
                    });
                }
            }
            if e > hit {
                last_positive = Some(t);
            }
            if rate < 0.0 && (!short || e <= 1e3 * hit) {
                // Newton probe: bracket the root early when it is near.
                let tn = t - e / rate;
                if tn > t
                    && tn <= t1
                    && let Some((cn, rate_n)) = self.contact_sinking(pair, tn, hit)
                {
                    let en = cn.distance + skin;
                    if en <= 0.0 {
                        return Ok(self.refine(pair, skin, t, tn, tol.root));
                    }
                    if en <= tol.root && rate_n < 0.0 {
                        // The probe landed on the root itself, approaching:
                        // the bracket's refinement would return this very
                        // time. (Certified steps would crawl the last
                        // nanometres to it.)
                        return Ok(Some((tn, cn)));
                    }
                    short = true;
                }
            }
            if ba.iter().chain(&bb).all(|&(a, b)| a <= 0.0 && b <= 0.0) {
                return Ok(None);
            }
            // Largest safe advance; inside the contact band, step just past it.
            let gap = if e > hit {
                e - 0.5 * hit
            } else {
                (2.0 * hit - e).max(hit)
            };
            let mut tau = Self::advance(&ba, &bb, gap);
            let [rearm, in_skin, graze] = self
                .plane_steps(
                    pair,
                    &sa,
                    &sb,
                    &planes,
                    [-0.5 * hit, skin - 0.5 * hit, skin - tol.root],
                    reach,
                    t,
                    rem,
                )
                .map_or([None; 3], |steps| steps.map(Some));
            if let Some(tp) = rearm
                && tp > tau
            {
                // Every point's next descent to the plane is bounded: the
                // contact just resolved is behind us, so re-arm.
                tau = tp;
                skin = 0.0;
            } else if skin > 0.0
                && let Some(tp) = in_skin
                && tp > tau
            {
                // A disarmed pair whose point still sits in the skin (a slow
                // separation after an impulse): the global speed bound would
                // crawl here for thousands of steps; the per-point bound says
                // no point sinks below the skin before `tp`. Stay disarmed.
                tau = tp;
            } else if e <= hit
                && rate < 0.0
                && let Some(tp) = graze
                && tp > tau
            {
                // Approaching inside the contact band, but too slowly for the
                // speed bound (a grazing contact): step to the earliest time
                // the gap could reach the root tolerance.
                tau = tp;
            }
            t += tau.max(f64::EPSILON * t.abs().max(1.0));
            if t > t1 {
                return Ok(None);
            }
            creep = if e <= hit && rate >= 0.0 {
                creep + 1
            } else {
                0
            };
            if self.scene.rest_speed > 0.0 && creep >= CREEP_STEPS {
                return Err(t);
            }
        }
        // No progress in the iteration budget: report it rather than let
        // the pair pass through each other unseen (that was the "bodies
        // sink through the floor" bug).
        Err(t)
    }
}
