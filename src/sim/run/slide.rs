//! Slides on a face of a hull in the run loop: their end where the
//! centre of mass reaches the face's edge (`sim::rest::face`), and which
//! pivot or slide ends next. No impulse: the state is continuous and the
//! body flies on from it; the Jacobian is carried across as the saltation
//! of a switch of flows, `J⁺ = J⁻ + (F_slide − F_free) dτ/du`, with
//! `dτ/du = −∇g J⁻ / (∇g F_slide)` for `g = −out·(x − a)`, the centre's
//! depth inside the edge (`out` its outward normal in the face's plane,
//! `a` a point of it).

use super::*;
use crate::sim::pivot::PivotEnd;
use crate::sim::rest::face;

impl Sim<'_> {
    /// The earliest end of a pivot or of a slide on a face in progress
    /// (time, body), other than the end of the simulation.
    pub(super) fn next_contact_end(&self) -> Option<(f64, usize)> {
        self.traj
            .tracks
            .iter()
            .enumerate()
            .filter_map(|(i, track)| {
                let seg = track.segments.last()?;
                let after = match (&seg.pivot, seg.slide.and_then(|s| s.face)) {
                    (Some(pv), _) => (pv.end != PivotEnd::Duration).then_some(pv.duration),
                    (None, Some(f)) => f.until.is_finite().then_some(f.until),
                    (None, None) => None,
                };
                after.map(|a| (seg.t0 + a, i))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
    }

    /// End body `i`'s pivot or face slide at `te`, whichever its segment
    /// is. (One of the two only: a pivot's landing impact may start a
    /// slide on a face, which must not be ended at once.)
    pub(super) fn end_contact(&mut self, te: f64, i: usize) -> Result<(), SimError> {
        let pivoting = self.traj.tracks[i]
            .segments
            .last()
            .is_some_and(|s| s.pivot.is_some());
        if pivoting {
            self.end_pivot(te, i)
        } else {
            self.end_slide(te, i)
        }
    }

    /// End body `i`'s slide at `te`: free flight from the same state.
    fn end_slide(&mut self, te: f64, i: usize) -> Result<(), SimError> {
        let Some(seg) = self.traj.tracks[i].segments.last() else {
            return Ok(());
        };
        let Some(slide) = seg.slide.filter(|s| s.face.is_some()) else {
            return Ok(());
        };
        let s = self.traj.state(i, te, Side::Pre);
        let d = &self.traj.dynamics[i];
        let j = match self.traj.jacobian(i, te, Side::Pre) {
            Ok(j_pre) => face::of(self.scene, &slide)
                .and_then(|f| f.nearest_edge(&s.x))
                .and_then(|(_, out)| {
                    let f_pre = slide.flow(&s, d.drag_k);
                    // The centre must be leaving (∇g = −out on δx alone).
                    let rate = -out.dot(&f_pre[0]);
                    if rate.is_nan() || rate >= -1e-6 * s.v.norm() {
                        return None;
                    }
                    let dtau = j_pre.rows(0, 3).tr_mul(&out) / rate;
                    let f_pre =
                        DVector::from_iterator(12, f_pre.iter().flat_map(|v| v.iter().copied()));
                    let jump = f_pre - self.traj.flow(i, &s, false);
                    let j = j_pre + jump * dtau.transpose();
                    j.iter().all(|v| v.is_finite()).then_some(j)
                }),
            Err(_) => None,
        };
        let m = self.traj.m;
        if j.is_none() {
            self.lose_tangent(te, i);
        }
        self.start_segment(
            i,
            te,
            s,
            j.unwrap_or_else(|| DMatrix::zeros(12, m)),
            false,
            None,
        );
        // It is in contact, not striking: the face is struck again only
        // once the body sinks below the arming distance (as after a pivot).
        let on = Party::Obstacle(slide.obstacle);
        if let Some(k) = self.pairs.iter().position(|p| p.a == i && p.b == on) {
            self.pairs[k].armed = false;
            self.pairs[k].hold = te;
        }
        Ok(())
    }
}
