//! Input from a path or standard input, output written whole or not at all, and spools (what a
//! later stage reads back, kept on disk: [`spool`]).

use crate::error::{Error, Result};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

pub mod spool;
pub mod stdout;
pub use spool::{DiskFailure, Get, Record, RecordSpool, Records, Share, Spool, Spooled, View};

/// The temporary files outputs are being written to: an interrupt removes them (see
/// [`remove_pending`]), so that a run stopped while writing or committing leaves nothing behind.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// A new temporary file `.camkit-*.tmp` in `dir` (mode 0666 less the umask), registered for
/// [`remove_pending`] under the same lock it is created in: an interrupt between creating it and
/// registering it would leave it behind.
fn registered_temp(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    use std::os::unix::fs::PermissionsExt;
    let mut guard = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    let tmp = tempfile::Builder::new()
        .prefix(".camkit-")
        .suffix(".tmp")
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)?;
    guard.push(tmp.path().to_path_buf());
    Ok(tmp)
}

/// Registers (`true`) or forgets a temporary file for [`remove_pending`].
fn pending(path: &Path, add: bool) {
    let mut guard = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    guard.retain(|p| p != path);
    if add {
        guard.push(path.to_path_buf());
    }
}

/// Removes the output files being written, if any, and keeps any other commit from starting:
/// for the interrupt handler ([`crate::cli::run`]), which exits right after.
pub fn remove_pending() {
    let guard = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    for path in guard.iter() {
        let _ = std::fs::remove_file(path);
    }
    // Held until the process exits: a commit cannot rename the file into place meanwhile.
    std::mem::forget(guard);
}

/// A whole input, read into memory, with the name errors should show.
#[derive(Clone, Debug)]
pub struct Input {
    /// The file name as given, `stdin` for standard input.
    pub name: String,
    /// The bytes.
    pub data: Vec<u8>,
}

impl Input {
    /// Reads `arg`: a path, or `-` for standard input.
    pub fn open(arg: &str) -> Result<Input> {
        if arg == "-" {
            let mut data = Vec::new();
            std::io::stdin().lock().read_to_end(&mut data).map_err(|e| Error::io(e, "stdin"))?;
            return Ok(Input { name: "stdin".into(), data });
        }
        let data = std::fs::read(arg).map_err(|e| Error::io(e, &format!("cannot read {arg}")))?;
        Ok(Input { name: arg.to_string(), data })
    }

    /// The input as text; invalid UTF-8 is an input error naming the line.
    pub fn text(&self) -> Result<&str> {
        std::str::from_utf8(&self.data).map_err(|e| self.not_utf8(e.valid_up_to()))
    }

    /// The input as owned text, moved out without a copy (`data` is left empty); invalid UTF-8
    /// is an input error naming the line (and `data` is kept).
    pub fn take_text(&mut self) -> Result<String> {
        String::from_utf8(std::mem::take(&mut self.data)).map_err(|e| {
            let valid = e.utf8_error().valid_up_to();
            self.data = e.into_bytes();
            self.not_utf8(valid)
        })
    }

    /// The error for text that stops being UTF-8 after `valid` bytes.
    fn not_utf8(&self, valid: usize) -> Error {
        let line = self.data[..valid].iter().filter(|&&b| b == b'\n').count() as u64 + 1;
        Error::input("text is not valid UTF-8").at(crate::error::Location::file(&self.name).line(line))
    }

    /// The file extension in lower case (empty for standard input).
    pub fn extension(&self) -> String {
        Path::new(&self.name).extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase()
    }
}

/// An input read as a stream, from its start as often as needed, never held whole: a file, or
/// standard input (or a pipe named as a file) copied first to an unnamed temporary file (on disk,
/// not in memory).
#[derive(Debug)]
pub struct Source {
    /// The file name as given, `stdin` for standard input.
    pub name: String,
    file: std::fs::File,
}

impl Source {
    /// Opens `arg`: a path, or `-` for standard input.
    pub fn open(arg: &str) -> Result<Source> {
        if arg == "-" {
            let cannot = |e| Error::io(e, "stdin");
            let mut file = tempfile::tempfile().map_err(cannot)?;
            std::io::copy(&mut std::io::stdin().lock(), &mut file).map_err(cannot)?;
            return Ok(Source { name: "stdin".into(), file });
        }
        let cannot = |e| Error::io(e, &format!("cannot read {arg}"));
        let file = std::fs::File::open(arg).map_err(cannot)?;
        let meta = file.metadata().map_err(cannot)?;
        if !meta.is_file() && !meta.is_dir() {
            // A pipe (`<(…)`, /dev/stdin) or a device reads once: copied first, as standard input.
            let mut copy = tempfile::tempfile().map_err(cannot)?;
            std::io::copy(&mut &file, &mut copy).map_err(cannot)?;
            return Ok(Source { name: arg.to_string(), file: copy });
        }
        // A directory opens but cannot be read: say so now, as reading it whole would.
        (&file).read(&mut [0u8; 1]).map_err(cannot)?;
        Ok(Source { name: arg.to_string(), file })
    }

    /// A buffered reader from the start of the input.
    pub fn reader(&self) -> Result<std::io::BufReader<std::fs::File>> {
        use std::io::Seek;
        let mut file = self.file.try_clone().map_err(|e| Error::io(e, &self.name))?;
        file.rewind().map_err(|e| Error::io(e, &self.name))?;
        Ok(std::io::BufReader::with_capacity(1 << 16, file))
    }

    /// The input's size in bytes.
    pub fn len(&self) -> Result<u64> {
        Ok(self.file.metadata().map_err(|e| Error::io(e, &self.name))?.len())
    }

    /// True for an empty input.
    pub fn is_empty(&self) -> Result<bool> {
        Ok(self.len()? == 0)
    }
}

/// A writer that can throw away what it holds and start again (an output redone from scratch).
pub trait Restart: Write {
    /// Forgets everything written so far.
    fn restart(&mut self) -> std::io::Result<()>;
}

impl Restart for Vec<u8> {
    fn restart(&mut self) -> std::io::Result<()> {
        self.clear();
        Ok(())
    }
}

/// Output written as it is made into a temporary file, never held in memory, and delivered whole
/// on [`Stream::commit`]: a file's temporary sits beside it and is renamed into place (an
/// interrupt removes it); standard output, a device or a pipe get an unnamed temporary file
/// copied to them. A run that fails before committing leaves no file and prints nothing.
#[derive(Debug)]
pub struct Stream {
    shown: String,
    /// The file renamed into place, and the mode of the file it replaces, if any.
    target: Option<(PathBuf, Option<std::fs::Permissions>)>,
    named: Registered,
    file: std::io::BufWriter<std::fs::File>,
    written: u64,
}

impl Stream {
    /// Output to `path`, or to standard output when `None` or `-`.
    pub fn new(path: Option<&Path>) -> Result<Stream> {
        let path = path.filter(|p| p.as_os_str() != "-");
        let shown = path.map_or("stdout".to_string(), |p| p.display().to_string());
        let cannot = |e: std::io::Error| Error::io(e, &format!("cannot write {shown}"));
        let unnamed = |shown: String, target| -> Result<Stream> {
            let file = tempfile::tempfile().map_err(cannot)?;
            Ok(Stream {
                shown,
                target,
                named: Registered(None),
                file: std::io::BufWriter::with_capacity(1 << 16, file),
                written: 0,
            })
        };
        let Some(path) = path else { return unnamed(shown.clone(), None) };
        let path = follow_links(path).map_err(cannot)?;
        let existing = std::fs::metadata(&path).ok();
        if existing.as_ref().is_some_and(|m| !m.is_file() && !m.is_dir()) {
            // A device or pipe is written in place at the commit (see [`write_atomic`]).
            return unnamed(shown.clone(), Some((path, None)));
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let tmp = registered_temp(&dir).map_err(cannot)?;
        let (file, named) = tmp.into_parts();
        let keep = existing.map(|m| m.permissions());
        Ok(Stream {
            shown,
            target: Some((path, keep)),
            named: Registered(Some(named)),
            file: std::io::BufWriter::with_capacity(1 << 16, file),
            written: 0,
        })
    }

    /// Bytes written so far.
    pub fn len(&self) -> u64 {
        self.written
    }

    /// True while nothing is written.
    pub fn is_empty(&self) -> bool {
        self.written == 0
    }

    /// Delivers the output.
    pub fn commit(mut self) -> Result<()> {
        use std::io::Seek;
        let shown = self.shown.clone();
        let cannot = |e: std::io::Error| Error::io(e, &format!("cannot write {shown}"));
        self.file.flush().map_err(cannot)?;
        let file = self.file.into_inner().map_err(|e| cannot(e.into_error()))?;
        match (self.target.take(), self.named.0.take()) {
            (Some((path, keep)), Some(named)) => {
                if let Some(mode) = keep {
                    file.set_permissions(mode).map_err(cannot)?;
                }
                drop(file);
                let tmp = named.to_path_buf();
                // Still registered while renamed: an interrupt then removes a name no longer there.
                let persisted = named.persist(&path).map_err(|e| cannot(e.error));
                pending(&tmp, false);
                persisted
            }
            (target, _) => {
                let mut file = file;
                file.rewind().map_err(cannot)?;
                match target {
                    Some((path, _)) => {
                        let mut dest = std::fs::OpenOptions::new().write(true).open(&path).map_err(cannot)?;
                        std::io::copy(&mut file, &mut dest).map_err(|e| Error::io(e, &shown))?;
                    }
                    None => {
                        stdout_open()?;
                        let mut out = std::io::stdout().lock();
                        std::io::copy(&mut file, &mut out)
                            .and_then(|_| out.flush())
                            .map_err(|e| Error::io(e, "stdout"))?;
                    }
                }
                Ok(())
            }
        }
    }
}

/// A temporary file registered for [`remove_pending`] until it is dropped (and deleted) or taken.
#[derive(Debug)]
struct Registered(Option<tempfile::TempPath>);

impl Drop for Registered {
    fn drop(&mut self) {
        if let Some(path) = &self.0 {
            pending(path, false);
        }
    }
}

impl Write for Stream {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        let n = self.file.write(data)?;
        self.written += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

impl Restart for Stream {
    fn restart(&mut self) -> std::io::Result<()> {
        use std::io::Seek;
        self.file.flush()?;
        self.file.get_mut().set_len(0)?;
        self.file.get_mut().rewind()?;
        self.written = 0;
        Ok(())
    }
}

/// Refuses to deliver output to a standard output that was closed at start-up.
fn stdout_open() -> Result<()> {
    if stdout::was_closed() {
        return Err(Error::input("cannot write stdout: it was closed when the filter started (give -o FILE)"));
    }
    Ok(())
}

/// Output collected in memory and delivered only on [`Output::commit`]: to a file through a
/// temporary file renamed into place, or to standard output in one write. A run that fails
/// before committing leaves no file and prints nothing.
#[derive(Debug)]
pub struct Output {
    path: Option<PathBuf>,
    /// The bytes to deliver.
    pub buf: Vec<u8>,
}

impl Output {
    /// Output to `path`, or to standard output when `None` or `-`.
    pub fn new(path: Option<&Path>) -> Output {
        let path = path.filter(|p| p.as_os_str() != "-").map(Path::to_path_buf);
        Output { path, buf: Vec::with_capacity(1 << 16) }
    }

    /// Delivers the output.
    pub fn commit(self) -> Result<()> {
        match &self.path {
            Some(path) => write_atomic(path, &self.buf),
            None => {
                stdout_open()?;
                let mut out = std::io::stdout().lock();
                out.write_all(&self.buf).and_then(|_| out.flush()).map_err(|e| Error::io(e, "stdout"))
            }
        }
    }
}

impl Write for Output {
    fn write(&mut self, data: &[u8]) -> std::io::Result<usize> {
        self.buf.extend_from_slice(data);
        Ok(data.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Writes `data` to `path` through a temporary file in the same directory, renamed into place,
/// so readers see the old file or the whole new one. A symbolic link is followed (its target is
/// replaced, the link kept); a new file gets the usual mode under the umask, a replaced one keeps
/// its mode.
pub fn write_atomic(path: &Path, data: &[u8]) -> Result<()> {
    let shown = path.display().to_string();
    let cannot = |e: std::io::Error| Error::io(e, &format!("cannot write {shown}"));
    let path = &follow_links(path).map_err(cannot)?;
    // A device or pipe (`-o /dev/null`, a FIFO) is written in place: renaming over it would
    // replace the device with a regular file.
    let existing = std::fs::metadata(path).ok();
    if existing.as_ref().is_some_and(|m| !m.is_file() && !m.is_dir()) {
        return std::fs::write(path, data).map_err(|e| Error::io(e, &shown));
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut tmp = registered_temp(&dir).map_err(cannot)?;
    let written = tmp.write_all(data).and_then(|_| tmp.flush());
    let registered = tmp.path().to_path_buf();
    let done = written
        .and_then(|_| existing.map_or(Ok(()), |m| tmp.as_file().set_permissions(m.permissions())))
        .map_err(cannot)
        .and_then(|_| tmp.persist(path).map(|_| ()).map_err(|e| cannot(e.error)));
    // Still registered while renamed (as in `Stream::commit`): an interrupt then removes a name
    // no longer there, and never leaves the temporary file.
    pending(&registered, false);
    done
}

/// `path` with symbolic links followed to the file they name (which need not exist yet).
fn follow_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut path = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&path) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&path)?;
                path = match path.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(path),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_are_written_in_place_not_replaced() {
        let null = std::path::Path::new("/dev/null");
        write_atomic(null, b"x").unwrap();
        assert!(!std::fs::metadata(null).unwrap().is_file(), "/dev/null was replaced by a file");
    }

    #[test]
    fn output_file_appears_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.csv");
        let mut out = Output::new(Some(&path));
        out.write_all(b"x,y\n").unwrap();
        assert!(!path.exists());
        out.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"x,y\n");
        let mut dropped = Output::new(Some(&dir.path().join("never.csv")));
        dropped.write_all(b"partial").unwrap();
        drop(dropped);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn taken_text_is_the_input_and_bad_utf8_names_its_line() {
        let mut good = Input { name: "a.nc".into(), data: b"G1 X1\nG1 X2\n".to_vec() };
        assert_eq!(good.take_text().unwrap(), "G1 X1\nG1 X2\n");
        assert!(good.data.is_empty());
        let mut bad = Input { name: "b.nc".into(), data: b"G1 X1\nG1 X\xff\n".to_vec() };
        let e = bad.take_text().unwrap_err();
        assert_eq!(e.exit_status(), 2);
        assert_eq!(e.to_string(), bad.text().unwrap_err().to_string());
        assert!(e.to_string().contains("b.nc:2"), "{e}");
        assert_eq!(bad.data.len(), 12, "the bytes are kept for the message");
    }

    /// A streamed output is a temporary file until committed, restarts empty, and a dropped
    /// one leaves nothing; a source reads from its start each time.
    #[test]
    fn streamed_output_appears_only_on_commit_and_sources_reread() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.nc");
        let mut out = Stream::new(Some(&path)).unwrap();
        out.write_all(b"G1 X1\n").unwrap();
        out.restart().unwrap();
        out.write_all(b"G1 X2\n").unwrap();
        assert_eq!(out.len(), 6);
        assert!(!path.exists());
        out.commit().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"G1 X2\n");
        let mut dropped = Stream::new(Some(&dir.path().join("never.nc"))).unwrap();
        dropped.write_all(b"partial").unwrap();
        drop(dropped);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "only out.nc");
        assert!(!PENDING.lock().unwrap().iter().any(|p| p.starts_with(dir.path())), "temporaries forgotten");
        let source = Source::open(path.to_str().unwrap()).unwrap();
        for _ in 0..2 {
            let mut text = String::new();
            source.reader().unwrap().read_to_string(&mut text).unwrap();
            assert_eq!(text, "G1 X2\n");
        }
        let e = Source::open(dir.path().to_str().unwrap()).unwrap_err();
        assert!(e.to_string().ends_with("Is a directory"), "{e}");
    }

    #[test]
    fn missing_input_is_an_input_error() {
        let e = Input::open("/nonexistent/file.csv").unwrap_err();
        assert_eq!(e.exit_status(), 2);
        assert_eq!(e.to_string(), "cannot read /nonexistent/file.csv: No such file or directory");
    }
}
