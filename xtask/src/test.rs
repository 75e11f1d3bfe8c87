//! `cargo xtask test`: every check, in the order a failure is cheapest to find.

use crate::config::WebBuild;
use crate::layering;
use crate::serve;
use crate::setup;
use crate::util::{self, Result, cargo, root};
use std::process::Command;
use std::time::Instant;

/// Runs all checks; stops at the first failure.
pub fn run() -> Result<()> {
    // A full run gains nothing from incremental caches, and on a small CI disk they cost
    // gigabytes (the wasm-pack children inherit this too).
    // SAFETY: set before any thread is spawned.
    unsafe { std::env::set_var("CARGO_INCREMENTAL", "0") };
    let web = WebBuild::load()?;
    let mut times = Vec::new();
    let mut step = |name: &str, f: &mut dyn FnMut() -> Result<()>| -> Result<()> {
        println!("\n==> {name}");
        let t = Instant::now();
        let r = f();
        times.push((name.to_string(), t.elapsed().as_secs_f64()));
        if let Some(gb) = util::free_disk_gb(&root()) {
            println!("    ({gb:.1} GB free on the target disk)");
        }
        r.map_err(|e| format!("{name}: {e}"))
    };
    step("setup", &mut || {
        setup::ensure(true).map(|i| setup::print_installed(&i))
    })?;
    step("rustfmt", &mut || {
        util::run(cargo().args(["fmt", "--all", "--check"]))
    })?;
    // No dependency cycles between a crate's top-level modules (a source scan: no build).
    step("module layering", &mut || layering::check())?;
    step("clippy (native)", &mut || {
        // With the fuzz binaries (libFuzzer's harness, 30 s more for its C++), so they keep
        // building; their inputs run in the native tests (`fuzz/tests/corpus.rs`).
        util::run(cargo().args([
            "clippy",
            "--workspace",
            "--all-targets",
            "--features",
            "dupin-fuzz/libfuzzer",
            "--",
            "-D",
            "warnings",
        ]))
    })?;
    step("clippy (wasm32)", &mut || {
        // Libraries, plus the web crate's wasm tests; benches and native tests stay native.
        let wasm = ["--target", "wasm32-unknown-unknown", "--", "-D", "warnings"];
        util::run(
            cargo()
                .args(["clippy", "-p", "dupin-core", "-p", "dupin-render", "--lib"])
                .args(wasm),
        )?;
        util::run(
            cargo()
                .args(["clippy", "-p", "dupin-web", "--lib", "--tests"])
                .args(wasm),
        )?;
        // The viewer-only module (shared presentations, `<dupin-viewer>`).
        util::run(
            cargo()
                .args([
                    "clippy",
                    "-p",
                    "dupin-web",
                    "--lib",
                    "--no-default-features",
                ])
                .args(wasm),
        )
    })?;
    step("native tests", &mut || {
        util::run(cargo().args(["test", "--workspace"]))
    })?;
    step("docs", &mut || {
        util::run(
            cargo()
                .args(["doc", "--workspace", "--no-deps"])
                .env("RUSTDOCFLAGS", "-D warnings"),
        )
    })?;
    step(
        "free the native test build if the disk is short",
        &mut || free_native_tests_if_short(),
    )?;
    step("core tests on wasm32 (Node)", &mut || {
        // The core's wasm32 test files run under wasm-bindgen-test-runner in Node. `-p
        // dupin-web` (which has no such test) only unifies features with the web crate's
        // build below, so that build reuses this one's faer, gemm and nalgebra instead of
        // compiling them again (bytemuck's features differ otherwise): 2 minutes less.
        util::run(
            cargo()
                .args([
                    "test",
                    "-p",
                    "dupin-core",
                    "-p",
                    "dupin-web",
                    "--target",
                    "wasm32-unknown-unknown",
                ])
                .args(["--test", "wasm_smoke"])
                .env(
                    "CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER",
                    "wasm-bindgen-test-runner",
                ),
        )
    })?;
    step("wasm tests (Node)", &mut || web.test_node())?;
    step("wasm tests (headless Chromium)", &mut || web.test_chrome())?;
    step("web build", &mut || web.build())?;
    step("browser end-to-end", &mut || {
        let listener = serve::bind(0)?;
        let port = listener.local_addr().map_err(|e| e.to_string())?.port();
        let dir = root().join("web");
        std::thread::spawn(move || serve::serve_forever(listener, dir));
        util::run(
            Command::new("node")
                .args(["--test", "--test-concurrency=1", "tests/e2e/"])
                .current_dir(root())
                .env("DUPIN_URL", format!("http://127.0.0.1:{port}/")),
        )
    })?;
    step("static dist on a plain file server", &mut || {
        // `cargo xtask dist`'s folder, served by Python's http.server (no xtask, no CSP): the
        // page's smoke test must pass there too.
        let out = root().join("target/dist");
        crate::dist::copy(&root().join("web"), &out)?;
        let port = {
            let l = serve::bind(0)?;
            l.local_addr().map_err(|e| e.to_string())?.port()
        };
        let mut server = Command::new("python3")
            .args([
                "-m",
                "http.server",
                &port.to_string(),
                "--bind",
                "127.0.0.1",
            ])
            .arg("--directory")
            .arg(&out)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .map_err(|e| format!("python3 -m http.server (a plain static server): {e}"))?;
        // Wait until it listens (it starts in the background).
        for _ in 0..100 {
            if std::net::TcpStream::connect(("127.0.0.1", port)).is_ok() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(100));
        }
        let result = util::run(
            Command::new("node")
                .args(["--test", "--test-concurrency=1", "tests/e2e/smoke.test.mjs"])
                .current_dir(root())
                .env("DUPIN_URL", format!("http://127.0.0.1:{port}/")),
        );
        let _ = server.kill();
        result
    })?;
    println!("\nxtask test: all checks passed");
    for (name, secs) in &times {
        println!("  {secs:8.1} s  {name}");
    }
    Ok(())
}

/// Below this much free disk the wasm and web builds (about 1.5 GB) may not fit.
const SHORT_DISK_GB: f64 = 4.0;

/// Removes the native debug build (tests have run, docs are built) when the disk is short, so a
/// CI machine with a few GB free still fits the wasm builds; a roomy machine keeps it for reruns.
fn free_native_tests_if_short() -> Result<()> {
    let target = root().join("target");
    match util::free_disk_gb(&target) {
        Some(gb) if gb < SHORT_DISK_GB => {
            let debug = target.join("debug");
            println!("only {gb:.1} GB free: removing {}", debug.display());
            std::fs::remove_dir_all(&debug)
                .map_err(|e| format!("could not remove {}: {e}", debug.display()))
        }
        Some(gb) => {
            println!("{gb:.1} GB free: keeping the native build");
            Ok(())
        }
        None => Ok(()),
    }
}
