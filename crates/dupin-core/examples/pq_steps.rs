//! Step-by-step profile of a PQ perturbation: per step the phase, the contract
//! `max_planarity`, the largest vertex move of that step and its wall time; at the end the
//! thread CPU time of set-up and steps, iterations, factorisations, `max_move` and the
//! umbrella fairness energy (sum over interior vertices of |v - mean of its neighbours|²),
//! to compare solver changes by cost and by the mesh they produce. Run:
//! `cargo run --release -p dupin-core --example pq_steps -- [torus|skew|FILE.obj] [MODE]`
//! with MODE `planar` (default), `conical` or `circular` (`torus`: the benchmark's centroid
//! dual, 1152 hexagons; `skew`: the 30 x 30 skew grid). `RUNS=n` repeats the run (default 3;
//! the first pays the allocations' first touch); `PENALTY=n` sets the penalty iterations,
//! `REFINEMENT=sqp` the exact phase.

use dupin_core::Stepper;
use dupin_core::mesh::{MeshTopology, PolyMesh, parse_obj};

use dupin_core::conical::{PqMode, PqOptions, PqPerturbation, Refinement};

use dupin_core::scenes::benchmark_meshes::{skew_quad_grid, torus_centroid_dual};

/// CPU time of this thread in seconds (Linux `schedstat`, whose resolution can be a 4 ms tick
/// in a VM; 0 elsewhere).
fn cpu() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(0.0, |ns| ns * 1e-9)
}

/// Umbrella fairness energy of `mesh`, whose connectivity is `topo`'s.
fn fairness(mesh: &PolyMesh, topo: &MeshTopology) -> f64 {
    (0..mesh.num_vertices())
        .filter(|&v| !topo.is_boundary(v))
        .map(|v| {
            let nb = topo.neighbors(v);
            if nb.is_empty() {
                return 0.0;
            }
            let mean = nb
                .iter()
                .map(|&u| mesh.positions[u as usize])
                .sum::<dupin_core::Vec3>()
                / nb.len() as f64;
            (mesh.positions[v] - mean).norm_squared()
        })
        .sum()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let input = args.next().unwrap_or_else(|| "torus".into());
    let mode = match args.next().as_deref() {
        None | Some("planar") => PqMode::Planar,
        Some("conical") => PqMode::Conical,
        Some("circular") => PqMode::Circular,
        Some(other) => return Err(format!("unknown mode {other}").into()),
    };
    let mesh = match input.as_str() {
        "torus" => torus_centroid_dual(48, 24, 3.0, 1.0),
        "skew" => skew_quad_grid(30, 30.0),
        path => parse_obj(&std::fs::read_to_string(path)?)?,
    };
    let runs: usize = std::env::var("RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let mut options = PqOptions {
        mode,
        ..PqOptions::default()
    };
    if let Some(n) = std::env::var("PENALTY").ok().and_then(|v| v.parse().ok()) {
        options.penalty_iterations = n;
    }
    if std::env::var("REFINEMENT").is_ok_and(|v| v == "sqp") {
        options.refinement = Refinement::Sqp;
    }
    // The perturbation keeps the connectivity: one topology for every fairness figure.
    let topo = MeshTopology::new(&mesh)?;
    for run in 0..runs {
        eprintln!("run {run}: {input}, {mode:?}");
        // Only set-up and steps are timed, not this example's own per-step figures.
        let mut cpu_s = -cpu();
        let mut solver = PqPerturbation::new(&mesh, options.clone())?;
        cpu_s += cpu();
        while !solver.is_done() {
            let before = solver.mesh().positions.clone();
            let (start, wall) = (cpu(), std::time::Instant::now());
            let Ok(info) = solver.step();
            let ms = wall.elapsed().as_secs_f64() * 1e3;
            cpu_s += cpu() - start;
            let moved = before
                .iter()
                .zip(&solver.mesh().positions)
                .map(|(a, b)| (a - b).norm())
                .fold(0.0, f64::max);
            eprintln!(
                "  step {:2} -> {:?}: max_planarity {:.3e}, mode residual {:.3e}, move {:.3e}, fairness {:.6e}, {:.1} ms",
                info.iteration,
                info.phase,
                info.max_planarity,
                info.mode_residual,
                moved,
                fairness(solver.mesh(), &topo),
                ms
            );
        }
        let cpu_ms = cpu_s * 1e3;
        let Ok(r) = solver.finish();
        eprintln!(
            "  total {cpu_ms:.1} ms CPU: {} iterations, {} factorisations, converged {}, max_planarity {:.3e}, max_move {:.4}, fairness {:.6e}",
            r.iterations,
            r.factorizations,
            r.converged,
            r.max_planarity,
            r.max_move,
            fairness(&r.mesh, &topo)
        );
    }
    Ok(())
}
