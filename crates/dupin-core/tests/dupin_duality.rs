//! Propositions 1 and 2 of the P-Hex paper (sections 3 and 4.1) on real surfaces: as the star
//! size h halves five times, the tangent-dual hexagon approaches the Dupin-dual hexagon, and a
//! Dupin conic, at rate O(h^2) (fitted log-log slope in [1.8, 2.2]).

use dupin_core::surface::{Curvature, Hyperboloid, Surface, Torus};

use dupin_core::phex::{TriangleStar, tangent_dual_point};

use dupin_core::{Vec2, Vec3};

/// The surface point whose orthogonal projection onto the tangent plane of `c` has local
/// coordinates `target` (Newton on (u, v) from `uv0`).
fn lift(s: &dyn Surface, c: &Curvature, uv0: (f64, f64), target: &Vec2) -> (f64, f64) {
    let f = c.frame();
    let (mut u, mut v) = uv0;
    for _ in 0..50 {
        let d = s.derivatives(u, v);
        let r = f.to_local(&d.p) - target;
        if r.norm() < 1e-15 {
            break;
        }
        let (a, b) = (f.vector_to_local(&d.pu), f.vector_to_local(&d.pv));
        let det = a.x * b.y - a.y * b.x;
        u -= (b.y * r.x - b.x * r.y) / det;
        v -= (-a.y * r.x + a.x * r.y) / det;
    }
    (u, v)
}

/// For star size h: (max distance between tangent-dual and Dupin-dual hexagon vertices,
/// max distance of tangent-dual vertices to the Dupin conic of Proposition 3).
fn distances(s: &dyn Surface, uv: (f64, f64), a: Vec2, b: Vec2, h: f64) -> (f64, f64) {
    let c = s.curvature(uv.0, uv.1).unwrap();
    let f = c.frame();
    let ind = c.indicatrix().unwrap();
    let star = TriangleStar::new(Vec2::zeros(), a * h, b * h).unwrap();
    let hex = star.dupin_hexagon(&ind).unwrap();
    let ring: Vec<(Vec3, Vec3)> = star
        .ring()
        .iter()
        .map(|t| {
            let (u, v) = lift(s, &c, uv, t);
            let p = s.position(u, v);
            assert!((f.to_local(&p) - t).norm() < 1e-12 * (1.0 + h));
            (p, s.normal(u, v))
        })
        .collect();
    let (mut d2, mut d1) = (0.0f64, 0.0f64);
    for i in 0..6 {
        let j = (i + 1) % 6;
        let td = tangent_dual_point(
            [&c.point, &ring[i].0, &ring[j].0],
            [&c.normal, &ring[i].1, &ring[j].1],
        )
        .unwrap();
        // The tangent-dual vertex lies in the tangent plane at v_c.
        assert!(f.height(&td.point).abs() < 1e-9 * h);
        d2 = d2.max((td.point - f.to_world(&hex.vertices[i])).norm());
        d1 = d1.max(hex.conic.distance_estimate(&f.to_local(&td.point)));
    }
    (d2, d1)
}

/// Least-squares slope of log(d) against log(h).
fn slope(hs: &[f64], ds: &[f64]) -> f64 {
    let n = hs.len() as f64;
    let xs: Vec<f64> = hs.iter().map(|h| h.ln()).collect();
    let ys: Vec<f64> = ds.iter().map(|d| d.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    sxy / sxx
}

fn rates(name: &str, s: &dyn Surface, uv: (f64, f64), sign: f64) -> (f64, f64) {
    let k = s.curvature(uv.0, uv.1).unwrap().gaussian;
    assert_eq!(k.signum(), sign, "{name}: sign of K");
    let (a, b) = (Vec2::new(1.0, 0.15), Vec2::new(0.35, 1.0));
    let hs: Vec<f64> = (0..6).map(|k| 0.1 / 2f64.powi(k)).collect();
    let (mut d2, mut d1) = (Vec::new(), Vec::new());
    for &h in &hs {
        let (x, y) = distances(s, uv, a, b, h);
        d2.push(x);
        d1.push(y);
    }
    let (s2, s1) = (slope(&hs, &d2), slope(&hs, &d1));
    eprintln!(
        "{name}: K = {k:+.3}, Prop 2 slope {s2:.4} (d from {:.2e} to {:.2e}), Prop 1 slope {s1:.4} (d from {:.2e} to {:.2e})",
        d2[0], d2[5], d1[0], d1[5]
    );
    (s2, s1)
}

#[test]
fn propositions_1_and_2_rates_are_quadratic() {
    let torus = Torus {
        major: 2.0,
        minor: 0.7,
    };
    let hyp = Hyperboloid::new(1.0, 1.5, 1.5).unwrap();
    for (name, s, uv, sign) in [
        ("torus outer", &torus as &dyn Surface, (0.5, 0.4), 1.0),
        ("torus inner", &torus as &dyn Surface, (0.5, 2.6), -1.0),
        ("hyperboloid", &hyp as &dyn Surface, (0.3, 0.4), -1.0),
    ] {
        let (s2, s1) = rates(name, s, uv, sign);
        assert!(
            (1.8..=2.2).contains(&s2),
            "{name}: Proposition 2 slope {s2}"
        );
        assert!(
            (1.8..=2.2).contains(&s1),
            "{name}: Proposition 1 slope {s1}"
        );
    }
}
