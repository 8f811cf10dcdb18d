//! Before/after trajectory pictures (like the paper's Figure 5) as SVG.

use crate::math::Vec3;
use crate::view::View;
use std::fmt::Write;

/// Project onto the vertical plane that shows the motion best: x–z when
/// the paths spread more along x than y, otherwise y–z.
fn axes(views: &[&View]) -> (usize, usize) {
    let spread = |k: usize| {
        let vals: Vec<f64> = views
            .iter()
            .flat_map(|v| {
                v.paths
                    .iter()
                    .flat_map(|p| p.points.iter().map(move |x| x[k]))
            })
            .collect();
        let lo = vals.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = vals.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        if hi > lo { hi - lo } else { 0.0 }
    };
    if spread(0) >= spread(1) {
        (0, 2)
    } else {
        (1, 2)
    }
}

fn panel(
    out: &mut String,
    view: &View,
    title: &str,
    (h, vax): (usize, usize),
    (x0, lo, scale, height): (f64, [f64; 2], f64, f64),
    (width, centre): (f64, f64),
    clip: &str,
) {
    let map = |p: &Vec3| {
        (
            x0 + 20.0 + centre + (p[h] - lo[0]) * scale,
            height - 40.0 - (p[vax] - lo[1]) * scale,
        )
    };
    let _ = writeln!(
        out,
        r##"<text x="{:.1}" y="20" font-family="monospace" font-size="14">{title}</text>"##,
        x0 + 20.0
    );
    // Obstacles (a ground plane) reach beyond the paths: keep each panel's
    // drawing inside it.
    let _ = writeln!(
        out,
        r##"<clipPath id="{clip}"><rect x="{:.1}" y="28" width="{:.1}" height="{:.1}"/></clipPath><g clip-path="url(#{clip})">"##,
        x0 + 5.0,
        width - 10.0,
        height - 33.0
    );
    for (a, b) in &view.obstacles {
        let (ax, ay) = map(a);
        let (bx, by) = map(b);
        if [ax, ay, bx, by].iter().all(|v| v.is_finite()) {
            let _ = writeln!(
                out,
                r##"<line x1="{ax:.1}" y1="{ay:.1}" x2="{bx:.1}" y2="{by:.1}" stroke="#888" stroke-width="1"/>"##
            );
        }
    }
    for p in &view.paths {
        let pts: Vec<String> = p
            .points
            .iter()
            .map(map)
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .map(|(x, y)| format!("{x:.1},{y:.1}"))
            .collect();
        let colour = ["#000", "#c03", "#06c", "#080"][p.body % 4];
        let _ = writeln!(
            out,
            r##"<polyline fill="none" stroke="{colour}" stroke-width="1.2" points="{}"/>"##,
            pts.join(" ")
        );
    }
    for e in &view.events {
        let (x, y) = map(&e.point);
        if x.is_finite() && y.is_finite() {
            let _ = writeln!(
                out,
                r##"<circle cx="{x:.1}" cy="{y:.1}" r="2.5" fill="none" stroke="#c60"/>"##
            );
        }
    }
    out.push_str("</g>\n");
}

/// An SVG with the `before` and `after` motions side by side.
pub fn before_after(before: &View, after: &View) -> String {
    let (h, v) = axes(&[before, after]);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for view in [before, after] {
        for p in view.paths.iter().flat_map(|p| p.points.iter()) {
            for (k, ax) in [h, v].iter().enumerate() {
                if p[*ax].is_finite() {
                    lo[k] = lo[k].min(p[*ax]);
                    hi[k] = hi[k].max(p[*ax]);
                }
            }
        }
    }
    for k in 0..2 {
        if !(lo[k].is_finite() && hi[k] > lo[k]) {
            lo[k] = -1.0;
            hi[k] = 1.0;
        }
        let pad = 0.1 * (hi[k] - lo[k]);
        lo[k] -= pad;
        hi[k] += pad;
    }
    let (w, height) = (420.0, 340.0);
    let scale = ((w - 40.0) / (hi[0] - lo[0])).min((height - 70.0) / (hi[1] - lo[1]));
    // A tall, narrow motion (the mug) sits in the middle of its panel.
    let centre = 0.5 * (w - 40.0 - (hi[0] - lo[0]) * scale);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{height}" viewBox="0 0 {} {height}">"##,
        2.0 * w,
        2.0 * w
    );
    let _ = writeln!(out, r##"<rect width="100%" height="100%" fill="white"/>"##);
    panel(
        &mut out,
        before,
        &format!("{} — before", before.scene),
        (h, v),
        (0.0, lo, scale, height),
        (w, centre),
        "before",
    );
    panel(
        &mut out,
        after,
        &format!("{} — after", after.scene),
        (h, v),
        (w, lo, scale, height),
        (w, centre),
        "after",
    );
    out.push_str("</svg>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::{Core, Editor};

    #[test]
    fn panels_are_clipped_and_every_coordinate_is_finite() {
        // The mug as it fell before it got friction (a frozen copy).
        let path = std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/hard/mug-frictionless.toml"
        ));
        let editor = Editor::open(path).unwrap();
        let view = editor.view();
        let svg = before_after(&view, &view);
        assert!(svg.starts_with("<svg ") && svg.ends_with("</svg>\n"));
        // One clipped group per panel, each closed.
        assert_eq!(svg.matches("<clipPath ").count(), 2);
        assert_eq!(svg.matches("<g clip-path=").count(), 2);
        assert_eq!(svg.matches("</g>").count(), 2);
        assert!(!svg.contains("NaN") && !svg.contains("inf"), "{svg}");
        // The mug falls nearly straight down: its paths sit in the middle of
        // the left panel (x within 20..400), not against its left edge.
        let xs: Vec<f64> = svg
            .lines()
            .filter(|l| l.starts_with("<polyline"))
            .take(view.paths.len())
            .flat_map(|l| {
                let pts = l
                    .split("points=\"")
                    .nth(1)
                    .unwrap()
                    .trim_end_matches("\"/>");
                pts.split(' ')
                    .map(|p| p.split(',').next().unwrap().parse::<f64>().unwrap())
                    .collect::<Vec<_>>()
            })
            .collect();
        let lo = xs.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        assert!(lo > 150.0 && hi < 270.0, "paths span x {lo:.1}..{hi:.1}");
    }
}
