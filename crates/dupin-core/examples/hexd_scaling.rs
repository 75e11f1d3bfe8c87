//! Scaling study for the hexagonal Delaunay triangulation: time and peak heap memory against
//! output triangles for 1k..64k uniform points, the fitted exponent, and spade's 30° refinement
//! on the same points. Run: `cargo run --release -p dupin-core --example hexd_scaling`
//! (simple mode) or `... --example hexd_scaling -- --extended` (extended mode).
//!
//! Environment: `HEXD_MIN` / `HEXD_MAX` bound the sizes; `HEXD_NO_SPADE` skips the peer;
//! `HEXD_HASH` prints a fingerprint of each output (triangles in order and vertex bits, to check
//! that a data-layout change changes nothing); `HEXD_DUMP=dir` writes the points for an outside
//! peer (e.g. Triangle); `HEXD_PHASES=n1,n2` prints the thread CPU time of refinement and dual
//! extraction at those sizes.

use dupin_core::hex_delaunay::{HexDelaunayMode, hex_delaunay};

use dupin_core::{Stepper, Vec2};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Counts live heap bytes and their peak.
struct Counting;
static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// CPU time of this thread in seconds (Linux `schedstat`), to separate our own work from the
/// machine's load; `None` elsewhere.
fn thread_cpu() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(s.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

fn uniform(n: usize, seed: u64) -> Vec<Vec2> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| Vec2::new(rng.random::<f64>(), rng.random::<f64>()))
        .collect()
}

fn spade_refine(points: &[Vec2]) -> (usize, f64) {
    use spade::{ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation};
    let start = Instant::now();
    let v: Vec<Point2<f64>> = points.iter().map(|p| Point2::new(p.x, p.y)).collect();
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::bulk_load_cdt(v, vec![])
        .expect("finite points");
    cdt.refine(RefinementParameters::default());
    (cdt.num_inner_faces(), start.elapsed().as_secs_f64())
}

/// FNV-1a over the triangles (in order) and the vertex coordinates' bits: equal fingerprints
/// mean the same triangulation, so a data-layout change can be checked to change nothing.
fn fingerprint(t: &dupin_core::hex_delaunay::HexTriangulation) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    let mut eat = |x: u64| {
        h ^= x;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    };
    for tri in &t.triangles {
        for &v in tri {
            eat(u64::from(v));
        }
    }
    for p in &t.vertices {
        eat(p.x.to_bits());
        eat(p.y.to_bits());
    }
    h
}

fn main() {
    let mode = if std::env::args().any(|a| a == "--extended") {
        HexDelaunayMode::Extended
    } else {
        HexDelaunayMode::Simple
    };
    println!("mode {mode:?}");
    // HEXD_MAX=N stops after N points.
    let max: usize = std::env::var("HEXD_MAX")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(64000);
    // HEXD_MIN=N skips the sizes below N.
    let min: usize = std::env::var("HEXD_MIN")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let sizes: Vec<usize> = [1000usize, 2000, 4000, 8000, 16000, 32000, 64000]
        .into_iter()
        .filter(|&n| n <= max && n >= min)
        .collect();
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    println!(
        "{:>7} {:>10} {:>9} {:>9} {:>10} {:>12} {:>9} | {:>10} {:>9}",
        "points",
        "triangles",
        "seconds",
        "cpu s",
        "ns/tri",
        "peak MB",
        "B/tri",
        "spade tri",
        "spade s"
    );
    for &n in &sizes {
        let pts = uniform(n, n as u64);
        if let Ok(dir) = std::env::var("HEXD_DUMP") {
            // The same points for an outside comparison (e.g. Triangle): one `x y` per line.
            let text: String = pts
                .iter()
                .map(|p| format!("{:?} {:?}\n", p.x, p.y))
                .collect();
            std::fs::write(format!("{dir}/uniform_{n}.txt"), text).expect("writable dump dir");
        }
        let mut hash = 0u64;
        let mut best = f64::INFINITY;
        let mut best_cpu = f64::INFINITY;
        let mut tris = 0;
        let mut peak = 0;
        let reps = match (mode, n <= 16000) {
            (HexDelaunayMode::Simple, true) => 7,
            (HexDelaunayMode::Simple, false) => 3,
            (HexDelaunayMode::Extended, _) => 1,
        };
        for _ in 0..reps {
            let base = LIVE.load(Ordering::Relaxed);
            PEAK.store(base, Ordering::Relaxed);
            let start = Instant::now();
            let cpu0 = thread_cpu();
            let t = hex_delaunay(&pts, &[], mode).expect("valid input");
            let s = start.elapsed().as_secs_f64();
            if let (Some(a), Some(b)) = (cpu0, thread_cpu()) {
                best_cpu = best_cpu.min(b - a);
            }
            peak = PEAK.load(Ordering::Relaxed) - base;
            best = best.min(s);
            tris = t.triangles.len();
            hash = fingerprint(&t);
        }
        if std::env::var("HEXD_HASH").is_ok() {
            println!("{n}: output fingerprint {hash:016x}");
        }
        if std::env::var("HEXD_NO_SPADE").is_ok() {
            xs.push((tris as f64).ln());
            ys.push((if best_cpu.is_finite() { best_cpu } else { best }).ln());
            println!(
                "{:>7} {:>10} {:>9.4} {:>9.4} {:>10.1} {:>12.1} {:>9.1}",
                n,
                tris,
                best,
                best_cpu,
                best_cpu.min(best) * 1e9 / tris as f64,
                peak as f64 / 1e6,
                peak as f64 / tris as f64
            );
            continue;
        }
        let (st, ss) = spade_refine(&pts);
        // Thread CPU time where available (the machine may be shared), else wall time.
        let fit_time = if best_cpu.is_finite() { best_cpu } else { best };
        println!(
            "{:>7} {:>10} {:>9.4} {:>9.4} {:>10.1} {:>12.1} {:>9.1} | {:>10} {:>9.4}",
            n,
            tris,
            best,
            best_cpu,
            fit_time * 1e9 / tris as f64,
            peak as f64 / 1e6,
            peak as f64 / tris as f64,
            st,
            ss
        );
        xs.push((tris as f64).ln());
        ys.push(fit_time.ln());
    }
    let m = xs.len() as f64;
    let (sx, sy) = (xs.iter().sum::<f64>() / m, ys.iter().sum::<f64>() / m);
    let slope = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - sx) * (y - sy))
        .sum::<f64>()
        / xs.iter().map(|x| (x - sx).powi(2)).sum::<f64>();
    // HEXD_PHASES=n1,n2,..: thread CPU time of refinement and of the dual (with the extended
    // relocations) at those sizes.
    if let Ok(list) = std::env::var("HEXD_PHASES") {
        for n in list.split(',').filter_map(|s| s.parse::<usize>().ok()) {
            let pts = uniform(n, n as u64);
            let t0 = thread_cpu().unwrap_or(0.0);
            let mut s = dupin_core::hex_delaunay::HexDelaunayStepper::new(&pts, &[], mode).unwrap();
            let t1 = thread_cpu().unwrap_or(0.0);
            s.run_to_end().unwrap();
            let t2 = thread_cpu().unwrap_or(0.0);
            let tri = s.triangulation();
            let t3 = thread_cpu().unwrap_or(0.0);
            println!(
                "{n}: CPU s: setup {:.4} refine {:.4} dual {:.4}; splits {} tris {}",
                t1 - t0,
                t2 - t1,
                t3 - t2,
                s.split_count(),
                tri.triangles.len()
            );
        }
    }
    if sizes.len() >= 2 {
        println!(
            "fitted exponent of (CPU) time against triangles ({}..{} points): {slope:.3}",
            sizes[0],
            sizes[sizes.len() - 1]
        );
    }
}
