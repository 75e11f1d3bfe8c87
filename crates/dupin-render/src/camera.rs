//! An orbit camera: yaw and pitch around a target, a distance, perspective projection.

use glam::camera::rh;
use glam::{Mat4, Vec3};

/// Orbit camera looking at `target` from `distance`, z up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitCamera {
    /// Point orbited around.
    pub target: Vec3,
    /// Distance from target to eye.
    pub distance: f32,
    /// Rotation about the z axis, radians.
    pub yaw: f32,
    /// Elevation above the xy plane, radians, kept inside (-pi/2, pi/2).
    pub pitch: f32,
    /// Vertical field of view, radians.
    pub fovy: f32,
}

impl OrbitCamera {
    /// A camera framing a bounding sphere (`center`, `radius`) from a pleasant three-quarter view.
    pub fn framing(center: Vec3, radius: f32) -> Self {
        let fovy = 40f32.to_radians();
        let radius = if radius.is_finite() && radius > 0.0 {
            radius
        } else {
            1.0
        };
        OrbitCamera {
            target: center,
            // The bounding sphere of a box overestimates most shapes: frame a little tighter.
            distance: radius / (fovy * 0.5).sin() * 0.85,
            yaw: -0.9,
            pitch: 0.55,
            fovy,
        }
    }

    /// A camera framing a set of `[x, y, z]` positions.
    pub fn framing_points(positions: &[f32]) -> Self {
        let mut lo = Vec3::splat(f32::INFINITY);
        let mut hi = Vec3::splat(f32::NEG_INFINITY);
        for p in positions.chunks_exact(3) {
            let p = Vec3::new(p[0], p[1], p[2]);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if !lo.is_finite() {
            return Self::framing(Vec3::ZERO, 1.0);
        }
        Self::framing((lo + hi) * 0.5, (hi - lo).length() * 0.5)
    }

    /// Eye position.
    pub fn eye(&self) -> Vec3 {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        self.target + self.distance * Vec3::new(cp * cy, cp * sy, sp)
    }

    /// Rotates by a drag of (`dx`, `dy`) radians.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        if dx.is_finite() && dy.is_finite() {
            self.yaw -= dx;
            self.pitch = (self.pitch + dy).clamp(-1.55, 1.55);
        }
    }

    /// Multiplies the distance by `factor` (a wheel notch is about 1.1), within sane limits.
    pub fn zoom(&mut self, factor: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(1e-3, 1e6);
        }
    }

    /// Projection times view, for a viewport of the given aspect ratio (width / height).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        let near = (self.distance * 0.01).max(1e-4);
        let far = self.distance * 10.0 + 10.0;
        // WebGPU clip space: z in [0, 1], y up, as DirectX.
        rh::proj::directx::perspective(self.fovy, aspect.max(1e-3), near, far)
            * rh::view::look_at_mat4(self.eye(), self.target, Vec3::Z)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framing_keeps_the_target_in_view() {
        let cam = OrbitCamera::framing(Vec3::new(1.0, 2.0, 3.0), 2.0);
        let clip = cam.view_proj(1.5) * Vec3::new(1.0, 2.0, 3.0).extend(1.0);
        let ndc = clip.truncate() / clip.w;
        assert!(ndc.x.abs() < 1e-5 && ndc.y.abs() < 1e-5 && ndc.z > 0.0 && ndc.z < 1.0);
    }

    #[test]
    fn orbit_moves_the_eye_and_clamps_pitch() {
        let mut cam = OrbitCamera::framing(Vec3::ZERO, 1.0);
        let e0 = cam.eye();
        cam.orbit(0.5, 10.0);
        assert!(cam.pitch <= 1.55);
        assert!((cam.eye() - e0).length() > 0.1);
        cam.orbit(f32::NAN, 0.0);
        assert!(cam.eye().is_finite());
    }
}
