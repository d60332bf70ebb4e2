//! The cost of a family solved per point (MEC, MLC), as docs/coordinates.md
//! quotes it: time a point on one thread and Newton iterations, on each cage.

use glam::DVec3;
use pmvc::geometry::{procedural, Cage};

/// Solve 2,000 points inside each of `scenes` with `solve` (which writes the
/// weights and returns its iterations) and print the figures; a failed solve
/// panics with the point and its distance to the surface.
pub fn print_solver_cost<E: std::fmt::Display>(
    scenes: Vec<(&'static str, Cage)>,
    mut solve: impl FnMut(DVec3, &Cage, &mut [f64]) -> Result<u32, E>,
) {
    for (name, cage) in scenes {
        let points = procedural::points_inside(&cage, 2000, 21, 1e-3);
        let mut out = vec![0.0; cage.vertex_count()];
        let (mut most, mut total) = (0, 0);
        let start = std::time::Instant::now();
        for &x in &points {
            let iterations = solve(x, &cage, &mut out).unwrap_or_else(|e| {
                panic!(
                    "{name} {x}: {e}, distance {}",
                    procedural::distance_to_surface(&cage, x)
                )
            });
            most = most.max(iterations);
            total += iterations;
        }
        let micros = start.elapsed().as_secs_f64() * 1e6 / points.len() as f64;
        println!(
            "{name} ({} vertices, {} faces): {micros:.1} µs a point on one thread, Newton iterations mean {:.1}, most {most}",
            cage.vertex_count(),
            cage.polygons().len(),
            total as f64 / points.len() as f64
        );
    }
}
