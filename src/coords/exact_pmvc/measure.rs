//! The cube map against the exact integral it discretises, and the figures of
//! the module doc: time and visible fragments per point, against the cube map
//! at 32² and 64² for the same points (ignored by default; run in release:
//! `cargo test --release --no-default-features --lib coords::exact_pmvc::measure
//! -- --ignored --nocapture --test-threads 1`).

use super::tests::{comb, exact};
use super::*;
use crate::coords::cubemap::TexelTable;
use crate::coords::pmvc::{pmvc_weights_inside, PmvcScratch};
use crate::geometry::{classify_points, procedural, PointClass, QuadSplit, TriMesh};
use std::path::Path;

/// Nanoseconds this thread has run on a CPU (Linux), so that other work on a
/// shared machine does not count; wall time elsewhere.
fn cpu_nanos() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| {
            static START: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
            START
                .get_or_init(std::time::Instant::now)
                .elapsed()
                .as_nanos() as f64
        })
}

fn cube_map(x: DVec3, cage: &Cage, table: &TexelTable, scratch: &mut PmvcScratch) -> Vec<f64> {
    let mut out = vec![0.0; cage.vertex_count()];
    assert!(pmvc_weights_inside(x, cage, table, &mut out, scratch));
    out
}

/// Largest and mean of the largest weight error per point of the cube map at
/// `resolution`, against the exact weights.
fn cube_map_error(
    cage: &Cage,
    points: &[DVec3],
    exact: &[Vec<f64>],
    resolution: u32,
) -> (f64, f64) {
    let table = TexelTable::new(resolution);
    let scratch = &mut PmvcScratch::default();
    let errors: Vec<f64> = points
        .iter()
        .zip(exact)
        .map(|(&x, reference)| {
            let w = cube_map(x, cage, &table, scratch);
            w.iter()
                .zip(reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
        })
        .collect();
    let largest = errors.iter().copied().fold(0.0, f64::max);
    (largest, errors.iter().sum::<f64>() / errors.len() as f64)
}

/// The cube map's error shrinks as its resolution grows: one ray per texel
/// misjudges the texels that a visibility boundary or a triangle's edge
/// crosses, about R of the 6R² per boundary, each off by its share 1/R², so
/// the error goes as 1/R (measured exponent in the module doc).
#[test]
fn cube_map_converges_to_exact() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 10, 29, 1e-2);
    let reference: Vec<Vec<f64>> = points.iter().map(|&x| exact(x, &cage)).collect();
    let errors: Vec<(u32, (f64, f64))> = [16, 32, 64, 128]
        .into_iter()
        .map(|r| (r, cube_map_error(&cage, &points, &reference, r)))
        .collect();
    for pair in errors.windows(2) {
        let ((r0, (_, mean0)), (r1, (_, mean1))) = (pair[0], pair[1]);
        let rate = (mean0 / mean1).log2();
        eprintln!("R {r0} → {r1}: mean error {mean0:.3e} → {mean1:.3e}, exponent {rate:.2}");
    }
    for pair in errors[1..].windows(2) {
        let ((r0, (largest0, mean0)), (r1, (largest1, mean1))) = (pair[0], pair[1]);
        assert!(mean1 < 0.8 * mean0, "R {r0} {mean0:e}, R {r1} {mean1:e}");
        assert!(
            largest1 < largest0,
            "R {r0} {largest0:e}, R {r1} {largest1:e}"
        );
    }
}

/// A cage of triangles from an OBJ file (its `v` and `f` lines), or the
/// vertices alone.
fn read_obj(path: &Path) -> Option<TriMesh> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut positions = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).filter_map(|w| w.parse().ok()).collect();
                positions.push(DVec3::new(c[0], c[1], c[2]));
            }
            Some("f") => faces.push(
                words
                    .filter_map(|w| w.split('/').next()?.parse::<u32>().ok())
                    .map(|k| k - 1)
                    .collect(),
            ),
            _ => {}
        }
    }
    Some(crate::geometry::triangulate_faces(&faces, &positions))
}

struct Figures {
    points: usize,
    refused: usize,
    exact_micros: f64,
    /// Per point: candidates, thin, scanned, cones overlapping, occluding,
    /// splits, fragments; and the most fragments at one point.
    mean: [f64; 10],
    fragments_max: usize,
    cube_micros: [f64; 2],
    cube_error: [f64; 2],
    /// Per point: quads seen whole, quads seen folded, rays cast on patches,
    /// quadrature triangles left above tolerance, rays that missed.
    quads: [f64; 5],
    /// Points that saw at least one quad folded.
    points_folded: usize,
    /// Largest `|Σ wᵢ vᵢ − x|` over the cage diagonal.
    linear: f64,
}

fn measure(cage: &Cage, points: &[DVec3]) -> Figures {
    let n = cage.vertex_count();
    let scratch = &mut ExactPmvcScratch::default();
    let mut exact_weights = vec![vec![0.0; n]; points.len()];
    let mut stats = Vec::with_capacity(points.len());
    let mut kept = Vec::with_capacity(points.len());
    let start = cpu_nanos();
    for (&x, out) in points.iter().zip(&mut exact_weights) {
        kept.push(exact_pmvc_weights_inside(x, cage, out, scratch).is_ok());
        stats.push(scratch.stats());
    }
    let exact_micros = (cpu_nanos() - start) * 1e-3 / points.len() as f64;
    let mut cube_micros = [0.0; 2];
    let mut cube_error = [0.0; 2];
    for (k, resolution) in [32, 64].into_iter().enumerate() {
        let table = TexelTable::new(resolution);
        let scratch = &mut PmvcScratch::default();
        let mut out = vec![0.0; n];
        let mut error: f64 = 0.0;
        let start = cpu_nanos();
        for ((&x, reference), &kept) in points.iter().zip(&exact_weights).zip(&kept) {
            if pmvc_weights_inside(x, cage, &table, &mut out, scratch) && kept {
                let e = out.iter().zip(reference).map(|(a, b)| (a - b).abs());
                error = error.max(e.fold(0.0, f64::max));
            }
        }
        cube_micros[k] = (cpu_nanos() - start) * 1e-3 / points.len() as f64;
        cube_error[k] = error;
    }
    let mut mean = [0.0; 10];
    let mut quads = [0.0; 5];
    for s in &stats {
        let values = [s.quads, s.folded, s.nodes, s.unresolved, s.missed];
        for (sum, value) in quads.iter_mut().zip(values) {
            *sum += value as f64 / stats.len() as f64;
        }
    }
    let linear = points
        .iter()
        .zip(&exact_weights)
        .zip(&kept)
        .filter(|(_, &kept)| kept)
        .map(|((&x, w), _)| {
            let p: DVec3 = w
                .iter()
                .zip(cage.positions())
                .map(|(&w, &v)| w * (v - x))
                .sum();
            p.length() / cage.diagonal()
        })
        .fold(0.0, f64::max);
    for s in &stats {
        let values = [
            s.candidates,
            s.thin,
            s.scanned,
            s.cones_overlapping,
            s.behind,
            s.separated,
            s.probed,
            s.occluding,
            s.splits,
            s.fragments,
        ];
        for (sum, value) in mean.iter_mut().zip(values) {
            *sum += value as f64 / stats.len() as f64;
        }
    }
    Figures {
        points: points.len(),
        refused: kept.iter().filter(|&&k| !k).count(),
        exact_micros,
        mean,
        fragments_max: stats.iter().map(|s| s.fragments).max().unwrap_or(0),
        cube_micros,
        cube_error,
        quads,
        points_folded: stats.iter().filter(|s| s.folded > 0).count(),
        linear,
    }
}

fn report(name: &str, cage: &Cage, f: &Figures) {
    let [candidates, thin, scanned, cones, behind, separated, probed, occluding, splits, fragments] =
        f.mean;
    println!(
        "{name}: {} triangles, {} points ({} refused): exact {:.1} µs/point, \
         {fragments:.1} fragments/point (max {}); cube map 32² {:.1} µs/point (largest \
         weight error {:.1e}), 64² {:.1} µs/point ({:.1e})\n  per point: {candidates:.1} \
         candidates ({thin:.2} thin), {scanned:.0} pairs scanned, {cones:.0} with cones \
         overlapping ({behind:.0} behind, {separated:.0} separated, {probed:.0} probed), \
         {occluding:.0} occluding, {splits:.0} splits",
        cage.triangle_count(),
        f.points,
        f.refused,
        f.exact_micros,
        f.fragments_max,
        f.cube_micros[0],
        f.cube_error[0],
        f.cube_micros[1],
        f.cube_error[1],
    );
    if cage.has_quads() {
        let [quads, folded, nodes, unresolved, missed] = f.quads;
        println!(
            "  {} quads as patches: per point {quads:.1} seen whole, {folded:.2} folded \
             ({} points saw a fold), {nodes:.0} rays cast by the quadrature ({unresolved:.2} \
             triangles above tolerance, {missed:.2} rays missed); largest |Σ wᵢ vᵢ − x| / \
             diagonal {:.1e}",
            cage.quads().len(),
            f.points_folded,
            f.linear,
        );
    }
}

#[test]
#[ignore = "a measurement: run in release with --ignored --nocapture"]
fn speed_and_fragments() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 2000, 31, 1e-4);
    report("comb", &cage, &measure(&cage, &points));
    // Larger cages, for how the pairs of candidates scale.
    let hand = procedural::table1_scene("hand-size").expect("a scene");
    let points: Vec<DVec3> = hand.points.iter().step_by(25).copied().collect();
    report("hand-size", &hand.cage, &measure(&hand.cage, &points));
    let sphere = procedural::icosphere(1.0, 3);
    let points = procedural::points_inside(&sphere, 500, 41, 1e-3);
    report("icosphere", &sphere, &measure(&sphere, &points));
    for (model, patches, inside) in shared_models() {
        let cage = patches.split_quads(QuadSplit::Shorter);
        report(&model, &cage, &measure(&cage, &inside));
    }
}

/// The artist cages of `../shared/data/qmvc` (read at test time, never
/// copied), each with about 2000 of its mesh's vertices inside its split
/// cage; "not run" when they are missing.
fn shared_models() -> Vec<(String, Cage, Vec<DVec3>)> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/qmvc");
    if !data.is_dir() {
        println!("not run: {} is not present", data.display());
        return Vec::new();
    }
    let mut models = Vec::new();
    for model in ["Beast", "Ogre", "FireHydrant", "ManHead", "Bench"] {
        let (Some(cage_mesh), Some(mesh)) = (
            read_obj(&data.join(format!("{model}_Cage.obj"))),
            read_obj(&data.join(format!("{model}.obj"))),
        ) else {
            println!("not run: {model} is not readable");
            continue;
        };
        let (patches, _) = Cage::new(cage_mesh).expect("a valid cage");
        let cage = patches.split_quads(QuadSplit::Shorter);
        let step = (mesh.positions.len() / 2000).max(1);
        let sample: Vec<DVec3> = mesh.positions.iter().step_by(step).copied().collect();
        let classes = classify_points(&cage, &sample).classes;
        let inside: Vec<DVec3> = sample
            .iter()
            .zip(&classes)
            .filter(|(_, class)| matches!(class, PointClass::Inside))
            .map(|(&x, _)| x)
            .collect();
        models.push((model.to_owned(), patches, inside));
    }
    models
}

/// Exact PMVC on the artist cages' quads as bilinear patches, beside the
/// same points on the split cages: time, pieces, folds and the quadrature's
/// rays per point (the figures of docs/coordinates.md).
#[test]
#[ignore = "a measurement: run in release with --ignored --nocapture"]
fn quads_as_patches() {
    let comb = crate::geometry::procedural_quads::quad_comb(3, 1.0, 0.5, 2.0, 1.0, 0.3);
    let points = procedural::points_inside(&comb, 500, 43, 1e-3);
    report("bent quad comb", &comb, &measure(&comb, &points));
    // PMVC_MEASURE_STEP=k measures every k-th point only.
    let step = std::env::var("PMVC_MEASURE_STEP")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    for (model, patches, inside) in shared_models() {
        let inside: Vec<DVec3> = inside.into_iter().step_by(step).collect();
        let cage = patches.split_quads(QuadSplit::Shorter);
        report(&format!("{model} (split)"), &cage, &measure(&cage, &inside));
        // The same points that are inside the patches too.
        let classes = classify_points(&patches, &inside).classes;
        let inside: Vec<DVec3> = inside
            .iter()
            .zip(&classes)
            .filter(|(_, class)| matches!(class, PointClass::Inside))
            .map(|(&x, _)| x)
            .collect();
        report(
            &format!("{model} (patches)"),
            &patches,
            &measure(&patches, &inside),
        );
    }
}

/// The convergence figure of the module doc, with more points and one more
/// resolution than [`cube_map_converges_to_exact`].
#[test]
#[ignore = "a measurement: run in release with --ignored --nocapture"]
fn cube_map_convergence_rate() {
    let cage = comb();
    let points = procedural::points_inside(&cage, 200, 37, 1e-2);
    let reference: Vec<Vec<f64>> = points.iter().map(|&x| exact(x, &cage)).collect();
    let mut previous: Option<(u32, f64, f64)> = None;
    for r in [16, 32, 64, 128, 256] {
        let (largest, mean) = cube_map_error(&cage, &points, &reference, r);
        print!("R {r}: largest {largest:.3e}, mean {mean:.3e}");
        if let Some((_, previous_largest, previous_mean)) = previous {
            let exponents = (
                (previous_largest / largest).log2(),
                (previous_mean / mean).log2(),
            );
            print!(
                ", exponents {:.2} (largest) {:.2} (mean)",
                exponents.0, exponents.1
            );
        }
        println!();
        previous = Some((r, largest, mean));
    }
}

/// Where the closed form's rounding shows on thin triangles, against a fine
/// quadrature: the figure behind [`THIN`]. Candidates of points in and near
/// the comb's faces, by the ratio `det / perimeter²`; the error of their
/// weights relative to the total weight at the point.
#[test]
#[ignore = "a measurement: run with --ignored --nocapture"]
fn thin_threshold() {
    use super::polygon::{mean_vector, mean_vector_by_quadrature_with};
    let cage = comb();
    let scratch = &mut ExactPmvcScratch::default();
    let mut points = procedural::points_inside(&cage, 300, 31, 1e-4);
    for k in 1..12 {
        let delta = 10f64.powi(-k);
        points.push(DVec3::new(0.5, 1.0 - delta, 0.1));
        points.push(DVec3::new(2.75, 1.0 - 3.0 * delta, -0.2));
    }
    let mut rows = Vec::new();
    for &x in &points {
        set_up(x, &cage, scratch).unwrap();
        let total =
            4.0 * PI * scratch.distances.len() as f64 / scratch.distances.iter().sum::<f64>();
        for t in 0..scratch.candidates.len() {
            let c = scratch.candidates[t];
            let [a, b, d, _] = c.directions;
            let perimeter = (a - b).length() + (b - d).length() + (d - a).length();
            let ratio = a.dot(b.cross(d)) / (perimeter * perimeter);
            visible_pieces(t, scratch);
            let mut error: f64 = 0.0;
            for piece in scratch.pieces.iter() {
                let (closed, _) = mean_vector(piece);
                let quadrature = mean_vector_by_quadrature_with(piece, 0.1);
                for normal in c.weight_normals {
                    error = error.max((normal.dot(closed) - normal.dot(quadrature)).abs());
                }
            }
            rows.push((ratio, error / total));
        }
    }
    for decade in -13..0 {
        let (low, high) = (10f64.powi(decade), 10f64.powi(decade + 1));
        let within: Vec<f64> = rows
            .iter()
            .filter(|(r, _)| (low..high).contains(r))
            .map(|&(_, e)| e)
            .collect();
        let worst = within.iter().copied().fold(0.0, f64::max);
        println!(
            "ratio in [{low:.0e}, {high:.0e}): {} candidates, largest difference {worst:.1e}",
            within.len()
        );
    }
}

/// Where the time goes on the armadillo-size scene of `pmvc bench` (every
/// fifth of its points): setting up the candidates, finding the visible
/// pieces, and integrating them, each timed by difference on the same points.
#[test]
#[ignore = "a measurement: run in release with --ignored --nocapture"]
fn armadillo_size_phases() {
    let scene = procedural::table1_scene("armadillo-size").expect("a scene");
    let cage = &scene.cage;
    let points: Vec<DVec3> = scene.points.iter().step_by(5).copied().collect();
    let scratch = &mut ExactPmvcScratch::default();
    let per_point = |start: f64| (cpu_nanos() - start) * 1e-3 / points.len() as f64;
    let start = cpu_nanos();
    for &x in &points {
        set_up(x, cage, scratch).expect("inside");
    }
    let set_up_micros = per_point(start);
    let start = cpu_nanos();
    for &x in &points {
        set_up(x, cage, scratch).expect("inside");
        for t in 0..scratch.candidates.len() {
            visible_pieces(t, scratch);
        }
    }
    let visibility_micros = per_point(start) - set_up_micros;
    let mut out = vec![0.0; cage.vertex_count()];
    let start = cpu_nanos();
    for &x in &points {
        exact_pmvc_weights_inside(x, cage, &mut out, scratch).expect("inside");
    }
    let total_micros = per_point(start);
    println!(
        "armadillo-size phases, {} points: total {total_micros:.1} µs/point: set-up \
         {set_up_micros:.1}, visibility {visibility_micros:.1}, integration {:.1}",
        points.len(),
        total_micros - set_up_micros - visibility_micros
    );
    report("armadillo-size", cage, &measure(cage, &points));
}
