//! SVG plots written by the project: paths (lines and exact arcs), points, circles and
//! filled regions in world coordinates (mm), with axes, ticks, a legend and a title. Equal
//! aspect for geometry; independent axis scales for charts.

use crate::geom::{Arc2, P2};
use std::fmt::Write;

/// How a mark is drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct Style {
    /// Stroke colour (any SVG colour), `none` for no stroke.
    pub stroke: String,
    /// Stroke width in pixels.
    pub width: f64,
    /// Fill colour, `none` for no fill.
    pub fill: String,
    /// Dash pattern in pixels (`4 2`), empty for solid.
    pub dash: String,
    /// Opacity 0..1.
    pub opacity: f64,
}

impl Style {
    /// A solid stroke.
    pub fn stroke(colour: &str, width: f64) -> Style {
        Style { stroke: colour.into(), width, fill: "none".into(), dash: String::new(), opacity: 1.0 }
    }

    /// A filled shape without outline.
    pub fn fill(colour: &str, opacity: f64) -> Style {
        Style { stroke: "none".into(), width: 0.0, fill: colour.into(), dash: String::new(), opacity }
    }

    /// The same style dashed.
    pub fn dashed(mut self, dash: &str) -> Style {
        self.dash = dash.into();
        self
    }

    fn attrs(&self) -> String {
        let mut s = format!(r#"stroke="{}" stroke-width="{}" fill="{}""#, self.stroke, self.width, self.fill);
        if !self.dash.is_empty() {
            let _ = write!(s, r#" stroke-dasharray="{}""#, self.dash);
        }
        if self.opacity < 1.0 {
            let _ = write!(s, r#" opacity="{}""#, self.opacity);
        }
        s
    }
}

#[derive(Clone, Debug)]
enum Mark {
    /// A path of straight and circular pieces starting at a point.
    Path {
        start: P2,
        pieces: Vec<Piece>,
        closed: bool,
        style: Style,
    },
    Dots {
        pts: Vec<P2>,
        radius_px: f64,
        style: Style,
    },
    Circle {
        c: P2,
        r: f64,
        style: Style,
    },
    Label {
        at: P2,
        text: String,
        size_px: f64,
        colour: String,
    },
    Raster(Raster),
}

/// A colour map of values on a regular grid (a height map), drawn as cells.
#[derive(Clone, Debug, PartialEq)]
pub struct Raster {
    /// World position of the lower-left corner of cell (0, 0).
    pub origin: P2,
    /// Cell size in world units (x, y).
    pub cell: (f64, f64),
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Values, row-major from the bottom row (`values[j * nx + i]`); NaN cells are not drawn.
    pub values: Vec<f64>,
    /// Values mapped to the ends of the colour ramp.
    pub range: (f64, f64),
}

/// Colour of `t` in [0, 1] on a perceptual ramp (dark blue, teal, green, yellow).
pub fn ramp(t: f64) -> (u8, u8, u8) {
    const STOPS: [(f64, f64, f64); 5] =
        [(68.0, 1.0, 84.0), (59.0, 82.0, 139.0), (33.0, 145.0, 140.0), (94.0, 201.0, 98.0), (253.0, 231.0, 37.0)];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 } * (STOPS.len() - 1) as f64;
    let k = (t.floor() as usize).min(STOPS.len() - 2);
    let f = t - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    (mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// One piece of a path.
#[derive(Clone, Copy, Debug)]
pub enum Piece {
    /// Straight to a point.
    Line(P2),
    /// Along an arc (its end is the next position).
    Arc(Arc2),
}

/// Whether both axes share one scale.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aspect {
    /// Geometry: 1 mm is the same length on both axes.
    Equal,
    /// Charts: each axis fills the frame.
    Free,
}

/// A plot under construction.
#[derive(Clone, Debug)]
pub struct Plot {
    title: String,
    x_label: String,
    y_label: String,
    aspect: Aspect,
    marks: Vec<Mark>,
    legend: Vec<(String, Style)>,
    min: P2,
    max: P2,
}

impl Plot {
    /// An empty plot with a title.
    pub fn new(title: &str, aspect: Aspect) -> Plot {
        Plot {
            title: title.into(),
            x_label: "x (mm)".into(),
            y_label: "y (mm)".into(),
            aspect,
            marks: Vec::new(),
            legend: Vec::new(),
            min: P2::new(f64::INFINITY, f64::INFINITY),
            max: P2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        }
    }

    /// Axis labels.
    pub fn labels(&mut self, x: &str, y: &str) -> &mut Self {
        self.x_label = x.into();
        self.y_label = y.into();
        self
    }

    fn grow(&mut self, p: &P2) {
        if p.x.is_finite() && p.y.is_finite() {
            self.min = P2::new(self.min.x.min(p.x), self.min.y.min(p.y));
            self.max = P2::new(self.max.x.max(p.x), self.max.y.max(p.y));
        }
    }

    /// A polyline.
    pub fn polyline(&mut self, pts: &[P2], style: Style) -> &mut Self {
        if let Some((first, rest)) = pts.split_first() {
            let pieces = rest.iter().map(|p| Piece::Line(*p)).collect();
            self.path(*first, pieces, false, style);
        }
        self
    }

    /// A closed polygon (filled if the style fills).
    pub fn polygon(&mut self, pts: &[P2], style: Style) -> &mut Self {
        if let Some((first, rest)) = pts.split_first() {
            let pieces = rest.iter().map(|p| Piece::Line(*p)).collect();
            self.path(*first, pieces, true, style);
        }
        self
    }

    /// A path of lines and arcs from `start`.
    pub fn path(&mut self, start: P2, pieces: Vec<Piece>, closed: bool, style: Style) -> &mut Self {
        self.grow(&start);
        for p in &pieces {
            match p {
                Piece::Line(q) => self.grow(q),
                Piece::Arc(a) => {
                    // Bounds from dense points of the arc.
                    for i in 0..=16 {
                        self.grow(&a.point_at_fraction(i as f64 / 16.0));
                    }
                }
            }
        }
        self.marks.push(Mark::Path { start, pieces, closed, style });
        self
    }

    /// Dots of a fixed size in pixels.
    pub fn dots(&mut self, pts: &[P2], radius_px: f64, style: Style) -> &mut Self {
        for p in pts {
            self.grow(p);
        }
        self.marks.push(Mark::Dots { pts: pts.to_vec(), radius_px, style });
        self
    }

    /// A circle of radius `r` in world units.
    pub fn circle(&mut self, c: P2, r: f64, style: Style) -> &mut Self {
        self.grow(&(c - nalgebra::Vector2::new(r, r)));
        self.grow(&(c + nalgebra::Vector2::new(r, r)));
        self.marks.push(Mark::Circle { c, r, style });
        self
    }

    /// Text at a world position.
    pub fn label(&mut self, at: P2, text: &str, size_px: f64, colour: &str) -> &mut Self {
        self.marks.push(Mark::Label { at, text: text.into(), size_px, colour: colour.into() });
        self
    }

    /// A colour map of grid values (see [`Raster`]); runs of equal colour along a row are drawn
    /// as one rectangle, so keep the grid to a few hundred cells a side.
    pub fn raster(&mut self, raster: Raster) -> &mut Self {
        self.grow(&raster.origin);
        self.grow(&P2::new(
            raster.origin.x + raster.cell.0 * raster.nx as f64,
            raster.origin.y + raster.cell.1 * raster.ny as f64,
        ));
        self.marks.push(Mark::Raster(raster));
        self
    }

    /// A legend entry.
    pub fn legend(&mut self, text: &str, style: Style) -> &mut Self {
        self.legend.push((text.into(), style));
        self
    }

    /// Makes sure `p` is inside the plotted range.
    pub fn include(&mut self, p: P2) -> &mut Self {
        self.grow(&p);
        self
    }

    /// The SVG document, `width` pixels wide.
    pub fn to_svg(&self, width: f64) -> String {
        let (mut min, mut max) = (self.min, self.max);
        if !min.x.is_finite() {
            (min, max) = (P2::new(0.0, 0.0), P2::new(1.0, 1.0));
        }
        let span = |a: f64, b: f64| if b - a > 0.0 { b - a } else { 1.0 };
        let (w_world, h_world) = (span(min.x, max.x), span(min.y, max.y));
        let pad = (72.0, 24.0, 56.0, 48.0); // left, right, bottom, top
        let frame_w = width - pad.0 - pad.1;
        let (sx, sy, frame_h) = match self.aspect {
            Aspect::Equal => {
                let s = frame_w / w_world;
                let fh = (h_world * s).clamp(40.0, 4.0 * width);
                (s, fh / h_world, fh)
            }
            Aspect::Free => {
                let fh = 0.6 * frame_w;
                (frame_w / w_world, fh / h_world, fh)
            }
        };
        let legend_h = 18.0 * self.legend.len() as f64;
        let height = pad.3 + frame_h + pad.2 + legend_h;
        let tx = |x: f64| pad.0 + (x - min.x) * sx;
        let ty = |y: f64| pad.3 + frame_h - (y - min.y) * sy;
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif">"#
        );
        let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
        let _ = writeln!(
            s,
            r#"<text x="{}" y="20" font-size="15" text-anchor="middle">{}</text>"#,
            width / 2.0,
            escape(&self.title)
        );
        // Axes with ticks.
        let _ = writeln!(
            s,
            r##"<rect x="{}" y="{}" width="{frame_w:.2}" height="{frame_h:.2}" fill="none" stroke="#888" stroke-width="1"/>"##,
            pad.0, pad.3
        );
        for (t, label) in ticks(min.x, max.x) {
            let x = tx(t);
            let _ = writeln!(
                s,
                r##"<line x1="{x:.2}" y1="{:.2}" x2="{x:.2}" y2="{:.2}" stroke="#ddd"/><text x="{x:.2}" y="{:.2}" font-size="11" text-anchor="middle">{label}</text>"##,
                pad.3,
                pad.3 + frame_h,
                pad.3 + frame_h + 16.0
            );
        }
        for (t, label) in ticks(min.y, max.y) {
            let y = ty(t);
            let _ = writeln!(
                s,
                r##"<line x1="{:.2}" y1="{y:.2}" x2="{:.2}" y2="{y:.2}" stroke="#ddd"/><text x="{:.2}" y="{:.2}" font-size="11" text-anchor="end">{label}</text>"##,
                pad.0,
                pad.0 + frame_w,
                pad.0 - 6.0,
                y + 4.0
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{:.2}" y="{:.2}" font-size="12" text-anchor="middle">{}</text>"#,
            pad.0 + frame_w / 2.0,
            pad.3 + frame_h + 36.0,
            escape(&self.x_label)
        );
        let _ = writeln!(
            s,
            r#"<text x="14" y="{:.2}" font-size="12" text-anchor="middle" transform="rotate(-90 14 {:.2})">{}</text>"#,
            pad.3 + frame_h / 2.0,
            pad.3 + frame_h / 2.0,
            escape(&self.y_label)
        );
        let _ = writeln!(s, r#"<g clip-path="none">"#);
        for mark in &self.marks {
            match mark {
                Mark::Path { start, pieces, closed, style } => {
                    let mut d = format!("M{:.3} {:.3}", tx(start.x), ty(start.y));
                    for p in pieces {
                        match p {
                            Piece::Line(q) => {
                                let _ = write!(d, "L{:.3} {:.3}", tx(q.x), ty(q.y));
                            }
                            Piece::Arc(a) => arc_commands(&mut d, a, &tx, &ty, sx, sy),
                        }
                    }
                    if *closed {
                        d.push('Z');
                    }
                    let _ = writeln!(s, r#"<path d="{d}" {} stroke-linejoin="round"/>"#, style.attrs());
                }
                Mark::Dots { pts, radius_px, style } => {
                    let _ = write!(s, "<g {}>", style.attrs());
                    for p in pts {
                        let _ = write!(s, r#"<circle cx="{:.3}" cy="{:.3}" r="{radius_px}"/>"#, tx(p.x), ty(p.y));
                    }
                    let _ = writeln!(s, "</g>");
                }
                Mark::Circle { c, r, style } => {
                    let _ = writeln!(
                        s,
                        r#"<ellipse cx="{:.3}" cy="{:.3}" rx="{:.3}" ry="{:.3}" {}/>"#,
                        tx(c.x),
                        ty(c.y),
                        r * sx,
                        r * sy,
                        style.attrs()
                    );
                }
                Mark::Raster(r) => {
                    let span = r.range.1 - r.range.0;
                    let level = |v: f64| -> Option<u32> {
                        v.is_finite().then(|| {
                            let t = if span > 0.0 { (v - r.range.0) / span } else { 0.5 };
                            (t.clamp(0.0, 1.0) * 255.0).round() as u32
                        })
                    };
                    let _ = writeln!(s, r#"<g shape-rendering="crispEdges">"#);
                    for j in 0..r.ny {
                        let (y0, y1) = (r.origin.y + r.cell.1 * j as f64, r.origin.y + r.cell.1 * (j + 1) as f64);
                        let mut i = 0;
                        while i < r.nx {
                            let Some(l) = level(r.values[j * r.nx + i]) else {
                                i += 1;
                                continue;
                            };
                            let mut e = i + 1;
                            while e < r.nx && level(r.values[j * r.nx + e]) == Some(l) {
                                e += 1;
                            }
                            let (x0, x1) = (r.origin.x + r.cell.0 * i as f64, r.origin.x + r.cell.0 * e as f64);
                            let (cr, cg, cb) = ramp(l as f64 / 255.0);
                            let _ = writeln!(
                                s,
                                r##"<rect x="{:.3}" y="{:.3}" width="{:.3}" height="{:.3}" fill="#{cr:02x}{cg:02x}{cb:02x}"/>"##,
                                tx(x0),
                                ty(y1),
                                tx(x1) - tx(x0),
                                ty(y0) - ty(y1)
                            );
                            i = e;
                        }
                    }
                    let _ = writeln!(s, "</g>");
                }
                Mark::Label { at, text, size_px, colour } => {
                    let _ = writeln!(
                        s,
                        r#"<text x="{:.2}" y="{:.2}" font-size="{size_px}" fill="{colour}">{}</text>"#,
                        tx(at.x),
                        ty(at.y),
                        escape(text)
                    );
                }
            }
        }
        let _ = writeln!(s, "</g>");
        for (k, (text, style)) in self.legend.iter().enumerate() {
            let y = pad.3 + frame_h + pad.2 + 18.0 * k as f64 + 4.0;
            let mut swatch = style.clone();
            swatch.width = swatch.width.max(2.0);
            if swatch.stroke == "none" {
                swatch.stroke = swatch.fill.clone();
                swatch.width = 8.0;
            }
            let _ = writeln!(
                s,
                r#"<line x1="{}" y1="{y:.1}" x2="{}" y2="{y:.1}" {}/><text x="{}" y="{:.1}" font-size="12">{}</text>"#,
                pad.0,
                pad.0 + 28.0,
                swatch.attrs(),
                pad.0 + 36.0,
                y + 4.0,
                escape(text)
            );
        }
        s.push_str("</svg>\n");
        s
    }
}

/// SVG arc commands for an arc; sweeps over 180° are split in two (SVG needs an unambiguous
/// large-arc flag).
fn arc_commands(d: &mut String, a: &Arc2, tx: &dyn Fn(f64) -> f64, ty: &dyn Fn(f64) -> f64, sx: f64, sy: f64) {
    let parts = if a.sweep.abs() > std::f64::consts::PI { 2 } else { 1 };
    for k in 1..=parts {
        let e = a.point_at(a.start + a.sweep * k as f64 / parts as f64);
        // y is flipped on screen, so counter-clockwise in the world is clockwise on screen.
        let sweep_flag = if a.sweep > 0.0 { 0 } else { 1 };
        let _ = write!(d, "A{:.3} {:.3} 0 0 {sweep_flag} {:.3} {:.3}", a.r * sx, a.r * sy, tx(e.x), ty(e.y));
    }
}

/// Round tick positions covering [lo, hi] with their labels.
fn ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let span = hi - lo;
    if span <= 0.0 || !span.is_finite() {
        return vec![(lo, format!("{lo}"))];
    }
    let raw = span / 6.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(10.0 * mag);
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let mut out = Vec::new();
    let mut t = (lo / step).ceil() * step;
    while t <= hi + 1e-9 * span {
        out.push((t, format!("{:.*}", decimals, if t.abs() < 1e-12 * step.max(1.0) { 0.0 } else { t })));
        t += step;
    }
    out
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_a_well_formed_document_with_arcs() {
        let mut p = Plot::new("t <1>", Aspect::Equal);
        let arc = Arc2::from_centre(P2::origin(), &P2::new(1.0, 0.0), &P2::new(-1.0, 0.0), true, false);
        p.path(
            P2::new(1.0, 0.0),
            vec![Piece::Arc(arc), Piece::Line(P2::new(1.0, 0.0))],
            true,
            Style::stroke("red", 1.0),
        );
        p.dots(&[P2::new(0.0, 0.0)], 2.0, Style::fill("blue", 1.0)).legend("arc", Style::stroke("red", 1.0));
        let svg = p.to_svg(400.0);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("A") && svg.contains("t &lt;1&gt;"));
        assert_eq!(svg.matches("<svg").count(), 1);
    }

    #[test]
    fn raster_merges_runs_and_skips_nan() {
        let mut p = Plot::new("map", Aspect::Equal);
        let values = vec![0.0, 0.0, 1.0, f64::NAN, 0.5, 0.5];
        p.raster(Raster { origin: P2::new(0.0, 0.0), cell: (1.0, 1.0), nx: 3, ny: 2, values, range: (0.0, 1.0) });
        let svg = p.to_svg(300.0);
        // Row 0: two runs; row 1: the NaN is skipped and the two 0.5 cells merge.
        assert_eq!(svg.matches("fill=\"#").count(), 3, "{svg}");
        assert_eq!(ramp(0.0), (68, 1, 84));
        assert_eq!(ramp(1.0), (253, 231, 37));
    }

    #[test]
    fn ticks_are_round() {
        let t = ticks(0.0, 62.8);
        assert_eq!(t.first().unwrap().1, "0");
        assert!(t.iter().any(|(_, l)| l == "60"));
    }
}
