//! `pmvc bind`: the weights of every mesh vertex, computed whole or in blocks of
//! rows and written as `.npy` (or Green coordinates' `.npz`).

use super::commands::{
    bind_rows, check_output, choose_backend, load_input, method_label, outside_note,
    outside_policy, progress_bar, summary, BoundInput, InputRules,
};
use super::weights_format::{check_weights_format, writes_npz};
use super::BindArgs;
use crate::coords::npy::{npy_file_bytes, npy_preamble, write_f32_values, write_npy_to};
use crate::coords::npz::{npz_payload_bytes, write_npz_to};
use crate::geometry::{shown_path, PendingOutput};
use crate::gpu::Backend;
use anyhow::Result;

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
    let method = args.method.method;
    let input = load_input(
        &args.input,
        &InputRules {
            method,
            strict: args.method.strict,
            outside_policy: outside_policy(Some(method)),
            resident_rows: &|rows, columns| bind_resident_rows(args, rows, columns),
        },
    )?;
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
