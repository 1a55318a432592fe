//! The plot of a posted program (`--svg`): the tool tip of every block read back, in the top
//! view and the side views, rapids dashed, feed moves by kind, G2/G3 drawn as arcs in the view of
//! their plane (G17 top, G18 from −y, G19 from +x) and as their sampled tip path elsewhere.

use crate::readback::{NcPose, Reading, joints_at, samples_of};
use camkit::geom::{Arc2, P2, P3, Plane};
use camkit::svg::figure::Figure;
use camkit::svg::{Aspect, Piece, Plot, Style};
use std::f64::consts::FRAC_PI_2;

/// What a block does, as the plot tells it apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// G0.
    Rapid,
    /// A feed move going down more steeply than [`ENTRY_SLOPE`] right after a rapid, or after an
    /// entry at the same feed or along a helix: a plunge or a leg of a ramp.
    Entry,
    /// An arc next to an entry, a rapid or a link: a lead in or out.
    Lead,
    /// A feed move going up more steeply than [`ENTRY_SLOPE`] right before a rapid (or the end),
    /// or before a link at the same feed: a retract at feed.
    Link,
    /// Every other feed move (a cut on a 3-D surface may go up and down).
    Cut,
}

/// Slope (rise over run) beyond which a feed move may be an entry or a link: 1°.
pub const ENTRY_SLOPE: f64 = 0.017_455;

impl Kind {
    fn style(self) -> Style {
        match self {
            Kind::Rapid => Style::stroke("#888888", 0.8).dashed("5 4").named("rapid (G0)"),
            Kind::Entry => Style::stroke("#d62728", 1.4).named("plunge or ramp"),
            Kind::Lead => Style::stroke("#2ca02c", 1.4).named("lead arc"),
            Kind::Link => Style::stroke("#ff7f0e", 1.2).named("retract at feed"),
            Kind::Cut => Style::stroke("#1f77b4", 1.0).named("cut"),
        }
    }
}

/// One block's tip path: its kind, the tips along it (start first), and its arc in controller
/// coordinates moved to the tip (for a machine whose tip is the controller's X, Y, Z shifted).
struct Block {
    kind: Kind,
    tips: Vec<P3>,
    arc: Option<(Plane, Arc2)>,
}

/// The kinds of the blocks from each pose to the next (`None` where either is unknown).
pub fn kinds(poses: &[Option<NcPose>], r: &Reading) -> Vec<Option<Kind>> {
    let n = poses.len();
    let tip = |p: &NcPose| r.at(&p.joints).0;
    let feed = |k: usize| poses[k].as_ref().and_then(|p| p.feed);
    // The block's climb: -1 steeply down, 1 steeply up, 0 otherwise (or unknown).
    let climb = |k: usize| match (&poses[k - 1], &poses[k]) {
        (Some(a), Some(b)) => {
            let d = tip(b) - tip(a);
            let run = d.xy().norm();
            if d.z < -ENTRY_SLOPE * run && d.z < 0.0 {
                -1
            } else if d.z > ENTRY_SLOPE * run && d.z > 0.0 {
                1
            } else {
                0
            }
        }
        _ => 0,
    };
    let mut out: Vec<Option<Kind>> = vec![None; n];
    for k in 1..n {
        let (Some(_), Some(b)) = (&poses[k - 1], &poses[k]) else { continue };
        let entry_before = match out[k - 1] {
            None | Some(Kind::Rapid) => true,
            // A helix going down goes on ramping whatever its feed.
            Some(Kind::Entry) => feed(k) == feed(k - 1) || b.arc.is_some(),
            _ => false,
        };
        out[k] = Some(if b.rapid {
            Kind::Rapid
        } else if climb(k) < 0 && entry_before {
            Kind::Entry
        } else {
            Kind::Cut
        });
    }
    for k in (1..n).rev() {
        let link_after = match out.get(k + 1) {
            None | Some(None | Some(Kind::Rapid)) => true,
            Some(Some(Kind::Link)) => feed(k) == feed(k + 1),
            _ => false,
        };
        if out[k] == Some(Kind::Cut) && climb(k) > 0 && link_after {
            out[k] = Some(Kind::Link);
        }
    }
    // Arcs next to an entry, a rapid or a link are leads.
    for k in 1..n {
        let is_arc = poses[k].as_ref().is_some_and(|p| p.arc.is_some());
        let beside = |j: usize| matches!(out.get(j), Some(Some(Kind::Rapid | Kind::Entry | Kind::Link)));
        if is_arc && out[k] == Some(Kind::Cut) && (beside(k - 1) || beside(k + 1)) {
            out[k] = Some(Kind::Lead);
        }
    }
    out
}

/// The blocks of a program read back, as tip paths.
fn blocks(poses: &[Option<NcPose>], r: &Reading) -> Vec<Option<Block>> {
    let kinds = kinds(poses, r);
    let rigid = r.tcp || r.rotary_at.is_empty();
    (0..poses.len())
        .map(|k| {
            let kind = kinds[k]?;
            let (a, b) = (poses[k - 1].as_ref()?, poses[k].as_ref()?);
            let n = samples_of(a, b, if rigid { 1 } else { 8 });
            let tips: Vec<P3> = (0..=n).map(|i| r.at(&joints_at(a, b, i as f64 / n as f64)).0).collect();
            let arc = b.arc.filter(|_| rigid).map(|arc| {
                let (xa, xb) = (P3::from(a.joints.xyz), P3::from(b.joints.xyz));
                let (mut in_plane, _, _) = arc.in_plane(&xa, &xb);
                let shift = arc.plane.split(&P3::from(tips[n] - xb)).0;
                in_plane.c += shift.coords;
                (arc.plane, in_plane)
            });
            Some(Block { kind, tips, arc })
        })
        .collect()
}

/// A view: the plane it shows (for arcs) and the projection of a point.
#[derive(Clone, Copy)]
struct View {
    plane: Plane,
    axes: [usize; 2],
}

impl View {
    fn flat(&self, p: &P3) -> P2 {
        P2::new(p[self.axes[0]], p[self.axes[1]])
    }

    /// The arc as drawn in this view, if its plane is the view's: G18's (z, x) coordinates are
    /// mirrored into the view's (x, z).
    fn arc(&self, plane: Plane, a: &Arc2) -> Option<Arc2> {
        if plane != self.plane {
            return None;
        }
        Some(match plane {
            Plane::Xz => Arc2 { c: P2::new(a.c.y, a.c.x), r: a.r, start: FRAC_PI_2 - a.start, sweep: -a.sweep },
            _ => *a,
        })
    }
}

/// One panel: runs of blocks of one kind drawn as one path each.
fn panel(title: &str, view: View, labels: (&str, &str), blocks: &[Option<Block>], aspect: Aspect) -> Plot {
    let mut p = Plot::new(title, aspect);
    p.labels(labels.0, labels.1);
    let mut run: Option<(Kind, P2, Vec<Piece>)> = None;
    let flush = |p: &mut Plot, run: &mut Option<(Kind, P2, Vec<Piece>)>| {
        if let Some((kind, start, pieces)) = run.take() {
            p.path(start, pieces, false, kind.style());
        }
    };
    for block in blocks {
        let Some(b) = block else {
            flush(&mut p, &mut run);
            continue;
        };
        if run.as_ref().is_some_and(|r| r.0 != b.kind) {
            flush(&mut p, &mut run);
        }
        let (_, _, pieces) = run.get_or_insert_with(|| (b.kind, view.flat(&b.tips[0]), Vec::new()));
        match b.arc.and_then(|(plane, a)| view.arc(plane, &a)) {
            Some(a) => pieces.push(Piece::Arc(a)),
            None => pieces.extend(b.tips[1..].iter().map(|t| Piece::Line(view.flat(t)))),
        }
    }
    flush(&mut p, &mut run);
    p
}

/// The figure of a posted program: top view above, the side views below.
pub fn plot(title: &str, poses: &[Option<NcPose>], r: &Reading) -> Figure {
    let blocks = blocks(poses, r);
    let top = View { plane: Plane::Xy, axes: [0, 1] };
    let xz = View { plane: Plane::Xz, axes: [0, 2] };
    let yz = View { plane: Plane::Yz, axes: [1, 2] };
    let mut f = Figure::new(title);
    f.row(vec![panel("top view (tool tip)", top, ("x (mm)", "y (mm)"), &blocks, Aspect::Equal)]).row(vec![
        panel("side view from −y", xz, ("x (mm)", "z (mm)"), &blocks, Aspect::Free),
        panel("side view from +x", yz, ("y (mm)", "z (mm)"), &blocks, Aspect::Free),
    ]);
    f
}
