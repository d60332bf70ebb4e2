//! `pmvc bench`: binding times on scenes of the paper's Table 1 and Table 2 sizes
//! and on the shared evaluation data, on the CPU and on a GPU adapter. Reports medians over repeated runs, as markdown on
//! stdout and optionally as JSON.

use crate::coords::{BindOptions, BindProgress, Method, QuadSplit, QuadSupport, EXACT_RESOLUTION};
use crate::formats::shown_path;
use crate::geometry::{procedural, Cage, PointClass};
use crate::gpu::{Backend, BindConfig, BindInput, Binder, GpuContext, PmvcKernel};
use anyhow::{bail, Result};
use glam::DVec3;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    /// Timed runs per row (1–1000); the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u16).range(1..=1000))]
    pub runs: u16,
    /// Also write the results as JSON.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Folder with X.obj / X_Cage.obj pairs (the shared evaluation data).
    #[arg(long, default_value = "../shared/data/qmvc")]
    pub data: PathBuf,
    /// Skip the shared evaluation data.
    #[arg(long)]
    pub no_data: bool,
    /// Only these scenes (Table 1 names, "table2", or shared-data model names);
    /// an unknown name is an error that lists the known ones.
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Also time a software GPU adapter (lavapipe/llvmpipe); by default GPU rows
    /// are run only on a hardware adapter.
    #[arg(long)]
    pub software_gpu: bool,
    /// PMVC kernels to time on the GPU, each as its own rows: auto (the tile
    /// kernel where the cage allows it), tiles, bands.
    #[arg(long, value_delimiter = ',', default_value = "auto", value_parser = PmvcKernel::parse)]
    pub pmvc_kernels: Vec<PmvcKernel>,
    /// Only these families (e.g. `pmvc,mvc`); all by default, except that on the
    /// shared models LBC and Somigliana coordinates (minutes per bind there)
    /// are timed only when named.
    #[arg(long, value_enum, value_delimiter = ',')]
    pub methods: Vec<Method>,
    /// Instead of timings, PMVC's cube-map error against exact PMVC at
    /// resolutions 8 to 128, on the bundled comb ("comb" in --scenes) and the
    /// shared models: weights and deformation, beside MVC's difference.
    #[arg(long)]
    pub exact_error: bool,
}

/// The `--scenes` name of the paper's Table 2 rows.
const TABLE2: &str = "table2";

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
    /// GPU rows: the median time waiting for the kernels (their share of the run),
    /// and the last run's batches and rows redone on the CPU.
    pub gpu_wait_seconds: Option<f64>,
    pub batches: usize,
    pub cpu_rows: usize,
    /// The paper's time for this scene size and method (its 2007 GPU for MVC and
    /// PMVC, its CPU solver for HC), for scale.
    pub paper_seconds: Option<f64>,
}

/// The paper's Table 1: (scene, method, parameter, seconds).
const PAPER_TABLE1: [(&str, Method, u32, f64); 21] = [
    ("armadillo-size", Method::Mvc, 0, 3.70),
    ("armadillo-size", Method::Pmvc, 32, 3.03),
    ("armadillo-size", Method::Pmvc, 64, 9.82),
    ("armadillo-size", Method::Harmonic, 64, 66.48),
    ("armadillo-size", Method::Harmonic, 128, 770.00),
    ("horse-size", Method::Mvc, 0, 5.92),
    ("horse-size", Method::Pmvc, 32, 8.75),
    ("horse-size", Method::Pmvc, 64, 30.64),
    ("horse-size", Method::Harmonic, 64, 28.61),
    ("horse-size", Method::Harmonic, 128, 305.93),
    ("hand-size", Method::Mvc, 0, 13.50),
    ("hand-size", Method::Pmvc, 32, 6.64),
    ("hand-size", Method::Pmvc, 64, 18.50),
    ("hand-size", Method::Harmonic, 64, 333.61),
    ("hand-size", Method::Harmonic, 128, 4413.66),
    // Table 2 (PMVC 32², by cage vertices) is matched by its own rows' label.
    ("sphere 51 (Table 2)", Method::Pmvc, 32, 16.07),
    ("sphere 102 (Table 2)", Method::Pmvc, 32, 16.32),
    ("sphere 198 (Table 2)", Method::Pmvc, 32, 16.73),
    ("sphere 402 (Table 2)", Method::Pmvc, 32, 17.44),
    ("sphere 843 (Table 2)", Method::Pmvc, 32, 18.70),
    ("sphere 1523 (Table 2)", Method::Pmvc, 32, 20.41),
];

fn paper_seconds(scene: &str, method: Method, parameter: u32) -> Option<f64> {
    let scene = scene.strip_suffix(" (Table 1)").unwrap_or(scene);
    PAPER_TABLE1
        .iter()
        .find(|(name, m, p, _)| {
            *name == scene && *m == method && (method.spec().parameter.is_none() || *p == parameter)
        })
        .map(|entry| entry.3)
}

/// A backend to time, with the name its rows carry.
struct Timed {
    name: String,
    backend: Backend,
    /// On a GPU, the PMVC kernel; other families' rows are timed with the first.
    pmvc_kernel: Option<PmvcKernel>,
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let shared = shared_models(args);
    check_scenes(&args.scenes, &shared, args)?;
    if args.exact_error {
        return run_exact_error(args, &shared);
    }
    // Opened before the work, so that an output that cannot be written is
    // reported now, not after the whole benchmark.
    let json_output = match &args.json {
        Some(path) => {
            if let Some(warning) = crate::formats::extension_warning(path, &["json"], "JSON") {
                warn_line!("pmvc: {warning}");
            }
            Some(crate::formats::PendingOutput::create(path)?)
        }
        None => None,
    };
    let threads = rayon::current_num_threads();
    let plural = if threads == 1 { "" } else { "s" };
    let mut backends = vec![Timed {
        name: format!("cpu ({threads} thread{plural})"),
        backend: Backend::Cpu,
        pmvc_kernel: None,
    }];
    let adapter = match GpuContext::new() {
        Ok(context) if !context.is_software() || args.software_gpu => {
            let name = context.describe();
            let context = Arc::new(context);
            let mut kernels: Vec<PmvcKernel> = Vec::new();
            for &kernel in &args.pmvc_kernels {
                if !kernels.contains(&kernel) {
                    kernels.push(kernel);
                }
            }
            for &kernel in &kernels {
                backends.push(Timed {
                    name: if kernels.len() > 1 {
                        format!("{name} [{}]", kernel.name())
                    } else {
                        name.clone()
                    },
                    backend: Backend::Gpu(Arc::clone(&context)),
                    pmvc_kernel: Some(kernel),
                });
            }
            name
        }
        Ok(context) => format!(
            "{} (software; GPU rows skipped, see --software-gpu)",
            context.describe()
        ),
        Err(error) => format!("none ({error})"),
    };
    warn_line!(
        "pmvc bench: {threads} CPU thread{plural} (RAYON_NUM_THREADS sets them), GPU adapter: {adapter}, {} run{} per row",
        args.runs,
        if args.runs == 1 { "" } else { "s" }
    );
    let wanted = |name: &str| args.scenes.is_empty() || args.scenes.iter().any(|s| s == name);

    let mut rows = Vec::new();
    let table1 = [
        (Method::Mvc, 0),
        (Method::Pmvc, 32),
        (Method::Pmvc, 64),
        (Method::Pmvc, EXACT_RESOLUTION),
        (Method::Mec, 0),
        (Method::Mlc, 0),
        (Method::Harmonic, 64),
        (Method::Harmonic, 128),
        (Method::Bbw, crate::coords::bbw::DEFAULT_GRID),
        (Method::Lbc, crate::coords::lbc::DEFAULT_GRID),
    ];
    for name in procedural::table1_scene_names() {
        if let Some(scene) = procedural::table1_scene(name).filter(|_| wanted(name)) {
            let label = format!("{name} (Table 1)");
            rows.extend(bench_scene(
                &label,
                &scene.cage,
                &scene.points,
                &table1,
                &backends,
                usize::from(args.runs),
                &args.methods,
            )?);
        }
    }
    if wanted(TABLE2) {
        // The paper's Table 2: one 24,795-vertex point set in ever finer spherical cages.
        let finest = procedural::uv_sphere(1.0, 40, 39);
        let points = procedural::points_inside(&finest, 24_795, 2, 1e-3);
        for (rings, segments) in [(8, 7), (11, 10), (15, 14), (21, 20), (30, 29), (40, 39)] {
            let cage = procedural::uv_sphere(1.0, rings, segments);
            let label = format!("sphere {} (Table 2)", cage.vertex_count());
            rows.extend(bench_scene(
                &label,
                &cage,
                &points,
                &[(Method::Pmvc, 32)],
                &backends,
                usize::from(args.runs),
                &args.methods,
            )?);
        }
    }
    let shared: Vec<String> = shared.into_iter().filter(|name| wanted(name)).collect();
    rows.extend(bench_shared_data(args, &shared, &backends)?);
    say!("{}", markdown(&rows));
    if let Some(output) = json_output {
        let json = to_json(&rows, threads, &adapter);
        output.finish(|out| out.write_all(json.as_bytes()))?;
    }
    Ok(())
}

/// `--exact-error`: the table of [`super::bench_exact`], as markdown.
fn run_exact_error(args: &BenchArgs, shared: &[String]) -> Result<()> {
    let wanted = |name: &str| args.scenes.is_empty() || args.scenes.iter().any(|s| s == name);
    let mut scenes = Vec::new();
    if wanted(BUNDLED_COMB) {
        scenes.push(super::bench_exact::comb_scene());
    }
    for name in shared.iter().filter(|name| wanted(name)) {
        scenes.push(super::bench_exact::shared_scene(&args.data, name)?);
    }
    let mut rows = Vec::new();
    for scene in &scenes {
        let start = Instant::now();
        rows.extend(super::bench_exact::measure(scene)?);
        warn_line!("  {}: {:.1} s", scene.name, start.elapsed().as_secs_f64());
    }
    say!("{}", super::bench_exact::markdown(&rows));
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&rows)?;
        crate::formats::PendingOutput::create(path)?
            .finish(|out| out.write_all(json.as_bytes()))?;
    }
    Ok(())
}

/// The `--scenes` name of the bundled comb (`--exact-error` only).
const BUNDLED_COMB: &str = "comb";

/// The shared-data models in `--data` (X.obj beside X_Cage.obj), sorted; none
/// with `--no-data` or when the folder cannot be read.
fn shared_models(args: &BenchArgs) -> Vec<String> {
    if args.no_data {
        return Vec::new();
    }
    let Ok(entries) = std::fs::read_dir(&args.data) else {
        warn_line!(
            "pmvc bench: {} not found; shared-data rows not run",
            shown_path(&args.data)
        );
        return Vec::new();
    };
    let mut names: Vec<String> = entries
        .filter_map(|entry| entry.ok()?.file_name().into_string().ok())
        .filter_map(|name| name.strip_suffix("_Cage.obj").map(str::to_owned))
        .collect();
    names.sort();
    names
}

/// `--scenes`: every name must be a scene this run knows, or nothing would be
/// timed for it.
fn check_scenes(scenes: &[String], shared: &[String], args: &BenchArgs) -> Result<()> {
    let mut known: Vec<&str> = procedural::table1_scene_names().to_vec();
    known.push(if args.exact_error {
        BUNDLED_COMB
    } else {
        TABLE2
    });
    let unknown: Vec<&str> = scenes
        .iter()
        .map(String::as_str)
        .filter(|name| !known.contains(name) && !shared.iter().any(|s| s == name))
        .collect();
    if unknown.is_empty() {
        return Ok(());
    }
    let data = if args.no_data {
        "shared-data models are skipped with --no-data".to_owned()
    } else if shared.is_empty() {
        format!("no shared-data models in {}", shown_path(&args.data))
    } else {
        format!("from {}: {}", shown_path(&args.data), shared.join(", "))
    };
    bail!(
        "--scenes: unknown scene {}; the scenes are {} ({data})",
        unknown.join(", "),
        known.join(", ")
    )
}

fn bench_scene(
    name: &str,
    cage: &Cage,
    points: &[DVec3],
    configurations: &[(Method, u32)],
    backends: &[Timed],
    runs: usize,
    only: &[Method],
) -> Result<Vec<BenchRow>> {
    let as_patches: Vec<_> = configurations
        .iter()
        .map(|&(method, value)| (method, value, QuadSplit::None))
        .collect();
    bench_scene_split(name, cage, points, &as_patches, backends, runs, only)
}

/// [`bench_scene`] with each configuration's quads bound as patches or split.
fn bench_scene_split(
    name: &str,
    cage: &Cage,
    points: &[DVec3],
    configurations: &[(Method, u32, QuadSplit)],
    backends: &[Timed],
    runs: usize,
    only: &[Method],
) -> Result<Vec<BenchRow>> {
    // Classified once per way the quads are bound, against that cage
    // ([`BindOptions::classify`]), outside the timings.
    let mut classified: Vec<(Option<QuadSplit>, Arc<[PointClass]>)> = Vec::new();
    let mut rows = Vec::new();
    // Families without a choice of kernel are timed once per GPU, with its first.
    let first_kernel = backends.iter().find_map(|timed| timed.pmvc_kernel);
    for timed in backends {
        for &(method, resolution, quads) in configurations {
            if !only.is_empty() && !only.contains(&method) {
                continue;
            }
            // A family without a GPU kernel binds on the CPU on every backend: its
            // CPU row says all there is.
            let mut options = BindOptions {
                quads,
                ..BindOptions::for_method(method)
            };
            if let Some(parameter) = method.spec().parameter {
                options.set(parameter.key, resolution);
            }
            // MVC on quads is QMVC, which has no GPU kernel either, nor has
            // exact PMVC.
            let gpu_backend = matches!(timed.backend, Backend::Gpu(_));
            let has_kernel = crate::gpu::backend_choice::Work::of(options, points.len(), cage)
                .kernel()
                .is_some();
            if gpu_backend && !has_kernel {
                continue;
            }
            let pmvc_kernel = timed.pmvc_kernel.unwrap_or_default();
            let work = crate::gpu::backend_choice::Work::of(options, points.len(), cage);
            let repeated = method != Method::Pmvc && timed.pmvc_kernel != first_kernel;
            // Tiles asked for on a cage they cannot take: no row, not an error.
            if gpu_backend && (repeated || pmvc_kernel.takes_tiles(&work).is_err()) {
                continue;
            }
            let split = options.split_applied(cage);
            let classes = match classified.iter().find(|(key, _)| *key == split) {
                Some((_, classes)) => Arc::clone(classes),
                None => {
                    let classes: Arc<[PointClass]> = options.classify(cage, points).classes.into();
                    classified.push((split, Arc::clone(&classes)));
                    classes
                }
            };
            let input = BindInput {
                points: points.into(),
                classes,
                cage: Arc::new(cage.clone()),
                options,
            };
            let binder = Binder::new(timed.backend.clone()).with_config(BindConfig {
                pmvc_kernel,
                ..BindConfig::default()
            });
            let mut times = Vec::with_capacity(runs);
            let mut waits = Vec::with_capacity(runs);
            let mut last = None;
            for _ in 0..runs {
                // Wall time of the whole bind: uploads and readbacks included.
                let start = Instant::now();
                let output = binder.bind_blocking(&input, &BindProgress::default())?;
                times.push(start.elapsed().as_secs_f64());
                waits.push(output.stats.gpu_wait.as_secs_f64());
                last = Some(output.stats);
            }
            let last = last.unwrap_or_default();
            let name_on_cage = options.family_name(cage);
            let label = match options.parameter() {
                Some((spec, value)) => format!("{name_on_cage} {}", (spec.format)(value)),
                None => name_on_cage,
            };
            let row = BenchRow {
                scene: name.to_owned(),
                mesh_vertices: points.len(),
                cage_vertices: cage.vertex_count(),
                method: label,
                backend: timed.name.clone(),
                median_seconds: median(&times),
                runs: times,
                gpu_wait_seconds: gpu_backend.then(|| median(&waits)),
                batches: last.batches,
                cpu_rows: last.cpu_rows,
                paper_seconds: paper_seconds(name, method, resolution),
            };
            let detail = row.gpu_wait_seconds.map_or(String::new(), |wait| {
                format!(
                    " ({:.3} s waiting on the GPU, {} batches, {} rows on the CPU)",
                    wait, row.batches, row.cpu_rows
                )
            });
            warn_line!(
                "  {} | {} | {}: {:.3} s{detail}",
                row.scene,
                row.method,
                row.backend,
                row.median_seconds
            );
            rows.push(row);
        }
    }
    Ok(rows)
}

fn bench_shared_data(
    args: &BenchArgs,
    names: &[String],
    backends: &[Timed],
) -> Result<Vec<BenchRow>> {
    let mut rows = Vec::new();
    for name in names {
        let mesh = crate::formats::load_mesh(&args.data.join(format!("{name}.obj")))?;
        let (cage, _) = crate::formats::load_cage(&args.data.join(format!("{name}_Cage.obj")))?;
        // On a cage with quads, each family as patches and split along the
        // shorter diagonal (as files were bound before quads were patches).
        let splits: &[QuadSplit] = if cage.has_quads() {
            &[QuadSplit::None, QuadSplit::Shorter]
        } else {
            &[QuadSplit::None]
        };
        // Every family quick to bind at its default parameter, so that a new
        // family gets rows, and the slow ones when named in --methods;
        // a family that binds triangles only splits quads itself: one row.
        let mut configurations: Vec<_> = Method::ALL
            .into_iter()
            .filter(|method| method.spec().quick_to_bind || args.methods.contains(method))
            .flat_map(|method| {
                let value = method.spec().parameter.map_or(0, |p| p.default);
                let patches = matches!(method.spec().quads, QuadSupport::Patches { .. });
                splits
                    .iter()
                    .filter(move |&&split| patches || split == QuadSplit::None)
                    .map(move |&split| (method, value, split))
            })
            .collect();
        // Exact PMVC, quads as patches: one row.
        configurations.push((Method::Pmvc, EXACT_RESOLUTION, QuadSplit::None));
        rows.extend(bench_scene_split(
            name,
            &cage,
            &mesh.mesh.positions,
            &configurations,
            backends,
            usize::from(args.runs),
            &args.methods,
        )?);
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
    let mut text = String::from("| scene | mesh vertices | cage vertices | method | backend | median (s) | paper (s) |\n|---|---:|---:|---|---|---:|---:|\n");
    for row in rows {
        let paper = row
            .paper_seconds
            .map_or(String::new(), |seconds| format!("{seconds:.2}"));
        text.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.3} | {paper} |\n",
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
    gpu_adapter: &'a str,
    rows: &'a [BenchRow],
}

fn to_json(rows: &[BenchRow], threads: usize, adapter: &str) -> String {
    let command = std::env::args().collect::<Vec<_>>().join(" ");
    let report = BenchReport {
        command,
        cpu_threads: threads,
        gpu_adapter: adapter,
        rows,
    };
    serde_json::to_string_pretty(&report).expect("bench rows serialise") + "\n"
}
