//! Pivots in the run loop: starting one at a Zeno-regime impact, and its
//! end — a landing impact, or free flight after lift-off or slip (see
//! `sim::pivot`).

use super::*;
use crate::geometry::NearPoint;
use crate::sim::pivot::{Lean, Pivot, PivotEnd, PivotStart, SupportLine, stepped, topple};

impl Sim<'_> {
    /// The pivot that an impact of body `a` on obstacle `o` (its part
    /// `part`) in the Zeno regime starts, if its supports make one line on
    /// that obstacle (or are one corner, for a skid) and touch no other.
    pub(super) fn try_pivot(
        &self,
        a: usize,
        o: usize,
        part: usize,
        post: &BodyState,
        tc: f64,
    ) -> Option<(Pivot, BodyState)> {
        let scene = self.scene;
        let d = &self.traj.dynamics[a];
        let (v_rest, band) = rest::thresholds(scene, d, &self.traj.gravity, self.tol.arm);
        let friction = rest::pair_friction(scene, a, o);
        // Most Zeno-regime impacts are neither on a line nor on a corner
        // that can skid (on a face, or without friction): that is asked
        // first, of this obstacle's supports only.
        let on_parts = rest::supports_on_parts(scene, a, o, post, band);
        let supports: Vec<NearPoint> = on_parts.iter().map(|(_, q)| *q).collect();
        let line = SupportLine::of(&supports, d.reach).is_some();
        // Lying on a face with the centre of mass beyond the supports'
        // hull, it topples over the hull's edge it hangs over.
        let toppling = match (!line).then(|| topple::edge(&supports, &post.x, d.reach)) {
            Some(Some(edge)) => Some(edge).filter(|e| SupportLine::of(e, d.reach).is_some()),
            _ => None,
        };
        // Two supports on surfaces with different normals: the body leans
        // on them, a hinge about the line through both (`pivot::lean`).
        let lean = match on_parts.as_slice() {
            [(k1, s1), (k2, s2)]
                if !line
                    && toppling.is_none()
                    && friction > 0.0
                    && s1.normal.dot(&s2.normal) < 1.0 - 1e-6 =>
            {
                let [a1, a2] = [(k1, s1), (k2, s2)].map(|(k, q)| surface(scene, o, *k, q));
                Some((
                    *k1,
                    [a1.0, a2.0],
                    Lean {
                        part: *k2,
                        normal: a2.0.normal,
                        planes: [a1.1, a2.1],
                    },
                ))
            }
            _ => None,
        };
        if !line && toppling.is_none() && lean.is_none() && (supports.len() != 1 || friction <= 0.0)
        {
            return None;
        }
        let elsewhere = (0..scene.obstacles.len())
            .filter(|&k| k != o)
            .any(|k| !rest::supports(scene, a, k, post, band).is_empty());
        // Nor on another body (a box with another lying on it).
        let touching = || {
            self.neighbours(a).into_iter().any(|j| {
                let sj = self.traj.state(j, tc, Side::Pre);
                !self.body_supports(a, post, j, &sj).is_empty()
            })
        };
        if elsewhere || touching() {
            return None;
        }
        let start = PivotStart {
            supports: match &lean {
                Some((_, ends, _)) => ends,
                None => toppling.as_deref().unwrap_or(&supports),
            },
            topple: toppling.is_some(),
            scene,
            dynamics: d,
            gravity: self.traj.gravity,
            body: a,
            obstacle: o,
            part: lean.map_or(part, |(k1, ..)| k1),
            post: *post,
            friction,
            horizon: self.traj.duration - tc,
            v_rest,
            lean: lean.map(|(.., l)| l),
        };
        // The hinge when friction holds the line, else a skid (on a single
        // corner, only a skid). Without friction a body stays in
        // micro-collisions: a skid loses energy only where it lands, and a
        // spinning polyhedron (the frictionless eggs) would skid from
        // corner to corner without end, where micro-collisions bring a
        // face down and it slides (`sim::rest`, rule 2).
        let skid = || {
            (start.friction > 0.0)
                .then(|| Pivot::enter_skid(&start))
                .flatten()
        };
        if toppling.is_some() || lean.is_some() {
            Pivot::enter(&start)
        } else if line {
            Pivot::enter(&start).or_else(skid)
        } else {
            skid()
        }
    }

    /// The stepped motion (`sim::pivot::stepped`) that a Zeno-regime
    /// impact of body `a` on obstacle `o` starts when no pivot takes it
    /// and the body has chattered [`TRAIN`] micro-collisions in a row,
    /// counting this one.
    ///
    /// [`TRAIN`]: crate::sim::pivot::stepped::TRAIN
    pub(super) fn try_stepped(
        &self,
        a: usize,
        o: usize,
        part: usize,
        post: &BodyState,
        tc: f64,
    ) -> Option<(Pivot, BodyState)> {
        let scene = self.scene;
        if !stepped::supported(scene, a) {
            return None;
        }
        let train = self
            .traj
            .events
            .iter()
            .rev()
            .filter(|e| e.a == a || e.b == Party::Body(a))
            .take(stepped::TRAIN - 1)
            .take_while(|e| e.micro)
            .count();
        if train + 1 < stepped::TRAIN {
            return None;
        }
        let d = &self.traj.dynamics[a];
        let (v_rest, band) = rest::thresholds(scene, d, &self.traj.gravity, self.tol.arm);
        // Not where every support is on one obstacle that is a lone
        // half-space: a slide or a rest takes the chatter there.
        let on: Vec<usize> = (0..scene.obstacles.len())
            .filter(|&k| !rest::supports(scene, a, k, post, band).is_empty())
            .collect();
        let plane = |k: usize| {
            let parts = &scene.obstacles[k].geometry.parts;
            parts.len() == 1 && matches!(parts[0].kind, crate::geometry::PartKind::HalfSpace { .. })
        };
        if on.len() == 1 && plane(on[0]) {
            return None;
        }
        Pivot::enter_stepped(&stepped::SteppedStart {
            scene,
            dynamics: d,
            gravity: self.traj.gravity,
            body: a,
            post: *post,
            horizon: self.traj.duration - tc,
            v_rest,
            band,
            obstacle: o,
            part,
        })
    }

    /// Start body `i` pivoting at `t0` from `start`; its Jacobian is lost
    /// from here on (`TangentError::Contact`).
    pub(super) fn start_pivot(
        &mut self,
        i: usize,
        t0: f64,
        start: BodyState,
        j0: DMatrix<f64>,
        pivot: Pivot,
    ) {
        self.forget_searches(i);
        self.traj.tracks[i].segments.push(Segment {
            t0,
            start,
            j0,
            rest: false,
            slide: None,
            pivot: Some(std::sync::Arc::new(pivot)),
            steps: Vec::new(),
        });
        self.cursors[i] = None;
        if self.traj.tangent {
            let e = TangentError::Contact { t: t0 };
            self.traj.tangent_lost[i].get_or_insert((t0, e));
            self.traj.tangent_error.get_or_insert(e);
        }
    }

    /// End body `i`'s pivot at `te`: the landing point's impact, or free
    /// flight from the same state.
    pub(super) fn end_pivot(&mut self, te: f64, i: usize) -> Result<(), SimError> {
        let Some(pv) = self.traj.tracks[i]
            .segments
            .last()
            .and_then(|s| s.pivot.clone())
        else {
            return Ok(());
        };
        let s = self.traj.state(i, te, Side::Post);
        let Some(k) = self
            .pairs
            .iter()
            .position(|p| p.a == i && p.b == Party::Obstacle(pv.obstacle))
        else {
            return Ok(());
        };
        if let (PivotEnd::Lands, Some((part, v))) = (pv.end, pv.landing) {
            let point_a = s.point(&v);
            // On the first end's plane, or leaning on either surface's.
            let (n, level, part_b) = match pv.lean {
                Some(l) if pv.lands_on_lean => (l.normal, l.planes[1], l.part),
                Some(l) => (pv.normal, l.planes[0], pv.part),
                None => (pv.normal, pv.normal.dot(&pv.point), pv.part),
            };
            let contact = crate::geometry::Contact {
                distance: 0.0,
                normal: n,
                point_a,
                point_b: point_a - n * (n.dot(&point_a) - level),
                part_a: part,
                part_b,
            };
            return self.impact(te, k, &contact);
        }
        let m = self.traj.m;
        if pv.stepped().is_some() {
            // Stepped on every obstacle: at rest, or flying from here with
            // every obstacle's pair disarmed (in contact, not striking).
            let rest = pv.end == PivotEnd::Rests;
            let s = if rest {
                BodyState {
                    v: Vec3::zeros(),
                    w: Vec3::zeros(),
                    ..s
                }
            } else {
                s
            };
            self.start_segment(i, te, s, DMatrix::zeros(12, m), rest, None);
            for k in 0..self.pairs.len() {
                if self.pairs[k].a == i && matches!(self.pairs[k].b, Party::Obstacle(_)) {
                    self.pairs[k].armed = false;
                    self.pairs[k].hold = te;
                }
            }
            return Ok(());
        }
        if pv.end == PivotEnd::Sticks {
            // The skid's line stopped slipping: the hinge, if friction
            // holds it.
            if let Some((hinge, start)) = self
                .try_pivot(i, pv.obstacle, pv.part, &s, te)
                .filter(|(next, _)| !next.skids())
            {
                self.start_pivot(i, te, start, DMatrix::zeros(12, m), hinge);
                return Ok(());
            }
        }
        self.start_segment(i, te, s, DMatrix::zeros(12, m), false, None);
        self.pairs[k].armed = false;
        self.pairs[k].hold = te;
        Ok(())
    }
}

/// The surface a support of body-on-obstacle `o` lies on, at part `k`:
/// the support with the normal of the part's face there when it lies on a
/// face (a corner's normal can be tilted by round-off), and that surface's
/// plane `n · x = offset`.
fn surface(scene: &Scene, o: usize, k: usize, q: &NearPoint) -> (NearPoint, f64) {
    let ob = &scene.obstacles[o];
    let face = ob.geometry.parts.get(k).and_then(|part| {
        crate::geometry::flat_faces(part, &ob.pose, &q.normal, 1.0 - 1e-6)
            .into_iter()
            .next()
    });
    match face {
        Some(f) => (
            NearPoint {
                normal: f.normal,
                distance: f.normal.dot(&q.point) - f.offset,
                ..*q
            },
            f.offset,
        ),
        None => (*q, q.normal.dot(&q.point) - q.distance),
    }
}
