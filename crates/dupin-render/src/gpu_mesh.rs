//! What both renderers share: the vertex format, validated uploads of plain buffers, the cached
//! depth buffer, the offscreen target of a snapshot, pipeline and pass boilerplate.

use crate::error::RenderError;
use crate::readback::{PendingSnapshot, read_back};
use dupin_core::mesh::TriangleBuffers;

pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// One vertex of every pipeline (`VsIn` in `vertex_io.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct Vertex {
    pub pos: [f32; 3],
    pub normal: [f32; 3],
    pub color: [f32; 3],
}

const ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3];

/// The vertex buffer layout of [`Vertex`].
pub(crate) const VERTEX_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: std::mem::size_of::<Vertex>() as u64,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &ATTRIBUTES,
};

const POSITION: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![0 => Float32x3];

/// Line vertices: a position only (`vs_line` in `shader.wgsl` colours them from its uniforms).
/// A full [`Vertex`] per line end made the panel outlines 78% of a large mesh's upload (250k
/// segments at 166k triangles: 18 MB of 23), and the upload was the page's longest main-thread
/// task.
pub(crate) const POSITION_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: 12,
    step_mode: wgpu::VertexStepMode::Vertex,
    attributes: &POSITION,
};

/// An indexed triangle or line list on the GPU.
pub(crate) struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    count: u32,
}

impl GpuMesh {
    /// Uploads `vertices` and `indices`; None when there is nothing to draw.
    pub fn upload<V: bytemuck::Pod>(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        vertices: &[V],
        indices: &[u32],
        label: &str,
    ) -> Option<GpuMesh> {
        if indices.is_empty() {
            return None;
        }
        let make = |bytes: &[u8], usage| buffer(device, queue, bytes, usage, label);
        Some(GpuMesh {
            vertices: make(bytemuck::cast_slice(vertices), wgpu::BufferUsages::VERTEX),
            indices: make(bytemuck::cast_slice(indices), wgpu::BufferUsages::INDEX),
            count: indices.len() as u32,
        })
    }

    /// Draws all of it with the pass's current pipeline and bind groups.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.count, 0, 0..1);
    }
}

/// A buffer of `bytes` for `usage`, filled through the queue: some WebGPU implementations
/// (SwiftShader) refuse `mappedAtCreation` for buffers of a few hundred kilobytes.
pub(crate) fn buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
    label: &str,
) -> wgpu::Buffer {
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
}

/// The vertices of `mesh`, coloured by `colors` (3 linear floats a vertex) or `default`, after
/// checking the buffers are consistent.
pub(crate) fn vertices(
    mesh: &TriangleBuffers,
    colors: Option<&[f32]>,
    default: [f32; 3],
) -> Result<Vec<Vertex>, RenderError> {
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
    if colors.is_some_and(|c| c.len() != 3 * n) {
        return Err(RenderError::InvalidBuffers(
            "colours need 3 floats per vertex".into(),
        ));
    }
    let v3 = |a: &[f32], i: usize| [a[3 * i], a[3 * i + 1], a[3 * i + 2]];
    Ok((0..n)
        .map(|i| Vertex {
            pos: v3(&mesh.positions, i),
            normal: v3(&mesh.normals, i),
            color: colors.map_or(default, |c| v3(c, i)),
        })
        .collect())
}

/// A depth buffer re-created only when the target size changes.
#[derive(Default)]
pub(crate) struct DepthBuffer(Option<(wgpu::TextureView, u32, u32)>);

impl DepthBuffer {
    /// The depth view for a `width` x `height` target.
    pub fn view(&mut self, device: &wgpu::Device, width: u32, height: u32) -> &wgpu::TextureView {
        if self
            .0
            .as_ref()
            .is_none_or(|d| (d.1, d.2) != (width, height))
        {
            let tex = texture(
                device,
                "dupin depth",
                (width, height),
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            );
            self.0 = Some((tex.create_view(&Default::default()), width, height));
        }
        &self.0.as_ref().expect("created above").0
    }
}

/// A 2D texture with one mip level and one sample.
pub(crate) fn texture(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// Renders one frame offscreen with `draw` (given the target view and its size, clamped to
/// 8192) into a texture of `format`, and starts copying it back: the body of both renderers'
/// `begin_snapshot`.
pub(crate) fn snapshot(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    format: wgpu::TextureFormat,
    (width, height): (u32, u32),
    draw: impl FnOnce(&wgpu::TextureView, u32, u32),
) -> PendingSnapshot {
    let (width, height) = (width.clamp(1, 8192), height.clamp(1, 8192));
    let tex = texture(
        device,
        "dupin snapshot",
        (width, height),
        format,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    draw(&tex.create_view(&Default::default()), width, height);
    read_back(device, queue, &tex, width, height, format)
}

/// A depth attachment cleared to the far plane.
pub(crate) fn cleared_depth(
    view: &wgpu::TextureView,
) -> wgpu::RenderPassDepthStencilAttachment<'_> {
    wgpu::RenderPassDepthStencilAttachment {
        view,
        depth_ops: Some(wgpu::Operations {
            load: wgpu::LoadOp::Clear(1.0),
            store: wgpu::StoreOp::Store,
        }),
        stencil_ops: None,
    }
}

/// A pass drawing into `target` cleared to `clear`, with `depth` cleared to the far plane.
pub(crate) fn begin_main_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    label: &str,
    target: &wgpu::TextureView,
    clear: wgpu::Color,
    depth: &wgpu::TextureView,
) -> wgpu::RenderPass<'e> {
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some(label),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: target,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(clear),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(cleared_depth(depth)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// How one pipeline differs from the others: entry points, topology, depth and colour output.
pub(crate) struct PipelineSpec<'a> {
    pub vertex: &'a str,
    /// Fragment entry point with its colour target format and blending; None for depth only.
    pub fragment: Option<(&'a str, wgpu::TextureFormat, Option<wgpu::BlendState>)>,
    pub topology: wgpu::PrimitiveTopology,
    /// [`VERTEX_LAYOUT`], or [`POSITION_LAYOUT`] for lines.
    pub layout: wgpu::VertexBufferLayout<'static>,
    pub depth_write: bool,
    pub bias: wgpu::DepthBiasState,
    /// Faces not drawn (closed meshes wound counter-clockwise seen from outside).
    pub cull: Option<wgpu::Face>,
}

/// A render pipeline over vertex buffers of `spec.layout` with a `LessEqual` depth test.
pub(crate) fn pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    shader: &wgpu::ShaderModule,
    spec: PipelineSpec<'_>,
) -> wgpu::RenderPipeline {
    let targets = spec.fragment.map(|(_, format, blend)| {
        [Some(wgpu::ColorTargetState {
            format,
            blend,
            write_mask: wgpu::ColorWrites::ALL,
        })]
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(spec.fragment.map_or(spec.vertex, |f| f.0)),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module: shader,
            entry_point: Some(spec.vertex),
            compilation_options: Default::default(),
            buffers: &[Some(spec.layout)],
        },
        primitive: wgpu::PrimitiveState {
            topology: spec.topology,
            cull_mode: spec.cull,
            ..Default::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(spec.depth_write),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: Default::default(),
            bias: spec.bias,
        }),
        multisample: Default::default(),
        fragment: spec
            .fragment
            .zip(targets.as_ref())
            .map(|((fs, _, _), targets)| wgpu::FragmentState {
                module: shader,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets,
            }),
        multiview_mask: None,
        cache: None,
    })
}

/// A bind group layout entry for the uniform buffer at binding 0.
pub(crate) const UNIFORM_ENTRY: wgpu::BindGroupLayoutEntry = wgpu::BindGroupLayoutEntry {
    binding: 0,
    visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
    ty: wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: None,
    },
    count: None,
};

/// A uniform buffer of `size` bytes, written through the queue.
pub(crate) fn uniform_buffer(device: &wgpu::Device, label: &str, size: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: size as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// A WGSL module: the shared vertex interface (`vertex_io.wgsl`) followed by `source`.
pub(crate) fn shader(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(
            format!("{}\n{source}", include_str!("vertex_io.wgsl")).into(),
        ),
    })
}
