//! `pmvc bind`: the weights of every mesh vertex, computed whole or in blocks of
//! rows and written as `.npy` (or Green coordinates' `.npz`), with what a reader
//! needs to trust them beside them: `W.json` (the family, its parameters, the
//! backend, the bind's time, the columns, the inputs; [`crate::formats::metadata`])
//! and `W.classes.npy` (each row's class). The three are replaced together or
//! not at all.

use super::commands::{
    bind_rows, check_output, choose_backend, load_input, method_label, outside_note,
    outside_policy, progress_bar, summary, BoundInput, InputRules,
};
use super::weights_format::{check_weights_format, writes_npz};
use super::BackendArg;
use super::BindArgs;
use crate::coords::{bind_cpu_f64, BindProgress, Dtype, DtypeError};
use crate::formats::metadata::{
    class_codes, classes_path, metadata_path, write_classes_npy_to, BindRecord, WeightsMetadata,
};
use crate::formats::npy::{
    npy_file_bytes_of, npy_preamble, npy_preamble_of, write_f32_values, write_values,
};
use crate::formats::npz::{npz_payload_bytes_of, write_npz, write_npz_values};
use crate::formats::{
    refuse_same_file, refuse_unwritable, resolve_output, shown_path, OutputSet, OutputTarget,
};
use crate::gpu::Backend;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Rows a streamed bind computes and writes at a time when `--block-rows` is not
/// given: 128 MiB of weights. Two blocks are held at once (one written while the
/// next is bound), so memory stays at 256 MiB of weights however large the mesh.
const BLOCK_BYTES: usize = 128 << 20;

/// Rows bound at a time by `pmvc bind`: all of them for a family that solves
/// for the whole cage or is written as a `.npz` (array after array), a block for
/// one whose rows are independent.
fn block_rows(args: &BindArgs, rows: usize, columns: usize) -> usize {
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

/// Rows held at once when `rows` are bound `block` at a time: all of them, or
/// two blocks, the one being written and the next, bound meanwhile.
fn resident_rows(block: usize, rows: usize) -> usize {
    if block >= rows {
        rows
    } else {
        block.saturating_mul(2).min(rows)
    }
}

/// Rows held at once by `pmvc bind` ([`resident_rows`] of [`block_rows`]).
fn bind_resident_rows(args: &BindArgs, rows: usize, columns: usize) -> usize {
    resident_rows(block_rows(args, rows, columns), rows)
}

/// The class mask and metadata that go beside the weights `out`, each refused
/// by the rules `--out` is held to (an input, a file its user may not write, a
/// folder or block device). None beside a device or pipe, which has no folder
/// to put them in.
fn companion_paths(out: &Path, inputs: &[&Path]) -> Result<Vec<PathBuf>> {
    if matches!(resolve_output(out)?, OutputTarget::Stream(_)) {
        return Ok(Vec::new());
    }
    let paths = vec![classes_path(out), metadata_path(out)];
    for path in &paths {
        refuse_same_file(path, inputs)?;
        refuse_unwritable(path)?;
        resolve_output(path)?;
    }
    Ok(paths)
}

/// How the bind went, for the metadata and the summary line.
#[derive(Default)]
struct BindDone {
    device: String,
    on_gpu: bool,
    seconds: f64,
}

pub(super) fn bind(args: &BindArgs) -> Result<()> {
    let inputs = [args.input.mesh.as_path(), args.input.cage.as_path()];
    check_weights_format(args)?;
    let dtype = args.dtype;
    dtype.check_family(args.method.method)?;
    let (extensions, what): (&[&str], _) = if writes_npz(args.method.method) {
        (
            &["npz"],
            format!("phi and psi {} arrays in .npz format", dtype.id()),
        )
    } else {
        (&["npy"], format!("{} weights in .npy format", dtype.id()))
    };
    check_output(&args.out, &inputs, extensions, &what)?;
    let companions = companion_paths(&args.out, &inputs)?;
    // Opening a device takes a tenth of a second or more, mostly waiting on the
    // driver: for `gpu`, and `auto` on a large mesh, it opens while the inputs load.
    // Float64 weights are computed on the CPU.
    let choice = if dtype == Dtype::Float64 {
        if args.method.backend == BackendArg::Gpu {
            warn_line!("pmvc: notice: {}", DtypeError::NotOnGpu);
        }
        BackendArg::Cpu
    } else {
        args.method.backend
    };
    let mesh_bytes = std::fs::metadata(&args.input.mesh).map_or(0, |meta| meta.len());
    let probe = std::thread::spawn(move || choose_backend(choice, mesh_bytes));
    let method = args.method.method;
    let input = load_input(
        &args.input,
        &InputRules {
            options: args.method.options(),
            strict: args.method.strict,
            outside_policy: outside_policy(Some(method)),
            // Rows of float64 hold twice the bytes the budget counts per row.
            resident_rows: &|rows, columns| match dtype {
                Dtype::Float32 => bind_resident_rows(args, rows, columns),
                Dtype::Float64 => rows.saturating_mul(2),
            },
        },
    )?;
    let backend = probe
        .join()
        .map_err(|_| anyhow::anyhow!("internal error: the adapter probe panicked"))??;
    let rows = input.mesh.mesh.positions.len();
    let columns = args.method.options().columns(&input.cage);
    // Opened before the work, so that a full disk or an unwritable folder is
    // reported now, and a signal during the bind removes the temporary files.
    let mut paths = vec![args.out.as_path()];
    paths.extend(companions.iter().map(PathBuf::as_path));
    let outputs = OutputSet::create(&paths)?;
    outputs.check_space(
        0,
        if writes_npz(method) {
            npz_payload_bytes_of(rows, columns, dtype)
        } else {
            npy_file_bytes_of(rows, columns, dtype)
        },
    )?;
    let done = match dtype {
        Dtype::Float32 => bind_to(args, &input, backend, outputs, rows, columns)?,
        Dtype::Float64 => bind_to_f64(args, &input, outputs, rows)?,
    };
    let shape = if writes_npz(method) {
        let vertices = input.cage.vertex_count();
        format!(
            "phi {rows} × {vertices} and psi {rows} × {} {}",
            columns - vertices,
            dtype.id()
        )
    } else {
        format!("{rows} × {columns} {} weights", dtype.id())
    };
    let beside = match companions.as_slice() {
        [classes, json] => format!(
            " (classes in {}, metadata in {})",
            shown_path(classes),
            shown_path(json)
        ),
        _ => String::new(),
    };
    summary(format_args!(
        "wrote {}{beside}: {shape} ({}, {}) bound in {:.2} s; {}",
        shown_path(&args.out),
        method_label(args.method.options(), &input.cage),
        done.device,
        done.seconds,
        outside_note(&input)
    ));
    Ok(())
}

/// `W.json` for weights bound from `input` as `done` says.
fn metadata_json(args: &BindArgs, input: &BoundInput, done: &BindDone) -> String {
    let mut metadata = WeightsMetadata::new(&BindRecord {
        options: args.method.options(),
        cage: &input.cage,
        points: &input.mesh.mesh.positions,
        classes: &input.classes.classes,
        backend: if done.on_gpu { "gpu" } else { "cpu" },
        device: &done.device,
        seconds: done.seconds,
        mesh_file: &args.input.mesh.to_string_lossy(),
        cage_file: &args.input.cage.to_string_lossy(),
        mesh_object: args.input.mesh_object.as_deref(),
        cage_object: args.input.cage_object.as_deref(),
        weights_file: &args.out,
    });
    metadata.dtype = args.dtype.id().to_owned();
    metadata.to_json_pretty()
}

/// `--dtype f64`: bind every row on the CPU in float64 (a family whose rows
/// are independent, so Green's `.npz` too), then write the weights, the class
/// mask and the metadata (`outputs` holds the weights first).
fn bind_to_f64(
    args: &BindArgs,
    input: &BoundInput,
    outputs: OutputSet,
    rows: usize,
) -> Result<BindDone> {
    let bar = progress_bar(rows as u64, args.method.method);
    let options = args.method.options();
    let progress = BindProgress::new(rows);
    let started = std::time::Instant::now();
    let weights = std::thread::scope(|scope| {
        let binding = scope.spawn(|| {
            bind_cpu_f64(
                &input.mesh.mesh.positions,
                &input.classes.classes,
                &input.cage,
                options,
                &progress,
            )
        });
        while !binding.is_finished() && !bar.is_hidden() {
            bar.set_position(progress.done() as u64);
            std::thread::sleep(std::time::Duration::from_millis(50));
        }
        binding
            .join()
            .map_err(|_| anyhow::anyhow!("internal error: the bind thread panicked"))
    })??;
    bar.finish_and_clear();
    let done = BindDone {
        device: "CPU".to_owned(),
        on_gpu: false,
        seconds: started.elapsed().as_secs_f64(),
    };
    let json = metadata_json(args, input, &done);
    let codes = class_codes(&input.classes.classes);
    let preamble = npy_preamble_of(&args.out, rows, weights.cols, Dtype::Float64)?;
    let vertices = args.method.method.vertex_columns(&input.cage);
    let npz = writes_npz(args.method.method);
    outputs.finish_seekable(|index, out| match index {
        0 if npz => write_npz_values(out, &args.out, (&weights.values, weights.cols), vertices),
        0 => {
            out.write_all(&preamble)?;
            write_values(out, &weights.values)
        }
        1 => write_classes_npy_to(out, &codes),
        _ => out.write_all(json.as_bytes()),
    })?;
    Ok(done)
}

/// Bind and write the weights, whole or in blocks of rows, then the class mask
/// and the metadata (`outputs` holds the weights first, then any companions).
fn bind_to(
    args: &BindArgs,
    input: &BoundInput,
    backend: Backend,
    outputs: OutputSet,
    rows: usize,
    columns: usize,
) -> Result<BindDone> {
    let block = block_rows(args, rows, columns);
    let bar = progress_bar(rows as u64, args.method.method);
    let codes = class_codes(&input.classes.classes);
    let preamble = npy_preamble(&args.out, rows, columns)?;
    if block >= rows {
        let bound = bind_rows(input, 0..rows, &args.method, &backend, &bar)?;
        bar.finish_and_clear();
        let done = BindDone {
            device: bound.device,
            on_gpu: bound.on_gpu,
            seconds: bound.seconds,
        };
        let json = metadata_json(args, input, &done);
        let npz = writes_npz(args.method.method);
        let vertices = args.method.method.vertex_columns(&input.cage);
        let weights = &bound.weights;
        outputs.finish_seekable(|index, out| match index {
            0 if npz => write_npz(out, &args.out, weights, vertices),
            0 => {
                out.write_all(&preamble)?;
                write_f32_values(out, &weights.values)
            }
            1 => write_classes_npy_to(out, &codes),
            _ => out.write_all(json.as_bytes()),
        })?;
        return Ok(done);
    }
    // In blocks of rows: a second thread binds block k + 1 while this one writes
    // block k, handing each over when the writer is ready for it (a rendezvous
    // channel), so at most two blocks are held ([`resident_rows`]) and the disk
    // is the only limit. The metadata, written last, has the whole bind's time.
    let mut bind_error = None;
    let mut done = BindDone::default();
    let written = outputs.finish(|index, out| match index {
        0 => {
            out.write_all(&preamble)?;
            std::thread::scope(|scope| {
                let (sender, receiver) = std::sync::mpsc::sync_channel(0);
                let (method, backend, bar) = (&args.method, &backend, &bar);
                let binder = scope.spawn(move || {
                    for start in (0..rows).step_by(block) {
                        let range = start..(start + block).min(rows);
                        let bound = bind_rows(input, range, method, backend, bar);
                        let failed = bound.is_err();
                        // A writer that stopped has dropped the receiver.
                        if sender.send(bound).is_err() || failed {
                            return;
                        }
                    }
                });
                let mut result = Ok(());
                for bound in &receiver {
                    match bound {
                        Ok(bound) => {
                            done.device = bound.device;
                            done.on_gpu = bound.on_gpu;
                            done.seconds += bound.seconds;
                            result = write_f32_values(out, &bound.weights.values);
                        }
                        Err(error) => {
                            bind_error = Some(error);
                            result = Err(std::io::Error::other("the bind failed"));
                        }
                    }
                    if result.is_err() {
                        break;
                    }
                }
                // The binder stops at its next hand-over once this is gone.
                drop(receiver);
                if binder.join().is_err() {
                    return Err(std::io::Error::other(
                        "internal error: the bind thread panicked",
                    ));
                }
                result
            })
        }
        1 => write_classes_npy_to(out, &codes),
        _ => out.write_all(metadata_json(args, input, &done).as_bytes()),
    });
    bar.finish_and_clear();
    match (bind_error, written) {
        (Some(error), _) => Err(error),
        (None, result) => Ok(result.map(|()| done)?),
    }
}

#[cfg(test)]
mod tests {
    use super::resident_rows;
    use crate::coords::QuadSplit;
    use crate::formats::metadata::read_classes_npy;
    use crate::formats::npy::{read_npy, ExpectedArray};
    use crate::geometry::generalized_winding_number;
    use crate::geometry::procedural_quads::twisted_box;
    use glam::DVec3;
    use std::fmt::Write as _;

    /// `pmvc bind --triangulate` classes each row against the cage it binds,
    /// the quads split into triangles, not against the bilinear patches: the
    /// class mask it writes is the split cage's own winding number, and PMVC
    /// rows it calls inside are never negative.
    #[test]
    fn a_split_bind_writes_the_classes_of_the_cage_it_bound() {
        let cage = twisted_box(2.0, 0.6);
        let folder = tempfile::tempdir().expect("a temporary folder");
        let mut cage_text = String::new();
        for p in cage.positions() {
            let _ = writeln!(cage_text, "v {:?} {:?} {:?}", p.x, p.y, p.z);
        }
        for face in cage.polygons() {
            let corners: Vec<String> = face.iter().map(|i| (i + 1).to_string()).collect();
            let _ = writeln!(cage_text, "f {}", corners.join(" "));
        }
        // A shell around the bent sides, where a patch and its triangles disagree.
        let mut points = Vec::new();
        let mut mesh_text = String::new();
        for a in 0..40 {
            let angle = (a as f64 + 0.37) * std::f64::consts::TAU / 40.0;
            for r in 0..10 {
                let radius = 0.7 + 0.75 * (r as f64 + 0.41) / 10.0;
                for z in 0..6 {
                    let p = DVec3::new(
                        radius * angle.cos(),
                        radius * angle.sin(),
                        0.4 + 0.2 * z as f64,
                    );
                    let _ = writeln!(mesh_text, "v {:?} {:?} {:?}", p.x, p.y, p.z);
                    points.push(p);
                }
            }
        }
        let cage_file = folder.path().join("cage.obj");
        let mesh_file = folder.path().join("points.obj");
        std::fs::write(&cage_file, cage_text).expect("cage written");
        std::fs::write(&mesh_file, mesh_text).expect("points written");
        let by_patches = crate::geometry::classify_points(&cage, &points).outside;
        for (split, diagonal) in [
            (QuadSplit::Shorter, "shorter"),
            (QuadSplit::Longer, "longer"),
        ] {
            let out = folder.path().join(format!("W-{diagonal}.npy"));
            let cli = <super::super::Cli as clap::Parser>::try_parse_from([
                "pmvc",
                "bind",
                "--mesh",
                mesh_file.to_str().unwrap(),
                "--cage",
                cage_file.to_str().unwrap(),
                "--method",
                "pmvc",
                "--resolution",
                "8",
                "--backend",
                "cpu",
                "--triangulate",
                diagonal,
                "--out",
                out.to_str().unwrap(),
            ])
            .expect("the arguments parse");
            let Some(super::super::Command::Bind(args)) = cli.command else {
                panic!("not a bind");
            };
            super::bind(&args).expect("the bind succeeds");
            let bound = cage.split_quads(split);
            let expected: Vec<i8> = points
                .iter()
                .map(|&p| {
                    if generalized_winding_number(&bound, p) > 0.5 {
                        0
                    } else {
                        2
                    }
                })
                .collect();
            let classes = read_classes_npy(
                &out.with_file_name(format!("W-{diagonal}.classes.npy")),
                points.len(),
            )
            .expect("the classes are written");
            let outside = expected.iter().filter(|&&c| c == 2).count();
            assert!(
                outside.abs_diff(by_patches.len()) >= 50,
                "{diagonal}: the split changes too few classes"
            );
            let wrong = (0..points.len())
                .filter(|&i| classes[i] != expected[i])
                .count();
            assert_eq!(
                wrong, 0,
                "{diagonal}: {wrong} rows classed against the patches"
            );
            let weights = read_npy(
                &out,
                ExpectedArray::cage_vertices(points.len(), cage.vertex_count()),
            )
            .expect("the weights are written");
            for row in (0..points.len()).filter(|&row| classes[row] == 0) {
                let min = weights
                    .row(row)
                    .iter()
                    .copied()
                    .fold(f32::INFINITY, f32::min);
                assert!(
                    min >= 0.0,
                    "{diagonal}: row {row} inside has a weight {min}"
                );
            }
        }
    }

    /// The memory check counts the block being written and the one bound
    /// meanwhile.
    #[test]
    fn a_streamed_bind_holds_two_blocks() {
        assert_eq!(resident_rows(100, 1000), 200);
        assert_eq!(resident_rows(600, 1000), 1000);
        assert_eq!(resident_rows(1000, 1000), 1000);
        assert_eq!(resident_rows(usize::MAX / 2 + 1, usize::MAX), usize::MAX);
    }
}
