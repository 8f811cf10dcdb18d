//! The scene format end to end: every shipped scene loads and saves back
//! bit for bit, saving keeps the user's comments and layout, and every
//! invalid scene under `tests/invalid_scenes/` fails with exactly the
//! message on its first line (`# expect: <message>`).
use nudge::files::WriteMode;
use nudge::geometry::{Geometry, PartKind};
use nudge::scene::{
    DEFAULT_SCENE, Method, Scene, SceneError, load, load_str, save, saved_text, to_toml,
};
use std::path::{Path, PathBuf};

/// The `.toml` files of a directory (relative to the crate root), sorted.
fn toml_files(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
        .map(|e| Path::new(dir).join(e.expect("directory entry").file_name()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
}

fn message(r: Result<Scene, SceneError>) -> Option<String> {
    match r {
        Ok(_) => None,
        Err(SceneError::Invalid(m)) => Some(m),
    }
}

#[test]
fn every_invalid_scene_fails_with_its_expected_message() {
    let files = toml_files("tests/invalid_scenes");
    assert!(files.len() >= 15, "only {} invalid scenes", files.len());
    let mut failures = Vec::new();
    for path in &files {
        let bytes = std::fs::read(path).expect("readable");
        let first = bytes.split(|b| *b == b'\n').next().unwrap_or_default();
        let first = String::from_utf8_lossy(first);
        let expected = first.strip_prefix("# expect: ").unwrap_or_else(|| {
            panic!(
                "{}: first line must be `# expect: <message>`",
                path.display()
            )
        });
        match message(load(path)) {
            None => failures.push(format!("{}: loaded without error", path.display())),
            Some(got) if got != expected => failures.push(format!(
                "{}:\n  expected: {expected}\n  got:      {got}",
                path.display()
            )),
            Some(_) => {}
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} invalid scenes failed:\n{}",
        failures.len(),
        files.len(),
        failures.join("\n")
    );
}

#[test]
fn every_shipped_scene_loads_and_starts_with_a_comment_block() {
    let files = toml_files("scenes");
    assert!(files.len() >= 8, "{files:?}");
    for path in &files {
        let text = std::fs::read_to_string(path).expect("readable");
        assert!(
            text.starts_with('#'),
            "{}: must start with a # comment block",
            path.display()
        );
        let scene = load(path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.notes.is_empty(), "{}: give notes", path.display());
        assert_eq!(
            scene.name,
            path.file_stem().unwrap().to_string_lossy(),
            "{}",
            path.display()
        );
    }
}

#[test]
fn the_default_scene_is_the_eggs() {
    let scene = load_str(DEFAULT_SCENE, "<default>").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.bodies.len(), 2);
    assert_eq!(scene.pairs, vec![[0, 1]]);
}

/// Every number of a scene, labelled, as bits.
#[derive(Default)]
struct Fingerprint(Vec<(String, u64)>);

impl Fingerprint {
    fn num(&mut self, label: String, x: f64) {
        self.0.push((label, x.to_bits()));
    }

    fn vec3(&mut self, label: &str, v: &nudge::math::Vec3) {
        for i in 0..3 {
            self.num(format!("{label}[{i}]"), v[i]);
        }
    }

    fn quat(&mut self, label: &str, q: &nalgebra::UnitQuaternion<f64>) {
        for (i, x) in q.coords.iter().enumerate() {
            self.num(format!("{label}[{i}]"), *x);
        }
    }

    fn geometry(&mut self, label: &str, g: &Geometry) {
        for (p, part) in g.parts.iter().enumerate() {
            let l = format!("{label}.part[{p}]");
            self.vec3(&format!("{l}.offset.t"), &part.offset.translation.vector);
            self.quat(&format!("{l}.offset.q"), &part.offset.rotation);
            match &part.kind {
                PartKind::Ball { radius } => self.num(format!("{l}.radius"), *radius),
                PartKind::Convex {
                    vertices, edges, ..
                } => {
                    for (v, p) in vertices.iter().enumerate() {
                        self.vec3(&format!("{l}.vertex[{v}]"), p);
                    }
                    self.num(format!("{l}.edges"), edges.len() as f64);
                }
                PartKind::HalfSpace { normal } => self.vec3(&format!("{l}.normal"), normal),
                PartKind::Parabola {
                    curvature,
                    half_width,
                } => {
                    self.num(format!("{l}.curvature"), *curvature);
                    self.num(format!("{l}.half_width"), *half_width);
                }
            }
        }
    }

    fn of(s: &Scene) -> Fingerprint {
        let mut f = Fingerprint::default();
        f.num("duration".into(), s.duration);
        f.vec3("gravity", &s.gravity);
        f.num("rest_speed".into(), s.rest_speed);
        match s.accuracy.method {
            Method::Rk4 { step } => f.num("rk4.step".into(), step),
            Method::Adaptive { tol, max_step } => {
                f.num("adaptive.tol".into(), tol);
                f.num("adaptive.max_step".into(), max_step);
            }
        }
        f.num("root_tol".into(), s.accuracy.root_tol);
        let sc = &s.scales;
        for (k, v) in [
            ("position", sc.position),
            ("orientation", sc.orientation),
            ("velocity", sc.velocity),
            ("angular_velocity", sc.angular_velocity),
            ("mass", sc.mass),
            ("inertia", sc.inertia),
            ("normal", sc.normal),
            ("restitution", sc.restitution),
        ] {
            f.num(format!("scales.{k}"), v);
        }
        for b in &s.bodies {
            let l = format!("body {}", b.name);
            f.num(format!("{l}.mass"), b.mass);
            f.vec3(&format!("{l}.inertia"), &b.inertia);
            f.quat(&format!("{l}.inertia_axes"), &b.inertia_axes);
            f.num(
                format!("{l}.inertia_given"),
                f64::from(u8::from(b.inertia_given)),
            );
            f.vec3(&format!("{l}.com_offset"), &b.com_offset);
            f.vec3(&format!("{l}.position"), &b.position);
            f.vec3(&format!("{l}.orientation"), &b.orientation);
            f.vec3(&format!("{l}.velocity"), &b.velocity);
            f.vec3(&format!("{l}.angular_velocity"), &b.angular_velocity);
            f.num(format!("{l}.restitution"), b.restitution);
            f.num(format!("{l}.friction"), b.friction);
            f.num(format!("{l}.drag"), b.drag);
            for (k, p) in b.traced.iter().enumerate() {
                f.vec3(&format!("{l}.traced[{k}]"), p);
            }
            for block in &b.free {
                f.num(format!("{l}.free.{}", block.name()), 1.0);
            }
            f.geometry(&l, &b.geometry);
        }
        for o in &s.obstacles {
            let l = format!("obstacle {}", o.name);
            f.vec3(&format!("{l}.pose.t"), &o.pose.translation.vector);
            f.quat(&format!("{l}.pose.q"), &o.pose.rotation);
            f.num(format!("{l}.restitution"), o.restitution);
            f.num(format!("{l}.friction"), o.friction);
            f.geometry(&l, &o.geometry);
        }
        for [i, j] in &s.pairs {
            f.num(format!("pair {i} {j}"), 1.0);
        }
        for c in &s.event_controls {
            let l = format!("event_control {}", c.event);
            if let Some([a, b]) = c.normal {
                f.num(format!("{l}.normal[0]"), a);
                f.num(format!("{l}.normal[1]"), b);
            }
            if let Some(e) = c.restitution {
                f.num(format!("{l}.restitution"), e);
            }
            f.num(format!("{l}.fixed"), f64::from(u8::from(c.fixed)));
        }
        for (k, c) in s.constraints.iter().enumerate() {
            if let Some(t) = c.time {
                f.num(format!("constraint {k}.time"), t);
            }
            for (i, x) in c.target.iter().enumerate() {
                f.num(format!("constraint {k}.target[{i}]"), *x);
            }
        }
        f
    }
}

fn assert_same(a: &Scene, b: &Scene, what: &str) {
    assert_eq!(a.name, b.name, "{what}: name");
    assert_eq!(a.notes, b.notes, "{what}: notes");
    assert_eq!(a.effects, b.effects, "{what}: effects");
    assert_eq!(a.constraints, b.constraints, "{what}: constraints");
    for (x, y) in a.bodies.iter().zip(&b.bodies) {
        assert_eq!(x.name, y.name, "{what}");
        assert_eq!(
            x.shape_source, y.shape_source,
            "{what}: body {} shape",
            x.name
        );
    }
    for (x, y) in a.obstacles.iter().zip(&b.obstacles) {
        assert_eq!(x.name, y.name, "{what}");
        assert_eq!(
            x.shape_source, y.shape_source,
            "{what}: obstacle {} shape",
            x.name
        );
    }
    let (fa, fb) = (Fingerprint::of(a).0, Fingerprint::of(b).0);
    assert_eq!(fa.len(), fb.len(), "{what}: different number of fields");
    for ((la, xa), (lb, xb)) in fa.iter().zip(&fb) {
        assert_eq!(la, lb, "{what}: field order");
        assert_eq!(
            xa,
            xb,
            "{what}: {la} differs: {} vs {}",
            f64::from_bits(*xa),
            f64::from_bits(*xb)
        );
    }
}

#[test]
fn every_shipped_scene_round_trips_bit_for_bit() {
    for path in toml_files("scenes") {
        let original = load(&path).unwrap_or_else(|e| panic!("{e}"));
        let text = to_toml(&original);
        let again =
            load_str(&text, &path.display().to_string()).unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert_same(&original, &again, &path.display().to_string());
        assert_eq!(
            to_toml(&again),
            text,
            "{}: saving is not idempotent",
            path.display()
        );
        let own = std::fs::read_to_string(&path).expect("readable");
        assert_eq!(
            saved_text(&original, &path),
            own,
            "{}: an unedited scene saves as its own text, byte for byte",
            path.display()
        );
    }
}

#[test]
fn edited_scenes_round_trip_too() {
    // Values the editor produces: arbitrary digits, a changed mass (so the
    // inertia no longer follows from the shape), event controls, scales and
    // constraints.
    let mut scene = load(Path::new("scenes/eggs.toml")).unwrap_or_else(|e| panic!("{e}"));
    let b = &mut scene.bodies[0];
    b.position.x += 0.1 / 3.0;
    b.velocity *= 1.0 + 1e-13;
    b.orientation = nudge::math::Vec3::new(0.7, -2.1, 1.9).normalize() * 2.9;
    b.mass *= 1.25;
    b.angular_velocity.z = -7.123_456_789_012_345;
    scene.scales.velocity = 2.5;
    scene.event_controls.push(nudge::scene::EventControl {
        event: 3,
        normal: Some([0.01, -1.0 / 7.0]),
        restitution: Some(0.55),
        fixed: true,
    });
    scene.constraints.push(nudge::scene::ConstraintSpec {
        kind: nudge::scene::ConstraintKind::Nail,
        body: "egg1".into(),
        other: None,
        time: Some(2.0 / 3.0),
        collision: None,
        side: None,
        quantities: vec![nudge::scene::StateQuantity::Position],
        target: vec![0.1, -0.2, 1.0 / 3.0],
    });
    scene.accuracy.method = Method::Adaptive {
        tol: 1e-10,
        max_step: 0.004,
    };
    let path = Path::new("scenes/eggs.toml");
    let fresh = to_toml(&scene);
    let in_place = saved_text(&scene, path);
    let original = std::fs::read_to_string(path).expect("readable");
    assert_comments_kept(&original, &in_place, "edited eggs");
    // egg1's edited mass takes the place of its density; egg2 keeps its own.
    let egg = |text: &str, k: usize| text.split("[[body]]").nth(k).unwrap_or("").to_string();
    let egg1 = egg(&in_place, 1);
    assert!(
        egg1.contains("\nmass = ") && !egg1.contains("density") && egg1.contains("\ninertia = "),
        "{egg1}"
    );
    assert!(
        egg(&in_place, 2).contains("\ndensity = 1000.0\n"),
        "{in_place}"
    );
    for (how, text) in [("new text", &fresh), ("in place", &in_place)] {
        let mut scene = scene.clone();
        let again = load_str(text, "scenes/eggs.toml").unwrap_or_else(|e| panic!("{e}\n{text}"));
        assert!(
            again.bodies[0].inertia_given,
            "{how}: an edited mass keeps the old inertia explicitly"
        );
        assert!(!again.bodies[1].inertia_given, "{how}");
        scene.bodies[0].inertia_given = true;
        assert_same(&scene, &again, &format!("edited eggs, {how}"));
    }
}

/// Each line of `text` that is a comment (or ends in one), trimmed.
fn comment_lines(text: &str) -> Vec<&str> {
    text.lines()
        .filter_map(|l| l.find('#').map(|i| l[i..].trim_end()))
        .collect()
}

/// Every comment of `original` is in `saved`, in the same order.
fn assert_comments_kept(original: &str, saved: &str, what: &str) {
    let mut left = comment_lines(saved).into_iter();
    for c in comment_lines(original) {
        assert!(
            left.any(|s| s == c),
            "{what}: comment {c:?} lost or out of order:\n{saved}"
        );
    }
}

/// For each line of `a`, whether it is kept unchanged in `b` (a longest
/// common subsequence of lines).
fn kept_lines(a: &[&str], b: &[&str]) -> Vec<bool> {
    let (n, m) = (a.len(), b.len());
    let mut lcs = vec![vec![0usize; m + 1]; n + 1];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            lcs[i][j] = if a[i] == b[j] {
                lcs[i + 1][j + 1] + 1
            } else {
                lcs[i + 1][j].max(lcs[i][j + 1])
            };
        }
    }
    let (mut i, mut j, mut kept) = (0, 0, vec![false; n]);
    while i < n && j < m {
        if a[i] == b[j] {
            kept[i] = true;
            (i, j) = (i + 1, j + 1);
        } else if lcs[i + 1][j] >= lcs[i][j + 1] {
            i += 1;
        } else {
            j += 1;
        }
    }
    kept
}

/// An edit through the editor core on every shipped scene (a freed block,
/// a velocity nudge, a nail, event controls, a scale) saved to a file:
/// every comment is still there in order, the only original lines that
/// changed are the edited keys' values, the file loads back to the edited
/// scene bit for bit, and saving again changes nothing.
#[test]
fn editor_edits_keep_every_comment_and_untouched_line_of_every_scene() {
    use nudge::edit::{Core, Edit, Editor};
    use nudge::scene::{Block, StateQuantity};
    let tmp = tempfile::Builder::new()
        .prefix("nudge-keep-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    std::fs::create_dir_all(dir.join("meshes")).expect("meshes dir");
    // Mesh shapes are found from the scene file's folder.
    for mesh in std::fs::read_dir("scenes/meshes").expect("scenes/meshes") {
        let mesh = mesh.expect("entry").path();
        std::fs::copy(
            &mesh,
            dir.join("meshes").join(mesh.file_name().expect("name")),
        )
        .expect("copy");
    }
    for path in toml_files("scenes") {
        let what = path.display().to_string();
        let original = std::fs::read_to_string(&path).expect("readable");
        let mut e = Editor::open(&path).unwrap_or_else(|err| panic!("{what}: {err}"));
        e.set_wall_clock(false);
        if !e.scene().bodies[0].is_free(Block::Velocity) {
            e.apply(Edit::SetBlock {
                body: 0,
                block: Block::Velocity,
                free: true,
            })
            .unwrap_or_else(|err| panic!("{what}: {err}"));
        }
        e.apply(Edit::SelectTime(0.4 * e.scene().duration))
            .unwrap_or_else(|err| panic!("{what}: {err}"));
        e.apply(Edit::Nudge {
            quantity: StateQuantity::Velocity,
            delta: nudge::math::Vec3::new(0.01, 0.0, 0.02),
        })
        .unwrap_or_else(|err| panic!("{what}: {err}"));
        e.apply(Edit::Nail {
            quantities: vec![StateQuantity::Position],
            exact: vec![],
        })
        .unwrap_or_else(|err| panic!("{what}: {err}"));
        let has_events = !e.trajectory().events.is_empty();
        let added = e.apply(Edit::AddEventControls {
            normal: true,
            restitution: true,
        });
        assert_eq!(added.is_ok(), has_events, "{what}: {added:?}");
        e.apply(Edit::SetScale {
            kind: nudge::scene::ScaleKind::Velocity,
            value: 2.0,
        })
        .unwrap_or_else(|err| panic!("{what}: {err}"));

        let file = dir.join(path.file_name().expect("file name"));
        let note = e
            .save(Some(&file), WriteMode::Normal)
            .unwrap_or_else(|err| panic!("{what}: {err}"));
        assert_eq!(note.layout_lost, None, "{what}: the text is kept");
        let saved = std::fs::read_to_string(&file).expect("saved");
        assert_comments_kept(&original, &saved, &what);
        let (old, new): (Vec<&str>, Vec<&str>) =
            (original.lines().collect(), saved.lines().collect());
        let edited = [
            "velocity",
            "position",
            "orientation",
            "angular_velocity",
            "free",
        ];
        for (line, kept) in old.iter().zip(kept_lines(&old, &new)) {
            let key = line.split(" = ").next().unwrap_or("");
            assert!(
                kept || edited.contains(&key),
                "{what}: line {line:?} changed, though the edit does not touch it:\n{saved}"
            );
        }
        assert!(
            saved.contains("\n[[constraint]]\nkind = \"nail\""),
            "{what}:\n{saved}"
        );
        assert_eq!(
            saved.contains("\n[[event_control]]\n"),
            has_events,
            "{what}"
        );

        let back = load(&file).unwrap_or_else(|err| panic!("{what}: {err}\n{saved}"));
        assert_same(&e.scene_to_save(), &back, &what);

        e.save(Some(&file), WriteMode::Normal)
            .unwrap_or_else(|err| panic!("{what}: {err}"));
        let twice = std::fs::read_to_string(&file).expect("saved");
        assert_eq!(twice, saved, "{what}: saving again changed the file");
        assert_eq!(
            saved_text(&back, &file),
            saved,
            "{what}: the saved file, opened and saved, changed"
        );
    }
}

/// A comment on the line of a value the edit changes stays on that line,
/// and the comment above it stays above it.
#[test]
fn a_field_comment_next_to_a_changed_value_survives() {
    let text = "\
# A ball.
duration = 1.0
effects = [\"gravity\"]

[[body]]
name = \"ball\"
shape = { type = \"sphere\", radius = 0.1 }
density = 1000.0
# Thrown up-range.
velocity = [1, 0, 2]   # m/s, towards the hill
free = [\"velocity\"]  # only the throw
";
    let path = Path::new("ball.toml");
    let mut scene = load_str(text, "ball.toml").unwrap_or_else(|e| panic!("{e}"));
    scene.bodies[0].velocity.x = 1.0 / 3.0;
    let saved = saved_text(&scene, path);
    assert_eq!(
        saved,
        text.replace(
            "velocity = [1, 0, 2]   # m/s",
            "velocity = [0.3333333333333333, 0, 2]   # m/s"
        ),
        "only the changed number is rewritten"
    );
    let back = load_str(&saved, "ball.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        back.bodies[0].velocity.x.to_bits(),
        (1.0f64 / 3.0).to_bits()
    );
}

#[test]
fn saved_text_is_readable() {
    let scene = load(Path::new("scenes/eggs.toml")).unwrap_or_else(|e| panic!("{e}"));
    let text = to_toml(&scene);
    if std::env::var_os("NUDGE_SHOW_SAVED").is_some() {
        println!("{text}");
    }
    assert!(text.contains("\n[[body]]\nname = \"egg1\"\nshape = { type = \"egg\", radii = [0.05, 0.05, 0.07], bottom = 1.3 }\n"), "{text}");
    assert!(
        !text.contains("inertia"),
        "inertia that follows from shape and mass is not written:\n{text}"
    );
    assert!(
        text.contains("trace = [[0.0, 0.0, 0.07], [0.0, 0.0, -0.091]]"),
        "traced points come back in the shape frame:\n{text}"
    );
}

#[test]
fn save_is_atomic_and_loads_back() {
    let tmp = tempfile::Builder::new()
        .prefix("nudge-save-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("mug.toml");
    let scene = load(Path::new("scenes/mug.toml")).unwrap_or_else(|e| panic!("{e}"));
    save(&scene, &path, WriteMode::Normal).expect("saved");
    save(&scene, &path, WriteMode::Normal).expect("saved over");
    let names: Vec<_> = std::fs::read_dir(&dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(
        names,
        vec![std::ffi::OsString::from("mug.toml")],
        "no temporary file is left behind"
    );
    let again = load(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_same(&scene, &again, "saved mug");
}

/// A scene whose bodies are an inline array, with a comment.
const INLINE_BODIES: &str = "# A comment the new text cannot keep.\nduration = 1.0\neffects = [\"gravity\"]\n\
     body = [{ name = \"ball\", shape = { type = \"sphere\", radius = 0.1 }, mass = 1.0, free = [\"velocity\"] }]\n";

/// A layout the editor does not edit in place (bodies as an inline array)
/// is saved as new text: every number is kept, and the user is told that
/// the comments were not, in the report of the save and on the status line.
#[test]
fn a_layout_not_edited_in_place_is_saved_as_new_text_and_the_user_is_told() {
    use nudge::edit::{Core, Edit, Editor};
    use nudge::scene::StateQuantity;
    let tmp = tempfile::Builder::new()
        .prefix("nudge-inline-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("inline.toml");
    std::fs::write(&path, INLINE_BODIES).expect("written");
    let mut e = Editor::open(&path).unwrap_or_else(|err| panic!("{err}"));
    e.apply(Edit::Nudge {
        quantity: StateQuantity::Velocity,
        delta: nudge::math::Vec3::new(0.5, 0.0, 0.0),
    })
    .unwrap_or_else(|err| panic!("{err}"));
    let saved = e
        .save(None, WriteMode::Normal)
        .unwrap_or_else(|err| panic!("{err}"));
    let why = saved
        .layout_lost
        .expect("the inline bodies are not edited in place");
    assert!(why.contains("not edited in place"), "{why}");
    let back = load(&path).unwrap_or_else(|err| panic!("{err}"));
    assert_same(&e.scene_to_save(), &back, "inline scene saved as new text");

    // Through the runner: the status line says so.
    std::fs::write(&path, INLINE_BODIES).expect("written");
    let keys = dir.join("save.keys");
    std::fs::write(&keys, "V l :w<CR>\n").expect("written");
    let screen = dir.join("screen.txt");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_nudge"))
        .args(["run", "--size", "120x30"])
        .arg(&path)
        .arg("--keys")
        .arg(&keys)
        .arg("--screen")
        .arg(&screen)
        .output()
        .expect("runs nudge");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&screen).expect("screen");
    assert!(
        text.contains("as new text, without its comments"),
        "the status line warns:\n{text}"
    );
}

/// The size is checked before reading: the file here is sparse and full of
/// NUL bytes, which would be a different error if it were read.
#[test]
fn an_oversized_file_is_refused_by_its_size() {
    let tmp = tempfile::Builder::new()
        .prefix("nudge-large-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("huge.toml");
    let file = std::fs::File::create(&path).expect("created");
    file.set_len(16 * 1024 * 1024 + 1).expect("sized");
    drop(file);
    let got = message(load(&path)).expect("refused");
    let expected = format!(
        "{}: the scene file is too large: 16777217 bytes; scene files may be at most 16 MiB (16777216 bytes): check that this is the scene you meant",
        path.display()
    );
    assert_eq!(got, expected);
}

#[test]
fn a_missing_file_names_the_path() {
    let got =
        message(load(Path::new("tests/invalid_scenes/does-not-exist.toml"))).expect("refused");
    assert!(
        got.starts_with("tests/invalid_scenes/does-not-exist.toml: cannot read the scene file: "),
        "{got}"
    );
}

/// No input may panic the loader: truncations of every shipped scene.
#[test]
fn truncated_scenes_fail_cleanly() {
    for path in toml_files("scenes") {
        let text = std::fs::read_to_string(&path).expect("readable");
        let mut cut = text.len();
        while cut > 0 {
            cut = cut * 7 / 8;
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            let _ = load_str(&text[..cut], "cut.toml");
        }
    }
}
