//! `wasm-pack.toml`: the web-build settings, turned into wasm-pack flags.

use crate::util::{Result, root, run};
use serde::Deserialize;
use std::process::Command;

#[derive(Deserialize)]
struct File {
    build: Build,
    test: Test,
}

#[derive(Deserialize)]
struct Build {
    #[serde(rename = "crate")]
    krate: String,
    target: String,
    #[serde(rename = "out-dir")]
    out_dir: String,
    profile: String,
    features: String,
}

#[derive(Deserialize)]
struct Test {
    node: Vec<String>,
    chrome: Vec<String>,
    chromedriver: String,
}

/// The parsed `wasm-pack.toml`.
pub struct WebBuild {
    file: File,
}

impl WebBuild {
    /// Reads `wasm-pack.toml` at the workspace root.
    pub fn load() -> Result<Self> {
        let path = root().join("wasm-pack.toml");
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let file: File = toml::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if !["release", "dev", "profiling"].contains(&file.build.profile.as_str()) {
            return Err(format!(
                "wasm-pack.toml: profile must be release, dev or profiling, not `{}`",
                file.build.profile
            ));
        }
        Ok(WebBuild { file })
    }

    /// Where the package lands, absolute.
    pub fn out_dir(&self) -> std::path::PathBuf {
        root().join(&self.file.build.out_dir)
    }

    /// `wasm-pack build` with the configured flags.
    pub fn build(&self) -> Result<()> {
        let b = &self.file.build;
        let mut cmd = Command::new("wasm-pack");
        cmd.current_dir(root())
            .args(["build", &b.krate, "--target", &b.target, "--out-dir"])
            .arg(self.out_dir())
            .arg(format!("--{}", b.profile))
            .arg("--no-pack");
        if !b.features.trim().is_empty() {
            cmd.args(["--features", b.features.trim()]);
        }
        run(&mut cmd)
    }

    /// `wasm-pack test --node` with the configured test selection.
    pub fn test_node(&self) -> Result<()> {
        let mut cmd = Command::new("wasm-pack");
        cmd.current_dir(root())
            .args(["test", "--node", &self.file.build.krate])
            .args(&self.file.test.node);
        run(&mut cmd)
    }

    /// `wasm-pack test --headless --chrome` (Chrome flags: the crate's webdriver.json).
    pub fn test_chrome(&self) -> Result<()> {
        let mut cmd = Command::new("wasm-pack");
        cmd.current_dir(root())
            .args(["test", "--headless", "--chrome", "--chromedriver"])
            .arg(&self.file.test.chromedriver)
            .arg(&self.file.build.krate)
            .args(&self.file.test.chrome);
        run(&mut cmd)
    }
}
