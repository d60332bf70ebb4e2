//! `pmvc check`'s report on a cage with quads: how far the choice of diagonal
//! moves the mesh, per family, at a pose.

use super::CheckArgs;
use crate::coords::split_effect::{split_effect, standard_twist, Spread};
use crate::coords::{BindOptions, Method};
use crate::formats::shown_path;
use crate::geometry::Cage;
use anyhow::Result;
use glam::DVec3;

/// Print, for every family, how far splitting the quads along one diagonal or
/// the other moves the sampled inside vertices, at `--deformed-cage` or the
/// standard twist. Nothing for a cage without quads.
pub(super) fn report_split_effect(args: &CheckArgs, cage: &Cage, points: &[DVec3]) -> Result<()> {
    if !cage.has_quads() || points.is_empty() {
        return Ok(());
    }
    let (pose, pose_name) = match &args.deformed_cage {
        Some(path) => {
            let posed = super::deform::load_pose(path, cage, &args.input)?;
            (posed, shown_path(path))
        }
        None => (
            standard_twist(cage),
            "the cage twisted 45° about its longest axis".to_owned(),
        ),
    };
    say!(
        "quads: how far the diagonal a quad is split along moves {} sampled inside vertices at {pose_name}, as a share of the cage diagonal (mean / max):",
        points.len()
    );
    let percent =
        |spread: Spread| format!("{:.3}% / {:.3}%", 100.0 * spread.mean, 100.0 * spread.max);
    for method in Method::ALL.into_iter().filter(|m| m.spec().quick_to_bind) {
        let options = BindOptions {
            resolution: args.resolution,
            grid: args.grid,
            ..BindOptions::for_method(method)
        };
        let Some(effect) = split_effect(points, cage, &pose, options)? else {
            continue;
        };
        let patches = match (effect.patches_vs_shorter, effect.patches_vs_longer) {
            (Some(shorter), Some(longer)) => format!(
                "; bilinear patches vs shorter {}, vs longer {}",
                percent(shorter),
                percent(longer)
            ),
            _ => "; bound on triangles only".to_owned(),
        };
        let label = match options.parameter() {
            Some((spec, value)) => format!("{} {}", effect.family, (spec.format)(value)),
            None => effect.family.clone(),
        };
        say!(
            "      {label}: shorter vs longer {}{patches}",
            percent(effect.shorter_vs_longer)
        );
    }
    Ok(())
}
