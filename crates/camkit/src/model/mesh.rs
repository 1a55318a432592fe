//! Triangle meshes: STL reading (binary and ASCII, through `stl_io`) with errors that name the
//! facet, and exact nearest points through a [`Bvh`] over the triangles.
//!
//! STL files as users have them (OpenSCAD, scanners) hold zero-area slivers and repeated facets:
//! neither changes a nearest point, so [`load_stl`] leaves them out and says which
//! ([`Dropped`]); a filter warns once and reports the counts, or refuses under `--strict`
//! ([`Dropped::refusal`]). Open and non-manifold meshes are read as they are: nearest points do
//! not need a closed solid (what does, the inside test of `collide::solid`, says so).

use super::analytic::Foot;
use super::bvh::{Aabb, Bvh};
use crate::error::{Error, Location, Result};
use crate::geom::{P3, V3};
use crate::io::Input;

/// A triangle ready for distance queries.
#[derive(Clone, Copy, Debug)]
struct Tri {
    a: P3,
    ab: V3,
    ac: V3,
    /// Unit normal by the right-hand rule on the corners' order.
    n: V3,
}

/// A triangle mesh with its spatial index.
#[derive(Clone, Debug)]
pub struct Mesh {
    tris: Vec<Tri>,
    /// Input number (facet in the file, from 0) of each triangle of `tris`.
    numbers: Vec<usize>,
    index: Bvh,
    dropped: Dropped,
}

/// Facets of an STL file its mesh leaves out: zero-area ones (corners collinear to rounding,
/// [`DEGENERATE_REL`]) and exact repeats of an earlier facet (the same corners in the same turn;
/// one with its corners in the opposite turn faces the other way and is kept).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Dropped {
    /// The file.
    pub file: String,
    /// Zero-area facets: input number (from 0) and corners.
    pub degenerate: Vec<(usize, [P3; 3])>,
    /// Repeated facets: input number and that of the first with the same corners.
    pub duplicate: Vec<(usize, usize)>,
}

impl Dropped {
    /// True when nothing was left out.
    pub fn is_empty(&self) -> bool {
        self.degenerate.is_empty() && self.duplicate.is_empty()
    }

    /// One line saying what was left out, for a warning.
    pub fn summary(&self) -> String {
        let mut parts = Vec::new();
        if let Some((k, _)) = self.degenerate.first() {
            parts.push(format!("{} zero-area facets (the first facet {})", self.degenerate.len(), k + 1));
        }
        if let Some((k, of)) = self.duplicate.first() {
            parts.push(format!(
                "{} duplicate facets (the first facet {}, a repeat of facet {})",
                self.duplicate.len(),
                k + 1,
                of + 1
            ));
        }
        format!("{}: {} dropped (--strict refuses them)", self.file, parts.join(" and "))
    }

    /// The first facet left out as an input error naming it (`--strict`), if any.
    pub fn refusal(&self) -> Option<Error> {
        let at = |k: usize| Location::file(&self.file).field(format!("facet {}", k + 1));
        let degenerate = self.degenerate.first().map(|(k, [a, b, c])| {
            let e = Error::input(format!(
                "degenerate triangle (zero area): corners ({}, {}, {}), ({}, {}, {}), ({}, {}, {})",
                a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z
            ));
            (*k, e.at(at(*k)))
        });
        let duplicate = self.duplicate.first().map(|(k, of)| {
            (*k, Error::input(format!("duplicate facet: the same corners as facet {}", of + 1)).at(at(*k)))
        });
        [degenerate, duplicate].into_iter().flatten().min_by_key(|(k, _)| *k).map(|(_, e)| e)
    }
}

/// The result of a mesh query: the foot and the triangle (its number in the input, from 0).
#[derive(Clone, Copy, Debug)]
pub struct MeshFoot {
    /// Nearest point and the face normal there.
    pub foot: Foot,
    /// Input number of the triangle holding it.
    pub triangle: usize,
}

/// Closest point of triangle (a, a+ab, a+ac) to p (Ericson, Real-Time Collision Detection 5.1.5).
#[inline]
fn closest_on_triangle(p: &P3, t: &Tri) -> P3 {
    let (a, ab, ac) = (t.a, t.ab, t.ac);
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = ap - ab;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return a + ab;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = ap - ac;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return a + ac;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return a + ab + (ac - ab) * w;
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// A triangle is degenerate when twice its area is below this fraction of its longest edge
/// squared (its corners are collinear to rounding).
pub const DEGENERATE_REL: f64 = 1e-12;

/// True when the triangle's area is zero to rounding: twice its area at most [`DEGENERATE_REL`]
/// times its longest edge squared (or not a number).
fn degenerate([a, b, c]: &[P3; 3]) -> bool {
    let (ab, ac) = (b - a, c - a);
    let cross = ab.cross(&ac).norm();
    let longest = ab.norm_squared().max(ac.norm_squared()).max((c - b).norm_squared());
    cross.is_nan() || cross <= DEGENERATE_REL * longest
}

/// The corners' bits, turned so the smallest corner comes first: equal for the same triangle
/// given from any corner in the same turn (−0 counts as 0).
fn facet_key(t: &[P3; 3]) -> [[u64; 3]; 3] {
    let bits = t.map(|p| [p.x, p.y, p.z].map(|v| (v + 0.0).to_bits()));
    let first = (0..3).min_by_key(|&i| bits[i]).expect("three corners");
    [bits[first], bits[(first + 1) % 3], bits[(first + 2) % 3]]
}

impl Mesh {
    /// A mesh from corner triples; `Err(k)` names the first degenerate triangle.
    pub fn new(triangles: &[[P3; 3]]) -> std::result::Result<Mesh, usize> {
        if let Some(k) = triangles.iter().position(degenerate) {
            return Err(k);
        }
        Ok(Mesh::build(triangles, (0..triangles.len()).collect(), Dropped::default()))
    }

    /// A mesh of STL facets: zero-area and repeated ones left out and listed (`file` names them).
    pub fn of_facets(facets: &[[P3; 3]], file: &str) -> Mesh {
        let mut dropped = Dropped { file: file.to_string(), ..Dropped::default() };
        let mut first = std::collections::HashMap::with_capacity(facets.len());
        let (mut kept, mut numbers) = (Vec::with_capacity(facets.len()), Vec::with_capacity(facets.len()));
        for (k, t) in facets.iter().enumerate() {
            if degenerate(t) {
                dropped.degenerate.push((k, *t));
                continue;
            }
            match first.entry(facet_key(t)) {
                std::collections::hash_map::Entry::Occupied(e) => dropped.duplicate.push((k, *e.get())),
                std::collections::hash_map::Entry::Vacant(e) => {
                    e.insert(k);
                    kept.push(*t);
                    numbers.push(k);
                }
            }
        }
        Mesh::build(&kept, numbers, dropped)
    }

    /// The mesh of non-degenerate triangles whose input numbers are `numbers`.
    fn build(triangles: &[[P3; 3]], numbers: Vec<usize>, dropped: Dropped) -> Mesh {
        let mut tris = Vec::with_capacity(triangles.len());
        let mut boxes = Vec::with_capacity(triangles.len());
        for [a, b, c] in triangles {
            let (ab, ac) = (b - a, c - a);
            tris.push(Tri { a: *a, ab, ac, n: ab.cross(&ac).normalize() });
            boxes.push(Aabb::of(&[*a, *b, *c]));
        }
        let index = Bvh::build(&boxes);
        let tris = index.order.iter().map(|&i| tris[i as usize]).collect();
        let numbers = index.order.iter().map(|&i| numbers[i as usize]).collect();
        Mesh { tris, numbers, index, dropped }
    }

    /// The facets of the file left out of the mesh.
    pub fn dropped(&self) -> &Dropped {
        &self.dropped
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.tris.len()
    }

    /// True if there are no triangles.
    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    /// A box holding the mesh.
    pub fn bounds(&self) -> Aabb {
        self.index.bounds()
    }

    /// The exact nearest point no farther than `bound`. Where several triangles are equally
    /// near (an edge or corner), the one facing `q` most is reported, so its normal tells the
    /// side `q` is on.
    pub fn nearest(&self, q: &P3, bound: f64) -> Option<MeshFoot> {
        let bound2 = if bound.is_finite() { bound * bound } else { f64::INFINITY };
        let mut best: Option<(usize, f64, P3, f64)> = None;
        self.index.nearest(q, bound2, |k, _| {
            let t = &self.tris[k];
            let p = closest_on_triangle(q, t);
            let e = (q - p).norm_squared();
            let facing = (q - p).dot(&t.n);
            let better = match &best {
                None => true,
                Some((_, b, _, f)) => {
                    let tie = (e - b).abs() <= 1e-12 * b.max(1e-12);
                    if tie { facing > *f } else { e < *b }
                }
            };
            if better && e <= bound2 {
                best = Some((k, e, p, facing));
            }
            e
        });
        let (k, _, point, _) = best?;
        Some(MeshFoot { foot: Foot { point, normal: self.tris[k].n }, triangle: self.numbers[k] })
    }

    /// Every triangle's corners, in the index's order (for brute-force checks and exports).
    pub fn corners(&self) -> impl Iterator<Item = [P3; 3]> + '_ {
        self.tris.iter().map(|t| [t.a, t.a + t.ab, t.a + t.ac])
    }
}

/// Reads an STL file (binary or ASCII) into corner triples. Empty, truncated and malformed files
/// and non-finite coordinates are input errors naming the facet (and its line in ASCII files).
pub fn read_stl(input: &Input) -> Result<Vec<[P3; 3]>> {
    // A byte order mark some editors put before an ASCII file's `solid` is not part of it.
    let data = input.data.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&input.data);
    let here = || Location::file(&input.name);
    if data.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::input("empty STL file").at(here()));
    }
    let starts_solid = data.len() >= 6 && data[..6].eq_ignore_ascii_case(b"solid ");
    let binary_count =
        (data.len() >= 84).then(|| u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as usize);
    let binary_fits = binary_count.is_some_and(|n| data.len() == 84 + 50 * n);
    // Binary files whose 80-byte header happens to start with "solid" are common: the size
    // decides. stl_io probes by the word, so such a header is blanked before it reads.
    let ascii = starts_solid && !binary_fits;
    let mut bytes = std::borrow::Cow::Borrowed(data);
    if !ascii {
        let Some(n) = binary_count else {
            return Err(
                Error::input(format!("truncated STL: {} bytes, a binary STL needs at least 84", data.len())).at(here())
            );
        };
        if data.len() < 84 + 50 * n {
            return Err(Error::input(format!(
                "truncated binary STL: the header announces {n} triangles ({} bytes) but the file has {} bytes",
                84 + 50 * n,
                data.len()
            ))
            .at(here()));
        }
        if data.len() > 84 + 50 * n {
            // More triangles than the header says (a writer that did not go back to count): the
            // size tells how many when it is whole records, else the file is not to be trusted.
            let extra = data.len() - 84 - 50 * n;
            if extra % 50 != 0 {
                return Err(Error::input(format!(
                    "binary STL of {} bytes: the header announces {n} triangles ({} bytes), and the rest is not whole triangles ({} bytes over)",
                    data.len(),
                    84 + 50 * n,
                    extra % 50
                ))
                .at(here()));
            }
            let m = (data.len() - 84) / 50;
            crate::cli::warn(&format!(
                "{}: the binary STL header announces {n} triangles but the file holds {m}: all {m} are read",
                input.name
            ));
            let mut owned = data.to_vec();
            owned[80..84].copy_from_slice(&(m as u32).to_le_bytes());
            bytes = std::borrow::Cow::Owned(owned);
        }
        if starts_solid {
            bytes.to_mut()[..6].copy_from_slice(b"binary");
        }
    }
    let mut cursor = std::io::Cursor::new(bytes.as_ref());
    let reader =
        stl_io::create_stl_reader(&mut cursor).map_err(|e| Error::input(format!("not an STL file: {e}")).at(here()))?;
    let mut out = Vec::with_capacity(((data.len().saturating_sub(84)) / 50).min(50_000_000));
    for (k, tri) in reader.enumerate() {
        let facet_at = |k: usize| {
            let loc = here().field(format!("facet {}", k + 1));
            if ascii { loc.line(ascii_facet_line(data, k)) } else { loc }
        };
        let tri = tri.map_err(|e| Error::input(format!("malformed STL: {e}")).at(facet_at(k)))?;
        let corners = tri.vertices.map(|v| P3::new(v[0] as f64, v[1] as f64, v[2] as f64));
        if !corners.iter().all(|p| p.iter().all(|c| c.is_finite())) {
            return Err(Error::input("a corner coordinate is not a finite number").at(facet_at(k)));
        }
        out.push(corners);
    }
    if out.is_empty() {
        return Err(Error::input("the STL file holds no triangles").at(here()));
    }
    Ok(out)
}

/// 1-based line of the `k`-th (0-based) `facet` keyword of an ASCII STL, or of the last line.
fn ascii_facet_line(data: &[u8], k: usize) -> u64 {
    let mut seen = 0;
    let mut last = 1;
    for (n, line) in data.split(|&b| b == b'\n').enumerate() {
        last = n as u64 + 1;
        let text = String::from_utf8_lossy(line);
        if text.trim_start().to_ascii_lowercase().starts_with("facet") {
            if seen == k {
                return last;
            }
            seen += 1;
        }
    }
    last
}

/// Reads an STL file and builds its mesh, zero-area and repeated facets left out and listed
/// ([`Mesh::dropped`]); a file with nothing else is an input error.
pub fn load_stl(input: &Input) -> Result<Mesh> {
    let corners = read_stl(input)?;
    let mesh = Mesh::of_facets(&corners, &input.name);
    if mesh.is_empty() {
        return Err(Error::input(format!(
            "all {} facets are degenerate (zero area) or repeats: no surface is left",
            corners.len()
        ))
        .at(Location::file(&input.name)));
    }
    Ok(mesh)
}

/// Binary STL bytes of the triangles (normals from the corners' order), for tests and tools.
pub fn binary_stl(triangles: &[[P3; 3]]) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out[..16].copy_from_slice(b"camkit mesh     ");
    out.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for [a, b, c] in triangles {
        let n = (b - a).cross(&(c - a)).try_normalize(0.0).unwrap_or(V3::zeros());
        for v in [n, a.coords, b.coords, c.coords] {
            for i in 0..3 {
                out.extend_from_slice(&(v[i] as f32).to_le_bytes());
            }
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn input(name: &str, data: Vec<u8>) -> Input {
        Input { name: name.into(), data }
    }

    /// A height field z = f(x, y) as triangles on an n × n grid over [0, 10]².
    fn field(n: usize) -> Vec<[P3; 3]> {
        let f = |i: usize, j: usize| {
            let (x, y) = (i as f64 * 10.0 / n as f64, j as f64 * 10.0 / n as f64);
            P3::new(x, y, (x * 0.7).sin() + (y * 0.4).cos())
        };
        let mut t = Vec::new();
        for i in 0..n {
            for j in 0..n {
                t.push([f(i, j), f(i + 1, j), f(i + 1, j + 1)]);
                t.push([f(i, j), f(i + 1, j + 1), f(i, j + 1)]);
            }
        }
        t
    }

    #[test]
    fn nearest_matches_brute_force() {
        let tris = field(30);
        let mesh = Mesh::new(&tris).unwrap();
        for q in [P3::new(3.1, 4.2, 3.0), P3::new(-2.0, 5.0, 0.0), P3::new(7.7, 9.9, -1.5), P3::new(5.0, 5.0, 0.9)] {
            let got = mesh.nearest(&q, f64::INFINITY).unwrap();
            let brute = tris
                .iter()
                .map(|[a, b, c]| {
                    let t = Tri { a: *a, ab: b - a, ac: c - a, n: V3::z() };
                    (closest_on_triangle(&q, &t) - q).norm()
                })
                .fold(f64::INFINITY, f64::min);
            assert_eq!((got.foot.point - q).norm(), brute);
            assert!(mesh.nearest(&q, brute * 0.999).is_none());
        }
    }

    #[test]
    fn reads_binary_and_ascii_and_refuses_bad_files() {
        let tris = field(3);
        let bin = binary_stl(&tris);
        assert_eq!(read_stl(&input("a.stl", bin.clone())).unwrap().len(), tris.len());
        // A binary file whose header starts with "solid " is still binary.
        let mut solid = bin.clone();
        solid[..6].copy_from_slice(b"solid ");
        assert_eq!(read_stl(&input("a.stl", solid)).unwrap().len(), tris.len());
        let e = read_stl(&input("a.stl", bin[..bin.len() - 7].to_vec())).unwrap_err();
        assert!(e.to_string().contains("truncated binary STL"), "{e}");
        assert!(read_stl(&input("e.stl", Vec::new())).unwrap_err().to_string().contains("empty STL"));
        let ascii = "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\n\
                     facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 x\n";
        let e = read_stl(&input("t.stl", ascii.as_bytes().to_vec())).unwrap_err();
        assert!(e.to_string().starts_with("t.stl:9 (facet 2): malformed STL"), "{e}");
        let flat = vec![[P3::origin(), P3::new(1.0, 0.0, 0.0), P3::new(2.0, 0.0, 0.0)]];
        let e = load_stl(&input("d.stl", binary_stl(&flat))).unwrap_err();
        assert!(e.to_string().starts_with("d.stl: all 1 facets are degenerate"), "{e}");
    }

    /// A header that counts fewer triangles than the file holds: all are read; bytes after them
    /// that are no whole triangle are refused. An ASCII file after a byte order mark is ASCII.
    #[test]
    fn stl_count_below_the_data_and_a_bom() {
        let tris = field(3);
        let mut low = binary_stl(&tris);
        low[80..84].copy_from_slice(&5u32.to_le_bytes());
        let whole = read_stl(&input("all.stl", binary_stl(&tris))).unwrap();
        assert_eq!((whole.len(), read_stl(&input("low.stl", low.clone())).unwrap()), (18, whole));
        low.extend_from_slice(&[0; 7]);
        let e = read_stl(&input("low.stl", low)).unwrap_err();
        assert!(
            e.to_string()
                .contains("announces 5 triangles (334 bytes), and the rest is not whole triangles (7 bytes over)"),
            "{e}"
        );
        let ascii = "\u{feff}solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid t\n";
        assert_eq!(read_stl(&input("bom.stl", ascii.as_bytes().to_vec())).unwrap().len(), 1);
    }

    /// An OpenSCAD-style STL: a closed box of 12 facets with zero-area slivers (collinear
    /// corners, a repeated corner) and repeated facets (one from another corner) among them.
    /// They are left out and listed; nearest points are those of the box; the facet numbers
    /// reported are the file's.
    #[test]
    fn slivers_and_repeats_are_dropped_and_listed() {
        let c = |i: usize| P3::new([0.0, 10.0][i & 1], [0.0, 8.0][(i >> 1) & 1], [0.0, 5.0][(i >> 2) & 1]);
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let boxed: Vec<[P3; 3]> =
            quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect();
        let mut facets = boxed.clone();
        facets.insert(3, [c(4), P3::new(5.0, 0.0, 5.0), c(5)]);
        facets.insert(7, [c(6), c(6), c(7)]);
        facets.push(boxed[5]);
        facets.push([boxed[0][1], boxed[0][2], boxed[0][0]]);
        facets.push([boxed[0][0], boxed[0][2], boxed[0][1]]);
        let mesh = load_stl(&input("scad.stl", binary_stl(&facets))).unwrap();
        let d = mesh.dropped();
        assert_eq!(d.degenerate.iter().map(|(k, _)| *k).collect::<Vec<_>>(), vec![3, 7]);
        assert_eq!(d.duplicate, vec![(14, 6), (15, 0)]);
        assert_eq!(mesh.len(), 13, "the box and the reversed repeat, which faces the other way");
        assert_eq!(
            d.summary(),
            "scad.stl: 2 zero-area facets (the first facet 4) and 2 duplicate facets (the first facet 15, a repeat of facet 7) dropped (--strict refuses them)"
        );
        assert!(d.refusal().unwrap().to_string().starts_with("scad.stl (facet 4): degenerate triangle (zero area)"));
        let q = P3::new(5.0, 4.0, 9.0);
        let foot = mesh.nearest(&q, f64::INFINITY).unwrap();
        assert!((foot.foot.point - P3::new(5.0, 4.0, 5.0)).norm() < 1e-12 && foot.foot.normal == V3::z());
        assert!([2, 4].contains(&foot.triangle), "the file's number of a top facet: {}", foot.triangle);
        let clean = load_stl(&input("box.stl", binary_stl(&boxed))).unwrap();
        assert!(clean.dropped().is_empty() && clean.dropped().refusal().is_none());
    }
}
