//! Texels that no primitive covered although x is enclosed, cast again with slack.

use super::super::cubemap::TexelTable;
use super::patch::{FacePatch, PatchSetup};
use super::TriangleSetup;
use glam::DVec3;
use std::ops::Range;

/// Edge values this far below zero, relative to the edge normal and the ray, still
/// count as on the edge when a missed texel is cast again: far above the rounding
/// of the edge values (about 1e-16), far below a texel's width.
const EDGE_SLACK: f64 = 1e-12;

/// The same for a patch's parameters u and v, which its solve rounds by more than
/// an edge value (a square root and a few divisions).
const PATCH_SLACK: f64 = 1e-9;

/// The primitive a missed ray reaches first: a triangle with its edge values, or a
/// patch with its corners' weights.
#[derive(Clone, Copy)]
enum Primitive {
    Triangle(usize, [f64; 3]),
    Patch(usize, [f64; 4]),
}

/// What a face's depth test drew, for casting missed texels again.
pub(super) struct Drawn<'a> {
    pub(super) triangles: &'a [(u32, [DVec3; 3])],
    pub(super) triangle_setups: &'a [TriangleSetup],
    pub(super) patches: &'a [(u32, FacePatch, Range<usize>)],
    pub(super) patch_setups: &'a [PatchSetup],
}

/// Texels that no primitive covered although x is enclosed: rays through a cage
/// vertex, where the triangles around it round their edge values independently,
/// rays along a face that x is in the plane of (skipped), which only its neighbour
/// can catch, and rays along a patch's edge, which its solve may put just outside.
/// A lost texel takes its `Ω·d̂` out of the sum that gives linear precision, so each
/// is cast again against the face's primitives with [`EDGE_SLACK`] or
/// [`PATCH_SLACK`], and the nearest one it reaches gets its weight as the resolve
/// would have given it. Returns how many texels were caught.
pub(super) fn catch_missed_texels(
    nearest: &[f64],
    code_mask: usize,
    table: &TexelTable,
    drawn: &Drawn,
    out: &mut [f64],
    total_weight: &mut f64,
) -> f64 {
    let mut caught = 0.0;
    for (k, (key, direction)) in nearest.iter().zip(&table.texel_directions).enumerate() {
        // A hit, or the padding (no weight).
        if key.to_bits() as usize & code_mask != 0 || direction[3] == 0.0 {
            continue;
        }
        let ray = DVec3::new(direction[0], direction[1], direction[2]);
        let mut nearest_hit: Option<(f64, Primitive)> = None;
        for &(t, edges) in drawn.triangles {
            let values = edges.map(|edge| edge.dot(ray));
            let on_triangle = values
                .iter()
                .zip(&edges)
                .all(|(&value, edge)| value >= -EDGE_SLACK * edge.length() * ray.length());
            let setup = &drawn.triangle_setups[t as usize];
            // Proportional to 1/t, as the depth test's key.
            let inverse_depth = values.iter().sum::<f64>() / setup.det.abs();
            if on_triangle
                && inverse_depth > 0.0
                && nearest_hit.is_none_or(|(nearest, _)| inverse_depth > nearest)
            {
                nearest_hit = Some((inverse_depth, Primitive::Triangle(t as usize, values)));
            }
        }
        // The texel's weight over its distance factor: `ray = w·(s, r, 1)`.
        let (weight, s, r) = (
            direction[2],
            table.centres[k % table.stride],
            table.centres[k / table.stride],
        );
        for (p, patch, _) in drawn.patches {
            let p = *p;
            let Some([inverse_t, u, below, above]) = patch.hit_with_slack(s, r, PATCH_SLACK) else {
                continue;
            };
            let inverse_depth = inverse_t * weight;
            if nearest_hit.is_none_or(|(nearest, _)| inverse_depth > nearest) {
                let (below, above) = (below * weight, above * weight);
                let weights = [(1.0 - u) * below, u * below, u * above, (1.0 - u) * above];
                nearest_hit = Some((inverse_depth, Primitive::Patch(p as usize, weights)));
            }
        }
        match nearest_hit {
            Some((_, Primitive::Triangle(t, values))) => {
                let setup = &drawn.triangle_setups[t];
                for (&corner, value) in setup.vertices.iter().zip(values) {
                    let weight = value.max(0.0) / setup.det.abs();
                    out[corner as usize] += weight;
                    *total_weight += weight;
                }
            }
            Some((_, Primitive::Patch(p, weights))) => {
                for (&corner, weight) in drawn.patch_setups[p].vertices.iter().zip(weights) {
                    out[corner as usize] += weight;
                    *total_weight += weight;
                }
            }
            None => continue,
        }
        caught += 1.0;
    }
    caught
}
