//! The mesh renderer: one lit triangle pipeline, one flat line pipeline, a depth buffer.

use crate::camera::OrbitCamera;
use dupin_core::TriangleBuffers;
use thiserror::Error;

/// Background colour of every view (linear RGB), also used by tests to count covered pixels.
pub const BACKGROUND: wgpu::Color = wgpu::Color {
    r: 0.030,
    g: 0.035,
    b: 0.045,
    a: 1.0,
};

const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
const DEFAULT_COLOR: [f32; 3] = [0.55, 0.70, 0.85];

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

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniforms {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    key_dir: [f32; 4],
    base_color: [f32; 4],
    flags: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    pos: [f32; 3],
    normal: [f32; 3],
    color: [f32; 3],
}

struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
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
    vertex_colors: bool,
    depth: Option<(wgpu::TextureView, u32, u32)>,
}

impl MeshRenderer {
    /// Creates the pipelines for colour targets of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("dupin shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shader.wgsl").into()),
        });
        let layout_bg = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("dupin uniforms"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("dupin layout"),
            bind_group_layouts: &[Some(&layout_bg)],
            immediate_size: 0,
        });
        let make_uniforms = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: std::mem::size_of::<Uniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let uniforms = make_uniforms("dupin uniforms");
        let line_uniforms = make_uniforms("dupin line uniforms");
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
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];
        let buffers = [Some(wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &attributes,
        })];
        let pipeline = |topology, fs: &str, depth_bias: i32| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(fs),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &shader,
                    entry_point: Some("vs_main"),
                    compilation_options: Default::default(),
                    buffers: &buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: wgpu::DepthBiasState {
                        constant: depth_bias,
                        slope_scale: 0.0,
                        clamp: 0.0,
                    },
                }),
                multisample: Default::default(),
                fragment: Some(wgpu::FragmentState {
                    module: &shader,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // Push triangles back a little so edges drawn on top of them win the depth test.
        let tri_pipeline = pipeline(wgpu::PrimitiveTopology::TriangleList, "fs_main", 2);
        let line_pipeline = pipeline(wgpu::PrimitiveTopology::LineList, "fs_line", 0);
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
            vertex_colors: false,
            depth: None,
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
        let n = mesh.vertex_count();
        if mesh.positions.len() != 3 * n || mesh.normals.len() != 3 * n {
            return Err(RenderError::InvalidBuffers(
                "positions and normals need 3 floats per vertex".into(),
            ));
        }
        if !mesh.indices.len().is_multiple_of(3) || mesh.indices.iter().any(|&i| i as usize >= n) {
            return Err(RenderError::InvalidBuffers(
                "indices must come in triples and name existing vertices".into(),
            ));
        }
        if let Some(c) = colors {
            if c.len() != 3 * n {
                return Err(RenderError::InvalidBuffers(
                    "colours need 3 floats per vertex".into(),
                ));
            }
        }
        let vertices: Vec<Vertex> = (0..n)
            .map(|i| Vertex {
                pos: [
                    mesh.positions[3 * i],
                    mesh.positions[3 * i + 1],
                    mesh.positions[3 * i + 2],
                ],
                normal: [
                    mesh.normals[3 * i],
                    mesh.normals[3 * i + 1],
                    mesh.normals[3 * i + 2],
                ],
                color: colors.map_or(DEFAULT_COLOR, |c| [c[3 * i], c[3 * i + 1], c[3 * i + 2]]),
            })
            .collect();
        self.vertex_colors = colors.is_some();
        self.mesh = Some(upload(device, queue, &vertices, &mesh.indices, "mesh"));
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
        let vertices: Vec<Vertex> = segments
            .chunks_exact(3)
            .map(|p| Vertex {
                pos: [p[0], p[1], p[2]],
                normal: [0.0, 0.0, 1.0],
                color,
            })
            .collect();
        let indices: Vec<u32> = (0..vertices.len() as u32 & !1).collect();
        self.lines =
            (!indices.is_empty()).then(|| upload(device, queue, &vertices, &indices, "lines"));
    }

    /// Removes the line segments.
    pub fn clear_lines(&mut self) {
        self.lines = None;
    }

    /// Renders the current view into an offscreen texture of this renderer's format and starts
    /// copying it back. The same pipelines draw it, so it is exactly what the canvas shows, at
    /// any resolution (a 2x screenshot, or a test's pixel check where the browser composites no
    /// WebGPU canvas into its own screenshots).
    pub fn begin_snapshot(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        width: u32,
        height: u32,
        camera: &OrbitCamera,
    ) -> PendingSnapshot {
        let (width, height) = (width.clamp(1, 8192), height.clamp(1, 8192));
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("dupin snapshot"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        self.render(device, queue, &view, width, height, camera);
        read_back(device, queue, &texture, width, height, self.format)
    }

    /// Draws the current mesh and lines seen by `camera` into `target` (of this renderer's
    /// format, `width` x `height` pixels), clearing it to [`BACKGROUND`] first.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target: &wgpu::TextureView,
        width: u32,
        height: u32,
        camera: &OrbitCamera,
    ) {
        let (width, height) = (width.max(1), height.max(1));
        if self
            .depth
            .as_ref()
            .is_none_or(|d| (d.1, d.2) != (width, height))
        {
            let tex = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("dupin depth"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: DEPTH_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            });
            self.depth = Some((tex.create_view(&Default::default()), width, height));
        }
        let view_proj = camera.view_proj(width as f32 / height as f32);
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
        u.flags[1] = 1.0;
        queue.write_buffer(&self.line_uniforms, 0, bytemuck::bytes_of(&u));

        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let depth_view = &self.depth.as_ref().expect("depth created above").0;
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("dupin pass"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(background_for(self.format)),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if let Some(m) = &self.mesh {
                pass.set_pipeline(&self.tri_pipeline);
                pass.set_bind_group(0, &self.bind_group, &[]);
                pass.set_vertex_buffer(0, m.vertices.slice(..));
                pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..m.count, 0, 0..1);
            }
            if let Some(l) = &self.lines {
                pass.set_pipeline(&self.line_pipeline);
                pass.set_bind_group(0, &self.line_bind_group, &[]);
                pass.set_vertex_buffer(0, l.vertices.slice(..));
                pass.set_index_buffer(l.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..l.count, 0, 0..1);
            }
        }
        queue.submit([encoder.finish()]);
    }
}

/// Copies `texture` (`width` x `height`, `format`) into readback buffers in bands of rows.
pub(crate) fn read_back(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    width: u32,
    height: u32,
    format: wgpu::TextureFormat,
) -> PendingSnapshot {
    // Rows of a texture-to-buffer copy are padded to 256 bytes.
    let padded_row = (width * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let rows_per_band = (READBACK_CHUNK / padded_row).max(1);
    let mut encoder = device.create_command_encoder(&Default::default());
    let mut bands = Vec::new();
    for first_row in (0..height).step_by(rows_per_band as usize) {
        let rows = rows_per_band.min(height - first_row);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dupin readback"),
            size: (padded_row * rows) as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture,
                mip_level: 0,
                origin: wgpu::Origin3d {
                    x: 0,
                    y: first_row,
                    z: 0,
                },
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_row),
                    rows_per_image: Some(rows),
                },
            },
            wgpu::Extent3d {
                width,
                height: rows,
                depth_or_array_layers: 1,
            },
        );
        bands.push((buffer, first_row));
    }
    queue.submit([encoder.finish()]);
    PendingSnapshot {
        bands,
        width,
        height,
        padded_row,
        rows_per_band,
        bgra: matches!(
            format,
            wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb
        ),
    }
}

/// Largest readback buffer: SwiftShader's WebGPU (headless Chromium) fails to map buffers of a
/// few hundred kilobytes, so a frame comes back in bands of rows.
const READBACK_CHUNK: u32 = 64 * 1024;

/// A rendered frame on its way back from the GPU (see [`MeshRenderer::begin_snapshot`]).
pub struct PendingSnapshot {
    /// Readback buffers with the first row each holds, top to bottom.
    bands: Vec<(wgpu::Buffer, u32)>,
    width: u32,
    height: u32,
    padded_row: u32,
    rows_per_band: u32,
    bgra: bool,
}

type Collected = std::sync::Arc<std::sync::Mutex<(Vec<u8>, usize, Option<RenderError>)>>;

impl PendingSnapshot {
    /// Width of the image in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height of the image in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Maps the pixels; `done` receives `width * height * 4` RGBA bytes, rows top to bottom,
    /// once the GPU is finished (natively: after `device.poll`; in a browser: on its own).
    pub fn read(
        self,
        done: impl FnOnce(Result<Vec<u8>, RenderError>) + wgpu::WasmNotSend + 'static,
    ) {
        let row = (self.width * 4) as usize;
        let total = self.bands.len();
        let state: Collected = std::sync::Arc::new(std::sync::Mutex::new((
            vec![0; row * self.height as usize],
            0,
            None,
        )));
        let done = std::sync::Arc::new(std::sync::Mutex::new(Some(done)));
        for (buffer, first_row) in self.bands {
            let rows = self.rows_per_band.min(self.height - first_row) as usize;
            let (state, done, mapped_buffer) = (state.clone(), done.clone(), buffer.clone());
            let (padded, bgra) = (self.padded_row as usize, self.bgra);
            buffer.map_async(wgpu::MapMode::Read, .., move |mapped| {
                let mut guard = state.lock().unwrap_or_else(|p| p.into_inner());
                let (pixels, finished, error) = &mut *guard;
                match mapped
                    .map_err(|e| RenderError::Readback(e.to_string()))
                    .and_then(|()| {
                        mapped_buffer
                            .get_mapped_range(..)
                            .map_err(|e| RenderError::Readback(e.to_string()))
                    }) {
                    Ok(data) => {
                        for y in 0..rows {
                            let dst = (first_row as usize + y) * row;
                            pixels[dst..dst + row]
                                .copy_from_slice(&data[y * padded..y * padded + row]);
                        }
                    }
                    Err(e) => *error = Some(e),
                }
                mapped_buffer.unmap();
                *finished += 1;
                if *finished == total {
                    let result = match error.take() {
                        Some(e) => Err(e),
                        None => {
                            let mut out = std::mem::take(pixels);
                            if bgra {
                                out.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
                            }
                            Ok(out)
                        }
                    };
                    drop(guard);
                    if let Some(done) = done.lock().unwrap_or_else(|p| p.into_inner()).take() {
                        done(result);
                    }
                }
            });
        }
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

fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    vertices: &[Vertex],
    indices: &[u32],
    label: &str,
) -> GpuMesh {
    // Plain buffers filled through the queue: some WebGPU implementations (SwiftShader) refuse
    // `mappedAtCreation` for buffers of a few hundred kilobytes.
    let make = |bytes: &[u8], usage: wgpu::BufferUsages| {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: (bytes.len() as u64)
                .max(4)
                .next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT),
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&buffer, 0, bytes);
        buffer
    };
    GpuMesh {
        vertices: make(bytemuck::cast_slice(vertices), wgpu::BufferUsages::VERTEX),
        indices: make(bytemuck::cast_slice(indices), wgpu::BufferUsages::INDEX),
        count: indices.len() as u32,
    }
}
