//! `pmvc deform`: move every mesh vertex with the cage, with fresh weights or
//! those `pmvc bind` stored, and write the mesh as OBJ or glTF (with more poses
//! as morph targets, and an animation through them) or the points as `.npy`.

use super::commands::{
    check_output, compute_weights, load_input, method_label, outside_note, outside_policy, summary,
    InputRules,
};
use super::weights_format::{is_npz, read_weights_for, stored_family, writes_npz};
use super::{CageInput, DeformArgs};
use crate::coords::{AnyWeights, BindOptions, Dtype, Method};
use crate::formats::gltf::{is_gltf_path, write_gltf, AnimationKey, GltfPose, GltfScene};
use crate::formats::metadata::{metadata_path, read_metadata, WeightsMetadata};
use crate::formats::{shown_path, LoadError, ObjectError};
use crate::geometry::{bounds_of, find_crossing, Cage};
use anyhow::{bail, Result};
use glam::DVec3;
use std::path::{Path, PathBuf};

/// What `--weights` brings: the family its rows apply as and, when `pmvc bind`
/// wrote `W.json` beside it, that metadata (and where it was read).
struct StoredWeights {
    options: BindOptions,
    metadata: Option<(PathBuf, WeightsMetadata)>,
}

/// Read `W.json` beside the weights `path` when it is there: the family and
/// parameters come from it, and its file must be the format that family is
/// written in. Without it (weights from an older pmvc, or saved by numpy) one
/// warning says that nothing can be checked, and the file's format and
/// `--method` decide the family, as before.
fn stored_weights(path: &Path, asked: Method) -> Result<StoredWeights> {
    let json = metadata_path(path);
    if !json.exists() {
        let method = stored_family(path, asked)?;
        warn_line!(
            "pmvc: {}: warning: no {} beside it (weights from an older pmvc, or saved by numpy), so they cannot be checked against the mesh and cage, and nothing records how they were bound",
            shown_path(path),
            shown_path(&json)
        );
        return Ok(StoredWeights {
            options: BindOptions::for_method(method),
            metadata: None,
        });
    }
    let metadata = read_metadata(&json)?;
    let options = metadata.options(&json)?;
    let method = options.method;
    if writes_npz(method) != is_npz(path) {
        let format = |npz: bool| if npz { ".npz" } else { ".npy" };
        bail!(
            "{}: it is a {}, but its metadata {} says it holds {} coordinates (--method {}), which are written as {}",
            shown_path(path),
            format(is_npz(path)),
            shown_path(&json),
            method.name(),
            method.id(),
            format(writes_npz(method)),
        );
    }
    Ok(StoredWeights {
        options,
        metadata: Some((json, metadata)),
    })
}

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
    inputs.extend(args.poses.iter().map(PathBuf::as_path));
    let gltf = is_gltf_path(&args.out);
    if !gltf {
        let flag = match (args.poses.is_empty(), args.animate) {
            (_, Some(_)) => Some("--animate"),
            (false, None) => Some("--poses"),
            (true, None) => None,
        };
        if let Some(flag) = flag {
            bail!(
                "{}: {flag} needs glTF output (--out ending in .glb or .gltf), which holds poses as morph targets",
                shown_path(&args.out)
            );
        }
    }
    check_output(
        &args.out,
        &inputs,
        &["obj", "npy", "glb", "gltf"],
        "an OBJ or glTF mesh",
    )?;
    // The family of stored weights decides what the warnings say of vertices
    // outside the cage, so it is known before the inputs are read.
    let stored = match &args.weights {
        Some(path) => Some(stored_weights(path, args.method.method)?),
        None => None,
    };
    let (options, policy) = match &stored {
        Some(stored) => {
            let recorded = stored.metadata.is_some() || writes_npz(stored.options.method);
            let known = recorded.then_some(stored.options.method);
            (stored.options, outside_policy(known))
        }
        None => (
            args.method.options(),
            outside_policy(Some(args.method.method)),
        ),
    };
    let mut options = options;
    for (parameter, value) in super::deform_settings(args.bulging, args.local_blend) {
        options.set(parameter, value);
        if options
            .deform_parameters()
            .all(|(spec, _)| spec.key != parameter)
        {
            let spec = parameter.spec();
            warn_line!(
                "pmvc: note: {} is ignored: {} weights read no {} (Somigliana coordinates do)",
                spec.flag,
                options.method.name(),
                spec.label.to_lowercase()
            );
        }
    }
    let method = options.method;
    let holds_weights = args.weights.is_none();
    let input = load_input(
        &args.input,
        &InputRules {
            options,
            strict: args.method.strict,
            outside_policy: policy,
            resident_rows: &|rows, _| if holds_weights { rows } else { 0 },
        },
    )?;
    let pose = load_pose(&args.deformed_cage, &input.cage, &args.input)?;
    let poses = args
        .poses
        .iter()
        .map(|path| load_pose(path, &input.cage, &args.input))
        .collect::<Result<Vec<_>>>()?;
    if let Some((json, metadata)) = stored.as_ref().and_then(|s| s.metadata.as_ref()) {
        metadata.check_inputs(json, &input.mesh.mesh.positions, &input.cage)?;
    }
    // Stored weights are float64 where their metadata says so.
    let dtype = stored
        .as_ref()
        .and_then(|stored| stored.metadata.as_ref())
        .map_or(Dtype::Float32, |(_, metadata)| metadata.dtype());
    let weights = match &args.weights {
        Some(path) => read_weights_for(path, &input, method, dtype)?,
        None => AnyWeights::F32(compute_weights(&input, &args.method)?),
    };
    // Displacement form, p + Σλ(c̃ − c): the same as Σλc̃ for weights that
    // reproduce their points at rest (every family pmvc binds), and better in f32:
    // Σλc̃ carries each weight's rounding times the cage's distance from the
    // origin, this form only times how far the cage moved. Rows were checked to
    // sum to 1 when read, so a translation of the cage moves every vertex with it.
    // Green's ψ columns follow the triangles the weights were bound on.
    let deform = |pose: &[DVec3]| -> Vec<DVec3> {
        let moves = options.column_moves(&input.cage, pose);
        weights.apply_moves(&input.mesh.mesh.positions, &moves)
    };
    let deformed = deform(&pose);
    if writes_points_npy(&args.out) {
        crate::formats::write_points_npy(&args.out, &deformed)?;
    } else if gltf {
        let shapes: Vec<(String, Vec<DVec3>)> = args
            .poses
            .iter()
            .zip(&poses)
            .map(|(path, pose)| (pose_name(path), deform(pose)))
            .collect();
        let targets: Vec<GltfPose> = shapes
            .iter()
            .map(|(name, positions)| GltfPose { name, positions })
            .collect();
        let keys = args
            .animate
            .map(|seconds| AnimationKey::evenly(targets.len(), seconds));
        write_gltf(
            &args.out,
            &GltfScene {
                mesh: &input.mesh,
                base: &deformed,
                poses: &targets,
                animation: keys.as_deref(),
            },
        )?;
    } else {
        for library in crate::formats::write_deformed_mesh(&input.mesh, &deformed, &args.out)? {
            warn_line!("pmvc: {}: note: {library}", shown_path(&args.out));
        }
    }
    let source = match (&args.weights, &stored) {
        (Some(path), Some(stored)) if stored.metadata.is_some() => format!(
            "{} weights from {}",
            method_label(stored.options, &input.cage),
            shown_path(path)
        ),
        (Some(path), _) => format!("weights from {}", shown_path(path)),
        (None, _) => format!("{} weights", method_label(options, &input.cage)),
    };
    // Deformation settings away from their defaults ("γ 2.5, local blend 0.5").
    let labels = options.deform_labels();
    let settings = match labels.is_empty() {
        true => String::new(),
        false => format!(" at {}", labels.join(", ")),
    };
    let source = source + &settings;
    let extra = match (args.poses.len(), args.animate) {
        (0, _) => String::new(),
        (poses, None) => format!(", and {poses} poses as morph targets"),
        (poses, Some(seconds)) => format!(
            ", and {poses} poses as morph targets with a {seconds} s animation through them"
        ),
    };
    summary(format_args!(
        "wrote {}: {} vertices deformed with {source}{extra} in {:.2} s; {}",
        shown_path(&args.out),
        deformed.len(),
        started.elapsed().as_secs_f64(),
        outside_note(&input)
    ));
    Ok(())
}

/// A pose of the cage read from `path`: its vertices, which must be as many as
/// the cage's, in order. A pose that crosses itself gets a warning. With
/// `--cage-object`, a pose file with named objects gives that object (one
/// exported from the same scene); one without (as pmvc saves poses) is read whole.
pub(super) fn load_pose(path: &Path, cage: &Cage, input: &CageInput) -> Result<Vec<DVec3>> {
    let cage_path = input.cage.as_path();
    let object = input.cage_object.as_deref();
    let pose = match crate::formats::load_mesh_object(path, object) {
        Err(LoadError::Object { source, .. }) if names_no_object(&source) => {
            crate::formats::load_mesh(path)?
        }
        read => read?,
    };
    if let Some(note) = &pose.object_note {
        warn_line!(
            "pmvc: {}: note: {note}; --cage-object NAME reads one alone",
            shown_path(path)
        );
    }
    let (expected, found) = (cage.vertex_count(), pose.mesh.positions.len());
    if found != expected {
        bail!(
            "{}: the deformed cage has {found} vertices, but the cage {} has {expected}; a pose must keep the cage's vertices in order",
            shown_path(path),
            shown_path(cage_path)
        );
    }
    warn_if_crossed(cage, &pose.mesh.positions, path);
    Ok(pose.mesh.positions)
}

/// Whether a file had no named objects to pick from.
fn names_no_object(error: &ObjectError) -> bool {
    match error {
        ObjectError::NotFound { names, .. } => names.is_empty(),
        ObjectError::Unnamed { .. } => true,
        ObjectError::Ambiguous { .. } => false,
    }
}

/// A morph target's name: its pose file's stem (`wave` for `poses/wave.obj`).
fn pose_name(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| path.to_string_lossy(), |stem| stem.to_string_lossy())
        .into_owned()
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
