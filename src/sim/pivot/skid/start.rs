//! Starting a skid at a Zeno-regime impact and integrating it to its end
//! (`sim::pivot::skid`).

use super::super::{
    Clear, Motion, Pivot, PivotEnd, PivotStart, STEP as HINGE_STEP, SupportLine, points,
};
use super::{STEP, Skid};
use crate::geometry::flat_faces;
use crate::math::Vec3;
use crate::sim::state::BodyState;

/// A point of the body off the line: its part, body-frame offset from the
/// centre of mass, and radius.
type Point = (usize, Vec3, f64);

impl Pivot {
    /// The skid that an impact in the Zeno regime starts when the body's
    /// supports on a half-space or a face of a hull make one line or are
    /// one corner (corners of its hulls), with the state it starts from; a
    /// single corner that friction holds is pinned instead. `None` when
    /// friction holds an end of a line (see `Skid::rates`; the hinge's
    /// case), when the support would lift off at once, when a point off it
    /// already meets the plane, or when the skid would end within a
    /// hinge's step. On a face of a hull the skid ends where an end slides
    /// off the face ([`PivotEnd::OffFace`]).
    pub(crate) fn enter_skid(p: &PivotStart<'_>) -> Option<(Pivot, BodyState)> {
        let (g, d, s) = (p.gravity, p.dynamics, &p.post);
        if g.norm() == 0.0 || d.drag_k.is_some() {
            return None;
        }
        let o = &p.scene.obstacles[p.obstacle];
        let part = o.geometry.parts.get(p.part)?;
        let line = match p.supports {
            [corner] => SupportLine::corner(corner),
            _ => SupportLine::of(p.supports, d.reach)?,
        };
        let n = line.normal;
        let ends_world = [line.point, line.point + line.axis * line.length];
        // The face skidded on (unbounded on a half-space); the ends start
        // on it.
        let face = flat_faces(part, &o.pose, &n, 1.0 - 1e-6)
            .into_iter()
            .next()?;
        if ends_world.iter().any(|e| face.depth(e) < 0.0) {
            return None;
        }
        let tol = 1e-6 * d.reach;
        // The ends must be corners of the body (a ball's lowest point is
        // not a fixed body point).
        let all = points(p.scene, p.body);
        let corner_at = |e: &Vec3| {
            all.iter()
                .any(|(_, v, radius)| *radius == 0.0 && (s.point(v) - e).norm() <= tol)
        };
        if !ends_world.iter().all(corner_at) {
            return None;
        }
        let ends = ends_world.map(|e| s.q.inverse() * (e - s.x));
        let levels = ends_world.map(|e| n.dot(&e));
        let mut skid = Skid {
            ends,
            count: if line.length > 0.0 { 2 } else { 1 },
            normal: n,
            levels,
            mass: d.mass,
            inertia: d.inertia,
            inertia_inv: d.inertia_inv,
            gravity: g,
            friction: p.friction,
            onset: p.v_rest,
            pinned: false,
            anchor: line.point,
            table: Vec::new(),
        };
        // A plastic impact of the whole line: no end moves along `n`.
        let mut start = skid.project(s)?;
        let scale = 1e-9 * d.mass * g.norm();
        // A corner slower than the onset speed is pinned when the force
        // that holds it still (after a plastic impact that stops it) is
        // within the friction cone.
        if skid.count == 1 && p.friction > 0.0 && skid.contact_slip(&start) < p.v_rest {
            skid.pinned = true;
            let held = skid.project(s).and_then(|st| Some((st, skid.rates(&st)?)));
            match held {
                Some((st, r))
                    if r.normal[0] >= -scale && r.grip <= p.friction * r.normal[0] + scale =>
                {
                    start = st;
                }
                _ => skid.pinned = false,
            }
        }
        let first = skid.rates(&start)?;
        if first.normal.iter().any(|&f| f < -scale) {
            return None;
        }
        if first.held.iter().any(|&h| h) {
            return None;
        }
        let off: Vec<Point> = all
            .iter()
            .copied()
            .filter(|(_, v, _)| {
                let r = start.q * v + start.x - line.point;
                let across = if line.length > 0.0 {
                    r - line.axis * line.axis.dot(&r)
                } else {
                    r
                };
                across.norm() > tol
            })
            .collect();
        let reach = all
            .iter()
            .map(|(_, v, radius)| v.norm() + radius)
            .fold(0.0, f64::max);
        let low = |s: &BodyState| lowest(&off, s, &n, levels[0]);
        let (start_low, _) = low(&start);
        if start_low < -tol {
            return None;
        }
        let floor = start_low.min(0.0);
        let mut course = Course {
            duration: 0.0,
            end: PivotEnd::Duration,
            landing: None,
            v_max: start.v.norm(),
            w_max: start.w.norm(),
            alpha_max: first.alpha.norm(),
            accel_max: first.a.norm(),
        };
        let b = line.axis.cross(&n);
        let frame = |x: &Vec3| {
            let r = x - line.point;
            [line.axis.dot(&r), b.dot(&r), n.dot(&r)]
        };
        let mut swept = frame(&start.x).map(|c| (c - reach, c + reach));
        // A sliding skid on a face of a hull keeps clear of the obstacle's
        // other parts (see below): refused before integrating when they
        // are near its start already (the box only grows).
        let on_hull = !face.polygon.is_empty();
        if on_hull
            && !skid.pinned
            && Pivot::clear_of(&line.point, &line.axis, &n, p, &swept) != Clear::Free
        {
            return None;
        }
        skid.table.push(start);
        // Points can come no nearer the plane than `budget` before the
        // lowest is measured again.
        let mut budget = start_low - floor;
        let steps = (p.horizon / STEP).ceil().min(1e7) as usize;
        let mut s0 = start;
        let mut prev_dir = first.dir;
        for k in 0..steps {
            let h = STEP.min(p.horizon - k as f64 * STEP);
            let t1 = k as f64 * STEP + h;
            let Some(s1) = skid.advance(&s0, h).and_then(|s1| skid.project(&s1)) else {
                course.duration = k as f64 * STEP;
                course.end = PivotEnd::LiftsOff;
                break;
            };
            let speed = |s: &BodyState| s.v.norm() + s.w.norm() * reach;
            budget -= 1.5 * speed(&s0).max(speed(&s1)) * h;
            if budget <= 0.0 {
                let (lowest1, _) = low(&s1);
                if lowest1 < floor {
                    let (tau, landing) = landing_in(&skid, &off, &s0, h, &n, levels[0], floor);
                    course.duration = k as f64 * STEP + tau;
                    course.end = PivotEnd::Lands;
                    course.landing = landing;
                    break;
                }
                budget = lowest1 - floor;
            }
            let Some(r1) = skid.rates(&s1) else {
                course.duration = t1;
                course.end = PivotEnd::LiftsOff;
                skid.table.push(s1);
                break;
            };
            course.v_max = course.v_max.max(s1.v.norm());
            course.w_max = course.w_max.max(s1.w.norm());
            course.alpha_max = course.alpha_max.max(r1.alpha.norm());
            course.accel_max = course.accel_max.max(r1.a.norm());
            for (c, (lo, hi)) in frame(&s1.x).iter().zip(swept.iter_mut()) {
                (*lo, *hi) = (lo.min(c - reach), hi.max(c + reach));
            }
            skid.table.push(s1);
            // An end stops slipping when, slower than the rest speed,
            // friction holds it, or when its slip turns back (it passed
            // through zero).
            let stuck = |r: &super::Rates| {
                (0..2).any(|i| {
                    r.held[i]
                        || (p.friction > 0.0
                            && r.slip[i] >= p.v_rest
                            && r.dir[i].dot(&prev_dir[i]) < 0.0)
                })
            };
            if r1.normal.iter().any(|&f| f < -scale) {
                course.duration = t1;
                course.end = PivotEnd::LiftsOff;
                break;
            }
            // Ends within the step, bisected there: an end sliding off the
            // face (its depth in the face's polygon), a pinned corner
            // slipping (its force leaving the friction cone), a sliding end
            // sticking (the friction's direction jumps there: RK4 is exact
            // only before it).
            let on_face = |s: &BodyState| skid.ends_at(s).iter().all(|e| face.depth(e) >= 0.0);
            let slips = |r: &super::Rates| r.grip > p.friction * r.normal[0] + scale;
            let rates_at = |tau: f64| skid.advance(&s0, tau).and_then(|s| skid.rates(&s));
            let ended = if !on_face(&s1) {
                let off = |tau: f64| {
                    skid.advance(&s0, tau)
                        .and_then(|s| skid.project(&s))
                        .is_none_or(|s| !on_face(&s))
                };
                Some((PivotEnd::OffFace, bisect(h, off)))
            } else if skid.pinned && slips(&r1) {
                let slipped = |tau: f64| rates_at(tau).is_none_or(|r| slips(&r));
                Some((PivotEnd::Slips, bisect(h, slipped)))
            } else if !skid.pinned && stuck(&r1) {
                let stopped = |tau: f64| rates_at(tau).is_none_or(|r| stuck(&r));
                Some((PivotEnd::Sticks, bisect(h, stopped)))
            } else {
                None
            };
            if let Some((end, tau)) = ended {
                skid.table.pop();
                course.duration = k as f64 * STEP + tau;
                course.end = end;
                break;
            }
            prev_dir = r1.dir;
            s0 = s1;
            if k + 1 == steps {
                course.duration = p.horizon;
            }
        }
        // Between samples the speeds can exceed the sampled ones by at most
        // a step's acceleration: the bounds the other pairs are searched
        // with must hold all through the skid.
        course.v_max += course.accel_max * STEP;
        course.w_max += course.alpha_max * STEP;
        // The sampled centres' box: points move at most `speed · STEP`
        // between samples.
        let pad = (course.v_max + course.w_max * reach) * STEP;
        let swept = swept.map(|(lo, hi)| (lo - pad, hi + pad));
        // A skid that ends within a hinge's step (two supports landing at
        // once, a lift-off or a stick at once) would make no progress: it
        // stays a micro-collision.
        if course.end != PivotEnd::Duration && course.duration < HINGE_STEP {
            return None;
        }
        let pv = Pivot {
            obstacle: p.obstacle,
            part: p.part,
            point: line.point,
            axis: line.axis,
            normal: n,
            length: line.length,
            motion: Motion::Skid(Box::new(skid)),
            duration: course.duration,
            end: course.end,
            landing: course.landing,
            lean: None,
            lands_on_lean: false,
            beside: false,
            v_max: course.v_max,
            w_max: course.w_max,
            alpha_max: course.alpha_max,
            accel_max: course.accel_max,
        };
        // On a face of a hull with other parts of the obstacle near the
        // sweep (a coatrack's pole on its base), an end sliding off the face
        // may meet one of them at that very instant, where the search of
        // those parts stops at the skid's end: no skid there.
        pv.started(s, p, &(swept, None), 0.0)
            .filter(|(pv, _)| !(on_hull && pv.beside && !pv.pinned()))
    }
}

/// The first time in `(0, h]` at which `ended` holds (it does not at 0
/// and does at `h`), by bisection to round-off.
fn bisect(h: f64, ended: impl Fn(f64) -> bool) -> f64 {
    let (mut lo, mut hi) = (0.0, h);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if ended(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// How long a skid lasts, how it ends, and its bounds (see [`Pivot`]).
struct Course {
    duration: f64,
    end: PivotEnd,
    landing: Option<(usize, Vec3)>,
    v_max: f64,
    w_max: f64,
    alpha_max: f64,
    accel_max: f64,
}

/// The lowest height over the plane `n · p = level` of the points `off`
/// at state `s`, and which point it is.
fn lowest(off: &[Point], s: &BodyState, n: &Vec3, level: f64) -> (f64, Option<(usize, Vec3)>) {
    off.iter()
        .map(|(k, v, radius)| (n.dot(&s.point(v)) - radius - level, Some((*k, *v))))
        .fold((f64::INFINITY, None), |a, b| if b.0 < a.0 { b } else { a })
}

/// When within a step of `h` from `s0` a point first goes below `floor`
/// (it is above at 0 and below at `h`), and the point: regula falsi with
/// the Illinois weighting on the lowest height, kept bracketed, until the
/// point is within 1e-13 m of `floor` below it or the bracket is 1e-15 s.
fn landing_in(
    skid: &Skid,
    off: &[Point],
    s0: &BodyState,
    h: f64,
    n: &Vec3,
    level: f64,
    floor: f64,
) -> (f64, Option<(usize, Vec3)>) {
    let height = |tau: f64| {
        skid.advance(s0, tau)
            .map(|s| lowest(off, &s, n, level))
            .filter(|(z, _)| z.is_finite())
    };
    let (mut lo, mut f_lo) = (0.0, lowest(off, s0, n, level).0 - floor);
    let (mut hi, mut last) = (h, height(h));
    let mut f_hi = last.map_or(-1.0, |(z, _)| z - floor);
    let mut side = 0;
    for _ in 0..60 {
        if hi - lo <= 1e-15 {
            break;
        }
        let mut tau = hi - f_hi * (hi - lo) / (f_hi - f_lo);
        if !(tau > lo && tau < hi) {
            tau = 0.5 * (lo + hi);
        }
        match height(tau) {
            Some((z, _)) if z >= floor => {
                (lo, f_lo) = (tau, z - floor);
                if side == -1 {
                    f_hi *= 0.5;
                }
                side = -1;
            }
            found => {
                let f = found.map_or(-1.0, |(z, _)| z - floor);
                (hi, f_hi, last) = (tau, f, found);
                if f > -1e-13 {
                    break;
                }
                if side == 1 {
                    f_lo *= 0.5;
                }
                side = 1;
            }
        }
    }
    (hi, last.and_then(|(_, p)| p))
}
