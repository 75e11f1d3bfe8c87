//! What every renderer of this crate offers a caller: draw into a colour target, and the
//! offscreen snapshot (the page's 2x PNG and the native tests) built on it.

use crate::camera::OrbitCamera;
use crate::gpu_mesh;
use crate::readback::PendingSnapshot;

/// A renderer that draws what it holds, seen by a camera, into a colour target of its format
/// ([`crate::MeshRenderer`], [`crate::PresentationRenderer`]).
pub trait Draw {
    /// The colour format of the targets it draws into.
    fn format(&self) -> wgpu::TextureFormat;

    /// Draws into `target` (`width` x `height` pixels of [`Draw::format`]).
    fn draw(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target: &wgpu::TextureView,
        width: u32,
        height: u32,
        camera: &OrbitCamera,
    );

    /// Renders the current view into an offscreen texture of this renderer's format and starts
    /// copying it back. The same pipelines draw it, so it is exactly what the canvas shows, at
    /// any resolution (a 2x screenshot, or a test's pixel check where the browser composites no
    /// WebGPU canvas into its own screenshots).
    fn begin_snapshot(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        camera: &OrbitCamera,
    ) -> PendingSnapshot {
        let format = self.format();
        gpu_mesh::snapshot(device, queue, format, (width, height), |view, w, h| {
            self.draw(device, queue, view, w, h, camera)
        })
    }
}
