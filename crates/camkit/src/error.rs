//! One error type for every filter: what went wrong, where (file, line, column, field), and
//! which exit status it maps to.

use std::fmt;

/// What kind of failure an error is; decides the exit status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// Bad input or bad usage: the user must change something. Exit status 2.
    Input,
    /// The run finished but a promised check failed (a tolerance, a convergence). Exit status 1.
    Check,
    /// The machine failed us (I/O, resources). Exit status 1.
    Runtime,
    /// The reader of our output went away; not an error for a Unix filter. Exit status 0.
    BrokenPipe,
}

/// Where in the input an error was found. Every part is optional but the file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    /// File name as the user gave it (`-` is shown as `stdin`).
    pub file: String,
    /// 1-based line number.
    pub line: Option<u64>,
    /// 1-based column: the field number in a CSV row, the character column in G-code or JSON.
    pub column: Option<u64>,
    /// What is at that place: a CSV column name, a JSON path, a G-code word.
    pub field: Option<String>,
}

impl Location {
    /// A location in `file`, nothing finer yet.
    pub fn file(file: impl Into<String>) -> Self {
        Location { file: file.into(), ..Default::default() }
    }

    /// Adds a 1-based line number.
    pub fn line(mut self, line: u64) -> Self {
        self.line = Some(line);
        self
    }

    /// Adds a 1-based column.
    pub fn column(mut self, column: u64) -> Self {
        self.column = Some(column);
        self
    }

    /// Adds what is at that place (column name, JSON path, word).
    pub fn field(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.file)?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
            if let Some(col) = self.column {
                write!(f, ":{col}")?;
            }
        }
        if let Some(field) = &self.field {
            write!(f, " ({field})")?;
        }
        Ok(())
    }
}

/// The error every `camkit` function and every filter returns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    /// What kind of failure; decides the exit status.
    pub kind: ErrorKind,
    /// Where, when the error is about a place in the input.
    pub location: Option<Location>,
    /// One line saying what is wrong, in the user's terms.
    pub message: String,
}

/// Result with the toolkit's error.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Bad input or usage (exit status 2).
    pub fn input(message: impl Into<String>) -> Self {
        Error { kind: ErrorKind::Input, location: None, message: message.into() }
    }

    /// A failed check of the result (exit status 1).
    pub fn check(message: impl Into<String>) -> Self {
        Error { kind: ErrorKind::Check, location: None, message: message.into() }
    }

    /// A runtime failure (exit status 1).
    pub fn runtime(message: impl Into<String>) -> Self {
        Error { kind: ErrorKind::Runtime, location: None, message: message.into() }
    }

    /// Attaches a location.
    pub fn at(mut self, location: Location) -> Self {
        self.location = Some(location);
        self
    }

    /// Attaches a location if none is set yet (inner errors know more than outer ones).
    pub fn or_at(mut self, location: impl FnOnce() -> Location) -> Self {
        if self.location.is_none() {
            self.location = Some(location());
        }
        self
    }

    /// The process exit status this error maps to.
    pub fn exit_status(&self) -> i32 {
        match self.kind {
            ErrorKind::Input => 2,
            ErrorKind::Check | ErrorKind::Runtime => 1,
            ErrorKind::BrokenPipe => 0,
        }
    }

    /// Wraps an I/O error met while reading or writing `what` (a file name).
    pub fn io(err: std::io::Error, what: &str) -> Self {
        if err.kind() == std::io::ErrorKind::BrokenPipe {
            return Error { kind: ErrorKind::BrokenPipe, location: None, message: "broken pipe".into() };
        }
        let kind = match err.kind() {
            // A path the user gave that cannot be a file: bad input, not a failure of the run.
            std::io::ErrorKind::NotFound
            | std::io::ErrorKind::PermissionDenied
            | std::io::ErrorKind::IsADirectory
            | std::io::ErrorKind::NotADirectory
            | std::io::ErrorKind::InvalidFilename => ErrorKind::Input,
            _ => ErrorKind::Runtime,
        };
        Error { kind, location: None, message: format!("{what}: {}", plain_io_message(&err)) }
    }
}

/// The I/O error's text without Rust's " (os error N)" suffix.
fn plain_io_message(err: &std::io::Error) -> String {
    let text = err.to_string();
    match text.find(" (os error") {
        Some(cut) => text[..cut].to_string(),
        None => text,
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(loc) = &self.location {
            write!(f, "{loc}: ")?;
        }
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_shape() {
        let e = Error::input("expected a number, found \"1,2x\"")
            .at(Location::file("in.csv").line(14).column(3).field("z"));
        assert_eq!(e.to_string(), "in.csv:14:3 (z): expected a number, found \"1,2x\"");
        assert_eq!(e.exit_status(), 2);
        assert_eq!(Error::check("x").exit_status(), 1);
        let pipe = Error::io(std::io::Error::from(std::io::ErrorKind::BrokenPipe), "stdout");
        assert_eq!(pipe.exit_status(), 0);
    }

    #[test]
    fn inner_location_wins() {
        let e = Error::input("bad").at(Location::file("a").line(2));
        let e = e.or_at(|| Location::file("b"));
        assert_eq!(e.to_string(), "a:2: bad");
    }
}
