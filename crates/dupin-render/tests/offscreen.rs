#![cfg(not(target_arch = "wasm32"))]
//! Native offscreen render test: the torus of the web slice, drawn through `dupin-render` on
//! whatever Vulkan/GL adapter exists (lavapipe in CI), compared with a stored reference image.
//!
//! `DUPIN_BLESS=1 cargo test -p dupin-render --test offscreen` rewrites the reference after an
//! intended visual change; look at `target/render-tests/*.png` before committing it.

use dupin_core::surface::{Torus, sample_surface};
use dupin_render::{BACKGROUND, OffscreenImage, OrbitCamera, render_offscreen};

mod common;
use common::{H, W, expect_image, reference_image, save};

fn torus_image(camera: impl FnOnce(&mut OrbitCamera)) -> OffscreenImage {
    let mesh = sample_surface(
        &Torus {
            major: 2.0,
            minor: 0.7,
        },
        96,
        48,
    );
    let mut cam = OrbitCamera::framing_points(&mesh.positions);
    camera(&mut cam);
    expect_image(render_offscreen(&mesh, None, &cam, W, H))
}

fn srgb8(c: f64) -> u8 {
    let s = if c <= 0.0031308 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

/// Fraction of pixels farther than 8 levels (any channel) from the background colour.
fn covered_fraction(img: &OffscreenImage) -> f64 {
    let bg = [
        srgb8(BACKGROUND.r),
        srgb8(BACKGROUND.g),
        srgb8(BACKGROUND.b),
    ];
    let covered = img
        .rgba
        .chunks_exact(4)
        .filter(|p| (0..3).any(|k| (p[k] as i32 - bg[k] as i32).abs() > 8))
        .count();
    covered as f64 / (img.width * img.height) as f64
}

/// (fraction of pixels differing by more than 24 levels in some channel, mean absolute difference)
fn difference(a: &[u8], b: &[u8]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let mut differing = 0usize;
    let mut sum = 0u64;
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let d = (0..3)
            .map(|k| (p[k] as i32 - q[k] as i32).unsigned_abs())
            .max()
            .unwrap();
        sum += d as u64;
        if d > 24 {
            differing += 1;
        }
    }
    let n = (a.len() / 4) as f64;
    (differing as f64 / n, sum as f64 / n)
}

#[test]
fn torus_matches_reference_image() {
    let img = torus_image(|_| {});
    let actual = save(&img, "torus.png");
    let covered = covered_fraction(&img);
    assert!(
        covered > 0.05,
        "only {:.1}% of pixels are covered",
        covered * 100.0
    );

    let (want, reference) = reference_image("torus.png", &actual);
    let (differing, mean) = difference(&img.rgba, &want);
    assert!(
        differing < 0.005 && mean < 1.5,
        "render differs from reference ({}): {:.2}% pixels off, mean |d| {mean:.2}; adapter {}; see {}",
        reference.display(),
        differing * 100.0,
        img.adapter,
        actual.display()
    );
}

#[test]
fn orbiting_changes_the_picture() {
    let a = torus_image(|_| {});
    let b = torus_image(|c| c.orbit(0.6, -0.3));
    save(&b, "torus-orbited.png");
    let (differing, _) = difference(&a.rgba, &b.rgba);
    assert!(
        differing > 0.05,
        "orbit changed only {:.2}% of pixels",
        differing * 100.0
    );
}
