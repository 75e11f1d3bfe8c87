//! `cargo xtask fuzz`: coverage-guided fuzzing with libFuzzer on the stable toolchain.
//!
//! cargo-fuzz needs nightly only for its sanitizer flags; the coverage instrumentation libFuzzer
//! feeds on (`-C passes=sancov-module` and LLVM's sanitizer-coverage options) is stable, so this
//! builds the `dupin-fuzz` binaries with those flags itself. The explicit `--target` keeps the
//! flags off build scripts and proc macros, as cargo-fuzz does.

use crate::util::{self, Result, cargo, root};
use std::path::{Path, PathBuf};
use std::process::Command;

/// What one fuzzing session does.
pub struct FuzzRun<'a> {
    /// The targets (all of `dupin-fuzz`'s when empty).
    pub targets: &'a [String],
    /// Stop each target after this many executions (libFuzzer's `-runs`).
    pub runs: Option<u64>,
    /// Stop each target after this many seconds (libFuzzer's `-max_total_time`).
    pub seconds: Option<u64>,
    /// The random seed (libFuzzer's `-seed`; a new one each run when `None`).
    pub seed: Option<u64>,
    /// CI's run: every kept input and regression through the instrumented binary under the
    /// limits, no mutations (overrides `runs`, `seconds` and `seed`). Mutation is not
    /// reproducible even with a fixed seed (coverage depends on hash seeds and addresses), and a
    /// CI that fails on one run and passes on the next lands nothing; fuzzing campaigns run with
    /// `--seconds` or `--runs`, and what they find becomes a regression input.
    pub replay: bool,
    /// Add the new inputs that reach new coverage to the kept corpus (`fuzz/corpus/TARGET`),
    /// minimised; otherwise the kept corpus is only read.
    pub keep: bool,
    /// Build at opt-level 1 (in its own target folder) for a short run: 80 s less to build on
    /// two cores, 30-50% slower executions (the kept corpora replay in 9 s more).
    pub quick_build: bool,
}

/// Every target: the files of `fuzz/fuzz_targets/`, sorted.
pub fn all_targets() -> Result<Vec<String>> {
    let dir = root().join("fuzz").join("fuzz_targets");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| {
            e.ok()?
                .file_name()
                .to_str()?
                .strip_suffix(".rs")
                .map(String::from)
        })
        .collect();
    names.sort();
    Ok(names)
}

/// The limits every execution must keep: a hang over 10 s or more than 2 GB is a failure.
const LIMITS: &[&str] = &["-timeout=10", "-rss_limit_mb=2048", "-malloc_limit_mb=2048"];

/// Largest input the fuzzer makes, per target: text formats need room for a few dozen lines.
fn max_len(target: &str) -> u32 {
    match target {
        "obj" | "mesh_file" | "planarize" | "nurbs_json" | "mesh_fit" => 8192,
        "point_set" => 2048,
        _ => 512,
    }
}

fn host_triple() -> Result<String> {
    let out = util::output(Command::new("rustc").arg("-vV")).ok_or("rustc -vV failed")?;
    out.lines()
        .find_map(|l| l.strip_prefix("host: "))
        .map(str::to_string)
        .ok_or_else(|| "rustc -vV names no host".into())
}

/// Builds the instrumented fuzz binaries (at opt-level 1 when `quick`); returns the folder that
/// holds them.
pub fn build(quick: bool) -> Result<PathBuf> {
    let triple = host_triple()?;
    let target_dir = root()
        .join("target")
        .join(if quick { "fuzz-quick" } else { "fuzz" });
    let flags = [
        "-Cpasses=sancov-module",
        "-Cllvm-args=-sanitizer-coverage-level=4",
        "-Cllvm-args=-sanitizer-coverage-inline-8bit-counters",
        "-Cllvm-args=-sanitizer-coverage-pc-table",
        "-Cllvm-args=-sanitizer-coverage-trace-compares",
        "--cfg=fuzzing",
        // Overflow and debug assertions on, as in the tests: the fuzzer should find what they
        // would.
        "-Cdebug-assertions",
        "-Coverflow-checks",
    ];
    util::run(
        cargo()
            .args(["build", "--release", "-p", "dupin-fuzz", "--features"])
            .args(["libfuzzer", "--bins", "--target", &triple])
            .arg("--target-dir")
            .arg(&target_dir)
            .env("RUSTFLAGS", flags.join(" "))
            .env(
                "CARGO_PROFILE_RELEASE_OPT_LEVEL",
                if quick { "1" } else { "3" },
            )
            .env_remove("CARGO_ENCODED_RUSTFLAGS"),
    )?;
    Ok(target_dir.join(triple).join("release"))
}

/// Builds and runs the targets; fails on the first target that finds a failing input (kept in
/// `fuzz/artifacts/TARGET/`).
pub fn run(r: &FuzzRun) -> Result<()> {
    let bin = build(r.quick_build)?;
    let fuzz = root().join("fuzz");
    let all = all_targets()?;
    let targets: Vec<&str> = if r.targets.is_empty() {
        all.iter().map(String::as_str).collect()
    } else {
        r.targets.iter().map(String::as_str).collect()
    };
    if let Some(t) = targets.iter().find(|t| !all.iter().any(|a| a == *t)) {
        return Err(format!(
            "no fuzz target `{t}`; the targets: {}",
            all.join(", ")
        ));
    }
    for t in targets {
        let kept = fuzz.join("corpus").join(t);
        std::fs::create_dir_all(&kept).map_err(|e| e.to_string())?;
        let scratch = root().join("target").join("fuzz").join("corpus").join(t);
        let _ = std::fs::remove_dir_all(&scratch);
        std::fs::create_dir_all(&scratch).map_err(|e| e.to_string())?;
        let artifacts = fuzz.join("artifacts").join(t);
        std::fs::create_dir_all(&artifacts).map_err(|e| e.to_string())?;
        println!("\n--- fuzz {t}");
        let mut cmd = Command::new(bin.join(t));
        cmd.args(LIMITS)
            .arg(format!("-max_len={}", max_len(t)))
            .arg(format!("-artifact_prefix={}/", artifacts.display()))
            .arg("-print_final_stats=1");
        let regressions = fuzz.join("regressions").join(t);
        if r.replay {
            // libFuzzer replays the folders it is given before it counts runs.
            cmd.arg("-runs=0");
        } else {
            if let Some(n) = r.runs {
                cmd.arg(format!("-runs={n}"));
            }
            if let Some(s) = r.seconds {
                cmd.arg(format!("-max_total_time={s}"));
            }
            if let Some(s) = r.seed {
                cmd.arg(format!("-seed={s}"));
            }
        }
        // New inputs go to the scratch folder; the kept corpus and the regressions are read.
        cmd.arg(&scratch).arg(&kept);
        if regressions.is_dir() {
            cmd.arg(&regressions);
        }
        util::run(&mut cmd).map_err(|e| format!("fuzz target {t} failed: {e}"))?;
        if r.keep {
            merge(&bin.join(t), &kept, &scratch)?;
        }
    }
    Ok(())
}

/// Adds to `kept` the inputs of `scratch` that reach coverage `kept` does not.
fn merge(bin: &Path, kept: &Path, scratch: &Path) -> Result<()> {
    util::run(
        Command::new(bin)
            .args(LIMITS)
            .arg("-merge=1")
            .arg(kept)
            .arg(scratch),
    )
}
