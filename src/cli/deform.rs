//! `pmvc deform`: move every mesh vertex with the cage, with fresh weights or
//! those `pmvc bind` stored, and write the mesh as OBJ or the points as `.npy`.

use super::commands::{
    check_output, compute_weights, load_input, method_label, outside_note, outside_policy, summary,
    InputRules,
};
use super::weights_format::{read_weights_for, stored_family};
use super::DeformArgs;
use crate::geometry::{self, bounds_of, find_crossing, shown_path, Cage};
use anyhow::{bail, Result};
use glam::DVec3;
use std::path::Path;

/// Whether `path` asks for the deformed points as a `.npy` array.
fn writes_points_npy(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

pub(super) fn deform(args: &DeformArgs) -> Result<()> {
    let started = std::time::Instant::now();
    let mut inputs = vec![
        args.input.mesh.as_path(),
        args.input.cage.as_path(),
        args.deformed_cage.as_path(),
    ];
    inputs.extend(args.weights.as_deref());
    check_output(
        &args.out,
        &inputs,
        &["obj", "npy"],
        "an OBJ mesh (float64 points when it ends in .npy)",
    )?;
    // The family of stored weights decides what the warnings say of vertices
    // outside the cage, so it is known before the inputs are read.
    let (method, policy) = match &args.weights {
        Some(path) => {
            let method = stored_family(path, args.method.method)?;
            (method, outside_policy(Some(method)))
        }
        None => (args.method.method, outside_policy(Some(args.method.method))),
    };
    let holds_weights = args.weights.is_none();
    let input = load_input(
        &args.input,
        &InputRules {
            method,
            strict: args.method.strict,
            outside_policy: policy,
            resident_rows: &|rows, _| if holds_weights { rows } else { 0 },
        },
    )?;
    let pose = geometry::load_mesh(&args.deformed_cage)?;
    let (expected, found) = (input.cage.vertex_count(), pose.mesh.positions.len());
    if found != expected {
        bail!(
            "{}: the deformed cage has {found} vertices, but the cage {} has {expected}; a pose must keep the cage's vertices in order",
            shown_path(&args.deformed_cage),
            shown_path(&args.input.cage)
        );
    }
    warn_if_crossed(&input.cage, &pose.mesh.positions, &args.deformed_cage);
    let weights = match &args.weights {
        Some(path) => read_weights_for(path, &input, method)?,
        None => compute_weights(&input, &args.method)?,
    };
    // Displacement form, p + Σλ(c̃ − c): the same as Σλc̃ for weights that
    // reproduce their points at rest (every family pmvc binds), and better in f32:
    // Σλc̃ carries each weight's rounding times the cage's distance from the
    // origin, this form only times how far the cage moved. Rows were checked to
    // sum to 1 when read, so a translation of the cage moves every vertex with it.
    let moves = method.column_displacements(&input.cage, &pose.mesh.positions);
    let deformed: Vec<DVec3> = weights.apply_displacements(&input.mesh.mesh.positions, &moves);
    if writes_points_npy(&args.out) {
        geometry::write_points_npy(&args.out, &deformed)?;
    } else {
        geometry::write_deformed_mesh(&input.mesh, &deformed, &args.out)?;
    }
    let source = match &args.weights {
        Some(path) => format!("weights from {}", shown_path(path)),
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

/// A warning, not an error, when the cage in its pose crosses itself: artists
/// fold cages on purpose, but the mesh may then pass through itself there. The
/// faces are the cage file's, 1-based, as `pmvc check` names them.
fn warn_if_crossed(cage: &Cage, posed: &[DVec3], pose_path: &Path) {
    let (low, high) = bounds_of(posed);
    let Some(crossing) = find_crossing(posed, cage.triangles(), (high - low).length()) else {
        return;
    };
    let face = |triangle: usize| {
        cage.triangle_faces()
            .get(triangle)
            .map_or(triangle, |&face| face as usize)
            + 1
    };
    warn_line!(
        "pmvc: {}: warning: the deformed cage crosses itself: faces {} and {} intersect; the mesh may pass through itself there (deformed anyway)",
        shown_path(pose_path),
        face(crossing.first),
        face(crossing.second)
    );
}
