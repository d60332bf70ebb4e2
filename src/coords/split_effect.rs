//! How far the choice of diagonal moves a deformed mesh: the same family bound
//! on the cage's quads split along their shorter and along their longer
//! diagonal, and as bilinear patches, then deformed to one pose. On a cage of
//! quads, a family whose weights depend on that invisible choice is comparing
//! splits, not families; `pmvc check` and the benchmarks report this.

use super::{bind_cpu, BindFailure, BindOptions, BindProgress, QuadSplit};
use crate::geometry::Cage;
use glam::{DQuat, DVec3};

/// Distances between two deformations of the same points, as shares of the
/// rest cage's diagonal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    pub mean: f64,
    pub max: f64,
}

impl Spread {
    /// Mean and largest distance between `a[i]` and `b[i]`, over `diagonal`.
    pub fn between(a: &[DVec3], b: &[DVec3], diagonal: f64) -> Spread {
        let distances: Vec<f64> = a.iter().zip(b).map(|(p, q)| p.distance(*q)).collect();
        let count = distances.len().max(1) as f64;
        Spread {
            mean: distances.iter().sum::<f64>() / count / diagonal,
            max: distances.iter().copied().fold(0.0, f64::max) / diagonal,
        }
    }
}

/// One family's sensitivity to the split.
#[derive(Clone, Debug)]
pub struct SplitEffect {
    /// What was bound: the family's name on quads ("QMVC", "PMVC", …).
    pub family: String,
    /// Shorter against longer diagonal.
    pub shorter_vs_longer: Spread,
    /// Bilinear patches against the shorter diagonal (the split files used to get);
    /// `None` for a family that takes only triangles.
    pub patches_vs_shorter: Option<Spread>,
    /// Bilinear patches against the longer diagonal.
    pub patches_vs_longer: Option<Spread>,
}

/// The standard pose for comparing splits when none is given: the cage twisted
/// by 45° about its bounding box's longest axis, through the box's centre, the
/// angle growing linearly from one end to the other. An affine pose would show
/// nothing: every family reproduces it whatever the split.
pub fn standard_twist(cage: &Cage) -> Vec<DVec3> {
    let (lo, hi) = crate::geometry::bounds_of(cage.positions());
    let size = hi - lo;
    let axis_index = if size.x >= size.y && size.x >= size.z {
        0
    } else if size.y >= size.z {
        1
    } else {
        2
    };
    let mut axis = DVec3::ZERO;
    axis[axis_index] = 1.0;
    let centre = 0.5 * (lo + hi);
    let length = size[axis_index].max(f64::MIN_POSITIVE);
    cage.positions()
        .iter()
        .map(|&p| {
            let along = (p[axis_index] - lo[axis_index]) / length - 0.5;
            let turn = DQuat::from_axis_angle(axis, along * std::f64::consts::FRAC_PI_4);
            centre + turn * (p - centre)
        })
        .collect()
}

/// Bind `points` with `options`' family three ways (patches, shorter, longer)
/// and deform them to `pose`; `None` for a cage without quads. Binding is on the
/// CPU, so that the figures are the reference's; each bind classes the points
/// against the cage it binds ([`BindOptions::classify`]).
pub fn split_effect(
    points: &[DVec3],
    cage: &Cage,
    pose: &[DVec3],
    options: BindOptions,
) -> Result<Option<SplitEffect>, BindFailure> {
    if !cage.has_quads() {
        return Ok(None);
    }
    let deformed = |quads: QuadSplit| -> Result<Vec<DVec3>, BindFailure> {
        let options = BindOptions { quads, ..options };
        let classes = options.classify(cage, points).classes;
        let weights = bind_cpu(points, &classes, cage, options, &BindProgress::default())?;
        let bound = options.cage_to_bind(cage);
        let moves = options.method.column_displacements(&bound, pose);
        Ok(weights.apply_displacements(points, &moves))
    };
    let diagonal = cage.diagonal();
    let shorter = deformed(QuadSplit::Shorter)?;
    let longer = deformed(QuadSplit::Longer)?;
    let as_patches = BindOptions {
        quads: QuadSplit::None,
        ..options
    };
    // Families that take only triangles (Green) have no patch form to compare.
    let patches = as_patches
        .split_applied(cage)
        .is_none()
        .then(|| deformed(QuadSplit::None))
        .transpose()?;
    let family = as_patches.family_name(cage);
    Ok(Some(SplitEffect {
        family,
        shorter_vs_longer: Spread::between(&shorter, &longer, diagonal),
        patches_vs_shorter: patches
            .as_ref()
            .map(|p| Spread::between(p, &shorter, diagonal)),
        patches_vs_longer: patches
            .as_ref()
            .map(|p| Spread::between(p, &longer, diagonal)),
    }))
}
