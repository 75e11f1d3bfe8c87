//! One presentation frame of a 10 112-panel torus (glass, frames, ground, sun shadows) at
//! 960 x 640, offscreen on whatever adapter exists (lavapipe here), as CPU time of the whole
//! process (on a software rasteriser that is the GPU work): the frame as orbiting draws it
//! (shadow map cached), the frame with the sun's shadow pass redrawn (every frame before the
//! cache), the orbit frame without frames, without glass, or with the ground only (where the
//! time goes); and the wall time of the `render()` call alone (encoding and submitting).
//! Run: `cargo bench -p dupin-render --bench present_frame -- --quick`.

use criterion::{Criterion, criterion_group, criterion_main};
use dupin_core::mesh::{polymesh_buffers, polymesh_edges};
use dupin_core::scenes::benchmark_meshes::torus_quad_mesh;
use dupin_render::{FrameInstances, OrbitCamera, PresentationOffscreen, frame_instances};
use std::time::{Duration, Instant};

const SIZE: (u32, u32) = (960, 640);

type Group<'a> = criterion::BenchmarkGroup<'a, criterion::measurement::WallTime>;

fn bench(c: &mut Criterion) {
    // The page's 10k demo: a torus (R = 2, r = 0.7) of 128 x 79 quads.
    let m = torus_quad_mesh(128, 79, 2.0, 0.7);
    let (glass, _) = polymesh_buffers(&m, None);
    let edges = polymesh_edges(&m);
    let mean = edges
        .chunks_exact(6)
        .map(|s| ((s[3] - s[0]).powi(2) + (s[4] - s[1]).powi(2) + (s[5] - s[2]).powi(2)).sqrt())
        .sum::<f32>()
        / (edges.len() / 6) as f32;
    let frames = frame_instances(&edges, 0.06 * mean, 0.11 * mean);
    println!(
        "{} panels: {} glass triangles ({} vertices), {} beams + {} nodes = {} frame triangles",
        m.num_faces(),
        glass.triangle_count(),
        glass.vertex_count(),
        frames.beam_count(),
        frames.node_count(),
        frames.triangle_count()
    );
    let mut p = match PresentationOffscreen::new(&glass, &frames) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("no adapter, skipping: {e}");
            return;
        }
    };
    let mut cam = OrbitCamera::framing(glam::Vec3::ZERO, 2.8);
    let mut g = c.benchmark_group("present_frame_10k_cpu");
    g.sample_size(10);
    // Reported times are CPU time of the whole process (every lavapipe thread): the software
    // rasteriser's work, which wall time on this shared, loaded machine does not show.
    let frame = |g: &mut Group<'_>,
                 name: &str,
                 p: &mut PresentationOffscreen,
                 cam: &mut OrbitCamera,
                 redraw_shadows: bool| {
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let c0 = process_cpu();
                for _ in 0..iters {
                    cam.orbit(0.01, 0.0);
                    if redraw_shadows {
                        p.renderer().set_shadows(false);
                        p.renderer().set_shadows(true);
                    }
                    p.frame(cam, SIZE).unwrap();
                }
                process_cpu() - c0
            })
        });
    };
    frame(
        &mut g,
        "orbit frame (shadow map cached)",
        &mut p,
        &mut cam,
        false,
    );
    frame(&mut g, "frame with shadow pass", &mut p, &mut cam, true);
    g.bench_function("render() call only (CPU encode + submit, wall)", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                cam.orbit(0.01, 0.0);
                let t = Instant::now();
                p.submit_frame(&cam, SIZE);
                total += t.elapsed();
                p.wait().unwrap();
            }
            total
        })
    });
    // Where the orbit frame's time goes: the same frame without the frames, without the glass,
    // with neither (ground and clear only).
    p.set_scene(&glass, &FrameInstances::default()).unwrap();
    frame(
        &mut g,
        "orbit frame, glass and ground only",
        &mut p,
        &mut cam,
        false,
    );
    p.set_scene(&Default::default(), &frames).unwrap();
    frame(
        &mut g,
        "orbit frame, frames and ground only",
        &mut p,
        &mut cam,
        false,
    );
    p.set_scene(&Default::default(), &FrameInstances::default())
        .unwrap();
    frame(&mut g, "orbit frame, ground only", &mut p, &mut cam, false);
    g.finish();
}

/// CPU time of every thread of this process (Linux `schedstat`, nanoseconds), so the rasteriser
/// threads of a software Vulkan driver count.
fn process_cpu() -> Duration {
    let mut ns = 0u64;
    if let Ok(dir) = std::fs::read_dir("/proc/self/task") {
        for t in dir.flatten() {
            if let Ok(s) = std::fs::read_to_string(t.path().join("schedstat")) {
                ns += s
                    .split_whitespace()
                    .next()
                    .and_then(|x| x.parse().ok())
                    .unwrap_or(0);
            }
        }
    }
    Duration::from_nanos(ns)
}

criterion_group!(benches, bench);
criterion_main!(benches);
