//! docs/guide.md runs as written: its `sh` blocks, in order, as one bash script from the
//! repository's root with the built filters first on the path (the guide's own `export PATH`
//! line is in a `text` block, so the binaries this test was built with are the ones run).

use std::path::Path;
use std::process::Command;

/// The `sh` blocks of a Markdown text, joined in order.
fn sh_blocks(markdown: &str) -> String {
    let mut script = String::new();
    let mut inside = false;
    for line in markdown.lines() {
        match (inside, line.trim_end()) {
            (false, "```sh") => inside = true,
            (true, "```") => inside = false,
            (true, l) => {
                script.push_str(l);
                script.push('\n');
            }
            _ => {}
        }
    }
    script
}

#[test]
fn the_guide_runs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let guide = std::fs::read_to_string(root.join("docs/guide.md")).expect("docs/guide.md");
    let script = sh_blocks(&guide);
    assert!(script.lines().count() > 20, "the guide's commands: {script}");
    let path = format!("{}:{}", e2e::bin_dir().display(), std::env::var("PATH").unwrap_or_default());
    let out = Command::new("bash")
        .args(["-euo", "pipefail", "-c", &script])
        .current_dir(&root)
        .env("PATH", path)
        .output()
        .expect("bash runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "the guide failed:\n{stdout}\n{stderr}");
    // What the guide tells the reader to look for.
    for needle in ["\"rapids_into_material\": 0", "\"part_collisions\": 0", "\"lines_not_covered\": 0"] {
        assert!(stdout.contains(needle), "{needle} not shown:\n{stdout}");
    }
    assert!(stdout.contains("refused, as it should be"), "{stdout}");
}
