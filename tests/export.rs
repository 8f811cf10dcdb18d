//! `nudge export --gltf`: the file is read back with the `gltf` crate and
//! held against the simulator. glTF stores `f32`, so poses and times agree
//! to `f32` precision (about 1e-7 relative), not to the simulator's f64;
//! that round trip is what is tested (docs/export.md §2).

use nudge::controls::Controls;
use nudge::export::{rotation_to_y_up, to_y_up};
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{Side, SimOptions, Trajectory, simulate};
use std::path::{Path, PathBuf};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn tmp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// `nudge export ARGS`: exit status and standard error.
fn export(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_nudge"))
        .arg("export")
        .args(args)
        .current_dir(ROOT)
        .output()
        .expect("run nudge");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn motion(scene: &Path) -> (Scene, Trajectory) {
    let scene = nudge::scene::load(scene).expect("the scene loads");
    let traj = simulate(
        &scene,
        &Controls::new(&scene),
        &SimOptions::without_tangents(),
    )
    .expect("it simulates");
    (scene, traj)
}

/// One body's animation as read from the file.
struct Channel {
    times: Vec<f32>,
    translations: Vec<[f32; 3]>,
    rotations: Vec<[f32; 4]>,
}

fn read(file: &Path) -> (gltf::Gltf, Vec<u8>) {
    let bytes = std::fs::read(file).expect("the file was written");
    let gltf = gltf::Gltf::from_slice(&bytes).expect("valid glTF");
    let blob = gltf.blob.clone().expect("a binary chunk");
    (gltf, blob)
}

fn channels(gltf: &gltf::Gltf, blob: &[u8], node: usize) -> Channel {
    let animation = gltf.animations().next().expect("one animation");
    let mut out = Channel {
        times: Vec::new(),
        translations: Vec::new(),
        rotations: Vec::new(),
    };
    for channel in animation
        .channels()
        .filter(|c| c.target().node().index() == node)
    {
        assert_eq!(
            channel.sampler().interpolation(),
            gltf::animation::Interpolation::Linear
        );
        let reader = channel.reader(|_| Some(blob));
        let times: Vec<f32> = reader.read_inputs().expect("times").collect();
        match reader.read_outputs().expect("values") {
            gltf::animation::util::ReadOutputs::Translations(t) => out.translations = t.collect(),
            gltf::animation::util::ReadOutputs::Rotations(r) => {
                out.rotations = r.into_f32().collect()
            }
            _ => panic!("only translation and rotation are animated"),
        }
        out.times = times;
    }
    out
}

fn f64s<const N: usize>(v: [f32; N]) -> [f64; N] {
    v.map(f64::from)
}

/// Every key of every body holds the simulator's pose at the key's time,
/// turned y-up, to `f32` precision: the pose was taken at the f64 time and
/// both it and the time were rounded, so the bound is the rounding of the
/// value plus the motion during the rounding of the time.
fn assert_keys_match(scene: &Scene, traj: &Trajectory, gltf: &gltf::Gltf, blob: &[u8]) {
    let eps = f64::from(f32::EPSILON);
    for (b, body) in scene.bodies.iter().enumerate() {
        let c = channels(gltf, blob, b);
        assert!(c.times.len() >= 2, "{}", body.name);
        assert_eq!(c.times.len(), c.translations.len());
        assert_eq!(c.times.len(), c.rotations.len());
        assert!(
            c.times.windows(2).all(|w| w[0] < w[1]),
            "strictly increasing"
        );
        assert_eq!(c.times[0], 0.0);
        assert_eq!(*c.times.last().expect("keys"), traj.duration as f32);
        for (k, &time) in c.times.iter().enumerate() {
            let t = f64::from(time);
            let (pre, post) = (traj.state(b, t, Side::Pre), traj.state(b, t, Side::Post));
            let speed = pre.v.norm().max(post.v.norm());
            let spin = pre.w.norm().max(post.w.norm());
            let x = to_y_up(&post.x);
            let got = Vec3::from(f64s(c.translations[k]));
            let bound = 2.0 * eps * (x.norm() + speed * t) + 1e-30;
            assert!(
                (got - x).norm() <= bound,
                "{} key {k} at {t}: {got} vs {x} (bound {bound:e})",
                body.name
            );
            let q = rotation_to_y_up(&post.q);
            let [i, j, kk, w] = f64s(c.rotations[k]);
            let got = nalgebra::Quaternion::new(w, i, j, kk);
            let off = (got - q.into_inner())
                .norm()
                .min((got + q.into_inner()).norm());
            let bound = 2.0 * eps * (2.0 + spin * t);
            assert!(
                off <= bound,
                "{} key {k} at {t}: rotation off by {off:e}",
                body.name
            );
        }
        // Every collision of the body is a key, and so is a moment just
        // before it: the impact is a corner, not smeared over a frame.
        for e in traj.body_events(b) {
            let at = e.t as f32;
            let i = c
                .times
                .iter()
                .position(|&t| t == at)
                .unwrap_or_else(|| panic!("{}: no key at the event at {}", body.name, e.t));
            if e.t > 1e-3 {
                let gap = f64::from(at) - f64::from(c.times[i - 1]);
                // max(1 µs, 2⁻²⁰ t), as rounded to f32.
                let most = 2.0 * nudge::export::keys::before(e.t);
                assert!(
                    gap <= most,
                    "{}: the key before {} is {gap} s earlier",
                    body.name,
                    e.t
                );
            }
        }
    }
}

/// The eggs as a glb: a node and mesh per body and obstacle, the bodies'
/// meshes their shapes' triangles turned y-up, and an animation whose keys
/// hold the simulator's poses, at every frame and every collision.
#[test]
fn the_eggs_export_holds_the_simulated_motion() {
    let file = tmp("eggs.glb");
    let (code, err) = export(&["scenes/eggs.toml", "--gltf", &file.display().to_string()]);
    assert_eq!(code, Some(0), "{err}");
    let (scene, traj) = motion(&Path::new(ROOT).join("scenes/eggs.toml"));
    assert!(!traj.events.is_empty(), "the eggs land");
    let (gltf, blob) = read(&file);
    let names: Vec<&str> = gltf.nodes().map(|n| n.name().unwrap_or("")).collect();
    assert_eq!(names, ["egg1", "egg2", "ground", "bucket_a", "bucket_b"]);
    for (b, body) in scene.bodies.iter().enumerate() {
        let node = gltf.nodes().nth(b).expect("a node per body");
        let primitive = node
            .mesh()
            .expect("a mesh")
            .primitives()
            .next()
            .expect("triangles");
        let reader = primitive.reader(|_| Some(&blob));
        let positions: Vec<[f32; 3]> = reader.read_positions().expect("positions").collect();
        let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
        let (vertices, triangles) = body.geometry.triangles();
        assert_eq!(indices.len(), 3 * triangles.len());
        assert_eq!(positions.len(), vertices.len());
        for (p, v) in positions.iter().zip(&vertices) {
            let y = to_y_up(v);
            assert_eq!(*p, [y.x as f32, y.y as f32, y.z as f32]);
        }
    }
    let frames = (traj.duration * 60.0).floor() as usize + 1;
    let keys = channels(&gltf, &blob, 0).times.len();
    assert!(keys > frames, "{keys} keys: every frame and the collisions");
    assert_keys_match(&scene, &traj, &gltf, &blob);
}

/// A spinning, bouncing body (the scissors thrown down) and a frame rate
/// that is not the default: the keys still hold the poses, and a body
/// turning fast gets keys between frames.
#[test]
fn a_spinning_body_at_another_frame_rate_keeps_its_poses() {
    let file = tmp("scissors-bounce.glb");
    let path = file.display().to_string();
    let (code, err) = export(&[
        "scenes/scissors-bounce.toml",
        "--gltf",
        &path,
        "--fps",
        "24",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let (scene, traj) = motion(&Path::new(ROOT).join("scenes/scissors-bounce.toml"));
    let (gltf, blob) = read(&file);
    assert_keys_match(&scene, &traj, &gltf, &blob);

    // A box spinning at ~350 rad/s turns ~15 rad per frame at 24 fps.
    let file = tmp("fast-spin.glb");
    let path = file.display().to_string();
    let fixture = "tests/fixtures/check/fast-spin.toml";
    let (code, err) = export(&[fixture, "--gltf", &path, "--fps", "24"]);
    assert_eq!(code, Some(0), "{err}");
    let (scene, traj) = motion(&Path::new(ROOT).join(fixture));
    let (gltf, blob) = read(&file);
    assert_keys_match(&scene, &traj, &gltf, &blob);
    let c = channels(&gltf, &blob, 0);
    for (k, pair) in c.rotations.windows(2).enumerate() {
        let dot: f32 = pair[0].iter().zip(&pair[1]).map(|(a, b)| a * b).sum();
        assert!(
            dot >= 0.0,
            "key {k}: consecutive rotations in one hemisphere"
        );
        let turn = 2.0 * f64::from(dot.min(1.0)).acos();
        // About 45° (from the spin at the frames), well under the 180°
        // past which a viewer's shortest path would turn the wrong way.
        assert!(
            turn < std::f64::consts::FRAC_PI_2,
            "key {k}: turns {turn} rad to the next"
        );
    }
}

/// `--keys` replays the script first: the file holds the edited motion,
/// the one the script saves, not the scene as loaded.
#[test]
fn an_edited_motion_is_exported_after_its_key_script() {
    let saved = tmp("bounce-edited.toml");
    let script = tmp("bounce-edit.keys");
    std::fs::write(
        &script,
        format!("5l 5k :w<Space>{}<Enter>\n", saved.display()),
    )
    .expect("write");
    let file = tmp("bounce-edited.glb");
    let (code, err) = export(&[
        "scenes/bounce.toml",
        "--keys",
        &script.display().to_string(),
        "--gltf",
        &file.display().to_string(),
    ]);
    assert_eq!(code, Some(0), "{err}");
    let (edited, traj) = motion(&saved);
    let (original, _) = motion(&Path::new(ROOT).join("scenes/bounce.toml"));
    assert_ne!(
        edited.bodies[0].position, original.bodies[0].position,
        "the edit moved the ball"
    );
    let (gltf, blob) = read(&file);
    assert_keys_match(&edited, &traj, &gltf, &blob);
}

/// A frame rate out of range is refused, naming the fix; nothing is written.
#[test]
fn a_frame_rate_out_of_range_is_refused() {
    for fps in ["0", "-1", "nan", "1e9"] {
        let file = tmp(&format!("refused-{fps}.glb"));
        let (code, err) = export(&[
            "scenes/bounce.toml",
            "--gltf",
            &file.display().to_string(),
            &format!("--fps={fps}"),
        ]);
        assert_eq!(code, Some(1), "{fps}: {err}");
        assert!(
            err.contains("give a frame rate above 0 and at most 10000, e.g. --fps 60"),
            "{err}"
        );
        assert!(!file.exists());
    }
}

/// `:export` in the editor writes the motion it shows (here after a nudge)
/// as a glTF file that reads back, and says where.
#[test]
fn the_editor_exports_what_it_shows() {
    let dir = tempfile::Builder::new()
        .prefix("nudge-export-editor-")
        .tempdir()
        .expect("temp dir");
    let out = dir.path().join("edited ball.glb");
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bounce.toml");
    let mut editor = nudge::edit::Editor::open(&path).expect("opens");
    let script = format!("]]]]] lll :export {}<Enter>", out.display());
    let keys = nudge::script::parse_keys(&script, "export.keys").expect("keys");
    let r = nudge::script::run_script(&mut editor, &keys, (120, 30));
    assert!(r.screen.contains("bytes of glTF"), "{}", r.screen);
    let (doc, _) = read(&out);
    assert_eq!(doc.animations().count(), 1);
    assert!(doc.nodes().any(|n| n.name() == Some("ball")));
}
