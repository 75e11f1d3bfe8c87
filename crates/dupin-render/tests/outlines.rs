#![cfg(not(target_arch = "wasm32"))]
//! Panel outlines drawn over their faces read as continuous lines at every view (no dashes from
//! depth fighting), and lines behind a surface stay hidden.
//!
//! The check compares two renders of the same camera: the lines alone give the pixels a line
//! covers; drawn over the mesh, nearly all of those pixels must still be line-coloured.

use dupin_core::mesh::TriangleBuffers;
use dupin_render::{OffscreenImage, OrbitCamera, render_offscreen};

mod common;
use common::{H, W, expect_image, reference_image, save};

/// A flat `n` x `n` grid of unit quads at height `z` (two triangles each), and its quad edges as
/// line segments.
fn grid(n: usize, z: f32) -> (TriangleBuffers, Vec<f32>) {
    let mut mesh = TriangleBuffers::default();
    let side = n + 1;
    for j in 0..side {
        for i in 0..side {
            mesh.positions.extend([i as f32, j as f32, z]);
            mesh.normals.extend([0.0, 0.0, 1.0]);
        }
    }
    let id = |i: usize, j: usize| (j * side + i) as u32;
    let mut lines = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            mesh.indices.extend([a, b, c, a, c, d]);
        }
    }
    let p = |i: usize, j: usize| [i as f32, j as f32, z];
    for k in 0..side {
        lines.extend(p(0, k).into_iter().chain(p(n, k)));
        lines.extend(p(k, 0).into_iter().chain(p(k, n)));
    }
    (mesh, lines)
}

/// Pixels dark enough to be the line colour or the background (the lit grey mesh is lighter).
fn dark(img: &OffscreenImage) -> Vec<bool> {
    img.rgba
        .chunks_exact(4)
        .map(|p| p[..3].iter().all(|&c| c < 90))
        .collect()
}

/// Pixels of `a` farther than `levels` (any channel) from the same pixel of `b`.
fn differ(a: &OffscreenImage, b: &OffscreenImage, levels: i32) -> Vec<bool> {
    a.rgba
        .chunks_exact(4)
        .zip(b.rgba.chunks_exact(4))
        .map(|(p, q)| (0..3).any(|k| (p[k] as i32 - q[k] as i32).abs() > levels))
        .collect()
}

/// The fraction of the pixels the lines alone cover that are still line-coloured when the lines
/// are drawn over `mesh`.
fn line_coverage(mesh: &TriangleBuffers, lines: &[f32], camera: &OrbitCamera, name: &str) -> f64 {
    let empty = TriangleBuffers::default();
    let background = expect_image(render_offscreen(&empty, None, camera, W, H));
    let alone = expect_image(render_offscreen(&empty, Some(lines), camera, W, H));
    let over = expect_image(render_offscreen(mesh, Some(lines), camera, W, H));
    save(&over, name);
    let (want, got) = (differ(&alone, &background, 6), dark(&over));
    let covered = want.iter().filter(|&&w| w).count();
    assert!(covered > 500, "the lines cover only {covered} pixels");
    let kept = want.iter().zip(&got).filter(|&(&w, &g)| w && g).count();
    let mut lost = over.clone();
    for (k, (&w, &g)) in want.iter().zip(&got).enumerate() {
        if w && !g {
            lost.rgba[4 * k..4 * k + 3].copy_from_slice(&[255, 0, 0]);
        }
    }
    // Lost line pixels in red, to see where a failure is.
    save(&lost, &format!("lost-{name}"));
    kept as f64 / covered as f64
}

#[test]
fn outlines_are_continuous_from_steep_and_grazing_views() {
    let (mesh, lines) = grid(10, 0.0);
    for (pitch, yaw) in [(0.55, -0.9), (0.25, -0.4), (0.12, 0.3), (1.2, 0.2)] {
        let mut cam = OrbitCamera::framing_points(&mesh.positions);
        cam.pitch = pitch;
        cam.yaw = yaw;
        let name = format!("outlines-pitch-{pitch}.png");
        let kept = line_coverage(&mesh, &lines, &cam, &name);
        eprintln!("pitch {pitch}: {:.2}% of outline pixels kept", kept * 100.0);
        assert!(
            kept > 0.97,
            "at pitch {pitch} only {:.1}% of the outline pixels survive the faces under them \
             (dashed lines); see target/render-tests/{name}",
            kept * 100.0
        );
    }
}

#[test]
fn outlined_grid_matches_reference_image() {
    let (mesh, lines) = grid(10, 0.0);
    let cam = OrbitCamera::framing_points(&mesh.positions);
    let img = expect_image(render_offscreen(&mesh, Some(&lines), &cam, W, H));
    let actual = save(&img, "outlines.png");
    let (want, reference) = reference_image("outlines.png", &actual);
    let off = img
        .rgba
        .chunks_exact(4)
        .zip(want.chunks_exact(4))
        .filter(|(p, q)| (0..3).any(|k| (p[k] as i32 - q[k] as i32).abs() > 24))
        .count();
    let fraction = off as f64 / (W * H) as f64;
    assert!(
        fraction < 0.005,
        "render differs from reference ({}): {:.2}% pixels off; adapter {}; see {}",
        reference.display(),
        fraction * 100.0,
        img.adapter,
        actual.display()
    );
}

#[test]
fn outlines_behind_a_surface_stay_hidden() {
    // Lines on a grid at z = 0, seen from above through an opaque grid at z = 0.2 (2% of the
    // viewing distance): none may show through.
    let (_, lines) = grid(10, 0.0);
    let (cover, _) = grid(10, 0.2);
    let mut cam = OrbitCamera::framing_points(&cover.positions);
    cam.pitch = 1.2;
    cam.distance *= 0.6;
    let img = expect_image(render_offscreen(&cover, Some(&lines), &cam, W, H));
    let bare = expect_image(render_offscreen(&cover, None, &cam, W, H));
    save(&img, "outlines-hidden.png");
    let shown = differ(&img, &bare, 24).iter().filter(|&&d| d).count();
    assert!(shown < 20, "{shown} pixels of hidden lines show through");
}
