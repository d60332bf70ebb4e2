//! The work behind each subcommand.

use super::weights_format::{check_weights_format, read_weights_for, writes_npz};
use super::{BackendArg, BindArgs, CageInput, CheckArgs, DeformArgs, GenerateArgs, MethodChoice};
use crate::coords::npy::{npy_file_bytes, npy_preamble, write_f32_values, write_npy_to};
use crate::coords::npz::{npz_payload_bytes, write_npz_to};
use crate::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use crate::geometry::{
    self, classify_points, extension_warning, refuse_same_file, shown_path, Cage, MeshFile,
    OutputSet, PendingOutput, PointClasses,
};
use crate::gpu::{Backend, BindInput, Binder, GpuContext};
use anyhow::{anyhow, bail, Context, Result};
use glam::DVec3;
use std::io::Write as _;
use std::sync::Arc;
use std::time::Duration;

/// A mesh, its validated cage, and where each mesh vertex lies.
pub(super) struct BoundInput {
    pub mesh: MeshFile,
    pub cage: Cage,
    pub classes: PointClasses,
}

/// How many weights rows a command holds in memory at once, given the mesh's
/// vertex count and the weights' columns: all of them, none, or a block.
pub(super) type ResidentRows<'a> = &'a dyn Fn(usize, usize) -> usize;

/// Load and validate the inputs, printing the cage's notices and the outside count.
/// Weights rows that cannot fit in memory (`resident_rows`) are an error before
/// any work on the points.
pub(super) fn load_input(
    input: &CageInput,
    choice: &MethodChoice,
    resident_rows: ResidentRows,
) -> Result<BoundInput> {
    let strict = choice.strict;
    let mesh = geometry::load_mesh(&input.mesh)?;
    let (cage, report) = geometry::load_cage(&input.cage)?;
    let columns = choice.method.columns(&cage);
    let rows = resident_rows(mesh.mesh.positions.len(), columns);
    check_weights_fit(rows, columns, &input.mesh)?;
    for message in report.messages() {
        warn_line!("pmvc: {}: {message}", shown_path(&input.cage));
    }
    let classes = classify_points(&cage, &mesh.mesh.positions);
    if !classes.outside.is_empty() {
        let summary = outside_summary(&classes, mesh.mesh.positions.len());
        if strict {
            bail!(
                "{}: {summary} of {} (--strict)",
                shown_path(&input.mesh),
                shown_path(&input.cage)
            );
        }
        let policy = if choice.method == Method::Green {
            "they get Green's exterior extension through the nearest cage triangle, exact at rest and continuous across it".to_owned()
        } else {
            format!("they get MVC weights (beyond {} cage diagonals, MVC's affine extension), which sum to one, reproduce their points at any distance and meet the inside coordinates continuously on the cage", crate::coords::mvc::FAR_FIELD_DIAGONALS)
        };
        warn_line!(
            "pmvc: {}: warning: {summary} of {}; {policy}",
            shown_path(&input.mesh),
            shown_path(&input.cage),
        );
    }
    Ok(BoundInput {
        mesh,
        cage,
        classes,
    })
}

fn outside_summary(classes: &PointClasses, total: usize) -> String {
    let first: Vec<String> = classes.outside.iter().take(5).map(u32::to_string).collect();
    let more = if classes.outside.len() > 5 {
        ", …"
    } else {
        ""
    };
    format!(
        "{} of {total} vertices ({:.2}%) lie outside the cage (first: {}{more})",
        classes.outside.len(),
        100.0 * classes.outside.len() as f64 / total.max(1) as f64,
        first.join(", ")
    )
}

/// Compute the weights with the chosen backend, showing progress on a terminal.
pub(super) fn compute_weights(input: &BoundInput, choice: &MethodChoice) -> Result<Weights> {
    compute_weights_on(input, choice, choose_backend(choice.backend)?)
}

/// [`compute_weights`] on a backend chosen beforehand.
fn compute_weights_on(
    input: &BoundInput,
    choice: &MethodChoice,
    backend: Backend,
) -> Result<Weights> {
    let rows = input.mesh.mesh.positions.len();
    let bar = progress_bar(rows as u64, choice.method);
    let (weights, _) = bind_rows(input, 0..rows, choice, &backend, &bar)?;
    bar.finish_and_clear();
    Ok(weights)
}

/// Bind the points in `range`, moving `bar` on from the range's start. Returns
/// the weights and where they were computed.
fn bind_rows(
    input: &BoundInput,
    range: std::ops::Range<usize>,
    choice: &MethodChoice,
    backend: &Backend,
    bar: &indicatif::ProgressBar,
) -> Result<(Weights, String)> {
    let bind_input = BindInput {
        points: input.mesh.mesh.positions[range.clone()].into(),
        classes: input.classes.classes[range.clone()].into(),
        cage: Arc::new(input.cage.clone()),
        options: choice.options(),
    };
    let output = if bar.is_hidden() {
        // Nothing to show: wait on the bind directly, not in steps of the poll below.
        Binder::new(backend.clone()).bind_blocking(&bind_input, &BindProgress::default())?
    } else {
        let handle = Binder::new(backend.clone()).start(bind_input);
        while !handle.is_finished() {
            bar.set_position((range.start + handle.progress().done()) as u64);
            std::thread::sleep(Duration::from_millis(50));
        }
        handle.wait()?
    };
    let weights = output
        .weights
        .context("internal error: the bind returned no CPU weights")?;
    Ok((weights, output.stats.device))
}

/// What a bind used, for the summary line: "PMVC 32²", "harmonic grid 64", "MVC".
fn method_label(choice: &MethodChoice) -> String {
    use crate::coords::Parameter;
    let name = choice.method.name();
    match choice.method.spec().parameter.as_ref().map(|p| p.key) {
        Some(Parameter::Resolution) => format!("{name} {}²", choice.resolution),
        Some(Parameter::Grid) => format!("{name} grid {}", choice.grid),
        None => name.to_owned(),
    }
}

/// One line on stderr when it is a terminal: what was written and how. Scripts
/// reading a pipe get nothing, as before.
fn summary(line: std::fmt::Arguments) {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() {
        let _ = writeln!(std::io::stderr(), "pmvc: {line}");
    }
}

fn outside_note(input: &BoundInput) -> String {
    match input.classes.outside.len() {
        0 => "all vertices inside the cage".to_owned(),
        n => format!("{n} vertices outside the cage"),
    }
}

/// Rows a streamed bind computes and writes at a time when `--block-rows` is not
/// given: 256 MiB of weights, so that memory stays flat however large the mesh.
const BLOCK_BYTES: usize = 256 << 20;

/// Rows held at once by `pmvc bind`: everything for a family that solves for the
/// whole cage or is written as a `.npz` (array after array), a block for one whose
/// rows are independent.
fn bind_resident_rows(args: &BindArgs, rows: usize, columns: usize) -> usize {
    if args.method.method.spec().rows_independent && !writes_npz(args.method.method) {
        let block = args
            .block_rows
            .map_or(BLOCK_BYTES / (4 * columns.max(1)), |rows| {
                usize::try_from(rows).unwrap_or(usize::MAX)
            });
        rows.min(block.max(1))
    } else {
        rows
    }
}

/// `auto` binds on a hardware GPU when there is one. With only a software adapter
/// (lavapipe, llvmpipe) the CPU path is faster (docs/benchmarks.md), so it uses that.
pub(super) fn choose_backend(choice: BackendArg) -> Result<Backend> {
    match choice {
        BackendArg::Cpu => Ok(Backend::Cpu),
        BackendArg::Gpu => {
            let context = GpuContext::new().context("--backend gpu")?;
            Ok(Backend::Gpu(Arc::new(context)))
        }
        BackendArg::Auto => match GpuContext::new_hardware() {
            Ok(Some(context)) => Ok(Backend::Gpu(Arc::new(context))),
            _ => Ok(Backend::Cpu),
        },
    }
}

/// A progress bar on stderr when it is a terminal; hidden otherwise.
pub(super) fn progress_bar(total: u64, method: Method) -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(total),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{msg} {wide_bar} {pos}/{len} vertices, {elapsed} (ETA {eta})",
    ) {
        bar.set_style(style);
    }
    bar.set_message(format!("binding ({})", method.name()));
    bar
}

/// Refuse an output that is one of the inputs, and warn when its name says it
/// holds something else.
pub(super) fn check_output(
    out: &std::path::Path,
    inputs: &[&std::path::Path],
    extensions: &[&str],
    what: &str,
) -> Result<()> {
    refuse_same_file(out, inputs)?;
    crate::geometry::refuse_unwritable(out)?;
    if let Some(warning) = extension_warning(out, extensions, what) {
        warn_line!("pmvc: {warning}");
    }
    Ok(())
}

/// An error before the work starts when a dense `rows` × `cols` weights matrix
/// cannot fit in the memory left, instead of an abort once it is allocated.
fn check_weights_fit(rows: usize, cols: usize, mesh: &std::path::Path) -> Result<()> {
    use crate::geometry::budget::{bytes_for, check_memory};
    let bytes = bytes_for(rows as u64, bytes_for(cols as u64, 4));
    check_memory(
        || format!("its weights ({rows} vertices × {cols} columns × 4 bytes)"),
        bytes,
    )
    .map_err(|error| {
        anyhow!(
            "{}: {error}; bind the mesh in parts, or use a coarser cage",
            shown_path(mesh)
        )
    })
}

pub(super) fn bind(args: &BindArgs) -> Result<()> {
    let inputs = [args.input.mesh.as_path(), args.input.cage.as_path()];
    check_weights_format(args)?;
    let (extensions, what): (&[&str], _) = if writes_npz(args.method.method) {
        (&["npz"], "phi and psi float32 arrays in .npz format")
    } else {
        (&["npy"], "float32 weights in .npy format")
    };
    check_output(&args.out, &inputs, extensions, what)?;
    // Probing adapters for `auto` or `gpu` takes tens of milliseconds, mostly waiting
    // on the driver: do it while the inputs load and are classified.
    let choice = args.method.backend;
    let probe = std::thread::spawn(move || choose_backend(choice));
    let input = load_input(&args.input, &args.method, &|rows, columns| {
        bind_resident_rows(args, rows, columns)
    })?;
    let backend = probe
        .join()
        .map_err(|_| anyhow::anyhow!("internal error: the adapter probe panicked"))??;
    let rows = input.mesh.mesh.positions.len();
    let columns = args.method.method.columns(&input.cage);
    // Opened before the work, so that a full disk or an unwritable folder is
    // reported now, and a signal during the bind removes the temporary file.
    let output = PendingOutput::create(&args.out)?;
    output.check_space(if writes_npz(args.method.method) {
        npz_payload_bytes(rows, columns)
    } else {
        npy_file_bytes(rows, columns)
    })?;
    let started = std::time::Instant::now();
    let device = bind_to(args, &input, backend, output, rows, columns)?;
    let shape = if writes_npz(args.method.method) {
        let vertices = input.cage.vertex_count();
        format!(
            "phi {rows} × {vertices} and psi {rows} × {} float32",
            columns - vertices
        )
    } else {
        format!("{rows} × {columns} float32 weights")
    };
    summary(format_args!(
        "wrote {}: {shape} ({}, {device}) in {:.2} s; {}",
        shown_path(&args.out),
        method_label(&args.method),
        started.elapsed().as_secs_f64(),
        outside_note(&input)
    ));
    Ok(())
}

/// Bind and write the weights, whole or in blocks of rows; returns where they
/// were computed.
fn bind_to(
    args: &BindArgs,
    input: &BoundInput,
    backend: Backend,
    output: PendingOutput,
    rows: usize,
    columns: usize,
) -> Result<String> {
    let block = bind_resident_rows(args, rows, columns);
    let bar = progress_bar(rows as u64, args.method.method);
    if block >= rows {
        let (weights, device) = bind_rows(input, 0..rows, &args.method, &backend, &bar)?;
        bar.finish_and_clear();
        if writes_npz(args.method.method) {
            let vertices = args.method.method.vertex_columns(&input.cage);
            write_npz_to(output, &args.out, &weights, vertices)?;
        } else {
            write_npy_to(output, &args.out, &weights)?;
        }
        return Ok(device);
    }
    // In blocks of rows, each written as soon as it is bound: memory stays at one
    // block, and the disk is the only limit.
    let preamble = npy_preamble(&args.out, rows, columns)?;
    let mut bind_error = None;
    let mut device = String::new();
    let written = output.finish(|out| {
        out.write_all(&preamble)?;
        for start in (0..rows).step_by(block) {
            let range = start..(start + block).min(rows);
            match bind_rows(input, range, &args.method, &backend, &bar) {
                Ok((weights, used)) => {
                    device = used;
                    write_f32_values(out, &weights.values)?
                }
                Err(error) => {
                    bind_error = Some(error);
                    return Err(std::io::Error::other("the bind failed"));
                }
            }
        }
        Ok(())
    });
    bar.finish_and_clear();
    match (bind_error, written) {
        (Some(error), _) => Err(error),
        (None, result) => Ok(result.map(|()| device)?),
    }
}

pub(super) fn deform(args: &DeformArgs) -> Result<()> {
    let started = std::time::Instant::now();
    let mut inputs = vec![
        args.input.mesh.as_path(),
        args.input.cage.as_path(),
        args.deformed_cage.as_path(),
    ];
    inputs.extend(args.weights.as_deref());
    check_output(&args.out, &inputs, &["obj"], "an OBJ mesh")?;
    let holds_weights = args.weights.is_none();
    let input = load_input(&args.input, &args.method, &|rows, _| {
        if holds_weights {
            rows
        } else {
            0
        }
    })?;
    let pose = geometry::load_mesh(&args.deformed_cage)?;
    let (expected, found) = (input.cage.vertex_count(), pose.mesh.positions.len());
    if found != expected {
        bail!(
            "{}: the deformed cage has {found} vertices, but the cage {} has {expected}; a pose must keep the cage's vertices in order",
            shown_path(&args.deformed_cage),
            shown_path(&args.input.cage)
        );
    }
    let (weights, method) = match &args.weights {
        Some(path) => read_weights_for(path, &input, args.method.method)?,
        None => (compute_weights(&input, &args.method)?, args.method.method),
    };
    // Displacement form, p + Σλ(c̃ − c): the same as Σλc̃ for weights that
    // reproduce their points at rest (every family pmvc binds), and better in f32:
    // Σλc̃ carries each weight's rounding times the cage's distance from the
    // origin, this form only times how far the cage moved. Rows were checked to
    // sum to 1 when read, so a translation of the cage moves every vertex with it.
    let moves = method.column_displacements(&input.cage, &pose.mesh.positions);
    let deformed: Vec<DVec3> = weights.apply_displacements(&input.mesh.mesh.positions, &moves);
    geometry::write_deformed_mesh(&input.mesh, &deformed, &args.out)?;
    let source = match &args.weights {
        Some(path) => format!("weights from {}", geometry::shown_path(path)),
        None => format!("{} weights", method_label(&args.method)),
    };
    summary(format_args!(
        "wrote {}: {} vertices deformed with {source} in {:.2} s; {}",
        shown_path(&args.out),
        deformed.len(),
        started.elapsed().as_secs_f64(),
        outside_note(&input)
    ));
    Ok(())
}

pub(super) fn check(args: &CheckArgs) -> Result<()> {
    let mesh = geometry::load_mesh(&args.input.mesh)?;
    say!(
        "mesh  {}: {} vertices, {} triangles{}",
        shown_path(&args.input.mesh),
        mesh.mesh.positions.len(),
        mesh.mesh.triangles.len(),
        if mesh.mesh.triangles.is_empty() {
            " (a point set)"
        } else {
            ""
        }
    );
    let (cage, report) = geometry::load_cage(&args.input.cage)?;
    say!(
        "cage  {}: {} vertices, {} triangles, closed, edge-manifold, consistently oriented",
        shown_path(&args.input.cage),
        cage.vertex_count(),
        cage.triangles().len()
    );
    say!(
        "      volume {:.6}, faces point {}, diagonal {:.6}",
        report.volume,
        if report.flipped {
            "inward (flipped to outward)"
        } else {
            "outward"
        },
        cage.diagonal()
    );
    for message in report.messages() {
        say!("      {message}");
    }
    let classes = classify_points(&cage, &mesh.mesh.positions);
    let on_surface = classes
        .classes
        .iter()
        .filter(|c| matches!(c, geometry::PointClass::OnSurface { .. }))
        .count();
    if classes.outside.is_empty() {
        say!(
            "inside: all {} mesh vertices ({} on the cage surface)",
            mesh.mesh.positions.len(),
            on_surface
        );
    } else {
        say!(
            "outside: {}",
            outside_summary(&classes, mesh.mesh.positions.len())
        );
    }

    let plan = crate::coords::harmonic::plan(&cage, args.grid, mesh.mesh.positions.len())?;
    say!(
        "harmonic at --grid {}: {} × {} × {} nodes of {:.6}, {} inside the cage, {} multigrid levels, about {} MiB",
        plan.grid,
        plan.dims[0],
        plan.dims[1],
        plan.dims[2],
        plan.cell,
        plan.inside_nodes,
        plan.levels,
        plan.predicted_bytes >> 20
    );

    // MVC negativity on an evenly spaced sample of inside vertices.
    let inside: Vec<usize> = (0..mesh.mesh.positions.len())
        .filter(|&i| matches!(classes.classes[i], geometry::PointClass::Inside))
        .collect();
    let step = (inside.len() / args.sample.max(1)).max(1);
    let sample: Vec<usize> = inside
        .iter()
        .step_by(step)
        .copied()
        .take(args.sample)
        .collect();
    let points: Vec<DVec3> = sample.iter().map(|&i| mesh.mesh.positions[i]).collect();
    let sample_classes: Vec<_> = sample.iter().map(|&i| classes.classes[i]).collect();
    let options = BindOptions::for_method(Method::Mvc);
    let weights = bind_cpu(
        &points,
        &sample_classes,
        &cage,
        options,
        &BindProgress::default(),
    )?;
    let negative_rows = (0..weights.rows)
        .filter(|&r| weights.row(r).iter().any(|&w| w < 0.0))
        .count();
    say!(
        "MVC on {} sampled inside vertices: {:.1}% have a negative weight, most negative {:.4}",
        weights.rows,
        100.0 * negative_rows as f64 / weights.rows.max(1) as f64,
        weights.min().min(0.0)
    );
    Ok(())
}

pub(super) fn generate(args: &GenerateArgs) -> Result<()> {
    use geometry::procedural::{sculpt_size_scene, table1_scene, SCULPT_SIZE};
    check_output(&args.mesh, &[], &["obj"], "an OBJ mesh")?;
    check_output(&args.cage, &[], &["obj"], "an OBJ cage")?;
    // Opened before the work: a mesh is never written without its cage.
    let outputs = OutputSet::create(&[&args.mesh, &args.cage])?;
    let (mesh, cage) = if args.scene == SCULPT_SIZE {
        sculpt_size_scene()
    } else if args.scene == geometry::twisted_bar::TWISTED_BAR {
        let bar = geometry::twisted_bar::twisted_bar();
        (bar.mesh, bar.cage)
    } else {
        let scene = table1_scene(&args.scene).context("unknown scene")?;
        let points = geometry::TriMesh {
            positions: scene.points,
            ..Default::default()
        };
        (points, scene.cage)
    };
    outputs.finish(|index, out| match index {
        0 => geometry::write_obj_to(out, &mesh.positions, &mesh.triangles),
        _ => geometry::write_obj_to(out, cage.positions(), cage.triangles()),
    })?;
    say!(
        "{}: {} mesh vertices ({} triangles) in a {}-vertex cage",
        args.scene,
        mesh.positions.len(),
        mesh.triangles.len(),
        cage.vertex_count()
    );
    Ok(())
}

pub(super) fn info() -> Result<()> {
    say!("{}", crate::gpu::adapters_report().trim_end());
    Ok(())
}
