//! Bodies resting on bodies: islands that freeze when held, and wake when
//! struck (docs/design.md §4, `sim::island` for the statics).
//!
//! A body is *slow* when every point of it moves slower than its rest speed
//! `v_r` (`sim::rest`). After an impact whose party is slow and touches
//! other bodies, the *island* is gathered: from the slow parties, every
//! body within the support band that is slow or frozen; from a frozen body
//! only other frozen bodies (what it rests on, transitively down to the
//! obstacles). When the contact forces of the island — at its contacts
//! with obstacles and between its bodies, equal and opposite — can balance
//! every weight inside the friction pyramids, all its moving bodies freeze
//! where they are. A frozen island costs nothing per step: its pairs with
//! obstacles and among its bodies are not searched.
//!
//! A moving body meeting a frozen one slower than `MICRO · v_r` is a
//! contact with a support: the frozen body is *anchored* (immovable in the
//! impulse, its mass and inertia scaled by [`ANCHOR`]) and stays frozen, so
//! gravity and slow neighbours never wake a stack. So is an impact from
//! above, whose normal out of the frozen body is within 45° of the vertical
//! ([`FROM_ABOVE`]): a held island passes a push from above to the ground
//! (shock propagation, Guendelman, Bridson & Fedkiw 2003: the bodies below
//! act as if infinitely heavy). This neglects the tipping such a push can
//! cause. Any other impact is a real collision: the frozen body takes its
//! impulse and it and every frozen body lying on it (contacts whose normal
//! points up from it, transitively) wake with their frozen state, starting
//! new segments.
//!
//! Jacobians, with the event sequence fixed (which bodies freeze or wake
//! at which event does not change under the perturbation): freezing and
//! waking happen at an impact's time `t_c(u)`, and change only velocities,
//! so they carry the tangent across as the saltation of that map does
//! (`tangent_across`): a body freezing keeps `J + F dt_c/du` on its
//! position and orientation rows, zero on its velocity rows; a woken body
//! starts from its frozen tangent less `F⁺ dt_c/du` (it starts falling
//! when the event happens). An anchored party's flow is zero in the
//! impulse's saltation, and a party held still after it has zero velocity
//! rows. Only a body without a tangent before the event (or an event
//! without `dt_c/du`) is flagged lost (`TangentError::Contact`).

use super::*;
use crate::sim::island::{self, IslandBody, IslandContact};

/// Mass and inertia factor of an anchored (frozen) party in the impulse of
/// a slow contact: its velocity change is 1e-15 of the other party's.
pub(super) const ANCHOR: f64 = 1e15;

/// An impact on a frozen body whose normal out of it has at least this
/// upward component (cos 45°) anchors it.
pub(super) const FROM_ABOVE: f64 = std::f64::consts::FRAC_1_SQRT_2;

impl Sim<'_> {
    /// Whether body `i` is frozen now (its current segment rests).
    pub(super) fn frozen(&self, i: usize) -> bool {
        self.traj.tracks[i].segments.last().is_some_and(|s| s.rest)
    }

    /// The rest speed `v_r` and support band of body `i`.
    pub(super) fn rest_thresholds(&self, i: usize) -> (f64, f64) {
        rest::thresholds(
            self.scene,
            &self.traj.dynamics[i],
            &self.traj.gravity,
            self.tol.arm,
        )
    }

    /// Whether body `i` in state `s` is slow enough to rest.
    pub(super) fn slow(&self, i: usize, s: &BodyState) -> bool {
        let v_r = self.rest_thresholds(i).0;
        v_r > 0.0 && rest::slower_than(self.scene, i, s, v_r)
    }

    /// The support points of body `i` on body `j` (normals from `j` into
    /// `i`), empty when they are farther apart than `i`'s band.
    pub(super) fn body_supports(
        &self,
        i: usize,
        si: &BodyState,
        j: usize,
        sj: &BodyState,
    ) -> Vec<crate::geometry::NearPoint> {
        let band = self.rest_thresholds(i).1;
        let d = &self.traj.dynamics;
        if (si.x - sj.x).norm() > d[i].reach + d[j].reach + band {
            return Vec::new();
        }
        crate::geometry::near_points(
            &self.scene.bodies[i].geometry,
            &si.pose(),
            &self.scene.bodies[j].geometry,
            &sj.pose(),
            band,
        )
    }

    /// The bodies of `i`'s listed pairs.
    pub(super) fn neighbours(&self, i: usize) -> Vec<usize> {
        self.pairs_of[i]
            .iter()
            .filter_map(|&k| {
                let p = &self.pairs[k];
                match p.b {
                    Party::Body(j) if p.a == i => Some(j),
                    Party::Body(_) => Some(p.a),
                    Party::Obstacle(_) => None,
                }
            })
            .collect()
    }

    /// The island of the slow `seeds` (with their post-impulse states) at
    /// `tc`, when it has a contact between bodies and is held: every moving
    /// body in it, with its state. `None` otherwise.
    ///
    /// # Errors
    /// [`SimError::IslandUnsolved`] when its contact-force solve did not
    /// converge.
    pub(super) fn held_island(
        &self,
        tc: f64,
        seeds: &[(usize, BodyState)],
    ) -> Result<Option<Vec<(usize, BodyState)>>, SimError> {
        let scene = self.scene;
        let gravity = self.traj.gravity;
        let state = |i: usize| {
            seeds
                .iter()
                .find(|(j, _)| *j == i)
                .map_or_else(|| self.traj.state(i, tc, Side::Post), |(_, s)| *s)
        };
        let mut members: Vec<(usize, BodyState, bool)> = seeds
            .iter()
            .filter(|(i, s)| !self.frozen(*i) && self.slow(*i, s))
            .map(|(i, s)| (*i, *s, false))
            .collect();
        if members.is_empty() {
            return Ok(None);
        }
        let mut contacts = Vec::new();
        let mut k = 0;
        while k < members.len() {
            let (i, si, frozen_i) = members[k];
            for j in self.neighbours(i) {
                if members.iter().any(|(b, _, _)| *b == j) {
                    continue;
                }
                let frozen_j = self.frozen(j);
                let sj = state(j);
                // From a frozen body only frozen ones join; from a moving one
                // frozen or slow ones.
                let joins = frozen_j || !frozen_i && self.slow(j, &sj);
                if !joins {
                    continue;
                }
                if !self.body_supports(i, &si, j, &sj).is_empty() {
                    members.push((j, sj, frozen_j));
                }
            }
            k += 1;
        }
        if members.len() < 2 {
            return Ok(None);
        }
        let index = |b: usize| members.iter().position(|(m, _, _)| *m == b);
        let friction = |mu_a: f64, mu_b: f64| {
            if scene.effects.friction {
                (mu_a * mu_b).sqrt()
            } else {
                0.0
            }
        };
        for (k, (i, si, _)) in members.iter().enumerate() {
            let band = self.rest_thresholds(*i).1;
            for (o, ob) in scene.obstacles.iter().enumerate() {
                let mu = rest::pair_friction(scene, *i, o);
                for p in crate::geometry::near_points(
                    &scene.bodies[*i].geometry,
                    &si.pose(),
                    &ob.geometry,
                    &ob.pose,
                    band,
                ) {
                    contacts.push(IslandContact {
                        a: k,
                        b: None,
                        point: p.point,
                        normal: p.normal,
                        friction: mu,
                    });
                }
            }
            for j in self.neighbours(*i) {
                let Some(m) = index(j).filter(|&m| m > k) else {
                    continue;
                };
                let mu = friction(scene.bodies[*i].friction, scene.bodies[j].friction);
                for p in self.body_supports(*i, si, j, &members[m].1) {
                    contacts.push(IslandContact {
                        a: k,
                        b: Some(m),
                        point: p.point,
                        normal: p.normal,
                        friction: mu,
                    });
                }
            }
        }
        Counters::bump(&self.traj.counters.islands, 1);
        let bodies: Vec<IslandBody> = members
            .iter()
            .map(|(i, s, _)| IslandBody {
                com: s.x,
                mass: self.traj.dynamics[*i].mass,
            })
            .collect();
        let lever = members
            .iter()
            .map(|(i, _, _)| self.traj.dynamics[*i].reach)
            .fold(0.0, f64::max);
        let held = island::solve(&bodies, &contacts, &gravity, lever)
            .map_err(|e| SimError::IslandUnsolved {
                bodies: members
                    .iter()
                    .map(|(i, _, _)| format!("\"{}\"", scene.bodies[*i].name))
                    .collect::<Vec<_>>()
                    .join(", "),
                t: tc,
                iterations: e.iterations,
            })?
            .is_some();
        Ok(held.then(|| {
            members
                .into_iter()
                .filter(|(_, _, frozen)| !frozen)
                .map(|(i, s, _)| (i, s))
                .collect()
        }))
    }

    /// The tangent body `i` starts a segment at `tc` with when the event
    /// at `tc` (moving with the controls by `dt_du`) freezes it (`still`:
    /// velocities zeroed) or wakes it from rest: the saltation
    /// `J⁺ = Φ (J⁻ + (F⁻ − F⁺') dt_c/du)` of a map that changes only the
    /// velocities (zeroes them, or keeps a frozen body's zero), with `F⁻`
    /// and `F⁺` the flows before and after (zero while frozen). Without a
    /// tangent before, or without `dt_c/du`, the Jacobian is flagged lost.
    fn tangent_across(
        &mut self,
        tc: f64,
        i: usize,
        dt_du: Option<&DVector<f64>>,
        pre: &BodyState,
        post: &BodyState,
        still: bool,
    ) -> DMatrix<f64> {
        let m = self.traj.m;
        let was_frozen = self.frozen(i);
        let known = self
            .traj
            .jacobian(i, tc, Side::Post)
            .ok()
            .zip(dt_du)
            .filter(|_| self.traj.tangent);
        let Some((mut j, dt)) = known else {
            self.lose_tangent(tc, i);
            return DMatrix::zeros(12, m);
        };
        let f_pre = self.traj.flow(i, pre, was_frozen);
        let f_post = self.traj.flow(i, post, still);
        j += (f_pre - f_post) * dt.transpose();
        if still {
            j.rows_mut(6, 6).fill(0.0);
        }
        j
    }

    /// Freeze body `i` at `tc` in state `s` (velocities zeroed), as a
    /// member of an island held by the event at `tc`.
    pub(super) fn freeze(
        &mut self,
        tc: f64,
        i: usize,
        s: &BodyState,
        dt_du: Option<&DVector<f64>>,
    ) {
        let still = BodyState {
            v: Vec3::zeros(),
            w: Vec3::zeros(),
            ..*s
        };
        let j = self.tangent_across(tc, i, dt_du, s, &still, true);
        self.start_segment(i, tc, still, j, true, None);
    }

    /// Flag body `i`'s Jacobian lost from `tc`.
    pub(super) fn lose_tangent(&mut self, tc: f64, i: usize) {
        if self.traj.tangent {
            let e = TangentError::Contact { t: tc };
            if self.traj.tangent_lost[i].is_none() {
                self.traj.diagnostics.push(e.to_string());
            }
            self.traj.tangent_lost[i].get_or_insert((tc, e));
        }
    }

    /// Wake every frozen body lying on body `j` (transitively) at `tc`, the
    /// time of the event that struck it: each starts a new segment from its
    /// frozen state.
    pub(super) fn wake_above(&mut self, tc: f64, j: usize, dt_du: Option<&DVector<f64>>) {
        let up = -self.traj.gravity.try_normalize(0.0).unwrap_or_else(Vec3::z);
        let mut queue = vec![j];
        let mut woken = vec![j];
        while let Some(b) = queue.pop() {
            let sb = self.traj.state(b, tc, Side::Post);
            for i in self.neighbours(b) {
                if woken.contains(&i) || !self.frozen(i) {
                    continue;
                }
                let si = self.traj.state(i, tc, Side::Post);
                let lies_on = self
                    .body_supports(i, &si, b, &sb)
                    .iter()
                    .any(|p| p.normal.dot(&up) > 0.0);
                if lies_on {
                    woken.push(i);
                    queue.push(i);
                    let jw = self.tangent_across(tc, i, dt_du, &si, &si, false);
                    self.start_segment(i, tc, si, jw, false, None);
                }
            }
        }
    }

    /// Whether the impact of `pair` (with `frozen` telling which party is
    /// frozen) meets a frozen body as a support: one party frozen, and the
    /// other approaching slower than `MICRO · v_r` or from above. The frozen
    /// party is then made immovable in `ctx`.
    pub(super) fn anchor(
        &self,
        ctx: &mut ImpulseCtx,
        pair: &Pair,
        contact: &crate::geometry::Contact,
        frozen: [bool; 2],
    ) -> bool {
        let [frozen_a, frozen_b] = frozen;
        if frozen_a == frozen_b {
            return false;
        }
        let n = contact.normal;
        let vb = ctx
            .b
            .as_ref()
            .map_or(Vec3::zeros(), |b| b.state.velocity_at(&contact.point_b));
        let vn = n.dot(&(ctx.a.state.velocity_at(&contact.point_a) - vb));
        let mover = if frozen_a {
            pair.b_body()
        } else {
            Some(pair.a)
        };
        let v_r = mover.map_or(0.0, |m| self.rest_thresholds(m).0);
        // The normal out of the frozen body into the mover.
        let out = if frozen_a { -n } else { n };
        let up = -self
            .traj
            .gravity
            .try_normalize(0.0)
            .unwrap_or_else(Vec3::zeros);
        let anchored = -vn < rest::MICRO * v_r || out.dot(&up) >= FROM_ABOVE;
        if anchored {
            let party = if frozen_a {
                Some(&mut ctx.a)
            } else {
                ctx.b.as_mut()
            };
            if let Some(p) = party {
                p.mass *= ANCHOR;
                p.principal *= ANCHOR;
            }
        }
        anchored
    }

    /// The held island of an impact's slow, unfrozen parties (pre-impulse
    /// states `pre`, the ordinary impulse `res`), or nothing.
    pub(super) fn impact_island(
        &self,
        tc: f64,
        pair: &Pair,
        pre: [&BodyState; 2],
        res: &crate::sim::ImpulseResult,
        frozen: [bool; 2],
    ) -> Result<Vec<(usize, BodyState)>, SimError> {
        let mut seeds = Vec::new();
        if !frozen[0] {
            seeds.push((
                pair.a,
                BodyState {
                    v: res.va,
                    w: res.wa,
                    ..*pre[0]
                },
            ));
        }
        if let (Some(j), false) = (pair.b_body(), frozen[1]) {
            seeds.push((
                j,
                BodyState {
                    v: res.vb,
                    w: res.wb,
                    ..*pre[1]
                },
            ));
        }
        Ok(self.held_island(tc, &seeds)?.unwrap_or_default())
    }

    /// After an impact's parties started their segments: freeze the rest of
    /// its island, and wake what lies on a struck frozen party.
    pub(super) fn settle_island(
        &mut self,
        tc: f64,
        pair: &Pair,
        island: &[(usize, BodyState)],
        anchored: bool,
        frozen: [bool; 2],
        dt_du: Option<&DVector<f64>>,
    ) {
        for (i, s) in island {
            if *i != pair.a && Some(*i) != pair.b_body() {
                self.freeze(tc, *i, s, dt_du);
            }
        }
        if !anchored {
            if frozen[0] {
                self.wake_above(tc, pair.a, dt_du);
            }
            if let (Some(j), true) = (pair.b_body(), frozen[1]) {
                self.wake_above(tc, j, dt_du);
            }
        }
    }
}
