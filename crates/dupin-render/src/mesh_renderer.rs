//! The mesh renderer: one lit triangle pipeline, one flat line pipeline, a depth buffer.

use crate::camera::OrbitCamera;
use crate::draw::{Draw, Frame};
use crate::error::RenderError;
use crate::gpu_mesh::{self, DepthBuffer, GpuMesh, PipelineSpec};
use dupin_core::mesh::TriangleBuffers;

/// Background colour of every view (linear RGB), also used by tests to count covered pixels.
pub const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.030,
    g: 0.035,
    b: 0.045,
    a: 1.0,
};

const DEFAULT_COLOR: [f32; 3] = [0.55, 0.70, 0.85];

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniforms {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    key_dir: [f32; 4],
    base_color: [f32; 4],
    flags: [f32; 4],
}

/// Draws one triangle mesh (lit, two-sided) and optional line segments into a colour target.
pub struct MeshRenderer {
    format: wgpu::TextureFormat,
    tri_pipeline: wgpu::RenderPipeline,
    line_pipeline: wgpu::RenderPipeline,
    uniforms: wgpu::Buffer,
    line_uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    line_bind_group: wgpu::BindGroup,
    mesh: Option<GpuMesh>,
    lines: Option<GpuMesh>,
    /// Linear RGB of the lines (the line pipeline's `base_color`).
    line_color: [f32; 3],
    vertex_colors: bool,
    depth: DepthBuffer,
}

impl MeshRenderer {
    /// Creates the pipelines for colour targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let shader = gpu_mesh::shader(device, "dupin shader", include_str!("shader.wgsl"));
        let layout_bg = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dupin uniforms"),
            entries: &[gpu_mesh::UNIFORM_ENTRY],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dupin layout"),
            bind_group_layouts: &[Some(&layout_bg)],
            immediate_size: 0,
        });
        let size = std::mem::size_of::<Uniforms>();
        let uniforms = gpu_mesh::uniform_buffer(device, "dupin uniforms", size);
        let line_uniforms = gpu_mesh::uniform_buffer(device, "dupin line uniforms", size);
        let make_group = |buffer: &wgpu::Buffer| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("dupin bind group"),
                layout: &layout_bg,
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: buffer.as_entire_binding(),
                }],
            })
        };
        let bind_group = make_group(&uniforms);
        let line_bind_group = make_group(&line_uniforms);
        let pipeline = |topology, vertex_layout, vs, fs, slope_scale| {
            let bias = wgpu::DepthBiasState {
                constant: 0,
                slope_scale,
                clamp: 0.0,
            };
            let spec = PipelineSpec {
                vertex: vs,
                fragment: Some((fs, format, None)),
                topology,
                layout: vertex_layout,
                depth_write: true,
                bias,
                cull: None,
            };
            gpu_mesh::pipeline(device, &layout, &shader, spec)
        };
        // Faces also step back by their own depth slope (a pixel's worth), which keeps the
        // far, nearly edge-on outlines whole where `vs_line`'s pull alone is too small.
        let tri_pipeline = pipeline(
            wgpu::PrimitiveTopology::TriangleList,
            gpu_mesh::VERTEX_LAYOUT,
            "vs_main",
            "fs_main",
            1.0,
        );
        let line_pipeline = pipeline(
            wgpu::PrimitiveTopology::LineList,
            gpu_mesh::POSITION_LAYOUT,
            "vs_line",
            "fs_line",
            0.0,
        );
        MeshRenderer {
            format,
            tri_pipeline,
            line_pipeline,
            uniforms,
            line_uniforms,
            bind_group,
            line_bind_group,
            mesh: None,
            lines: None,
            line_color: [0.0; 3],
            vertex_colors: false,
            depth: DepthBuffer::default(),
        }
    }

    /// Uploads the triangle mesh to draw, with optional per-vertex linear RGB colours.
    pub fn set_mesh(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &TriangleBuffers,
        colors: Option<&[f32]>,
    ) -> Result<(), RenderError> {
        let vertices = gpu_mesh::vertices(mesh, colors, DEFAULT_COLOR)?;
        self.vertex_colors = colors.is_some();
        self.mesh = GpuMesh::upload(device, queue, &vertices, &mesh.indices, "mesh");
        Ok(())
    }

    /// Uploads line segments (pairs of `[x, y, z]` endpoints, 6 floats a segment), drawn in `color`.
    pub fn set_lines(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        segments: &[f32],
        color: [f32; 3],
    ) {
        let ends = (segments.len() / 3) & !1;
        let indices: Vec<u32> = (0..ends as u32).collect();
        self.lines = GpuMesh::upload(device, queue, &segments[..3 * ends], &indices, "lines");
        self.line_color = color;
    }

    /// Removes the line segments.
    pub fn clear_lines(&mut self) {
        self.lines = None;
    }
}

/// The clear colour in the target's encoding, so the background looks the same on sRGB and
/// linear targets.
pub(crate) fn background_for(format: wgpu::TextureFormat) -> wgpu::Color {
    if format.is_srgb() {
        BACKGROUND
    } else {
        let g = |c: f64| c.powf(1.0 / 2.2);
        wgpu::Color {
            r: g(BACKGROUND.r),
            g: g(BACKGROUND.g),
            b: g(BACKGROUND.b),
            a: 1.0,
        }
    }
}

impl Draw for MeshRenderer {
    fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Draws the current mesh and lines seen by `camera`, clearing the target to
    /// [`BACKGROUND`] first.
    fn draw(&mut self, frame: &Frame<'_>, camera: &OrbitCamera) {
        let (device, queue, target) = (frame.device, frame.queue, frame.target);
        let (width, height) = frame.size();
        let view_proj = camera.view_proj(frame.aspect());
        let eye = camera.eye();
        // Key light from above-right of the viewer, in world space.
        let fwd = (camera.target - eye).normalize_or_zero();
        let right = fwd.cross(glam::Vec3::Z).normalize_or_zero();
        let key = (-fwd + 0.6 * right + 0.8 * glam::Vec3::Z).normalize_or_zero();
        let gamma = if self.format.is_srgb() { 0.0 } else { 1.0 };
        let mut u = Uniforms {
            view_proj: view_proj.to_cols_array_2d(),
            eye: eye.extend(1.0).to_array(),
            key_dir: key.extend(0.0).to_array(),
            base_color: [DEFAULT_COLOR[0], DEFAULT_COLOR[1], DEFAULT_COLOR[2], 1.0],
            flags: [gamma, if self.vertex_colors { 1.0 } else { 0.0 }, 0.0, 0.0],
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let [r, g, b] = self.line_color;
        u.base_color = [r, g, b, 1.0];
        queue.write_buffer(&self.line_uniforms, 0, bytemuck::bytes_of(&u));

        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let depth = self.depth.view(device, width, height);
            let clear = background_for(self.format);
            let mut pass =
                gpu_mesh::begin_main_pass(&mut encoder, "dupin pass", target, clear, depth);
            if let Some(m) = &self.mesh {
                pass.set_pipeline(&self.tri_pipeline);
                pass.set_bind_group(0, &self.bind_group, &[]);
                m.draw(&mut pass);
            }
            if let Some(l) = &self.lines {
                pass.set_pipeline(&self.line_pipeline);
                pass.set_bind_group(0, &self.line_bind_group, &[]);
                l.draw(&mut pass);
            }
        }
        queue.submit([encoder.finish()]);
    }
}
