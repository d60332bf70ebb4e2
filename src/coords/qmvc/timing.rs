//! Binding the Ogre (from the QMVC paper's data, not in the repository) with
//! MVC on its quads (QMVC) and on its quads split into triangles:
//! `PMVC_OGRE_DIR=/path/to/qmvc/data cargo test --release --lib
//! coords::qmvc::timing -- --ignored --nocapture`.

use super::quadrature::{integrate_counting, Rule, RULE};
use super::tests::max_difference;
use crate::coords::mvc::{closed_form_with, MvcScratch};
use crate::coords::{bind_cpu, BindOptions, BindProgress, Method};
use crate::geometry::{classify_points, load_cage, load_mesh, PointClass, QuadSplit};
use std::cell::Cell;
use std::path::PathBuf;
use std::time::Instant;

fn ogre_dir() -> PathBuf {
    std::env::var_os("PMVC_OGRE_DIR")
        .map_or_else(|| PathBuf::from("/work/shared/data/qmvc"), PathBuf::from)
}

#[test]
#[ignore = "needs the Ogre files; a timing, not a check"]
fn bind_the_ogre() {
    let dir = ogre_dir();
    let mesh = load_mesh(&dir.join("Ogre.obj")).expect("Ogre.obj").mesh;
    let (cage, _) = load_cage(&dir.join("Ogre_Cage.obj")).expect("Ogre_Cage.obj");
    let split = cage.split_quads(QuadSplit::Shorter);
    let points = &mesh.positions;
    println!(
        "Ogre: {} points, cage {} vertices, {} quads, {} lone triangles, {} threads",
        points.len(),
        cage.vertex_count(),
        cage.quads().len(),
        cage.lone_triangles().count(),
        rayon::current_num_threads()
    );
    let options = BindOptions::for_method(Method::Mvc);
    let mut medians = Vec::new();
    for (name, cage) in [("QMVC (quads)", &cage), ("MVC (split, shorter)", &split)] {
        let classes = classify_points(cage, points).classes;
        let mut seconds: Vec<f64> = (0..5)
            .map(|_| {
                let start = Instant::now();
                let progress = BindProgress::new(points.len());
                bind_cpu(points, &classes, cage, options, &progress).unwrap();
                start.elapsed().as_secs_f64()
            })
            .collect();
        seconds.sort_by(f64::total_cmp);
        println!("{name}: median {:.3} s of {seconds:.3?}", seconds[2]);
        medians.push(seconds[2]);
    }
    println!(
        "ratio QMVC / MVC on the split: {:.2}",
        medians[0] / medians[1]
    );

    // The quadrature on the Ogre's own points: evaluations and error.
    let classes = classify_points(&cage, points).classes;
    let converged = Rule {
        eta: 0.06,
        tau: 1e-16,
        order: Some(6),
    };
    let (samples, calls) = (Cell::new(0usize), Cell::new(0usize));
    let row = |rule: &Rule, x| {
        let mut out = vec![0.0; cage.vertex_count()];
        closed_form_with(
            x,
            &cage,
            &mut out,
            &mut MvcScratch::default(),
            |x, q, tol| {
                let (integral, count) = integrate_counting(x, q, tol, rule);
                samples.set(samples.get() + count);
                calls.set(calls.get() + 1);
                integral
            },
        );
        out
    };
    let inside: Vec<_> = (0..points.len())
        .step_by(25)
        .filter(|&i| classes[i] == PointClass::Inside)
        .map(|i| points[i])
        .collect();
    let references: Vec<Vec<f64>> = inside.iter().map(|&x| row(&converged, x)).collect();
    for rule in [
        RULE,
        Rule {
            eta: 0.5,
            tau: 1e-4,
            order: None,
        },
        Rule {
            eta: 0.5,
            tau: 1e-5,
            order: None,
        },
        Rule {
            eta: 0.6,
            tau: 1e-6,
            order: None,
        },
        Rule {
            eta: 0.7,
            tau: 1e-6,
            order: None,
        },
    ] {
        samples.set(0);
        calls.set(0);
        let worst = inside
            .iter()
            .zip(&references)
            .map(|(&x, reference)| max_difference(&row(&rule, x), reference))
            .fold(0.0, f64::max);
        println!(
            "{rule:?} on every 25th inside point: {:.1} evaluations per quad, largest weight error {worst:.2e}",
            samples.get() as f64 / calls.get() as f64
        );
    }

    // One thread: the quadrature against the closed-form part of the quad terms.
    let quads: Vec<[glam::DVec3; 4]> = (0..cage.quads().len()).map(|k| cage.quad(k)).collect();
    let tolerance = 1e-12 * cage.diagonal();
    let start = Instant::now();
    let mut sink = 0.0;
    for &x in &inside {
        for q in &quads {
            if let super::Integral::Value(v) = super::quadrature::integrate(x, q, tolerance, &RULE)
            {
                sink += v[0];
            }
        }
    }
    let quadrature = start.elapsed().as_secs_f64();
    let start = Instant::now();
    for &x in &inside {
        for q in &quads {
            let a = q.map(|p| p - x);
            let term = super::quad_term(
                x,
                q,
                a.map(glam::DVec3::length),
                a.map(glam::DVec3::normalize),
                super::Integral::Value([1.0, 2.0, 3.0, 4.0]),
            );
            if let super::QuadTerm::Weights(w) = term {
                sink += w[0];
            }
        }
    }
    let closed = start.elapsed().as_secs_f64();
    let pairs = (inside.len() * quads.len()) as f64;
    println!(
        "per point and quad: quadrature {:.0} ns, closed-form part {:.0} ns ({sink:.1})",
        quadrature / pairs * 1e9,
        closed / pairs * 1e9
    );
}
