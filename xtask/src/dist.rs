//! `cargo xtask dist --out DIR`: the configurator as static files that any static file server
//! hosts: the page, its scripts and styles, the wasm package and the rhino3dm module the page
//! loads for .3dm files. Nothing here needs a server of ours: without xtask's
//! Content-Security-Policy headers the page runs the same (the policy is a defence, not a
//! dependency).

use crate::config::WebBuild;
use crate::setup;
use crate::util::{Result, root};
use std::path::{Path, PathBuf};

/// What the page loads, relative to `web/`: everything the browser fetches, nothing else (no
/// TypeScript declarations, no npm metadata).
const FILES: &[&str] = &[
    "pkg/dupin_web.js",
    "pkg/dupin_web_bg.wasm",
    // The WebGL2 build, loaded where the browser has no WebGPU adapter.
    "pkg-gl/dupin_web.js",
    "pkg-gl/dupin_web_bg.wasm",
    // Fetched by the page when it writes a shared presentation file (both builds go in it), and
    // by `<dupin-viewer>`.
    "pkg-viewer/dupin_viewer.js",
    "pkg-viewer/dupin_viewer_bg.wasm",
    "pkg-viewer-gl/dupin_viewer.js",
    "pkg-viewer-gl/dupin_viewer_bg.wasm",
    "vendor/node_modules/rhino3dm/rhino3dm.module.js",
    "vendor/node_modules/rhino3dm/rhino3dm.wasm",
    // The design `viewer-example.html` embeds with `<dupin-viewer>`.
    "examples/conical-station.json",
];

/// Sets up, builds the page and copies it to `out`; returns the files written.
pub fn run(out: &Path) -> Result<Vec<PathBuf>> {
    let installed = setup::ensure(false)?;
    setup::print_installed(&installed);
    WebBuild::load()?.build()?;
    copy(&root().join("web"), out)
}

/// Copies the page's files from `web` to `out` (the top-level HTML, JS and CSS, and [`FILES`]).
pub fn copy(web: &Path, out: &Path) -> Result<Vec<PathBuf>> {
    let top = std::fs::read_dir(web).map_err(|e| format!("{}: {e}", web.display()))?;
    let mut files: Vec<PathBuf> = top
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.is_file()
                && matches!(
                    p.extension().and_then(|e| e.to_str()),
                    Some("html" | "js" | "css")
                )
        })
        .filter_map(|p| p.strip_prefix(web).ok().map(Path::to_path_buf))
        .collect();
    files.extend(FILES.iter().map(PathBuf::from));
    files.sort();
    for f in &files {
        let (from, to) = (web.join(f), out.join(f));
        if let Some(dir) = to.parent() {
            std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        std::fs::copy(&from, &to).map_err(|e| {
            format!(
                "{}: {e} (run `cargo xtask build-web` first?)",
                from.display()
            )
        })?;
    }
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_the_page_and_what_it_loads_only() {
        let tmp = std::env::temp_dir().join(format!("dupin-dist-test-{}", std::process::id()));
        let web = tmp.join("web");
        for f in [
            "index.html",
            "main.js",
            "style.css",
            "notes.md",
            "pkg/dupin_web.js",
            "pkg/dupin_web_bg.wasm",
            "pkg/dupin_web.d.ts",
            "pkg-gl/dupin_web.js",
            "pkg-gl/dupin_web_bg.wasm",
            "pkg-viewer/dupin_viewer.js",
            "pkg-viewer/dupin_viewer_bg.wasm",
            "pkg-viewer-gl/dupin_viewer.js",
            "pkg-viewer-gl/dupin_viewer_bg.wasm",
            "vendor/package.json",
            "vendor/node_modules/rhino3dm/rhino3dm.module.js",
            "vendor/node_modules/rhino3dm/rhino3dm.wasm",
            "vendor/node_modules/rhino3dm/rhino3dm.d.ts",
            "examples/conical-station.json",
            "examples/scratch.json",
        ] {
            let p = web.join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, f).unwrap();
        }
        let out = tmp.join("dist");
        let files = copy(&web, &out).unwrap();
        assert_eq!(files.len(), 14, "{files:?}");
        for f in &files {
            assert_eq!(
                std::fs::read_to_string(out.join(f)).unwrap(),
                f.to_str().unwrap()
            );
        }
        for absent in [
            "notes.md",
            "pkg/dupin_web.d.ts",
            "vendor/package.json",
            "examples/scratch.json",
        ] {
            assert!(!out.join(absent).exists(), "{absent}");
        }
        std::fs::remove_dir_all(web.join("pkg")).unwrap();
        assert!(
            copy(&web, &tmp.join("dist2"))
                .unwrap_err()
                .contains("build-web")
        );
        std::fs::remove_dir_all(&tmp).unwrap();
    }
}
