//! Scene builders for tests and benchmarks (not part of the stable API).
#![doc(hidden)]

use crate::geometry::Geometry;
use crate::math::Vec3;
use crate::scene::{Accuracy, Block, Body, Effects, Method, Obstacle, Scales, Scene};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

/// An empty scene with gravity and collisions.
pub fn scene(duration: f64) -> Scene {
    Scene {
        name: "test".into(),
        notes: String::new(),
        duration,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        effects: Effects {
            gravity: true,
            collisions: true,
            ..Effects::default()
        },
        accuracy: Accuracy::default(),
        rest_speed: 1e-3,
        bodies: Vec::new(),
        obstacles: Vec::new(),
        pairs: Vec::new(),
        scales: Scales::default(),
        event_controls: Vec::new(),
        constraints: Vec::new(),
        source_text: None,
    }
}

/// An empty scene with gravity, collisions, friction and gyroscopic
/// terms, over the ground plane `z = 0` with friction coefficient `mu`.
pub fn on_ground(duration: f64, mu: f64) -> Scene {
    let mut s = scene(duration);
    s.effects.friction = true;
    s.effects.gyroscopic = true;
    let mut floor = ground();
    floor.friction = mu;
    s.obstacles.push(floor);
    s
}

/// Mechanical energy of `body` at `t` (J): kinetic (the inertia turned
/// into the world frame) plus gravity's potential.
pub fn energy(tr: &crate::sim::Trajectory, body: usize, t: f64) -> f64 {
    let d = &tr.dynamics[body];
    let s = tr.state(body, t, crate::sim::Side::Post);
    let r = *s.q.to_rotation_matrix().matrix();
    let ic = r * d.inertia * r.transpose();
    0.5 * (d.mass * s.v.norm_squared() + s.w.dot(&(ic * s.w))) - d.mass * tr.gravity.dot(&s.x)
}

/// The smallest signed distance (m) between any body and any obstacle
/// over a motion: sampled at `n + 1` evenly spaced times and on both sides
/// of every event.
pub fn lowest_gap(scene: &Scene, tr: &crate::sim::Trajectory, n: usize) -> f64 {
    let gap = |b: usize, t: f64, side: crate::sim::Side| {
        let pose = tr.state(b, t, side).pose();
        scene
            .obstacles
            .iter()
            .filter_map(|o| {
                crate::geometry::contact(
                    &scene.bodies[b].geometry,
                    &pose,
                    &o.geometry,
                    &o.pose,
                    f64::INFINITY,
                )
            })
            .map(|c| c.distance)
            .fold(f64::INFINITY, f64::min)
    };
    let mut low = f64::INFINITY;
    for b in 0..scene.bodies.len() {
        for k in 0..=n {
            low = low.min(gap(
                b,
                scene.duration * k as f64 / n as f64,
                crate::sim::Side::Post,
            ));
        }
        for e in tr.body_events(b) {
            low = low.min(gap(b, e.t, crate::sim::Side::Pre)).min(gap(
                b,
                e.t,
                crate::sim::Side::Post,
            ));
        }
    }
    low
}

/// A body with the given geometry and density 1000 kg/m³, inertia from the shape.
pub fn body(name: &str, geometry: Geometry, position: Vec3) -> Body {
    let props = geometry
        .mass_properties(1000.0)
        .expect("bounded test geometry");
    let geometry = geometry.recentered(&props.com);
    let eig = props.inertia.symmetric_eigen();
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let mut axes = nalgebra::Matrix3::from_columns(&[
        eig.eigenvectors.column(idx[0]),
        eig.eigenvectors.column(idx[1]),
        eig.eigenvectors.column(idx[2]),
    ]);
    if axes.determinant() < 0.0 {
        axes.set_column(2, &(-axes.column(2)));
    }
    let inertia = Vec3::new(
        eig.eigenvalues[idx[0]],
        eig.eigenvalues[idx[1]],
        eig.eigenvalues[idx[2]],
    );
    Body {
        name: name.into(),
        geometry,
        shape_source: toml::Value::Table(Default::default()),
        com_offset: props.com,
        mass: props.mass,
        inertia,
        inertia_axes: UnitQuaternion::from_matrix(&axes),
        inertia_given: false,
        position,
        orientation: Vec3::zeros(),
        velocity: Vec3::zeros(),
        angular_velocity: Vec3::zeros(),
        restitution: 1.0,
        friction: 0.5,
        drag: 0.0,
        traced: vec![Vec3::zeros()],
        free: Vec::new(),
    }
}

/// A body with the given mass and principal inertia (axes = body axes).
pub fn body_with_inertia(
    name: &str,
    geometry: Geometry,
    position: Vec3,
    mass: f64,
    inertia: Vec3,
) -> Body {
    let mut b = body(name, geometry, position);
    b.mass = mass;
    b.inertia = inertia;
    b.inertia_axes = UnitQuaternion::identity();
    b.inertia_given = true;
    b
}

/// A static obstacle.
pub fn obstacle(name: &str, geometry: Geometry, position: Vec3) -> Obstacle {
    Obstacle {
        name: name.into(),
        geometry,
        shape_source: toml::Value::Table(Default::default()),
        pose: Isometry3::from_parts(Translation3::from(position), UnitQuaternion::identity()),
        restitution: 1.0,
        friction: 0.5,
    }
}

/// The ground plane `z = 0`.
pub fn ground() -> Obstacle {
    obstacle(
        "ground",
        Geometry::half_space(Vec3::z()).expect("unit normal"),
        Vec3::zeros(),
    )
}

/// Free all four state blocks of every body.
pub fn free_state(scene: &mut Scene) {
    for b in &mut scene.bodies {
        b.free = vec![
            Block::Position,
            Block::Orientation,
            Block::Velocity,
            Block::AngularVelocity,
        ];
    }
}

/// Use the adaptive integrator.
pub fn adaptive(scene: &mut Scene, tol: f64) {
    scene.accuracy.method = Method::Adaptive {
        tol,
        max_step: 0.02,
    };
}

/// Ball radius of [`balls_in_box`], m.
pub const BALL_RADIUS: f64 = 0.05;

/// `n` balls of radius [`BALL_RADIUS`] on a grid in a box (ground and four
/// walls) whose floor area grows with `n` (constant density, so collisions
/// per ball stay about the same), with seeded random velocities and the
/// given restitution; the first `free` balls have free position and
/// velocity; every body–body pair is listed.
pub fn balls_in_box(
    n: usize,
    horizon: f64,
    free: usize,
    seed: u64,
    restitution: f64,
) -> Result<Scene, String> {
    let mut scene = self::scene(horizon);
    scene.name = format!("{n} balls");
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let half = 0.5 * side as f64;
    let spacing = 2.0 * half / side as f64;
    let mut rng = crate::math::Rng(seed);
    let sphere = Geometry::sphere(BALL_RADIUS).map_err(|e| e.to_string())?;
    for i in 0..n {
        let (gx, gy) = ((i % side) as f64, (i / side) as f64);
        let position = Vec3::new(
            -half + spacing * (gx + 0.5),
            -half + spacing * (gy + 0.5),
            rng.range(0.3, 1.0),
        );
        let mut b = body(&format!("ball{i}"), sphere.clone(), position);
        b.velocity = Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(0.0, 2.0),
        );
        b.restitution = restitution;
        if i < free {
            b.free = vec![Block::Position, Block::Velocity];
        }
        scene.bodies.push(b);
    }
    scene.obstacles.push(ground());
    for (name, normal) in [
        ("wall+x", -Vec3::x()),
        ("wall-x", Vec3::x()),
        ("wall+y", -Vec3::y()),
        ("wall-y", Vec3::y()),
    ] {
        let g = Geometry::half_space(normal).map_err(|e| e.to_string())?;
        scene.obstacles.push(obstacle(name, g, -normal * half));
    }
    scene.pairs = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| [i, j]))
        .collect();
    Ok(scene)
}

/// Two central difference quotients of a Jacobian column that agree to this
/// (relative to the column, or 1e-3 if smaller) resolve it: a tenth of the
/// 1e-6 tangents are held to, so the quotients' own noise cannot decide a
/// comparison.
pub const RESOLVED: f64 = 1e-7;

/// Column by column, the tangent `jt` of `body` at `t` against the closest
/// of the difference quotients of `runs` (the same columns at several
/// steps), over the columns whose collision sequence up to `t` is
/// unchanged and that two quotients resolve: the worst relative
/// disagreement and how many columns it covers (`None` if none does).
pub fn resolved_agreement(
    runs: &[crate::tangent::FiniteDifference],
    jt: &nalgebra::DMatrix<f64>,
    body: usize,
    t: f64,
) -> Option<(f64, usize)> {
    let quotients: Vec<(Vec<bool>, nalgebra::DMatrix<f64>)> = runs
        .iter()
        .map(|fd| {
            (
                fd.comparable_until(t),
                fd.at(body, t, crate::sim::Side::Post),
            )
        })
        .collect();
    let rel = |a: nalgebra::DVectorView<f64>, b: nalgebra::DVectorView<f64>| {
        (a - b).norm() / b.norm().max(1e-3)
    };
    let mut worst: Option<(f64, usize)> = None;
    for c in 0..jt.ncols() {
        let cols: Vec<_> = quotients
            .iter()
            .filter(|(keeps, _)| keeps[c])
            .map(|(_, j)| j.column(c))
            .collect();
        if !cols.windows(2).any(|w| rel(w[0], w[1]) < RESOLVED) {
            continue;
        }
        let err = cols
            .iter()
            .map(|f| rel(jt.column(c), *f))
            .fold(f64::INFINITY, f64::min);
        worst = Some(worst.map_or((err, 1), |(w, n)| (w.max(err), n + 1)));
    }
    worst
}

/// Compare tangent and central-difference Jacobians of every body at the
/// given times and just before/after every event; returns the worst
/// relative error over comparable columns, and which columns those are
/// (their perturbed runs keep the collision sequence). Panics, naming the
/// place, where the error reaches `tol` (a test helper).
pub fn check_against_central(scene: &Scene, times: &[f64], tol: f64) -> (f64, Vec<bool>) {
    // Event times are differenced over steps of ~1e-5: refine roots far
    // below that so the quotient's noise (root_tol / (|v_n| h)) stays small.
    let mut scene = scene.clone();
    scene.accuracy.root_tol = 1e-14;
    let scene = &scene;
    let controls = crate::controls::Controls::new(scene);
    let tr = crate::sim::simulate(scene, &controls, &crate::sim::SimOptions::default())
        .expect("simulates");
    assert!(tr.tangent_error.is_none(), "{:?}", tr.tangent_error);
    let fd =
        crate::tangent::FiniteDifference::new(scene, &controls, crate::tangent::Scheme::Central)
            .expect("perturbed runs");
    assert!(
        fd.comparable.iter().any(|c| *c),
        "some column must keep the signature"
    );
    let mut worst: f64 = 0.0;
    for b in 0..scene.bodies.len() {
        for &t in times {
            let jt = tr.jacobian(b, t, crate::sim::Side::Post).expect("jacobian");
            let jf = fd.at(b, t, crate::sim::Side::Post);
            let err = crate::tangent::max_relative_error(&jt, &jf, &fd.comparable, 1e-3);
            assert!(
                err < tol,
                "body {b} t={t}: relative error {err:.2e}\ntangent {jt:.6}\nfd {jf:.6}"
            );
            worst = worst.max(err);
        }
    }
    for (k, ev) in tr.events.iter().enumerate() {
        // Floating quantities: the state at each run's own event time.
        for side in [crate::sim::Side::Pre, crate::sim::Side::Post] {
            let fl = fd.at_event(k, ev.a, side).expect("same events");
            let jt = tr
                .jacobian_at_event(ev.a, ev, side)
                .expect("jacobian and dt/du");
            let err = crate::tangent::max_relative_error(&jt, &fl, &fd.comparable, 1e-3);
            assert!(
                err < tol,
                "event {k} {side:?}: relative error {err:.2e}\ntangent {jt:.6}\nfd {fl:.6}"
            );
            worst = worst.max(err);
        }
        let dtf = fd.event_time(k).expect("event times");
        let dtt = ev.dt_du.as_ref().expect("dt/du");
        for c in 0..dtf.len() {
            if fd.comparable[c] {
                let e = (dtt[c] - dtf[c]).abs() / dtf[c].abs().max(1e-3);
                assert!(
                    e < tol,
                    "event {k} dt/du column {c}: {} vs {}",
                    dtt[c],
                    dtf[c]
                );
            }
        }
    }
    (worst, fd.comparable)
}
