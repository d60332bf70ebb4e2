//! The work behind each subcommand.

use super::{BackendArg, CageInput, CheckArgs, GenerateArgs, MethodChoice};
use crate::coords::{bind_cpu, BindOptions, BindProgress, Method, Weights};
use crate::formats::{extension_warning, refuse_same_file, shown_path, MeshFile, OutputSet};
use crate::geometry::{self, classify_points, Cage, PointClasses};
use crate::gpu::backend_choice::{
    decide, decide_and_open, device_for, BackendRequest, Decision, Work,
};
use crate::gpu::{Backend, BindConfig, BindInput, Binder};
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

/// What the outside warning says of vertices outside the cage: the family's
/// own policy, or, for stored weights whose family is not recorded, that their
/// rows are used as stored.
pub(super) fn outside_policy(method: Option<Method>) -> &'static str {
    match method {
        Some(method) => method.spec().outside_policy,
        None => "their rows are used as the weights file stores them (it has no metadata to say how they were bound)",
    }
}

/// How `load_input` treats the inputs: whose columns the weights have, against
/// which cage the points are classified, what vertices outside the cage get,
/// and how many weights rows are held at once.
pub(super) struct InputRules<'a> {
    /// The bind whose weights are held: its family decides their columns, and
    /// the points are classified against the cage it binds (its quads split if
    /// it splits them; [`BindOptions::classify`]).
    pub options: BindOptions,
    /// `--strict`: vertices outside the cage are an error.
    pub strict: bool,
    /// What the warning says those vertices get ([`outside_policy`]).
    pub outside_policy: &'static str,
    pub resident_rows: ResidentRows<'a>,
}

/// Load and validate the inputs, printing the cage's notices and the outside count.
/// Weights rows that cannot fit in memory (`rules.resident_rows`) are an error
/// before any work on the points.
pub(super) fn load_input(input: &CageInput, rules: &InputRules) -> Result<BoundInput> {
    let mesh = read_mesh(&input.mesh, input.mesh_object.as_deref())?;
    let (cage, report) = read_cage(&input.cage, input.cage_object.as_deref())?;
    let columns = rules.options.columns(&cage);
    let rows = (rules.resident_rows)(mesh.mesh.positions.len(), columns);
    check_weights_fit(rows, columns, &input.mesh)?;
    for message in report.messages() {
        warn_line!("pmvc: {}: {message}", shown_path(&input.cage));
    }
    let classes = rules.options.classify(&cage, &mesh.mesh.positions);
    if !classes.outside.is_empty() {
        let summary = outside_summary(&classes, mesh.mesh.positions.len());
        if rules.strict {
            bail!(
                "{}: {summary} of {} (--strict)",
                shown_path(&input.mesh),
                shown_path(&input.cage)
            );
        }
        warn_line!(
            "pmvc: {}: warning: {summary} of {}; {}",
            shown_path(&input.mesh),
            shown_path(&input.cage),
            rules.outside_policy,
        );
    }
    Ok(BoundInput {
        mesh,
        cage,
        classes,
    })
}

fn outside_summary(classes: &PointClasses, total: usize) -> String {
    crate::coords::outside_summary(&classes.outside, total)
}

/// Compute the weights with the chosen backend, showing progress on a terminal.
pub(super) fn compute_weights(input: &BoundInput, choice: &MethodChoice) -> Result<Weights> {
    compute_weights_on(input, choice, choose_backend(choice.backend, 0)?)
}

/// [`compute_weights`] on a backend chosen beforehand.
fn compute_weights_on(
    input: &BoundInput,
    choice: &MethodChoice,
    backend: Backend,
) -> Result<Weights> {
    let rows = input.mesh.mesh.positions.len();
    let bar = progress_bar(rows as u64, choice.method);
    let bound = bind_rows(input, 0..rows, choice, &backend, &bar)?;
    bar.finish_and_clear();
    Ok(bound.weights)
}

/// Weights of a range of rows, and how they were computed.
pub(super) struct BoundRows {
    pub weights: Weights,
    /// Where they were computed, in words ("CPU", or the adapter).
    pub device: String,
    /// Whether GPU kernels computed them (a family without one binds on the
    /// CPU on every backend).
    pub on_gpu: bool,
    /// The bind's own time, without loading or writing.
    pub seconds: f64,
}

/// Bind the points in `range`, moving `bar` on from the range's start.
pub(super) fn bind_rows(
    input: &BoundInput,
    range: std::ops::Range<usize>,
    choice: &MethodChoice,
    backend: &Backend,
    bar: &indicatif::ProgressBar,
) -> Result<BoundRows> {
    // Decided on the whole bind, so that every block of a streamed one binds
    // on the same device.
    let decision = decide_on(input, input.mesh.mesh.positions.len(), choice, backend)?;
    if choice.verbose && range.start == 0 {
        warn_line!("pmvc: {}", decision.explain());
    }
    if range.start == 0 {
        if let Some(notice) = choice.options().quad_notice(&input.cage) {
            warn_line!("pmvc: {notice}");
        }
    }
    let on_gpu = decision.on_gpu(choice.method);
    let backend = &decision.backend;
    let bind_input = BindInput {
        points: input.mesh.mesh.positions[range.clone()].into(),
        classes: input.classes.classes[range.clone()].into(),
        cage: Arc::new(input.cage.clone()),
        options: choice.options(),
    };
    let binder = Binder::new(backend.clone()).with_config(BindConfig {
        pmvc_kernel: choice.pmvc_kernel,
        ..BindConfig::default()
    });
    let output = if bar.is_hidden() {
        // Nothing to show: wait on the bind directly, not in steps of the poll below.
        binder.bind_blocking(&bind_input, &BindProgress::default())
    } else {
        let handle = binder.start(bind_input);
        while !handle.is_finished() {
            bar.set_position((range.start + handle.progress().done()) as u64);
            std::thread::sleep(Duration::from_millis(50));
        }
        handle.wait()
    };
    if let Backend::Gpu(context) = backend {
        for notice in context.take_notices() {
            warn_line!("pmvc: {notice}");
        }
    }
    let output = output?;
    let weights = output
        .weights
        .context("internal error: the bind returned no CPU weights")?;
    Ok(BoundRows {
        weights,
        device: output.stats.device,
        on_gpu,
        seconds: output.stats.elapsed.as_secs_f64(),
    })
}

/// What a bind used, for the summary line: "PMVC 32²", "HC grid 64", "MVC",
/// "QMVC" (MVC on a cage's bilinear quads), "PMVC (shorter split) 32²".
pub(super) fn method_label(options: BindOptions, cage: &Cage) -> String {
    let name = options.family_name(cage);
    match options.parameter() {
        Some((spec, value)) => format!("{name} {}", (spec.format)(value)),
        None => name.to_owned(),
    }
}

/// One line on stderr when it is a terminal: what was written and how. Scripts
/// reading a pipe get nothing, as before.
pub(super) fn summary(line: std::fmt::Arguments) {
    use std::io::IsTerminal;
    if std::io::stderr().is_terminal() {
        let _ = writeln!(std::io::stderr(), "pmvc: {line}");
    }
}

pub(super) fn outside_note(input: &BoundInput) -> String {
    match input.classes.outside.len() {
        0 => "all vertices inside the cage".to_owned(),
        1 => "1 vertex outside the cage".to_owned(),
        n => format!("{n} vertices outside the cage"),
    }
}

impl From<BackendArg> for BackendRequest {
    fn from(choice: BackendArg) -> Self {
        match choice {
            BackendArg::Auto => BackendRequest::Auto,
            BackendArg::Cpu => BackendRequest::Cpu,
            BackendArg::Gpu => BackendRequest::Gpu,
        }
    }
}

/// From this size of mesh file `auto` opens a hardware device while the inputs
/// load: about 250,000 vertices of OBJ text, where a GPU may win and its start
/// (0.14–0.18 s on the H200 machine) would otherwise add to the bind.
const AUTO_EARLY_OPEN_BYTES: u64 = 8 << 20;

/// The device to bind on, opened while the inputs load (`mesh_bytes` is the mesh
/// file's size, 0 when unknown): for `gpu` always; for `auto` only for a large
/// mesh. Otherwise nothing is opened here, and `auto` loads a driver only once
/// the work is known and a GPU could win it ([`decide_on`]).
pub(super) fn choose_backend(choice: BackendArg, mesh_bytes: u64) -> Result<Backend> {
    let request = match choice {
        BackendArg::Gpu => BackendRequest::Gpu,
        BackendArg::Auto if mesh_bytes >= AUTO_EARLY_OPEN_BYTES => BackendRequest::Auto,
        _ => return Ok(Backend::Cpu),
    };
    let device = device_for(request).map_err(|error| anyhow!(error).context("--backend gpu"))?;
    Ok(device.map_or(Backend::Cpu, Backend::Gpu))
}

/// Where a bind of `rows` rows of `input` runs, by the one rule of
/// [`crate::gpu::backend_choice`]: on the device [`choose_backend`] opened, or,
/// for `auto`, on one opened now when a hardware GPU could beat the CPU.
pub(super) fn decide_on(
    input: &BoundInput,
    rows: usize,
    choice: &MethodChoice,
    device: &Backend,
) -> Result<Decision> {
    let work = Work::of(choice.options(), rows, &input.cage);
    Ok(match device {
        Backend::Gpu(context) => decide(choice.backend.into(), Some(context), &work),
        Backend::Cpu => decide_and_open(choice.backend.into(), &work)?,
    })
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
    crate::formats::refuse_unwritable(out)?;
    if let Some(warning) = extension_warning(out, extensions, what) {
        warn_line!("pmvc: {warning}");
    }
    Ok(())
}

/// An error before the work starts when a dense `rows` × `cols` weights matrix
/// cannot fit in the memory left, instead of an abort once it is allocated.
fn check_weights_fit(rows: usize, cols: usize, mesh: &std::path::Path) -> Result<()> {
    use crate::budget::{bytes_for, check_memory};
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

/// Read object `object` of the mesh file `path`; where none was named and
/// the file has several, a note says which was read.
pub(super) fn read_mesh(path: &std::path::Path, object: Option<&str>) -> Result<MeshFile> {
    let mut file = crate::formats::load_mesh_object(path, object)?;
    if let Some(note) = file.object_note.take() {
        warn_line!(
            "pmvc: {}: note: {note}; --mesh-object NAME reads one alone",
            shown_path(path)
        );
    }
    Ok(file)
}

/// [`read_mesh`] for the cage, validated.
pub(super) fn read_cage(
    path: &std::path::Path,
    object: Option<&str>,
) -> Result<(Cage, geometry::CageReport)> {
    let (cage, report, read) = crate::formats::load_cage_object(path, object)?;
    if let Some(note) = read.note {
        warn_line!(
            "pmvc: {}: note: {note}; --cage-object NAME reads one alone",
            shown_path(path)
        );
    }
    Ok((cage, report))
}

pub(super) fn check(args: &CheckArgs) -> Result<()> {
    let mesh = read_mesh(&args.input.mesh, args.input.mesh_object.as_deref())?;
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
    let (cage, report) = read_cage(&args.input.cage, args.input.cage_object.as_deref())?;
    let faces = if cage.has_quads() {
        format!(
            "{} quads (bilinear patches) and {} triangles",
            cage.quads().len(),
            cage.lone_triangles().count()
        )
    } else {
        format!("{} triangles", cage.triangles().len())
    };
    say!(
        "cage  {}: {} vertices, {faces}, closed, edge-manifold, consistently oriented",
        shown_path(&args.input.cage),
        cage.vertex_count(),
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
        "{} on {} sampled inside vertices: {:.1}% have a negative weight, most negative {:.4}",
        options.family_name(&cage),
        weights.rows,
        100.0 * negative_rows as f64 / weights.rows.max(1) as f64,
        weights.min().min(0.0)
    );
    super::quad_report::report_split_effect(args, &cage, &points)?;
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
        0 => crate::formats::write_obj_to(out, &mesh.positions, &mesh.triangles),
        _ => crate::formats::write_obj_to(out, cage.positions(), cage.triangles()),
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
