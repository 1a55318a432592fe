//! Input from a path or standard input, and output written whole or not at all.

use crate::error::{Error, Result};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The temporary file an output is being written to, if any: an interrupt removes it (see
/// [`remove_pending`]), so that a run stopped while committing leaves nothing behind.
static PENDING: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Removes the output file being written, if any, and keeps any other commit from starting:
/// for the interrupt handler ([`crate::cli::run`]), which exits right after.
pub fn remove_pending() {
    let guard = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(path) = guard.as_ref() {
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
    use std::os::unix::fs::PermissionsExt;
    // Created under the lock: an interrupt between creating the file and naming it pending
    // would leave it behind.
    let mut tmp = {
        let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
        let tmp = tempfile::Builder::new()
            .prefix(".camkit-")
            .suffix(".tmp")
            .permissions(std::fs::Permissions::from_mode(0o666))
            .tempfile_in(&dir)
            .map_err(cannot)?;
        *pending = Some(tmp.path().to_path_buf());
        tmp
    };
    let written = tmp.write_all(data).and_then(|_| tmp.flush());
    let mut pending = PENDING.lock().unwrap_or_else(|e| e.into_inner());
    *pending = None;
    written.map_err(cannot)?;
    if let Some(m) = existing {
        tmp.as_file().set_permissions(m.permissions()).map_err(cannot)?;
    }
    tmp.persist(path).map_err(|e| cannot(e.error))?;
    Ok(())
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

    #[test]
    fn missing_input_is_an_input_error() {
        let e = Input::open("/nonexistent/file.csv").unwrap_err();
        assert_eq!(e.exit_status(), 2);
        assert_eq!(e.to_string(), "cannot read /nonexistent/file.csv: No such file or directory");
    }
}
