//! `pmvc bench`: binding times on scenes of the paper's Table 1 sizes and on the
//! shared evaluation data. Reports medians over repeated runs, as markdown on
//! stdout and optionally as JSON.

use crate::coords::{bind_cpu, BindOptions, BindProgress, Method};
use crate::geometry::{self, classify_points, procedural, Cage};
use anyhow::Result;
use glam::DVec3;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Timed runs per row; the median is reported.
    #[arg(long, default_value_t = 3)]
    pub runs: usize,
    /// Also write the results as JSON.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Folder with X.obj / X_Cage.obj pairs (the shared evaluation data).
    #[arg(long, default_value = "../shared/data/qmvc")]
    pub data: PathBuf,
    /// Skip the shared evaluation data.
    #[arg(long)]
    pub no_data: bool,
}

/// One timed configuration.
#[derive(Clone, Debug, serde::Serialize)]
pub struct BenchRow {
    pub scene: String,
    pub mesh_vertices: usize,
    pub cage_vertices: usize,
    pub method: String,
    pub backend: String,
    pub median_seconds: f64,
    pub runs: Vec<f64>,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let threads = rayon::current_num_threads();
    eprintln!(
        "pmvc bench: CPU backend, {threads} rayon threads, {} runs per row",
        args.runs
    );
    let mut rows = Vec::new();
    for scene in procedural::table1_scenes() {
        rows.extend(bench_scene(
            scene.name,
            &scene.cage,
            &scene.points,
            args.runs,
        )?);
    }
    if !args.no_data {
        rows.extend(bench_shared_data(args)?);
    }
    println!("{}", markdown(&rows));
    if let Some(path) = &args.json {
        let json = to_json(&rows, threads);
        geometry::write_atomically(path, |out| out.write_all(json.as_bytes()))?;
    }
    Ok(())
}

fn bench_scene(name: &str, cage: &Cage, points: &[DVec3], runs: usize) -> Result<Vec<BenchRow>> {
    let classes = classify_points(cage, points);
    let configurations = [(Method::Mvc, 0), (Method::Pmvc, 32), (Method::Pmvc, 64)]
        .map(|(method, resolution)| BindOptions { method, resolution });
    let mut rows = Vec::new();
    for options in configurations {
        let mut times = Vec::with_capacity(runs);
        for _ in 0..runs.max(1) {
            let start = Instant::now();
            bind_cpu(
                points,
                &classes.classes,
                cage,
                options,
                &BindProgress::default(),
            )?;
            times.push(start.elapsed().as_secs_f64());
        }
        let label = match options.method {
            Method::Mvc => "MVC".to_owned(),
            Method::Pmvc => format!("PMVC {}²", options.resolution),
        };
        let row = BenchRow {
            scene: name.to_owned(),
            mesh_vertices: points.len(),
            cage_vertices: cage.vertex_count(),
            method: label,
            backend: "cpu".to_owned(),
            median_seconds: median(&times),
            runs: times,
        };
        eprintln!(
            "  {} {} {}: {:.3} s",
            row.scene, row.method, row.backend, row.median_seconds
        );
        rows.push(row);
    }
    Ok(rows)
}

fn bench_shared_data(args: &BenchArgs) -> Result<Vec<BenchRow>> {
    let Ok(entries) = std::fs::read_dir(&args.data) else {
        eprintln!(
            "pmvc bench: {} not found; shared-data rows not run",
            args.data.display()
        );
        return Ok(Vec::new());
    };
    let mut names: Vec<String> = entries
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter_map(|name| name.strip_suffix("_Cage.obj").map(str::to_owned))
        .collect();
    names.sort();
    let mut rows = Vec::new();
    for name in names {
        let mesh = geometry::load_mesh(&args.data.join(format!("{name}.obj")))?;
        let (cage, _) = geometry::load_cage(&args.data.join(format!("{name}_Cage.obj")))?;
        rows.extend(bench_scene(&name, &cage, &mesh.mesh.positions, args.runs)?);
    }
    Ok(rows)
}

fn median(times: &[f64]) -> f64 {
    let mut sorted = times.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        sorted[n / 2]
    } else {
        0.5 * (sorted[n / 2 - 1] + sorted[n / 2])
    }
}

pub fn markdown(rows: &[BenchRow]) -> String {
    let mut text = String::from("| scene | mesh vertices | cage vertices | method | backend | median (s) |\n|---|---:|---:|---|---|---:|\n");
    for row in rows {
        text.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.3} |\n",
            row.scene,
            row.mesh_vertices,
            row.cage_vertices,
            row.method,
            row.backend,
            row.median_seconds
        ));
    }
    text
}

#[derive(serde::Serialize)]
struct BenchReport<'a> {
    command: String,
    cpu_threads: usize,
    rows: &'a [BenchRow],
}

fn to_json(rows: &[BenchRow], threads: usize) -> String {
    let command = std::env::args().collect::<Vec<_>>().join(" ");
    let report = BenchReport {
        command,
        cpu_threads: threads,
        rows,
    };
    serde_json::to_string_pretty(&report).expect("bench rows serialise") + "\n"
}
