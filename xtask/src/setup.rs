//! Installs what the project needs when it is missing, and says what it installed.

use crate::util::{Result, cargo, is_root, output, root, run};
use std::path::Path;
use std::process::Command;

/// wasm-pack release the project is tested with.
const WASM_PACK_VERSION: &str = "0.15.1";
/// The Vulkan driver file of lavapipe (Mesa's software rasteriser) for native render tests.
const LAVAPIPE_ICD: &str = "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json";
/// binaryen's wasm-opt script under `xtask/npm` (run with Node).
pub const WASM_OPT: &str = "node_modules/binaryen/bin/wasm-opt";
const APT_PACKAGES: [&str; 3] = ["chromium", "chromium-driver", "mesa-vulkan-drivers"];

/// Installs the wasm toolchain (and with `browser`, the browser-test tools); returns what it
/// installed.
pub fn ensure(browser: bool) -> Result<Vec<String>> {
    let mut installed = Vec::new();
    let targets =
        output(Command::new("rustup").args(["target", "list", "--installed"])).unwrap_or_default();
    if !targets
        .lines()
        .any(|t| t.trim() == "wasm32-unknown-unknown")
    {
        run(Command::new("rustup").args(["target", "add", "wasm32-unknown-unknown"]))?;
        installed.push("rust target wasm32-unknown-unknown".into());
    }

    let want = wasm_bindgen_version()?;
    let have = output(Command::new("wasm-bindgen").arg("--version")).unwrap_or_default();
    if have.split_whitespace().nth(1) != Some(want.as_str()) {
        // Pinned exactly: the CLI must match the wasm-bindgen crate in Cargo.lock.
        run(cargo().args([
            "install",
            "wasm-bindgen-cli",
            "--version",
            &format!("={want}"),
        ]))?;
        installed.push(format!("wasm-bindgen-cli {want}"));
    }
    if output(Command::new("wasm-pack").arg("--version")).is_none() {
        run(cargo().args([
            "install",
            "wasm-pack",
            "--version",
            &format!("={WASM_PACK_VERSION}"),
        ]))?;
        installed.push(format!("wasm-pack {WASM_PACK_VERSION}"));
    }

    // binaryen's wasm-opt (npm, compiled to wasm), which the web build runs on the module.
    let tools = root().join("xtask/npm");
    if !tools.join(WASM_OPT).exists() {
        run(Command::new("npm")
            .args(["ci", "--no-audit", "--no-fund"])
            .current_dir(&tools))?;
        installed.push("npm: binaryen (xtask/npm)".into());
    }

    // rhino3dm, which the page loads from web/vendor when a .3dm is opened or written.
    let vendor = root().join("web/vendor");
    if !vendor.join("node_modules/rhino3dm/rhino3dm.wasm").exists() {
        run(Command::new("npm")
            .args(["ci", "--no-audit", "--no-fund"])
            .current_dir(&vendor))?;
        installed.push("npm: rhino3dm (web/vendor)".into());
    }

    if browser {
        let missing = !Path::new("/usr/bin/chromium").exists()
            || !Path::new("/usr/bin/chromedriver").exists()
            || !Path::new(LAVAPIPE_ICD).exists();
        if missing {
            if !is_root() {
                return Err(format!(
                    "Chromium, chromedriver or lavapipe is missing and we are not root; run \
                     `sudo apt-get install -y {}` and try again",
                    APT_PACKAGES.join(" ")
                ));
            }
            run(Command::new("apt-get")
                .arg("update")
                .env("DEBIAN_FRONTEND", "noninteractive"))?;
            run(Command::new("apt-get")
                .args(["install", "-y", "--no-install-recommends"])
                .args(APT_PACKAGES)
                .env("DEBIAN_FRONTEND", "noninteractive"))?;
            installed.push(format!("apt: {}", APT_PACKAGES.join(", ")));
        }
        let e2e = root().join("tests/e2e");
        let packages = [
            "playwright-core",
            "dxf-parser",
            "gltf-validator",
            "@axe-core/playwright",
        ];
        if packages
            .iter()
            .any(|p| !e2e.join("node_modules").join(p).exists())
        {
            run(Command::new("npm")
                .args(["ci", "--no-audit", "--no-fund"])
                .current_dir(&e2e))?;
            installed.push(format!("npm: {} (tests/e2e)", packages.join(", ")));
        }
    }
    Ok(installed)
}

/// Prints what [`ensure`] installed.
pub fn print_installed(installed: &[String]) {
    if installed.is_empty() {
        println!("setup: everything needed was already installed");
    } else {
        println!("setup: installed {}", installed.join("; "));
    }
}

/// The exact wasm-bindgen version in Cargo.lock.
fn wasm_bindgen_version() -> Result<String> {
    let lock = root().join("Cargo.lock");
    let text = std::fs::read_to_string(&lock).map_err(|e| format!("{}: {e}", lock.display()))?;
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim() == "name = \"wasm-bindgen\""
            && let Some(v) = lines
                .next()
                .and_then(|l| l.trim().strip_prefix("version = "))
        {
            return Ok(v.trim_matches('"').to_string());
        }
    }
    Err("Cargo.lock has no wasm-bindgen entry".into())
}
