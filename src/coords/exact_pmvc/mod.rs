//! Exact positive mean value coordinates: the PMVC integral (Lipman, Kopf,
//! Cohen-Or and Levin 2007) over the cage as x sees it, in closed form, with
//! no cube map ([`super::pmvc`] samples the same integral with one ray per
//! texel of a cube map around x).
//!
//! # The integral
//!
//! PMVC are `wᵢ ∝ ∫ φᵢ(y(σ)) / |y(σ) − x| dσ` over the sphere of directions
//! σ, with y(σ) the first cage point on the ray from x along σ and φᵢ the
//! barycentric coordinates of y on its triangle. Split the sphere into the
//! parts R that each triangle T = (v₀, v₁, v₂) shows first. On R,
//! `Σₖ (vₖ − x) φₖ(y) / |y − x| = σ`, so the weights `wₖᴿ` of T's corners over
//! R satisfy `Σₖ (vₖ − x) wₖᴿ = ∫_R σ dσ = m_R`, the mean vector of R, which for
//! a convex spherical polygon is `½ Σₑ θₑ nₑ` (θₑ the arc of side e, nₑ the
//! unit normal of its great circle, pointing in; Ju, Schaefer and Warren 2005).
//! Off T's plane the `vₖ − x` are a basis, so `wᴿ = [v₀ − x, v₁ − x, v₂ − x]⁻¹ m_R`
//! exactly: `wₖᴿ = (ûₖ₊₁ × ûₖ₊₂)·m_R / (|vₖ − x| det[û₀, û₁, û₂])` with ûₖ the
//! unit directions of the corners. The weights are the sums of `wᴿ` over the
//! visible pieces of every triangle, normalised to sum to one.
//!
//! # Visibility
//!
//! From a point strictly inside a cage that does not cross itself, the first
//! hit of every ray leaves the volume, on a triangle x sees from its inner side
//! (`det[û₀, û₁, û₂] > 0`, a *candidate*); the others neither show nor hide
//! anything that shows, and are skipped, as [`super::pmvc::pmvc_weights_inside`]
//! skips them. Two candidates whose cones overlap are in one depth order over
//! the whole overlap: it is convex, hence connected, and the order could only
//! change where they meet. So the part of T that x sees is T's cone less the
//! cones of the candidates in front of it: convex pieces, each cut along the
//! occluder's edge planes (Sutherland–Hodgman on directions, [`polygon`]).
//! Whether s is in front of t is read from their planes when one lies wholly
//! on one side of the other's plane, else from one ray through their overlap.
//! Candidates are sorted by their distance from x; s is passed over when it is
//! wholly farther than t (and so are all after it), when bounding cones around
//! the two do not meet, or when an edge plane of one has the other wholly
//! outside ([`visibility`]).
//!
//! # Quads
//!
//! A quad is the bilinear patch `P(u, v)` of its corners, as in the cube map
//! ([`super::pmvc`]) and QMVC, and its corners weigh `∫_R ψₖ(u, v) / |P − x| dσ`
//! over the part R of its image that x sees, ψ its bilinear basis at the ray's
//! hit. Its edges are straight, so its image is bounded by four great-circle
//! arcs; `det[P − x, Pᵤ, Pᵥ]` is bilinear, so its corner values decide
//! whether x sees a fold ([`patch`]). With none, the image is the convex
//! spherical quadrilateral of its corners: a candidate of four sides, cut and
//! cutting like a triangle. Its depth against another face is read from the
//! slab between its corners along `(p₂ − p₀) × (p₃ − p₁)`, which holds the
//! patch, when the other lies wholly on one side, else from one ray through
//! the overlap (ray–patch as the cube map solves it), assuming the order
//! holds over the whole overlap as it does for planar faces. Each visible
//! piece is integrated by adaptive quadrature: a fan of spherical
//! triangles, each by 4² and 8² Gauss–Legendre nodes on the square collapsed
//! onto it, split in four until the two differ by less than its share of
//! [`QUAD_TOLERANCE`] (1e-9) of the weights' sum. The patch reproduces its
//! points (`Σ ψₖ(y) qₖ = y`), so `Σₖ wₖ (vₖ − x) = ∫ σ dσ = 0` over the
//! sphere: linear precision holds on quads too. At each node the identity
//! holds exactly, so what is left is the rule's error on σ itself over each
//! piece, which is smooth: measured 3e-17 of the cage diagonal on the bent
//! comb of quads, far below the tolerance of the weights.
//!
//! Where x sees a quad folded (a silhouette inside it: its tangent planes at
//! the corners do not all have x on their inner side), that quad is cut at
//! that point into [`setup::FOLD_GRID`]² sub-patches, each the bilinear patch
//! of its corners (the quad's basis composed with theirs is the quad's):
//! those x sees whole are candidates as above, those it sees from outside
//! are skipped, and those still folded are taken as two triangles, the only
//! approximation left. Grid points are vertices after the cage's, and hand
//! their weights to the quad's corners by its basis. Folds are common on
//! bent quads, whose tangent planes fan out across the cage: on the comb of
//! quads with a corner lifted by 0.3 of a prong's width, 27 of 60 points
//! inside saw one, and every measured point of the Beast and Ogre cages (see
//! docs/coordinates.md). Against 3.2e5 rays cast from points seeing a fold
//! on that comb, the weights differ by 2e-6 (2e-7 where there is no fold,
//! the rays' own error); taking the whole quad as two triangles instead
//! moved them by up to 0.26 on Beast.
//!
//! # Rounding
//!
//! - Everything is computed relative to x: a scene moved 1e7 from the origin
//!   gives the weights it gives at the origin, bit for bit when its
//!   coordinates move exactly.
//! - Sides of a plane are exact where they matter: a corner knows the cage
//!   vertex or the two edge planes it lies on and is on them exactly, so
//!   triangles that share an edge or a vertex meet with no sliver of overlap
//!   or gap. A plane's side within its rounding is 0, which keeps collinear
//!   cage edges (one plane, computed from two pairs of corners) from cutting
//!   slivers out of each other.
//! - A piece's mean vector uses the great circles through its own corners, so
//!   a sliver whose corners lie on one circle integrates to about 0 whatever
//!   their order (the sum of a fan of spherical triangles, whose shared
//!   diagonals cancel).
//! - A triangle seen nearly edge on has a thin cone whose mean vector is small
//!   against the rounding of `½ Σ θₑ nₑ`, and the weights divide it by the small
//!   det: below [`THIN`] its pieces are integrated by Gauss–Legendre quadrature
//!   instead, a sum of positive terms accurate to its own size
//!   ([`polygon::mean_vector_by_quadrature`]). Closed form alone, linear
//!   precision at 1e-15 from the plane of a face of an L-shaped cage was off
//!   by 1e-2; with quadrature it holds to 1e-16 at every distance.
//! - x exactly in a triangle's plane: the triangle is no candidate; its cone
//!   has no area, so it neither shows nor hides anything.
//! - Weights a hair below 0 from rounding are clamped to 0 (each piece's are
//!   non-negative in exact arithmetic).
//!
//! # What it does not take
//!
//! - Points not strictly inside, where the visible pieces do not cover the
//!   sphere to [`MAX_UNCOVERED_SHARE`]: [`ExactPmvcFailure::NotEnclosed`], and
//!   the caller follows the outside policy (MVC), as it does when the cube map
//!   loses rays. Points on the cage get the surface policy before this is
//!   called ([`crate::geometry::classify_points`]).
//! - Cages that cross themselves: the depth order above does not hold; the
//!   result is undefined (though finite), as for the cube map's culling.
//!
//! # Measured
//!
//! The cube map converges to these weights as `R⁻¹` (its misjudged texels are
//! those a visibility boundary or a triangle edge crosses, about R of the 6R²
//! per boundary): on the comb, over 200 points, the mean of each point's
//! largest weight error is 6.4e-4, 2.9e-4, 1.3e-4, 6.6e-5 and 3.3e-5 at
//! R = 16, 32, 64, 128 and 256 (exponents 1.16, 1.17, 0.96, 0.98); the
//! largest error 6.1e-3, 3.0e-3, 1.3e-3, 4.6e-4 and 3.2e-4.
//!
//! Cost per point, one thread, release build, CPU time, against the cube map
//! for the same points (the artist cages of `../shared/data/qmvc`, quads split
//! along the shorter diagonal, at about 2000 of their mesh's inside vertices;
//! the procedural cages at points spread inside; armadillo-size at every
//! fifth of `pmvc bench`'s points), on 2 cores shared with other builds
//! (load average 5 to 6):
//!
//! | cage | triangles | exact | fragments (max) | cube 32² | cube 64² | cube 64² largest error |
//! |---|---|---|---|---|---|---|
//! | ManHead | 20 | 17 µs | 20 (27) | 19 µs | 60 µs | 4.7e-4 |
//! | Bench | 44 | 36 µs | 30 (44) | 22 µs | 68 µs | 1.7e-3 |
//! | comb | 60 | 82 µs | 40 (70) | 28 µs | 82 µs | 1.4e-3 |
//! | FireHydrant | 92 | 123 µs | 71 (84) | 24 µs | 68 µs | 2.8e-3 |
//! | armadillo-size | 216 | 339 µs | 106 (176) | 47 µs | 116 µs | 1.8e-3 |
//! | Ogre | 232 | 256 µs | 93 (212) | 34 µs | 84 µs | 1.5e-3 |
//! | Beast | 300 | 280 µs | 97 (235) | 40 µs | 85 µs | 5.0e-4 |
//! | hand-size | 500 | 1.06 ms | 207 (370) | 89 µs | 173 µs | 2.4e-3 |
//! | icosphere | 1280 | 3.8 ms | 1280 | 128 µs | 176 µs | 2.6e-5 |
//!
//! The time goes to the pairs of candidates: every candidate scans those not
//! wholly farther than itself, which grows as the square of their number,
//! then to cutting pieces. On armadillo-size, per point: set-up 27 µs (8 %),
//! finding the visible pieces 294 µs (86 %), integrating them 19 µs (6 %);
//! 181 candidates, 11,101 pairs scanned, 5053 with bounding cones meeting, of
//! which 1852 are behind by the sides of the planes, 2793 separated by an
//! edge plane, none needing a ray, and 407 occluding (339 cuts, 106 visible
//! pieces). Cutting is the small part: the scan stops at a candidate once it
//! is hidden, and without the cuts (so without that stop) finding the pieces
//! took 480 µs (measured with the variants below in place). Beast: 9754
//! pairs scanned, 2234 with cones meeting, 316 occluding; the icosphere,
//! where every triangle is at about the same distance: 913,313 scanned,
//! 16,159 with cones meeting, none occluding.
//!
//! Tried and not kept, for gaining less than the noise of these figures
//! (under 3 % on armadillo-size, the same weights bit for bit): testing the
//! pairs that share no corner with no branch; ruling candidates out by a
//! bounding ball (wholly beyond t's plane) and their cone against t's edge
//! planes before reading them (a quarter of the pairs with cones meeting);
//! trying the candidates that last hid a whole one first (48 of the 181 per
//! point hidden at once). Looking at each pair once for both orders loses
//! the stop at hidden candidates, scans half as many pairs again and was a
//! quarter slower. A grid of directions listing the candidates by cube-map cell (to
//! scan only those sharing a cell) halved the icosphere's time but doubled
//! the hand's and Beast's, whose large triangles fill many cells. Commands:
//! `cargo test --release --no-default-features --lib coords::exact_pmvc::measure
//! -- --ignored --nocapture --test-threads 1` (`armadillo_size_phases` for the
//! phases).

#[cfg(test)]
mod measure;
mod patch;
mod polygon;
#[cfg(test)]
mod quad_tests;
mod setup;
#[cfg(test)]
mod tests;
mod visibility;

use crate::geometry::Cage;
use glam::DVec3;
use patch::{integrate_piece, Patch, QuadView, QuadratureCount};
use polygon::{mean_vector, mean_vector_by_quadrature, Corner, EdgePlane, Label};
use setup::set_up;
use std::f64::consts::PI;
use visibility::{visible_pieces, Pieces};

/// Why [`exact_pmvc_weights_inside`] gave no weights.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ExactPmvcFailure {
    /// The visible triangles do not cover every direction from the point to
    /// within [`MAX_UNCOVERED_SHARE`]: the point is not strictly inside the
    /// cage (on it, outside it, or in a defect of it).
    #[error("the point is not enclosed by the cage")]
    NotEnclosed,
}

/// Share of the sphere of directions that may be left uncovered (or covered
/// twice) before a point is taken as not enclosed.
pub const MAX_UNCOVERED_SHARE: f64 = 1e-6;

/// What one evaluation did, for measurements.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExactPmvcStats {
    /// Triangles that x sees from their inner side.
    pub candidates: usize,
    /// Of those, seen nearly edge on (integrated by quadrature).
    pub thin: usize,
    /// Candidate pairs (t, s) scanned: s not wholly farther than t.
    pub scanned: usize,
    /// Of those, pairs whose bounding cones overlap.
    pub cones_overlapping: usize,
    /// Of those, pairs the sides of their planes put s behind t.
    pub behind: usize,
    /// Of the rest, pairs with an edge plane separating the two.
    pub separated: usize,
    /// Of the rest, pairs whose order took a ray through their overlap.
    pub probed: usize,
    /// Pairs where s overlaps t and is in front of it.
    pub occluding: usize,
    /// Pieces an occluder cut or hid.
    pub splits: usize,
    /// Visible convex pieces integrated.
    pub fragments: usize,
    /// Patches x sees from their inner side with no fold (quads, and the
    /// sub-patches of folded ones): candidates of four sides, integrated by
    /// quadrature.
    pub quads: usize,
    /// Quads x sees folded (a silhouette inside the patch): cut into a grid
    /// of sub-patches at this point.
    pub folded: usize,
    /// Rays cast on patches by the quadrature.
    pub nodes: usize,
    /// Of those, rays that missed their patch (rounding at its edge).
    pub missed: usize,
    /// Quadrature triangles kept at the deepest split above their tolerance.
    pub unresolved: usize,
}

/// Reusable buffers, so that binding allocates nothing per point once warm.
#[derive(Debug, Default)]
pub struct ExactPmvcScratch {
    relative: Vec<DVec3>,
    directions: Vec<DVec3>,
    distances: Vec<f64>,
    candidates: Vec<Candidate>,
    cones: Vec<Cone>,
    /// For sorting both by distance.
    order: Vec<u32>,
    sorted: Vec<Candidate>,
    sorted_cones: Vec<Cone>,
    /// The pieces of the triangle at hand: corners, and where each piece ends.
    pieces: Pieces,
    next: Pieces,
    work: Vec<Corner>,
    cut: Vec<Corner>,
    sides: Vec<f64>,
    /// How x sees each quad of the cage.
    quad_views: Vec<QuadView>,
    /// The points of folded quads' grids, vertices after the cage's: their
    /// quad and (u, v) on it.
    grid_points: Vec<(u32, f64, f64)>,
    /// Unnormalised weights of the cage's vertices and the grid points.
    sums: Vec<f64>,
    stats: ExactPmvcStats,
}

impl ExactPmvcScratch {
    /// What the last evaluation did.
    pub fn stats(&self) -> ExactPmvcStats {
        self.stats
    }
}

/// A triangle, or a quad's patch, that x sees from its inner side, set up at x.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    /// The corners (the first `count`: 3, or 4 for a quad).
    vertices: [u32; 4],
    count: usize,
    /// Side k runs from corner k to corner k + 1; the face's cone is where
    /// all are kept.
    sides: [EdgePlane; 4],
    /// A triangle's `N = (p₁ − p₀) × (p₂ − p₀)` and `N·p₀` for the corners p
    /// relative to x: a ray `t·d` meets the triangle's plane at
    /// `t = offset / (N·d)`. A quad's `N = (p₂ − p₀) × (p₃ − p₁)` and the
    /// least `N·pₖ`: its patch lies between that and `far_offset`.
    normal: DVec3,
    offset: f64,
    far_offset: f64,
    /// `wₖ = weight_normals[k]·m` for a piece of mean vector m: `(ûₖ₊₁ × ûₖ₊₂) /
    /// (|pₖ| det[û₀, û₁, û₂])`, since `Σ pₖ wₖ = m` (see the module doc).
    /// Triangles only.
    weight_normals: [DVec3; 3],
    /// The unit directions of its corners.
    directions: [DVec3; 4],
    /// The distance from x to the triangle, and to its farthest corner.
    /// Candidates are sorted by the first, so that those after one nearer
    /// than t's farthest corner are all wholly farther than t.
    nearest: f64,
    farthest: f64,
    /// Seen nearly edge on ([`THIN`]): its pieces are integrated by quadrature.
    thin: bool,
    /// The quad (index into [`Cage::quads`]) whose patch this is.
    quad: Option<u32>,
}

/// A triangle is thin, seen from x, when `det[û₀, û₁, û₂]` is below this times
/// the square of the chords between its corners (a few times the sine of the
/// angle at which x sees its plane). The closed form's mean vector is a sum
/// of terms of the size of the arcs, accurate to their rounding, and the
/// weights divide its component across the triangle by det: measured on the
/// comb against fine quadrature (`measure::thin_threshold`), its error is
/// about 6e-18 of the total weight over this ratio, 7e-14 at the threshold;
/// below it quadrature ([`polygon::mean_vector_by_quadrature`]) takes over.
const THIN: f64 = 1e-4;

/// What the scan for a triangle's possible occluders reads of each
/// candidate, kept apart so that the scan runs through little memory.
#[derive(Clone, Copy, Debug)]
struct Cone {
    /// A cone around the triangle's directions: unit axis, cos and sin of its
    /// half angle (−1 and 0 for a cone that may hold any direction).
    axis: DVec3,
    cos_radius: f64,
    sin_radius: f64,
    /// [`Candidate::nearest`].
    nearest: f64,
}

impl Candidate {
    // The accessors below take the corner count as a constant, N = `count`
    // (3, or 4 for a patch): the scan of visibility.rs is written once per
    // pair of counts, so that on cages of triangles its loops are over 3,
    // fully unrolled, with no test of the face's kind inside them.

    fn vertices<const N: usize>(&self) -> &[u32; N] {
        debug_assert_eq!(N, self.count);
        self.vertices[..N].try_into().expect("N ≤ 4")
    }

    fn sides<const N: usize>(&self) -> &[EdgePlane; N] {
        debug_assert_eq!(N, self.count);
        self.sides[..N].try_into().expect("N ≤ 4")
    }

    fn directions<const N: usize>(&self) -> &[DVec3; N] {
        debug_assert_eq!(N, self.count);
        self.directions[..N].try_into().expect("N ≤ 4")
    }

    fn holds<const N: usize>(&self, v: u32) -> bool {
        self.vertices::<N>().contains(&v)
    }

    /// The distance from x to the face along the unit direction `d`, inside
    /// its cone (infinite where a ray misses a patch by rounding).
    fn distance(&self, d: DVec3, relative: &[DVec3]) -> f64 {
        let d = d.normalize();
        match self.quad {
            None => self.offset / self.normal.dot(d),
            Some(_) => {
                let corners = self.vertices.map(|v| relative[v as usize]);
                Patch::new(self.vertices, corners)
                    .hit(d)
                    .map_or(f64::INFINITY, |(inverse, _)| 1.0 / inverse)
            }
        }
    }

    /// Side of cage vertex `v` (relative position `p`) of this triangle's
    /// plane: positive beyond it, as seen from x; 0 for its own corners.
    /// Triangles only.
    fn plane_side(&self, v: u32, p: DVec3) -> f64 {
        if self.holds::<3>(v) {
            0.0
        } else {
            self.normal.dot(p) - self.offset
        }
    }

    /// The corners of its cone (N = `count`).
    fn corners<const N: usize>(&self) -> [Corner; N] {
        std::array::from_fn(|k| Corner {
            direction: self.directions[k],
            label: Label::Vertex(self.vertices[k]),
            side: self.sides[k],
        })
    }
}

/// PMVC of `x`, integrated exactly: written to `out` (one value per cage
/// vertex), for a point [`crate::geometry::classify_points`] found strictly
/// inside a cage that does not intersect itself. See the module doc for the
/// method and [`ExactPmvcFailure`] for when it gives none (then `out` is
/// unspecified; the caller follows the outside policy, MVC).
pub fn exact_pmvc_weights_inside(
    x: DVec3,
    cage: &Cage,
    out: &mut [f64],
    scratch: &mut ExactPmvcScratch,
) -> Result<(), ExactPmvcFailure> {
    out.fill(0.0);
    scratch.stats = ExactPmvcStats::default();
    set_up(x, cage, scratch)?;
    scratch.sums.clear();
    scratch.sums.resize(scratch.relative.len(), 0.0);
    let count = scratch.candidates.len();
    scratch.stats.candidates = count;
    scratch.stats.thin = scratch.candidates.iter().filter(|c| c.thin).count();
    scratch.stats.quads = scratch
        .candidates
        .iter()
        .filter(|c| c.quad.is_some())
        .count();
    scratch.stats.folded = (scratch.quad_views.iter())
        .filter(|&&view| view == QuadView::Folded)
        .count();
    // The weights' sum is at least 4π over the farthest vertex's distance:
    // the patches' quadrature errors add up to at most QUAD_TOLERANCE of it.
    let farthest = scratch.distances.iter().copied().fold(0.0, f64::max);
    let tolerance_per_steradian = QUAD_TOLERANCE / farthest;
    let mut quadrature = QuadratureCount::default();
    let mut total_weight = 0.0;
    let mut solid_angle = 0.0;
    for t in 0..count {
        visible_pieces(t, scratch);
        let target = &scratch.candidates[t];
        scratch.stats.fragments += scratch.pieces.ends.len();
        if target.quad.is_some() {
            if scratch.pieces.is_empty() {
                continue;
            }
            let corners = target.vertices.map(|v| scratch.relative[v as usize]);
            let mut patch = Patch::new(target.vertices, corners);
            for piece in scratch.pieces.iter() {
                let (weights, omega) =
                    integrate_piece(piece, &mut patch, tolerance_per_steradian, &mut quadrature);
                solid_angle += omega;
                for (&v, weight) in target.vertices.iter().zip(weights) {
                    let weight = weight.max(0.0);
                    scratch.sums[v as usize] += weight;
                    total_weight += weight;
                }
            }
            continue;
        }
        for piece in scratch.pieces.iter() {
            let (mut mean, omega) = mean_vector(piece);
            if target.thin {
                mean = mean_vector_by_quadrature(piece);
            }
            solid_angle += omega;
            for k in 0..3 {
                // Non-negative in exact arithmetic: clamp the rounding.
                let weight = target.weight_normals[k].dot(mean).max(0.0);
                scratch.sums[target.vertices[k] as usize] += weight;
                total_weight += weight;
            }
        }
    }
    scratch.stats.nodes = quadrature.nodes;
    scratch.stats.missed = quadrature.missed;
    scratch.stats.unresolved = quadrature.unresolved;
    let sphere = 4.0 * PI;
    if (solid_angle - sphere).abs() > MAX_UNCOVERED_SHARE * sphere
        || !(total_weight > 0.0 && total_weight.is_finite())
    {
        return Err(ExactPmvcFailure::NotEnclosed);
    }
    let inverse = 1.0 / total_weight;
    let vertices = out.len();
    for (value, sum) in out.iter_mut().zip(&scratch.sums) {
        *value = sum * inverse;
    }
    // A grid point's weight goes to its quad's corners by the quad's basis.
    for (&(q, u, v), sum) in scratch.grid_points.iter().zip(&scratch.sums[vertices..]) {
        let corners = cage.quads()[q as usize].corners;
        let basis = crate::geometry::quads::bilinear_basis(u, v);
        for (corner, psi) in corners.iter().zip(basis) {
            out[*corner as usize] += sum * inverse * psi;
        }
    }
    Ok(())
}

/// The quadrature of the patches stops splitting where its estimated error,
/// summed over a piece's corners, is below this share of the weights' sum
/// (summed over every piece, against a lower bound of that sum).
pub const QUAD_TOLERANCE: f64 = 1e-9;
