//! `medial-trochoid`: engagement analysis of contour-parallel pocketing, danger regions on the
//! medial axis, and trochoidal clearing of them first (paper 001).
//!
//! [`plan`] takes regions (outer boundary with islands), makes the contour-parallel passes with
//! `camkit::contour::pocket`, simulates the material removal to get the exact engagement along
//! them ([`engagement`]), finds where passes over the threshold meet the medial axis
//! ([`medial`]), clears those stretches first with constant-radius trochoids ([`trochoid`]),
//! re-simulates the whole program and estimates both programs' times ([`feed`]). Material the
//! re-simulation still finds over the threshold makes the medial points within R of it
//! dangerous too (the plan made again, a few rounds); what no loop can clear is named.
//! [`plan_leaving_uncut`] then plans the regions opened by a radius ([`uncut`]) instead,
//! leaving uncut, and naming, the material no program reaches under the threshold.

pub mod adaptive;
pub mod angles;
pub mod breakdown;
pub mod budget;
pub mod chords;
pub mod corner;
pub mod engagement;
pub mod feed;
pub mod given;
pub mod medial;
pub mod plot;
pub mod program;
pub mod relink;
pub mod step;
pub mod trochoid;
pub mod uncut;

use camkit::contour::pocket::{Direction, Pass, Passes, PocketOptions, pocket_stepped};
use camkit::contour::region::Region;
use camkit::contour::{OffsetOptions, SegSet};
use camkit::geom::P2;
use engagement::Cut;
use feed::{FeedModel, Load};
use medial::{Medial, MedialOptions, medial_axis};
use program::{Entry, Program, Tag, point_clearance};
use rayon::prelude::*;
use std::collections::HashMap;

/// Settings of a plan.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Tool radius R (mm).
    pub radius: f64,
    /// Radial step over between passes (mm).
    pub step: f64,
    /// Engagement threshold (degrees).
    pub threshold: f64,
    /// Trochoid loop radius (mm).
    pub trochoid_radius: f64,
    /// Trochoid pitch (mm); `None` picks the largest that holds the threshold.
    pub pitch: Option<f64>,
    /// Material left on the walls (mm).
    pub allowance: f64,
    /// Radius of the tangent arcs that replace the wall passes' sharp inside corners (mm);
    /// `None` fits each corner by simulation (the smallest of [`CORNER_RADII`] that holds the
    /// threshold).
    pub corner_radius: Option<f64>,
    /// Engagement sample spacing along the path (mm).
    pub sample: f64,
    /// Medial axis settings.
    pub medial: MedialOptions,
    /// Feed model for the time estimate.
    pub feed: FeedModel,
    /// How entry loops take the tool down.
    pub entry: Entry,
}

#[cfg(test)]
impl Settings {
    /// Unit tests' settings for tool radius `r`: 40° at a 1 mm step, loops of r/2, samples every
    /// 0.5 mm, a fine medial axis and the force-limited feed model.
    pub(crate) fn for_tests(r: f64) -> Settings {
        Settings {
            radius: r,
            step: 1.0,
            threshold: 40.0,
            trochoid_radius: 0.5 * r,
            pitch: None,
            allowance: 0.0,
            corner_radius: None,
            sample: 0.5,
            medial: MedialOptions { resolution: 1e-6, sagitta: 1e-3, chord_error: 1e-3 },
            feed: FeedModel { spindle: 4800.0, teeth: 6.0, chip: 0.03, fz_max: 0.1, force_at: Some(40.0) },
            entry: Entry::FLAT,
        }
    }
}

/// A program of one layer with its simulated engagement.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Analysed {
    /// The moves.
    pub program: Program,
    /// Sample positions (move, fraction).
    pub samples: Vec<(usize, f64)>,
    /// Engagement at each sample (degrees).
    pub engagement: Vec<f64>,
    /// What the teeth meet at each sample, for the feed model.
    pub loads: Vec<Load>,
    /// Feed (mm/min) at each sample (of the move up to it).
    pub feeds: Vec<f64>,
    /// Largest engagement over cutting moves (trochoids and passes, entries excluded).
    pub max_cutting: f64,
    /// Largest engagement over links.
    pub max_link: f64,
    /// Samples of cutting moves (trochoids and passes) over the threshold.
    pub over: usize,
    /// Samples of links over the threshold.
    pub over_links: usize,
    /// Largest engagement over entries.
    pub max_entry: f64,
    /// Machining time of the layer (min) with the feed following the engagement sample by sample.
    pub minutes: f64,
    /// Machining time of the layer (min) with each kind of move at the feed its slowest sample allows.
    pub minutes_constant: f64,
    /// [`Analysed::minutes`] under the feed model's chip-thickness limit alone.
    pub minutes_chip_only: f64,
    /// [`Analysed::minutes_constant`] under the feed model's chip-thickness limit alone.
    pub minutes_constant_chip_only: f64,
    /// Smallest distance from the tool centre to the walls (mm).
    pub wall_clearance: f64,
}

/// The result of [`plan`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    /// The regions.
    pub regions: Vec<Region>,
    /// Contour-parallel passes.
    pub passes: Vec<Pass>,
    /// Medial axis of each region.
    pub medial: Vec<Medial>,
    /// Offset-only program.
    pub offset_only: Analysed,
    /// Trochoids-first program.
    pub trochoidal: Analysed,
    /// Dangerous stretches of the medial axis (polylines).
    pub danger: Vec<Vec<P2>>,
    /// Stretches cleared by trochoids.
    pub runs: Vec<Run>,
    /// Dangerous stretches where no trochoid fits (polylines).
    pub uncleared: Vec<Vec<P2>>,
    /// Samples of the offset-only program over the threshold.
    pub danger_samples: usize,
    /// Rest material at the wall passes' rounded inside corners, left to finishing.
    pub rests: Vec<corner::Rest>,
    /// Links of the trochoids-first program that went over the threshold, replaced.
    pub relinks: Vec<relink::Relink>,
    /// Entries of runs that met no material (earlier runs had cleared their disk), dropped: the
    /// run starts with a plunge on cleared ground ([`drop_idle_entries`]).
    pub idle_entries: usize,
    /// Rounds of repair: the whole-program check found material over the threshold and
    /// the medial points within R of it were made dangerous too (the plan made again).
    pub repair_rounds: usize,
    /// Points of material over the threshold that the repairs were made for.
    pub repair_points: usize,
    /// True if samples are left over because the repair rounds ran out (else, if any are,
    /// because no loop fits within R of their material).
    pub repairs_exhausted: bool,
    /// Samples of cutting moves still over the threshold after the repairs: where the tool
    /// centre is (mm) and the engagement (degrees). Empty when the threshold holds.
    pub left_over: Vec<(P2, f64)>,
    /// What was left uncut so that the rest holds the threshold ([`plan_leaving_uncut`]): then
    /// `regions` are the opened regions, planned in place of the input's.
    pub uncut: Option<Uncut>,
    /// Opening radii tried by [`plan_leaving_uncut`] whose plan did not hold the threshold
    /// (mm, in the order tried; all of [`OPENING_LADDER`] when none held).
    pub openings_tried: Vec<f64>,
}

/// Material left uncut: the input regions opened by a radius, and the stretches of their loops
/// the opening does not reach.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncut {
    /// The opening radius ρ (mm).
    pub rho: f64,
    /// The input regions (the gouge check is against them).
    pub original: Vec<Region>,
    /// Stretches of the input loops left uncut.
    pub stretches: Vec<uncut::Stretch>,
    /// Area of the input regions less the opened regions' (mm²).
    pub area: f64,
}

/// Opening radii tried when a plan leaves samples over the threshold, as multiples of the wall
/// distance R + allowance (smallest first, so that as little as possible is left): 1.1 already
/// drops a gap exactly 2R wide and rounds each inside corner to a wall-pass arc a tenth of the
/// wall distance; 3 rounds corners to an arc of twice it. A larger opening leaves more than a
/// finishing tool would take.
pub const OPENING_LADDER: [f64; 5] = [1.1, 1.25, 1.5, 2.0, 3.0];

/// Round-off of a computed engagement (degrees): a side cut at exactly the threshold's step
/// over computes to the threshold within this (measured: 1.2e-6° where a rounded corner's
/// line meets the previous pass's band tangentially).
pub const ENGAGEMENT_ROUNDOFF_DEG: f64 = 1e-5;

/// Largest coordinate (mm) of a pocket (30 km): there a double's spacing (3.7e-9 mm) is 270
/// times under the engagement simulation's 1e-6 mm screen margin. Past it round-off leaves
/// slivers the screen cannot drop: inkscape.svg with its island moved to 5e7 mm plans 3.5
/// times slower than at 3e7 mm, at 1e9 mm 8 times (a fuzz mutant past 20 s of CPU).
pub const COORD_LIMIT: f64 = 3e7;

/// The default step over for a tool of radius `r` and a threshold of `threshold` degrees:
/// R(1 − cos threshold), the straight side cut at the threshold ([`side_cut_deg`]'s inverse).
pub fn default_step(r: f64, threshold: f64) -> f64 {
    r * (1.0 - threshold.to_radians().cos())
}

/// Engagement of a straight side cut at radial depth `step` with a tool of radius `r`
/// (degrees): acos(1 − step/R), 180° from a step of 2R on. Passes that follow one another at
/// this step cannot hold a lower threshold on straight walls.
pub fn side_cut_deg(r: f64, step: f64) -> f64 {
    (1.0 - step / r).clamp(-1.0, 1.0).acos().to_degrees()
}

/// Most links over the threshold a plan replaces (each takes a re-simulation of the program).
const RELINK_ROUNDS: usize = 16;

/// How many loop radii a plan tries: the given one and its shrinkings by [`LEVEL_RATIO`].
const LEVELS: usize = 13;

/// The smallest loop a plan tries, as a fraction of the given loop radius.
pub const SMALLEST_LOOP: f64 = 0.068_719_476_736; // LEVEL_RATIO^(LEVELS − 1) = 0.8^12

/// Ratio of consecutive loop radii: fine enough that a loop's radius stays within a fifth of the
/// largest that fits the clearance (halvings left up to half the clearance to the passes).
const LEVEL_RATIO: f64 = 0.8;

/// A stretch of the medial axis cleared by trochoids, the loops shrinking along it.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The stretch (polyline, mm).
    pub points: Vec<P2>,
    /// Loop radius at each point (mm), not increasing.
    pub radii: Vec<f64>,
    /// Pitch at each point (mm).
    pub pitches: Vec<f64>,
}

/// Why a plan could not be made.
#[derive(Clone, Debug, PartialEq)]
pub enum PlanError {
    /// The pocket's offsets could not be verified.
    Pocket(String),
    /// The tool does not fit the region.
    NoPasses,
    /// The medial axis could not be built.
    Medial(String),
    /// No pitch keeps the trochoids under the threshold with this loop radius.
    NoPitch,
    /// Leaving uncut what the tool cannot reach under the threshold would leave all of it:
    /// the smaller openings do not hold and a disk of this radius (mm) fits nowhere.
    TooLarge(f64),
}

impl std::fmt::Display for PlanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PlanError::Pocket(e) => write!(f, "pocket passes: {e}"),
            PlanError::NoPasses => write!(f, "the tool does not fit in the pocket: no pass"),
            PlanError::Medial(e) => write!(f, "medial axis: {e}"),
            PlanError::NoPitch => write!(
                f,
                "no trochoid pitch keeps the engagement under the threshold: use a smaller --trochoid-radius or a larger --threshold"
            ),
            PlanError::TooLarge(rho) => write!(
                f,
                "the tool is too large to cut any of the pocket under the threshold: wherever it fits it engages more than that, and a disk of radius {rho:.3} mm (the opening that would leave the rest uncut) fits nowhere"
            ),
        }
    }
}

/// Simulates `program` for a tool of radius `r` and times it (see [`Analysed`]'s minutes).
pub fn analyse(program: Program, s: &Settings, regions: &[Region]) -> Analysed {
    analyse_after(program, s, regions, &Analysed::default(), 0)
}

/// [`analyse`] of a program whose first `unchanged` moves are those of `previous.program`:
/// the engagement at their samples is taken from `previous`, not simulated again.
pub fn analyse_after(
    program: Program,
    s: &Settings,
    regions: &[Region],
    previous: &Analysed,
    unchanged: usize,
) -> Analysed {
    let cut = Cut::new(s.radius, program.moves.iter().map(|m| m.seg).collect());
    let samples = cut.samples(s.sample);
    let same = previous.samples.iter().take_while(|(i, _)| *i < unchanged).count();
    debug_assert!(
        previous.program.moves[..unchanged.min(previous.program.moves.len())]
            == program.moves[..unchanged.min(program.moves.len())]
    );
    let known: Vec<(f64, Load)> =
        previous.engagement.iter().copied().zip(previous.loads.iter().copied()).take(same).collect();
    let (engagement, loads): (Vec<f64>, Vec<Load>) = cut.contacts_from(&samples, &known).into_iter().unzip();
    let mut worst: HashMap<Tag, f64> = HashMap::new();
    for (&(i, _), &e) in samples.iter().zip(&engagement) {
        let w = worst.entry(program.moves[i].tag).or_insert(0.0);
        *w = w.max(e);
    }
    let get = |t: Tag| worst.get(&t).copied().unwrap_or(0.0);
    let max_cutting = get(Tag::Trochoid).max(get(Tag::Contour));
    let over = cutting_over(&program, &samples, &engagement, s.threshold).count();
    let over_links = samples
        .iter()
        .zip(&engagement)
        .filter(|((i, _), e)| program.moves[*i].tag == Tag::Link && **e > s.threshold + ENGAGEMENT_ROUNDOFF_DEG)
        .count();
    let (feeds, minutes, minutes_constant) = times(&program, &samples, &loads, &s.feed);
    let (_, minutes_chip_only, minutes_constant_chip_only) = times(&program, &samples, &loads, &s.feed.chip_only());
    // The least so far bounds the search of the walls' index for each move: measured move by
    // move against every wall piece, a pocket 3x as tall took 8x the time.
    let walls = SegSet::new(regions.iter().flat_map(|r| r.loops()));
    let wall_clearance = program.moves.iter().fold(f64::INFINITY, |least, m| walls.distance_within(&m.seg, least));
    Analysed {
        program,
        samples,
        engagement,
        loads,
        feeds,
        max_cutting,
        max_link: get(Tag::Link),
        over,
        over_links,
        max_entry: get(Tag::Entry),
        minutes,
        minutes_constant,
        minutes_chip_only,
        minutes_constant_chip_only,
        wall_clearance,
    }
}

/// Feeds per sample and the layer's minutes under `model` for two feed strategies: every sample
/// at the feed its own load allows (the slower of the loads at its two ends; air at the tool's
/// largest feed per tooth), and each kind of move at one feed, the one its slowest sample
/// allows. Entries ramp at the slot feed.
fn times(program: &Program, samples: &[(usize, f64)], loads: &[Load], model: &FeedModel) -> (Vec<f64>, f64, f64) {
    let mut feeds = Vec::with_capacity(samples.len());
    let mut slowest: HashMap<Tag, f64> = HashMap::new();
    let mut before: Option<(usize, f64)> = None;
    let slot = Load::slot();
    for (&(i, _), load) in samples.iter().zip(loads) {
        let tag = program.moves[i].tag;
        let own = model.feed(if tag == Tag::Entry { &slot } else { load });
        let w = slowest.entry(tag).or_insert(f64::INFINITY);
        *w = w.min(own);
        feeds.push(match before {
            Some((j, f0)) if j == i => own.min(f0),
            _ => own,
        });
        before = Some((i, own));
    }
    let (mut minutes, mut minutes_constant) = (0.0, 0.0);
    let mut t0 = (usize::MAX, 0.0);
    for (&(i, t), f) in samples.iter().zip(&feeds) {
        let m = &program.moves[i];
        let from = if t0.0 == i { t0.1 } else { 0.0 };
        let len = m.seg.length() * (t - from);
        minutes += len / f;
        minutes_constant += len / slowest[&m.tag];
        t0 = (i, t);
    }
    (feeds, minutes, minutes_constant)
}

/// The offset-only and the trochoids-first programs of `regions`.
pub fn plan(regions: &[Region], s: &Settings) -> Result<Plan, PlanError> {
    plan_in(regions, regions, s)
}

/// [`plan`], and where its program leaves samples over the threshold, the plan of the regions
/// opened by the first radius of [`OPENING_LADDER`] whose plan holds it: the material the
/// opening drops is left uncut and named ([`Plan::uncut`]). Both programs (offset-only and
/// trochoids-first) are then made in the opened regions, so their times compare like with
/// like; the gouge check stays against `regions`. If no opening holds, the plan of `regions`;
/// if an opening leaves nothing before one holds, [`PlanError::TooLarge`]: all would be uncut.
pub fn plan_leaving_uncut(regions: &[Region], s: &Settings) -> Result<Plan, PlanError> {
    let mut full = plan(regions, s)?;
    if full.left_over.is_empty() {
        return Ok(full);
    }
    let wall = s.radius + s.allowance;
    let mut tried = Vec::new();
    for k in OPENING_LADDER {
        let rho = wall * k;
        let Ok(opening) = uncut::open(regions, rho) else {
            tried.push(rho);
            continue;
        };
        if opening.regions.is_empty() {
            // Nothing is left to cut at this radius, nor at a larger one, and no smaller one
            // held: the tool cuts nothing of this pocket under the threshold.
            return Err(PlanError::TooLarge(rho));
        }
        match plan_in(&opening.regions, regions, s) {
            Ok(mut p) if p.left_over.is_empty() => {
                let area =
                    regions.iter().map(uncut::area).sum::<f64>() - opening.regions.iter().map(uncut::area).sum::<f64>();
                p.openings_tried = tried;
                p.uncut = Some(Uncut {
                    rho,
                    original: regions.to_vec(),
                    stretches: uncut::stretches(regions, &opening.regions, s.sample),
                    area,
                });
                return Ok(p);
            }
            _ => tried.push(rho),
        }
    }
    full.openings_tried = tried;
    Ok(full)
}

/// The plan of `regions` with the tool's clearance (the gouge check) measured from `walls`
/// (the same regions, or the input regions around opened ones).
fn plan_in(regions: &[Region], walls: &[Region], s: &Settings) -> Result<Plan, PlanError> {
    let wall = s.radius + s.allowance;
    let opts = PocketOptions {
        radius: wall,
        step: s.step,
        passes: Passes::UntilEmpty,
        direction: Direction::Climb,
        offset: OffsetOptions::default(),
    };
    let rule = |loops: &[camkit::contour::Contour]| step::step_after(loops, s);
    let pocket = pocket_stepped(regions, &opts, Some(&rule))
        .map_err(|e| PlanError::Pocket(format!("offset {} mm: {}", e.distance, e.error)))?;
    if pocket.passes.is_empty() {
        return Err(PlanError::NoPasses);
    }
    let mut passes_only = Program::default();
    for (ri, region) in regions.iter().enumerate() {
        let mine: Vec<Pass> = pocket.passes.iter().filter(|p| p.region == ri).cloned().collect();
        passes_only.push_passes(&mine, region, wall);
    }
    let offset_only = analyse(passes_only.clone(), s, walls);
    let medial: Vec<Medial> = regions
        .iter()
        .map(|r| medial_axis(r, &s.medial).map_err(|e| PlanError::Medial(e.to_string())))
        .collect::<Result<_, _>>()?;
    // Danger: medial points within a step over of a pass sample over the threshold.
    let hot: Vec<P2> = offset_only
        .samples
        .iter()
        .zip(&offset_only.engagement)
        .filter(|(_, e)| **e > s.threshold + ENGAGEMENT_ROUNDOFF_DEG)
        .map(|(&(i, t), _)| offset_only.program.moves[i].seg.point_at(t))
        .collect();
    let reach = s.step.max(s.sample);
    let grid = PointGrid::new(&hot, reach);
    // Loop radii: the given one and shrinkings of it, so that runs reach into corners; each
    // loop has the largest that fits inside the clearance where it is.
    let radii: Vec<f64> = (0..LEVELS).map(|k| s.trochoid_radius * LEVEL_RATIO.powi(k as i32)).collect();
    let pitches: Vec<Option<f64>> = radii
        .par_iter()
        .map(|&rt| match s.pitch {
            Some(p) => Some(p),
            None => trochoid::pitch_for(s.radius, rt, s.threshold, s.sample.min(0.1)),
        })
        .collect();
    if pitches[0].is_none() {
        return Err(PlanError::NoPitch);
    }
    let loops = Loops { radii, pitches };
    // Material found over the threshold by the re-simulation: medial points within R of it
    // are dangerous too (a loop centred there sweeps it away).
    let mut repair_points: Vec<P2> = Vec::new();
    let mut stretches = dangerous(regions, &medial, &loops, s, |p| grid.any_within(p, reach));
    let mut built = build(regions, walls, &pocket.passes, &stretches.runs, s, None);
    let mut repair_rounds = 0;
    let mut repairs_exhausted = true;
    // The plan returned is the best of the rounds (fewest samples over, then the lowest
    // largest engagement): a round's new loops could make things worse elsewhere.
    let score = |b: &Built| (b.trochoidal.over, b.trochoidal.max_cutting);
    let mut best: Option<(Built, Stretches, usize)> = None;
    for round in 1..=REPAIR_ROUNDS {
        let found = over_material(&built.trochoidal, s);
        if found.is_empty() {
            repairs_exhausted = false;
            break;
        }
        repair_points.extend(found);
        let near = PointGrid::new(&repair_points, s.radius);
        let more =
            dangerous(regions, &medial, &loops, s, |p| grid.any_within(p, reach) || near.any_within(p, s.radius));
        // The runs made before are kept, in their order, and the new ones cut after them: the
        // loops before are the same moves, so their engagement is not simulated again (a run
        // that grew is cut again whole, the part cut before now in cleared ground).
        let added: Vec<Run> = more.runs.into_iter().filter(|r| !stretches.runs.contains(r)).collect();
        if added.is_empty() {
            repairs_exhausted = false;
            break;
        }
        let kept = stretches.runs.len();
        let next = Stretches {
            runs: stretches.runs.iter().cloned().chain(added).collect(),
            danger: more.danger,
            uncleared: more.uncleared,
        };
        let again = build(regions, walls, &pocket.passes, &next.runs, s, Some((&built.trochoidal, kept)));
        let before = std::mem::replace(&mut built, again);
        let previous = std::mem::replace(&mut stretches, next);
        if best.as_ref().is_none_or(|b| score(&before) < score(&b.0)) {
            best = Some((before, previous, repair_rounds));
        }
        repair_rounds = round;
    }
    if let Some((b, st, rounds)) = best
        && score(&b) < score(&built)
    {
        (built, stretches, repair_rounds) = (b, st, rounds);
    }
    let (trochoidal, idle_entries) = drop_idle_entries(built.trochoidal, s, walls);
    let b = &trochoidal;
    let left_over = cutting_over(&b.program, &b.samples, &b.engagement, s.threshold)
        .map(|((i, t), e)| (b.program.moves[i].seg.point_at(t), e))
        .collect::<Vec<_>>();
    let repairs_exhausted = repairs_exhausted && !left_over.is_empty();
    Ok(Plan {
        regions: regions.to_vec(),
        passes: built.passes,
        medial,
        offset_only,
        trochoidal,
        idle_entries,
        danger: stretches.danger,
        runs: stretches.runs,
        uncleared: stretches.uncleared,
        danger_samples: hot.len(),
        rests: built.rests,
        relinks: built.relinks,
        repair_rounds,
        repair_points: repair_points.len(),
        repairs_exhausted,
        left_over,
        uncut: None,
        openings_tried: Vec::new(),
    })
}

/// Most rounds of repair after the whole-program check (each takes a re-simulation).
const REPAIR_ROUNDS: usize = 4;

/// Loop radii tried (mm, the given one first, shrinking by [`LEVEL_RATIO`]) and the pitch
/// that holds the threshold for each (`None`: none does).
struct Loops {
    radii: Vec<f64>,
    pitches: Vec<Option<f64>>,
}

/// The medial axis's dangerous stretches (the points `hot` flags), the runs of loops along
/// them and the stretches where no loop fits.
struct Stretches {
    danger: Vec<Vec<P2>>,
    runs: Vec<Run>,
    uncleared: Vec<Vec<P2>>,
}

/// The stretches of `medial` whose points `hot` flags, with the loops that fit there.
fn dangerous(
    regions: &[Region],
    medial: &[Medial],
    loops: &Loops,
    s: &Settings,
    hot: impl Fn(&P2) -> bool,
) -> Stretches {
    let wall = s.radius + s.allowance;
    let (radii, pitches) = (&loops.radii, &loops.pitches);
    let mut danger = Vec::new();
    let mut runs: Vec<Run> = Vec::new();
    let mut uncleared = Vec::new();
    let spacing = s.sample.min(0.5);
    for (ri, m) in medial.iter().enumerate() {
        for chain in chains(&m.edges) {
            let pts = densify(&chain, spacing);
            let flags: Vec<(bool, Option<(f64, f64)>)> = pts
                .iter()
                .map(|p| {
                    let hot = hot(p);
                    // A loop's centre keeps its radius plus a pitch (the chord between centres
                    // cuts bends of the axis) from the walls. The radius is the largest that
                    // fits, at the pitch of the largest level that fits (a loop larger than its
                    // level at that level's pitch engages less).
                    let cap = point_clearance(p, &regions[ri]) - wall;
                    let fits = |k: usize| pitches[k].is_some_and(|pk| radii[k] + pk <= cap);
                    let fit = (0..LEVELS).find(|&k| fits(k)).map(|k| {
                        let pk = pitches[k].expect("a level that fits has a pitch");
                        let above = if k == 0 { radii[0] } else { radii[k - 1] };
                        ((cap - pk).min(above), pk)
                    });
                    (hot, fit)
                })
                .collect();
            danger.extend(stretches(&pts, &flags, |f| f.0));
            uncleared.extend(stretches(&pts, &flags, |f| f.0 && f.1.is_none()));
            let loops: Vec<(f64, f64)> = flags.iter().map(|f| f.1.unwrap_or((0.0, 0.0))).collect();
            for (a, b) in spans(&flags, |f| f.0 && f.1.is_some()) {
                for (points, radii, pitches) in shrinking(&pts[a..b], &loops[a..b]) {
                    runs.push(Run { points, radii, pitches });
                }
            }
        }
    }
    Stretches { danger, runs: uncovered(runs), uncleared }
}

/// How far (mm) a loop may reach past an earlier one and still count as inside it: round-off of
/// points of the medial axis that are one point in exact arithmetic (the centre of a circle
/// drawn with chords) and of their clearance.
const COVER_TOL: f64 = 1e-3;

/// `runs` without those whose every loop lies inside a loop of a run kept before it (the disk of
/// radius r about p inside the one of radius r' about q: |p − q| + r ≤ r' + [`COVER_TOL`]):
/// such a run's tool only sweeps again what the earlier one swept (e.g. the many short
/// stretches of a circle's medial axis, all at its centre). The whole-program simulation
/// still checks the result.
fn uncovered(runs: Vec<Run>) -> Vec<Run> {
    let cell = runs.iter().flat_map(|r| r.radii.iter().copied()).fold(0.0, f64::max) + COVER_TOL;
    let key = |p: &P2| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
    let mut kept_disks: HashMap<(i64, i64), Vec<(P2, f64)>> = HashMap::new();
    let mut kept = Vec::new();
    for run in runs {
        let inside = |p: &P2, r: f64| {
            let (kx, ky) = key(p);
            (kx - 1..=kx + 1).any(|x| {
                (ky - 1..=ky + 1).any(|y| {
                    kept_disks
                        .get(&(x, y))
                        .is_some_and(|v| v.iter().any(|(q, rq)| (q - p).norm() + r <= rq + COVER_TOL))
                })
            })
        };
        if run.points.iter().zip(&run.radii).all(|(p, &r)| inside(p, r)) {
            continue;
        }
        for (p, &r) in run.points.iter().zip(&run.radii) {
            kept_disks.entry(key(p)).or_default().push((*p, r));
        }
        kept.push(run);
    }
    kept
}

/// A trochoids-first program and what making it decided.
struct Built {
    passes: Vec<Pass>,
    rests: Vec<corner::Rest>,
    trochoidal: Analysed,
    relinks: Vec<relink::Relink>,
}

/// The trochoids-first program: `runs` first, then the pocket's `passes` (the wall passes'
/// corners fitted), re-simulated, links over the threshold replaced. With `before` (a program
/// whose runs were the first `k` of `runs`), the engagement along those runs' moves is taken
/// from it. The tool's clearance is measured from `walls`.
fn build(
    regions: &[Region],
    walls: &[Region],
    passes: &[Pass],
    runs: &[Run],
    s: &Settings,
    before: Option<(&Analysed, usize)>,
) -> Built {
    let wall = s.radius + s.allowance;
    let mut troch = Program::default();
    let mut same = 0;
    for (k, run) in runs.iter().enumerate() {
        if before.is_some_and(|(_, kept)| k == kept) {
            same = troch.moves.len();
        }
        trochoid::push_varying(&mut troch, &run.points, &run.radii, &run.pitches, &s.entry);
    }
    let (passes, rests) = round_walls(passes, &troch, s);
    let mut first = true;
    for (ri, region) in regions.iter().enumerate() {
        let mine: Vec<Pass> = passes.iter().filter(|p| p.region == ri).cloned().collect();
        if first && !troch.moves.is_empty() {
            // Start the passes with a retract: the trochoids end somewhere in the pocket.
            let mut rest = Program::default();
            rest.push_passes(&mine, region, wall);
            if let Some(m) = rest.moves.first_mut() {
                m.retract_before = true;
            }
            troch.moves.extend(rest.moves);
        } else {
            troch.push_passes(&mine, region, wall);
        }
        first = false;
    }
    let mut trochoidal = match before {
        Some((a, _)) => analyse_after(troch, s, walls, a, same),
        None => analyse(troch, s, walls),
    };
    // Links over the threshold: their passes started on cleared ground instead (one link a
    // round, re-simulated each time; a second round on the same link makes it a retract, and so
    // does a link into an open pass, or one still over when the rounds run out).
    let mut relinks = Vec::new();
    for _ in 0..RELINK_ROUNDS {
        let Some(&i) = links_over(&trochoidal, s.threshold).first() else {
            break;
        };
        let p = match relink::relink(&trochoidal.program, i, s.radius, wall, s.sample, regions) {
            Some((p, how)) => {
                relinks.push(how);
                p
            }
            None => retracted(&trochoidal.program, &[i], s.radius, &mut relinks),
        };
        // The moves before the link are the same: their engagement is reused.
        trochoidal = analyse_after(p, s, walls, &trochoidal, i);
    }
    // Links still over the threshold when the rounds ran out: retracts (again while a link
    // meets material a dropped one no longer cuts; each round drops one link or more).
    loop {
        let over = links_over(&trochoidal, s.threshold);
        let Some(&first) = over.first() else { break };
        let p = retracted(&trochoidal.program, &over, s.radius, &mut relinks);
        trochoidal = analyse_after(p, s, walls, &trochoidal, first);
    }
    debug_assert!(trochoidal.program.continuous(), "a chain of the program jumps");
    Built { passes, rests, trochoidal, relinks }
}

/// Largest engagement (degrees) at which an entry counts as meeting no material.
const IDLE_ENTRY_DEG: f64 = 1e-6;

/// `a` without the entries that meet no material at any sample (earlier runs of the layer
/// cleared their disk to its depth): their runs start with a plunge on cleared ground instead,
/// as a relink's retract does, not a helix at the slot feed down through air. `a` as it was if
/// the re-simulation then finds more over the threshold (a sliver between samples). With the
/// count dropped.
fn drop_idle_entries(a: Analysed, s: &Settings, walls: &[Region]) -> (Analysed, usize) {
    let moves = &a.program.moves;
    let mut worst = vec![0.0f64; moves.len()];
    for (&(i, _), &e) in a.samples.iter().zip(&a.engagement) {
        worst[i] = worst[i].max(e);
    }
    let mut keep = Program::default();
    let (mut dropped, mut first) = (0, None);
    let mut i = 0;
    while i < moves.len() {
        let mut j = i + 1;
        if moves[i].tag == Tag::Entry && moves[i].retract_before {
            while j < moves.len() && moves[j].tag == Tag::Entry && !moves[j].retract_before {
                j += 1;
            }
            if worst[i..j].iter().all(|&e| e <= IDLE_ENTRY_DEG) {
                first.get_or_insert(keep.moves.len());
                dropped += 1;
                if let Some(next) = moves.get(j) {
                    let mut start = *next;
                    start.retract_before = true;
                    keep.moves.push(start);
                    j += 1;
                }
                i = j;
                continue;
            }
        }
        keep.moves.extend_from_slice(&moves[i..j]);
        i = j;
    }
    let Some(first) = first else { return (a, 0) };
    let b = analyse_after(keep, s, walls, &a, first);
    if (b.over, b.over_links) > (a.over, a.over_links) || b.max_cutting > a.max_cutting + ENGAGEMENT_ROUNDOFF_DEG {
        return (a, 0);
    }
    (b, dropped)
}

/// Indices of the links of `a` with a sample over `threshold` beyond round-off, in order.
fn links_over(a: &Analysed, threshold: f64) -> Vec<usize> {
    let mut out: Vec<usize> = a
        .samples
        .iter()
        .zip(&a.engagement)
        .filter(|((i, _), e)| a.program.moves[*i].tag == Tag::Link && **e > threshold + ENGAGEMENT_ROUNDOFF_DEG)
        .map(|((i, _), _)| *i)
        .collect();
    out.dedup();
    out
}

/// `p` with the links at `links` (indices, increasing) made retracts, each noted in `relinks`
/// (the plunge at the next move's start, with the engagement of a tool of radius `r` standing
/// there after everything cut before).
fn retracted(p: &Program, links: &[usize], r: f64, relinks: &mut Vec<relink::Relink>) -> Program {
    let mut q = p.clone();
    let cut = Cut::new(r, p.moves.iter().map(|m| m.seg).collect());
    for &i in links {
        let at = p.moves.get(i + 1).map_or(p.moves[i].seg.end(), |m| m.seg.start());
        relinks.push(relink::Relink { at, standing_deg: cut.engagement_at(&at, i).to_degrees(), retract: true });
    }
    for &i in links.iter().rev() {
        q.retract_link(i);
    }
    q
}

/// Samples (piece, fraction) of cutting moves (trochoids and passes) whose engagement is over
/// `threshold` beyond round-off, with the engagement (degrees).
fn cutting_over<'a>(
    program: &'a Program,
    samples: &'a [(usize, f64)],
    engagement: &'a [f64],
    threshold: f64,
) -> impl Iterator<Item = ((usize, f64), f64)> + 'a {
    samples.iter().zip(engagement).filter_map(move |(&(i, t), &e)| {
        (matches!(program.moves[i].tag, Tag::Trochoid | Tag::Contour) && e > threshold + ENGAGEMENT_ROUNDOFF_DEG)
            .then_some(((i, t), e))
    })
}

/// Points of the material met over the threshold by cutting moves (trochoids and passes) of
/// `a`: along each arc of the tool circle in material at each such sample, at most `s.sample`
/// mm apart, ends included.
fn over_material(a: &Analysed, s: &Settings) -> Vec<P2> {
    let over: Vec<(usize, f64)> =
        cutting_over(&a.program, &a.samples, &a.engagement, s.threshold).map(|(it, _)| it).collect();
    if over.is_empty() {
        return Vec::new();
    }
    let cut = Cut::new(s.radius, a.program.moves.iter().map(|m| m.seg).collect());
    let r = s.radius;
    over.iter()
        .flat_map(|&(i, t)| {
            let p = a.program.moves[i].seg.point_at(t);
            cut.material(i, t)
                .into_iter()
                .flat_map(move |(a0, a1)| {
                    let n = ((a1 - a0) * r / s.sample).ceil().max(1.0) as usize;
                    (0..=n).map(move |k| {
                        let th = a0 + (a1 - a0) * k as f64 / n as f64;
                        P2::new(p.x + r * th.cos(), p.y + r * th.sin())
                    })
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Corner radii (mm) tried, smallest first, when the wall passes' corners are fitted by
/// simulation.
pub const CORNER_RADII: [f64; 18] =
    [0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.25, 2.5, 2.75, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0];

/// The passes with the wall passes' (level 0) sharp inside corners rounded, and the rest each
/// rounded corner leaves. Each corner's radius is the given one, or none (kept sharp) if the
/// sharp corner holds the threshold in the simulation (shallow turns), or the smallest of
/// [`CORNER_RADII`] whose simulated engagement (after the trochoids and every inner pass) stays
/// at or under the threshold; where none does, the one with the lowest engagement (and the
/// whole-program check reports it).
fn round_walls(passes: &[Pass], troch: &Program, s: &Settings) -> (Vec<Pass>, Vec<corner::Rest>) {
    let mut before: Vec<camkit::contour::Seg> = troch.moves.iter().map(|m| m.seg).collect();
    let is_wall = |p: &Pass| p.level == 0 && !p.clean_up;
    for p in passes.iter().filter(|p| !is_wall(p)) {
        before.extend(p.contour.segs());
    }
    let base = Cut::new(s.radius, before);
    let limit = s.threshold + ENGAGEMENT_ROUNDOFF_DEG;
    let step = s.sample.min(0.25);
    let mut rests = Vec::new();
    let out = passes
        .iter()
        .map(|p| {
            if !is_wall(p) {
                return p.clone();
            }
            let start = corner::start_mid_line(&p.contour);
            let corners = corner::inside_corners(&start);
            let fits: Vec<(f64, Option<f64>)> = match s.corner_radius {
                Some(r) => corners.iter().map(|_| (r, None)).collect(),
                None => corner::fit_corners(&base, &start, &CORNER_RADII, limit, trochoid::PITCH_MARGIN_DEG, step)
                    .into_iter()
                    .map(|f| match f {
                        Ok((r, e)) | Err((r, e)) => (r, Some(e)),
                    })
                    .collect(),
            };
            let at = |i: usize| corners.iter().position(|&c| c == i);
            let (contour, rounded) = corner::round_with(&start, |i| at(i).map_or(0.0, |k| fits[k].0));
            // Corners kept sharp (radius 0: they hold the threshold) make no arc and leave no rest.
            rests.extend(rounded.into_iter().zip(fits.iter().filter(|f| f.0 > 0.0)).map(|(k, f)| corner::Rest {
                corner: k.at - k.inward * (s.radius / (0.5 * k.turn).cos()),
                inward: k.inward,
                rho: k.rho,
                turn: k.turn,
                tool: s.radius,
                fitted_deg: f.1,
            }));
            Pass { contour, ..p.clone() }
        })
        .collect();
    (out, rests)
}

/// The medial axis as polylines: edges joined end to end through vertices where exactly two
/// edges meet, so that a trochoid run does not start over at every Voronoi vertex.
fn chains(edges: &[medial::MedialEdge]) -> Vec<Vec<P2>> {
    let key = |p: &P2| ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64);
    let mut at: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, e) in edges.iter().enumerate() {
        at.entry(key(&e.points[0])).or_default().push(i);
        at.entry(key(&e.points[e.points.len() - 1])).or_default().push(i);
    }
    let mut used = vec![false; edges.len()];
    let mut out = Vec::new();
    // Start at chain ends (vertices of degree other than two) first, then close loops.
    let mut order: Vec<usize> = (0..edges.len()).collect();
    order.sort_by_key(|&i| {
        let e = &edges[i];
        let deg = |p: &P2| at.get(&key(p)).map_or(0, Vec::len);
        u8::from(deg(&e.points[0]) == 2 && deg(&e.points[e.points.len() - 1]) == 2)
    });
    for start in order {
        if used[start] {
            continue;
        }
        used[start] = true;
        let mut line = edges[start].points.clone();
        let deg = |p: &P2| at.get(&key(p)).map_or(0, Vec::len);
        if deg(&line[0]) == 2 && deg(&line[line.len() - 1]) != 2 {
            // Walk from the free end.
            line.reverse();
        }
        loop {
            let end = key(&line[line.len() - 1]);
            let Some(next) = at.get(&end).filter(|v| v.len() == 2).and_then(|v| v.iter().copied().find(|&j| !used[j]))
            else {
                break;
            };
            used[next] = true;
            let mut pts = edges[next].points.clone();
            if key(&pts[0]) != end {
                pts.reverse();
            }
            line.extend(pts.into_iter().skip(1));
        }
        out.push(line);
    }
    out
}

/// The polyline with points added so that none are more than `h` apart.
fn densify(pts: &[P2], h: f64) -> Vec<P2> {
    let mut out = vec![pts[0]];
    for w in pts.windows(2) {
        let n = ((w[1] - w[0]).norm() / h).ceil().max(1.0) as usize;
        out.extend((1..=n).map(|k| w[0] + (w[1] - w[0]) * (k as f64 / n as f64)));
    }
    out
}

/// Index ranges of the maximal runs of consecutive flags that pass `keep`.
fn spans<F: Copy>(flags: &[F], keep: impl Fn(F) -> bool) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = None;
    for (i, &f) in flags.iter().enumerate() {
        match (keep(f), start) {
            (true, None) => start = Some(i),
            (false, Some(a)) => {
                out.push((a, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(a) = start {
        out.push((a, flags.len()));
    }
    out
}

/// A stretch with a loop (radius, pitch) per point cut into pieces along which the radius only
/// shrinks: split where the trend turns (the turning point in both pieces), each piece directed
/// from its larger loops to its smaller.
fn shrinking(pts: &[P2], loops: &[(f64, f64)]) -> Vec<(Vec<P2>, Vec<f64>, Vec<f64>)> {
    let mut out = Vec::new();
    let mut start = 0;
    let mut trend = 0.0;
    let mut push = |a: usize, b: usize, trend: f64| {
        let mut p = pts[a..b].to_vec();
        let mut l = loops[a..b].to_vec();
        if trend > 0.0 {
            p.reverse();
            l.reverse();
        }
        out.push((p, l.iter().map(|x| x.0).collect(), l.iter().map(|x| x.1).collect()));
    };
    for i in 1..loops.len() {
        let d = loops[i].0 - loops[i - 1].0;
        let d = if d.abs() <= camkit::tol::OFFSET_TOL { 0.0 } else { d.signum() };
        if d != 0.0 && trend != 0.0 && d != trend {
            push(start, i, trend);
            start = i - 1;
        }
        if d != 0.0 {
            trend = d;
        }
    }
    push(start, loops.len(), trend);
    out
}

/// Maximal runs of consecutive points whose flags pass `keep` (runs of one point included).
fn stretches<F: Copy>(pts: &[P2], flags: &[F], keep: impl Fn(F) -> bool) -> Vec<Vec<P2>> {
    let mut out = Vec::new();
    let mut cur: Vec<P2> = Vec::new();
    for (p, &f) in pts.iter().zip(flags) {
        if keep(f) {
            cur.push(*p);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Points hashed on a grid for "is any within r" queries.
struct PointGrid {
    cell: f64,
    map: HashMap<(i64, i64), Vec<P2>>,
}

impl PointGrid {
    fn new(pts: &[P2], cell: f64) -> PointGrid {
        let mut map: HashMap<(i64, i64), Vec<P2>> = HashMap::new();
        for p in pts {
            map.entry(((p.x / cell).floor() as i64, (p.y / cell).floor() as i64)).or_default().push(*p);
        }
        PointGrid { cell, map }
    }

    fn any_within(&self, p: &P2, r: f64) -> bool {
        let (kx, ky) = ((p.x / self.cell).floor() as i64, (p.y / self.cell).floor() as i64);
        (kx - 1..=kx + 1).any(|x| {
            (ky - 1..=ky + 1).any(|y| self.map.get(&(x, y)).is_some_and(|v| v.iter().any(|q| (q - p).norm() <= r)))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_cut_where_the_loops_stop_shrinking() {
        let pts: Vec<P2> = (0..7).map(|k| P2::new(f64::from(k), 0.0)).collect();
        let r = [1.0, 2.0, 3.0, 3.0, 2.0, 1.0, 2.0];
        let loops: Vec<(f64, f64)> = r.iter().map(|&x| (x, 0.1 * x)).collect();
        let pieces = shrinking(&pts, &loops);
        assert_eq!(pieces.len(), 3);
        for (p, radii, pitches) in &pieces {
            assert_eq!(p.len(), radii.len());
            assert!(radii.windows(2).all(|w| w[1] <= w[0]), "{radii:?}");
            assert!(pitches.iter().zip(radii).all(|(p, r)| (p - 0.1 * r).abs() < 1e-12));
        }
        // Every point is in some piece; turning points are shared.
        assert_eq!(pieces[0].0[0], P2::new(3.0, 0.0));
        assert_eq!(pieces[1].0[0], P2::new(3.0, 0.0));
        assert_eq!(pieces[2].0, vec![P2::new(6.0, 0.0), P2::new(5.0, 0.0)]);
        assert_eq!(spans(&[true, true, false, true], |f| f), vec![(0, 2), (3, 4)]);
        assert!((SMALLEST_LOOP - LEVEL_RATIO.powi(LEVELS as i32 - 1)).abs() < 1e-15);
    }

    #[test]
    fn side_cut_is_the_closed_form_and_the_default_step_meets_the_threshold() {
        // The step over R(1 − cos θ) side-cuts at θ; 0.6 R at acos(0.4) = 66.42°; 2R and more: a slot.
        for theta in [30.0f64, 40.0] {
            assert!((side_cut_deg(5.0, default_step(5.0, theta)) - theta).abs() < 1e-9);
        }
        assert!((side_cut_deg(2.0, 1.2) - 0.4f64.acos().to_degrees()).abs() < 1e-12);
        assert_eq!(side_cut_deg(2.0, 4.0), 180.0);
        assert_eq!(side_cut_deg(2.0, 5.0), 180.0);
    }

    #[test]
    fn runs_inside_earlier_loops_are_dropped() {
        let run = |pts: &[(f64, f64)], r: f64| Run {
            points: pts.iter().map(|&(x, y)| P2::new(x, y)).collect(),
            radii: vec![r; pts.len()],
            pitches: vec![0.1; pts.len()],
        };
        let along: Vec<(f64, f64)> = (0..=20).map(|k| (0.25 * f64::from(k), 0.0)).collect();
        let first = run(&along, 2.0);
        // The same stretch a micron off (a circle's centre drawn as many short edges).
        let again = run(&[(0.0, 1e-4), (1e-4, 0.0)], 2.0 - 5e-4);
        // Smaller loops inside the first's.
        let inner = run(&[(1.0, 0.5), (4.0, -0.5)], 1.0);
        // Reaching past them by more than the tolerance, or elsewhere.
        let past = run(&[(1.0, 0.0), (6.0, 0.0)], 2.0);
        let away = run(&[(20.0, 0.0)], 2.0);
        let kept = uncovered(vec![first.clone(), again, inner, past.clone(), away.clone()]);
        assert_eq!(kept, vec![first, past, away]);
    }
}
