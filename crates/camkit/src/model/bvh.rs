//! A bounding-volume hierarchy over axis-aligned boxes for nearest-item queries: the spatial index
//! behind meshes (one box per triangle) and free-form patches (one box per knot span).
//!
//! Written here rather than taken from a crate because the queries need f64 boxes, a caller-given
//! distance bound that prunes from the start, and a visitor that computes each item's exact
//! distance itself; the build is a median split on the widest centroid axis (O(n log n), about a
//! second for a million triangles) and items are renumbered so every leaf is a contiguous range.

use crate::geom::P3;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lowest corner.
    pub min: P3,
    /// Highest corner.
    pub max: P3,
}

impl Aabb {
    /// The empty box (the identity of [`Aabb::union`]).
    pub fn empty() -> Aabb {
        Aabb {
            min: P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
            max: P3::new(-f64::INFINITY, -f64::INFINITY, -f64::INFINITY),
        }
    }

    /// The box of all space (unbounded surfaces).
    pub fn everything() -> Aabb {
        Aabb {
            min: P3::new(-f64::INFINITY, -f64::INFINITY, -f64::INFINITY),
            max: P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
        }
    }

    /// The smallest box holding `points`.
    pub fn of(points: &[P3]) -> Aabb {
        points.iter().fold(Aabb::empty(), |b, p| b.with(p))
    }

    /// This box grown to hold `p`.
    pub fn with(&self, p: &P3) -> Aabb {
        Aabb { min: self.min.inf(p), max: self.max.sup(p) }
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb { min: self.min.inf(&other.min), max: self.max.sup(&other.max) }
    }

    /// The box grown by `d` on every side.
    pub fn inflate(&self, d: f64) -> Aabb {
        let v = crate::geom::V3::repeat(d);
        Aabb { min: self.min - v, max: self.max + v }
    }

    /// True when every coordinate is finite.
    pub fn is_bounded(&self) -> bool {
        self.min.iter().chain(self.max.iter()).all(|c| c.is_finite())
    }

    /// True when no point is inside (the empty box).
    pub fn is_empty(&self) -> bool {
        (0..3).any(|i| self.min[i] > self.max[i])
    }

    /// Centre point.
    pub fn centre(&self) -> P3 {
        nalgebra::center(&self.min, &self.max)
    }

    /// Distance from the point `q` of the xy plane to the box's shadow on it (0 inside): how near
    /// the z axis through `q` anything in the box can be.
    #[inline]
    pub fn dist_xy(&self, q: [f64; 2]) -> f64 {
        let dx = (self.min.x - q[0]).max(q[0] - self.max.x).max(0.0);
        let dy = (self.min.y - q[1]).max(q[1] - self.max.y).max(0.0);
        dx.hypot(dy)
    }

    /// Squared distance from `p` to the box (0 inside): a lower bound for anything in it.
    #[inline]
    pub fn dist2(&self, p: &P3) -> f64 {
        let mut d = 0.0;
        for i in 0..3 {
            let e = (self.min[i] - p[i]).max(p[i] - self.max[i]).max(0.0);
            d += e * e;
        }
        d
    }
}

/// One node: a box and either two children (`count == 0`, children at `start`, `start + 1`) or
/// a leaf's items `start .. start + count` in the hierarchy's order.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: Aabb,
    start: u32,
    count: u32,
}

/// Items per leaf.
const LEAF: usize = 4;

/// The hierarchy. Items are numbered in the hierarchy's order; [`Bvh::order`] maps them back.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// `order[k]` is the original index of the item the hierarchy numbers `k`.
    pub order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over `boxes` (one per item).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut order: Vec<u32> = (0..boxes.len() as u32).collect();
        let centres: Vec<P3> = boxes.iter().map(Aabb::centre).collect();
        let mut nodes = Vec::with_capacity(2 * boxes.len() / LEAF + 1);
        nodes.push(Node { bounds: Aabb::empty(), start: 0, count: 0 });
        if !boxes.is_empty() {
            split(&mut nodes, 0, &mut order, 0, boxes, &centres);
        }
        Bvh { nodes, order }
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// True if there are no items.
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Box of everything.
    pub fn bounds(&self) -> Aabb {
        self.nodes[0].bounds
    }

    /// Visits items nearest-box-first, skipping every box farther than the best squared distance
    /// so far (initially `bound2`). `visit(k, best2)` measures item `k` (hierarchy order) and
    /// returns its squared distance; the smallest is returned with its item, or `None` when
    /// nothing lies within the bound.
    pub fn nearest(&self, p: &P3, bound2: f64, mut visit: impl FnMut(usize, f64) -> f64) -> Option<(usize, f64)> {
        if self.order.is_empty() {
            return None;
        }
        let mut best: Option<(usize, f64)> = None;
        let mut best2 = bound2;
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        let root = self.nodes[0].bounds.dist2(p);
        if root > best2 {
            return None;
        }
        stack.push((0, root));
        while let Some((n, d2)) = stack.pop() {
            if d2 > best2 {
                continue;
            }
            let node = self.nodes[n as usize];
            if node.count > 0 {
                for k in node.start..node.start + node.count {
                    let e = visit(k as usize, best2);
                    if e <= best2 && best.is_none_or(|(_, b)| e < b) {
                        best = Some((k as usize, e));
                        best2 = e;
                    }
                }
            } else {
                let (a, b) = (node.start, node.start + 1);
                let da = self.nodes[a as usize].bounds.dist2(p);
                let db = self.nodes[b as usize].bounds.dist2(p);
                // Push the farther child first so the nearer one is searched first.
                let ((near, dn), (far, df)) = if da <= db { ((a, da), (b, db)) } else { ((b, db), (a, da)) };
                if df <= best2 {
                    stack.push((far, df));
                }
                if dn <= best2 {
                    stack.push((near, dn));
                }
            }
        }
        best
    }
}

impl Bvh {
    /// The items (hierarchy order) under each node, by node number (as [`Bvh::maximise`]
    /// gives it to its bound).
    pub fn spans(&self) -> Vec<std::ops::Range<usize>> {
        let mut spans = vec![0..0; self.nodes.len()];
        // Children come after their parent: fill from the end.
        for (n, node) in self.nodes.iter().enumerate().rev() {
            let (s, c) = (node.start as usize, node.count as usize);
            spans[n] = if c > 0 { s..s + c } else { spans[s].start..spans[s + 1].end };
        }
        if self.order.is_empty() {
            spans[0] = 0..0;
        }
        spans
    }

    /// The largest value over the items by branch and bound: `bound(node, box)` is an upper
    /// bound of the values of the items under the node (−∞: none counts), `visit(k)` measures
    /// item `k`
    /// (hierarchy order). Boxes are searched highest bound first and skipped once their bound
    /// is not above the best so far; the first item reaching the largest value wins. `visit` is
    /// given the best value so far (−∞ at first) and may skip an item that cannot beat it.
    pub fn maximise<T>(
        &self,
        bound: impl Fn(usize, &Aabb) -> f64,
        mut visit: impl FnMut(usize, f64) -> Option<(f64, T)>,
    ) -> Option<(f64, T)> {
        let mut best: Option<(f64, T)> = None;
        let beats = |b: f64, best: &Option<(f64, T)>| b > f64::NEG_INFINITY && best.as_ref().is_none_or(|x| b > x.0);
        if self.order.is_empty() {
            return None;
        }
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        let root = bound(0, &self.nodes[0].bounds);
        if beats(root, &best) {
            stack.push((0, root));
        }
        while let Some((n, b)) = stack.pop() {
            if !beats(b, &best) {
                continue;
            }
            let node = self.nodes[n as usize];
            if node.count > 0 {
                for k in node.start..node.start + node.count {
                    let floor = best.as_ref().map_or(f64::NEG_INFINITY, |x| x.0);
                    if let Some((v, t)) = visit(k as usize, floor) {
                        if best.as_ref().is_none_or(|x| v > x.0) {
                            best = Some((v, t));
                        }
                    }
                }
            } else {
                let (a, c) = (node.start, node.start + 1);
                let ba = bound(a as usize, &self.nodes[a as usize].bounds);
                let bc = bound(c as usize, &self.nodes[c as usize].bounds);
                // The higher bound is pushed last, so searched first.
                let ((hi, bh), (lo, bl)) = if ba >= bc { ((a, ba), (c, bc)) } else { ((c, bc), (a, ba)) };
                if beats(bl, &best) {
                    stack.push((lo, bl));
                }
                if beats(bh, &best) {
                    stack.push((hi, bh));
                }
            }
        }
        best
    }
}

/// Makes node `n` over `order[lo..]` (its slice) and recurses.
fn split(nodes: &mut Vec<Node>, n: usize, order: &mut [u32], lo: u32, boxes: &[Aabb], centres: &[P3]) {
    let bounds = order.iter().fold(Aabb::empty(), |b, &i| b.union(&boxes[i as usize]));
    if order.len() <= LEAF {
        nodes[n] = Node { bounds, start: lo, count: order.len() as u32 };
        return;
    }
    let cb = order.iter().fold(Aabb::empty(), |b, &i| b.with(&centres[i as usize]));
    let ext = cb.max - cb.min;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&a, &b| centres[a as usize][axis].total_cmp(&centres[b as usize][axis]));
    let child = nodes.len();
    nodes.push(Node { bounds: Aabb::empty(), start: 0, count: 0 });
    nodes.push(Node { bounds: Aabb::empty(), start: 0, count: 0 });
    nodes[n] = Node { bounds, start: child as u32, count: 0 };
    let (left, right) = order.split_at_mut(mid);
    split(nodes, child, left, lo, boxes, centres);
    split(nodes, child + 1, right, lo + mid as u32, boxes, centres);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_box_matches_brute_force() {
        // Unit boxes on a jittered grid; the nearest centre found by the tree is the true one.
        let mut boxes = Vec::new();
        for i in 0..20 {
            for j in 0..15 {
                let c = P3::new(i as f64 * 1.7 + (j % 3) as f64 * 0.2, j as f64 * 1.3, ((i * j) % 5) as f64);
                boxes.push(Aabb::of(&[c, c + crate::geom::V3::repeat(0.1)]));
            }
        }
        let bvh = Bvh::build(&boxes);
        for q in [P3::new(3.3, 4.4, 1.0), P3::new(-5.0, 40.0, 2.0), P3::new(17.0, 9.0, -3.0)] {
            let got = bvh.nearest(&q, f64::INFINITY, |k, _| (boxes[bvh.order[k] as usize].min - q).norm_squared());
            let want = boxes.iter().map(|b| (b.min - q).norm_squared()).fold(f64::INFINITY, f64::min);
            assert_eq!(got.unwrap().1, want);
            assert!(
                bvh.nearest(&q, want * 0.99, |k, _| (boxes[bvh.order[k] as usize].min - q).norm_squared()).is_none()
            );
        }
    }

    #[test]
    fn spans_hold_each_nodes_items() {
        // The root holds every item; each inner node's span is its children's, end to end;
        // every item lies in its leaf's box.
        let boxes: Vec<Aabb> = (0..37)
            .map(|i| {
                let c = P3::new((i * 7 % 11) as f64, (i * 5 % 13) as f64, (i % 3) as f64);
                Aabb::of(&[c, c + crate::geom::V3::repeat(0.5)])
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let spans = bvh.spans();
        assert_eq!(spans[0], 0..37);
        for (n, node) in bvh.nodes.iter().enumerate() {
            let s = node.start as usize;
            if node.count == 0 {
                assert_eq!(
                    (spans[s].start, spans[s].end, spans[s + 1].end),
                    (spans[n].start, spans[s + 1].start, spans[n].end)
                );
            }
            for k in spans[n].clone() {
                let b = boxes[bvh.order[k] as usize];
                assert_eq!(node.bounds.union(&b), node.bounds);
            }
        }
    }
}
