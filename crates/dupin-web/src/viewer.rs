//! A canvas viewer: wgpu surface + `dupin_render::MeshRenderer` + orbit camera.

use crate::mesh_data::MeshData;
use dupin_render::{Draw, MeshRenderer, OrbitCamera, wgpu};
use wasm_bindgen::prelude::*;

/// Draws meshes into an HTML canvas with WebGPU, or WebGL2 where WebGPU is unavailable.
#[wasm_bindgen]
pub struct Viewer {
    surface: wgpu::Surface<'static>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    renderer: MeshRenderer,
    camera: OrbitCamera,
    backend: &'static str,
}

#[wasm_bindgen]
impl Viewer {
    /// Creates a viewer on `canvas`. With `force_webgl2`, WebGPU is not tried (for testing the
    /// fallback and for browsers whose WebGPU misbehaves).
    pub async fn create(
        canvas: web_sys::HtmlCanvasElement,
        force_webgl2: bool,
    ) -> Result<Viewer, JsError> {
        let CanvasGpu {
            surface,
            device,
            queue,
            config,
            backend,
        } = CanvasGpu::open(canvas, force_webgl2, "dupin").await?;
        let renderer = MeshRenderer::new(&device, config.format);
        Ok(Viewer {
            surface,
            device,
            queue,
            config,
            renderer,
            camera: OrbitCamera::framing(glam::Vec3::ZERO, 1.0),
            backend,
        })
    }

    /// `"WebGPU"` or `"WebGL2"`.
    #[wasm_bindgen(getter)]
    pub fn backend(&self) -> String {
        self.backend.to_string()
    }

    /// Shows `mesh`; with `reframe`, the camera is reset to frame it.
    #[wasm_bindgen(js_name = setMesh)]
    pub fn set_mesh(&mut self, mesh: &MeshData, reframe: bool) -> Result<(), JsError> {
        let colors = (!mesh.colors.is_empty()).then_some(mesh.colors.as_slice());
        self.renderer
            .set_mesh(&self.device, &self.queue, &mesh.buffers, colors)
            .map_err(crate::js::err)?;
        if mesh.edges.is_empty() {
            self.renderer.clear_lines();
        } else {
            self.renderer
                .set_lines(&self.device, &self.queue, &mesh.edges, [0.06, 0.06, 0.07]);
        }
        if reframe {
            self.camera = OrbitCamera::framing_points(&mesh.buffers.positions);
        }
        Ok(())
    }

    /// Rotates the view by a drag of (`dx`, `dy`) radians.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.camera.orbit(dx, dy);
    }

    /// The camera as `[target x, y, z, distance, yaw, pitch]` (for the URL hash).
    pub fn camera(&self) -> Vec<f32> {
        let c = &self.camera;
        vec![
            c.target.x, c.target.y, c.target.z, c.distance, c.yaw, c.pitch,
        ]
    }

    /// Sets the camera from [`Viewer::camera`]'s six numbers. Throws for a wrong length,
    /// non-finite values or a distance that is not positive.
    #[wasm_bindgen(js_name = setCamera)]
    pub fn set_camera(&mut self, v: Vec<f32>) -> Result<(), JsError> {
        // The orbit camera's own pitch limits apply.
        self.camera = crate::pick::camera_from(&v).map_err(crate::js::err)?;
        Ok(())
    }

    /// The view ray through a canvas point given in normalised device coordinates (x, y in
    /// [-1, 1], y up): `[origin x, y, z, direction x, y, z]` (unit direction), for
    /// `Session.pickVertex`. Throws for non-finite input.
    #[wasm_bindgen(js_name = pickRay)]
    pub fn pick_ray(&self, ndc_x: f32, ndc_y: f32) -> Result<Vec<f64>, JsError> {
        let (o, d) = crate::pick::view_ray(&self.camera, self.aspect(), ndc_x, ndc_y)
            .filter(|_| ndc_x.is_finite() && ndc_y.is_finite())
            .ok_or_else(|| JsError::new("the click is not a finite canvas point"))?;
        Ok([o.x, o.y, o.z, d.x, d.y, d.z].map(f64::from).to_vec())
    }

    /// Normalised device coordinates and depth `[x, y, z]` of the 3D point (x, y, z) in the
    /// current view (to mark a picked vertex); `undefined` behind the eye.
    pub fn project(&self, x: f32, y: f32, z: f32) -> Option<Vec<f32>> {
        crate::pick::project(&self.camera, self.aspect(), glam::Vec3::new(x, y, z))
            .map(|p| p.to_vec())
    }

    fn aspect(&self) -> f32 {
        self.config.width as f32 / self.config.height.max(1) as f32
    }

    /// Moves the camera closer (`factor` < 1) or farther (`factor` > 1).
    pub fn zoom(&mut self, factor: f32) {
        self.camera.zoom(factor);
    }

    /// Adapts to a new canvas size in device pixels.
    pub fn resize(&mut self, width: u32, height: u32) {
        resize_surface(&self.surface, &self.device, &mut self.config, width, height);
    }

    /// Renders the current view at `scale` times the canvas size (e.g. 2 for a 2x PNG) and
    /// resolves to an `ImageData` of it. Pixels come back from the GPU, so this works where a
    /// browser screenshot does not show WebGPU canvases (headless Chromium).
    pub fn snapshot(&mut self, scale: f32) -> Result<js_sys::Promise, JsError> {
        let (w, h) = snapshot_size(&self.config, scale)?;
        let pending = self
            .renderer
            .begin_snapshot(&self.device, &self.queue, w, h, &self.camera);
        let promise = image_data_promise(pending);
        self.poll();
        Ok(promise)
    }

    /// Lets wgpu deliver finished work (buffer maps of [`Viewer::snapshot`]). WebGPU does this
    /// by itself; the WebGL2 backend needs it called, so the page calls it every frame.
    pub fn poll(&self) {
        let _ = self.device.poll(wgpu::PollType::Poll);
    }

    /// Draws one frame.
    pub fn render(&mut self) -> Result<(), JsError> {
        let (renderer, camera) = (&mut self.renderer, &self.camera);
        let (w, h) = (self.config.width, self.config.height);
        draw_frame(
            &self.surface,
            &self.device,
            &self.queue,
            &self.config,
            |d, q, view| renderer.draw(d, q, view, w, h, camera),
        )
    }
}

/// The canvas's next frame, or `None` when there is nothing to draw into this time (an outdated
/// or lost surface is reconfigured; a timeout or an occluded canvas skips the frame).
/// Reconfigures the canvas surface for a new size in device pixels (clamped to 1..=8192),
/// when it changed.
pub(crate) fn resize_surface(
    surface: &wgpu::Surface<'static>,
    device: &wgpu::Device,
    config: &mut wgpu::SurfaceConfiguration,
    width: u32,
    height: u32,
) {
    let (width, height) = (width.clamp(1, 8192), height.clamp(1, 8192));
    if (width, height) != (config.width, config.height) {
        config.width = width;
        config.height = height;
        surface.configure(device, config);
    }
}

/// Draws one frame into the canvas with `draw` and presents it (nothing when the surface has no
/// frame to give, e.g. while it is being reconfigured).
pub(crate) fn draw_frame(
    surface: &wgpu::Surface<'static>,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    config: &wgpu::SurfaceConfiguration,
    draw: impl FnOnce(&wgpu::Device, &wgpu::Queue, &wgpu::TextureView),
) -> Result<(), JsError> {
    let Some(frame) = next_frame(surface, device, config)? else {
        return Ok(());
    };
    let view = frame.texture.create_view(&Default::default());
    draw(device, queue, &view);
    queue.present(frame);
    Ok(())
}

fn next_frame(
    surface: &wgpu::Surface<'static>,
    device: &wgpu::Device,
    config: &wgpu::SurfaceConfiguration,
) -> Result<Option<wgpu::SurfaceTexture>, JsError> {
    match surface.get_current_texture() {
        wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
            Ok(Some(t))
        }
        wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
            surface.configure(device, config);
            Ok(None)
        }
        wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => Ok(None),
        wgpu::CurrentSurfaceTexture::Validation => Err(JsError::new(
            "the canvas surface reported a validation error",
        )),
    }
}

/// A canvas with its wgpu surface, device and queue (shared by [`Viewer`] and the presenter).
pub(crate) struct CanvasGpu {
    pub(crate) surface: wgpu::Surface<'static>,
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) config: wgpu::SurfaceConfiguration,
    /// `"WebGPU"` or `"WebGL2"`.
    pub(crate) backend: &'static str,
}

impl CanvasGpu {
    /// Opens `canvas` with WebGPU, or WebGL2 where WebGPU is missing (`force_webgl2`: WebGL2
    /// only), under WebGL2's limits so both backends behave alike.
    pub(crate) async fn open(
        canvas: web_sys::HtmlCanvasElement,
        force_webgl2: bool,
        label: &str,
    ) -> Result<CanvasGpu, JsError> {
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = if force_webgl2 {
            wgpu::Backends::GL
        } else {
            wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL
        };
        let instance = wgpu::util::new_instance_with_webgpu_detection(desc).await;
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| JsError::new(&format!("cannot draw into the canvas: {e}")))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                compatible_surface: Some(&surface),
                ..Default::default()
            })
            .await
            .map_err(|e| {
                JsError::new(&format!("no WebGPU or WebGL2 adapter in this browser: {e}"))
            })?;
        let backend = match adapter.get_info().backend {
            wgpu::Backend::BrowserWebGpu => "WebGPU",
            wgpu::Backend::Gl => "WebGL2",
            _ => "other",
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some(label),
                required_limits: wgpu::Limits::downlevel_webgl2_defaults()
                    .using_resolution(adapter.limits()),
                ..Default::default()
            })
            .await
            .map_err(|e| JsError::new(&format!("cannot open the graphics device: {e}")))?;
        let config = surface
            .get_default_config(&adapter, width, height)
            .ok_or_else(|| JsError::new("the canvas is not supported by this adapter"))?;
        surface.configure(&device, &config);
        Ok(CanvasGpu {
            surface,
            device,
            queue,
            config,
            backend,
        })
    }
}

/// The pixel size of a snapshot at `scale` times the canvas (`scale` in (0, 8]).
pub(crate) fn snapshot_size(
    config: &wgpu::SurfaceConfiguration,
    scale: f32,
) -> Result<(u32, u32), JsError> {
    if !(scale.is_finite() && scale > 0.0 && scale <= 8.0) {
        return Err(JsError::new(&format!(
            "snapshot scale must be in (0, 8], got {scale}"
        )));
    }
    Ok((
        (config.width as f32 * scale).round() as u32,
        (config.height as f32 * scale).round() as u32,
    ))
}

/// A promise of the `ImageData` a GPU readback delivers (the caller polls the device).
pub(crate) fn image_data_promise(pending: dupin_render::PendingSnapshot) -> js_sys::Promise {
    let (w, h) = (pending.width(), pending.height());
    // Promise::new takes an FnMut it calls exactly once.
    let mut pending = Some(pending);
    js_sys::Promise::new(&mut |resolve, reject| {
        let Some(pending) = pending.take() else {
            return;
        };
        pending.read(move |result| {
            let value = result
                .map_err(|e| JsValue::from(js_sys::Error::new(&e.to_string())))
                .and_then(|rgba| {
                    web_sys::ImageData::new_with_u8_clamped_array_and_sh(
                        wasm_bindgen::Clamped(&rgba),
                        w,
                        h,
                    )
                    .map(JsValue::from)
                });
            let _ = match value {
                Ok(v) => resolve.call1(&JsValue::NULL, &v),
                Err(e) => reject.call1(&JsValue::NULL, &e),
            };
        });
    })
}
