//! The camera: which way the world is projected onto the screen, where it is
//! centred and how far it is zoomed.
//!
//! Projection is orthographic. A view is an orthonormal pair of world
//! vectors, [`Camera::right`] and [`Camera::up`]; a world point `p` lands at
//! screen coordinates `((p − target)·right, (p − target)·up)` in world units.
//! The same two vectors turn a key press into a world-space nudge.

use crate::math::Vec3;

/// The four views. Fixed views look along a world axis; the orbit view is
/// set by yaw (about world `z`) and pitch (elevation of the eye).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViewKind {
    /// `x` right, `z` up (looking along +y).
    Front,
    /// `y` right, `z` up (looking along −x).
    Side,
    /// `x` right, `y` up (looking down −z).
    Top,
    /// Yaw and pitch in radians; `(0, 0)` is the front view and
    /// `(0, π/2)` the top view.
    Orbit { yaw: f64, pitch: f64 },
}

impl ViewKind {
    /// The orbit view the `4` key selects.
    pub const DEFAULT_ORBIT: ViewKind = ViewKind::Orbit {
        yaw: 0.5,
        pitch: 0.35,
    };

    /// Short name for the canvas title.
    pub fn name(self) -> &'static str {
        match self {
            ViewKind::Front => "front",
            ViewKind::Side => "side",
            ViewKind::Top => "top",
            ViewKind::Orbit { .. } => "orbit",
        }
    }

    /// The yaw and pitch that reproduce this view as an orbit.
    pub fn angles(self) -> (f64, f64) {
        use std::f64::consts::FRAC_PI_2;
        match self {
            ViewKind::Front => (0.0, 0.0),
            ViewKind::Side => (FRAC_PI_2, 0.0),
            ViewKind::Top => (0.0, FRAC_PI_2),
            ViewKind::Orbit { yaw, pitch } => (yaw, pitch),
        }
    }
}

/// Smallest and largest half-height of the visible window, world units.
/// Keeps zooming from ever producing a zero or non-finite window.
const MIN_HALF: f64 = 1e-9;
const MAX_HALF: f64 = 1e12;

/// An orthographic camera.
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    pub kind: ViewKind,
    /// World point at the centre of the screen.
    pub target: Vec3,
    /// Half the visible height in world units.
    pub half_height: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Camera {
            kind: ViewKind::Front,
            target: Vec3::zeros(),
            half_height: 1.0,
        }
    }
}

impl Camera {
    /// Unit world vector pointing right on the screen.
    pub fn right(&self) -> Vec3 {
        match self.kind {
            ViewKind::Front | ViewKind::Top => Vec3::x(),
            ViewKind::Side => Vec3::y(),
            ViewKind::Orbit { yaw, .. } => Vec3::new(yaw.cos(), yaw.sin(), 0.0),
        }
    }

    /// Unit world vector pointing up on the screen.
    pub fn up(&self) -> Vec3 {
        match self.kind {
            ViewKind::Front | ViewKind::Side => Vec3::z(),
            ViewKind::Top => Vec3::y(),
            ViewKind::Orbit { yaw, pitch } => Vec3::new(
                -pitch.sin() * yaw.sin(),
                pitch.sin() * yaw.cos(),
                pitch.cos(),
            ),
        }
    }

    /// Unit world vector pointing out of the screen, towards the viewer
    /// (`right × up`).
    pub fn toward_viewer(&self) -> Vec3 {
        self.right().cross(&self.up())
    }

    /// Screen coordinates of a world point (world units, origin at the
    /// screen centre, `y` up), or `None` if the point is not finite.
    pub fn project(&self, p: &Vec3) -> Option<(f64, f64)> {
        let d = p - self.target;
        let uv = (d.dot(&self.right()), d.dot(&self.up()));
        (uv.0.is_finite() && uv.1.is_finite()).then_some(uv)
    }

    /// Visible window `([x_min, x_max], [y_min, y_max])` in screen
    /// coordinates for a canvas of `cols × rows` terminal cells. A cell is
    /// taken to be twice as tall as it is wide, so circles stay round.
    pub fn bounds(&self, cols: u16, rows: u16) -> ([f64; 2], [f64; 2]) {
        let h = self.half_height;
        let w = h * aspect(cols, rows);
        ([-w, w], [-h, h])
    }

    /// Centre and zoom so that every finite point fits a `cols × rows`
    /// canvas with a small margin. Leaves the view direction alone. With no
    /// finite points the camera looks at the origin with a 1 m window.
    pub fn fit<'a>(&mut self, points: impl IntoIterator<Item = &'a Vec3>, cols: u16, rows: u16) {
        let (right, up) = (self.right(), self.up());
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        let mut any = false;
        for p in points
            .into_iter()
            .filter(|p| p.iter().all(|c| c.is_finite()))
        {
            lo = lo.inf(p);
            hi = hi.sup(p);
            any = true;
        }
        if !any {
            self.target = Vec3::zeros();
            self.half_height = 1.0;
            return;
        }
        let centre = (lo + hi) / 2.0;
        // Half-extents of the projected bounding box (corners of the world box).
        let (mut half_u, mut half_v) = (0.0_f64, 0.0_f64);
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let d = corner - centre;
            half_u = half_u.max(d.dot(&right).abs());
            half_v = half_v.max(d.dot(&up).abs());
        }
        let needed = half_v.max(half_u / aspect(cols, rows)) * 1.08;
        self.target = centre;
        self.half_height = if needed.is_finite() && needed > MIN_HALF {
            needed.min(MAX_HALF)
        } else {
            1.0
        };
    }

    /// Zoom by `factor` (> 1 zooms in).
    pub fn zoom(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            self.half_height = (self.half_height / factor).clamp(MIN_HALF, MAX_HALF);
        }
    }

    /// Move the window by `(dx, dy)` fractions of its half-height, in screen
    /// directions.
    pub fn pan(&mut self, dx: f64, dy: f64) {
        let moved = self.target + (self.right() * dx + self.up() * dy) * self.half_height;
        if moved.iter().all(|c| c.is_finite()) {
            self.target = moved;
        }
    }

    /// Turn the orbit view by `d_yaw` and `d_pitch` radians. A fixed view
    /// first becomes the orbit view that looks the same. Pitch stays within
    /// ±90°.
    pub fn orbit(&mut self, d_yaw: f64, d_pitch: f64) {
        use std::f64::consts::{FRAC_PI_2, TAU};
        let (yaw, pitch) = self.kind.angles();
        let yaw = (yaw + d_yaw).rem_euclid(TAU);
        let pitch = (pitch + d_pitch).clamp(-FRAC_PI_2, FRAC_PI_2);
        self.kind = ViewKind::Orbit { yaw, pitch };
    }
}

/// Width-to-height ratio of the visible window for `cols × rows` cells
/// (cells are about twice as tall as wide).
fn aspect(cols: u16, rows: u16) -> f64 {
    if cols == 0 || rows == 0 {
        return 1.0;
    }
    f64::from(cols) / (2.0 * f64::from(rows))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).norm() < 1e-12
    }

    fn cam(kind: ViewKind) -> Camera {
        Camera {
            kind,
            ..Camera::default()
        }
    }

    #[test]
    fn fixed_views_project_onto_the_named_axes() {
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert_eq!(cam(ViewKind::Front).project(&p), Some((1.0, 3.0)));
        assert_eq!(cam(ViewKind::Side).project(&p), Some((2.0, 3.0)));
        assert_eq!(cam(ViewKind::Top).project(&p), Some((1.0, 2.0)));
    }

    #[test]
    fn orbit_at_zero_is_front_and_at_right_angle_pitch_is_top() {
        let front = cam(ViewKind::Orbit {
            yaw: 0.0,
            pitch: 0.0,
        });
        assert!(close(front.right(), Vec3::x()) && close(front.up(), Vec3::z()));
        let top = cam(ViewKind::Orbit {
            yaw: 0.0,
            pitch: FRAC_PI_2,
        });
        assert!(close(top.right(), Vec3::x()) && close(top.up(), Vec3::y()));
        let side = cam(ViewKind::Orbit {
            yaw: FRAC_PI_2,
            pitch: 0.0,
        });
        assert!(close(side.right(), Vec3::y()) && close(side.up(), Vec3::z()));
    }

    #[test]
    fn every_view_is_orthonormal_and_right_handed() {
        let kinds = [
            ViewKind::Front,
            ViewKind::Side,
            ViewKind::Top,
            ViewKind::Orbit {
                yaw: 1.1,
                pitch: -0.4,
            },
        ];
        for kind in kinds {
            let c = cam(kind);
            let (r, u, b) = (c.right(), c.up(), c.toward_viewer());
            assert!(
                (r.norm() - 1.0).abs() < 1e-12 && (u.norm() - 1.0).abs() < 1e-12,
                "{kind:?}"
            );
            assert!(r.dot(&u).abs() < 1e-12, "{kind:?}");
            assert!((r.cross(&u) - b).norm() < 1e-12, "{kind:?}");
        }
        // Front view: the viewer stands at −y.
        assert!(close(cam(ViewKind::Front).toward_viewer(), -Vec3::y()));
    }

    #[test]
    fn fit_contains_every_point_with_margin() {
        let pts = [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(3.0, 5.0, 2.0),
            Vec3::new(f64::NAN, 0.0, 0.0),
        ];
        let mut c = cam(ViewKind::Front);
        c.fit(&pts, 40, 20);
        let ([x0, x1], [y0, y1]) = c.bounds(40, 20);
        for p in &pts[..2] {
            let (u, v) = c.project(p).expect("finite");
            assert!(x0 < u && u < x1 && y0 < v && v < y1, "{p:?} outside");
        }
        assert!(c.target.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn fit_without_points_and_extreme_zoom_stay_finite() {
        let mut c = cam(ViewKind::Top);
        c.fit(std::iter::empty(), 0, 0);
        assert_eq!(c.half_height, 1.0);
        for _ in 0..10_000 {
            c.zoom(1.25);
        }
        assert!(c.half_height >= MIN_HALF);
        for _ in 0..10_000 {
            c.zoom(0.8);
            c.pan(1.0, 1.0);
        }
        assert!(c.half_height <= MAX_HALF && c.target.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn bounds_follow_cell_aspect() {
        let c = Camera {
            half_height: 2.0,
            ..Camera::default()
        };
        // 40 columns × 10 rows is square in physical units: 40 wide, 20 tall.
        assert_eq!(c.bounds(40, 10), ([-4.0, 4.0], [-2.0, 2.0]));
    }

    #[test]
    fn orbiting_from_a_fixed_view_keeps_its_look() {
        let mut c = cam(ViewKind::Side);
        c.orbit(0.0, 0.0);
        assert!(close(c.right(), Vec3::y()) && close(c.up(), Vec3::z()));
        c.orbit(0.0, 10.0);
        assert_eq!(c.kind.angles().1, FRAC_PI_2);
    }
}
