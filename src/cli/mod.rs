//! The `pmvc` command line: `edit` (the default), `bind`, `deform`, `check`, `cage`,
//! `bench`, `generate` and `info`.
//!
//! Errors are reported as one line on stderr naming the file, with exit status 1.
//! Outputs are written through a temporary file, so an existing output survives a
//! failure.

/// `println!` that returns a closed or failing stdout as an error (`pmvc check |
/// head -1`) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($arg)*).map_err($crate::cli::OutputError)?
    }};
}

/// `eprintln!` that never panics: with stderr closed there is nowhere to report.
macro_rules! warn_line {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod bench;
mod bench_exact;
mod bind;
mod cage;
mod commands;
mod deform;
mod environment;
mod parse;
mod quad_report;
mod weights_format;

/// Standard output could not be written.
#[derive(Debug, thiserror::Error)]
#[error("cannot write to standard output: {0}")]
pub struct OutputError(pub std::io::Error);

use clap::{Parser, Subcommand, ValueEnum};
use parse::{
    parse_bulging, parse_grid, parse_local_blend, parse_object_name, parse_percent,
    parse_poisson_ratio, parse_resolution, parse_seconds, parse_view, TriangulateArg,
};
use std::path::PathBuf;
use std::process::ExitCode;

/// Cage-based mesh deformation with positive mean value coordinates.
#[derive(Debug, Parser)]
#[command(name = "pmvc", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Open the editor (the default with no subcommand) on the bundled scene or on MESH and CAGE.
    Edit(EditArgs),
    /// Compute the weights of every mesh vertex with respect to the cage and write them as .npy.
    Bind(BindArgs),
    /// Move every mesh vertex p by Σ λᵢ (c̃ᵢ − cᵢ), the weighted moves of the cage vertices (Σ λᵢ c̃ᵢ for weights that reproduce p at rest, with less rounding), and write the mesh as OBJ.
    Deform(DeformArgs),
    /// Validate a mesh and its cage and print statistics.
    Check(CheckArgs),
    /// Generate a cage of about N vertices around a mesh, write it as OBJ and print what was measured on it.
    Cage(cage::CageArgs),
    /// Time binding on scenes of the paper's sizes and on the shared evaluation data.
    Bench(bench::BenchArgs),
    /// Write one of the procedural benchmark scenes as OBJ files.
    Generate(GenerateArgs),
    /// List GPU adapters, the one binding would use, and the limits that matter.
    Info,
}

/// `--method` takes the identifier of any registered coordinate family
/// ([`crate::coords::Method::ALL`]), with its summary as help.
impl ValueEnum for crate::coords::Method {
    fn value_variants<'a>() -> &'a [Self] {
        &crate::coords::Method::ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.id()).help(self.spec().summary))
    }
}

/// Where binding runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum BackendArg {
    /// The faster path for this bind: the CPU, or a hardware GPU where a cost model
    /// predicts it faster for the work, start-up included (see --verbose). Without
    /// a GPU device on the system the GPU drivers are not even loaded.
    Auto,
    /// Rayon-parallel CPU reference.
    Cpu,
    /// wgpu compute kernels.
    Gpu,
}

#[derive(Debug, clap::Args)]
pub struct CageInput {
    /// The mesh to deform (.obj, .off, or the first mesh of a .glb or .gltf, unless
    /// --mesh-object names another). A file
    /// with vertices and no faces is a point set, and so is a .npy array of shape
    /// (n, 3), float32 or float64, in C order.
    #[arg(long, value_name = "MESH")]
    pub mesh: PathBuf,
    /// The cage: a closed, consistently oriented triangle or polygon mesh (.obj, .off,
    /// or a .glb or .gltf, whose vertices at one position are welded).
    #[arg(long, value_name = "CAGE")]
    pub cage: PathBuf,
    /// Read the mesh from this object of a file with several (an OBJ's `o` name,
    /// a glTF node's or mesh's name). Without it an OBJ's objects are read as one
    /// mesh and a glTF's first mesh alone, and a note names the others.
    #[arg(long, value_name = "NAME", value_parser = parse_object_name)]
    pub mesh_object: Option<String>,
    /// Read the cage from this object of a file with several, as --mesh-object.
    #[arg(long, value_name = "NAME", value_parser = parse_object_name)]
    pub cage_object: Option<String>,
}

#[derive(Debug, clap::Args)]
pub struct MethodChoice {
    /// Coordinates to compute.
    #[arg(long, value_enum, default_value_t = crate::coords::Method::Pmvc)]
    pub method: crate::coords::Method,
    /// PMVC cube-map resolution: texels along one face edge (1–1024), or `exact`: the visible cage integrated with no cube map, on the CPU (triangles in closed form, quads as bilinear patches by adaptive quadrature).
    #[arg(long, default_value_t = crate::coords::DEFAULT_RESOLUTION, value_parser = parse_resolution)]
    pub resolution: u32,
    /// Harmonic coordinates and BBW: grid cells along the cage's longest side (4–2048); default 64 for harmonic coordinates, 32 for BBW.
    #[arg(long, value_parser = parse_grid)]
    pub grid: Option<u32>,
    /// Somigliana coordinates: the material's Poisson ratio ν (-0.999–0.499), in steps
    /// of 0.001 (below 0: auxetic); default 0.
    #[arg(long, value_parser = parse_poisson_ratio, allow_negative_numbers = true)]
    pub poisson_ratio: Option<u32>,
    /// Split the cage's quads into triangles along their shorter or longer diagonal
    /// before binding, as before quads were bilinear patches, to reproduce earlier
    /// results or see how much the split moves the mesh. Without it, quads stay
    /// bilinear patches (MVC on quads is then QMVC, Green coordinates QGC).
    #[arg(long, value_enum, value_name = "DIAGONAL")]
    pub triangulate: Option<TriangulateArg>,
    /// Where binding runs (harmonic coordinates always bind on the CPU).
    #[arg(long, value_enum, default_value_t = BackendArg::Auto)]
    pub backend: BackendArg,
    /// PMVC on a GPU: the kernel. `auto` takes the tile kernel where the cage
    /// allows it and a cost model predicts it faster, else the band kernel
    /// (what older releases always used: to reproduce their GPU weights);
    /// `tiles` on a cage with quads or over 2,048 vertices is an error. The two
    /// differ where a ray grazes an edge (up to about 1e-4 in a weight, measured).
    #[arg(long, default_value = "auto", value_name = "auto|tiles|bands", value_parser = crate::gpu::PmvcKernel::parse)]
    pub pmvc_kernel: crate::gpu::PmvcKernel,
    /// Print where the bind runs and why: for `auto`, the CPU's and the GPU's
    /// predicted times; on a GPU, how long the device took to open and whether
    /// the compiled kernels came from the pipeline cache.
    #[arg(long)]
    pub verbose: bool,
    /// Treat mesh vertices outside the cage as an error instead of binding them by
    /// the family's outside policy (MVC weights for MVC, PMVC and harmonic
    /// coordinates; Green's exterior extension for Green coordinates).
    #[arg(long)]
    pub strict: bool,
}

/// The deformation settings given by `--bulging` and `--local-blend` (the
/// same flags on `deform` and `edit`), in the order they are applied.
fn deform_settings(
    bulging: Option<u32>,
    local_blend: Option<u32>,
) -> Vec<(crate::coords::Parameter, u32)> {
    use crate::coords::Parameter;
    [
        (Parameter::Bulging, bulging),
        (Parameter::LocalBlend, local_blend),
    ]
    .into_iter()
    .filter_map(|(parameter, value)| Some((parameter, value?)))
    .collect()
}

impl MethodChoice {
    /// The bind options these flags ask for.
    pub fn options(&self) -> crate::coords::BindOptions {
        crate::coords::BindOptions {
            method: self.method,
            resolution: self.resolution,
            grid: self
                .grid
                .unwrap_or(crate::coords::BindOptions::for_method(self.method).grid),
            poisson_ratio: self
                .poisson_ratio
                .unwrap_or(crate::coords::BindOptions::for_method(self.method).poisson_ratio),
            bulging: crate::coords::BindOptions::for_method(self.method).bulging,
            local_blend: crate::coords::BindOptions::for_method(self.method).local_blend,
            quads: self
                .triangulate
                .map_or(crate::coords::QuadSplit::None, TriangulateArg::split),
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct BindArgs {
    #[command(flatten)]
    pub input: CageInput,
    #[command(flatten)]
    pub method: MethodChoice,
    /// Output .npy: little-endian float32, shape (mesh vertices, cage vertices), rows and columns in file `v` order. Green coordinates (--method green) go to a .npz with two arrays: phi (mesh vertices × cage vertices) and psi (mesh vertices × cage triangles, in the order the cage's faces are triangulated). Beside W.npy or W.npz go W.json (the method and its parameters, backend, device, the bind's seconds, program version, what each column is and Green's psi triangles, the outside policy, the inputs' names and digests) and W.classes.npy (int8 per row: 0 inside, 1 on the cage, 2 outside), replaced together with the weights or not at all; beside a device or pipe, none.
    #[arg(long, value_name = "W.npy|W.npz")]
    pub out: PathBuf,
    /// Bind and write this many rows at a time, so that memory holds two blocks
    /// (one written while the next binds; MVC and PMVC; default: 128 MiB of weights
    /// each). Harmonic coordinates solve for
    /// the whole cage at once and hold every row.
    #[arg(long, value_name = "ROWS", value_parser = clap::value_parser!(u64).range(1..))]
    pub block_rows: Option<u64>,
    /// How the weights are stored: f32 (little-endian float32, the default) or
    /// f64 (float64, every row as computed, without its rounding to float32, for
    /// studies that check weights past 7 digits; W.json's "dtype" says which).
    /// f64 binds on the CPU, whole (not in blocks), and not harmonic coordinates,
    /// which are solved in float32 on their grid.
    #[arg(long, default_value = "f32", value_name = "f32|f64", value_parser = parse_dtype)]
    pub dtype: crate::coords::Dtype,
}

/// `--dtype`, read by the one parser of a dtype ([`crate::coords::Dtype::parse`]).
fn parse_dtype(text: &str) -> Result<crate::coords::Dtype, String> {
    crate::coords::Dtype::parse(text).map_err(|error| error.to_string())
}

#[derive(Debug, clap::Args)]
pub struct DeformArgs {
    #[command(flatten)]
    pub input: CageInput,
    /// The cage in its new pose: same vertices in the same order as --cage.
    #[arg(long, value_name = "CAGE2")]
    pub deformed_cage: PathBuf,
    #[command(flatten)]
    pub method: MethodChoice,
    /// Use weights from `pmvc bind` instead of computing them (--method, --resolution and --grid are then ignored): a .npy applies one weight per cage vertex, a .npz Green coordinates (phi and psi, as numpy.savez writes them). W.json beside them names their family and is checked against the mesh and cage (rows, cage vertices and triangles, digests); without it they are used with a warning that they cannot be checked. Values must be finite float32 (float64 where W.json says "dtype": "float64"), one row per mesh vertex, and each row's cage-vertex weights must sum to 1 (within 1e-4, times Σ|λᵢ| where that is over 1).
    #[arg(long, value_name = "W.npy|W.npz")]
    pub weights: Option<PathBuf>,
    /// Somigliana coordinates: the bulging γ (0–10), in steps of 0.01, default 0
    /// (none): each cage triangle pushes along its normal harder the more volume
    /// the pose sweeps outward from where the fitted similarity puts it. Read
    /// when deforming, so the same weights serve every γ.
    #[arg(long, value_parser = parse_bulging, allow_negative_numbers = true)]
    pub bulging: Option<u32>,
    /// Somigliana coordinates: the local/global blend (0–1), in steps of 0.01,
    /// default 0 (the global variant): at 1 each cage triangle and vertex turns
    /// and stretches with its own frame instead of the similarity fitted to
    /// the whole cage. Read when deforming, as --bulging is.
    #[arg(long, value_parser = parse_local_blend, allow_negative_numbers = true)]
    pub local_blend: Option<u32>,
    /// Output OBJ. Faces, texture coordinates and groups of an OBJ mesh are kept; normals are recomputed from the deformed mesh. A name ending in .npy gets the deformed points instead, as little-endian float64 of shape (mesh vertices, 3), whatever the input's format. A name ending in .glb gets binary glTF 2.0, and .gltf glTF's JSON with its buffer inside: positions, recomputed normals, texture coordinates (v flipped, as glTF has it) and the OBJ's groups as primitives.
    #[arg(long, value_name = "M2.obj|P2.npy|M2.glb|M2.gltf")]
    pub out: PathBuf,
    /// glTF output only: more poses of the cage (each with --cage's vertices in order), each adding the mesh deformed by it as a morph target named after the file's stem (mesh.extras.targetNames, which Blender reads as shape keys). The mesh deformed by --deformed-cage is the base.
    #[arg(long, value_name = "POSE", num_args = 1..)]
    pub poses: Vec<PathBuf>,
    /// glTF output only, with --poses: an animation of the morph target weights over SECONDS, from the base at 0 s through each pose in order, evenly spaced, the last at SECONDS, blended linearly between neighbours.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds, requires = "poses")]
    pub animate: Option<f32>,
}

#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    #[command(flatten)]
    pub input: CageInput,
    /// Mesh vertices sampled for the MVC negativity statistic.
    #[arg(long, default_value_t = 2000)]
    pub sample: usize,
    /// The harmonic grid to report on: cells along the cage's longest side (4–2048).
    #[arg(long, default_value_t = crate::coords::harmonic::DEFAULT_GRID, value_parser = parse_grid)]
    pub grid: u32,
    /// On a cage with quads, the pose at which to measure how far the choice of
    /// diagonal moves the mesh (default: the cage twisted by 45° about its
    /// longest axis).
    #[arg(long, value_name = "POSE.obj")]
    pub deformed_cage: Option<PathBuf>,
    /// PMVC cube-map resolution for that measurement (1–1024), or `exact`.
    #[arg(long, default_value_t = crate::coords::DEFAULT_RESOLUTION, value_parser = parse_resolution)]
    pub resolution: u32,
}

#[derive(Debug, clap::Args)]
pub struct EditArgs {
    /// Mesh to open instead of the bundled scene (.obj, .off, .glb, .gltf or a .npy point set). Without a cage
    /// it opens in a box, with the Generate cage window offering a cage.
    pub mesh: Option<PathBuf>,
    /// Its cage.
    pub cage: Option<PathBuf>,
    /// The object of the mesh file to open, where it has several (an OBJ's
    /// `o` name, a glTF node or mesh name); the side panel offers the others.
    #[arg(long, value_name = "NAME", value_parser = parse_object_name, requires = "mesh")]
    pub mesh_object: Option<String>,
    /// The object of the cage file that is the cage.
    #[arg(long, value_name = "NAME", value_parser = parse_object_name, requires = "cage")]
    pub cage_object: Option<String>,
    /// A session saved by the editor (File > Save session): mesh, cage, poses,
    /// method and views. Other options given with it override what it holds.
    #[arg(long, value_name = "FILE.json", conflicts_with_all = ["mesh", "cage"])]
    pub session: Option<PathBuf>,
    /// A deformed cage with the same vertex count, applied after binding.
    #[arg(long, value_name = "POSE.obj")]
    pub pose: Option<PathBuf>,
    /// PMVC cube-map resolution (1–1024), or `exact` (no cube map).
    #[arg(long, value_parser = parse_resolution)]
    pub resolution: Option<u32>,
    /// Harmonic coordinates and BBW: grid cells along the cage's longest side (4–2048), for both; without it 64 and 32.
    #[arg(long, value_parser = parse_grid)]
    pub grid: Option<u32>,
    /// Bind the cage's quads split along their shorter or longer diagonal
    /// instead of as bilinear patches (the Quads setting in the side panel).
    #[arg(long, value_enum, value_name = "DIAGONAL")]
    pub triangulate: Option<TriangulateArg>,
    /// Somigliana coordinates' bulging γ (0–10), as `pmvc deform --bulging`:
    /// the side panel's Bulging γ, applied after --pose.
    #[arg(long, value_parser = parse_bulging, allow_negative_numbers = true)]
    pub bulging: Option<u32>,
    /// Somigliana coordinates' local/global blend (0–1), as `pmvc deform
    /// --local-blend`: the side panel's Local blend, applied after --pose.
    #[arg(long, value_parser = parse_local_blend, allow_negative_numbers = true)]
    pub local_blend: Option<u32>,
    /// Coordinates to bind first.
    #[arg(long, value_enum)]
    pub method: Option<crate::coords::Method>,
    /// Wait for the bind, render, save the window as PNG and exit.
    #[arg(long, value_name = "PATH")]
    pub screenshot: Option<PathBuf>,
    /// With --screenshot: first drag this cage vertex's handle (0-based) with the
    /// pointer for 60 frames, then print how far it moved and the average frame
    /// time while dragging. A handle outside the first view fails the run.
    #[arg(long, value_name = "CAGE_VERTEX", requires = "screenshot")]
    pub drag: Option<usize>,
    /// With --screenshot: run without a window or display, drawing the editor's
    /// frames on the GPU that wgpu finds (a server, a CI machine).
    #[arg(long, requires = "screenshot")]
    pub offscreen: bool,
    /// Where binding runs: auto puts each bind on the editor's GPU or the CPU,
    /// whichever a cost model predicts faster for it.
    #[arg(long, value_enum, default_value_t = BackendArg::Auto)]
    pub backend: BackendArg,
    /// What the viewport shows: one method (give its name, e.g. `mvc`), methods
    /// side by side (`side-by-side`), or the distance between two methods'
    /// deformations (`difference`).
    #[arg(long, value_parser = parse_view)]
    pub view: Option<ViewArg>,
    /// The families the side-by-side view shows, e.g. `mvc,pmvc,harmonic` (default
    /// mvc,pmvc); implies `--view side-by-side` when no view is given.
    #[arg(long, value_enum, value_delimiter = ',', value_name = "METHODS")]
    pub compare: Vec<crate::coords::Method>,
    /// Colour the mesh by the coordinate function of this cage vertex (0-based).
    #[arg(long, value_name = "CAGE_VERTEX", conflicts_with = "negativity")]
    pub heatmap: Option<usize>,
    /// Colour the mesh by Green coordinates' ψ of this cage triangle (0-based, in
    /// the order the cage's faces are triangulated); other families show shaded.
    #[arg(long, value_name = "CAGE_TRIANGLE", conflicts_with_all = ["negativity", "heatmap"])]
    pub heatmap_triangle: Option<usize>,
    /// Colour the mesh by each vertex's most negative weight.
    #[arg(long)]
    pub negativity: bool,
    /// Show heatmap and difference magnitudes on a log scale (three decades).
    #[arg(long)]
    pub log_scale: bool,
    /// Show the negativity view on a linear scale instead of its default log scale.
    #[arg(long)]
    pub linear_negativity: bool,
    /// End the difference view's colour scale at this distance, in % of the cage
    /// diagonal, instead of at the largest distance (at least 0.1%): pictures of
    /// several runs then share one scale.
    #[arg(long, value_name = "PERCENT", value_parser = parse_percent)]
    pub difference_limit: Option<f32>,
    /// Open the bundled comb with its middle finger pulled up, MVC and PMVC side
    /// by side with their difference (unless --view says otherwise): what `pmvc`
    /// with no arguments opens.
    #[arg(long, conflicts_with_all = ["mesh", "pose"])]
    pub demo: bool,
}

/// What the editor's viewport shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewArg {
    /// The mesh deformed with one method.
    Single(crate::coords::Method),
    /// Methods next to each other, cameras locked.
    SideBySide,
    /// The distance between two methods' deformations per mesh vertex, relative
    /// to the cage size.
    Difference,
}

impl EditArgs {
    fn editor_options(self) -> crate::app::EditorOptions {
        use crate::app::compare::{Layout, MethodSet, Overlay, ViewSettings};
        let mut view = ViewSettings::default();
        let mut method = self.method;
        match self.view {
            Some(ViewArg::Single(shown)) => method = Some(shown),
            Some(ViewArg::SideBySide) => view.layout = Layout::SideBySide,
            Some(ViewArg::Difference) => view.layout = Layout::Difference,
            None if !self.compare.is_empty() => view.layout = Layout::SideBySide,
            None if self.demo => {
                view.layout = Layout::SideBySide;
                view.difference_pane = true;
            }
            None => {}
        }
        if !self.compare.is_empty() {
            view.compared = MethodSet::of(&self.compare);
        }
        if let Some(vertex) = self.heatmap {
            view.overlay = Overlay::Heatmap;
            view.heat_vertex = vertex;
        }
        if let Some(triangle) = self.heatmap_triangle {
            view.overlay = Overlay::Heatmap;
            view.heat_triangle = Some(triangle);
        }
        if self.negativity {
            view.overlay = Overlay::Negativity;
        }
        if self.log_scale {
            view.scale = crate::render::colormap::Scale::LogMagnitude;
        }
        if self.linear_negativity {
            view.negativity_scale = crate::render::colormap::Scale::Linear;
        }
        view.difference_limit = self.difference_limit.map(|percent| percent / 100.0);
        crate::app::EditorOptions {
            mesh: self.mesh,
            cage: self.cage,
            mesh_object: self.mesh_object,
            cage_object: self.cage_object,
            session: self.session,
            pose: self.pose,
            resolution: self.resolution,
            grid: self.grid,
            deform: deform_settings(self.bulging, self.local_blend),
            triangulate: self.triangulate.map(TriangulateArg::split),
            method,
            screenshot: self.screenshot,
            drag_handle: self.drag,
            bind_on: match self.backend {
                BackendArg::Auto => crate::app::BindOn::Auto,
                BackendArg::Cpu => crate::app::BindOn::Cpu,
                BackendArg::Gpu => crate::app::BindOn::Gpu,
            },
            view,
            hide_timings: false,
            recovery_dir: None,
            demo_pose: self.demo,
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct GenerateArgs {
    /// Scene name: the paper's Table 1 sizes (point sets), sculpt-size (a
    /// million-vertex triangle mesh), or twisted-bar (a round bar in a box cage,
    /// for docs/poses/twisted-bar.obj).
    #[arg(value_parser = clap::builder::PossibleValuesParser::new(generate_scene_names()))]
    pub scene: String,
    /// Output mesh as OBJ.
    #[arg(long)]
    pub mesh: PathBuf,
    /// Output cage as OBJ.
    #[arg(long)]
    pub cage: PathBuf,
}

fn generate_scene_names() -> Vec<&'static str> {
    let mut names = crate::geometry::procedural::table1_scene_names().to_vec();
    names.push(crate::geometry::procedural::SCULPT_SIZE);
    names.push(crate::geometry::twisted_bar::TWISTED_BAR);
    names
}

/// Entry point of the binary: parse, run, report.
pub fn main() -> ExitCode {
    environment::ensure_runtime_dir();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Help and version go to stdout and succeed; a bad argument is bad input
        // like any other: its message, then exit status 1 (clap's own is 2).
        Err(error) => {
            let _ = error.print();
            return if error.use_stderr() {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    if matches!(
        cli.command,
        Some(
            Command::Bind(_)
                | Command::Deform(_)
                | Command::Cage(_)
                | Command::Generate(_)
                | Command::Bench(_)
        )
    ) {
        environment::remove_unfinished_outputs_on_signals();
    }
    let result = match cli.command {
        None => crate::app::run_editor(crate::app::EditorOptions::first_run())
            .map_err(anyhow::Error::from),
        Some(Command::Edit(args)) => {
            let offscreen = args.offscreen;
            let options = args.editor_options();
            let checked = match &options.screenshot {
                Some(screenshot) => check_screenshot_path(screenshot, &options),
                None => Ok(()),
            };
            checked.and_then(|()| {
                if offscreen {
                    crate::app::run_offscreen(options)
                } else {
                    crate::app::run_editor(options)
                }
                .map_err(anyhow::Error::from)
            })
        }
        Some(Command::Bind(args)) => bind::bind(&args),
        Some(Command::Deform(args)) => deform::deform(&args),
        Some(Command::Check(args)) => commands::check(&args),
        Some(Command::Cage(args)) => cage::cage(&args),
        Some(Command::Bench(args)) => bench::run(&args),
        Some(Command::Generate(args)) => commands::generate(&args),
        Some(Command::Info) => commands::info(),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // The reader went away (`| head`): what it wanted it has, so end quietly.
        Err(error)
            if error
                .downcast_ref::<OutputError>()
                .is_some_and(|e| e.0.kind() == std::io::ErrorKind::BrokenPipe) =>
        {
            ExitCode::SUCCESS
        }
        Err(error) => {
            warn_line!("pmvc: error: {}", error_line(&error));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line. The library's messages already quote
/// their cause (`w.npy: cannot write: No space left on device`), so a cause whose
/// text is there is not repeated.
fn error_line(error: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if !line.contains(&text) {
            if !line.is_empty() {
                line.push_str(": ");
            }
            line.push_str(&text);
        }
    }
    line
}

#[cfg(test)]
mod tests;

/// `--screenshot` before the window opens: never one of the run's inputs (the
/// scene's files are checked again when the image is written, since a session
/// names its own), and a warning when the name does not say PNG.
fn check_screenshot_path(
    screenshot: &std::path::Path,
    options: &crate::app::EditorOptions,
) -> anyhow::Result<()> {
    let inputs = [
        &options.mesh,
        &options.cage,
        &options.session,
        &options.pose,
    ];
    let named = options
        .session
        .as_deref()
        .map(crate::app::session::files_named)
        .unwrap_or_default();
    let inputs: Vec<&std::path::Path> = inputs
        .into_iter()
        .flatten()
        .chain(&named)
        .map(PathBuf::as_path)
        .collect();
    commands::check_output(screenshot, &inputs, &["png"], "a PNG image")
}
