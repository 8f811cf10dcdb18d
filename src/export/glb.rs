//! Writing the binary glTF: the JSON document (nodes, meshes, the
//! animation) with `gltf-json`, its data in one buffer, both in the glb
//! container (a 12-byte header, a JSON chunk, a BIN chunk).

use super::keys::Track;
use super::mesh::Mesh;
use super::{ExportError, rotation_to_y_up, single, to_y_up};
use crate::scene::Scene;
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use serde_json::Value;

/// The document and its binary buffer as it grows.
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    /// Append `bytes` as a buffer view (4-byte aligned).
    fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// An accessor of `f32` elements of `width` numbers, with bounds when given.
    fn floats(
        &mut self,
        values: &[f32],
        type_: json::accessor::Type,
        width: usize,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        self.accessor(
            view,
            values.len() / width,
            json::accessor::ComponentType::F32,
            type_,
            bounds,
        )
    }

    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let (min, max) = match bounds {
            Some((lo, hi)) => (Some(Value::from(lo)), Some(Value::from(hi))),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
            extensions: None,
            extras: Default::default(),
        })
    }

    /// A mesh of one triangle primitive; `None` when it has no triangles.
    fn mesh(&mut self, name: &str, mesh: &Mesh) -> Option<json::Index<json::Mesh>> {
        if mesh.indices.is_empty() {
            return None;
        }
        let flat: Vec<f32> = mesh.positions.iter().flatten().copied().collect();
        let (lo, hi) = mesh.bounds();
        let positions = self.floats(
            &flat,
            json::accessor::Type::Vec3,
            3,
            Some((lo.to_vec(), hi.to_vec())),
            Some(json::buffer::Target::ArrayBuffer),
        );
        let bytes: Vec<u8> = mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(json::buffer::Target::ElementArrayBuffer));
        let indices = self.accessor(
            view,
            mesh.indices.len(),
            json::accessor::ComponentType::U32,
            json::accessor::Type::Scalar,
            None,
        );
        let primitive = json::mesh::Primitive {
            attributes: [(Valid(json::mesh::Semantic::Positions), positions)]
                .into_iter()
                .collect(),
            indices: Some(indices),
            material: None,
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
            extensions: None,
            extras: Default::default(),
        };
        Some(self.root.push(json::Mesh {
            name: Some(name.to_string()),
            primitives: vec![primitive],
            weights: None,
            extensions: None,
            extras: Default::default(),
        }))
    }
}

/// A node at a pose (y-up, `f32`).
fn node(
    name: &str,
    mesh: Option<json::Index<json::Mesh>>,
    translation: [f32; 3],
    rotation: [f32; 4],
) -> json::Node {
    json::Node {
        name: Some(name.to_string()),
        mesh,
        translation: Some(translation),
        rotation: Some(json::scene::UnitQuaternion(rotation)),
        ..Default::default()
    }
}

/// A pose turned y-up and rounded to `f32`: translation and `[x, y, z, w]`.
fn pose(
    x: &crate::math::Vec3,
    q: &nalgebra::UnitQuaternion<f64>,
    what: &dyn Fn() -> String,
) -> Result<([f32; 3], [f32; 4]), ExportError> {
    let (p, r) = (to_y_up(x), rotation_to_y_up(q));
    let f = |v: f64| single(v, what);
    Ok((
        [f(p.x)?, f(p.y)?, f(p.z)?],
        [f(r.i)?, f(r.j)?, f(r.k)?, f(r.w)?],
    ))
}

/// The whole file: nodes for the bodies (in scene order, then the
/// obstacles), their meshes, and one animation named after the scene.
///
/// # Errors
/// A pose or time beyond `f32`'s range.
pub fn write(
    scene: &Scene,
    bodies: &[Mesh],
    obstacles: &[Mesh],
    tracks: &[Track],
) -> Result<Vec<u8>, ExportError> {
    let mut b = Builder {
        root: json::Root::default(),
        bin: Vec::new(),
    };
    b.root.asset.generator = Some(format!("nudge {}", env!("CARGO_PKG_VERSION")));
    let mut nodes = Vec::new();
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    for ((body, mesh), track) in scene.bodies.iter().zip(bodies).zip(tracks) {
        let what = || format!("body \"{}\": a pose", body.name);
        let mut translations = Vec::with_capacity(3 * track.times.len());
        let mut rotations = Vec::with_capacity(4 * track.times.len());
        for (x, q) in track.positions.iter().zip(&track.rotations) {
            let (t, r) = pose(x, q, &what)?;
            translations.extend(t);
            rotations.extend(r);
        }
        let mesh = b.mesh(&body.name, mesh);
        let first = |v: &[f32], n: usize| v.get(..n).map(|s| s.to_vec());
        let (t0, r0) = match (first(&translations, 3), first(&rotations, 4)) {
            (Some(t), Some(r)) => ([t[0], t[1], t[2]], [r[0], r[1], r[2], r[3]]),
            _ => ([0.0; 3], [0.0, 0.0, 0.0, 1.0]),
        };
        let index = b.root.push(node(&body.name, mesh, t0, r0));
        nodes.push(index);
        let (Some(&lo), Some(&hi)) = (track.times.first(), track.times.last()) else {
            continue;
        };
        let input = b.floats(
            &track.times,
            json::accessor::Type::Scalar,
            1,
            Some((vec![lo], vec![hi])),
            None,
        );
        for (values, type_, width, path) in [
            (
                &translations,
                json::accessor::Type::Vec3,
                3,
                json::animation::Property::Translation,
            ),
            (
                &rotations,
                json::accessor::Type::Vec4,
                4,
                json::animation::Property::Rotation,
            ),
        ] {
            let output = b.floats(values, type_, width, None, None);
            let sampler = json::Index::push(
                &mut samplers,
                json::animation::Sampler {
                    input,
                    interpolation: Valid(json::animation::Interpolation::Linear),
                    output,
                    extensions: None,
                    extras: Default::default(),
                },
            );
            channels.push(json::animation::Channel {
                sampler,
                target: json::animation::Target {
                    node: index,
                    path: Valid(path),
                    extensions: None,
                    extras: Default::default(),
                },
                extensions: None,
                extras: Default::default(),
            });
        }
    }
    for (o, mesh) in scene.obstacles.iter().zip(obstacles) {
        let what = || format!("obstacle \"{}\": its pose", o.name);
        let (t, r) = pose(&o.pose.translation.vector, &o.pose.rotation, &what)?;
        let mesh = b.mesh(&o.name, mesh);
        nodes.push(b.root.push(node(&o.name, mesh, t, r)));
    }
    if !channels.is_empty() {
        b.root.push(json::Animation {
            name: Some(scene.name.clone()),
            channels,
            samplers,
            extensions: None,
            extras: Default::default(),
        });
    }
    let scene_index = b.root.push(json::Scene {
        name: Some(scene.name.clone()),
        nodes,
        extensions: None,
        extras: Default::default(),
    });
    b.root.scene = Some(scene_index);
    if !b.bin.is_empty() {
        b.root.push(json::Buffer {
            byte_length: USize64::from(b.bin.len()),
            uri: None,
            name: None,
            extensions: None,
            extras: Default::default(),
        });
    }
    let text =
        json::serialize::to_string(&b.root).map_err(|e| ExportError::Document(e.to_string()))?;
    container(text.into_bytes(), b.bin)
}

/// The glb container: header, JSON chunk padded with spaces, BIN chunk
/// padded with zeros (glTF 2.0 §4.4).
///
/// # Errors
/// A file over glb's limit of 4 GiB.
fn container(mut json: Vec<u8>, mut bin: Vec<u8>) -> Result<Vec<u8>, ExportError> {
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let size = |n: usize| u32::try_from(n).map_err(|_| ExportError::TooLarge { bytes: total });
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&size(total)?.to_le_bytes());
    out.extend_from_slice(&size(json.len())?.to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if !bin.is_empty() {
        out.extend_from_slice(&size(bin.len())?.to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    Ok(out)
}
