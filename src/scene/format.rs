//! The TOML scene format: parsing, validation with located messages, and
//! saving. The format is documented in `docs/scene-format.md`.
//!
//! Loading reads the document with spans ([`toml::de::DeTable`]) and walks it
//! by hand, so every error names `origin:line:column`, the field (`body
//! "egg1" field mass`), the value as written and the fix:
//!
//! ```text
//! scenes/eggs.toml:12:8: body "egg1" field mass must be greater than 0: -0.2; give the mass in kg, ...
//! ```
//!
//! Saving ([`save`], [`saved_text`]) writes text that loads back to the
//! same [`Scene`] bit for bit in every number. A scene loaded from text is
//! saved by editing that text in place, keeping the user's comments and
//! layout; a scene built in code is printed afresh ([`to_toml`]). What is
//! saved is decided once, for both.
mod body;
mod constraint;
mod in_place;
mod inertia;
mod mesh;

pub use mesh::mesh_files;
mod read;
mod saved;
mod shape;
mod source;
mod write;

use super::model::Scene;
use crate::files::{WriteError, WriteMode};
use source::Source;
use std::path::Path;
use toml::de::DeTable;

/// The built-in scene (two eggs, two buckets), used when no file is given.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/eggs.toml");

/// Largest scene file accepted, bytes (16 MiB). Checked before reading.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// A scene that could not be loaded. The message is complete and
/// user-facing: `origin:line:col: what is wrong: value; how to fix it`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("{0}")]
    Invalid(String),
}

fn too_large(origin: &str, bytes: u64) -> SceneError {
    SceneError::Invalid(format!(
        "{origin}: the scene file is too large: {bytes} bytes; scene files may be at most 16 MiB ({MAX_FILE_BYTES} bytes): check that this is the scene you meant"
    ))
}

/// Load and validate a scene file. The file's size is checked before it is
/// read; messages name the file by `path` as given.
///
/// # Errors
/// [`SceneError::Invalid`] with a located, user-facing message when the file
/// cannot be read, is larger than [`MAX_FILE_BYTES`], is not UTF-8, or is not
/// a valid scene (see [`load_str`]).
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let origin = path.display().to_string();
    let io = |e: std::io::Error| {
        SceneError::Invalid(format!(
            "{origin}: cannot read the scene file: {e}; check the path and permissions"
        ))
    };
    let size = std::fs::metadata(path).map_err(io)?.len();
    if size > MAX_FILE_BYTES {
        return Err(too_large(&origin, size));
    }
    // Only a regular file is opened: a FIFO would block `open` forever.
    let bytes = crate::files::read_regular(path, MAX_FILE_BYTES).map_err(io)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(&origin, bytes.len() as u64));
    }
    let text = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let good = e.utf8_error().valid_up_to();
            let bytes = e.as_bytes();
            let prefix = String::from_utf8_lossy(&bytes[..good]);
            let src = Source {
                text: &prefix,
                origin: &origin,
            };
            let bad = bytes.get(good).copied().unwrap_or(0);
            return Err(src.error(
                &(good..good),
                "the scene file is not UTF-8 text",
                &format!("byte 0x{bad:02x}"),
                "save the file as UTF-8",
            ));
        }
    };
    load_str(&text, &origin)
}

/// Parse and validate scene text; `origin` names the file in messages and
/// gives the default scene name (its file stem).
///
/// # Errors
/// [`SceneError::Invalid`] for the first problem found, as
/// `origin:line:col: what is wrong: value; how to fix it`: TOML syntax,
/// unknown keys, wrong types, out-of-range or non-finite numbers, unknown
/// names, and bodies that overlap at t = 0.
pub fn load_str(text: &str, origin: &str) -> Result<Scene, SceneError> {
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(too_large(origin, text.len() as u64));
    }
    let src = Source { text, origin };
    let doc = DeTable::parse(text).map_err(|e| syntax_error(&src, &e))?;
    read::scene(&src, &doc)
}

/// A TOML syntax error, located, quoting the offending text when toml
/// points at some.
fn syntax_error(src: &Source<'_>, e: &toml::de::Error) -> SceneError {
    let span = e.span().unwrap_or(0..0);
    let fix = if e.message() == "duplicate key" {
        "a key may appear only once in a table: remove or rename one of them"
    } else {
        "fix the syntax at this line and column (see https://toml.io)"
    };
    let quote = src.quote(&span);
    if quote.is_empty() {
        src.error(&span, "TOML syntax error", e.message(), fix)
    } else {
        src.error(
            &span,
            &format!("TOML syntax error: {}", e.message()),
            &quote,
            fix,
        )
    }
}

/// The scene as new TOML text, in the format's own layout, that loads back
/// to the same scene bit for bit. Comments of the text it was loaded from
/// are not kept (`notes` is): [`saved_text`] keeps them.
#[must_use]
pub fn to_toml(scene: &Scene) -> String {
    write::to_toml(scene)
}

/// The text [`save`] writes for `scene` at `path` (before [`save`] gives
/// it the file's byte-order mark and line endings). For a scene loaded from
/// text ([`Scene::source_text`]), that text with only what changed edited
/// in place: every comment, blank line, key order and untouched value stays
/// as written. Otherwise, or if that text cannot be edited in place, new
/// text ([`to_toml`]). Either loads back from `path` to the same scene bit
/// for bit.
#[must_use]
pub fn saved_text(scene: &Scene, path: &Path) -> String {
    saved_text_noting(scene, path).0
}

/// [`saved_text`], and why the source text could not be kept when the
/// scene had one but it is written as new text (comments and layout lost).
fn saved_text_noting(scene: &Scene, path: &Path) -> (String, Option<String>) {
    match scene.source_text.as_deref() {
        None => (to_toml(scene), None),
        Some(text) => match in_place::edit(text, scene, &path.display().to_string()) {
            Ok(kept) => (kept, None),
            Err(why) => (to_toml(scene), Some(why.to_string())),
        },
    }
}

/// Write a scene ([`saved_text`]) with [`crate::files::write_text`]:
/// atomically, through symlinks, keeping the file's permissions, hard
/// links, byte-order mark and line endings; a read-only file only with
/// [`WriteMode::Force`]. A new file takes the byte-order mark and line
/// endings of the text the scene was loaded from (an existing one keeps
/// its own), so `:w other.toml` writes the scene as its file is written,
/// edited or not. Returns why the text the scene was loaded from
/// could not be kept, when it was written as new text instead (its
/// comments and layout are then gone; the numbers are all there).
///
/// # Errors
/// As [`crate::files::write_text`]; `path` is then left as it was.
pub fn save(scene: &Scene, path: &Path, mode: WriteMode) -> Result<Option<String>, WriteError> {
    let (text, unkept) = saved_text_noting(scene, path);
    let text = match scene.source_text.as_deref() {
        Some(source) => crate::files::TextStyle::of(source.as_bytes()).apply(&text),
        None => text,
    };
    crate::files::write_text(path, &text, mode).map(|()| unkept)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Mat3, Vec3};

    fn err(text: &str) -> String {
        match load_str(text, "t.toml") {
            Ok(_) => panic!("expected an error for:\n{text}"),
            Err(SceneError::Invalid(m)) => m,
        }
    }

    const HEAD: &str = "duration = 1.0\neffects = []\n";

    #[test]
    fn box_inertia_from_the_shape_matches_the_closed_form() {
        let s = load_str(&format!("{HEAD}[[body]]\nname = \"b\"\nshape = {{ type = \"box\", half_extents = [0.3, 0.2, 0.1] }}\ndensity = 500.0\n"), "t")
            .unwrap();
        let b = &s.bodies[0];
        let (x, y, z) = (0.6, 0.4, 0.2);
        let m = 500.0 * x * y * z;
        assert!((b.mass - m).abs() < 1e-12 * m);
        let closed = Vec3::new(
            m / 12.0 * (y * y + z * z),
            m / 12.0 * (x * x + z * z),
            m / 12.0 * (x * x + y * y),
        );
        assert!(
            (b.inertia - closed).norm() < 1e-12 * m,
            "{:?} vs {closed:?}",
            b.inertia
        );
        assert!(b.inertia_axes.angle() < 1e-15);
        assert!(!b.inertia_given);
        assert!(b.com_offset.norm() < 1e-15);
    }

    #[test]
    fn a_rotated_box_gets_sorted_moments_and_proper_axes() {
        // A box tilted inside a compound: the axes must come out rotated,
        // proper (det +1), and reproduce the shape's tensor.
        let s = load_str(
            &format!(
                "{HEAD}[[body]]\nname = \"b\"\nmass = 2.0\nshape = {{ type = \"compound\", parts = [{{ shape = {{ type = \"box\", half_extents = [0.1, 0.2, 0.3] }}, orientation = [0.3, -0.2, 0.5] }}] }}\n"
            ),
            "t",
        )
        .unwrap();
        let b = &s.bodies[0];
        assert!(b.inertia.x <= b.inertia.y && b.inertia.y <= b.inertia.z);
        let q = b.inertia_axes.to_rotation_matrix();
        assert!((q.matrix().determinant() - 1.0).abs() < 1e-12);
        let tensor = b.geometry.mass_properties(1.0).unwrap().inertia
            * (b.mass / b.geometry.mass_properties(1.0).unwrap().mass);
        assert!((b.inertia_tensor() - tensor).norm() < 1e-12 * tensor.norm());
        let m = 2.0;
        let expect = Vec3::new(
            m / 3.0 * (0.04 + 0.09),
            m / 3.0 * (0.01 + 0.09),
            m / 3.0 * (0.01 + 0.04),
        );
        let mut sorted = [expect.x, expect.y, expect.z];
        sorted.sort_by(f64::total_cmp);
        assert!((b.inertia - Vec3::from(sorted)).norm() < 1e-12);
    }

    #[test]
    fn a_given_mass_scales_the_unit_density_inertia() {
        let shape = "shape = { type = \"sphere\", radius = 0.5 }";
        let by_mass = load_str(
            &format!("{HEAD}[[body]]\nname = \"s\"\n{shape}\nmass = 3.0\n"),
            "t",
        )
        .unwrap();
        let b = &by_mass.bodies[0];
        assert_eq!(b.mass, 3.0);
        let closed = 0.4 * 3.0 * 0.25;
        assert!(
            (b.inertia - Vec3::repeat(closed)).norm() < 1e-12,
            "{:?}",
            b.inertia
        );
        assert_eq!(b.inertia_axes, nalgebra::UnitQuaternion::identity());
        // The same body by density has bit-identical inertia when its mass
        // is written back (what lets the writer omit the inertia).
        let by_density = load_str(
            &format!("{HEAD}[[body]]\nname = \"s\"\n{shape}\ndensity = 7.0\n"),
            "t",
        )
        .unwrap();
        let d = &by_density.bodies[0];
        let again = load_str(
            &format!(
                "{HEAD}[[body]]\nname = \"s\"\n{shape}\nmass = {:?}\n",
                d.mass
            ),
            "t",
        )
        .unwrap();
        assert_eq!(
            again.bodies[0].inertia.map(f64::to_bits),
            d.inertia.map(f64::to_bits)
        );
    }

    #[test]
    fn explicit_inertia_must_satisfy_the_triangle_inequality() {
        let body = |i: &str| {
            format!(
                "{HEAD}[[body]]\nname = \"b\"\nshape = {{ type = \"sphere\", radius = 0.1 }}\nmass = 1.0\ninertia = {i}\n"
            )
        };
        assert!(
            load_str(&body("[1.0, 1.0, 2.0]"), "t").is_ok(),
            "equality is a flat plate"
        );
        assert!(load_str(&body("[1.0, 2.0, 1.5]"), "t").is_ok());
        let m = err(&body("[1.0, 1.0, 2.5]"));
        assert!(
            m.starts_with("t.toml:7:11: body \"b\" field inertia violates the triangle inequality"),
            "{m}"
        );
        let m = err(&body("[3.0, 1.0, 1.0]"));
        assert!(
            m.contains("the other two): [3.0, 1.0, 1.0]; no rigid body"),
            "{m}"
        );
        assert!(inertia::triangle_ok(&Vec3::new(
            1.0,
            1.0,
            2.0 * (1.0 + 1e-14)
        )));
    }

    fn nested(levels: usize) -> String {
        let mut shape = "{ type = \"sphere\", radius = 0.1 }".to_string();
        for _ in 0..levels {
            shape = format!("{{ type = \"compound\", parts = [{{ shape = {shape} }}] }}");
        }
        format!("{HEAD}[[body]]\nname = \"n\"\nmass = 1.0\nshape = {shape}\n")
    }

    #[test]
    fn compounds_nest_at_most_eight_deep() {
        assert!(load_str(&nested(8), "t").is_ok());
        let m = err(&nested(9));
        let path = "shape.parts[0]".to_string() + &".shape.parts[0]".repeat(7) + ".shape.type";
        assert!(m.contains(&format!("body \"n\" field {path} is a compound nested 9 deep: \"compound\"; compounds may nest at most 8 deep")), "{m}");
        let deeper = err(&nested(20));
        assert!(deeper.contains("nested 9 deep"), "{deeper}");
        // Input deeper than the TOML parser's own limit is refused by it.
        let deepest = err(&nested(200));
        assert!(
            deepest.contains("TOML syntax error: cannot recurse further"),
            "{deepest}"
        );
    }

    #[test]
    fn principal_axes_of_a_diagonal_tensor_are_a_signed_permutation() {
        let (m, q) = inertia::principal(&Mat3::from_diagonal(&Vec3::new(3.0, 1.0, 2.0)));
        assert_eq!(m, Vec3::new(1.0, 2.0, 3.0));
        let r = q.to_rotation_matrix();
        let t = r.matrix() * Mat3::from_diagonal(&m) * r.matrix().transpose();
        assert!((t - Mat3::from_diagonal(&Vec3::new(3.0, 1.0, 2.0))).norm() < 1e-14);
    }

    #[test]
    fn exp_map_vectors_are_recovered_exactly() {
        use crate::math::{Rng, exp_so3};
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let mut next = || rng.range(-1.0, 1.0);
        for _ in 0..2000 {
            let r = Vec3::new(next(), next(), next()) * 1.8;
            let q = exp_so3(&r);
            let back = saved::exp_map_of(&q);
            assert_eq!(
                exp_so3(&back).coords.map(f64::to_bits),
                q.coords.map(f64::to_bits),
                "{r:?}"
            );
        }
    }

    #[test]
    fn floats_are_written_in_round_trip_form() {
        for x in [0.1, 1e-9, 1e20, -0.0, 1.0 / 3.0, 5e-324, f64::MAX] {
            let text = write::float(x);
            let back: f64 = toml::from_str::<toml::Table>(&format!("x = {text}")).unwrap()["x"]
                .as_float()
                .unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{text}");
        }
    }

    #[test]
    fn syntax_errors_are_located() {
        assert_eq!(
            err("duration = \"x\nb = 3\n"),
            "t.toml:1:14: TOML syntax error: invalid basic string, expected `\"`; fix the syntax at this line and column (see https://toml.io)"
        );
    }

    /// Extreme but finite numbers anywhere must give an error or a scene, never a panic or a hang.
    #[test]
    fn extreme_numbers_never_panic() {
        let values = [
            "1e300",
            "-1e300",
            "1e-300",
            "5e-324",
            "1.7976931348623157e308",
            "0.0",
            "-0.0",
            "1e19",
            "123456789.0",
        ];
        let templates = [
            "duration = 1.0\neffects = [\"collisions\"]\n[[body]]\nname = \"b\"\nshape = { type = \"sphere\", radius = X }\ndensity = 1.0\n",
            "duration = 1.0\neffects = [\"collisions\"]\n[[body]]\nname = \"b\"\nshape = { type = \"box\", half_extents = [X, 1.0, 1.0] }\nmass = X\n",
            "duration = 1.0\neffects = [\"collisions\"]\n[[body]]\nname = \"b\"\nshape = { type = \"sphere\", radius = 0.1 }\nmass = 1.0\nposition = [X, X, X]\norientation = [X, 0.0, X]\n[[obstacle]]\nname = \"o\"\nshape = { type = \"plane\", normal = [X, 0.0, 1.0] }\norientation = [X, X, X]\n",
            "duration = 1.0\neffects = [\"collisions\"]\n[[body]]\nname = \"b\"\nshape = { type = \"hull\", points = [[0.0, 0.0, 0.0], [X, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] }\ndensity = 1.0\n[[obstacle]]\nname = \"o\"\nshape = { type = \"parabola\", curvature = X, half_width = 1.0 }\nposition = [0.0, 0.0, -X]\n",
            "duration = 1.0\neffects = []\n[[body]]\nname = \"b\"\nshape = { type = \"egg\", radii = [X, 1.0, X], bottom = X, resolution = 64 }\nmass = 1.0\ninertia = [X, X, X]\ninertia_axes = [X, X, 1.0]\n",
            "duration = 1.0\neffects = []\n[[body]]\nname = \"b\"\nshape = { type = \"compound\", parts = [{ shape = { type = \"sphere\", radius = 1.0 }, position = [X, 0.0, 0.0], orientation = [X, X, X] }] }\ndensity = X\n",
        ];
        for t in templates {
            for v in values {
                let text = t.replace('X', v);
                if let Ok(s) = load_str(&text, "x.toml") {
                    for b in &s.bodies {
                        let numbers = [b.mass]
                            .into_iter()
                            .chain(b.inertia.iter().copied())
                            .chain(b.inertia_axes.coords.iter().copied())
                            .chain(b.com_offset.iter().copied())
                            .chain(b.orientation.iter().copied());
                        assert!(numbers.into_iter().all(f64::is_finite), "{text}\n{b:?}");
                        assert!(
                            b.orientation.norm() <= std::f64::consts::PI + 1e-12,
                            "{text}"
                        );
                    }
                    for o in &s.obstacles {
                        assert!(
                            o.pose.rotation.coords.iter().all(|x| x.is_finite()),
                            "{text}"
                        );
                    }
                }
            }
        }
    }
}
