//! Where a program's time goes: the feed-following minutes and the length of each kind of
//! travel, the compass for making a program faster (cutting near the threshold, light cutting,
//! air inside passes, links, entries).

use crate::Analysed;
use crate::program::Tag;

/// How far under the threshold (degrees) a cut still counts as at it.
pub const NEAR_THRESHOLD_DEG: f64 = 5.0;

/// Engagement (degrees) at or under which a sample is in air.
pub const AIR_DEG: f64 = 0.01;

/// Minutes and length (mm) of one kind of travel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Share {
    /// Time at the feed following the engagement (min).
    pub minutes: f64,
    /// Length of travel (mm).
    pub mm: f64,
}

/// A layer's feed-following time split by what the tool does.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Breakdown {
    /// Trochoids and passes at ≥ threshold − [`NEAR_THRESHOLD_DEG`].
    pub full: Share,
    /// Trochoids and passes cutting under that.
    pub light: Share,
    /// Trochoids and passes in air (≤ [`AIR_DEG`]), a given program's links at depth included.
    pub air: Share,
    /// Moves tagged links.
    pub link: Share,
    /// Entries (ramps, helices).
    pub entry: Share,
    /// Retracts (chains after the first): the feed model does not time them, for any program.
    pub retracts: usize,
    /// Distance in xy the tool travels in air over the retracts (mm; not timed).
    pub retract_mm: f64,
}

impl Breakdown {
    /// The breakdown of `a` at `threshold` (degrees): each stretch between two samples of a
    /// move classed by the larger engagement at its ends, timed at its feed in `a.feeds`.
    pub fn of(a: &Analysed, threshold: f64) -> Breakdown {
        let mut out = Breakdown::default();
        for (k, m) in a.program.moves.iter().enumerate().skip(1).filter(|(_, m)| m.retract_before) {
            out.retracts += 1;
            out.retract_mm += (m.seg.start() - a.program.moves[k - 1].seg.end()).norm();
        }
        let mut before: Option<(usize, f64, f64)> = None;
        for ((&(i, t), &e), &f) in a.samples.iter().zip(&a.engagement).zip(&a.feeds) {
            let (from, e0) = match before {
                Some((j, t0, e0)) if j == i => (t0, e0),
                _ => (0.0, e),
            };
            before = Some((i, t, e));
            let m = &a.program.moves[i];
            let len = m.seg.length() * (t - from);
            let worst = e.max(e0);
            let share = match m.tag {
                Tag::Entry => &mut out.entry,
                Tag::Link => &mut out.link,
                _ if worst <= AIR_DEG => &mut out.air,
                _ if worst >= threshold - NEAR_THRESHOLD_DEG => &mut out.full,
                _ => &mut out.light,
            };
            share.minutes += len / f;
            share.mm += len;
        }
        out
    }

    /// The report's `time_by_kind`: {kind: {minutes, mm}} times `layers`, and the retracts'
    /// count and air distance (`retracts`: {count, mm}; their minutes are not in the model).
    pub fn to_json(&self, layers: f64) -> serde_json::Value {
        let share = |s: &Share| serde_json::json!({ "minutes": s.minutes * layers, "mm": s.mm * layers });
        serde_json::json!({
            "full": share(&self.full),
            "light": share(&self.light),
            "air": share(&self.air),
            "link": share(&self.link),
            "entry": share(&self.entry),
            "retracts": { "count": self.retracts as f64 * layers, "mm": self.retract_mm * layers },
        })
    }

    /// The sum over the kinds (min).
    pub fn minutes(&self) -> f64 {
        [self.full, self.light, self.air, self.link, self.entry].iter().map(|s| s.minutes).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Settings;
    use crate::program::{Move, Program};
    use camkit::contour::Contour;
    use camkit::contour::Seg;
    use camkit::contour::region::regions;
    use camkit::geom::P2;

    #[test]
    fn the_kinds_add_up_to_the_program_and_class_a_slot_a_side_cut_and_air() {
        // In a 60 × 40 box, R 2: an entry, a slot along y = 10 (180°), a link back through the
        // slot's own ground, a side cut at the 40° step, a light cut 0.05 mm further and air
        // back along y = 10.
        let r = 2.0;
        let s = Settings::for_tests(r);
        let outer =
            Contour::polygon(&[P2::new(0.0, 0.0), P2::new(60.0, 0.0), P2::new(60.0, 40.0), P2::new(0.0, 40.0)], true);
        let (rs, _) = regions(&[outer]).expect("a region");
        let line = |a: (f64, f64), b: (f64, f64)| Seg::Line(P2::new(a.0, a.1), P2::new(b.0, b.1));
        let mv = |seg, tag| Move { seg, tag, retract_before: false };
        let lift = |seg, tag| Move { seg, tag, retract_before: true };
        let mut p = Program::default();
        p.moves.push(mv(line((8.0, 10.0), (10.0, 10.0)), Tag::Entry));
        p.moves.push(mv(line((10.0, 10.0), (50.0, 10.0)), Tag::Contour));
        p.moves.push(mv(line((50.0, 10.0), (10.0, 10.0)), Tag::Link));
        // The step 1 − cos 40° × R = 0.468 mm: at the threshold after the tool's first R.
        let a40 = r * (1.0 - 40f64.to_radians().cos());
        p.moves.push(mv(line((10.0, 10.0 + a40), (50.0, 10.0 + a40)), Tag::Contour));
        p.moves.push(lift(line((50.0, 10.0 + a40 + 0.05), (10.0, 10.0 + a40 + 0.05)), Tag::Contour));
        p.moves.push(mv(line((10.0, 10.0), (50.0, 10.0)), Tag::Contour));
        let a = crate::analyse(p, &s, &rs);
        let b = Breakdown::of(&a, s.threshold);
        assert!((b.minutes() - a.minutes).abs() < 1e-12 * a.minutes, "{} vs {}", b.minutes(), a.minutes);
        let total: f64 = a.program.moves.iter().map(|m| m.seg.length()).sum();
        let mm = b.full.mm + b.light.mm + b.air.mm + b.link.mm + b.entry.mm;
        assert!((mm - total).abs() < 1e-9, "{mm} vs {total}");
        assert!((b.entry.mm - 2.0).abs() < 1e-9 && (b.link.mm - 40.0).abs() < 1e-9, "{b:?}");
        // The slot and the 40° side cut are full (give or take R at their ends, where the
        // entry, the slot's start and the light pass's turn meet), the 0.05 mm pass light, the
        // last pass air.
        assert!((b.full.mm - 80.0).abs() < 2.0 * r, "{b:?}");
        assert!(b.light.mm > 40.0 - 2.0 * r && b.light.mm < 40.0 + 4.0 * r, "{b:?}");
        assert!(b.air.mm > 40.0 - 2.0 * r, "{b:?}");
        // One retract, 0.05 mm across; air runs at the largest feed per tooth.
        assert_eq!(b.retracts, 1);
        assert!((b.retract_mm - 0.05).abs() < 1e-9, "{b:?}");
        let air_feed = s.feed.fz_max * s.feed.teeth * s.feed.spindle;
        assert!((b.link.minutes - 40.0 / air_feed).abs() < 1e-12, "{b:?}");
    }
}
