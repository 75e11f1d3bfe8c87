//! Reading a rendered frame back to RGBA bytes, in bands small enough for every WebGPU.

use crate::error::RenderError;

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

/// A rendered frame on its way back from the GPU (see [`crate::Draw::begin_snapshot`]).
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
