#![cfg(not(target_arch = "wasm32"))]
//! Native offscreen test of presentation mode: a curved panel grid as glass with metal frames
//! over a ground, with sun shadows, drawn on whatever Vulkan/GL adapter exists (lavapipe in CI).
//! Checks a stored reference image, that the frames are visible, that the glass lets the ground
//! through, and that the frames cast shadows on the ground.
//!
//! `DUPIN_BLESS=1 cargo test -p dupin-render --test presentation` rewrites the reference.

use dupin_core::mesh::{PolyMesh, TriangleBuffers, polymesh_buffers, polymesh_edges};

use dupin_core::Vec3;
use dupin_render::{
    FrameInstances, OffscreenImage, OrbitCamera, PresentationOffscreen, frame_instances,
    render_presentation_offscreen,
};

mod common;
use common::{H, W, expect_image, reference_image, save};

/// An 8 x 6 grid of quads on a gentle saddle, lifted above the ground it casts shadows on.
fn panels() -> PolyMesh {
    let (nu, nv) = (8usize, 6usize);
    let mut pos = Vec::new();
    for i in 0..=nu {
        for j in 0..=nv {
            let (x, y) = (
                i as f64 / nu as f64 * 4.0 - 2.0,
                j as f64 / nv as f64 * 3.0 - 1.5,
            );
            pos.push(Vec3::new(x, y, 1.2 + 0.12 * (x * x - y * y)));
        }
    }
    let faces: Vec<[u32; 4]> = (0..nu)
        .flat_map(|i| {
            (0..nv).map(move |j| {
                let k = |a: usize, b: usize| (a * (nv + 1) + b) as u32;
                [k(i, j), k(i + 1, j), k(i + 1, j + 1), k(i, j + 1)]
            })
        })
        .collect();
    PolyMesh::new(pos, &faces).unwrap()
}

/// Glass and frame buffers of the test scene (without frames: only the four legs, so the ground
/// sits at the same height in every variant; without glass: no panels) and its camera.
fn scene(with_frames: bool, with_glass: bool) -> (TriangleBuffers, FrameInstances, OrbitCamera) {
    let m = panels();
    let (glass, _) = polymesh_buffers(&m, None);
    let mut edges = polymesh_edges(&m);
    for c in [[-2.0f32, -1.5], [2.0, -1.5], [2.0, 1.5], [-2.0, 1.5]] {
        let z = 1.2 + 0.12 * (c[0] * c[0] - c[1] * c[1]);
        edges.extend([c[0], c[1], z, c[0], c[1], 0.0]);
    }
    let frames = if with_frames {
        frame_instances(&edges, 0.05, 0.09)
    } else {
        frame_instances(&edges[edges.len() - 24..], 0.05, 0.09)
    };
    let glass = if with_glass {
        glass
    } else {
        TriangleBuffers::default()
    };
    let mut cam = OrbitCamera::framing_points(
        &m.positions
            .iter()
            .flat_map(|p| [p.x as f32, p.y as f32, 0.6])
            .collect::<Vec<_>>(),
    );
    cam.distance *= 1.15;
    (glass, frames, cam)
}

fn render(with_frames: bool, with_glass: bool, shadows: bool) -> OffscreenImage {
    let (glass, frames, cam) = scene(with_frames, with_glass);
    expect_image(render_presentation_offscreen(
        &glass,
        &frames,
        &cam,
        (W, H),
        shadows,
    ))
}

/// Fraction of pixels differing by more than `t` levels in some channel.
fn differing(a: &[u8], b: &[u8], t: i32) -> f64 {
    let n = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(p, q)| (0..3).any(|k| (p[k] as i32 - q[k] as i32).abs() > t))
        .count();
    n as f64 / (a.len() / 4) as f64
}

fn mean_abs(a: &[u8], b: &[u8]) -> f64 {
    let s: u64 = a
        .iter()
        .zip(b)
        .enumerate()
        .filter(|(i, _)| i % 4 != 3)
        .map(|(_, (x, y))| (*x as i32 - *y as i32).unsigned_abs() as u64)
        .sum();
    s as f64 / (a.len() / 4 * 3) as f64
}

#[test]
fn presentation_matches_reference_and_shows_frames_glass_and_shadows() {
    let full = render(true, true, true);
    let actual = save(&full, "presentation.png");
    let no_frames = render(false, true, true);
    save(&no_frames, "presentation-no-frames.png");
    let no_glass = render(true, false, true);
    save(&no_glass, "presentation-no-glass.png");

    // Frames visible: removing the beams and nodes changes a good part of the picture.
    let by_frames = differing(&full.rgba, &no_frames.rgba, 24);
    assert!(
        by_frames > 0.02,
        "frames change only {:.2}% of pixels",
        by_frames * 100.0
    );
    // Glass is there but translucent: it changes the picture, yet far less than an opaque
    // surface would (what is behind it still shows through).
    let by_glass = mean_abs(&full.rgba, &no_glass.rgba);
    assert!(by_glass > 1.0, "glass invisible (mean |d| {by_glass:.2})");
    // Shadows: with the sun's shadow map the picture only gets darker, in a visible part of it.
    let unshadowed = render(true, true, false);
    save(&unshadowed, "presentation-no-shadows.png");
    let shaded = differing(&full.rgba, &unshadowed.rgba, 8);
    assert!(
        shaded > 0.01,
        "shadows change only {:.2}% of pixels",
        shaded * 100.0
    );
    let brighter = full
        .rgba
        .chunks_exact(4)
        .zip(unshadowed.rgba.chunks_exact(4))
        .filter(|(p, q)| (0..3).any(|k| p[k] as i32 > q[k] as i32 + 8))
        .count();
    assert!(
        brighter as f64 / (W * H) as f64 <= 0.001,
        "{brighter} pixels brighter in shadow"
    );

    let (want, _) = reference_image("presentation.png", &actual);
    let off = differing(&full.rgba, &want, 24);
    let mean = mean_abs(&full.rgba, &want);
    assert!(
        off < 0.005 && mean < 1.5,
        "render differs from reference: {:.2}% pixels off, mean |d| {mean:.2}; adapter {}; see {}",
        off * 100.0,
        full.adapter,
        actual.display()
    );
}

/// The shadow map is drawn once per scene or shadow setting, not once per frame, and the cached
/// map gives exactly the picture a fresh renderer draws: orbiting does not need the sun's pass.
#[test]
fn shadow_map_is_cached_across_orbit_frames_and_redrawn_on_change() {
    let (glass, frames, cam) = scene(true, true);
    let mut p = expect_image_ok(PresentationOffscreen::new(&glass, &frames));
    assert_eq!(p.renderer().shadow_passes(), 0);
    let mut orbit = cam;
    for _ in 0..5 {
        orbit.orbit(0.3, 0.05);
        p.frame(&orbit, (W, H)).unwrap();
    }
    assert_eq!(
        p.renderer().shadow_passes(),
        1,
        "one shadow pass for five orbit frames"
    );
    // After five frames from elsewhere, the cached map draws this view exactly as a fresh
    // renderer (which draws its shadow map for this very frame) does.
    let cached = p.snapshot(&cam, (W, H)).unwrap();
    let fresh = render(true, true, true);
    assert_eq!(p.renderer().shadow_passes(), 1);
    assert!(
        cached.rgba == fresh.rgba,
        "cached shadows differ from fresh ones"
    );

    // Setting the same value keeps the map; a change redraws it, once.
    p.renderer().set_shadows(true);
    p.frame(&orbit, (W, H)).unwrap();
    assert_eq!(p.renderer().shadow_passes(), 1);
    p.renderer().set_shadows(false);
    let unlit = p.snapshot(&cam, (W, H)).unwrap();
    p.frame(&orbit, (W, H)).unwrap();
    assert_eq!(p.renderer().shadow_passes(), 2);
    assert!(
        unlit.rgba == render(true, true, false).rgba,
        "stale shadows after turning them off"
    );
    p.renderer().set_shadows(true);
    assert!(p.snapshot(&cam, (W, H)).unwrap().rgba == fresh.rgba);
    assert_eq!(p.renderer().shadow_passes(), 3);

    // A new scene (frames reduced to the legs) redraws the map: its shadows are the new ones.
    let (glass2, frames2, _) = scene(false, true);
    p.set_scene(&glass2, &frames2).unwrap();
    let legs = p.snapshot(&cam, (W, H)).unwrap();
    assert_eq!(p.renderer().shadow_passes(), 4);
    assert!(
        legs.rgba == render(false, true, true).rgba,
        "stale shadows after a new scene"
    );
    assert!(legs.rgba != fresh.rgba);
}

fn expect_image_ok<T>(r: Result<T, dupin_render::RenderError>) -> T {
    r.unwrap_or_else(|e| panic!("offscreen rendering failed: {e}; install mesa-vulkan-drivers"))
}
