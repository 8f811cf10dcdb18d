//! One step's contact impulses for a stepped body (`sim::pivot::stepped`):
//! projected Gauss–Seidel over the normal and friction impulses.

use super::contacts::Touch;
use crate::math::{Mat3, Vec3, plane_basis};
use crate::sim::dynamics::BodyDynamics;
use crate::sim::state::BodyState;
use nalgebra::Vector2;

/// Gauss–Seidel sweeps at most per solve.
const SWEEPS: usize = 200;

/// `[r]×`, the matrix of `v ↦ r × v`.
fn skew(r: &Vec3) -> Mat3 {
    Mat3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// One contact's rows of the Gauss–Seidel solve.
struct Row {
    touch: Touch,
    t1: Vec3,
    t2: Vec3,
    /// Inverse of the effective mass along the normal, and in the plane.
    normal_mass: f64,
    tangent_mass: f64,
    /// Least normal velocity allowed, m/s.
    target: f64,
}

/// The body's world inertia inverse at `s`.
pub(super) fn inverse_inertia(d: &BodyDynamics, s: &BodyState) -> Mat3 {
    let rot = *s.q.to_rotation_matrix().matrix();
    rot * d.inertia_inv * rot.transpose()
}

/// The world inertia at `s`.
pub(super) fn inertia(d: &BodyDynamics, s: &BodyState) -> Mat3 {
    let rot = *s.q.to_rotation_matrix().matrix();
    rot * d.inertia * rot.transpose()
}

/// How one step's impulses are solved.
pub(super) struct Solve<'a> {
    pub(super) dynamics: &'a BodyDynamics,
    /// The world inertia inverse at the step's start.
    pub(super) i_inv: Mat3,
    /// Step, s; fraction of a penetration pushed out; the gap contacts
    /// are held at, m; and the change (N·s) at which sweeps stop: the
    /// mass times the velocity change of the body's fastest-changing
    /// point (`|Δv| + |Δω| r`) over a full sweep, one normal impulse's
    /// change over a normal sweep.
    pub(super) h: f64,
    pub(super) push: f64,
    pub(super) clearance: f64,
    pub(super) tol: f64,
}

/// One step's impulses, per contact: along the normal and in the plane
/// (in the contact's `plane_basis`).
#[derive(Debug, Clone, Default)]
pub(super) struct Impulses {
    pub(super) normal: Vec<f64>,
    pub(super) tangent: Vec<Vector2<f64>>,
}

impl Impulses {
    /// Each contact's impulse (world, N·s) with its key, to start the next
    /// step's solve from.
    pub(super) fn keyed(&self, touches: &[Touch]) -> Vec<([usize; 5], Vec3)> {
        touches
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let (t1, t2) = plane_basis(&t.normal);
                let p = t.normal * self.normal[k] + t1 * self.tangent[k].x + t2 * self.tangent[k].y;
                (t.key, p)
            })
            .collect()
    }

    /// The last step's impulses for the same contacts as a start for
    /// this step's (zero for new contacts; each projected on its contact's
    /// normal and plane).
    pub(super) fn warm(touches: &[Touch], last: &[([usize; 5], Vec3)]) -> Impulses {
        let (mut normal, mut tangent) = (Vec::new(), Vec::new());
        for t in touches {
            let p = last
                .iter()
                .find(|(key, _)| *key == t.key)
                .map_or(Vec3::zeros(), |(_, p)| *p);
            let (t1, t2) = plane_basis(&t.normal);
            normal.push(t.normal.dot(&p).max(0.0));
            tangent.push(Vector2::new(t1.dot(&p), t2.dot(&p)));
        }
        Impulses { normal, tangent }
    }
}

impl Solve<'_> {
    /// The velocities after the contact impulses from `(v, w)`, with the
    /// impulses (starting from `warm`'s, when given for the same contacts).
    pub(super) fn run(
        &self,
        touches: &[Touch],
        v: Vec3,
        w: Vec3,
        warm: Option<&Impulses>,
    ) -> (Vec3, Vec3, Impulses) {
        let (m, i_inv, h) = (self.dynamics.mass, &self.i_inv, self.h);
        let rows: Vec<Row> = touches
            .iter()
            .map(|t| {
                let rx = skew(&t.r);
                let k = Mat3::identity() / m - rx * i_inv * rx;
                let (t1, t2) = plane_basis(&t.normal);
                // One mass for both tangent directions (the mean of the
                // block's diagonal): at a slipping contact the projection
                // then leaves friction opposite the slip, as Coulomb's law
                // has it (the 2×2 block's inverse would turn it aside).
                let kt = 0.5 * (t1.dot(&(k * t1)) + t2.dot(&(k * t2)));
                // The gap left at the end of the step: the clearance, plus
                // what the contact's own turn takes from its linear
                // prediction where it turns inward.
                let keep = self.clearance - t.turn.min(0.0);
                let gap = if t.distance >= 0.0 {
                    t.distance
                } else {
                    self.push * t.distance
                };
                Row {
                    touch: *t,
                    t1,
                    t2,
                    normal_mass: 1.0 / t.normal.dot(&(k * t.normal)),
                    tangent_mass: if kt > 0.0 { 1.0 / kt } else { 0.0 },
                    target: (keep - gap) / h,
                }
            })
            .collect();
        let (mut v, mut w) = (v, w);
        let apply = |v: &mut Vec3, w: &mut Vec3, r: &Vec3, p: Vec3| {
            *v += p / m;
            *w += i_inv * r.cross(&p);
        };
        let mut out = match warm {
            Some(warm) if warm.normal.len() == rows.len() => {
                for (k, row) in rows.iter().enumerate() {
                    let p = row.touch.normal * warm.normal[k]
                        + row.t1 * warm.tangent[k].x
                        + row.t2 * warm.tangent[k].y;
                    apply(&mut v, &mut w, &row.touch.r, p);
                }
                warm.clone()
            }
            _ => Impulses {
                normal: vec![0.0; rows.len()],
                tangent: vec![Vector2::zeros(); rows.len()],
            },
        };
        let normal_pass = |v: &mut Vec3, w: &mut Vec3, out: &mut Impulses| {
            let mut change: f64 = 0.0;
            for (k, row) in rows.iter().enumerate() {
                let t = &row.touch;
                let vn = t.normal.dot(&(*v + w.cross(&t.r)));
                let next = (out.normal[k] + (row.target - vn) * row.normal_mass).max(0.0);
                let dl = next - out.normal[k];
                if dl != 0.0 {
                    out.normal[k] = next;
                    apply(v, w, &t.r, t.normal * dl);
                }
                change = change.max(dl.abs());
            }
            change
        };
        let reach = self.dynamics.reach;
        for _ in 0..SWEEPS {
            let (v0, w0) = (v, w);
            normal_pass(&mut v, &mut w, &mut out);
            for (k, row) in rows.iter().enumerate() {
                let t = &row.touch;
                if t.friction <= 0.0 {
                    continue;
                }
                let u = v + w.cross(&t.r);
                let slip = Vector2::new(row.t1.dot(&u), row.t2.dot(&u));
                let mut next = out.tangent[k] - slip * row.tangent_mass;
                let limit = t.friction * out.normal[k];
                let size = next.norm();
                if size > limit {
                    next *= limit / size;
                }
                let dt = next - out.tangent[k];
                if dt != Vector2::zeros() {
                    out.tangent[k] = next;
                    apply(&mut v, &mut w, &t.r, row.t1 * dt.x + row.t2 * dt.y);
                }
            }
            // Converged when no point's velocity moved by more than the
            // tolerance over the sweep (redundant contacts can trade
            // impulse among themselves long after the motion is settled).
            let change = m * ((v - v0).norm() + reach * (w - w0).norm());
            if change <= self.tol {
                break;
            }
        }
        // Non-penetration first: normal sweeps alone until the normal
        // impulses settle to round-off, each followed by bringing any
        // friction impulse back inside its disc of the normal's new size.
        for _ in 0..SWEEPS {
            let change = normal_pass(&mut v, &mut w, &mut out);
            for (k, row) in rows.iter().enumerate() {
                let limit = row.touch.friction * out.normal[k];
                let size = out.tangent[k].norm();
                if size > limit {
                    let dt = out.tangent[k] * (limit / size - 1.0);
                    out.tangent[k] += dt;
                    apply(&mut v, &mut w, &row.touch.r, row.t1 * dt.x + row.t2 * dt.y);
                }
            }
            if change <= self.tol {
                break;
            }
        }
        (v, w, out)
    }
}
