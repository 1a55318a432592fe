//! Several plots in one SVG (rows of panels), and the 3-D view of toolpaths: an isometric view,
//! the top view and the side views XZ and YZ, coloured by a value per point on one colour bar.

use super::{Aspect, Plot, Style, document, escape};
use crate::geom::{P2, P3};
use std::fmt::Write;

/// Plots side by side in rows under one title.
#[derive(Clone, Debug)]
pub struct Figure {
    title: String,
    rows: Vec<Vec<Plot>>,
}

impl Figure {
    /// An empty figure with a title.
    pub fn new(title: &str) -> Figure {
        Figure { title: title.into(), rows: Vec::new() }
    }

    /// A row of panels sharing the width equally.
    pub fn row(&mut self, plots: Vec<Plot>) -> &mut Self {
        if !plots.is_empty() {
            self.rows.push(plots);
        }
        self
    }

    /// The SVG document, `width` pixels wide.
    pub fn to_svg(&self, width: f64) -> String {
        let mut body = String::new();
        let _ = writeln!(
            body,
            r#"<text x="{:.1}" y="22" font-size="16" font-weight="bold" text-anchor="middle">{}</text>"#,
            width / 2.0,
            escape(&self.title)
        );
        let mut y = 32.0;
        for row in &self.rows {
            let w = width / row.len() as f64;
            let mut row_h: f64 = 0.0;
            for (k, plot) in row.iter().enumerate() {
                let r = plot.render(w);
                let _ = writeln!(body, r#"<g transform="translate({:.1} {y:.1})">"#, w * k as f64);
                body.push_str(&r.body);
                body.push_str("</g>\n");
                row_h = row_h.max(r.height);
            }
            y += row_h;
        }
        document(width, y, &body)
    }
}

/// A polyline in space with one value per point (its z, an engagement, a deviation, a feed).
#[derive(Clone, Debug, PartialEq)]
pub struct Path3 {
    /// Points (mm).
    pub pts: Vec<P3>,
    /// Values, one per point, shown on the colour bar.
    pub values: Vec<f64>,
}

impl Path3 {
    /// A path coloured by its height.
    pub fn by_z(pts: Vec<P3>) -> Path3 {
        let values = pts.iter().map(|p| p.z).collect();
        Path3 { pts, values }
    }
}

/// A projection of space onto a panel.
#[derive(Clone, Copy, Debug, PartialEq)]
enum View {
    /// Isometric, seen from (−x, −y, +z), heights scaled by the factor.
    Iso(f64),
    /// From above: x right, y up.
    Top,
    /// From −y: x right, z up.
    Xz,
    /// From +x: y right, z up.
    Yz,
}

impl View {
    fn project(self, p: &P3) -> P2 {
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        match self {
            View::Iso(k) => P2::new((p.x - p.y) * c, (p.x + p.y) * s + p.z * k),
            View::Top => P2::new(p.x, p.y),
            View::Xz => P2::new(p.x, p.z),
            View::Yz => P2::new(p.y, p.z),
        }
    }
}

/// A round factor (1, 2 or 5 times a power of ten) by which heights are scaled in the isometric
/// view so that a flat part's relief shows: its height range made at least a fifth of its width.
fn relief(lo: &P3, hi: &P3) -> f64 {
    let (w, h) = ((hi.x - lo.x).max(hi.y - lo.y), hi.z - lo.z);
    if h.is_nan() || h <= 0.0 || h >= 0.2 * w {
        return 1.0;
    }
    let raw = 0.2 * w / h;
    let mag = 10f64.powf(raw.log10().floor());
    [5.0, 2.0, 1.0].iter().map(|m| m * mag).find(|f| *f <= raw).unwrap_or(mag).max(1.0)
}

/// The 3-D views of `paths` (isometric, top, side XZ and YZ), coloured by their values on one
/// colour bar labelled `bar_label`, over `underlay` (the model's outline, surface lines or
/// contact lines, each in its own style).
pub fn views(title: &str, paths: &[Path3], bar_label: &str, underlay: &[(Vec<P3>, Style)]) -> Figure {
    let all = paths.iter().flat_map(|p| p.pts.iter()).chain(underlay.iter().flat_map(|u| u.0.iter()));
    let (mut lo, mut hi) = (
        P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        P3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY),
    );
    for p in all.filter(|p| p.coords.iter().all(|v| v.is_finite())) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let (vlo, vhi) = paths
        .iter()
        .flat_map(|p| p.values.iter())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| (a.0.min(v), a.1.max(v)));
    let k = if lo.x.is_finite() { relief(&lo, &hi) } else { 1.0 };
    let iso_title = if k > 1.0 { format!("isometric (heights ×{k})") } else { "isometric".to_string() };
    let panel = |view: View, title: &str, aspect: Aspect, labels: (&str, &str)| {
        let mut p = Plot::new(title, aspect);
        p.labels(labels.0, labels.1).colour_bar(bar_label);
        if vlo.is_finite() {
            p.colour_range(vlo, vhi);
        }
        for (u, style) in underlay {
            let flat: Vec<P2> = u.iter().map(|q| view.project(q)).collect();
            p.polyline(&flat, style.clone());
        }
        for path in paths {
            let flat: Vec<P2> = path.pts.iter().map(|q| view.project(q)).collect();
            p.heat(&flat, &path.values, 1.0);
        }
        p
    };
    let mut iso = panel(View::Iso(k), &iso_title, Aspect::Equal, ("", ""));
    iso.without_axes();
    if lo.x.is_finite() {
        // Axis triad at the lowest corner, a sixth of the width long.
        let len = (hi.x - lo.x).max(hi.y - lo.y).max(hi.z - lo.z).max(1e-9) / 6.0;
        for (d, name) in
            [(P3::new(len, 0.0, 0.0), "x"), (P3::new(0.0, len, 0.0), "y"), (P3::new(0.0, 0.0, len / k), "z")]
        {
            let a = View::Iso(k).project(&lo);
            let b = View::Iso(k).project(&(lo + d.coords));
            iso.polyline(&[a, b], Style::stroke("black", 1.2)).label(b, name, 12.0, "black");
        }
    }
    let top = panel(View::Top, "top view", Aspect::Equal, ("x (mm)", "y (mm)"));
    let xz = panel(View::Xz, "side view from −y", Aspect::Free, ("x (mm)", "z (mm)"));
    let yz = panel(View::Yz, "side view from +x", Aspect::Free, ("y (mm)", "z (mm)"));
    let mut f = Figure::new(title);
    f.row(vec![iso, top]).row(vec![xz, yz]);
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::svg::inspect::inspect;

    /// A dome of 101 passes of 1001 points (101 101 points): four panels, one colour bar range
    /// (the data's) in each, and well under 1 MB.
    #[test]
    fn a_dense_dome_is_bounded_and_its_bars_match_the_data() {
        let r = 500.0;
        let paths: Vec<Path3> = (0..=100)
            .map(|j| {
                let y = -50.0 + j as f64;
                Path3::by_z(
                    (0..=1000)
                        .map(|i| {
                            let x = -50.0 + 0.1 * i as f64;
                            P3::new(x, y, (r * r - x * x - y * y).sqrt() - r)
                        })
                        .collect(),
                )
            })
            .collect();
        let zmin = paths.iter().flat_map(|p| p.values.iter()).copied().fold(f64::INFINITY, f64::min);
        let svg = views("dome", &paths, "z (mm)", &[]).to_svg(1200.0);
        assert!(svg.len() < 600_000, "{} bytes", svg.len());
        let seen = inspect(&svg).unwrap();
        assert_eq!(seen.bars.len(), 4);
        for (lo, hi, label) in &seen.bars {
            assert_eq!((*lo, *hi, label.as_str()), (zmin, 0.0, "z (mm)"));
        }
        assert!(seen.legend.is_empty() && seen.drawn.is_empty());
        assert!(svg.contains("heights ×"), "the 5 mm relief over 100 mm is scaled up");
    }

    #[test]
    fn relief_is_round_and_only_for_flat_parts() {
        let lo = P3::new(0.0, 0.0, 0.0);
        assert_eq!(relief(&lo, &P3::new(100.0, 100.0, 50.0)), 1.0);
        assert_eq!(relief(&lo, &P3::new(100.0, 100.0, 2.5)), 5.0);
        assert_eq!(relief(&lo, &P3::new(100.0, 50.0, 0.3)), 50.0);
    }
}
