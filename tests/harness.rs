//! Harness for end-to-end tests: runs the built filter binaries in a scratch directory and
//! captures exit status, stdout and stderr. Build the binaries first (`make test` does).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Directory of the built binaries: the profile directory of this test executable.
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    // target/<profile>/deps/<test>-<hash>
    exe.parent().and_then(Path::parent).expect("target/<profile>").to_path_buf()
}

/// Path of a filter binary; panics with a hint if it has not been built.
pub fn bin(name: &str) -> PathBuf {
    let p = bin_dir().join(name);
    assert!(
        p.exists(),
        "{} is not built: run `cargo build --bins` (`--release` for `cargo test --release`; make test does)",
        p.display()
    );
    p
}

/// The repository's `data/` directory.
pub fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("data").join(rel)
}

/// What a run of a binary did.
#[derive(Debug)]
pub struct Outcome {
    /// Exit status (−1 if killed by a signal).
    pub status: i32,
    /// Standard output.
    pub stdout: Vec<u8>,
    /// Standard error, as text.
    pub stderr: String,
}

impl Outcome {
    /// Standard output as text.
    pub fn out(&self) -> String {
        String::from_utf8_lossy(&self.stdout).into_owned()
    }

    /// Asserts success and returns stdout as text.
    pub fn ok(&self) -> String {
        assert_eq!(self.status, 0, "expected success, stderr: {}", self.stderr);
        self.out()
    }

    /// Asserts a failure with `status` and one line on stderr containing `needle`.
    pub fn fails(&self, status: i32, needle: &str) {
        assert_eq!(self.status, status, "status; stderr: {}", self.stderr);
        assert!(self.stderr.contains(needle), "stderr {:?} lacks {needle:?}", self.stderr);
        assert_eq!(self.stderr.trim_end().lines().count(), 1, "one line on stderr: {:?}", self.stderr);
        assert!(!self.stderr.contains("panicked") && !self.stderr.contains("backtrace"), "{}", self.stderr);
    }
}

/// A scratch directory where a test writes inputs and runs filters.
pub struct Work {
    dir: tempfile::TempDir,
}

impl Default for Work {
    fn default() -> Self {
        Self::new()
    }
}

impl Work {
    /// A fresh, empty directory.
    pub fn new() -> Work {
        Work { dir: tempfile::tempdir().expect("temp dir") }
    }

    /// Path of a file in the directory.
    pub fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    /// Writes a file; returns its path.
    pub fn write(&self, name: &str, content: impl AsRef<[u8]>) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, content).expect("write input");
        p
    }

    /// Reads a file as text.
    pub fn read(&self, name: &str) -> String {
        std::fs::read_to_string(self.path(name)).unwrap_or_else(|e| panic!("read {name}: {e}"))
    }

    /// True if a file exists.
    pub fn exists(&self, name: &str) -> bool {
        self.path(name).exists()
    }

    /// Names of the files in the directory.
    pub fn files(&self) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(self.dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    /// Runs filter `name` with `args` in this directory, feeding `stdin`.
    pub fn run(&self, name: &str, args: &[&str], stdin: &[u8]) -> Outcome {
        let mut child = Command::new(bin(name))
            .args(args)
            .current_dir(self.dir.path())
            .env_remove("RUST_BACKTRACE")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn filter");
        let mut input = child.stdin.take().expect("stdin");
        // A filter may exit before reading everything (bad arguments): ignore a broken pipe here.
        let _ = input.write_all(stdin);
        drop(input);
        let out = child.wait_with_output().expect("wait");
        Outcome {
            status: out.status.code().unwrap_or(-1),
            stdout: out.stdout,
            stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        }
    }
}

impl Work {
    /// Runs filter `name` with `args` in this directory with a terminal for its streams (under
    /// util-linux `script`), returning what the terminal showed; `None` where `script` is absent.
    pub fn run_on_terminal(&self, name: &str, args: &[&str]) -> Option<Outcome> {
        Command::new("script").arg("--version").output().ok()?;
        let line = std::iter::once(bin(name).display().to_string())
            .chain(args.iter().map(|a| format!("'{a}'")))
            .collect::<Vec<_>>()
            .join(" ");
        let out = Command::new("script")
            .args(["-qec", &line, "/dev/null"])
            .current_dir(self.dir.path())
            .env_remove("RUST_BACKTRACE")
            .stdin(Stdio::null())
            .output()
            .expect("run script");
        Some(Outcome { status: out.status.code().unwrap_or(-1), stdout: out.stdout, stderr: String::new() })
    }
}

impl Work {
    /// Issue 20's promise for every numeric option: runs filter `name` on `input` (in this
    /// directory) with `base` arguments and one of `options` set to an extreme value (0,
    /// negative, NaN, ±inf, 1e-300, 1e300, tiny, huge), `count` pairs picked by a generator
    /// seeded with `seed`, each under a 4 GiB address-space limit; asserts for each: no panic,
    /// exit 0, 1 or 2, one error line on a failure (warnings aside), done within 20 s.
    pub fn fuzz_options(&self, name: &str, input: &str, base: &[&str], options: &[&str], seed: u64, count: usize) {
        const VALUES: [&str; 9] = ["0", "-1", "NaN", "inf", "-inf", "1e-300", "1e300", "1e-9", "1e9"];
        let mut state = seed;
        let mut next = |n: usize| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) as usize % n
        };
        for _ in 0..count {
            let (opt, value) = (options[next(options.len())], VALUES[next(VALUES.len())]);
            let mut args: Vec<String> = vec![input.into()];
            let mut rest = base.iter();
            while let Some(a) = rest.next() {
                if *a == opt {
                    rest.next();
                } else {
                    args.push(a.to_string());
                }
            }
            args.push(format!("{opt}={value}"));
            let started = std::time::Instant::now();
            let mut child = Command::new("sh")
                .arg("-c")
                .arg("ulimit -v 4194304; exec \"$0\" \"$@\"")
                .arg(bin(name))
                .args(&args)
                .current_dir(self.dir.path())
                .env_remove("RUST_BACKTRACE")
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .expect("spawn filter");
            let status = loop {
                if let Some(s) = child.try_wait().expect("wait") {
                    break s;
                }
                if started.elapsed().as_secs_f64() > 20.0 {
                    let _ = child.kill();
                    panic!("{name} {args:?}: still running after 20 s");
                }
                std::thread::sleep(std::time::Duration::from_millis(5));
            };
            let mut stderr = String::new();
            std::io::Read::read_to_string(&mut child.stderr.take().expect("stderr"), &mut stderr).expect("stderr");
            let code = status.code().unwrap_or(-1);
            assert!((0..=2).contains(&code), "{name} {args:?}: status {status}: {stderr}");
            assert!(!stderr.contains("internal error") && !stderr.contains("panicked"), "{name} {args:?}: {stderr}");
            let errors = stderr.lines().filter(|l| !l.trim().is_empty() && !l.contains("warning:")).count();
            assert!(code == 0 || errors == 1, "{name} {args:?}: status {code}, {errors} error lines: {stderr}");
        }
    }
}

pub mod paths;
