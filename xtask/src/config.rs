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
    #[serde(rename = "wasm-opt", default)]
    wasm_opt: Vec<String>,
    #[serde(rename = "viewer-out-dir")]
    viewer_out_dir: String,
    #[serde(rename = "viewer-profile")]
    viewer_profile: String,
    #[serde(rename = "viewer-wasm-opt", default)]
    viewer_wasm_opt: Vec<String>,
    #[serde(rename = "gl-out-dir")]
    gl_out_dir: String,
    #[serde(rename = "viewer-gl-out-dir")]
    viewer_gl_out_dir: String,
    #[serde(rename = "gl-features")]
    gl_features: String,
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
        for p in [&file.build.profile, &file.build.viewer_profile] {
            if p.is_empty()
                || !p
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
            {
                return Err(format!(
                    "wasm-pack.toml: a profile must be release, dev, profiling or a Cargo profile name, not `{p}`"
                ));
            }
        }
        Ok(WebBuild { file })
    }

    /// `wasm-pack build` with the configured flags: the configurator's module, then the
    /// viewer-only one (the same crate without its default `configurator` feature, as a classic
    /// script a shared presentation file inlines), each as a WebGPU-only build and a WebGL2
    /// fallback build (`gl-features`), each through wasm-opt.
    pub fn build(&self) -> Result<()> {
        let b = &self.file.build;
        let with = |extra: &str| -> Vec<String> {
            let all: Vec<&str> = [b.features.trim(), extra]
                .into_iter()
                .flat_map(|f| f.split(','))
                .map(str::trim)
                .filter(|f| !f.is_empty())
                .collect();
            if all.is_empty() {
                Vec::new()
            } else {
                vec!["--features".into(), all.join(",")]
            }
        };
        // wasm-opt (single-threaded, 15-90 s a module) runs beside the next module's build,
        // whose LTO link is single-threaded too: on two cores the web build takes minutes less.
        std::thread::scope(|scope| {
            let mut optimising = Vec::new();
            for (dir, extra) in [(&b.out_dir, ""), (&b.gl_out_dir, b.gl_features.as_str())] {
                let out = root().join(dir);
                self.wasm_pack(&b.target, &b.profile, &out, "dupin_web", &with(extra))?;
                optimising.push(
                    scope.spawn(move || self.optimise(&out.join("dupin_web_bg.wasm"), &b.wasm_opt)),
                );
            }
            for (dir, extra) in [
                (&b.viewer_out_dir, ""),
                (&b.viewer_gl_out_dir, b.gl_features.as_str()),
            ] {
                let out = root().join(dir);
                let mut flags = vec!["--".to_string(), "--no-default-features".to_string()];
                if !extra.trim().is_empty() {
                    flags.extend(["--features".to_string(), extra.trim().to_string()]);
                }
                self.wasm_pack(
                    "no-modules",
                    &b.viewer_profile,
                    &out,
                    "dupin_viewer",
                    &flags,
                )?;
                optimising.push(scope.spawn(move || {
                    self.optimise(&out.join("dupin_viewer_bg.wasm"), &b.viewer_wasm_opt)
                }));
            }
            optimising.into_iter().try_for_each(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("wasm-opt thread panicked".into()))
            })
        })
    }

    /// One `wasm-pack build` of the crate for `target` with Cargo profile `profile`, written to
    /// `out_dir` as `out_name`, with `extra` flags last (after `--`: Cargo's).
    fn wasm_pack(
        &self,
        target: &str,
        profile: &str,
        out_dir: &std::path::Path,
        out_name: &str,
        extra: &[String],
    ) -> Result<()> {
        let b = &self.file.build;
        let mut cmd = Command::new("wasm-pack");
        cmd.current_dir(root())
            .args([
                "build",
                &b.krate,
                "--target",
                target,
                "--out-name",
                out_name,
            ])
            .arg("--out-dir")
            .arg(out_dir);
        if ["release", "dev", "profiling"].contains(&profile) {
            cmd.arg(format!("--{profile}"));
        } else {
            cmd.args(["--profile", profile]);
        }
        cmd.arg("--no-pack").args(extra);
        run(&mut cmd)
    }

    /// Runs wasm-opt with `flags` on `module`, in place; a note instead when wasm-opt is not
    /// installed (the module works, only larger).
    fn optimise(&self, module: &std::path::Path, flags: &[String]) -> Result<()> {
        if flags.is_empty() {
            return Ok(());
        }
        let wasm_opt = root().join("xtask/npm").join(crate::setup::WASM_OPT);
        if !wasm_opt.exists() {
            println!(
                "build-web: wasm-opt (npm binaryen in xtask/npm) is not installed; the module \
                 stays unoptimised (`cargo xtask setup`)"
            );
            return Ok(());
        }
        let input = std::fs::read(module).map_err(|e| format!("{}: {e}", module.display()))?;
        // wasm-opt takes over a minute: its output is kept per input and flags, so an
        // unchanged module is not optimised again.
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            (&input, flags).hash(&mut h);
            h.finish()
        };
        let cache = root().join("target/wasm-opt");
        let cached = cache.join(format!("{key:016x}.wasm"));
        if !cached.exists() {
            std::fs::create_dir_all(&cache).map_err(|e| format!("{}: {e}", cache.display()))?;
            let optimised = cache.join(format!("{key:016x}.part.wasm"));
            run(Command::new("node")
                .arg(&wasm_opt)
                .args(flags)
                .arg(module)
                .arg("-o")
                .arg(&optimised))?;
            std::fs::rename(&optimised, &cached)
                .map_err(|e| format!("{}: {e}", cached.display()))?;
        }
        std::fs::copy(&cached, module).map_err(|e| format!("{}: {e}", module.display()))?;
        let after = std::fs::metadata(module).map_err(|e| format!("{}: {e}", module.display()))?;
        println!(
            "build-web: wasm-opt {} {}: {:.2} MB -> {:.2} MB",
            flags.join(" "),
            module.display(),
            input.len() as f64 / 1e6,
            after.len() as f64 / 1e6
        );
        Ok(())
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
            .args(&self.file.test.chrome)
            // The browser tests draw with WebGL2 too.
            .args(["--features", &self.file.build.gl_features]);
        run(&mut cmd)
    }
}
