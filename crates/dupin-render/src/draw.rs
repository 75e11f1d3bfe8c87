//! What every renderer of this crate offers a caller: draw into a colour target, and the
//! offscreen snapshot (the page's 2x PNG and the native tests) built on it.

use crate::camera::OrbitCamera;
use crate::gpu_mesh;
use crate::readback::PendingSnapshot;

/// Where a frame is drawn: the GPU, the colour target and its size in pixels.
#[derive(Clone, Copy)]
pub struct Frame<'a> {
    /// The device the renderer was created on.
    pub device: &'a wgpu::Device,
    /// Its queue.
    pub queue: &'a wgpu::Queue,
    /// The colour target, of the renderer's [`Draw::format`].
    pub target: &'a wgpu::TextureView,
    /// Target width in pixels (0 counts as 1).
    pub width: u32,
    /// Target height in pixels (0 counts as 1).
    pub height: u32,
}

impl Frame<'_> {
    /// Width and height, at least 1 pixel each.
    pub fn size(&self) -> (u32, u32) {
        (self.width.max(1), self.height.max(1))
    }

    /// Width over height.
    pub fn aspect(&self) -> f32 {
        let (w, h) = self.size();
        w as f32 / h as f32
    }
}

/// A renderer that draws what it holds, seen by a camera, into a colour target of its format
/// ([`crate::MeshRenderer`], [`crate::PresentationRenderer`]).
pub trait Draw {
    /// The colour format of the targets it draws into.
    fn format(&self) -> wgpu::TextureFormat;

    /// Draws into `frame`'s target what `camera` sees, clearing it first.
    fn draw(&mut self, frame: &Frame<'_>, camera: &OrbitCamera);

    /// Renders the current view into an offscreen texture of this renderer's format and starts
    /// copying it back. The same pipelines draw it, so it is exactly what the canvas shows, at
    /// any resolution (a 2x screenshot, or a test's pixel check where the browser composites no
    /// WebGPU canvas into its own screenshots).
    fn begin_snapshot(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        camera: &OrbitCamera,
    ) -> PendingSnapshot {
        let format = self.format();
        gpu_mesh::snapshot(
            device,
            queue,
            format,
            (width, height),
            |target, width, height| {
                let frame = Frame {
                    device,
                    queue,
                    target,
                    width,
                    height,
                };
                self.draw(&frame, camera)
            },
        )
    }
}
