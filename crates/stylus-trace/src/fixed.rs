//! The command line of the fixed-axis cutter mode (`--tool`).

use super::{Args, ModeArg, numbers, usage};
use camkit::cli::positive;
use camkit::doc::tool::Tool;
use camkit::error::{Error, Location, Result};
use camkit::geom::V3;
use camkit::io::{Input, Output};
use camkit::model::Model;
use camkit::model::cutter::Cutter;
use camkit::model::drop::DropCutter;
use camkit::report::Report;
use camkit::table::{self, WriteOptions};
use std::time::Instant;
use stylus_trace::Region;
use stylus_trace::budget::{self, Budget};
use stylus_trace::fixed_axis;
use stylus_trace::scan::Scan;

/// The fixed axis of `--axis` (default +z), unit.
fn axis(text: Option<&str>) -> Result<V3> {
    let Some(text) = text else { return Ok(V3::z()) };
    let v = numbers(text, "--axis", Some(3))?;
    V3::new(v[0], v[1], v[2])
        .try_normalize(1e-12)
        .ok_or_else(|| usage(format!("--axis must be a nonzero direction, got {text:?}")))
}

/// Drops the tool's cutter along the scan lines and writes the tips.
pub fn run(args: &Args, tool_path: &str, model: &Model, input: &Input, started: Instant, loaded: f64) -> Result<()> {
    if args.mode != ModeArg::Scan {
        return Err(usage("--tool drops the cutter along scan lines: it takes --mode scan only"));
    }
    let tool = Tool::read(tool_path)?;
    let cutter = tool.cutter().ok_or_else(|| {
        usage(format!(
            "--tool {tool_path}: a {:?} tool does not rotate; the fixed-axis mode takes flat, ball, bull and cone cutters",
            tool.kind
        ))
    })?;
    let axis = axis(args.axis.as_deref())?;
    let dc = DropCutter::new(model, cutter, axis).map_err(|u| {
        Error::input(format!("surface {}: {}", model.surfaces[u.surface].name, u.what)).at(Location::file(&input.name))
    })?;
    let region = match &args.region {
        Some(r) => *r,
        None => {
            let b = dc.bounds();
            if !b.is_bounded() {
                return Err(usage(
                    "the model is unbounded (a plane or an endless cylinder): give --region X0,X1,Y0,Y1",
                ));
            }
            Region { x0: b.min.x, x1: b.max.x, y0: b.min.y, y1: b.max.y }
        }
    };
    // As in the stylus's modes: positions far out lose the bits the exact drops rely on.
    let source = if args.region.is_some() { "--region" } else { "the model's bounding box (the default --region)" };
    let b = dc.bounds();
    let heights = if b.is_bounded() { [b.min.z, b.max.z] } else { [0.0, 0.0] };
    budget::check_round_off(
        &[region.x0, region.x1, region.y0, region.y1, heights[0], heights[1], cutter.radius()],
        positive(args.contact_tol, "--contact-tol")?,
        &format!("{}: the area the cutter drops onto within {source}", input.name),
    )?;
    if !(args.angle.is_finite() && args.angle.abs() <= 360.0) {
        return Err(usage(format!("--angle must be a number of degrees from -360 to 360, got {}", args.angle)));
    }
    let pick = positive(args.pick, "--pick")?;
    let step = positive(args.max_step, "--max-step")?;
    let bounds = Budget {
        memory: args.max_memory.saturating_mul(1_000_000) as f64,
        points: positive(args.max_points, "--max-points")?,
        weight: model.query_weight(),
    };
    let lines = budget::scan_lines(&region, args.angle, pick);
    budget::fixed_axis(lines, &region, step).check(
        &bounds,
        &format!(
            "the cutter's drops at --pick {pick} and --max-step {step} over x {}..{}, y {}..{}",
            region.x0, region.x1, region.y0, region.y1
        ),
    )?;
    let scan = Scan { region, angle: args.angle, pick, zigzag: args.zigzag };
    let progress = args.io.progress(lines as u64, "dropping the cutter");
    let dropped_at = Instant::now();
    let passes = fixed_axis::drop_lines(&dc, &scan, step, &|| progress.inc(1));
    progress.finish();
    let drop_seconds = dropped_at.elapsed().as_secs_f64();
    let points: usize = passes.iter().map(Vec::len).sum();
    if points == 0 {
        return Err(Error::input(
            "the cutter is over the model nowhere in the region: the scan region misses the model",
        )
        .at(Location::file(&input.name)));
    }
    let t = fixed_axis::table(model, &dc, &passes);
    let mut out = Output::new(args.io.output.as_deref());
    table::write(&mut out, &t, &WriteOptions { decimals: args.decimals })?;
    if let Some(path) = &args.io.report {
        let (kind, corner, half_angle) = match cutter {
            Cutter::Flat { .. } => ("flat", 0.0, None),
            Cutter::Ball { radius } => ("ball", radius, None),
            Cutter::Bull { corner, .. } => ("bull", corner, None),
            Cutter::Cone { half_angle, .. } => ("cone", 0.0, Some(half_angle.to_degrees())),
        };
        let mut r = Report::new("stylus-trace");
        r.set("mode", "drop")
            .set("cutter", kind)
            .set("radius_mm", cutter.radius())
            .set("corner_radius_mm", corner)
            .set("axis", [axis.x, axis.y, axis.z])
            .set("surfaces", model.surfaces.len())
            .set("triangles", model.triangles())
            .set("degenerate_facets_dropped", model.dropped_counts().0)
            .set("duplicate_facets_dropped", model.dropped_counts().1)
            .set("lines", lines as u64)
            .set("paths", passes.len())
            .set("points", points)
            .set("bull_edge_tol_mm", camkit::model::cutter::EDGE_TOL)
            .set("load_seconds", loaded)
            .set("trace_seconds", drop_seconds)
            .set("seconds", started.elapsed().as_secs_f64())
            .set("points_per_second", points as f64 / drop_seconds.max(1e-9))
            .set("threads", rayon::current_num_threads());
        if let Some(a) = half_angle {
            r.set("half_angle_deg", a);
        }
        r.write(path)?;
    }
    out.commit()
}
