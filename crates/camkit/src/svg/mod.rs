//! SVG plots written by the project: paths (lines and exact arcs), points, circles, filled
//! regions, height maps and value-coloured paths in world coordinates (mm), with axes, ticks, a
//! colour bar, a legend and a title. Equal aspect for geometry; independent axis scales for
//! charts. Panels of several plots in one SVG and 3-D views are in [`figure`].
//!
//! The legend is made from the marks: a mark drawn with a [`Style::named`] style adds its name,
//! so the legend cannot list what is not drawn. Every height map and value-coloured path is
//! drawn with a colour bar whose range is the data's (or the one the plot fixes). Polylines are
//! thinned to a quarter pixel and dots to half a pixel, so a plot's size is bounded by what can
//! be seen.

pub mod figure;
pub mod inspect;
pub mod relief;
mod simplify;

use crate::geom::{Arc2, P2};
use std::collections::{BTreeMap, HashSet};
use std::fmt::Write;
use std::hash::{Hash, Hasher};

/// Largest distance (pixels) of a dropped polyline point from the drawn line.
pub const THIN_PX: f64 = 0.25;

/// Colour levels of height maps and value-coloured paths (and of the colour bar).
pub const LEVELS: usize = 32;

/// How a mark is drawn, and the legend entry it makes.
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
    /// Legend text of the marks drawn so; empty for marks not in the legend.
    pub name: String,
}

impl Style {
    /// A solid stroke.
    pub fn stroke(colour: &str, width: f64) -> Style {
        Style {
            stroke: colour.into(),
            width,
            fill: "none".into(),
            dash: String::new(),
            opacity: 1.0,
            name: String::new(),
        }
    }

    /// A filled shape without outline.
    pub fn fill(colour: &str, opacity: f64) -> Style {
        Style {
            stroke: "none".into(),
            width: 0.0,
            fill: colour.into(),
            dash: String::new(),
            opacity,
            name: String::new(),
        }
    }

    /// The same style dashed.
    pub fn dashed(mut self, dash: &str) -> Style {
        self.dash = dash.into();
        self
    }

    /// The same style with a legend entry: the legend lists `name` once a mark is drawn so.
    pub fn named(mut self, name: &str) -> Style {
        self.name = name.into();
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
        if !self.name.is_empty() {
            let _ = write!(s, r#" data-series="{}""#, escape(&self.name));
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
    /// A polyline coloured segment by segment by the mean of its end points' values.
    Heat {
        pts: Vec<P2>,
        values: Vec<f64>,
        width: f64,
    },
}

/// A colour map of values on a regular grid (a height map), drawn as cells coloured on the
/// plot's colour bar.
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

/// `#rrggbb` of colour level `level` (of [`LEVELS`]).
fn level_colour(level: usize) -> String {
    let (r, g, b) = ramp((level as f64 + 0.5) / LEVELS as f64);
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The colour level of `v` on `range`: the middle one for an empty range, none for NaN.
fn level_of(v: f64, range: (f64, f64)) -> Option<usize> {
    let span = range.1 - range.0;
    v.is_finite().then(|| {
        let t = if span > 0.0 { (v - range.0) / span } else { 0.5 };
        ((t * LEVELS as f64).floor().max(0.0) as usize).min(LEVELS - 1)
    })
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
    axes: bool,
    marks: Vec<Mark>,
    bar_label: String,
    bar_range: Option<(f64, f64)>,
    min: P2,
    max: P2,
}

/// A plot rendered: the SVG elements, its size in pixels.
struct Rendered {
    body: String,
    width: f64,
    height: f64,
}

impl Plot {
    /// An empty plot with a title.
    pub fn new(title: &str, aspect: Aspect) -> Plot {
        Plot {
            title: title.into(),
            x_label: "x (mm)".into(),
            y_label: "y (mm)".into(),
            aspect,
            axes: true,
            marks: Vec::new(),
            bar_label: "value".into(),
            bar_range: None,
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

    /// Leaves out the frame, ticks and axis labels (a projection whose screen axes are no world
    /// axes).
    pub fn without_axes(&mut self) -> &mut Self {
        self.axes = false;
        self
    }

    /// The colour bar's label, with its unit (`z (mm)`); drawn whenever a height map or a
    /// value-coloured path is.
    pub fn colour_bar(&mut self, label: &str) -> &mut Self {
        self.bar_label = label.into();
        self
    }

    /// Fixes the colour bar's range (else it is the range of the coloured values).
    pub fn colour_range(&mut self, lo: f64, hi: f64) -> &mut Self {
        self.bar_range = Some((lo.min(hi), lo.max(hi)));
        self
    }

    fn grow(&mut self, p: &P2) {
        if p.x.is_finite() && p.y.is_finite() {
            self.min = P2::new(self.min.x.min(p.x), self.min.y.min(p.y));
            self.max = P2::new(self.max.x.max(p.x), self.max.y.max(p.y));
        }
    }

    /// A polyline (nothing for fewer than two points).
    pub fn polyline(&mut self, pts: &[P2], style: Style) -> &mut Self {
        if pts.len() >= 2 {
            let pieces = pts[1..].iter().map(|p| Piece::Line(*p)).collect();
            self.path(pts[0], pieces, false, style);
        }
        self
    }

    /// A closed polygon, filled if the style fills (nothing for fewer than three points).
    pub fn polygon(&mut self, pts: &[P2], style: Style) -> &mut Self {
        if pts.len() >= 3 {
            let pieces = pts[1..].iter().map(|p| Piece::Line(*p)).collect();
            self.path(pts[0], pieces, true, style);
        }
        self
    }

    /// A path of lines and arcs from `start` (nothing without pieces).
    pub fn path(&mut self, start: P2, pieces: Vec<Piece>, closed: bool, style: Style) -> &mut Self {
        if pieces.is_empty() {
            return self;
        }
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

    /// Dots of a fixed size in pixels (nothing for no points).
    pub fn dots(&mut self, pts: &[P2], radius_px: f64, style: Style) -> &mut Self {
        if pts.is_empty() {
            return self;
        }
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

    /// Text at a world position (inside the plotted range).
    pub fn label(&mut self, at: P2, text: &str, size_px: f64, colour: &str) -> &mut Self {
        self.grow(&at);
        self.marks.push(Mark::Label { at, text: text.into(), size_px, colour: colour.into() });
        self
    }

    /// A colour map of grid values (see [`Raster`]); runs of one colour level along a row are
    /// drawn as one rectangle, so keep the grid to a few hundred cells a side.
    pub fn raster(&mut self, raster: Raster) -> &mut Self {
        self.grow(&raster.origin);
        self.grow(&P2::new(
            raster.origin.x + raster.cell.0 * raster.nx as f64,
            raster.origin.y + raster.cell.1 * raster.ny as f64,
        ));
        self.marks.push(Mark::Raster(raster));
        self
    }

    /// A polyline coloured by `values` (one per point) on the colour bar; runs of one colour
    /// level are drawn as one path per level.
    pub fn heat(&mut self, pts: &[P2], values: &[f64], width: f64) -> &mut Self {
        if pts.len() >= 2 && pts.len() == values.len() {
            for p in pts {
                self.grow(p);
            }
            self.marks.push(Mark::Heat { pts: pts.to_vec(), values: values.to_vec(), width });
        }
        self
    }

    /// Makes sure `p` is inside the plotted range.
    pub fn include(&mut self, p: P2) -> &mut Self {
        self.grow(&p);
        self
    }

    /// The legend: each style name once, in the order first drawn, with its first style.
    fn legend(&self) -> Vec<&Style> {
        let mut seen = HashSet::new();
        self.marks
            .iter()
            .filter_map(|m| match m {
                Mark::Path { style, .. } | Mark::Dots { style, .. } | Mark::Circle { style, .. } => Some(style),
                _ => None,
            })
            .filter(|s| !s.name.is_empty() && seen.insert(s.name.as_str()))
            .collect()
    }

    /// The range of the colour bar: the fixed one, or that of the coloured values; `None` when
    /// nothing is coloured.
    fn colour_scale(&self) -> Option<(f64, f64)> {
        let mut coloured = false;
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for m in &self.marks {
            let values = match m {
                Mark::Raster(r) => &r.values,
                Mark::Heat { values, .. } => values,
                _ => continue,
            };
            coloured = true;
            for &v in values.iter().filter(|v| v.is_finite()) {
                (lo, hi) = (lo.min(v), hi.max(v));
            }
        }
        match (coloured, self.bar_range) {
            (false, _) => None,
            (true, Some(r)) => Some(r),
            (true, None) if lo.is_finite() => Some((lo, hi)),
            (true, None) => Some((0.0, 0.0)),
        }
    }

    /// The SVG document, `width` pixels wide.
    pub fn to_svg(&self, width: f64) -> String {
        let r = self.render(width);
        document(r.width, r.height, &r.body)
    }

    /// The plot's elements for a box `width` pixels wide.
    fn render(&self, width: f64) -> Rendered {
        let (mut min, mut max) = (self.min, self.max);
        if !min.x.is_finite() {
            (min, max) = (P2::new(0.0, 0.0), P2::new(1.0, 1.0));
        }
        let scale = self.colour_scale();
        let span = |a: f64, b: f64| if b - a > 0.0 { b - a } else { 1.0 };
        // A point's extent is widened by half a unit, so that a single point has a frame.
        if max.x - min.x <= 0.0 {
            (min.x, max.x) = (min.x - 0.5, max.x + 0.5);
        }
        if max.y - min.y <= 0.0 {
            (min.y, max.y) = (min.y - 0.5, max.y + 0.5);
        }
        let (w_world, h_world) = (span(min.x, max.x), span(min.y, max.y));
        let bar_w = if scale.is_some() { 110.0 } else { 0.0 };
        let pad = if self.axes { (72.0, 24.0 + bar_w, 56.0, 48.0) } else { (16.0, 16.0 + bar_w, 16.0, 40.0) };
        let frame_w = width - pad.0 - pad.1;
        let (sx, sy, frame_h) = match self.aspect {
            Aspect::Equal => {
                let s = frame_w / w_world;
                let fh = (h_world * s).clamp(if scale.is_some() { 160.0 } else { 40.0 }, 4.0 * width);
                (s, fh / h_world, fh)
            }
            Aspect::Free => {
                let fh = 0.6 * frame_w;
                (frame_w / w_world, fh / h_world, fh)
            }
        };
        // With a clamped height the world is centred vertically in the frame.
        let y_shift = 0.5 * (frame_h - h_world * sy);
        let legend = self.legend();
        let legend_h = 18.0 * legend.len() as f64;
        let height = pad.3 + frame_h + pad.2 + legend_h;
        let tx = |x: f64| pad.0 + (x - min.x) * sx;
        let ty = |y: f64| pad.3 + frame_h - y_shift - (y - min.y) * sy;
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<text x="{:.1}" y="20" font-size="15" text-anchor="middle">{}</text>"#,
            width / 2.0,
            escape(&self.title)
        );
        if self.axes {
            axes(&mut s, self, (min, max), pad, (frame_w, frame_h), &tx, &ty);
        }
        let mut drawn = Drawn::new();
        let mut heat_drawn = false;
        for mark in &self.marks {
            match mark {
                Mark::Path { start, pieces, closed, style } => {
                    // Only open, unfilled paths skip segments drawn before (a fill needs its outline).
                    let key = (!*closed && style.fill == "none").then(|| style_key(style));
                    let d = path_data(*start, pieces, *closed, &tx, &ty, (sx, sy), &mut drawn, key);
                    let _ = writeln!(s, r#"<path d="{d}" {} stroke-linejoin="round"/>"#, style.attrs());
                }
                Mark::Dots { pts, radius_px, style } => {
                    let _ = write!(s, "<g {}>", style.attrs());
                    let mut seen = HashSet::new();
                    for p in pts {
                        let (x, y) = (tx(p.x), ty(p.y));
                        if x.is_finite() && y.is_finite() && seen.insert(((x * 2.0) as i64, (y * 2.0) as i64)) {
                            let _ = write!(s, r#"<circle cx="{x:.1}" cy="{y:.1}" r="{radius_px}"/>"#);
                        }
                    }
                    let _ = writeln!(s, "</g>");
                }
                Mark::Circle { c, r, style } => {
                    let _ = writeln!(
                        s,
                        r#"<ellipse cx="{:.2}" cy="{:.2}" rx="{:.2}" ry="{:.2}" {}/>"#,
                        tx(c.x),
                        ty(c.y),
                        r * sx,
                        r * sy,
                        style.attrs()
                    );
                }
                Mark::Raster(r) => raster(&mut s, r, scale.unwrap_or((0.0, 0.0)), &tx, &ty),
                // All value-coloured paths, batched by colour, where the first one was drawn.
                Mark::Heat { .. } if !heat_drawn => {
                    heat(&mut s, &self.marks, scale.unwrap_or((0.0, 0.0)), &tx, &ty);
                    heat_drawn = true;
                }
                Mark::Heat { .. } => {}
                Mark::Label { at, text, size_px, colour } => {
                    let _ = writeln!(
                        s,
                        r#"<text x="{:.1}" y="{:.1}" font-size="{size_px}" fill="{colour}">{}</text>"#,
                        tx(at.x),
                        ty(at.y),
                        escape(text)
                    );
                }
            }
        }
        if let Some(range) = scale {
            colour_bar(&mut s, range, &self.bar_label, (pad.0 + frame_w + 24.0, pad.3), frame_h);
        }
        for (k, style) in legend.into_iter().enumerate() {
            let y = pad.3 + frame_h + pad.2 + 18.0 * k as f64 + 4.0;
            let mut swatch = style.clone();
            swatch.name.clear();
            swatch.width = swatch.width.max(2.0);
            swatch.opacity = swatch.opacity.max(0.5);
            if swatch.stroke == "none" {
                swatch.stroke = swatch.fill.clone();
                swatch.width = 8.0;
            }
            let _ = writeln!(
                s,
                r#"<g class="legend-entry" data-series="{}"><line x1="{}" y1="{y:.1}" x2="{}" y2="{y:.1}" {}/><text x="{}" y="{:.1}" font-size="12">{}</text></g>"#,
                escape(&style.name),
                pad.0,
                pad.0 + 28.0,
                swatch.attrs(),
                pad.0 + 36.0,
                y + 4.0,
                escape(&style.name)
            );
        }
        Rendered { body: s, width, height }
    }
}

/// A whole SVG document around `body`.
fn document(width: f64, height: f64, body: &str) -> String {
    let mut s = String::with_capacity(body.len() + 256);
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif">"#
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    s.push_str(body);
    s.push_str("</svg>\n");
    s
}

/// The frame, grid, ticks and axis labels.
fn axes(
    s: &mut String,
    p: &Plot,
    (min, max): (P2, P2),
    pad: (f64, f64, f64, f64),
    (frame_w, frame_h): (f64, f64),
    tx: &dyn Fn(f64) -> f64,
    ty: &dyn Fn(f64) -> f64,
) {
    let _ = writeln!(
        s,
        r##"<rect x="{}" y="{}" width="{frame_w:.1}" height="{frame_h:.1}" fill="none" stroke="#888" stroke-width="1"/>"##,
        pad.0, pad.3
    );
    for (t, label) in ticks(min.x, max.x) {
        let x = tx(t);
        let _ = writeln!(
            s,
            r##"<line x1="{x:.1}" y1="{:.1}" x2="{x:.1}" y2="{:.1}" stroke="#ddd"/><text x="{x:.1}" y="{:.1}" font-size="11" text-anchor="middle">{label}</text>"##,
            pad.3,
            pad.3 + frame_h,
            pad.3 + frame_h + 16.0
        );
    }
    for (t, label) in ticks(min.y, max.y) {
        let y = ty(t);
        if y < pad.3 - 0.5 || y > pad.3 + frame_h + 0.5 {
            continue;
        }
        let _ = writeln!(
            s,
            r##"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" font-size="11" text-anchor="end">{label}</text>"##,
            pad.0,
            pad.0 + frame_w,
            pad.0 - 6.0,
            y + 4.0
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle">{}</text>"#,
        pad.0 + frame_w / 2.0,
        pad.3 + frame_h + 36.0,
        escape(&p.x_label)
    );
    let _ = writeln!(
        s,
        r#"<text x="14" y="{:.1}" font-size="12" text-anchor="middle" transform="rotate(-90 14 {:.1})">{}</text>"#,
        pad.3 + frame_h / 2.0,
        pad.3 + frame_h / 2.0,
        escape(&p.y_label)
    );
}

/// Pieces already drawn, by style and pixels (halves of a pixel): a segment's ends either way,
/// an arc's ends, centre and sense.
type Drawn = HashSet<(u64, [i64; 7])>;

/// Path data being written: the pen skips pieces drawn before in the same style (`key`) and
/// moves on to the next piece it draws.
struct Pen<'a> {
    d: String,
    drawn: &'a mut Drawn,
    key: Option<u64>,
    lifted: bool,
}

impl Pen<'_> {
    /// Draws a piece from `from` with signature `sig`, written by `cmd`, unless drawn before.
    fn piece(&mut self, from: (f64, f64), sig: [i64; 7], cmd: impl FnOnce(&mut String)) {
        if self.key.is_some_and(|k| !self.drawn.insert((k, sig))) {
            self.lifted = true;
            return;
        }
        if self.lifted {
            let _ = write!(self.d, "M{:.1} {:.1}", from.0, from.1);
            self.lifted = false;
        }
        cmd(&mut self.d);
    }
}

/// Half-pixel units of a screen coordinate.
fn half_px(v: f64) -> i64 {
    (v * 2.0).round() as i64
}

/// Path data of a path mark. Runs of straight pieces are thinned to [`THIN_PX`]; consecutive
/// arcs on one circle are drawn as one; a piece already drawn in the same style (`key`, if
/// given) on the same pixels is skipped (the layers of a pocket seen from above are drawn once).
#[allow(clippy::too_many_arguments)]
fn path_data(
    start: P2,
    pieces: &[Piece],
    closed: bool,
    tx: &dyn Fn(f64) -> f64,
    ty: &dyn Fn(f64) -> f64,
    (sx, sy): (f64, f64),
    drawn: &mut Drawn,
    key: Option<u64>,
) -> String {
    let screen = |p: P2| (tx(p.x), ty(p.y));
    let mut pen = Pen { d: format!("M{:.1} {:.1}", tx(start.x), ty(start.y)), drawn, key, lifted: false };
    let mut run = vec![screen(start)];
    let mut arc: Option<Arc2> = None;
    let lines = |pen: &mut Pen, run: &mut Vec<(f64, f64)>| {
        for w in simplify::simplify(run, THIN_PX).windows(2) {
            let (a, b) = ([half_px(w[0].0), half_px(w[0].1)], [half_px(w[1].0), half_px(w[1].1)]);
            let sig = if a <= b { [a[0], a[1], b[0], b[1], 0, 0, 0] } else { [b[0], b[1], a[0], a[1], 0, 0, 0] };
            pen.piece(w[0], sig, |d| {
                let _ = write!(d, "L{:.1} {:.1}", w[1].0, w[1].1);
            });
        }
        let last = run.last().copied();
        run.clear();
        run.extend(last);
    };
    let arcs = |pen: &mut Pen, arc: &mut Option<Arc2>| {
        if let Some(a) = arc.take() {
            let (p, q) = (screen(a.point_at_fraction(0.0)), screen(a.point_at_fraction(1.0)));
            let sig = [
                half_px(p.0),
                half_px(p.1),
                half_px(q.0),
                half_px(q.1),
                half_px(tx(a.c.x)),
                half_px(ty(a.c.y)),
                a.sweep.signum() as i64,
            ];
            pen.piece(p, sig, |d| arc_commands(d, &a, tx, ty, sx, sy));
        }
    };
    for p in pieces {
        match p {
            Piece::Line(q) => {
                arcs(&mut pen, &mut arc);
                run.push(screen(*q));
            }
            Piece::Arc(a) => {
                lines(&mut pen, &mut run);
                let same_circle =
                    |b: &Arc2| ((b.c - a.c).norm() * sx).max((b.r - a.r).abs() * sx) < 0.05 && b.sweep * a.sweep > 0.0;
                match &mut arc {
                    Some(b) if same_circle(b) => b.sweep += a.sweep,
                    _ => {
                        arcs(&mut pen, &mut arc);
                        arc = Some(*a);
                    }
                }
                run = vec![screen(a.point_at_fraction(1.0))];
            }
        }
    }
    arcs(&mut pen, &mut arc);
    lines(&mut pen, &mut run);
    if closed {
        pen.d.push('Z');
    }
    pen.d
}

/// A key telling styles apart for [`Drawn`].
fn style_key(style: &Style) -> u64 {
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (&style.stroke, style.width.to_bits(), &style.fill, &style.dash, style.opacity.to_bits()).hash(&mut h);
    h.finish()
}

/// The cells of a height map, one path of rectangles per colour level.
fn raster(s: &mut String, r: &Raster, range: (f64, f64), tx: &dyn Fn(f64) -> f64, ty: &dyn Fn(f64) -> f64) {
    let mut by_level: BTreeMap<usize, String> = BTreeMap::new();
    for j in 0..r.ny {
        let (y0, y1) = (r.origin.y + r.cell.1 * j as f64, r.origin.y + r.cell.1 * (j + 1) as f64);
        let mut i = 0;
        while i < r.nx {
            let Some(l) = level_of(r.values[j * r.nx + i], range) else {
                i += 1;
                continue;
            };
            let mut e = i + 1;
            while e < r.nx && level_of(r.values[j * r.nx + e], range) == Some(l) {
                e += 1;
            }
            let (x0, x1) = (r.origin.x + r.cell.0 * i as f64, r.origin.x + r.cell.0 * e as f64);
            let d = by_level.entry(l).or_default();
            let _ = write!(d, "M{:.1} {:.1}H{:.1}V{:.1}H{:.1}z", tx(x0), ty(y1), tx(x1), ty(y0), tx(x0));
            i = e;
        }
    }
    let _ = writeln!(s, r#"<g class="raster" shape-rendering="crispEdges">"#);
    for (l, d) in by_level {
        let _ = writeln!(s, r#"<path fill="{}" d="{d}"/>"#, level_colour(l));
    }
    let _ = writeln!(s, "</g>");
}

/// The value-coloured polylines: segments binned by colour level (and width), each bin one path
/// of thinned runs.
fn heat(s: &mut String, marks: &[Mark], range: (f64, f64), tx: &dyn Fn(f64) -> f64, ty: &dyn Fn(f64) -> f64) {
    let mut bins: BTreeMap<(usize, u64), String> = BTreeMap::new();
    for m in marks {
        let Mark::Heat { pts, values, width } = m else { continue };
        let mut run: Vec<(f64, f64)> = Vec::new();
        let mut run_level = None;
        let mut flush = |run: &mut Vec<(f64, f64)>, level: Option<usize>| {
            if let (Some(l), true) = (level, run.len() >= 2) {
                let d = bins.entry((l, width.to_bits())).or_default();
                for (k, (x, y)) in simplify::simplify(run, THIN_PX).iter().enumerate() {
                    let _ = write!(d, "{}{x:.1} {y:.1}", if k == 0 { 'M' } else { 'L' });
                }
            }
            run.clear();
        };
        for k in 1..pts.len() {
            let level = level_of(0.5 * (values[k - 1] + values[k]), range);
            if level != run_level || run.is_empty() {
                flush(&mut run, run_level);
                run_level = level;
                run.push((tx(pts[k - 1].x), ty(pts[k - 1].y)));
            }
            run.push((tx(pts[k].x), ty(pts[k].y)));
        }
        flush(&mut run, run_level);
    }
    if bins.is_empty() {
        return;
    }
    let _ = writeln!(s, r#"<g class="heat" fill="none" stroke-linejoin="round" stroke-linecap="round">"#);
    for ((l, w), d) in bins {
        let _ = writeln!(s, r#"<path stroke="{}" stroke-width="{}" d="{d}"/>"#, level_colour(l), f64::from_bits(w));
    }
    let _ = writeln!(s, "</g>");
}

/// The colour bar: the levels from low (bottom) to high, ticks and the label with its unit.
fn colour_bar(s: &mut String, range: (f64, f64), label: &str, (x, y): (f64, f64), h: f64) {
    let w = 16.0;
    let _ = writeln!(
        s,
        r#"<g class="colour-bar" data-min="{}" data-max="{}" data-label="{}" shape-rendering="crispEdges">"#,
        range.0,
        range.1,
        escape(label)
    );
    let span = range.1 - range.0;
    if span > 0.0 {
        let step = h / LEVELS as f64;
        for l in 0..LEVELS {
            let top = y + h - step * (l + 1) as f64;
            let _ = writeln!(
                s,
                r#"<rect x="{x:.1}" y="{top:.2}" width="{w}" height="{:.2}" fill="{}"/>"#,
                step + 0.3,
                level_colour(l)
            );
        }
    } else {
        let _ = writeln!(
            s,
            r#"<rect x="{x:.1}" y="{y:.1}" width="{w}" height="{h:.1}" fill="{}"/>"#,
            level_colour(LEVELS / 2)
        );
    }
    let _ = writeln!(s, r##"<rect x="{x:.1}" y="{y:.1}" width="{w}" height="{h:.1}" fill="none" stroke="#888"/>"##);
    let at = |v: f64| if span > 0.0 { y + h - (v - range.0) / span * h } else { y + h / 2.0 };
    for (t, text) in ticks(range.0, range.1) {
        let ty = at(t);
        let _ = writeln!(
            s,
            r#"<line x1="{:.1}" y1="{ty:.1}" x2="{:.1}" y2="{ty:.1}" stroke="black"/><text x="{:.1}" y="{:.1}" font-size="11">{text}</text>"#,
            x + w,
            x + w + 4.0,
            x + w + 6.0,
            ty + 4.0
        );
    }
    let lx = x + w + 66.0;
    let _ = writeln!(
        s,
        r#"<text x="{lx:.1}" y="{:.1}" font-size="12" text-anchor="middle" transform="rotate(-90 {lx:.1} {:.1})">{}</text></g>"#,
        y + h / 2.0,
        y + h / 2.0,
        escape(label)
    );
}

/// SVG arc commands for an arc; it is split into pieces under 180° (SVG needs an unambiguous
/// large-arc flag).
fn arc_commands(d: &mut String, a: &Arc2, tx: &dyn Fn(f64) -> f64, ty: &dyn Fn(f64) -> f64, sx: f64, sy: f64) {
    let parts = ((a.sweep.abs() / (0.99 * std::f64::consts::PI)).ceil() as usize).max(1);
    for k in 1..=parts {
        let e = a.point_at(a.start + a.sweep * k as f64 / parts as f64);
        // y is flipped on screen, so counter-clockwise in the world is clockwise on screen.
        let sweep_flag = if a.sweep > 0.0 { 0 } else { 1 };
        let _ = write!(d, "A{:.2} {:.2} 0 0 {sweep_flag} {:.2} {:.2}", a.r * sx, a.r * sy, tx(e.x), ty(e.y));
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
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
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
            Style::stroke("red", 1.0).named("arc"),
        );
        p.dots(&[P2::new(0.0, 0.0)], 2.0, Style::fill("blue", 1.0));
        let svg = p.to_svg(400.0);
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>\n"));
        assert!(svg.contains("A") && svg.contains("t &lt;1&gt;"));
        let seen = inspect::inspect(&svg).unwrap();
        assert_eq!(seen.legend, vec!["arc"]);
    }

    #[test]
    fn the_legend_lists_exactly_the_drawn_names() {
        let mut p = Plot::new("legend", Aspect::Equal);
        let a = Style::stroke("red", 1.0).named("a");
        p.polyline(&[P2::new(0.0, 0.0), P2::new(1.0, 1.0)], a.clone());
        p.polyline(&[P2::new(0.0, 1.0), P2::new(1.0, 0.0)], a);
        // Nothing drawn: no legend entry.
        p.polyline(&[P2::new(0.0, 0.0)], Style::stroke("blue", 1.0).named("b"));
        p.polygon(&[], Style::fill("green", 1.0).named("c"));
        p.dots(&[P2::new(0.5, 0.5)], 2.0, Style::fill("black", 1.0).named("d"));
        let seen = inspect::inspect(&p.to_svg(300.0)).unwrap();
        assert_eq!(seen.legend, vec!["a", "d"]);
        assert_eq!(seen.drawn.iter().collect::<Vec<_>>(), vec!["a", "d"]);
    }

    #[test]
    fn raster_merges_runs_skips_nan_and_spans_the_colour_bar() {
        let mut p = Plot::new("map", Aspect::Equal);
        let values = vec![0.0, 0.0, 1.0, f64::NAN, 0.5, 0.5];
        p.raster(Raster { origin: P2::new(0.0, 0.0), cell: (1.0, 1.0), nx: 3, ny: 2, values }).colour_bar("h (mm)");
        let svg = p.to_svg(300.0);
        // Row 0: two runs; row 1: the NaN is skipped and the two 0.5 cells merge: three
        // rectangles in three levels.
        let cells = svg.split(r#"class="raster""#).nth(1).unwrap().split("</g>").next().unwrap();
        assert_eq!(cells.matches('z').count(), 3, "{svg}");
        let seen = inspect::inspect(&svg).unwrap();
        assert_eq!(seen.bars, vec![(0.0, 1.0, "h (mm)".to_string())]);
        assert_eq!(ramp(0.0), (68, 1, 84));
        assert_eq!(ramp(1.0), (253, 231, 37));
    }

    #[test]
    fn a_flat_map_has_one_colour_and_a_one_value_bar() {
        let mut p = Plot::new("flat", Aspect::Equal);
        p.raster(Raster { origin: P2::new(0.0, 0.0), cell: (1.0, 1.0), nx: 2, ny: 2, values: vec![3.0; 4] });
        let svg = p.to_svg(300.0);
        let seen = inspect::inspect(&svg).unwrap();
        assert_eq!(seen.bars[0].0, 3.0);
        assert_eq!(seen.bars[0].1, 3.0);
        // One cell colour: the middle level, drawn as one path.
        let cells = svg.split(r#"class="raster""#).nth(1).unwrap().split("</g>").next().unwrap();
        assert_eq!(cells.matches("<path").count(), 1);
    }

    #[test]
    fn heat_paths_batch_by_level_and_thin_to_the_pixel() {
        let mut p = Plot::new("heat", Aspect::Equal);
        // 100 000 points on a line: thinned to its ends, one colour level.
        let pts: Vec<P2> = (0..100_000).map(|i| P2::new(i as f64 * 1e-3, 0.0)).collect();
        p.heat(&pts, &vec![1.0; pts.len()], 1.0);
        let ramp_pts: Vec<P2> = (0..=10).map(|i| P2::new(i as f64 * 10.0, 10.0)).collect();
        let values: Vec<f64> = (0..=10).map(|i| i as f64).collect();
        p.heat(&ramp_pts, &values, 1.0).colour_bar("z (mm)");
        let svg = p.to_svg(600.0);
        assert!(svg.len() < 8_000, "{} bytes", svg.len());
        let seen = inspect::inspect(&svg).unwrap();
        assert_eq!(seen.bars, vec![(0.0, 10.0, "z (mm)".to_string())]);
    }

    #[test]
    fn ticks_are_round() {
        let t = ticks(0.0, 62.8);
        assert_eq!(t.first().unwrap().1, "0");
        assert!(t.iter().any(|(_, l)| l == "60"));
    }
}
