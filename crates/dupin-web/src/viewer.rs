//! A canvas viewer: wgpu surface + `dupin_render::MeshRenderer` + orbit camera.

use crate::mesh_data::MeshData;
use dupin_render::{Draw, Frame, MeshRenderer, OrbitCamera, wgpu};
use wasm_bindgen::prelude::*;

/// Draws meshes into an HTML canvas with WebGPU, or WebGL2 where WebGPU is unavailable.
#[wasm_bindgen]
pub struct Viewer {
    canvas: Canvas<MeshRenderer>,
}

#[wasm_bindgen]
impl Viewer {
    /// Creates a viewer on `canvas`. With `force_webgl2`, WebGPU is not tried (for testing the
    /// fallback and for browsers whose WebGPU misbehaves). The build without the `webgl` feature
    /// refuses, with the canvas untouched, where it would need WebGL2.
    pub async fn create(
        canvas: web_sys::HtmlCanvasElement,
        force_webgl2: bool,
    ) -> Result<Viewer, JsError> {
        let canvas = Canvas::open(canvas, force_webgl2, "dupin", MeshRenderer::new).await?;
        Ok(Viewer { canvas })
    }

    /// `"WebGPU"` or `"WebGL2"`.
    #[wasm_bindgen(getter)]
    pub fn backend(&self) -> String {
        self.canvas.backend.to_string()
    }

    /// Shows `mesh`; with `reframe`, the camera is reset to frame it.
    #[wasm_bindgen(js_name = setMesh)]
    pub fn set_mesh(&mut self, mesh: &MeshData, reframe: bool) -> Result<(), JsError> {
        let colors = (!mesh.colors.is_empty()).then_some(mesh.colors.as_slice());
        let c = &mut self.canvas;
        c.renderer
            .set_mesh(&c.device, &c.queue, &mesh.buffers, colors)
            .map_err(crate::js::err)?;
        if mesh.edges.is_empty() {
            c.renderer.clear_lines();
        } else {
            c.renderer
                .set_lines(&c.device, &c.queue, &mesh.edges, [0.06, 0.06, 0.07]);
        }
        if reframe {
            c.camera = OrbitCamera::framing_points(&mesh.buffers.positions);
        }
        Ok(())
    }

    /// Rotates the view by a drag of (`dx`, `dy`) radians.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.canvas.camera.orbit(dx, dy);
    }

    /// The camera as `[target x, y, z, distance, yaw, pitch]` (for the URL hash).
    pub fn camera(&self) -> Vec<f32> {
        crate::pick::camera_numbers(&self.canvas.camera)
    }

    /// Sets the camera from [`Viewer::camera`]'s six numbers. Throws for a wrong length,
    /// non-finite values or a distance that is not positive.
    #[wasm_bindgen(js_name = setCamera)]
    pub fn set_camera(&mut self, v: Vec<f32>) -> Result<(), JsError> {
        // The orbit camera's own pitch limits apply.
        self.canvas.camera = crate::pick::camera_from(&v).map_err(crate::js::err)?;
        Ok(())
    }

    /// The view ray through a canvas point given in normalised device coordinates (x, y in
    /// [-1, 1], y up): `[origin x, y, z, direction x, y, z]` (unit direction), for
    /// `Session.pickVertex`. Throws for non-finite input.
    #[wasm_bindgen(js_name = pickRay)]
    pub fn pick_ray(&self, ndc_x: f32, ndc_y: f32) -> Result<Vec<f64>, JsError> {
        let (o, d) = crate::pick::view_ray(&self.canvas.camera, self.canvas.aspect(), ndc_x, ndc_y)
            .filter(|_| ndc_x.is_finite() && ndc_y.is_finite())
            .ok_or_else(|| JsError::new("the click is not a finite canvas point"))?;
        Ok([o.x, o.y, o.z, d.x, d.y, d.z].map(f64::from).to_vec())
    }

    /// Normalised device coordinates and depth `[x, y, z]` of the 3D point (x, y, z) in the
    /// current view (to mark a picked vertex); `undefined` behind the eye.
    pub fn project(&self, x: f32, y: f32, z: f32) -> Option<Vec<f32>> {
        crate::pick::project(
            &self.canvas.camera,
            self.canvas.aspect(),
            glam::Vec3::new(x, y, z),
        )
        .map(|p| p.to_vec())
    }

    /// The current view and projection as one 4 x 4 matrix, 16 numbers column-major (for
    /// `Session.verticesInRect`).
    #[wasm_bindgen(js_name = viewProj)]
    pub fn view_proj(&self) -> Vec<f32> {
        self.canvas
            .camera
            .view_proj(self.canvas.aspect())
            .to_cols_array()
            .to_vec()
    }

    /// Moves the camera closer (`factor` < 1) or farther (`factor` > 1).
    pub fn zoom(&mut self, factor: f32) {
        self.canvas.camera.zoom(factor);
    }

    /// Adapts to a new canvas size in device pixels.
    pub fn resize(&mut self, width: u32, height: u32) {
        self.canvas.resize(width, height);
    }

    /// Renders the current view at `scale` times the canvas size (e.g. 2 for a 2x PNG) and
    /// resolves to an `ImageData` of it. Pixels come back from the GPU, so this works where a
    /// browser screenshot does not show WebGPU canvases (headless Chromium).
    pub fn snapshot(&mut self, scale: f32) -> Result<js_sys::Promise, JsError> {
        self.canvas.snapshot(scale)
    }

    /// Lets wgpu deliver finished work (buffer maps of [`Viewer::snapshot`]). WebGPU does this
    /// by itself; the WebGL2 backend needs it called, so the page calls it every frame.
    pub fn poll(&self) {
        self.canvas.poll();
    }

    /// Draws one frame.
    pub fn render(&mut self) -> Result<(), JsError> {
        self.canvas.render()
    }
}

/// The canvas's next frame, or `None` when there is nothing to draw into this time (an outdated
/// or lost surface is reconfigured; a timeout or an occluded canvas skips the frame).
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

/// A canvas with its wgpu surface, device and queue, the renderer drawing into it and the camera
/// it draws with (shared by [`Viewer`] and the presenter).
pub(crate) struct Canvas<R> {
    surface: wgpu::Surface<'static>,
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    config: wgpu::SurfaceConfiguration,
    /// `"WebGPU"` or `"WebGL2"`.
    pub(crate) backend: &'static str,
    pub(crate) renderer: R,
    pub(crate) camera: OrbitCamera,
}

impl<R: Draw> Canvas<R> {
    /// Opens `canvas` with WebGPU, or WebGL2 where WebGPU is missing (`force_webgl2`: WebGL2
    /// only; an error without the `webgl` feature), under WebGL2's limits so both backends
    /// behave alike.
    pub(crate) async fn open(
        canvas: web_sys::HtmlCanvasElement,
        force_webgl2: bool,
        label: &str,
        renderer: impl FnOnce(&wgpu::Device, wgpu::TextureFormat) -> R,
    ) -> Result<Self, JsError> {
        let (width, height) = (canvas.width().max(1), canvas.height().max(1));
        // WebGPU only where the browser gives an adapter (Chrome on Linux offers `navigator.gpu`
        // and none). Asked before the canvas is touched: a canvas that gave out a WebGPU context
        // gives no WebGL2 one, and the page retries this canvas with the WebGL2 build.
        let webgpu = !force_webgl2 && wgpu::util::is_browser_webgpu_supported().await;
        if !webgpu && !cfg!(feature = "webgl") {
            return Err(JsError::new(
                "this browser gives no WebGPU adapter, and this build of Dupin's module draws \
                 with WebGPU only (its WebGL2 build is pkg-gl/ or pkg-viewer-gl/)",
            ));
        }
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = if webgpu {
            wgpu::Backends::BROWSER_WEBGPU | wgpu::Backends::GL
        } else {
            wgpu::Backends::GL
        };
        let instance = wgpu::Instance::new(desc);
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
        Ok(Canvas {
            renderer: renderer(&device, config.format),
            camera: OrbitCamera::framing(glam::Vec3::ZERO, 1.0),
            surface,
            device,
            queue,
            config,
            backend,
        })
    }

    /// Width over height of the canvas.
    pub(crate) fn aspect(&self) -> f32 {
        self.config.width as f32 / self.config.height.max(1) as f32
    }

    /// Reconfigures the surface for a new size in device pixels (clamped to 1..=8192), when it
    /// changed.
    pub(crate) fn resize(&mut self, width: u32, height: u32) {
        let (width, height) = (width.clamp(1, 8192), height.clamp(1, 8192));
        if (width, height) != (self.config.width, self.config.height) {
            self.config.width = width;
            self.config.height = height;
            self.surface.configure(&self.device, &self.config);
        }
    }

    /// Draws one frame into the canvas and presents it (nothing when the surface has no frame
    /// to give, e.g. while it is being reconfigured).
    pub(crate) fn render(&mut self) -> Result<(), JsError> {
        let Some(texture) = next_frame(&self.surface, &self.device, &self.config)? else {
            return Ok(());
        };
        let target = texture.texture.create_view(&Default::default());
        let frame = Frame {
            device: &self.device,
            queue: &self.queue,
            target: &target,
            width: self.config.width,
            height: self.config.height,
        };
        self.renderer.draw(&frame, &self.camera);
        self.queue.present(texture);
        Ok(())
    }

    /// Renders at `scale` x the canvas size (2 for the 2x PNG); resolves to an `ImageData`.
    pub(crate) fn snapshot(&mut self, scale: f32) -> Result<js_sys::Promise, JsError> {
        let size = snapshot_size(&self.config, scale)?;
        let pending = self
            .renderer
            .begin_snapshot(&self.device, &self.queue, size, &self.camera);
        let promise = image_data_promise(pending);
        self.poll();
        Ok(promise)
    }

    /// Lets wgpu deliver finished work (snapshots on WebGL2).
    pub(crate) fn poll(&self) {
        let _ = self.device.poll(wgpu::PollType::Poll);
    }
}

/// The pixel size of a snapshot at `scale` times the canvas (`scale` in (0, 8]).
fn snapshot_size(config: &wgpu::SurfaceConfiguration, scale: f32) -> Result<(u32, u32), JsError> {
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
fn image_data_promise(pending: dupin_render::PendingSnapshot) -> js_sys::Promise {
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
