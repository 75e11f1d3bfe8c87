//! Native offscreen rendering to RGBA pixels (lavapipe/llvmpipe in CI, any GPU elsewhere).

use crate::camera::OrbitCamera;
use crate::draw::{Draw, Frame};
use crate::error::RenderError;
use crate::mesh_renderer::MeshRenderer;
use crate::presentation::{FrameInstances, PresentationRenderer};
use crate::readback::PendingSnapshot;
use dupin_core::mesh::TriangleBuffers;

/// An 8-bit sRGB RGBA image, rows top to bottom.
#[derive(Debug, Clone, PartialEq)]
pub struct OffscreenImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba: Vec<u8>,
    /// Name of the adapter that drew it (e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub adapter: String,
}

/// Renders `mesh` (and optional line segments) seen by `camera` into a `width` x `height` image.
///
/// Blocks until the GPU is done. Fails with [`RenderError::NoAdapter`] when no Vulkan or GL
/// adapter exists (install `mesa-vulkan-drivers` for the software rasteriser).
pub fn render_offscreen(
    mesh: &TriangleBuffers,
    lines: Option<&[f32]>,
    camera: &OrbitCamera,
    width: u32,
    height: u32,
) -> Result<OffscreenImage, RenderError> {
    let (width, height) = (width.max(1), height.max(1));
    pollster::block_on(async {
        let (adapter, device, queue) = gpu().await?;
        let mut renderer = MeshRenderer::new(&device, wgpu::TextureFormat::Rgba8UnormSrgb);
        renderer.set_mesh(&device, &queue, mesh, None)?;
        if let Some(l) = lines {
            renderer.set_lines(&device, &queue, l, [0.05, 0.05, 0.06]);
        }
        let pending = renderer.begin_snapshot(&device, &queue, (width, height), camera);
        finish(&adapter, &device, pending)
    })
}

/// Waits for `pending` to come back from the GPU.
fn finish(
    adapter: &wgpu::Adapter,
    device: &wgpu::Device,
    pending: PendingSnapshot,
) -> Result<OffscreenImage, RenderError> {
    let (width, height) = (pending.width(), pending.height());
    let (tx, rx) = std::sync::mpsc::channel();
    pending.read(move |r| {
        let _ = tx.send(r);
    });
    device
        .poll(wgpu::PollType::Wait {
            submission_index: None,
            timeout: None,
        })
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    let rgba = rx
        .recv()
        .map_err(|e| RenderError::Readback(e.to_string()))??;
    Ok(OffscreenImage {
        width,
        height,
        rgba,
        adapter: adapter.get_info().name,
    })
}

/// The first Vulkan/Metal/DX12 adapter, else GL, with a device of WebGL2-level limits.
async fn gpu() -> Result<(wgpu::Adapter, wgpu::Device, wgpu::Queue), RenderError> {
    // Vulkan (lavapipe on CI) or Metal first; GL only when neither exists, since EGL probing is
    // noisy on headless machines.
    let mut last_error = String::new();
    let mut found = None;
    for backends in [
        wgpu::Backends::VULKAN | wgpu::Backends::METAL | wgpu::Backends::DX12,
        wgpu::Backends::GL,
    ] {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        match instance
            .request_adapter(&wgpu::RequestAdapterOptions::default())
            .await
        {
            Ok(a) => {
                found = Some(a);
                break;
            }
            Err(e) => last_error = e.to_string(),
        }
    }
    let adapter = found.ok_or(RenderError::NoAdapter(last_error))?;
    let (device, queue) = adapter
        .request_device(&wgpu::DeviceDescriptor {
            label: Some("dupin offscreen"),
            required_limits: wgpu::Limits::downlevel_webgl2_defaults()
                .using_resolution(adapter.limits()),
            ..Default::default()
        })
        .await
        .map_err(|e| RenderError::Device(e.to_string()))?;
    Ok((adapter, device, queue))
}

/// Renders a presentation scene (glass `panels`, metal `frames`, ground and sun shadows; see
/// [`PresentationRenderer`]) seen by `camera` into a `width` x `height` image, with or without
/// the sun's `shadows`. Blocks.
pub fn render_presentation_offscreen(
    panels: &TriangleBuffers,
    frames: &FrameInstances,
    camera: &OrbitCamera,
    size: (u32, u32),
    shadows: bool,
) -> Result<OffscreenImage, RenderError> {
    let mut p = PresentationOffscreen::new(panels, frames)?;
    p.renderer().set_shadows(shadows);
    p.snapshot(camera, size)
}

/// A presentation view kept alive offscreen, frame after frame, as the page's canvas is: for
/// tests of what carries over between frames (the cached shadow map) and for frame benchmarks.
pub struct PresentationOffscreen {
    adapter: wgpu::Adapter,
    device: wgpu::Device,
    queue: wgpu::Queue,
    renderer: PresentationRenderer,
    /// The colour target of [`Self::frame`], re-created only when the size changes.
    target: Option<(wgpu::TextureView, u32, u32)>,
}

impl PresentationOffscreen {
    /// Opens a device (as [`render_offscreen`]) and uploads the scene: glass `panels` and metal
    /// `frames`.
    pub fn new(panels: &TriangleBuffers, frames: &FrameInstances) -> Result<Self, RenderError> {
        let (adapter, device, queue) = pollster::block_on(gpu())?;
        let mut renderer = PresentationRenderer::new(&device, wgpu::TextureFormat::Rgba8UnormSrgb);
        renderer.set_scene(&device, &queue, panels, None, frames)?;
        Ok(PresentationOffscreen {
            adapter,
            device,
            queue,
            renderer,
            target: None,
        })
    }

    /// The renderer, for settings ([`PresentationRenderer::set_shadows`]) and counters.
    pub fn renderer(&mut self) -> &mut PresentationRenderer {
        &mut self.renderer
    }

    /// Replaces the scene, as [`PresentationRenderer::set_scene`].
    pub fn set_scene(
        &mut self,
        panels: &TriangleBuffers,
        frames: &FrameInstances,
    ) -> Result<(), RenderError> {
        self.renderer
            .set_scene(&self.device, &self.queue, panels, None, frames)
    }

    /// Draws one frame seen by `camera` into a `width` x `height` target and waits until the
    /// GPU has finished it (no read-back): what one orbit frame of the page costs.
    pub fn frame(&mut self, camera: &OrbitCamera, size: (u32, u32)) -> Result<(), RenderError> {
        self.submit_frame(camera, size);
        self.wait()
    }

    /// Encodes and submits one frame as [`Self::frame`] does, without waiting for the GPU: the
    /// CPU cost of the page's `render()` call.
    pub fn submit_frame(&mut self, camera: &OrbitCamera, (width, height): (u32, u32)) {
        let (width, height) = (width.clamp(1, 8192), height.clamp(1, 8192));
        if self
            .target
            .as_ref()
            .is_none_or(|t| (t.1, t.2) != (width, height))
        {
            let tex = crate::gpu_mesh::texture(
                &self.device,
                "dupin offscreen frame",
                (width, height),
                wgpu::TextureFormat::Rgba8UnormSrgb,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            );
            self.target = Some((tex.create_view(&Default::default()), width, height));
        }
        let view = &self.target.as_ref().expect("created above").0;
        let frame = Frame {
            device: &self.device,
            queue: &self.queue,
            target: view,
            width,
            height,
        };
        self.renderer.draw(&frame, camera);
    }

    /// Blocks until the GPU has finished everything submitted.
    pub fn wait(&self) -> Result<(), RenderError> {
        self.device
            .poll(wgpu::PollType::Wait {
                submission_index: None,
                timeout: None,
            })
            .map(|_| ())
            .map_err(|e| RenderError::Readback(e.to_string()))
    }

    /// Renders the view seen by `camera` at `width` x `height` and reads it back. Blocks.
    pub fn snapshot(
        &mut self,
        camera: &OrbitCamera,
        (width, height): (u32, u32),
    ) -> Result<OffscreenImage, RenderError> {
        let pending = self.renderer.begin_snapshot(
            &self.device,
            &self.queue,
            (width.max(1), height.max(1)),
            camera,
        );
        finish(&self.adapter, &self.device, pending)
    }
}
