//! `shape = { type = "mesh", file = "...", scale = 1.0, decomposition =
//! "hull" }`: a closed triangle mesh from an OBJ (tobj) or STL (stl_io)
//! file, resolved against the scene file's folder. Every problem is an
//! error at the `file` (or `scale`, `decomposition`) value, naming the
//! mesh file's line (OBJ) or facet (STL) where there is one.

use super::SceneError;
use super::source::{Bound, Table};
use crate::geometry::{Decomposition, Geometry, MeshError};
use crate::math::Vec3;
use std::path::{Path, PathBuf};

/// Most triangles a mesh may have: a hull's event search visits its
/// vertices at every step, and a decomposition voxelises every triangle.
pub const MAX_TRIANGLES: usize = 20_000;

/// Largest mesh file read, bytes (as for scene files).
const MAX_BYTES: u64 = 16 * 1024 * 1024;

const FILE_HINT: &str = "give the path of an .obj or .stl file, relative to the scene file's folder, e.g. file = \"meshes/hat.obj\"";

/// The mesh file's path: relative ones from the folder of the scene file
/// `origin` (the working directory for a scene that has no file).
fn resolve(origin: &str, file: &str) -> PathBuf {
    let file = Path::new(file);
    if file.is_absolute() || origin.starts_with('<') {
        return file.to_path_buf();
    }
    Path::new(origin)
        .parent()
        .map_or_else(|| file.to_path_buf(), |dir| dir.join(file))
}

/// Vertices and triangles of an OBJ file's every object, after checking
/// its vertex lines (which tobj reads without saying where it failed).
fn obj(
    t: &Table<'_, '_>,
    file: &str,
    bytes: &[u8],
) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), SceneError> {
    let text = String::from_utf8_lossy(bytes);
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if words.next() != Some("v") {
            continue;
        }
        let numbers: Vec<Option<f64>> = words.take(3).map(|w| w.parse().ok()).collect();
        let line_no = n + 1;
        if numbers.len() < 3 || numbers.iter().any(Option::is_none) {
            return Err(t.bad(
                "file",
                &format!("has a vertex that is not three numbers ({file} line {line_no})"),
                "write each vertex as v x y z",
            ));
        }
        if numbers.iter().flatten().any(|x| !x.is_finite()) {
            return Err(t.bad(
                "file",
                &format!("has a coordinate that is not a finite number ({file} line {line_no})"),
                "give every vertex finite coordinates",
            ));
        }
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _materials) =
        tobj::load_obj_buf(&mut std::io::Cursor::new(bytes), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| t.bad("file", &format!("could not be read as OBJ: {e}"), FILE_HINT))?;
    let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
    for m in models {
        let base = vertices.len() as u32;
        vertices.extend(
            m.mesh
                .positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        triangles.extend(
            m.mesh
                .indices
                .chunks_exact(3)
                .map(|i| [i[0] + base, i[1] + base, i[2] + base]),
        );
    }
    Ok((vertices, triangles))
}

/// Vertices and triangles of an STL file (binary or ASCII).
fn stl(
    t: &Table<'_, '_>,
    file: &str,
    bytes: &[u8],
) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), SceneError> {
    let mesh = stl_io::read_stl(&mut std::io::Cursor::new(bytes))
        .map_err(|e| t.bad("file", &format!("could not be read as STL: {e}"), FILE_HINT))?;
    let vertices: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::new(v[0].into(), v[1].into(), v[2].into()))
        .collect();
    let mut triangles = Vec::with_capacity(mesh.faces.len());
    for (k, f) in mesh.faces.iter().enumerate() {
        if f.vertices
            .iter()
            .any(|&i| !vertices[i].iter().all(|c| c.is_finite()))
        {
            return Err(t.bad(
                "file",
                &format!(
                    "has a coordinate that is not a finite number ({file} facet {})",
                    k + 1
                ),
                "give every vertex finite coordinates",
            ));
        }
        triangles.push(f.vertices.map(|i| i as u32));
    }
    Ok((vertices, triangles))
}

/// Build the shape of the `mesh` table `t`.
pub(super) fn build(t: &Table<'_, '_>) -> Result<Geometry, SceneError> {
    t.allow_only(&["type", "file", "scale", "decomposition"])?;
    let file = t
        .string("file", FILE_HINT)?
        .ok_or_else(|| t.missing("file", FILE_HINT))?;
    let scale = t.number_or(
        "scale",
        1.0,
        Bound::Positive,
        "give the factor from the file's units to m, e.g. scale = 0.01 for a file in cm",
    )?;
    let decomposition_hint = "give decomposition = \"hull\" (the convex hull, the default) or \"convex\" (convex pieces that follow hollows)";
    let decomposition = match t.string("decomposition", decomposition_hint)? {
        None | Some("hull") => Decomposition::Hull,
        Some("convex") => Decomposition::Convex,
        Some(_) => return Err(t.bad("decomposition", "is not hull or convex", decomposition_hint)),
    };
    let path = resolve(t.src.origin, file);
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    type Reader = fn(&Table<'_, '_>, &str, &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), SceneError>;
    let read: Reader = match extension.as_deref() {
        Some("obj") => obj,
        Some("stl") => stl,
        _ => return Err(t.bad("file", "is not an .obj or .stl file", FILE_HINT)),
    };
    let bytes = crate::files::read_regular(&path, MAX_BYTES).map_err(|e| {
        t.bad(
            "file",
            &format!("cannot be read ({}: {e})", path.display()),
            FILE_HINT,
        )
    })?;
    if bytes.len() as u64 > MAX_BYTES {
        return Err(t.bad("file", "is larger than 16 MiB", "simplify the mesh"));
    }
    let (vertices, triangles) = read(t, file, &bytes)?;
    if triangles.len() > MAX_TRIANGLES {
        return Err(t.bad(
            "file",
            &format!(
                "has {} triangles, more than {MAX_TRIANGLES}",
                triangles.len()
            ),
            &format!("simplify (decimate) the mesh to at most {MAX_TRIANGLES} triangles"),
        ));
    }
    let scaled: Vec<Vec3> = vertices.iter().map(|v| v * scale).collect();
    if scaled.iter().any(|v| !v.iter().all(|c| c.is_finite())) {
        return Err(t.bad(
            "scale",
            "makes a vertex beyond the finite numbers",
            "give a smaller scale",
        ));
    }
    Geometry::from_mesh(&scaled, &triangles, decomposition).map_err(|e| {
        let fix = match e {
            MeshError::NoTriangles => "export the mesh with its faces (f lines in OBJ, facets in STL)",
            MeshError::NotClosed { .. } => "close the mesh's holes and face its triangles one way: its solid gives the body's mass",
            MeshError::Flat => "give a mesh of a solid with a thickness",
            MeshError::Overflow => "give a smaller scale",
            MeshError::NoPieces | MeshError::TooManyPieces { .. } => {
                "use decomposition = \"hull\", or a simpler mesh"
            }
            MeshError::NonFinite { .. } | MeshError::BadIndex { .. } => "export the mesh again",
        };
        t.bad("file", &e.to_string(), fix)
    })
}

/// The mesh files a scene's shapes name, as written (relative ones are
/// relative to the scene file's folder).
pub fn mesh_files(scene: &crate::scene::Scene) -> Vec<String> {
    fn walk(v: &toml::Value, out: &mut Vec<String>) {
        match v {
            toml::Value::Table(t) => {
                if t.get("type").and_then(toml::Value::as_str) == Some("mesh")
                    && let Some(f) = t.get("file").and_then(toml::Value::as_str)
                {
                    out.push(f.to_string());
                }
                t.values().for_each(|x| walk(x, out));
            }
            toml::Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    for b in &scene.bodies {
        walk(&b.shape_source, &mut out);
    }
    for o in &scene.obstacles {
        walk(&o.shape_source, &mut out);
    }
    out.sort();
    out.dedup();
    out
}
