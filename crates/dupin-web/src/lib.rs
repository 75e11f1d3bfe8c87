//! # dupin-web
//!
//! The browser face of Dupin: the only crate with `#[wasm_bindgen]`. It exposes the core's
//! computations to JavaScript as typed arrays and plain objects, and a `Viewer` that draws
//! them with `dupin-render` into a canvas (WebGPU, or WebGL2 where WebGPU is missing).
//! Errors cross the boundary as JS `Error`s carrying the Rust message.

mod hexd2d;
mod js;
mod mesh_data;
mod pick;
mod present;
mod schema;
mod session;
mod teach;
// The canvas viewer needs wgpu's browser backends, which exist only on wasm32.
#[cfg(target_arch = "wasm32")]
mod viewer;

pub use hexd2d::HexDelaunayLab;
pub use mesh_data::{MeshData, torus_mesh};
#[cfg(target_arch = "wasm32")]
pub use present::Presenter;
pub use present::torus_panels_js;
pub use schema::page_schema;
pub use session::{Session, color_legend, free_defaults, scene_names, surface_catalog_js};
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
