//! An impact: the contact's features, the impulse (with its patch of
//! corners when a face lands flat), how a bounce ends (rest, slide,
//! micro-collision) and the new segments of the parties.

use super::*;

/// Depth of a contact patch as a fraction of the body's reach: corners on
/// a flat face weigh fully in the impulse point, corners up to this height
/// over it (3e-4 of the body's size: 0.2 mm for a 1.2 m plank, 20 µm for a
/// mug) less and less. An edge or face landing nearly flat is then one
/// impulse near the patch's centre, not a sequence of corner impacts whose
/// order rocks and turns the body.
const PATCH_DEPTH: f64 = 1e-3;
/// A face takes part in a contact patch when its normal is within this
/// angle (rad) of the contact normal.
const PATCH_ANGLE: f64 = 0.02;

impl Sim<'_> {
    pub(super) fn party_name(&self, p: Party) -> String {
        match p {
            Party::Body(i) => self.scene.bodies[i].name.clone(),
            Party::Obstacle(i) => self.scene.obstacles[i].name.clone(),
        }
    }

    pub(super) fn party_ctx(&self, i: usize, s: &BodyState) -> PartyCtx {
        let d = &self.traj.dynamics[i];
        PartyCtx {
            state: *s,
            mass: d.mass,
            principal: d.principal,
            axes: d.axes,
        }
    }

    /// Apply the impulse of pair `k` at `tc`, start new segments and update
    /// the Jacobians by the saltation formula.
    pub(super) fn impact(
        &mut self,
        tc: f64,
        k: usize,
        contact: &crate::geometry::Contact,
    ) -> Result<(), SimError> {
        let pair = self.pairs[k];
        self.pairs[k].armed = false;
        self.searched[k] = None;
        let scene = self.scene;
        let a = pair.a;
        let sa = self.traj.state(a, tc, Side::Post);
        let sb = match pair.b {
            Party::Body(j) => Some(self.traj.state(j, tc, Side::Post)),
            Party::Obstacle(_) => None,
        };
        let (gb, pose_b, e_b, mu_b) = match pair.b {
            Party::Body(j) => (
                &scene.bodies[j].geometry,
                sb.as_ref().map(BodyState::pose).unwrap_or_default(),
                scene.bodies[j].restitution,
                scene.bodies[j].friction,
            ),
            Party::Obstacle(o) => (
                &scene.obstacles[o].geometry,
                scene.obstacles[o].pose,
                scene.obstacles[o].restitution,
                scene.obstacles[o].friction,
            ),
        };
        let body_a = &scene.bodies[a];
        let mut feature = FeaturePair::classify(&body_a.geometry, &sa.pose(), gb, &pose_b, contact);
        let index = self.traj.events.len();
        let control = scene.event_control(index);
        let restitution = control
            .and_then(|c| c.restitution)
            .unwrap_or(body_a.restitution * e_b);
        let n = contact.normal;
        let axis = {
            let k = (0..3)
                .min_by(|&x, &y| n[x].abs().total_cmp(&n[y].abs()))
                .unwrap_or(0);
            let mut e = Vec3::zeros();
            e[k] = 1.0;
            e
        };
        let friction = if scene.effects.friction {
            (body_a.friction * mu_b).sqrt()
        } else {
            0.0
        };
        let mut ctx = ImpulseCtx {
            feature: feature.clone(),
            a: self.party_ctx(a, &sa),
            b: match (pair.b, &sb) {
                (Party::Body(j), Some(s)) => Some(self.party_ctx(j, s)),
                _ => None,
            },
            b_pose: pose_b,
            restitution,
            normal_dev: control.and_then(|c| c.normal),
            tangent_axis: axis,
            friction,
            mode: FrictionMode::default(),
            min_separation: None,
        };
        // Frozen parties: anchored supports, or woken (run/islands.rs).
        let frozen_a = self.frozen(a);
        let frozen_b = pair.b_body().is_some_and(|j| self.frozen(j));
        let anchored = self.anchor(&mut ctx, &pair, contact, [frozen_a, frozen_b]);
        let mut res = ctx.apply();
        if friction > 0.0 {
            Counters::bump(&self.traj.counters.friction, 1);
        }
        if let Some((corners, depth, face)) = self.patch(
            a,
            &body_a.geometry.parts[contact.part_a],
            &sa,
            gb.parts.get(contact.part_b),
            &pose_b,
            contact,
        ) {
            let patch = feature.at_patch(corners, depth, face);
            ctx.feature = patch.clone();
            let r2 = ctx.apply();
            // The patch's impulse must also stop the touching point: a body
            // pivoting fast about it (a box spinning onto a corner) would
            // otherwise keep sinking there while the centroid separates.
            let touching = contact.point_a;
            let at = |v: &Vec3, w: &Vec3, x: &Vec3| v + w.cross(&(touching - x));
            let vb = sb.map_or(Vec3::zeros(), |s| at(&r2.vb, &r2.wb, &s.x));
            let stopped = n.dot(&(at(&r2.va, &r2.wa, &sa.x) - vb)) >= -1e-9 * r2.approach.abs();
            if r2.approach < 0.0 && stopped {
                feature = patch;
                res = r2;
            } else {
                ctx.feature = feature.clone();
            }
        }
        if res.approach >= 0.0 {
            // A simultaneous contact whose centroid does not approach may
            // still have a vertex that does (an edge or face rocking about
            // its centre, after an inelastic impulse there): that vertex
            // takes the impulse. Skipping it let the vertex sink below the
            // surface.
            let deepest = feature
                .a_vertices(&body_a.geometry)
                .into_iter()
                .map(|(i, p)| {
                    let at = sa.point(&p);
                    let vb = sb.map_or(Vec3::zeros(), |s| s.velocity_at(&at));
                    (i, p, n.dot(&(sa.point_velocity(&p) - vb)))
                })
                .min_by(|x, y| x.2.total_cmp(&y.2));
            if let Some((i, p, vn)) = deepest
                && vn < 0.0
            {
                let single = feature.with_a_vertex(i, p);
                ctx.feature = single.clone();
                let r2 = ctx.apply();
                if r2.approach < 0.0 {
                    feature = single;
                    res = r2;
                } else {
                    ctx.feature = feature.clone();
                }
            }
        }
        if res.approach >= 0.0 {
            // The feature model extrapolates its features (an edge's line,
            // a face's plane): when the features really touch at an end of
            // one of them — an edge's interior resting on a corner — its
            // point can be separating while the material point at the
            // actual contact approaches. The search skipped such a contact
            // for 1e-8 s at a time while it sank, a hundred thousand times
            // (scissors settling on the coatrack's lip). The actual contact
            // point on b's tangent plane takes the impulse then.
            let at_contact = |s: &BodyState, p: &Vec3| s.velocity_at(p);
            let vb = sb.map_or(Vec3::zeros(), |s| at_contact(&s, &contact.point_b));
            if n.dot(&(at_contact(&sa, &contact.point_a) - vb)) < 0.0 {
                let tangent = feature.on_tangent_plane(&sa.pose(), &pose_b, contact);
                ctx.feature = tangent.clone();
                let r2 = ctx.apply();
                if r2.approach < 0.0 {
                    feature = tangent;
                    res = r2;
                } else {
                    ctx.feature = feature.clone();
                }
            }
        }
        if res.approach >= 0.0 && ctx.normal_dev.is_some() {
            // The bodies approach along the contact's normal, but the
            // controlled normal is tilted so far that they separate along
            // it: no impulse could keep them apart. Refuse (a solver trial
            // fails; an edit is refused) rather than let them sink.
            let at = |s: &BodyState, p: &Vec3| s.velocity_at(p);
            let vb = sb.map_or(Vec3::zeros(), |s| at(&s, &contact.point_b));
            if n.dot(&(at(&sa, &contact.point_a) - vb)) < 0.0 {
                return Err(SimError::NormalAwayFromApproach {
                    event: index,
                    t: tc,
                });
            }
        }
        // A sustained contact between two bodies whose search stalled is
        // pushed apart as a micro-collision (run/sustained.rs).
        let push = std::mem::take(&mut self.pairs[k].push) && res.approach < self.pair_floor(&pair);
        if res.approach >= 0.0 && !push {
            // Touching without approaching (a graze at the root): no impulse;
            // resume this pair's search just past the contact.
            let v = res.separation.abs().max(1e-3);
            self.pairs[k].hold = tc + (10.0 * self.tol.root / v).max(1e-12 * tc.abs().max(1.0));
            let p = &mut self.pairs[k];
            if p.skips == 0 || tc - p.skipped_since > crate::sim::events::SKIP_SPAN {
                p.skips = 0;
                p.skipped_since = tc;
            }
            p.skips += 1;
            if p.skips > crate::sim::events::MAX_SKIPS {
                return Err(SimError::EventSearchStalled {
                    a: self.scene.bodies[a].name.clone(),
                    b: self.party_name(pair.b),
                    t: tc,
                });
            }
            return Ok(());
        }
        self.pairs[k].skips = 0;
        self.pairs[k].hold = tc;
        self.check_sustained(k, tc)?;
        // How the bounce ends (rest, slide, or on bouncing; see `sim::rest`).
        let mut mode = match pair.b {
            Party::Obstacle(o) => {
                let post = BodyState {
                    v: res.va,
                    w: res.wa,
                    ..sa
                };
                let (v_rest, band) = rest::thresholds(
                    scene,
                    &self.traj.dynamics[a],
                    &self.traj.gravity,
                    self.tol.arm,
                );
                rest::decide(&rest::Impact {
                    scene,
                    dynamics: &self.traj.dynamics[a],
                    gravity: self.traj.gravity,
                    body: a,
                    obstacle: o,
                    post,
                    band,
                    v_rest,
                    part: contact.part_b,
                    normal: contact.normal,
                    horizon: self.traj.duration - tc,
                })
            }
            Party::Body(_) => Mode::Bounce,
        };
        // Bodies resting on bodies: the slow parties' island, when held,
        // freezes (run/islands.rs).
        let island = if mode == Mode::Rest {
            Vec::new()
        } else {
            self.impact_island(
                tc,
                &pair,
                [&sa, sb.as_ref().unwrap_or(&sa)],
                &res,
                [frozen_a, frozen_b],
            )?
        };
        if island.iter().any(|(i, _)| *i == a) {
            mode = Mode::Rest;
        }
        let b_rests = island.iter().any(|(i, _)| Some(*i) == pair.b_body());
        let rest = mode == Mode::Rest;
        let mut micro = false;
        // The micro-collision floor of a pair of bodies is the larger of
        // their rest speeds.
        let v_min = std::iter::once(a)
            .chain(pair.b_body())
            .map(|i| self.rest_thresholds(i).0)
            .fold(0.0, f64::max);
        // A Zeno-regime impact on a line of support starts a pivot
        // (`sim::pivot`) instead of a micro-collision.
        let pivot = match pair.b {
            Party::Obstacle(o)
                if mode == Mode::Bounce
                    && !frozen_a
                    && !anchored
                    && res.separation < v_min
                    && -res.approach < rest::MICRO * v_min =>
            {
                let post = BodyState {
                    v: res.va,
                    w: res.wa,
                    ..sa
                };
                self.try_pivot(a, o, contact.part_b, &post, tc)
                    .or_else(|| self.try_stepped(a, o, contact.part_b, &post, tc))
            }
            _ => None,
        };
        if pivot.is_none()
            && mode == Mode::Bounce
            && !b_rests
            && res.separation < v_min
            && -res.approach < rest::MICRO * v_min
        {
            // A micro-collision: elastic, or at least `v_min` (bounded
            // chatter instead of a Zeno series; see `sim::rest`).
            ctx.min_separation = Some(v_min);
            res = ctx.apply();
            micro = true;
        }
        let mut post_a = BodyState {
            v: res.va,
            w: res.wa,
            ..sa
        };
        let mut slide: Option<Slide> = None;
        match &mode {
            Mode::Rest => {
                post_a.v = Vec3::zeros();
                post_a.w = Vec3::zeros();
            }
            Mode::Slide {
                slide: sl,
                proj_v,
                proj_w,
            } => {
                post_a.v = proj_v * post_a.v;
                post_a.w = proj_w * post_a.w;
                slide = Some(*sl);
            }
            Mode::Bounce => {}
        }
        if let Some((_, start)) = &pivot {
            post_a = *start;
        }
        // A body that rests or slides lying on a face lies on it exactly
        // (see `sim::settle`); a frozen body held in place stays as it is.
        let settled = match &mode {
            _ if anchored && frozen_a => None,
            Mode::Rest => Some((0..scene.obstacles.len()).collect::<Vec<_>>()),
            Mode::Slide { slide: sl, .. } => Some(vec![sl.obstacle]),
            Mode::Bounce => None,
        }
        .and_then(|among| {
            let d = &self.traj.dynamics[a];
            let band = rest::thresholds(scene, d, &self.traj.gravity, self.tol.arm).1;
            crate::sim::settle::onto_face(scene, a, &post_a, &among, band, d.reach)
        })
        .filter(|s| self.settles_clear(a, &post_a, &s.state, tc));
        if let Some(s) = &settled {
            post_a = s.state;
        }
        let post_b = sb.map(|s| {
            if b_rests || (anchored && frozen_b) {
                BodyState {
                    v: Vec3::zeros(),
                    w: Vec3::zeros(),
                    ..s
                }
            } else {
                BodyState {
                    v: res.vb,
                    w: res.wb,
                    ..s
                }
            }
        });
        if anchored && frozen_a {
            post_a = BodyState {
                v: Vec3::zeros(),
                w: Vec3::zeros(),
                ..sa
            };
        }
        for (i, s) in [(Some(a), Some(post_a)), (pair.b_body(), post_b)] {
            if let (Some(i), Some(s)) = (i, s)
                && !s.is_finite()
            {
                return Err(SimError::NonFinite {
                    body: scene.bodies[i].name.clone(),
                    t: tc,
                });
            }
        }
        let g_n = -self.traj.gravity.dot(&n);
        let rest_time = (rest || slide.is_some()).then(|| {
            if restitution < 1.0 && g_n > 0.0 {
                tc + 2.0 * res.separation.max(0.0) / (g_n * (1.0 - restitution))
            } else {
                tc
            }
        });
        // Tangents through the impulse.
        let m = self.traj.m;
        let mut ja = DMatrix::zeros(12, m);
        let mut jb = DMatrix::zeros(12, m);
        let mut dt_du = None;
        let mut graze_ratio = f64::NAN;
        let mut grazing = false;
        let b_body = pair.b_body();
        let lost = self.traj.tangent_lost[a].or(b_body.and_then(|j| self.traj.tangent_lost[j]));
        if let (true, Some((_, e))) = (self.traj.tangent, lost) {
            // One party's Jacobians are already lost: the collision takes
            // the other's from now on.
            for body in std::iter::once(a).chain(b_body) {
                self.traj.tangent_lost[body].get_or_insert((tc, e));
            }
        } else if self.traj.tangent {
            match self.saltation(
                tc,
                index,
                pair,
                &sa,
                sb.as_ref(),
                &post_a,
                post_b.as_ref(),
                &mode,
                b_rests || (anchored && frozen_b),
                &ctx,
            ) {
                Ok((jpost, dt, ratio)) => {
                    graze_ratio = ratio;
                    ja.copy_from(&jpost.rows(0, 12));
                    if jpost.nrows() == 24 {
                        jb.copy_from(&jpost.rows(12, 12));
                    }
                    dt_du = Some(dt);
                }
                Err((e, ratio)) => {
                    graze_ratio = ratio;
                    grazing = matches!(e, TangentError::Grazing { .. });
                    self.traj.diagnostics.push(e.to_string());
                    self.traj.tangent_error.get_or_insert(e);
                    for body in std::iter::once(a).chain(b_body) {
                        self.traj.tangent_lost[body] = Some((e.time(), e));
                    }
                }
            }
        }
        if let Some(s) = &settled {
            s.project(&mut ja);
        }
        // A contact on a surface beyond the finite numbers (a parabola of
        // curvature 1e308) gives a NaN normal: a typed error, never an
        // event of NaNs in the report.
        let finite = |v: &Vec3| v.iter().all(|x| x.is_finite());
        let all_finite = finite(&res.normal)
            && finite(&res.point)
            && res.approach.is_finite()
            && finite(&post_a.v)
            && finite(&post_a.w);
        if !all_finite {
            return Err(SimError::NonFinite {
                body: body_a.name.clone(),
                t: tc,
            });
        }
        let event = Event {
            index,
            t: tc,
            a,
            b: pair.b,
            key: feature.key(),
            simultaneous: feature.simultaneous(),
            feature,
            normal: res.normal,
            point: res.point,
            approach: res.approach,
            separation: if rest || slide.is_some() {
                0.0
            } else {
                res.separation
            },
            restitution,
            graze_ratio,
            grazing,
            rest,
            slide,
            roll: false,
            micro,
            rest_time,
            friction: (friction > 0.0).then_some(ctx.mode),
            dt_du: dt_du.clone(),
            pre: [sa, sb.unwrap_or(sa)],
            post: [post_a, post_b.unwrap_or(post_a)],
        };
        self.traj.events.push(event);
        if let Some((pv, _)) = pivot {
            self.start_pivot(a, tc, post_a, ja, pv);
        } else if !(anchored && frozen_a) {
            self.start_segment(a, tc, post_a, ja, rest, slide);
        }
        if let (Some(j), Some(s)) = (pair.b_body(), post_b)
            && !(anchored && frozen_b)
        {
            self.start_segment(j, tc, s, jb, b_rests, None);
        }
        self.settle_island(
            tc,
            &pair,
            &island,
            anchored,
            [frozen_a, frozen_b],
            dt_du.as_ref(),
        );
        Ok(())
    }

    /// The contact patch of an impact: when a flat face of either party
    /// lies in the contact plane (within [`PATCH_ANGLE`]) — an edge or face
    /// landing on a face, a face on an edge — the corners lying on it
    /// within twice the patch depth, each with its face (see
    /// [`crate::geometry::FeaturePair::at_patch`]), and the depth. Two
    /// curved (tessellated) surfaces never touch in a patch: their facets
    /// meet at angles. `a` is the body's index.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn patch(
        &self,
        a: usize,
        part_a: &crate::geometry::Part,
        sa: &BodyState,
        part_b: Option<&crate::geometry::Part>,
        pose_b: &Isometry3<f64>,
        contact: &crate::geometry::Contact,
    ) -> Option<(Vec<PatchCorner>, f64, (bool, Vec3))> {
        let part_b = part_b?;
        if !matches!(part_a.kind, PartKind::Convex { .. }) {
            return None;
        }
        let n = contact.normal;
        let pose_a = sa.pose();
        let cos = PATCH_ANGLE.cos();
        let flat_a = crate::geometry::flat_faces(part_a, &pose_a, &-n, cos);
        let flat_b = crate::geometry::flat_faces(part_b, pose_b, &n, cos);
        // The impulse takes the normal of b's flat face, or of a's; the one
        // closest to the contact normal.
        let closest = |faces: &[crate::geometry::FlatFace], dir: &Vec3| {
            faces
                .iter()
                .max_by(|x, y| x.normal.dot(dir).total_cmp(&y.normal.dot(dir)))
                .map(|f| f.normal)
        };
        let impulse_face = match (closest(&flat_b, &n), closest(&flat_a, &-n)) {
            (Some(m), _) => (false, pose_b.inverse_transform_vector(&m)),
            (None, Some(m)) => (true, pose_a.inverse_transform_vector(&m)),
            (None, None) => return None,
        };
        let depth = PATCH_DEPTH * self.traj.dynamics[a].reach;
        let band = 2.0 * depth;
        // A corner takes part when it is a vertex lying on the other
        // party's flat face, or where an edge lying on one party's flat
        // face crosses the other's edge. (Around a vertex touching a face
        // the edges rise away from it: their crossings are not contacts.)
        let face = |faces: &[crate::geometry::FlatFace], p: &Vec3, on_a: bool| {
            faces
                .iter()
                .find(|f| f.holds(p, band))
                .map(|f| (f.clone(), on_a))
        };
        let lying =
            |faces: &[crate::geometry::FlatFace], p: &Vec3, q: &Vec3, at: &Vec3, on_a: bool| {
                faces
                    .iter()
                    .find(|f| {
                        f.holds(at, band)
                            && (f.normal.dot(p) - f.offset).abs() <= band
                            && (f.normal.dot(q) - f.offset).abs() <= band
                    })
                    .map(|f| (f.clone(), on_a))
            };
        let world = |pose: &Isometry3<f64>, p: &Vec3| (pose * nalgebra::Point3::from(*p)).coords;
        let face_of = |c: &Corner, at: &Vec3| match c {
            Corner::A { .. } => face(&flat_b, at, false),
            Corner::B { p, .. } => face(&flat_a, &world(pose_b, p), true),
            Corner::Crossing { a: ea, b: eb, .. } => {
                let wa = ea.map(|p| world(&pose_a, &p));
                let wb = eb.map(|p| world(pose_b, &p));
                lying(&flat_b, &wa[0], &wa[1], at, false)
                    .or_else(|| lying(&flat_a, &wb[0], &wb[1], at, true))
            }
            Corner::Ball => None,
        };
        let near = crate::geometry::part_near_points(part_a, &pose_a, part_b, pose_b, band);
        let merge = 1e-9 * (1.0 + sa.x.norm());
        let mut seen: Vec<Vec3> = Vec::new();
        let mut corners = Vec::new();
        for p in near {
            if seen.iter().any(|c| (c - p.point).norm() <= merge) {
                continue;
            }
            if let Some((f, on_a)) = face_of(&p.corner, &p.point) {
                let owner = if on_a { &pose_a } else { pose_b };
                seen.push(p.point);
                corners.push(PatchCorner {
                    corner: p.corner,
                    face_on_a: on_a,
                    face_normal: owner.inverse_transform_vector(&f.normal),
                    face_point: owner
                        .inverse_transform_point(&nalgebra::Point3::from(f.normal * f.offset))
                        .coords,
                });
            }
        }
        (!corners.is_empty()).then_some((corners, depth, impulse_face))
    }

    /// Whether settling body `a` from `before` to `after` at `tc` pushes it
    /// no deeper than the event skin into a body it collides with (nor
    /// deeper than it already was). Settling turns and shifts the body by
    /// up to its support band (tens of micrometres): a box settling on the
    /// floor under another lying on it pushed its top 6.6 µm into that one.
    fn settles_clear(&self, a: usize, before: &BodyState, after: &BodyState, tc: f64) -> bool {
        let ga = &self.scene.bodies[a].geometry;
        self.neighbours(a).into_iter().all(|j| {
            let sj = self.traj.state(j, tc, Side::Post);
            let gj = &self.scene.bodies[j].geometry;
            let depth = |s: &BodyState| {
                crate::geometry::contact(ga, &s.pose(), gj, &sj.pose(), 0.0)
                    .map_or(0.0, |c| -c.distance)
            };
            let settled = depth(after);
            settled <= self.tol.arm || settled <= depth(before)
        })
    }

    /// Refuse a pair that chatters: many impacts in a tiny span of time.
    pub(super) fn check_sustained(&self, k: usize, tc: f64) -> Result<(), SimError> {
        const COUNT: usize = 200;
        let pair = self.pairs[k];
        let recent: Vec<f64> = self
            .traj
            .events
            .iter()
            .rev()
            .filter(|e| e.a == pair.a && e.b == pair.b)
            .take(COUNT)
            .map(|e| e.t)
            .collect();
        if recent.len() == COUNT {
            let span = tc - recent[COUNT - 1];
            if span < 1e-3 * self.scene.duration.max(1e-3) {
                let name = |p: Party| match p {
                    Party::Body(i) => self.scene.bodies[i].name.clone(),
                    Party::Obstacle(i) => self.scene.obstacles[i].name.clone(),
                };
                return Err(SimError::SustainedContact {
                    a: name(Party::Body(pair.a)),
                    b: name(pair.b),
                    t: recent[COUNT - 1],
                    count: COUNT,
                    span,
                });
            }
        }
        Ok(())
    }

    pub(super) fn start_segment(
        &mut self,
        i: usize,
        t0: f64,
        start: BodyState,
        j0: DMatrix<f64>,
        rest: bool,
        slide: Option<Slide>,
    ) {
        let columns = rotation_columns(&self.opts, &j0, self.controls, i);
        self.forget_searches(i);
        self.traj.tracks[i].segments.push(Segment {
            t0,
            start,
            j0,
            rest,
            slide,
            pivot: None,
            steps: Vec::new(),
        });
        // Resting and sliding bodies move in closed form: nothing to integrate.
        self.cursors[i] =
            (self.traj.dynamics[i].integrate && !rest && slide.is_none()).then(|| {
                Cursor::new(
                    start.q,
                    integrator::initial(&(start.q.inverse() * start.w), columns),
                )
            });
    }
}
