//! Closed contours from an SVG drawing: `path`, `rect`, `circle`, `ellipse`, `polygon`,
//! `polyline` and `line` elements (with every ancestor's `transform`), as the same
//! [`crate::dxf::Read`] a DXF drawing gives, so that both go the same way into the toolpath table.
//!
//! Units: a user unit is 1/96 in (0.2645833 mm) unless the root's `width`/`height` carry a unit
//! (mm, cm, in, pt, pc, px), in which case the `viewBox` is scaled onto them (an Inkscape drawing
//! with `width="100mm"` and `viewBox="0 0 100 100"` is in mm). The y axis is turned up: a point's
//! mm coordinates are measured from the bottom-left corner of the viewBox. Lines stay lines,
//! circular arcs stay arcs (a `circle` is a full circle of two half arcs from its rightmost point
//! after the transform, counter-clockwise like a DXF CIRCLE); cubic and quadratic Béziers and
//! elliptical arcs become lines and arcs within the tolerance ([`super::curve`]). Inkscape layers
//! (`g` with `inkscape:groupmode="layer"`) are named by their `inkscape:label`, other groups by
//! their `id`. Parsed with roxmltree and svgtypes (path data, transforms and lengths in f64).

use super::Vertex;
use super::curve::{self, Bezier, Ellipse};
use crate::contour::Contour;
use crate::dxf::{Closed, Options, Piece, Read};
use crate::error::{Error, Location, Result};
use crate::geom::{P2, V2, arc::angle_of, cross2};
use std::f64::consts::{PI, TAU};
use std::str::FromStr;

const INKSCAPE: &str = "http://www.inkscape.org/namespaces/inkscape";

/// An affine map `(x, y) ↦ (a x + c y + e, b x + d y + f)`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Affine([f64; 6]);

impl Affine {
    fn point(&self, x: f64, y: f64) -> P2 {
        let [a, b, c, d, e, f] = self.0;
        P2::new(a * x + c * y + e, b * x + d * y + f)
    }

    fn vector(&self, x: f64, y: f64) -> V2 {
        let [a, b, c, d, ..] = self.0;
        V2::new(a * x + c * y, b * x + d * y)
    }

    /// This map after `inner` (`self ∘ inner`).
    fn after(&self, inner: &Affine) -> Affine {
        let [a, b, c, d, e, f] = self.0;
        let [a2, b2, c2, d2, e2, f2] = inner.0;
        Affine([
            a * a2 + c * b2,
            b * a2 + d * b2,
            a * c2 + c * d2,
            b * c2 + d * d2,
            a * e2 + c * f2 + e,
            b * e2 + d * f2 + f,
        ])
    }
}

/// What one element adds: closed contours, open pieces, and the line it is on.
struct Sink<'a> {
    name: &'a str,
    opts: &'a Options,
    closed: Vec<Closed>,
    pieces: Vec<Piece>,
    out: Read,
    line: u64,
}

/// Reads the closed contours of the SVG text `text` (file `name`).
pub fn read(name: &str, text: &str, opts: &Options) -> Result<Read> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let pos = e.pos();
        Error::input(format!("not well-formed XML: {e}"))
            .at(Location::file(name).line(u64::from(pos.row)).column(u64::from(pos.col)))
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "svg" {
        return Err(Error::input(format!("not an SVG document: the root element is <{}>", root.tag_name().name()))
            .at(Location::file(name).line(1)));
    }
    let view = page(name, &doc, root)?;
    let mut sink = Sink { name, opts, closed: Vec::new(), pieces: Vec::new(), out: Read::default(), line: 1 };
    walk(&doc, root, view, opts.layers.is_empty(), &mut sink)?;
    let Sink { closed, pieces, mut out, .. } = sink;
    crate::dxf::finish(name, closed, &pieces, &mut out)?;
    Ok(out)
}

/// The map from the root's user units to mm with y up (see the module's documentation).
fn page(name: &str, doc: &roxmltree::Document, root: roxmltree::Node) -> Result<Affine> {
    let at = || Location::file(name).line(doc.text_pos_at(root.range().start).row as u64);
    let px = 25.4 / 96.0;
    let length = |attr: &str| -> Result<Option<f64>> {
        let Some(v) = root.attribute(attr) else { return Ok(None) };
        let l =
            svgtypes::Length::from_str(v).map_err(|e| Error::input(format!("root {attr}=\"{v}\": {e}")).at(at()))?;
        use svgtypes::LengthUnit as U;
        let mm = match l.unit {
            U::None | U::Px => px,
            U::Mm => 1.0,
            U::Cm => 10.0,
            U::In => 25.4,
            U::Pt => 25.4 / 72.0,
            U::Pc => 25.4 / 6.0,
            _ => return Ok(None),
        };
        Ok(Some(l.number * mm))
    };
    let (w, h) = (length("width")?, length("height")?);
    let vb = match root.attribute("viewBox") {
        Some(v) => {
            Some(svgtypes::ViewBox::from_str(v).map_err(|e| Error::input(format!("viewBox=\"{v}\": {e}")).at(at()))?)
        }
        None => None,
    };
    Ok(match vb {
        Some(vb) => {
            let sx = w.map_or(px, |w| w / vb.w);
            let sy = h.map_or(sx, |h| h / vb.h);
            Affine([sx, 0.0, 0.0, -sy, -sx * vb.x, sy * (vb.y + vb.h)])
        }
        None => Affine([px, 0.0, 0.0, -px, 0.0, h.unwrap_or(0.0)]),
    })
}

/// Elements whose content is never drawn as it stands.
const NOT_DRAWN: [&str; 14] = [
    "defs",
    "clipPath",
    "mask",
    "pattern",
    "marker",
    "symbol",
    "metadata",
    "title",
    "desc",
    "style",
    "script",
    "linearGradient",
    "radialGradient",
    "filter",
];

fn walk(doc: &roxmltree::Document, node: roxmltree::Node, m: Affine, selected: bool, sink: &mut Sink) -> Result<()> {
    for child in node.children().filter(|c| c.is_element()) {
        let tag = child.tag_name().name();
        let line = doc.text_pos_at(child.range().start).row as u64;
        sink.line = line;
        let hidden = child.attribute("display") == Some("none")
            || child.attribute("style").is_some_and(|s| s.replace(' ', "").contains("display:none"));
        if hidden || NOT_DRAWN.contains(&tag) || child.tag_name().namespace() != node.tag_name().namespace() {
            continue;
        }
        let m = match child.attribute("transform") {
            Some(t) => {
                let t = svgtypes::Transform::from_str(t).map_err(|e| {
                    Error::input(format!("transform=\"{t}\": {e}")).at(Location::file(sink.name).line(line))
                })?;
                m.after(&Affine([t.a, t.b, t.c, t.d, t.e, t.f]))
            }
            None => m,
        };
        match tag {
            "g" | "svg" | "a" | "switch" => {
                let layer = if child.attribute((INKSCAPE, "groupmode")) == Some("layer") {
                    child.attribute((INKSCAPE, "label")).or(child.attribute("id"))
                } else {
                    child.attribute("id")
                };
                if let Some(l) = layer
                    && child.attribute((INKSCAPE, "groupmode")) == Some("layer")
                    && !sink.out.layers.iter().any(|x| x == l)
                {
                    sink.out.layers.push(l.to_string());
                }
                let chosen = selected || layer.is_some_and(|l| sink.opts.layers.iter().any(|x| x == l));
                walk(doc, child, m, chosen, sink)?;
            }
            "path" | "rect" | "circle" | "ellipse" | "polygon" | "polyline" | "line" if selected => {
                shape(child, tag, &m, sink)?;
            }
            "path" | "rect" | "circle" | "ellipse" | "polygon" | "polyline" | "line" => {}
            other => sink.out.skipped.push((other.to_string(), line)),
        }
    }
    Ok(())
}

fn shape(node: roxmltree::Node, tag: &str, m: &Affine, sink: &mut Sink) -> Result<()> {
    let at = Location::file(sink.name).line(sink.line);
    let num = |attr: &str| -> Result<f64> {
        match node.attribute(attr) {
            None => Ok(0.0),
            Some(v) => {
                let l = svgtypes::Length::from_str(v)
                    .map_err(|e| Error::input(format!("{tag} {attr}=\"{v}\": {e}")).at(at.clone()))?;
                if !matches!(l.unit, svgtypes::LengthUnit::None | svgtypes::LengthUnit::Px) {
                    return Err(Error::input(format!(
                        "{tag} {attr}=\"{v}\": only user units are read in shapes (the root's width and height carry the unit)"
                    ))
                    .at(at.clone()));
                }
                Ok(l.number)
            }
        }
    };
    match tag {
        "circle" | "ellipse" => {
            let (rx, ry) = if tag == "circle" { (num("r")?, num("r")?) } else { (num("rx")?, num("ry")?) };
            if !(rx > 0.0 && ry > 0.0) {
                return Ok(());
            }
            let e = Ellipse { c: m.point(num("cx")?, num("cy")?), u: m.vector(rx, 0.0), v: m.vector(0.0, ry) };
            let line = sink.line;
            match e.radius() {
                Some(r) => sink.closed.push((Contour::circle(e.c, r, angle_of(&e.u), true), 0.0, line, line)),
                None => {
                    let mut path = Subpath::new(e.point(0.0));
                    path.ellipse(&e, 0.0, TAU, sink)?;
                    path.close(sink);
                }
            }
        }
        "rect" => {
            let (x, y, w, h) = (num("x")?, num("y")?, num("width")?, num("height")?);
            if !(w > 0.0 && h > 0.0) {
                return Ok(());
            }
            let (mut rx, mut ry) = (node.attribute("rx").map(|_| num("rx")), node.attribute("ry").map(|_| num("ry")));
            let (rx, ry) = match (rx.take().transpose()?, ry.take().transpose()?) {
                (None, None) => (0.0, 0.0),
                (Some(r), None) | (None, Some(r)) => (r, r),
                (Some(a), Some(b)) => (a, b),
            };
            let (rx, ry) = (rx.clamp(0.0, w / 2.0), ry.clamp(0.0, h / 2.0));
            if rx == 0.0 || ry == 0.0 {
                let mut path = Subpath::new(m.point(x, y));
                for (px, py) in [(x + w, y), (x + w, y + h), (x, y + h)] {
                    path.line(m.point(px, py));
                }
                path.close(sink);
            } else {
                let mut path = Subpath::new(m.point(x + rx, y));
                let corner = |cx: f64, cy: f64, t0: f64| {
                    (Ellipse { c: m.point(cx, cy), u: m.vector(rx, 0.0), v: m.vector(0.0, ry) }, t0)
                };
                let sides = [
                    ((x + w - rx, y), corner(x + w - rx, y + ry, -PI / 2.0)),
                    ((x + w, y + h - ry), corner(x + w - rx, y + h - ry, 0.0)),
                    ((x + rx, y + h), corner(x + rx, y + h - ry, PI / 2.0)),
                    ((x, y + ry), corner(x + rx, y + ry, PI)),
                ];
                for ((px, py), (e, t0)) in sides {
                    path.line(m.point(px, py));
                    path.ellipse(&e, t0, t0 + PI / 2.0, sink)?;
                }
                path.close(sink);
            }
        }
        "line" => {
            let mut path = Subpath::new(m.point(num("x1")?, num("y1")?));
            path.line(m.point(num("x2")?, num("y2")?));
            path.end(sink);
        }
        "polygon" | "polyline" => {
            let pts: Vec<P2> = svgtypes::PointsParser::from(node.attribute("points").unwrap_or(""))
                .map(|(x, y)| m.point(x, y))
                .collect();
            let Some(first) = pts.first() else { return Ok(()) };
            let mut path = Subpath::new(*first);
            for p in &pts[1..] {
                path.line(*p);
            }
            if tag == "polygon" { path.close(sink) } else { path.end(sink) }
        }
        _ => path(node.attribute("d").unwrap_or(""), m, sink)?,
    }
    Ok(())
}

/// One subpath being built: its vertices (each with the bulge of the piece leaving it).
struct Subpath {
    verts: Vec<Vertex>,
}

impl Subpath {
    fn new(p: P2) -> Subpath {
        Subpath { verts: vec![Vertex { p, bulge: 0.0 }] }
    }

    fn line(&mut self, p: P2) {
        self.verts.push(Vertex { p, bulge: 0.0 });
    }

    /// Lines and arcs within the tolerance of the Bézier `b` (from the current point), ending
    /// exactly at its last control point.
    fn bezier(&mut self, b: &Bezier, sink: &mut Sink) -> Result<()> {
        let segs = curve::biarcs(b, sink.opts.tol, &mut sink.out.curve_deviation).map_err(|u| {
            Error::input(format!(
                "a curve cannot be approximated by arcs within {} mm near ({:.6}, {:.6}) (a cusp?)",
                sink.opts.tol, u.at.x, u.at.y
            ))
            .at(Location::file(sink.name).line(sink.line))
        })?;
        for (k, s) in segs.iter().enumerate() {
            let last = self.verts.len() - 1;
            if k > 0 {
                self.verts.push(Vertex { p: s.start(), bulge: 0.0 });
            }
            self.verts[last + usize::from(k > 0)].bulge = s.bulge();
        }
        self.verts.push(Vertex { p: b.p[b.p.len() - 1], bulge: 0.0 });
        Ok(())
    }

    /// The ellipse `e` from angle `t0` to `t1` (from the current point) to `to` (the end as
    /// given; computed from the angles when `None`).
    fn ellipse_to(&mut self, e: &Ellipse, t0: f64, t1: f64, to: Option<P2>, sink: &mut Sink) -> Result<()> {
        match e.arc(t0, t1) {
            Ok(crate::contour::Seg::Arc(a)) => {
                let last = self.verts.len() - 1;
                self.verts[last].bulge = curve::bulge_of(a.sweep);
                self.verts.push(Vertex { p: to.unwrap_or_else(|| a.end_point()), bulge: 0.0 });
            }
            Ok(s) => self.line(to.unwrap_or_else(|| s.end())),
            Err(pieces) => {
                for b in &pieces {
                    self.bezier(b, sink)?;
                }
                if let Some(to) = to {
                    let last = self.verts.len() - 1;
                    self.verts[last].p = to;
                }
            }
        }
        Ok(())
    }

    fn ellipse(&mut self, e: &Ellipse, t0: f64, t1: f64, sink: &mut Sink) -> Result<()> {
        self.ellipse_to(e, t0, t1, None, sink)
    }

    /// A closed subpath.
    fn close(self, sink: &mut Sink) {
        crate::dxf::polyline(&mut sink.closed, &mut sink.pieces, self.verts, true, 0.0, sink.line);
    }

    /// A subpath left open: closed if it ends where it starts, else pieces to chain.
    fn end(self, sink: &mut Sink) {
        if self.verts.len() > 1 {
            crate::dxf::polyline(&mut sink.closed, &mut sink.pieces, self.verts, false, 0.0, sink.line);
        }
    }
}

/// The subpaths of the path data `d`.
fn path(d: &str, m: &Affine, sink: &mut Sink) -> Result<()> {
    use svgtypes::PathSegment as S;
    let mut sub: Option<Subpath> = None;
    // Current point, subpath start and the last control point (for S and T) in user units.
    let (mut cur, mut start) = ((0.0, 0.0), (0.0, 0.0));
    let mut last_ctrl: Option<(char, (f64, f64))> = None;
    for seg in svgtypes::PathParser::from(d) {
        let seg =
            seg.map_err(|e| Error::input(format!("path data: {e}")).at(Location::file(sink.name).line(sink.line)))?;
        let here = cur;
        let rel = move |abs: bool, x: f64, y: f64| if abs { (x, y) } else { (here.0 + x, here.1 + y) };
        let mut ctrl = None;
        match seg {
            S::MoveTo { abs, x, y } => {
                if let Some(s) = sub.take() {
                    s.end(sink);
                }
                cur = rel(abs, x, y);
                start = cur;
                sub = Some(Subpath::new(m.point(cur.0, cur.1)));
            }
            S::ClosePath { .. } => {
                if let Some(s) = sub.take() {
                    s.close(sink);
                }
                cur = start;
            }
            seg => {
                let s = sub.get_or_insert_with(|| Subpath::new(m.point(cur.0, cur.1)));
                let from = cur;
                let pt = |q: (f64, f64)| m.point(q.0, q.1);
                match seg {
                    S::LineTo { abs, x, y } => cur = rel(abs, x, y),
                    S::HorizontalLineTo { abs, x } => cur = (if abs { x } else { here.0 + x }, here.1),
                    S::VerticalLineTo { abs, y } => cur = (here.0, if abs { y } else { here.1 + y }),
                    _ => {}
                }
                let reflect = |kind: char| match last_ctrl {
                    Some((k, c)) if k == kind => (2.0 * from.0 - c.0, 2.0 * from.1 - c.1),
                    _ => from,
                };
                let cubic = |c1: (f64, f64), c2: (f64, f64), to: (f64, f64)| {
                    Bezier::polynomial(vec![pt(from), pt(c1), pt(c2), pt(to)])
                };
                match seg {
                    S::LineTo { .. } | S::HorizontalLineTo { .. } | S::VerticalLineTo { .. } => s.line(pt(cur)),
                    S::CurveTo { abs, x1, y1, x2, y2, x, y } => {
                        let (c1, c2, to) = (rel(abs, x1, y1), rel(abs, x2, y2), rel(abs, x, y));
                        s.bezier(&cubic(c1, c2, to), sink)?;
                        (cur, ctrl) = (to, Some(('C', c2)));
                    }
                    S::SmoothCurveTo { abs, x2, y2, x, y } => {
                        let (c2, to) = (rel(abs, x2, y2), rel(abs, x, y));
                        s.bezier(&cubic(reflect('C'), c2, to), sink)?;
                        (cur, ctrl) = (to, Some(('C', c2)));
                    }
                    S::Quadratic { abs, x1, y1, x, y } => {
                        let (c1, to) = (rel(abs, x1, y1), rel(abs, x, y));
                        s.bezier(&Bezier::polynomial(vec![pt(from), pt(c1), pt(to)]), sink)?;
                        (cur, ctrl) = (to, Some(('Q', c1)));
                    }
                    S::SmoothQuadratic { abs, x, y } => {
                        let (c1, to) = (reflect('Q'), rel(abs, x, y));
                        s.bezier(&Bezier::polynomial(vec![pt(from), pt(c1), pt(to)]), sink)?;
                        (cur, ctrl) = (to, Some(('Q', c1)));
                    }
                    S::EllipticalArc { abs, rx, ry, x_axis_rotation, large_arc, sweep, x, y } => {
                        let to = rel(abs, x, y);
                        match arc_centre(from, to, rx.abs(), ry.abs(), x_axis_rotation.to_radians(), large_arc, sweep) {
                            None => s.line(pt(to)),
                            Some((c, u, v, t0, dt)) => {
                                let e = Ellipse { c: pt(c), u: m.vector(u.0, u.1), v: m.vector(v.0, v.1) };
                                s.ellipse_to(&e, t0, t0 + dt, Some(pt(to)), sink)?;
                            }
                        }
                        cur = to;
                    }
                    _ => {}
                }
            }
        }
        last_ctrl = ctrl;
    }
    if let Some(s) = sub.take() {
        s.end(sink);
    }
    Ok(())
}

/// SVG's endpoint arc in centre form (SVG 1.1 appendix F.6.5): centre, the semi-axes as
/// vectors, the start angle and the signed sweep; `None` for a straight line (a zero radius or
/// coincident ends).
#[allow(clippy::type_complexity)]
fn arc_centre(
    p1: (f64, f64),
    p2: (f64, f64),
    mut rx: f64,
    mut ry: f64,
    phi: f64,
    large: bool,
    sweep: bool,
) -> Option<((f64, f64), (f64, f64), (f64, f64), f64, f64)> {
    if rx == 0.0 || ry == 0.0 || (p1.0 == p2.0 && p1.1 == p2.1) {
        return None;
    }
    let (cs, sn) = (phi.cos(), phi.sin());
    let (hx, hy) = ((p1.0 - p2.0) / 2.0, (p1.1 - p2.1) / 2.0);
    let (x1, y1) = (cs * hx + sn * hy, -sn * hx + cs * hy);
    let lambda = x1 * x1 / (rx * rx) + y1 * y1 / (ry * ry);
    if lambda > 1.0 {
        rx *= lambda.sqrt();
        ry *= lambda.sqrt();
    }
    let num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1;
    let den = rx * rx * y1 * y1 + ry * ry * x1 * x1;
    let mut coef = (num / den).max(0.0).sqrt();
    if large == sweep {
        coef = -coef;
    }
    let (cx1, cy1) = (coef * rx * y1 / ry, -coef * ry * x1 / rx);
    let c = (cs * cx1 - sn * cy1 + (p1.0 + p2.0) / 2.0, sn * cx1 + cs * cy1 + (p1.1 + p2.1) / 2.0);
    let a = V2::new((x1 - cx1) / rx, (y1 - cy1) / ry);
    let b = V2::new((-x1 - cx1) / rx, (-y1 - cy1) / ry);
    let t0 = angle_of(&a);
    let mut dt = cross2(&a, &b).atan2(a.dot(&b));
    if !sweep && dt > 0.0 {
        dt -= TAU;
    } else if sweep && dt < 0.0 {
        dt += TAU;
    }
    Some((c, (rx * cs, rx * sn), (-ry * sn, ry * cs), t0, dt))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn svg(body: &str) -> String {
        format!(
            "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100mm\" height=\"80mm\" viewBox=\"0 0 100 80\">\n{body}\n</svg>\n"
        )
    }

    #[test]
    fn shapes_in_mm_with_y_up() {
        let text = svg(
            "<rect x=\"10\" y=\"10\" width=\"60\" height=\"40\"/>\n<circle cx=\"30\" cy=\"30\" r=\"5\"/>\n<text>hi</text>",
        );
        let r = read("a.svg", &text, &Options::default()).unwrap();
        assert_eq!(r.sources.len(), 2);
        assert_eq!(r.skipped, vec![("text".to_string(), 5)]);
        let rect = &r.sources[0].contour;
        assert_eq!(rect.vertices[0].p, P2::new(10.0, 70.0));
        assert_eq!(rect.vertices[2].p, P2::new(70.0, 30.0));
        assert_eq!(rect.area(), -2400.0);
        assert_eq!(r.sources[1].contour, Contour::circle(P2::new(30.0, 50.0), 5.0, 0.0, true));
        assert_eq!((r.sources[0].line, r.sources[1].line), (3, 4));
    }

    #[test]
    fn arcs_transforms_and_beziers() {
        // A 20 × 10 slot with round ends drawn with arcs in a translated group, and a bezier
        // blob scaled by 2 in 96 dpi units.
        let text = svg(
            "<g transform=\"translate(10,20)\"><path d=\"M 0 0 h 20 a 5 5 0 0 1 0 10 h -20 A 5 5 0 0 1 0 0 z\"/></g>\n\
             <path transform=\"scale(2)\" d=\"M 5 5 C 10 0 20 0 25 5 S 30 20 15 20 Q 0 20 5 5 Z\"/>",
        );
        let opts = Options { tol: 1e-4, layers: Vec::new() };
        let r = read("b.svg", &text, &opts).unwrap();
        let slot = &r.sources[0].contour;
        assert_eq!(slot.vertices.len(), 4);
        assert_eq!(slot.vertices.iter().map(|v| v.bulge).collect::<Vec<_>>(), vec![0.0, -1.0, 0.0, -1.0]);
        assert!((slot.area().abs() - (200.0 + 25.0 * PI)).abs() < 1e-9);
        assert_eq!(slot.vertices[0].p, P2::new(10.0, 60.0));
        assert!(r.curve_deviation <= 1e-4 && r.curve_deviation > 0.0);
        // The blob: its pieces end at the given points (scaled, flipped).
        let blob = &r.sources[1].contour;
        assert_eq!(blob.vertices[0].p, P2::new(10.0, 70.0));
        assert!(blob.vertices.iter().any(|v| v.p == P2::new(50.0, 70.0)));
    }

    #[test]
    fn layers_and_open_paths() {
        let text = svg(
            "<g xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" inkscape:groupmode=\"layer\" inkscape:label=\"Cut\"><circle cx=\"50\" cy=\"40\" r=\"10\"/></g>\n\
             <g id=\"notes\"><path d=\"M 0 0 L 10 0 L 10 10\"/></g>",
        );
        let only = Options { tol: 1e-3, layers: vec!["Cut".into()] };
        let r = read("l.svg", &text, &only).unwrap();
        assert_eq!((r.sources.len(), r.layers.clone()), (1, vec!["Cut".to_string()]));
        let e = read("l.svg", &text, &Options::default()).unwrap_err().to_string();
        assert!(
            e.contains("l.svg:4") && e.contains("open contour") && e.contains("is 14.142135623730951 mm away"),
            "{e}"
        );
        let e = read("x.svg", "<svg><path d=\"M 0 0 L", &Options::default()).unwrap_err().to_string();
        assert!(e.contains("XML"), "{e}");
    }
}
