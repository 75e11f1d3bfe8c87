//! # dupin-render
//!
//! A small wgpu renderer for Dupin meshes. It takes plain buffers from `dupin-core`
//! ([`dupin_core::mesh::TriangleBuffers`], line segments) and draws them lit into any colour target:
//! a browser canvas (WebGPU, or WebGL2 as the fallback) or an offscreen texture read back to RGBA
//! for tests. The core never knows about this crate.

mod camera;
mod draw;
mod error;
mod gpu_mesh;
mod mesh_renderer;
#[cfg(not(target_arch = "wasm32"))]
mod offscreen;
mod presentation;
mod readback;

pub use camera::OrbitCamera;
pub use draw::{Draw, Frame};
pub use error::RenderError;
pub use mesh_renderer::{BACKGROUND, MeshRenderer};
#[cfg(not(target_arch = "wasm32"))]
pub use offscreen::{
    OffscreenImage, PresentationOffscreen, render_offscreen, render_presentation_offscreen,
};
pub use presentation::{
    FrameInstances, GLASS_TINT, METAL_COLOR, PresentationRenderer, frame_instances,
};
pub use readback::PendingSnapshot;
pub use wgpu;
