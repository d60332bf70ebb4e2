//! The quadtree against a much finer one, before and after the projection.

use super::*;

/// A bent quad (one corner lifted) and its split along q0–q2.
fn bent() -> QuadFrame {
    let q = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(2.2, 1.8, 0.6),
        DVec3::new(-0.1, 2.0, 0.0),
    ];
    QuadFrame::new(q, [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
}

const FINE: Quadtree = Quadtree {
    eta: 0.1,
    tau: 1e-16,
};

fn largest_difference(a: &QuadIntegrals, b: &QuadIntegrals) -> f64 {
    a.phi
        .iter()
        .zip(&b.phi)
        .chain(a.psi.iter().zip(&b.psi))
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_quadtree_converges_at_every_height_above_the_patch() {
    let frame = bent();
    for height in [0.5, 1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8] {
        let (mut raw_worst, mut projected_worst) = (0.0f64, 0.0f64);
        let mut residual_worst = 0.0f64;
        for (u, v) in [(0.3, 0.4), (0.9, 0.95), (0.02, 0.5), (0.5, 0.0)] {
            let normal = frame.normal_at(u, v).normalize();
            // Below the patch: on its inner side.
            let x = frame.offset(DVec3::ZERO, u, v) - height * normal;
            let fine = frame.quadrature(x, &FINE);
            let raw = frame.quadrature(x, &QUADTREE);
            let projected = frame.integrals(x, &QUADTREE);
            raw_worst = raw_worst.max(largest_difference(&raw, &fine));
            // What the quadrature alone misses of the closed-form sums: its
            // share of the rest pose's error, over the quad's size.
            let (angle, moment) = frame.halves_closed_form(x);
            let sum: DVec3 = (0..4)
                .map(|k| raw.phi[k] * (frame.corners[k] - x) + raw.psi[k] * frame.corner_normals[k])
                .sum();
            // Between the patch and its triangles the solid angles differ by 4π.
            let turns = ((raw.solid_angle - angle) / (4.0 * PI)).round();
            residual_worst = residual_worst
                .max((sum - moment).length() / frame.size)
                .max((raw.solid_angle - angle - 4.0 * PI * turns).abs() / (4.0 * PI));
            projected_worst = projected_worst.max(largest_difference(&projected, &fine));
        }
        eprintln!(
            "height {height:.0e}: quadrature {raw_worst:.1e}, projected {projected_worst:.1e}, \
             quadrature's closed-form residual {residual_worst:.1e}"
        );
        assert!(residual_worst < 1e-9, "{height}: {residual_worst}");
        assert!(raw_worst < 1e-9, "{height}: {raw_worst}");
        assert!(projected_worst < 1e-9, "{height}: {projected_worst}");
    }
}
