//! What every filter's `main` shares: the program name in messages, exit statuses, the common
//! input/output/report arguments, warnings, and progress bars that appear only on a terminal.

use crate::error::{Error, Result};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::OnceLock;

static PROGRAM: OnceLock<&'static str> = OnceLock::new();

/// The running filter's name, for messages.
pub fn program() -> &'static str {
    PROGRAM.get().copied().unwrap_or("camkit")
}

/// Runs a filter's body: errors become one line on stderr (`name: file:line:col (field): what`)
/// and the exit status of their kind; a closed output pipe ends quietly with status 0; a panic
/// (a bug) prints one line, not a backtrace, and a temporary file's failing disk
/// ([`crate::io::DiskFailure`]) is a runtime failure (exit 1); an interrupt (SIGINT, SIGTERM,
/// SIGHUP) removes the output file being written and exits with 130.
pub fn run(name: &'static str, body: impl FnOnce() -> Result<()>) -> ExitCode {
    let _ = PROGRAM.set(name);
    let _ = ctrlc::set_handler(|| {
        crate::io::remove_pending();
        std::process::exit(130);
    });
    std::panic::set_hook(Box::new(|info| {
        if info.payload().is::<crate::io::DiskFailure>() {
            return; // said by the caller below
        }
        let place = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        let what = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic".into());
        eprintln!("{}: internal error (a bug, please report it): {what}{place}", program());
    }));
    // The body's values are dropped while unwinding (an output being written is removed).
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(body)).unwrap_or_else(|p| {
        match p.downcast::<crate::io::DiskFailure>() {
            Ok(f) => Err(crate::error::Error::runtime(f.0)),
            Err(p) => std::panic::resume_unwind(p),
        }
    });
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if e.kind != crate::error::ErrorKind::BrokenPipe {
                eprintln!("{name}: {}", printable(&e.to_string()));
            }
            ExitCode::from(e.exit_status() as u8)
        }
    }
}

/// `text` with control characters from the input (a CR, a NUL, an escape) shown as escapes, so
/// that a message stays one line and prints nothing raw to the terminal.
pub fn printable(text: &str) -> String {
    text.chars().flat_map(|c| if c.is_control() { c.escape_default().collect::<Vec<_>>() } else { vec![c] }).collect()
}

/// A command-line number that must be finite and above zero (`what` names the option): usage
/// errors say so in one message shape for every filter.
pub fn positive(v: f64, what: &str) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::input(format!("{what} must be a positive number, got {v}")))
    }
}

/// Parses the command line of a filter for [`run`]: help and version print and exit 0 as clap
/// does; a usage error (an unknown option, a value its parser refuses) becomes a one-line input
/// error naming the option (exit 2), like every other bad input.
pub fn parse<C: clap::Parser>() -> Result<C> {
    C::try_parse().map_err(|e| match e.kind() {
        clap::error::ErrorKind::DisplayHelp
        | clap::error::ErrorKind::DisplayVersion
        | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
        _ => {
            let text = e.render().to_string();
            // The message runs to the first blank line (a missing option is on the next line).
            let lines: Vec<&str> = text.lines().map(str::trim).take_while(|l| !l.is_empty()).collect();
            Error::input(lines.join(" ").trim_start_matches("error: ").to_string())
        }
    })
}

/// A clap value parser for numeric options: a finite number (`NaN`, `inf` and overflowing values
/// are refused with the option named, exit 2), in the message shape of the table readers. Use as
/// `#[arg(long, value_parser = camkit::cli::finite)]`.
pub fn finite(text: &str) -> std::result::Result<f64, String> {
    crate::num::parse_finite(text).map_err(|e| e.message(text))
}

/// A command-line number that must lie in `lo..=hi` (`what` names the option and `unit` its
/// unit, for the message).
pub fn within(v: f64, lo: f64, hi: f64, what: &str, unit: &str) -> Result<f64> {
    if v >= lo && v <= hi {
        Ok(v)
    } else {
        Err(Error::input(format!("{what} must be from {lo} to {hi}{unit}, got {}", short(v))))
    }
}

/// A number as a message shows it: plain, or in exponent form when very large or small.
pub fn short(v: f64) -> String {
    if v != 0.0 && !(1e-6..1e9).contains(&v.abs()) { format!("{v:e}") } else { v.to_string() }
}

/// What a filter reads or writes: the toolpath table or G-code, or decided by the input's name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// Decide by the file extension (.nc .ngc .gcode .gco .g .tap .cnc are G-code).
    Auto,
    /// The toolpath table (CSV).
    Table,
    /// G-code.
    Gcode,
}

/// Prints a warning on stderr (`name: warning: ...`).
pub fn warn(message: &str) {
    eprintln!("{}: warning: {}", program(), printable(message));
}

/// Arguments every filter takes: input, `-o`, `--report`.
#[derive(Clone, Debug, clap::Args)]
pub struct IoArgs {
    /// Input file; `-` or nothing reads standard input.
    #[arg(default_value = "-", value_name = "INPUT")]
    pub input: String,
    /// Write the output to FILE (whole or not at all) instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Write figures of the run (counts, deviations, timings) to FILE as JSON.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// No progress bars, even on a terminal (they never appear in a pipe or a file).
    #[arg(short = 'q', long)]
    pub quiet: bool,
}

impl IoArgs {
    /// A progress bar for `total` steps of `what` (see [`progress`]), hidden by `--quiet`.
    pub fn progress(&self, total: u64, what: &str) -> Progress {
        progress(self.quiet, total, what)
    }
}

/// A progress bar on stderr for `total` steps of `what`, drawn only when stderr is a terminal
/// and not `quiet`, so pipes, files and tests stay clean.
pub fn progress(quiet: bool, total: u64, what: &str) -> Progress {
    let p = Progress { bar: indicatif::ProgressBar::hidden() };
    p.stage(total, what);
    if !quiet && std::io::stderr().is_terminal() {
        // Shown only once styled and named, so its first frame is whole.
        p.bar.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        p.bar.tick();
        if total == 0 {
            p.bar.enable_steady_tick(std::time::Duration::from_millis(120));
        }
    }
    p
}

/// The value parser of `--region X0,X1,Y0,Y1`: four finite numbers with X0 < X1 and Y0 < Y1
/// (clap names the option in the error, exit 2).
pub fn region(text: &str) -> std::result::Result<crate::geom::Region, String> {
    let v: Vec<f64> = text
        .split(',')
        .map(finite)
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("expected X0,X1,Y0,Y1 (mm): {e}"))?;
    match v[..] {
        [x0, x1, y0, y1] if x0 < x1 && y0 < y1 => Ok(crate::geom::Region { x0, x1, y0, y1 }),
        [_, _, _, _] => Err(format!("expected X0,X1,Y0,Y1 with X0 < X1 and Y0 < Y1, got {text:?}")),
        _ => Err(format!("expected four numbers X0,X1,Y0,Y1 (mm), got {text:?}")),
    }
}

/// A progress bar (position, rate, ETA) or, for a stage of unknown length, a spinner with the
/// time spent; made by [`progress`].
pub struct Progress {
    bar: indicatif::ProgressBar,
}

impl Progress {
    /// Starts the next stage of a run: `total` steps of `what` counted from zero, or a spinner
    /// when `total` is 0 (the stage cannot count its steps).
    pub fn stage(&self, total: u64, what: &str) {
        let template = if total == 0 {
            "{spinner} {msg} ({elapsed})"
        } else {
            "{msg} [{bar:40}] {pos}/{len} ({per_sec}, {eta} left)"
        };
        let style = indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> ");
        self.bar.set_style(style);
        self.bar.set_length(total);
        self.bar.set_position(0);
        self.bar.set_message(what.to_string());
        self.bar.reset_eta();
        self.bar.reset_elapsed();
        if total == 0 && !self.bar.is_hidden() {
            self.bar.enable_steady_tick(std::time::Duration::from_millis(120));
        } else {
            self.bar.disable_steady_tick();
        }
    }

    /// Advances by `n` steps.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

/// A run that ends early (an error) clears its bar too, so the message stands alone.
impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failing_disk_is_a_runtime_failure_and_a_bug_still_panics() {
        let failed = || -> Result<()> { std::panic::panic_any(crate::io::DiskFailure("disk full".into())) };
        assert_eq!(run("t", failed), ExitCode::from(1));
        let bug = std::panic::catch_unwind(|| run("t", || -> Result<()> { panic!("a bug") }));
        assert!(bug.is_err());
    }

    #[test]
    fn numeric_options_are_finite_and_in_range() {
        assert_eq!(finite(" 2.5"), Ok(2.5));
        assert_eq!(finite("NaN").unwrap_err(), "expected a finite number, found \"NaN\"");
        assert!(finite("inf").is_err() && finite("1e400").is_err() && finite("x").is_err());
        assert_eq!(within(3.0, 0.0, 90.0, "--angle", "°").unwrap(), 3.0);
        let e = within(-1.0, 0.0, 90.0, "--angle", "°").unwrap_err();
        assert_eq!((e.to_string().as_str(), e.exit_status()), ("--angle must be from 0 to 90°, got -1", 2));
        assert!(within(1e300, 0.0, 1.0, "--x", "").unwrap_err().to_string().ends_with("got 1e300"));
    }
}
