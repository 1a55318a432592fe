//! Closed contours from an ASCII DXF file: LINE, ARC, CIRCLE, LWPOLYLINE and old-style
//! POLYLINE/VERTEX (with bulges), ELLIPSE and SPLINE (NURBS, as lines and arcs within
//! [`Options::tol`] by [`crate::contour::curve`]) entities of the ENTITIES section, on the layers
//! asked for, chained end to end within [`tol::DXF_JOIN`] into closed contours, as the same
//! [`Source`]s the toolpath table gives (`contour::table::pocket_regions` then nests them into
//! outer boundaries and islands).
//! Coordinates are taken as millimetres in the XY plane (extrusion +Z); errors name the DXF line.
//! A small reader of the group-code pairs: the format is two lines per value, and a reader of our
//! own gives every error its line (the `dxf` crate's errors do not carry one).

use crate::contour::curve::{self, Bezier, Ellipse};
use crate::contour::table::Source;
use crate::contour::{Contour, Seg, Vertex};
use crate::error::{Error, Location, Result};
use crate::geom::P2;
use crate::tol;

/// How a drawing is read.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Largest distance (mm) between an ELLIPSE or SPLINE and the lines and arcs made of it.
    pub tol: f64,
    /// Layers to read (all when empty).
    pub layers: Vec<String>,
}

impl Default for Options {
    fn default() -> Options {
        Options { tol: tol::CURVE_TOL, layers: Vec::new() }
    }
}

/// Contours read from a DXF file and what was left out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Read {
    /// Closed contours, in the order their first entity appears (`path` numbers them from 1).
    pub sources: Vec<Source>,
    /// Entities of other types (TEXT, INSERT, POINT, ...) skipped, with their type and line.
    pub skipped: Vec<(String, u64)>,
    /// Largest gap closed when chaining pieces (mm).
    pub largest_gap: f64,
    /// Largest proven distance (mm) between a curve (ELLIPSE, SPLINE) and its lines and arcs.
    pub curve_deviation: f64,
    /// The layers of the drawing's contour entities, in order of appearance.
    pub layers: Vec<String>,
}

/// One group: code, value and the line of the code.
struct Group<'a> {
    code: i32,
    value: &'a str,
    line: u64,
}

/// A piece of a contour to be chained, with its z and source line.
#[derive(Clone, Copy)]
pub(crate) struct Piece {
    /// The line or arc.
    pub(crate) seg: Seg,
    /// Its height.
    pub(crate) z: f64,
    /// The source line of its entity or element.
    pub(crate) line: u64,
}

fn groups<'a>(name: &str, text: &'a str) -> Result<Vec<Group<'a>>> {
    let lines: Vec<&str> = text.lines().map(|l| l.trim_end_matches('\r')).collect();
    if text.starts_with("AutoCAD Binary DXF") {
        return Err(Error::input("binary DXF is not read: save the drawing as ASCII DXF").at(Location::file(name)));
    }
    let mut out = Vec::with_capacity(lines.len() / 2);
    let mut k = 0;
    while k + 1 < lines.len() {
        let code = lines[k].trim().parse::<i32>().map_err(|_| {
            Error::input(format!("expected a DXF group code (an integer), got {:?}", lines[k].trim()))
                .at(Location::file(name).line(k as u64 + 1))
        })?;
        out.push(Group { code, value: lines[k + 1].trim(), line: k as u64 + 1 });
        k += 2;
    }
    if k < lines.len() && !lines[k].trim().is_empty() {
        return Err(Error::input("a DXF group code without its value at the end of the file")
            .at(Location::file(name).line(k as u64 + 1)));
    }
    Ok(out)
}

fn number(name: &str, g: &Group) -> Result<f64> {
    crate::num::parse_finite(g.value).map_err(|_| {
        Error::input(format!("group {} needs a number, got {:?}", g.code, g.value))
            .at(Location::file(name).line(g.line + 1))
    })
}

/// The entities of the ENTITIES section: each a type, its line and its groups.
fn entities<'a, 'g>(gs: &'g [Group<'a>]) -> Vec<(&'a str, u64, &'g [Group<'a>])> {
    let mut out = Vec::new();
    let mut k = 0;
    let mut inside = false;
    while k < gs.len() {
        let g = &gs[k];
        if g.code == 0 && g.value == "SECTION" {
            inside = gs.get(k + 1).is_some_and(|n| n.code == 2 && n.value == "ENTITIES");
            k += 1;
            continue;
        }
        if g.code == 0 && g.value == "ENDSEC" {
            inside = false;
        }
        if inside && g.code == 0 {
            let end = (k + 1..gs.len()).find(|&j| gs[j].code == 0).unwrap_or(gs.len());
            out.push((g.value, g.line, &gs[k + 1..end]));
            k = end;
            continue;
        }
        k += 1;
    }
    out
}

/// Reads the closed contours of the DXF text `text` (file `name`).
pub fn read(name: &str, text: &str, opts: &Options) -> Result<Read> {
    let gs = groups(name, text)?;
    let ents = entities(&gs);
    let mut out = Read::default();
    let mut closed: Vec<Closed> = Vec::new();
    let mut pieces: Vec<Piece> = Vec::new();
    let mut k = 0;
    while k < ents.len() {
        let (kind, line, body) = ents[k];
        k += 1;
        let at = |code: i32| body.iter().find(|g| g.code == code);
        let num = |code: i32, default: Option<f64>| -> Result<f64> {
            match (at(code), default) {
                (Some(g), _) => number(name, g),
                (None, Some(d)) => Ok(d),
                (None, None) => {
                    Err(Error::input(format!("{kind} needs group {code}")).at(Location::file(name).line(line)))
                }
            }
        };
        let contour_kind = matches!(kind, "LINE" | "ARC" | "CIRCLE" | "LWPOLYLINE" | "POLYLINE" | "ELLIPSE" | "SPLINE");
        if contour_kind {
            let layer = at(8).map_or("0", |g| g.value);
            if !out.layers.iter().any(|l| l == layer) {
                out.layers.push(layer.to_string());
            }
            if !opts.layers.is_empty() && !opts.layers.iter().any(|l| l == layer) {
                if kind == "POLYLINE" {
                    while k < ents.len() && matches!(ents[k].0, "VERTEX" | "SEQEND") {
                        k += 1;
                    }
                }
                continue;
            }
        }
        if contour_kind {
            let ez = num(230, Some(1.0))?;
            if ez < 1.0 - tol::UNIT_VECTOR_SLACK {
                return Err(Error::input(format!(
                    "{kind} with extrusion direction z = {ez}: only entities in the XY plane (extrusion +Z) are read"
                ))
                .at(Location::file(name).line(line)));
            }
        }
        match kind {
            "LINE" => {
                let a = P2::new(num(10, None)?, num(20, None)?);
                let b = P2::new(num(11, None)?, num(21, None)?);
                let (za, zb) = (num(30, Some(0.0))?, num(31, Some(0.0))?);
                if (za - zb).abs() > tol::POINT_EPS {
                    return Err(Error::input(format!("a LINE of a contour lies at one z, this one from {za} to {zb}"))
                        .at(Location::file(name).line(line)));
                }
                if (b - a).norm() > tol::POINT_EPS {
                    pieces.push(Piece { seg: Seg::Line(a, b), z: za, line });
                }
            }
            "ARC" | "CIRCLE" => {
                let c = P2::new(num(10, None)?, num(20, None)?);
                let z = num(30, Some(0.0))?;
                let r = num(40, None)?;
                if r <= tol::POINT_EPS {
                    return Err(Error::input(format!("{kind} radius must be positive, got {r}"))
                        .at(Location::file(name).line(line)));
                }
                if kind == "CIRCLE" {
                    closed.push((Contour::circle(c, r, 0.0, true), z, line, line));
                } else {
                    let (a0, a1) = (num(50, None)?.to_radians(), num(51, None)?.to_radians());
                    let mut sweep = (a1 - a0).rem_euclid(std::f64::consts::TAU);
                    if sweep <= tol::ANGLE_EPS {
                        sweep = std::f64::consts::TAU;
                    }
                    let p = c + r * crate::geom::V2::new(a0.cos(), a0.sin());
                    if sweep >= std::f64::consts::TAU - tol::ANGLE_EPS {
                        closed.push((Contour::circle(c, r, a0, true), z, line, line));
                    } else {
                        let q = c + r * crate::geom::V2::new((a0 + sweep).cos(), (a0 + sweep).sin());
                        pieces.push(Piece { seg: Seg::from_bulge(p, q, (sweep / 4.0).tan()), z, line });
                    }
                }
            }
            "LWPOLYLINE" => {
                let flags = num(70, Some(0.0))? as i64;
                let z = num(38, Some(0.0))?;
                let mut verts: Vec<Vertex> = Vec::new();
                let mut x = None;
                for g in body {
                    match g.code {
                        10 => x = Some(number(name, g)?),
                        20 => {
                            let Some(px) = x.take() else {
                                return Err(Error::input("LWPOLYLINE: a y (20) without its x (10)")
                                    .at(Location::file(name).line(g.line)));
                            };
                            verts.push(Vertex { p: P2::new(px, number(name, g)?), bulge: 0.0 });
                        }
                        42 => {
                            if let Some(v) = verts.last_mut() {
                                v.bulge = number(name, g)?;
                            }
                        }
                        _ => {}
                    }
                }
                polyline(&mut closed, &mut pieces, verts, flags & 1 == 1, z, line);
            }
            "POLYLINE" => {
                let flags = num(70, Some(0.0))? as i64;
                if flags & (8 | 16 | 64) != 0 {
                    return Err(Error::input("a 3D polyline or mesh is not a contour: only 2D POLYLINEs are read")
                        .at(Location::file(name).line(line)));
                }
                let z = num(30, Some(0.0))?;
                let mut verts = Vec::new();
                while k < ents.len() && ents[k].0 == "VERTEX" {
                    let (_, vline, vb) = ents[k];
                    let get = |code: i32| vb.iter().find(|g| g.code == code);
                    let coord = |code: i32| match get(code) {
                        Some(g) => number(name, g),
                        None => {
                            Err(Error::input(format!("VERTEX needs group {code}")).at(Location::file(name).line(vline)))
                        }
                    };
                    let bulge = match get(42) {
                        Some(g) => number(name, g)?,
                        None => 0.0,
                    };
                    verts.push(Vertex { p: P2::new(coord(10)?, coord(20)?), bulge });
                    k += 1;
                }
                if k < ents.len() && ents[k].0 == "SEQEND" {
                    k += 1;
                }
                polyline(&mut closed, &mut pieces, verts, flags & 1 == 1, z, line);
            }
            "ELLIPSE" => {
                let c = P2::new(num(10, None)?, num(20, None)?);
                let z = num(30, Some(0.0))?;
                let u = crate::geom::V2::new(num(11, None)?, num(21, None)?);
                let ratio = num(40, None)?;
                if u.norm() <= tol::POINT_EPS || !(ratio > 0.0 && ratio <= 1.0 + tol::UNIT_VECTOR_SLACK) {
                    return Err(Error::input(format!(
                        "ELLIPSE needs a major axis (11, 21) and a ratio (40) in (0, 1], got {} and {ratio}",
                        u.norm()
                    ))
                    .at(Location::file(name).line(line)));
                }
                let e = Ellipse { c, u, v: crate::geom::V2::new(-u.y, u.x) * ratio };
                let (t0, t1) = (num(41, Some(0.0))?, num(42, Some(std::f64::consts::TAU))?);
                let mut sweep = (t1 - t0).rem_euclid(std::f64::consts::TAU);
                if sweep <= tol::ANGLE_EPS {
                    sweep = std::f64::consts::TAU;
                }
                let segs = match e.arc(t0, t0 + sweep) {
                    Ok(Seg::Arc(a)) if sweep >= std::f64::consts::TAU - tol::ANGLE_EPS => {
                        closed.push((Contour::circle(c, a.r, a.start, true), z, line, line));
                        continue;
                    }
                    Ok(seg) => vec![seg],
                    Err(beziers) => curve_segs(name, line, &beziers, opts.tol, &mut out.curve_deviation)?,
                };
                curve(&mut closed, &mut pieces, segs, z, line);
            }
            "SPLINE" => {
                let beziers = spline(name, line, body)?;
                let segs = curve_segs(name, line, &beziers, opts.tol, &mut out.curve_deviation)?;
                curve(&mut closed, &mut pieces, segs, num(30, Some(0.0))?, line);
            }
            "SEQEND" | "VERTEX" => {}
            other => out.skipped.push((other.to_string(), line)),
        }
    }
    finish(name, closed, &pieces, &mut out)?;
    Ok(out)
}

/// A closed contour read from a drawing: the contour, its z, its first and last source lines.
pub(crate) type Closed = (Contour, f64, u64, u64);

/// The drawing's contours: the closed ones and the open `pieces` chained, in the order of their
/// first line, numbered from 1 as `path`.
pub(crate) fn finish(name: &str, mut closed: Vec<Closed>, pieces: &[Piece], out: &mut Read) -> Result<()> {
    let chained = chain(name, pieces, &mut out.largest_gap)?;
    closed.extend(chained);
    closed.sort_by_key(|c| c.2);
    out.sources = closed
        .into_iter()
        .enumerate()
        .map(|(i, (contour, z, line, last_line))| Source { contour, path: i as i64 + 1, z, row: 0, line, last_line })
        .collect();
    Ok(())
}

/// The lines and arcs of a curve's Bézier pieces within `tol`, the error naming the entity.
fn curve_segs(name: &str, line: u64, beziers: &[Bezier], tol: f64, worst: &mut f64) -> Result<Vec<Seg>> {
    let mut segs = Vec::new();
    for b in beziers {
        segs.extend(curve::biarcs(b, tol, worst).map_err(|u| {
            Error::input(format!(
                "the curve cannot be approximated by arcs within {tol} mm near ({:.6}, {:.6}) (a cusp?)",
                u.at.x, u.at.y
            ))
            .at(Location::file(name).line(line))
        })?);
    }
    Ok(segs)
}

/// A curve's pieces as a closed contour (when it ends where it starts) or as pieces to chain.
fn curve(closed: &mut Vec<Closed>, pieces: &mut Vec<Piece>, segs: Vec<Seg>, z: f64, line: u64) {
    let (Some(first), Some(last)) = (segs.first(), segs.last()) else { return };
    if (last.end() - first.start()).norm() <= tol::DXF_JOIN {
        closed.push((Contour::from_segs(&segs, true), z, line, line));
    } else {
        pieces.extend(segs.into_iter().map(|seg| Piece { seg, z, line }));
    }
}

/// A SPLINE entity's NURBS as rational Bézier pieces.
fn spline(name: &str, line: u64, body: &[Group]) -> Result<Vec<Bezier>> {
    let here = |g: &Group| Location::file(name).line(g.line);
    let whole = || Location::file(name).line(line);
    let (mut degree, mut knots, mut weights, mut points, mut fit) = (None, Vec::new(), Vec::new(), Vec::new(), 0);
    let mut x = None;
    for g in body {
        match g.code {
            71 => degree = Some(number(name, g)? as usize),
            40 => knots.push(number(name, g)?),
            41 => weights.push(number(name, g)?),
            10 => x = Some(number(name, g)?),
            20 => {
                let Some(px) = x.take() else {
                    return Err(Error::input("SPLINE: a y (20) without its x (10)").at(here(g)));
                };
                points.push(P2::new(px, number(name, g)?));
            }
            11 => fit += 1,
            _ => {}
        }
    }
    if points.is_empty() {
        let what = if fit > 0 { format!("{fit} fit points and no control points") } else { "no control points".into() };
        return Err(Error::input(format!(
            "SPLINE with {what}: save the drawing with control points (every CAD program's DXF export does)"
        ))
        .at(whole()));
    }
    let degree = degree.ok_or_else(|| Error::input("SPLINE needs its degree (71)").at(whole()))?;
    if weights.is_empty() {
        weights = vec![1.0; points.len()];
    }
    curve::nurbs_beziers(degree, &knots, &points, &weights)
        .map_err(|e| Error::input(format!("SPLINE: {e}")).at(whole()))
}

/// A polyline's vertices as a closed contour (flagged closed, or ending where it starts) or as
/// pieces to chain.
pub(crate) fn polyline(
    closed: &mut Vec<Closed>,
    pieces: &mut Vec<Piece>,
    mut verts: Vec<Vertex>,
    flag: bool,
    z: f64,
    line: u64,
) {
    verts.dedup_by(|b, a| {
        let same = (a.p - b.p).norm() <= tol::POINT_EPS;
        if same {
            a.bulge = b.bulge;
        }
        same
    });
    if verts.len() < 2 {
        return;
    }
    let ends_at_start = (verts[0].p - verts[verts.len() - 1].p).norm() <= tol::DXF_JOIN;
    if ends_at_start {
        verts.pop();
    }
    if flag || ends_at_start {
        if verts.len() >= 2 || verts.iter().any(|v| v.bulge != 0.0) {
            closed.push((Contour { vertices: verts, closed: true }, z, line, line));
        }
        return;
    }
    for w in verts.windows(2) {
        pieces.push(Piece { seg: Seg::from_bulge(w[0].p, w[1].p, w[0].bulge), z, line });
    }
}

/// Open pieces joined end to end (a piece may be reversed) into closed contours; a chain that
/// does not close, or a point where three or more pieces meet, is an error naming a line.
fn chain(name: &str, pieces: &[Piece], largest_gap: &mut f64) -> Result<Vec<Closed>> {
    let cell = tol::DXF_JOIN.max(tol::POINT_EPS) * 4.0;
    let key = |p: &P2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut grid: std::collections::HashMap<(i64, i64), Vec<(usize, bool)>> = std::collections::HashMap::new();
    for (i, pc) in pieces.iter().enumerate() {
        grid.entry(key(&pc.seg.start())).or_default().push((i, false));
        grid.entry(key(&pc.seg.end())).or_default().push((i, true));
    }
    // Pieces with an end within the join tolerance of `p`, other than `skip`.
    let near = |p: &P2, skip: usize| -> Vec<(usize, bool, f64)> {
        let (kx, ky) = key(p);
        let mut v = Vec::new();
        for x in kx - 1..=kx + 1 {
            for y in ky - 1..=ky + 1 {
                for &(i, at_end) in grid.get(&(x, y)).map_or(&[][..], |v| v.as_slice()) {
                    let q = if at_end { pieces[i].seg.end() } else { pieces[i].seg.start() };
                    let d = (q - p).norm();
                    if i != skip && d <= tol::DXF_JOIN {
                        v.push((i, at_end, d));
                    }
                }
            }
        }
        v
    };
    let mut used = vec![false; pieces.len()];
    let mut out = Vec::new();
    for first in 0..pieces.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let mut segs = vec![pieces[first].seg];
        let (mut last, mut last_line) = (first, pieces[first].line);
        loop {
            let end = segs[segs.len() - 1].end();
            let cands = near(&end, last);
            if cands.len() > 1 {
                let lines: Vec<String> = std::iter::once(pieces[last].line)
                    .chain(cands.iter().map(|c| pieces[c.0].line))
                    .map(|l| l.to_string())
                    .collect();
                return Err(Error::input(format!(
                    "{} piece ends meet at ({:.6}, {:.6}) (from lines {}): a contour's pieces join two by two",
                    cands.len() + 1,
                    end.x,
                    end.y,
                    lines.join(", ")
                ))
                .at(Location::file(name).line(pieces[last].line)));
            }
            let Some(&(next, at_end, gap)) = cands.first() else {
                return Err(open_chain(name, pieces, &used, first, last, &segs));
            };
            *largest_gap = largest_gap.max(gap);
            if next == first {
                break;
            }
            if used[next] {
                return Err(Error::input(format!(
                    "the piece from line {} is reached twice while chaining",
                    pieces[next].line
                ))
                .at(Location::file(name).line(pieces[next].line)));
            }
            if (pieces[next].z - pieces[first].z).abs() > tol::POINT_EPS {
                return Err(Error::input(format!(
                    "a contour lies at one z: it starts at z = {} and reaches z = {}",
                    pieces[first].z, pieces[next].z
                ))
                .at(Location::file(name).line(pieces[next].line)));
            }
            used[next] = true;
            segs.push(if at_end { pieces[next].seg.reversed() } else { pieces[next].seg });
            last = next;
            last_line = last_line.max(pieces[next].line);
        }
        let vertices = segs.iter().map(|s| Vertex { p: s.start(), bulge: s.bulge() }).collect();
        out.push((Contour { vertices, closed: true }, pieces[first].z, pieces[first].line, last_line));
    }
    Ok(out)
}

/// The error for a chain that does not close: where it ends, and the nearest end it could have
/// met (its own start, or a free end of another entity) with the gap's size.
fn open_chain(name: &str, pieces: &[Piece], used: &[bool], first: usize, last: usize, segs: &[Seg]) -> Error {
    let end = segs[segs.len() - 1].end();
    let mut nearest = (segs[0].start(), (segs[0].start() - end).norm(), "its own start".to_string());
    for pc in pieces.iter().zip(used).filter(|(_, u)| !**u).map(|(pc, _)| pc) {
        for q in [pc.seg.start(), pc.seg.end()] {
            let d = (q - end).norm();
            if d < nearest.1 {
                nearest = (q, d, format!("an end of the piece from line {}", pc.line));
            }
        }
    }
    let (q, gap, what) = nearest;
    Error::input(format!(
        "open contour: the chain of pieces from line {} ends at ({:.6}, {:.6}); the nearest end, {what} at ({:.6}, {:.6}), is {} mm away (ends join within {} mm)",
        pieces[first].line,
        end.x,
        end.y,
        q.x,
        q.y,
        crate::cli::short(gap),
        tol::DXF_JOIN
    ))
    .at(Location::file(name).line(pieces[last].line))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dxf(entities: &str) -> String {
        format!("0\nSECTION\n2\nHEADER\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n{entities}0\nENDSEC\n0\nEOF\n")
    }

    fn line(a: (f64, f64), b: (f64, f64)) -> String {
        format!("0\nLINE\n8\n0\n10\n{}\n20\n{}\n30\n0\n11\n{}\n21\n{}\n31\n0\n", a.0, a.1, b.0, b.1)
    }

    #[test]
    fn lines_and_arcs_chain_into_a_closed_contour() {
        // A 20 × 10 slot with round ends: two lines (one reversed) and two half arcs, plus a
        // circle island and a text that is skipped.
        let mut e = line((0.0, 0.0), (20.0, 0.0));
        e += "0\nARC\n10\n20\n20\n5\n30\n0\n40\n5\n50\n270\n51\n90\n";
        e += &line((0.0, 10.0), (20.0, 10.0));
        e += "0\nARC\n10\n0\n20\n5\n30\n0\n40\n5\n50\n90\n51\n270\n";
        e += "0\nCIRCLE\n10\n10\n20\n5\n30\n0\n40\n2\n0\nTEXT\n1\nhello\n";
        let r = read("t.dxf", &dxf(&e), &Options::default()).unwrap();
        assert_eq!(r.sources.len(), 2);
        assert_eq!(r.skipped.len(), 1);
        let slot = &r.sources[0].contour;
        assert_eq!(slot.vertices.len(), 4);
        let exact = 40.0 + 10.0 * std::f64::consts::PI;
        assert!((slot.length() - exact).abs() < 1e-9, "{} vs {exact}", slot.length());
        assert!((slot.area().abs() - (200.0 + std::f64::consts::PI * 25.0)).abs() < 1e-9);
        assert!((r.sources[1].contour.area().abs() - std::f64::consts::PI * 4.0).abs() < 1e-9);
        let (regions, _) = crate::contour::table::pocket_regions(&r.sources, "t.dxf").unwrap();
        assert_eq!(regions.len(), 1);
        assert_eq!(regions[0].islands.len(), 1);
    }

    #[test]
    fn polylines_with_bulges() {
        // LWPOLYLINE: a 10 × 10 square whose right side bulges out into a half circle.
        let lw = "0\nLWPOLYLINE\n90\n4\n70\n1\n10\n0\n20\n0\n10\n10\n20\n0\n42\n1\n10\n10\n20\n10\n10\n0\n20\n10\n";
        // POLYLINE: the same as VERTEX entities.
        let pl = "0\nPOLYLINE\n66\n1\n70\n1\n10\n0\n20\n0\n30\n0\n0\nVERTEX\n10\n30\n20\n0\n0\nVERTEX\n10\n40\n20\n0\n42\n1\n\
                  0\nVERTEX\n10\n40\n20\n10\n0\nVERTEX\n10\n30\n20\n10\n0\nSEQEND\n";
        let r = read("p.dxf", &dxf(&format!("{lw}{pl}")), &Options::default()).unwrap();
        assert_eq!(r.sources.len(), 2);
        let want = 100.0 + std::f64::consts::PI * 25.0 / 2.0;
        for s in &r.sources {
            assert!((s.contour.area().abs() - want).abs() < 1e-9, "{}", s.contour.area());
        }
    }

    #[test]
    fn ellipses_splines_and_layers() {
        // Half an ellipse (a = 10, b = 5) closed by a LINE on layer Cut; a full ratio-1 ELLIPSE
        // (a circle, read exactly) and a fit-point SPLINE elsewhere.
        let half = "0\nELLIPSE\n8\nCut\n10\n0\n20\n0\n11\n10\n21\n0\n40\n0.5\n41\n0\n42\n3.141592653589793\n";
        let chord = "0\nLINE\n8\nCut\n10\n-10\n20\n0\n11\n10\n21\n0\n";
        let round = "0\nELLIPSE\n8\nOther\n10\n40\n20\n0\n11\n0\n21\n3\n40\n1\n";
        let text = dxf(&format!("{half}{chord}{round}"));
        let cut = Options { tol: 1e-4, layers: vec!["Cut".into()] };
        let r = read("e.dxf", &text, &cut).unwrap();
        assert_eq!((r.sources.len(), r.layers.clone()), (1, vec!["Cut".to_string(), "Other".to_string()]));
        let d = &r.sources[0].contour;
        let exact = std::f64::consts::PI * 25.0;
        // Within tol of the curve everywhere: the area within tol times the perimeter.
        assert!((d.area().abs() - exact).abs() <= 1e-4 * d.length(), "{} vs {exact}", d.area());
        assert!(r.curve_deviation > 0.0 && r.curve_deviation <= 1e-4, "{}", r.curve_deviation);
        let all = read("e.dxf", &text, &Options::default()).unwrap();
        assert_eq!(all.sources[1].contour, Contour::circle(P2::new(40.0, 0.0), 3.0, std::f64::consts::FRAC_PI_2, true));
        let fit = dxf("0\nSPLINE\n71\n3\n74\n2\n11\n0\n21\n0\n11\n5\n21\n5\n");
        let e = read("s.dxf", &fit, &Options::default()).unwrap_err().to_string();
        assert!(e.contains("s.dxf:") && e.contains("2 fit points and no control points"), "{e}");
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]

        /// A star polygon written as LINEs in any order, each possibly reversed and its ends
        /// moved by less than the join tolerance, chains back into one contour of its area.
        #[test]
        fn shuffled_lines_chain_back(n in 3usize..24, seed in 0u64..1_000_000) {
            let mut rng = seed;
            let mut next = || {
                rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (rng >> 11) as f64 / (1u64 << 53) as f64
            };
            let pts: Vec<P2> = (0..n)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / n as f64;
                    let r = 10.0 + 5.0 * next();
                    P2::new(r * a.cos(), r * a.sin())
                })
                .collect();
            let mut order: Vec<usize> = (0..n).collect();
            for i in (1..n).rev() {
                order.swap(i, (next() * (i + 1) as f64) as usize % (i + 1));
            }
            let jitter = 0.4 * tol::DXF_JOIN;
            let mut e = String::new();
            for &k in &order {
                let (a, b) = (pts[k], pts[(k + 1) % n]);
                let (a, b) = if next() < 0.5 { (a, b) } else { (b, a) };
                let a = (a.x + jitter * (next() - 0.5), a.y + jitter * (next() - 0.5));
                e += &line(a, (b.x, b.y));
            }
            let r = read("s.dxf", &dxf(&e), &Options::default()).unwrap();
            proptest::prop_assert_eq!(r.sources.len(), 1);
            let c = &r.sources[0].contour;
            proptest::prop_assert_eq!(c.vertices.len(), n);
            // Each start moved by at most jitter/√2: the area by at most that times the perimeter.
            let exact = Contour::polygon(&pts, true);
            let bound = exact.length() * jitter;
            proptest::prop_assert!((c.area().abs() - exact.area().abs()).abs() <= bound, "{} vs {}", c.area(), exact.area());
            proptest::prop_assert!(r.largest_gap <= tol::DXF_JOIN);
        }
    }

    #[test]
    fn bad_files_name_their_line() {
        let open = dxf(&(line((0.0, 0.0), (10.0, 0.0)) + &line((10.0, 0.0), (10.0, 10.0))));
        let e = read("o.dxf", &open, &Options::default()).unwrap_err().to_string();
        assert!(e.contains("o.dxf:") && e.contains("open contour"), "{e}");
        assert!(e.contains("its own start at (0.000000, 0.000000), is 14.142135623730951 mm away"), "{e}");
        let bad = dxf("0\nLINE\n10\nten\n20\n0\n11\n1\n21\n0\n");
        let e = read("b.dxf", &bad, &Options::default()).unwrap_err().to_string();
        assert!(e.contains("b.dxf:14"), "{e}");
        let code = "0\nSECTION\nx\nENTITIES\n";
        let e = read("c.dxf", code, &Options::default()).unwrap_err().to_string();
        assert!(e.contains("c.dxf:3"), "{e}");
        let three =
            dxf(&(line((0.0, 0.0), (10.0, 0.0)) + &line((10.0, 0.0), (0.0, 0.0)) + &line((0.0, 0.0), (0.0, 5.0))));
        let e = read("t.dxf", &three, &Options::default()).unwrap_err().to_string();
        assert!(e.contains("meet"), "{e}");
    }
}
