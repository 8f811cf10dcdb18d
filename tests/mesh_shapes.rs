//! `shape = { type = "mesh", ... }`: OBJ and STL files as bodies and
//! obstacles, collided as their hull or their convex decomposition, with
//! the mass of the solid they enclose. Meshes in `tests/fixtures/mesh/`;
//! the invalid ones are in `tests/invalid_scenes/`.

use nudge::controls::Controls;
use nudge::scene::{Scene, load, load_str};
use nudge::sim::{SimOptions, Trajectory, simulate};
use std::path::Path;

/// A scene in `tests/fixtures/mesh/` (mesh paths resolve from there).
fn scene(text: &str) -> Scene {
    load_str(text, "tests/fixtures/mesh/scene.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::without_tangents()).expect("it simulates")
}

/// A 0.2 m cube dropped with a tilt onto a floor, its shape given as `shape`.
fn dropped(shape: &str) -> String {
    format!(
        r#"duration = 1.0
effects = ["gravity", "collisions"]
[[body]]
name = "cube"
shape = {shape}
density = 500.0
position = [0.0, 0.0, 0.5]
orientation = [0.3, 0.2, 0.0]
restitution = 0.5
[[obstacle]]
name = "floor"
shape = {{ type = "plane", normal = [0.0, 0.0, 1.0] }}
"#
    )
}

/// The cube as OBJ quads and as ASCII STL weighs and turns like the `box`
/// shape, and falls and bounces like it.
#[test]
fn a_cube_mesh_is_the_box_it_describes() {
    let reference = scene(&dropped(
        r#"{ type = "box", half_extents = [0.1, 0.1, 0.1] }"#,
    ));
    let motion = run(&reference);
    assert!(motion.events.len() >= 2, "it bounces");
    // STL stores f32: its 0.1 is 0.1 to 1.5e-9 m, and so is the cube.
    for (file, within) in [("cube.obj", 1e-12), ("cube.stl", 1e-7)] {
        let s = scene(&dropped(&format!(
            r#"{{ type = "mesh", file = "{file}" }}"#
        )));
        let (a, b) = (&s.bodies[0], &reference.bodies[0]);
        assert!(
            (a.mass - b.mass).abs() < within * b.mass,
            "{file}: {}",
            a.mass
        );
        assert!(
            (a.inertia - b.inertia).norm() < within * b.inertia.norm(),
            "{file}"
        );
        assert!(a.com_offset.norm() < within, "{file}");
        // The first bounces (the rest, micro-collisions as it settles, may
        // differ in number for the STL's cube, 1.5e-9 m larger).
        let m = run(&s);
        assert_eq!(m.signature()[..2], motion.signature()[..2], "{file}");
        for (e, f) in m.events.iter().zip(&motion.events).take(2) {
            assert!(
                (e.t - f.t).abs() < 1e3 * within,
                "{file}: {} vs {}",
                e.t,
                f.t
            );
        }
    }
}

/// `scale` takes the file's units to metres: the cube at half its size.
#[test]
fn scale_takes_the_file_to_metres() {
    let s = scene(&dropped(
        r#"{ type = "mesh", file = "cube.obj", scale = 0.5 }"#,
    ));
    let volume = 0.1 * 0.1 * 0.1;
    assert!((s.bodies[0].mass - 500.0 * volume).abs() < 1e-12);
}

/// A ball dropped onto the L's horizontal leg, 0.2 m from its corner: the
/// hull fills the corner, so the ball lands on its slanted face, 0.3 m up;
/// the decomposition follows the L, so the ball lands on the leg, about
/// 0.1 m up. The L's mass is its solid's either way.
#[test]
fn a_decomposition_follows_a_hollow_the_hull_fills() {
    let text = |decomposition: &str| {
        format!(
            r#"duration = 1.0
effects = ["gravity", "collisions"]
[[body]]
name = "ball"
shape = {{ type = "sphere", radius = 0.02 }}
density = 1000.0
position = [0.2, 0.0, 0.8]
[[body]]
name = "ell"
shape = {{ type = "mesh", file = "ell.obj", decomposition = "{decomposition}" }}
density = 1000.0
position = [2.0, 0.0, 0.5]
[[obstacle]]
name = "corner"
shape = {{ type = "mesh", file = "ell.obj", decomposition = "{decomposition}" }}
"#
        )
    };
    let volume = 0.4 * 0.1 * 0.1 + 0.3 * 0.1 * 0.1;
    let mut landed = Vec::new();
    for d in ["hull", "convex"] {
        let s = scene(&text(d));
        assert!(
            (s.bodies[1].mass - 1000.0 * volume).abs() < 1e-9,
            "{d}: {}",
            s.bodies[1].mass
        );
        let first = run(&s)
            .events
            .into_iter()
            .find(|e| e.a == 0)
            .expect("the ball lands");
        landed.push(first.point.z);
    }
    // The slanted face is x + z = 0.5: a 0.02 m ball at x = 0.2 touches it
    // at z = 0.3 + 0.02/√2.
    let slant = 0.3 + 0.02 / 2f64.sqrt();
    assert!(
        (landed[0] - slant).abs() < 1e-6,
        "on the hull: {}",
        landed[0]
    );
    // The decomposition is approximate: it follows the corner to within
    // about 2 % of the L's size (0.57 m).
    assert!(
        (0.1..0.12).contains(&landed[1]),
        "on the leg: {}",
        landed[1]
    );
}

/// Saving keeps the mesh reference as written and adds no inertia: it
/// still follows from the mesh and the mass. The scene is written as new
/// text (no source to edit in place), which rebuilds nothing from the
/// reference: the file is found from the scene's folder only on loading.
#[test]
fn saving_keeps_the_mesh_reference() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("mesh-save");
    std::fs::create_dir_all(&dir).expect("a folder");
    std::fs::copy("tests/fixtures/mesh/cube.obj", dir.join("cube.obj")).expect("copy");
    let file = dir.join("cube.toml");
    let text = dropped(r#"{ type = "mesh", file = "cube.obj" }"#);
    std::fs::write(&file, &text).expect("write");
    let mut s = load(&file).expect("loads");
    s.source_text = None;
    let saved = dir.join("saved.toml");
    nudge::scene::save(&s, &saved, nudge::files::WriteMode::Normal).expect("saves");
    let back_text = std::fs::read_to_string(&saved).expect("read");
    assert!(back_text.contains(r#"file = "cube.obj""#), "{back_text}");
    assert!(!back_text.contains("inertia"), "{back_text}");
    let back = load(&saved).expect("loads back");
    assert_eq!(back.bodies[0].mass, s.bodies[0].mass);
    assert_eq!(back.bodies[0].inertia, s.bodies[0].inertia);
    assert_eq!(back.bodies[0].inertia_axes, s.bodies[0].inertia_axes);
}

/// A mesh over the triangle budget is refused, saying how many it has.
#[test]
fn a_mesh_over_the_triangle_budget_is_refused() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"));
    // A fan of 20,001 triangles around the z axis, closed by a cone.
    let n = 10_001;
    let mut obj = String::from("v 0 0 1\nv 0 0 -1\n");
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        obj.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    for k in 0..n {
        let (i, j) = (3 + k, 3 + (k + 1) % n);
        obj.push_str(&format!("f 1 {i} {j}\nf 2 {j} {i}\n"));
    }
    let mesh = dir.join("too-many.obj");
    std::fs::write(&mesh, obj).expect("write");
    let shape = format!(r#"{{ type = "mesh", file = "{}" }}"#, mesh.display());
    let err = load_str(&dropped(&shape), "<test>")
        .map(|_| ())
        .expect_err("refused");
    assert!(
        err.to_string()
            .contains("has 20002 triangles, more than 20000: "),
        "{err}"
    );
}

/// Saving a scene with a relative mesh path into another folder is refused
/// while the mesh is not there (the file would not load), and allowed once
/// it is.
#[test]
fn saving_elsewhere_needs_the_meshes_beside_the_new_file() {
    use nudge::edit::{Core, Editor, WriteMode};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::Builder::new()
        .prefix("nudge-mesh-save-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path();
    let out = dir.join("hat-copy.toml");
    let mut editor = Editor::open(&root.join("scenes/hat.toml")).expect("opens");
    let err = editor
        .save(Some(&out), WriteMode::Normal)
        .expect_err("no mesh beside it");
    assert!(err.to_string().contains("meshes/hat.obj"), "{err}");
    assert!(!out.exists());
    std::fs::create_dir_all(dir.join("meshes")).expect("meshes dir");
    std::fs::copy(
        root.join("scenes/meshes/hat.obj"),
        dir.join("meshes/hat.obj"),
    )
    .expect("copy");
    editor.save(Some(&out), WriteMode::Normal).expect("saves");
    nudge::scene::load(&out).expect("the saved scene loads with its mesh");
}
