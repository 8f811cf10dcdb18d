//! The control vector `u` (paper §3.1): named entries over the scene's
//! physical parameters. Body blocks (position, orientation, velocity,
//! angular velocity, mass, inertia) and per-event blocks (normal deviation,
//! restitution) are read from and written back to the [`Scene`], so the
//! scene is always the single source of truth.

use crate::scene::{Block, Scene};
use nalgebra::DVector;

/// What one entry of the control vector controls.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Target {
    /// Component `axis` of a body block.
    Body {
        body: usize,
        block: Block,
        axis: usize,
    },
    /// Component `axis` (0 = a, 1 = b) of the normal deviation at an event.
    Normal { event: usize, axis: usize },
    /// Restitution at an event.
    Restitution { event: usize },
}

/// One entry of the control vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// e.g. `egg1.orientation.z`, `event3.normal.a`, `event3.restitution`.
    pub name: String,
    pub target: Target,
    /// Whether the solver may change it.
    pub free: bool,
    /// Diagonal of `M`: larger scale means the solver changes it less.
    pub scale: f64,
    /// Desired value (surface parameters only: the geometric normal and the
    /// scene's restitution), pulling the solution towards it through `d`.
    pub desired: Option<f64>,
    /// The physically meaningful range `[lower, upper]`: the solver never
    /// steps outside it (restitution in [0, 1], a normal deviation of at
    /// most [`MAX_NORMAL_DEVIATION`], positive masses and moments).
    pub bounds: (f64, f64),
}

/// Largest tilt of a controlled normal from the geometric one, rad (30°).
/// Each deviation component is bounded by `tan(30°)/√2`, so that together
/// they tilt the normal by at most 30°.
pub const MAX_NORMAL_DEVIATION: f64 = std::f64::consts::FRAC_PI_6;

/// Bounds of a deviation component (see [`MAX_NORMAL_DEVIATION`]).
fn normal_bound() -> f64 {
    MAX_NORMAL_DEVIATION.tan() / std::f64::consts::SQRT_2
}

/// Smallest mass (kg) or principal moment (kg·m²) the solver may step to.
const MIN_POSITIVE: f64 = 1e-12;

/// The control vector's layout for a scene: every entry, free or fixed, and
/// the column of each free entry in Jacobians.
#[derive(Debug, Clone, PartialEq)]
pub struct Controls {
    pub entries: Vec<Entry>,
    /// Indices into `entries` of the free entries, in column order.
    pub free: Vec<usize>,
    /// `columns[body][block] = first column` of a free body block.
    body_cols: Vec<[Option<usize>; 6]>,
    /// `(event, normal a column, restitution column)`.
    event_cols: Vec<(usize, Option<usize>, Option<usize>)>,
}

const AXES: [&str; 3] = ["x", "y", "z"];

fn block_index(b: Block) -> usize {
    Block::ALL.iter().position(|x| *x == b).unwrap_or(0)
}

impl Controls {
    /// The layout for the scene's current free blocks and event controls.
    pub fn new(scene: &Scene) -> Controls {
        let mut entries = Vec::new();
        for (bi, body) in scene.bodies.iter().enumerate() {
            for block in Block::ALL {
                let free = body.is_free(block);
                for (axis, tag) in AXES.iter().enumerate().take(block.len()) {
                    let name = if block.len() == 1 {
                        format!("{}.{}", body.name, block.name())
                    } else {
                        format!("{}.{}.{tag}", body.name, block.name())
                    };
                    entries.push(Entry {
                        name,
                        target: Target::Body {
                            body: bi,
                            block,
                            axis,
                        },
                        free,
                        scale: scene.scales.of(block),
                        desired: None,
                        bounds: match block {
                            Block::Mass | Block::Inertia => (MIN_POSITIVE, f64::INFINITY),
                            _ => (f64::NEG_INFINITY, f64::INFINITY),
                        },
                    });
                }
            }
        }
        let mut events: Vec<_> = scene.event_controls.clone();
        events.sort_by_key(|c| c.event);
        for c in &events {
            if c.normal.is_some() {
                for (axis, tag) in ["a", "b"].iter().enumerate() {
                    entries.push(Entry {
                        name: format!("event{}.normal.{tag}", c.event),
                        target: Target::Normal {
                            event: c.event,
                            axis,
                        },
                        free: !c.fixed,
                        scale: scene.scales.normal,
                        desired: Some(0.0),
                        bounds: (-normal_bound(), normal_bound()),
                    });
                }
            }
            if c.restitution.is_some() {
                entries.push(Entry {
                    name: format!("event{}.restitution", c.event),
                    target: Target::Restitution { event: c.event },
                    free: !c.fixed,
                    scale: scene.scales.restitution,
                    desired: None,
                    bounds: (0.0, 1.0),
                });
            }
        }
        let free: Vec<usize> = (0..entries.len()).filter(|&i| entries[i].free).collect();
        let mut body_cols = vec![[None; 6]; scene.bodies.len()];
        let mut event_cols: Vec<(usize, Option<usize>, Option<usize>)> = Vec::new();
        for (col, &i) in free.iter().enumerate() {
            match entries[i].target {
                Target::Body {
                    body,
                    block,
                    axis: 0,
                } => body_cols[body][block_index(block)] = Some(col),
                Target::Normal { event, axis: 0 } => {
                    match event_cols.iter_mut().find(|e| e.0 == event) {
                        Some(e) => e.1 = Some(col),
                        None => event_cols.push((event, Some(col), None)),
                    }
                }
                Target::Restitution { event } => match event_cols.iter_mut().find(|e| e.0 == event)
                {
                    Some(e) => e.2 = Some(col),
                    None => event_cols.push((event, None, Some(col))),
                },
                _ => {}
            }
        }
        Controls {
            entries,
            free,
            body_cols,
            event_cols,
        }
    }

    /// Number of free controls (columns of the Jacobian).
    pub fn m(&self) -> usize {
        self.free.len()
    }

    /// First Jacobian column of a free body block.
    pub fn body_column(&self, body: usize, block: Block) -> Option<usize> {
        self.body_cols.get(body).and_then(|c| c[block_index(block)])
    }

    /// Columns of event `k`'s normal deviation (a, then b at +1) and restitution.
    pub fn event_columns(&self, event: usize) -> (Option<usize>, Option<usize>) {
        self.event_cols
            .iter()
            .find(|e| e.0 == event)
            .map(|e| (e.1, e.2))
            .unwrap_or((None, None))
    }

    /// Read an entry's current value from the scene.
    pub fn get(&self, scene: &Scene, i: usize) -> f64 {
        match self.entries[i].target {
            Target::Body { body, block, axis } => {
                let b = &scene.bodies[body];
                match block {
                    Block::Position => b.position[axis],
                    Block::Orientation => b.orientation[axis],
                    Block::Velocity => b.velocity[axis],
                    Block::AngularVelocity => b.angular_velocity[axis],
                    Block::Mass => b.mass,
                    Block::Inertia => b.inertia[axis],
                }
            }
            Target::Normal { event, axis } => scene
                .event_control(event)
                .and_then(|c| c.normal)
                .map(|n| n[axis])
                .unwrap_or(0.0),
            Target::Restitution { event } => scene
                .event_control(event)
                .and_then(|c| c.restitution)
                .unwrap_or(1.0),
        }
    }

    /// Write an entry's value into the scene.
    pub fn set(&self, scene: &mut Scene, i: usize, value: f64) {
        match self.entries[i].target {
            Target::Body { body, block, axis } => {
                let b = &mut scene.bodies[body];
                match block {
                    Block::Position => b.position[axis] = value,
                    Block::Orientation => b.orientation[axis] = value,
                    Block::Velocity => b.velocity[axis] = value,
                    Block::AngularVelocity => b.angular_velocity[axis] = value,
                    Block::Mass => b.mass = value,
                    Block::Inertia => b.inertia[axis] = value,
                }
            }
            Target::Normal { event, axis } => {
                if let Some(c) = scene.event_controls.iter_mut().find(|c| c.event == event) {
                    let mut n = c.normal.unwrap_or([0.0, 0.0]);
                    n[axis] = value;
                    c.normal = Some(n);
                }
            }
            Target::Restitution { event } => {
                if let Some(c) = scene.event_controls.iter_mut().find(|c| c.event == event) {
                    c.restitution = Some(value);
                }
            }
        }
    }

    /// The free entries' values `u`.
    pub fn values(&self, scene: &Scene) -> DVector<f64> {
        DVector::from_iterator(self.m(), self.free.iter().map(|&i| self.get(scene, i)))
    }

    /// Write `u` into the scene's free entries, then keep every orientation
    /// within `|r| ≤ π` (Grassia's reparameterisation).
    pub fn write(&self, scene: &mut Scene, u: &DVector<f64>) {
        for (col, &i) in self.free.iter().enumerate() {
            self.set(scene, i, u[col]);
        }
        for b in &mut scene.bodies {
            b.orientation = crate::math::reparameterize(&b.orientation).0;
        }
    }

    /// Lower and upper bounds over the free entries.
    pub fn bounds(&self) -> (DVector<f64>, DVector<f64>) {
        let lo = DVector::from_iterator(
            self.m(),
            self.free.iter().map(|&i| self.entries[i].bounds.0),
        );
        let hi = DVector::from_iterator(
            self.m(),
            self.free.iter().map(|&i| self.entries[i].bounds.1),
        );
        (lo, hi)
    }

    /// Diagonal of `M` over the free entries.
    pub fn scales(&self) -> DVector<f64> {
        DVector::from_iterator(self.m(), self.free.iter().map(|&i| self.entries[i].scale))
    }
}
