//! Helpers shared by the CLI end-to-end tests: run the built `dupin`, name temp files, read
//! JSON reports, and check the two outcomes every command has (a run that wrote its mesh and
//! report, or a refusal with one `error:` line).
#![allow(dead_code)] // each test file uses its own subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A file name in the temp directory, unique per test process.
pub fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("dupin-test-{}-{name}", std::process::id()))
}

/// Runs the `dupin` binary of this build.
pub fn dupin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dupin"))
        .args(args)
        .output()
        .expect("dupin runs")
}

/// Runs `dupin` and asserts that it succeeded (the failure message is its stderr).
pub fn dupin_ok(args: &[&str]) -> Output {
    let o = dupin(args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// Runs `dupin` and returns its exit code (-1 when it has none), stdout and stderr as text.
pub fn dupin_text(args: &[&str]) -> (i32, String, String) {
    let o = dupin(args);
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Runs `dupin args` and asserts the refusal contract every command keeps: exit code 2 and
/// exactly one stderr line, starting `error:`. Returns stdout and stderr.
pub fn refused(args: &[&str]) -> (String, String) {
    let (code, out, err) = dupin_text(args);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
    assert!(err.starts_with("error:"), "{args:?}: {err}");
    (out, err)
}

/// Reads a JSON file.
pub fn json(p: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// The scene names docs/cli.md gives in `dupin COMMAND`'s section: the backquoted words of
/// its `Scenes:` sentence. The outside contract's names are written there, so a test comparing
/// them with `--list-scenes` keeps the code, the docs and the contract in step.
pub fn documented_scenes(command: &str) -> Vec<String> {
    let doc = include_str!("../../../../docs/cli.md");
    let heading = format!("## `dupin {command}`");
    let section = doc.split(&heading).nth(1).expect("the command's section");
    let section = section.split("\n## ").next().unwrap();
    let sentence = section
        .split("Scenes: ")
        .nth(1)
        .expect("a Scenes: sentence");
    let sentence = sentence.split(". ").next().unwrap();
    sentence
        .split('`')
        .skip(1)
        .step_by(2)
        .map(String::from)
        .collect()
}

/// The names `dupin COMMAND --list-scenes` prints, one a line (asserting that it succeeds).
pub fn listed_scenes(command: &str) -> Vec<String> {
    let o = dupin_ok(&[command, "--list-scenes"]);
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(String::from)
        .collect()
}

/// What one `dupin ... --out OUT --report REPORT` run left behind: the process output, the
/// written OBJ (or other `--out` file) as text and the JSON report, each when written. The temp
/// files are removed once read.
pub struct Run {
    /// Exit status, stdout and stderr.
    pub o: Output,
    /// The `--out` file's text.
    pub out: Option<String>,
    /// The `--report` file.
    pub report: Option<serde_json::Value>,
}

impl Run {
    /// Stdout as text.
    pub fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.o.stdout).into_owned()
    }

    /// Stderr as text.
    pub fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.o.stderr).into_owned()
    }

    /// Asserts success and returns the report.
    pub fn ok(&self) -> &serde_json::Value {
        assert!(self.o.status.success(), "{}", self.stderr());
        self.report.as_ref().expect("a report")
    }

    /// Asserts exit code 3 (the result misses what was asked): one `error:` line on stderr,
    /// the output and the report written, the report's `converged` false with a `reason`.
    /// Returns the report.
    pub fn unmet(&self) -> &serde_json::Value {
        let err = self.stderr();
        assert_eq!(self.o.status.code(), Some(3), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.starts_with("error: "), "{err}");
        assert!(self.out.is_some(), "the output is written");
        let r = self.report.as_ref().expect("a report");
        assert_eq!(r["converged"], false, "{r}");
        assert!(r["reason"].as_str().is_some_and(|s| !s.is_empty()), "{r}");
        r
    }

    /// Asserts exit code 2 and returns the error text.
    pub fn fails(&self) -> String {
        assert_eq!(self.o.status.code(), Some(2), "{}", self.stderr());
        self.stderr()
    }

    /// The `--out` file parsed as an OBJ mesh.
    pub fn mesh(&self) -> dupin_core::mesh::PolyMesh {
        dupin_core::mesh::parse_obj(self.out.as_deref().expect("an output file")).unwrap()
    }
}

/// Runs `dupin ARGS --out OUT --report REPORT`, OUT and REPORT temp files named after `name`
/// (`NAME-out.obj`, `NAME.json`; distinct per test, as tests run in parallel), and reads both
/// back.
pub fn run_reported(name: &str, args: &[&str]) -> Run {
    let (out, report) = (
        tmp(&format!("{name}-out.obj")),
        tmp(&format!("{name}.json")),
    );
    for p in [&out, &report] {
        let _ = std::fs::remove_file(p);
    }
    let mut all = args.to_vec();
    all.extend(["--out", out.to_str().unwrap()]);
    all.extend(["--report", report.to_str().unwrap()]);
    let run = Run {
        o: dupin(&all),
        out: std::fs::read_to_string(&out).ok(),
        report: report.exists().then(|| json(&report)),
    };
    for p in [out, report] {
        let _ = std::fs::remove_file(p);
    }
    run
}

/// `COMMAND` followed by the words of `line` (split at white space), the word `OUT` standing
/// for `out`: so that a table of refused cases reads as the command lines it runs.
pub fn command_line<'a>(command: &'a str, line: &'a str, out: &'a str) -> Vec<&'a str> {
    std::iter::once(command)
        .chain(
            line.split_whitespace()
                .map(|w| if w == "OUT" { out } else { w }),
        )
        .collect()
}
