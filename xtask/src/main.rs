//! `cargo xtask`: Dupin's build, serve and test automation (the wgpu/eframe convention).
//!
//! - `cargo xtask setup [--browser]`: install what is missing (wasm32 target, the wasm-bindgen-cli
//!   pinned by Cargo.lock, wasm-pack; with `--browser` also Chromium, chromedriver, lavapipe and
//!   the end-to-end test's npm packages).
//! - `cargo xtask build-web`: build the wasm package into the page (settings: `wasm-pack.toml`).
//! - `cargo xtask serve [--port 8080]`: set up, build, and serve `web/` at http://127.0.0.1:8080/.
//! - `cargo xtask dist --out DIR`: set up, build, and write the page as static files to DIR.
//! - `cargo xtask test`: everything CI runs (`.ci/run` is exactly this).
//! - `cargo xtask fuzz [TARGET...] [--runs N] [--seconds S] [--seed N] [--replay] [--keep]`: coverage-guided fuzzing
//!   of the `dupin-fuzz` targets with libFuzzer on the stable toolchain.
//! - `cargo xtask layering`: print each crate's top-level module graph; fails on a cycle (also a
//!   step of `test`).

mod config;
mod dist;
mod fuzz;
mod layering;
mod serve;
mod setup;
mod test;
mod util;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "cargo xtask", about = "Dupin build, serve and test automation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Install missing tools (wasm32 target, wasm-bindgen-cli, wasm-pack; --browser: Chromium,
    /// chromedriver, lavapipe, npm packages).
    Setup {
        /// Also install the browser-test tools.
        #[arg(long)]
        browser: bool,
    },
    /// Build the wasm package of the page with wasm-pack (settings from wasm-pack.toml).
    BuildWeb,
    /// Build and serve the configurator page.
    Serve {
        /// Port on 127.0.0.1.
        #[arg(long, default_value_t = 8080)]
        port: u16,
    },
    /// Write the configurator as static files (DIR/index.html and what it loads) that any
    /// static file server can host.
    Dist {
        /// The folder to write (created; existing files are overwritten).
        #[arg(long)]
        out: std::path::PathBuf,
    },
    /// Run every check CI runs.
    Test,
    /// Fuzz the entry points that take outside data (libFuzzer, stable toolchain); fails when
    /// an input makes a target panic, hang over 10 s or allocate over 2 GB (kept in
    /// fuzz/artifacts/TARGET/).
    Fuzz {
        /// Targets to run (default: all, see fuzz/fuzz_targets/).
        targets: Vec<String>,
        /// Executions per target.
        #[arg(long)]
        runs: Option<u64>,
        /// Seconds per target.
        #[arg(long)]
        seconds: Option<u64>,
        /// libFuzzer's random seed (a new one each run by default).
        #[arg(long)]
        seed: Option<u64>,
        /// CI's run, exactly: the kept inputs and regressions only, no mutations, built at
        /// opt-level 1; overrides --runs, --seconds and --seed.
        #[arg(long)]
        replay: bool,
        /// Add the inputs that reach new coverage to fuzz/corpus/TARGET (minimised).
        #[arg(long)]
        keep: bool,
    },
    /// Print each crate's top-level module dependencies (`a -> b`) and fail on any cycle.
    Layering {
        /// Check the workspace at this directory instead of this one (e.g. another checkout).
        #[arg(long)]
        workspace: Option<std::path::PathBuf>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Setup { browser } => setup::ensure(browser).map(|installed| {
            setup::print_installed(&installed);
        }),
        Command::BuildWeb => setup::ensure(false).and_then(|installed| {
            setup::print_installed(&installed);
            config::WebBuild::load()?.build()
        }),
        Command::Serve { port } => serve::run(port),
        Command::Dist { out } => dist::run(&out).map(|files| {
            println!("dist: {} files in {}", files.len(), out.display());
        }),
        Command::Test => test::run(),
        Command::Fuzz {
            targets,
            runs,
            seconds,
            seed,
            replay,
            keep,
        } => fuzz::run(&fuzz::FuzzRun {
            targets: &targets,
            runs,
            seconds,
            seed,
            replay,
            keep,
            quick_build: replay,
        }),
        Command::Layering { workspace } => layering::print(workspace.as_deref()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: error: {e}");
            ExitCode::FAILURE
        }
    }
}
