//! Timing of quad-native PMVC against the triangulated cage on the shared artist
//! cages: `cargo test --release --lib coords::pmvc::timing -- --ignored --nocapture`.
//! `PMVC_RUNS` sets the runs per median (5); `PMVC_WHICH=quads`, `split` or `both`
//! times them (or one) one point after another on one thread.

use super::{pmvc_weights_inside, PmvcScratch};
use crate::coords::cubemap::TexelTable;
use crate::coords::{bind_cpu, BindOptions, BindProgress, Method};
use crate::geometry::{classify_points, load_cage, load_mesh, Cage, PointClass, QuadSplit};
use std::path::Path;
use std::time::Instant;

/// This thread's time on a CPU so far, in seconds: unlike the wall clock, it does
/// not count the time other processes on a busy machine take.
fn thread_time() -> f64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let nanoseconds: f64 = stat
        .split(' ')
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.0);
    nanoseconds * 1e-9
}

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

#[test]
#[ignore = "timing, run by hand"]
fn quad_native_timing_on_shared_models() {
    let folder = Path::new("/work/shared/data/qmvc");
    if !folder.is_dir() {
        println!("not run: {} is missing", folder.display());
        return;
    }
    let runs: usize = std::env::var("PMVC_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let which = std::env::var("PMVC_WHICH").unwrap_or_default();
    let every: usize = std::env::var("PMVC_EVERY")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let models = std::env::var("PMVC_MODELS").unwrap_or("Ogre,FireHydrant,ManHead".into());
    for model in models.split(',') {
        let (cage, _) = load_cage(&folder.join(format!("{model}_Cage.obj"))).expect("cage");
        let points = load_mesh(&folder.join(format!("{model}.obj")))
            .expect("mesh")
            .mesh
            .positions;
        let split = cage.split_quads(QuadSplit::Shorter);
        let classes = classify_points(&cage, &points).classes;
        let table = TexelTable::new(32);
        let inside: Vec<_> = points
            .iter()
            .zip(&classes)
            .filter(|(_, c)| matches!(c, PointClass::Inside))
            .map(|(&x, _)| x)
            .step_by(every)
            .collect();
        let per_point = |cage: &Cage| {
            let scratch = &mut PmvcScratch::default();
            let mut out = vec![0.0; cage.vertex_count()];
            let start = thread_time();
            for &x in &inside {
                pmvc_weights_inside(x, cage, &table, &mut out, scratch);
            }
            (thread_time() - start) * 1e6 / inside.len() as f64
        };
        if !which.is_empty() {
            let (mut quads, mut triangles, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
            for _ in 0..runs {
                let q = if which != "split" {
                    per_point(&cage)
                } else {
                    0.0
                };
                let t = if which != "quads" {
                    per_point(&split)
                } else {
                    0.0
                };
                quads.push(q);
                triangles.push(t);
                ratios.push(q / t);
            }
            let least = |times: &[f64]| times.iter().copied().fold(f64::INFINITY, f64::min);
            let (q, t) = (least(&quads), least(&triangles));
            println!(
                "{model}: one thread, us per inside point, medians of {runs}: quads {:.1}, split {:.1}, ratio {:.2}; least: {q:.1}, {t:.1}, ratio {:.2}",
                median(quads.clone()),
                median(triangles.clone()),
                median(ratios),
                q / t
            );
            continue;
        }
        let options = BindOptions {
            method: Method::Pmvc,
            resolution: 32,
            ..BindOptions::default()
        };
        let time = |cage| {
            let start = Instant::now();
            let progress = BindProgress::new(points.len());
            bind_cpu(&points, &classes, cage, options, &progress).expect("bind");
            start.elapsed().as_secs_f64()
        };
        let (mut quads, mut triangles) = (Vec::new(), Vec::new());
        for _ in 0..runs {
            quads.push(time(&cage));
            triangles.push(time(&split));
        }
        let (q, t) = (median(quads), median(triangles));
        println!(
            "{model}: {} points, {} quads, bind_cpu medians of {runs}: quads {q:.3} s, split {t:.3} s, ratio {:.2}",
            points.len(),
            cage.quads().len(),
            q / t
        );
    }
}
