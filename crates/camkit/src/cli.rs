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
/// (a bug) prints one line, not a backtrace; an interrupt (SIGINT, SIGTERM, SIGHUP) removes the
/// output file being written and exits with 130.
pub fn run(name: &'static str, body: impl FnOnce() -> Result<()>) -> ExitCode {
    let _ = PROGRAM.set(name);
    let _ = ctrlc::set_handler(|| {
        crate::io::remove_pending();
        std::process::exit(130);
    });
    std::panic::set_hook(Box::new(|info| {
        let place = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
        let what = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic".into());
        eprintln!("{}: internal error (a bug, please report it): {what}{place}", program());
    }));
    match body() {
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

impl Kind {
    /// `Auto` decided by the name of `input`; the others as they are.
    pub fn resolve(self, input: &crate::io::Input) -> Kind {
        match self {
            Kind::Auto
                if matches!(input.extension().as_str(), "nc" | "ngc" | "gcode" | "gco" | "g" | "tap" | "cnc") =>
            {
                Kind::Gcode
            }
            Kind::Auto => Kind::Table,
            k => k,
        }
    }
}

/// Parses the command line. A usage error (an unknown option, a value that is no number) is an
/// input error of one line naming the option, like every other bad input, rather than clap's
/// three lines; `--help` and `--version` print and exit as usual.
pub fn parse_args<A: clap::Parser>() -> Result<A> {
    A::try_parse().map_err(|e| match e.kind() {
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
}

/// A progress bar on stderr when stderr is a terminal; silent in pipes and tests.
pub struct Progress {
    bar: indicatif::ProgressBar,
}

impl Progress {
    /// A bar for `total` steps of `what`.
    pub fn new(total: u64, what: &str) -> Progress {
        let bar = if std::io::stderr().is_terminal() {
            let bar = indicatif::ProgressBar::new(total);
            let style = indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
            bar.set_style(style.progress_chars("=> "));
            bar.set_message(what.to_string());
            bar
        } else {
            indicatif::ProgressBar::hidden()
        };
        Progress { bar }
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
