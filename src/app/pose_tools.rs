//! Posing tools, as Blender's users know them: move, rotate and scale about a
//! pivot, optionally along one axis; symmetry across a plane; soft selection,
//! where handles near the selection follow with a smooth falloff. Pure geometry
//! on poses: no UI here, so every rule is tested on its own.

use glam::{DMat3, DVec3};
use std::collections::BTreeSet;

/// What a move, rotate or scale does to a point, about a pivot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Transform {
    Translate(DVec3),
    /// Right-handed rotation by `angle` radians about `axis` (unit length).
    Rotate {
        axis: DVec3,
        angle: f64,
    },
    /// A factor per world axis (uniform scaling has three equal ones).
    Scale(DVec3),
}

impl Transform {
    pub fn apply(&self, point: DVec3, pivot: DVec3) -> DVec3 {
        match *self {
            Transform::Translate(offset) => point + offset,
            Transform::Rotate { axis, angle } => {
                pivot + DMat3::from_axis_angle(axis.normalize_or_zero(), angle) * (point - pivot)
            }
            Transform::Scale(factors) => pivot + (point - pivot) * factors,
        }
    }
}

/// Where rotations and scalings turn about.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Pivot {
    /// The centre of the selected handles.
    #[default]
    SelectionCentre,
    /// The 3D cursor, placed by Shift+right-click.
    Cursor,
}

/// Where the symmetry's mirror plane passes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum MirrorPlane {
    /// Through the rest cage's bounding-box centre.
    #[default]
    CageCentre,
    /// Through the 3D cursor (Shift+right-click picks it on the mesh or cage),
    /// for a cage whose extent is not symmetric (a tail, a raised arm).
    Cursor,
    /// At this coordinate along the axis: the plane that pairs the most
    /// handles, found by [`fitted_mirror_offset`] when it was asked for.
    Fitted(f64),
}

/// The posing tools' settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseToolSettings {
    pub pivot: Pivot,
    pub cursor: DVec3,
    /// Mirror edits across the plane perpendicular to this world axis (0 = x,
    /// 1 = y, 2 = z), through [`Self::mirror_plane`].
    pub symmetry: Option<usize>,
    pub mirror_plane: MirrorPlane,
    /// Handles near the selection follow its edits.
    pub soft_selection: bool,
    /// How far they follow from, as a fraction of the cage diagonal.
    pub soft_radius: f64,
    /// How far a handle's mirror image may be from its partner's rest
    /// position, as a fraction of the rest cage's mean edge: artists' cages are
    /// symmetric only to within a tolerance.
    pub mirror_tolerance: f64,
}

/// The mirror tolerances offered, as fractions of the mean cage edge.
pub const MIRROR_TOLERANCES: std::ops::RangeInclusive<f64> = 0.0..=0.5;

impl Default for PoseToolSettings {
    fn default() -> Self {
        Self {
            pivot: Pivot::default(),
            cursor: DVec3::ZERO,
            symmetry: None,
            mirror_plane: MirrorPlane::default(),
            soft_selection: false,
            soft_radius: 0.15,
            mirror_tolerance: 0.1,
        }
    }
}

pub const AXIS_NAMES: [&str; 3] = ["X", "Y", "Z"];

/// Each handle's mirror partner across the plane `axis = centre`, matched by rest
/// position within `tolerance`: itself for a handle on the plane, `None` for one
/// with no partner. Partners are mutual: a handle is paired with the nearest
/// handle to its mirror image only when it is that handle's nearest too, so a
/// wide tolerance never gives two handles one partner.
pub fn mirror_partners(
    rest: &[DVec3],
    axis: usize,
    centre: f64,
    tolerance: f64,
) -> Vec<Option<usize>> {
    let nearest: Vec<Option<usize>> = rest
        .iter()
        .map(|&p| {
            let mut mirrored = p;
            mirrored[axis] = 2.0 * centre - p[axis];
            rest.iter()
                .enumerate()
                .map(|(j, &q)| (j, (q - mirrored).length()))
                .filter(|&(_, distance)| distance <= tolerance)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(j, _)| j)
        })
        .collect();
    nearest
        .iter()
        .enumerate()
        .map(|(i, &partner)| partner.filter(|&j| nearest[j] == Some(i)))
        .collect()
}

/// The most cage vertices a mirror plane is fitted to, and the most candidate
/// planes it weighs (8 MiB of them): beyond either, fitting is refused.
pub const FIT_VERTEX_LIMIT: usize = 8192;
pub const FIT_CANDIDATE_LIMIT: usize = 1 << 20;

/// The plane `axis = offset` that pairs the most handles of `rest` within
/// `tolerance`, and how many it pairs. Every two handles whose other two
/// coordinates agree within `tolerance` vote for the plane midway between them
/// with the two handles it would pair, and each handle for the plane through
/// it with one; of the planes within `tolerance` of one another, the run with
/// the most handles gives its median. An artist's
/// posed cage is symmetric only in parts, and its box centre then misses them.
pub fn fitted_mirror_offset(
    rest: &[DVec3],
    axis: usize,
    tolerance: f64,
) -> Result<Option<(f64, usize)>, String> {
    if rest.len() > FIT_VERTEX_LIMIT {
        return Err(format!(
            "a mirror plane is fitted to at most {FIT_VERTEX_LIMIT} cage vertices, not {}",
            rest.len()
        ));
    }
    let [u, v] = [(axis + 1) % 3, (axis + 2) % 3];
    // (plane, handles it would pair): 2 for two handles, 1 for one on it.
    let mut votes: Vec<(f64, usize)> = Vec::new();
    for (i, p) in rest.iter().enumerate() {
        for (k, q) in rest[i..].iter().enumerate() {
            if (p[u] - q[u]).hypot(p[v] - q[v]) <= tolerance {
                if votes.len() == FIT_CANDIDATE_LIMIT {
                    return Err(format!(
                        "more than {FIT_CANDIDATE_LIMIT} candidate planes: the tolerance is too wide \
                         for a fit"
                    ));
                }
                votes.push(((p[axis] + q[axis]) / 2.0, if k == 0 { 1 } else { 2 }));
            }
        }
    }
    votes.sort_by(|a, b| a.0.total_cmp(&b.0));
    // The run of planes within one tolerance of each other that would pair
    // the most handles.
    let (mut best, mut best_weight, mut start, mut weight) = ((0, 0), 0, 0, 0);
    for end in 0..votes.len() {
        weight += votes[end].1;
        while votes[end].0 - votes[start].0 > tolerance {
            weight -= votes[start].1;
            start += 1;
        }
        if weight > best_weight {
            (best, best_weight) = ((start, end + 1), weight);
        }
    }
    let run = &votes[best.0..best.1];
    let Some(&(offset, _)) = run.get(run.len() / 2) else {
        return Ok(None);
    };
    let paired = mirror_partners(rest, axis, offset, tolerance)
        .iter()
        .filter(|p| p.is_some())
        .count();
    Ok(Some((offset, paired)))
}

/// The mean length of the edges of `triangles` over `positions`, each edge
/// counted once.
pub fn mean_edge_length(positions: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let edges: BTreeSet<(u32, u32)> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    let lengths = edges.iter().filter_map(|&(a, b)| {
        Some((*positions.get(a as usize)? - *positions.get(b as usize)?).length())
    });
    let (sum, count) = lengths.fold((0.0, 0usize), |(s, n), l| (s + l, n + 1));
    if count == 0 {
        0.0
    } else {
        sum / count as f64
    }
}

/// The centre of `points`' bounding box along `axis`.
impl PoseToolSettings {
    /// Where the mirror plane crosses `axis`, for the rest cage `rest`.
    pub fn mirror_offset(&self, rest: &[DVec3], axis: usize) -> f64 {
        match self.mirror_plane {
            MirrorPlane::CageCentre => mid_plane(rest, axis),
            MirrorPlane::Cursor => self.cursor[axis],
            MirrorPlane::Fitted(offset) => offset,
        }
    }
}

pub fn mid_plane(points: &[DVec3], axis: usize) -> f64 {
    let (lo, hi) = crate::geometry::bounds_of(points);
    (lo[axis] + hi[axis]) / 2.0
}

/// How much each handle follows an edit: 1 for the selection, and with soft
/// selection a smooth falloff (smoothstep of 1 − d/r) with distance d to the
/// nearest selected handle in `pose`, reaching 0 at `radius`.
pub fn follow_weights(
    pose: &[DVec3],
    selection: &BTreeSet<usize>,
    soft_radius: Option<f64>,
) -> Vec<f64> {
    pose.iter()
        .enumerate()
        .map(|(i, &p)| {
            if selection.contains(&i) {
                return 1.0;
            }
            let Some(radius) = soft_radius.filter(|r| *r > 0.0) else {
                return 0.0;
            };
            let nearest = selection
                .iter()
                .filter_map(|&s| pose.get(s))
                .map(|&s| (s - p).length())
                .fold(f64::INFINITY, f64::min);
            let t = (1.0 - nearest / radius).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        })
        .collect()
}

/// `start` with `transform` applied about `pivot` to each handle in proportion
/// to its weight, then, with symmetry, each moved handle's motion mirrored onto
/// its partner. Of two partners that both move, the one that follows more (or,
/// equally, the lower-numbered) leads; a handle on the plane keeps its
/// coordinate across it.
pub fn posed(
    start: &[DVec3],
    weights: &[f64],
    transform: &Transform,
    pivot: DVec3,
    symmetry: Option<(usize, &[Option<usize>])>,
) -> Vec<DVec3> {
    let mut pose: Vec<DVec3> = start
        .iter()
        .zip(weights)
        .map(|(&p, &w)| {
            if w > 0.0 {
                p + (transform.apply(p, pivot) - p) * w
            } else {
                p
            }
        })
        .collect();
    let Some((axis, partners)) = symmetry else {
        return pose;
    };
    let weight = |i: usize| weights.get(i).copied().unwrap_or(0.0);
    for i in 0..pose.len() {
        if weight(i) <= 0.0 {
            continue;
        }
        match partners.get(i).copied().flatten() {
            Some(j) if j == i => pose[i][axis] = start[i][axis],
            Some(j) => {
                let leads = weight(i) > weight(j) || (weight(i) == weight(j) && i < j);
                if leads {
                    let mut motion = pose[i] - start[i];
                    motion[axis] = -motion[axis];
                    pose[j] = start[j] + motion;
                }
            }
            None => {}
        }
    }
    pose
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec3, b: DVec3) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn a_quarter_turn_about_z_takes_x_to_y_around_the_pivot() {
        let pivot = DVec3::new(1.0, 1.0, 0.0);
        let turn = Transform::Rotate {
            axis: DVec3::Z,
            angle: std::f64::consts::FRAC_PI_2,
        };
        assert!(close(turn.apply(pivot + DVec3::X, pivot), pivot + DVec3::Y));
        assert!(close(turn.apply(pivot, pivot), pivot));
        let stretch = Transform::Scale(DVec3::new(2.0, 1.0, 1.0));
        assert!(close(
            stretch.apply(DVec3::new(3.0, 5.0, 7.0), pivot),
            DVec3::new(5.0, 5.0, 7.0)
        ));
    }

    #[test]
    fn partners_are_found_by_mirrored_rest_position() {
        let rest = [
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 3.0, 0.0),
        ];
        let centre = mid_plane(&rest, 0);
        assert_eq!(centre, 0.0);
        let partners = mirror_partners(&rest, 0, centre, 1e-9);
        assert_eq!(partners, vec![Some(2), Some(1), Some(0), None]);
    }

    #[test]
    fn partners_within_a_tolerance_are_mutual() {
        // 0 and 2 mirror each other to 1% off; 3 is as near to 2's image as 0
        // is, but 2 is nearer to 0's image: 3 gets no partner of its own.
        let rest = [
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(1.01, 0.0, 0.0),
            DVec3::new(-1.0, 0.02, 0.0),
        ];
        assert_eq!(
            mirror_partners(&rest, 0, 0.0, 1e-9),
            vec![None, Some(1), None, None]
        );
        let partners = mirror_partners(&rest, 0, 0.0, 0.05);
        assert_eq!(partners, vec![Some(2), Some(1), Some(0), None]);
    }

    #[test]
    fn the_mean_edge_counts_each_edge_once() {
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        // Four sides of 1 and one diagonal of √2, the shared edge once.
        let mean = mean_edge_length(&square, &[[0, 1, 2], [0, 2, 3]]);
        assert!((mean - (4.0 + 2f64.sqrt()) / 5.0).abs() < 1e-12);
        assert_eq!(mean_edge_length(&square, &[]), 0.0);
    }

    #[test]
    fn soft_selection_falls_from_one_at_the_selection_to_zero_at_the_radius() {
        let pose: Vec<DVec3> = (0..6).map(|i| DVec3::new(i as f64, 0.0, 0.0)).collect();
        let selection = BTreeSet::from([0]);
        let weights = follow_weights(&pose, &selection, Some(4.0));
        assert_eq!(weights[0], 1.0);
        // smoothstep(1 - 2/4) = 0.5 half way.
        assert!((weights[2] - 0.5).abs() < 1e-12);
        assert!(weights.windows(2).all(|w| w[1] <= w[0]));
        assert_eq!(weights[4], 0.0);
        assert_eq!(weights[5], 0.0);
        assert_eq!(
            follow_weights(&pose, &selection, None),
            vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        );
    }

    #[test]
    fn a_mirrored_edit_moves_the_partner_to_the_mirror_image() {
        let start = [
            DVec3::new(-1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let partners = mirror_partners(&start, 0, 0.0, 1e-9);
        let weights = [1.0, 0.0, 1.0];
        let moved = posed(
            &start,
            &weights,
            &Transform::Translate(DVec3::new(-0.5, 0.25, 1.0)),
            DVec3::ZERO,
            Some((0, &partners)),
        );
        assert!(close(moved[0], DVec3::new(-1.5, 0.25, 1.0)));
        assert!(close(moved[1], DVec3::new(1.5, 0.25, 1.0)));
        // On the plane: it moves, but stays on the plane.
        assert!(close(moved[2], DVec3::new(0.0, 1.25, 1.0)));
    }

    #[test]
    fn a_half_weight_handle_moves_half_way() {
        let start = [DVec3::ZERO, DVec3::X];
        let moved = posed(
            &start,
            &[1.0, 0.5],
            &Transform::Translate(DVec3::Y),
            DVec3::ZERO,
            None,
        );
        assert!(close(moved[0], DVec3::Y));
        assert!(close(moved[1], DVec3::new(1.0, 0.5, 0.0)));
    }

    #[test]
    fn a_fitted_plane_finds_the_symmetry_the_box_centre_misses() {
        // Symmetric about x = 0.37 to within 1e-3, plus an arm reaching far
        // out on one side only.
        let plane = 0.37;
        let mut rest = Vec::new();
        for k in 0..12 {
            let k = f64::from(k);
            let (y, z, d) = ((k * 0.7).sin(), (k * 1.3).cos(), 0.2 + 0.1 * k);
            let wobble = 1e-3 * (k * 2.1).sin();
            rest.push(DVec3::new(plane - d, y, z));
            rest.push(DVec3::new(plane + d + wobble, y, z));
        }
        rest.push(DVec3::new(plane + 9.0, 0.5, 0.5));
        let tolerance = 0.01;
        let centre = mid_plane(&rest, 0);
        let at_centre = mirror_partners(&rest, 0, centre, tolerance);
        assert!(
            at_centre.iter().all(Option::is_none),
            "the box centre pairs nothing"
        );
        let (offset, paired) = fitted_mirror_offset(&rest, 0, tolerance).unwrap().unwrap();
        assert!((offset - plane).abs() < 1e-3, "{offset}");
        assert_eq!(paired, 24, "every handle but the arm's");
    }

    #[test]
    fn fitting_is_refused_with_sizes_beyond_its_limits() {
        let many = vec![DVec3::ZERO; FIT_VERTEX_LIMIT + 1];
        let error = fitted_mirror_offset(&many, 0, 0.1).unwrap_err();
        assert!(
            error.contains(&format!("{}", FIT_VERTEX_LIMIT + 1)),
            "{error}"
        );
        // Two thousand handles in one column: every pair votes.
        let column: Vec<DVec3> = (0..2000)
            .map(|i| DVec3::new(f64::from(i), 0.0, 0.0))
            .collect();
        let error = fitted_mirror_offset(&column, 0, 0.1).unwrap_err();
        assert!(error.contains("candidate planes"), "{error}");
    }
}
