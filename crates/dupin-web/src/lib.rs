//! # dupin-web
//!
//! The browser face of Dupin: the only crate with `#[wasm_bindgen]`. It exposes the core's
//! computations to JavaScript as typed arrays and plain objects, and a `Viewer` that draws
//! them with `dupin-render` into a canvas (WebGPU, or WebGL2 where WebGPU is missing).
//! Errors cross the boundary as JS `Error`s carrying the Rust message.
//!
//! Features: `configurator` (default) is the whole page: sessions, the lesson, the hexagonal
//! Delaunay lab and imports. Without it the module is the viewer only (`Viewer`, `Presenter`,
//! `designMesh`): what a shared presentation file and `<dupin-viewer>` need, with the solvers
//! left out by the linker because nothing exported reaches them.

// The viewer-only build leaves the configurator's helpers (argument checks, pick stars, layer
// buffers) unused on purpose.
#![cfg_attr(not(feature = "configurator"), allow(dead_code))]

#[cfg(feature = "configurator")]
mod hexd2d;
#[cfg(feature = "configurator")]
mod import;
mod js;
mod mesh_data;
mod pick;
mod present;
#[cfg(feature = "configurator")]
mod schema;
#[cfg(feature = "configurator")]
mod session;
#[cfg(feature = "configurator")]
mod shown_mesh;
#[cfg(feature = "configurator")]
mod teach;
// The canvas viewer needs wgpu's browser backends, which exist only on wasm32.
#[cfg(target_arch = "wasm32")]
mod viewer;

#[cfg(feature = "configurator")]
pub use hexd2d::HexDelaunayLab;
pub use mesh_data::{MeshData, design_mesh, torus_mesh};
#[cfg(target_arch = "wasm32")]
pub use present::Presenter;
pub use present::torus_panels_js;
#[cfg(feature = "configurator")]
pub use schema::page_schema;
#[cfg(feature = "configurator")]
pub use session::{
    Session, color_legend, free_defaults, scene_description, scene_names, surface_catalog_js,
};
#[cfg(feature = "configurator")]
pub use teach::DupinLesson;
#[cfg(target_arch = "wasm32")]
pub use viewer::Viewer;

use wasm_bindgen::prelude::*;

/// Installs a panic hook that forwards Rust panics to `console.error` (called once by the page).
#[wasm_bindgen(start)]
pub fn start() {
    std::panic::set_hook(Box::new(|info| {
        web_sys::console::error_1(&format!("dupin panicked: {info}").into());
    }));
}

/// Dupin's version (the workspace's), as a shared presentation's certificate states it.
#[wasm_bindgen(js_name = dupinVersion)]
pub fn dupin_version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// Fails the way a bug would, so that the page's recovery can be tested: `"trap"` panics (a
/// wasm `unreachable` trap with panic = abort) and `"oom"` asks for more memory than wasm32 can
/// address (an allocation failure, also a trap). The module instance is unusable afterwards,
/// as after a real fault; the page's worker is restarted. Anything else is a JS `Error`.
#[cfg(feature = "configurator")]
#[wasm_bindgen(js_name = debugFault)]
pub fn debug_fault(kind: &str) -> Result<(), JsError> {
    match kind {
        "trap" => panic!("debugFault(\"trap\"): a deliberate panic"),
        "oom" => {
            // Keeps taking 256 MB blocks (untouched, so the browser commits no pages) until
            // wasm32's 4 GB is gone and the allocator fails: a real out-of-memory trap.
            let mut blocks: Vec<Vec<u8>> = Vec::new();
            loop {
                blocks.push(Vec::with_capacity(256 << 20));
                std::hint::black_box(&blocks);
            }
        }
        _ => Err(js::err(format!(
            "debugFault takes \"trap\" or \"oom\", got {kind:?}"
        ))),
    }
}
