//! The renderer's one error type, shared by the GPU helpers, the read-back and the renderers.

use thiserror::Error;

/// Why rendering could not start or finish.
#[derive(Debug, Error)]
pub enum RenderError {
    /// No GPU adapter (hardware, software rasteriser, WebGPU or WebGL2) was found.
    #[error("no graphics adapter available: {0}")]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not create a graphics device: {0}")]
    Device(String),
    /// Mesh buffers are inconsistent (lengths not multiples of 3, indices out of range).
    #[error("invalid mesh buffers: {0}")]
    InvalidBuffers(String),
    /// Reading back the rendered image failed.
    #[error("could not read back the image: {0}")]
    Readback(String),
}
