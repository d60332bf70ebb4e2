//! The posing tools applied to the document: the pose a transform gives the
//! selection, about the tools' pivot, with their soft selection and symmetry
//! (`pose_tools.rs` is the geometry, knowing nothing of the document). Shared
//! by the viewport's transforms, the Posing tools panel and the editor's API.

use super::commands::Command;
use super::document::Document;
use super::model::Model;
use super::pose_tools::{
    follow_weights, mean_edge_length, mirror_partners, posed, Pivot, PoseToolSettings, Transform,
};
use glam::DVec3;

/// The pose `transform` gives `start` with the document's selection and the
/// tools' pivot, soft selection and symmetry.
pub fn pose_transformed(
    document: &Document,
    tools: &PoseToolSettings,
    start: &[DVec3],
    transform: &Transform,
) -> Vec<DVec3> {
    let diagonal = document.cage().diagonal();
    let soft = tools.soft_selection.then_some(tools.soft_radius * diagonal);
    let weights = follow_weights(start, document.selection(), soft);
    let partners = symmetry_partners(document, tools);
    let symmetry = partners.as_ref().map(|(axis, p)| (*axis, p.as_slice()));
    posed(
        start,
        &weights,
        transform,
        pivot_of(document, tools, start),
        symmetry,
    )
}

/// What rotations and scalings turn about: the 3D cursor, or the selection's
/// centre in `pose` (the scene's centre when nothing is selected).
pub(super) fn pivot_of(document: &Document, tools: &PoseToolSettings, pose: &[DVec3]) -> DVec3 {
    let selection = document.selection();
    match tools.pivot {
        Pivot::Cursor => tools.cursor,
        Pivot::SelectionCentre if !selection.is_empty() => {
            selection.iter().filter_map(|&i| pose.get(i)).sum::<DVec3>() / selection.len() as f64
        }
        Pivot::SelectionCentre => document.bounding_sphere().0,
    }
}

/// Handles with no mirror partner under the symmetry in use.
pub fn handles_without_partner(document: &Document, tools: &PoseToolSettings) -> usize {
    symmetry_partners(document, tools).map_or(0, |(_, partners)| {
        partners.iter().filter(|p| p.is_none()).count()
    })
}

/// Under the symmetry in use, its axis and each handle's mirror partner in the
/// rest cage, across the tools' plane (the cage's bounding-box centre or the 3D
/// cursor), within the tools' tolerance (a share of the mean cage edge).
pub fn symmetry_partners(
    document: &Document,
    tools: &PoseToolSettings,
) -> Option<(usize, Vec<Option<usize>>)> {
    let axis = tools.symmetry?;
    let cage = document.cage();
    let rest = cage.positions();
    let tolerance = tools.mirror_tolerance * mean_edge_length(rest, cage.triangles());
    Some((
        axis,
        mirror_partners(rest, axis, tools.mirror_offset(rest, axis), tolerance),
    ))
}

/// Apply `transform` to the selection as one undo step.
pub fn transform_selection(model: &mut Model, tools: &PoseToolSettings, transform: Transform) {
    let start = model.document().pose().to_vec();
    let pose = pose_transformed(model.document(), tools, &start, &transform);
    model.apply(Command::edit_pose(pose));
}
