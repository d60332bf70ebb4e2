//! The prior of maximum entropy coordinates (Hormann and Sukumar 2008): vertex
//! `i`'s prior is `Π ρ_f(x)` over the faces `f` not incident to `i`, with
//! `ρ_f(x) = Σ_e area(x, e) − |vector area of f|` over `f`'s edges `e`.
//!
//! Dividing every prior by the common factor `Π_f ρ_f(x)` leaves
//! `1 / Π ρ_f(x)` over the faces incident to `i`, which the weights do not tell
//! apart: that form costs one pass over the faces and a few factors per vertex,
//! so it is what is computed, as a logarithm (the priors span hundreds of orders
//! of magnitude near the cage).

use crate::geometry::Cage;
use glam::DVec3;

/// Below this a face's `ρ` (in units of the cage's area) is taken as this: a
/// point that close is on the face for every purpose, and the logarithm stays
/// finite.
const RHO_FLOOR: f64 = 1e-300;

/// `log` of each vertex's prior at the point the offsets are taken from, up to
/// a constant shared by all vertices; `−∞` for a vertex no face uses (its weight
/// is zero). `offsets[i]` is cage vertex `i` less the point.
///
/// Areas are measured in units of the cage's area `Σ_f |vector area of f|`:
/// a vertex's prior has as many factors as faces it misses, which differs
/// between vertices, so the unit matters; this one moves with the cage, which
/// makes the coordinates invariant under rotations and scalings.
pub(super) fn log_prior(cage: &Cage, offsets: &[DVec3], rho: &mut Vec<f64>, out: &mut Vec<f64>) {
    rho.clear();
    let mut area = 0.0;
    let mut measure = |corners: &[DVec3]| {
        let (excess, face_area) = excess(corners);
        rho.push(excess);
        area += face_area;
    };
    for t in cage.lone_triangles() {
        measure(&cage.triangles()[t].map(|i| offsets[i as usize]));
    }
    for quad in cage.quads() {
        measure(&quad.corners.map(|i| offsets[i as usize]));
    }
    let log_area = area.ln();
    out.clear();
    out.resize(offsets.len(), f64::NEG_INFINITY);
    let lone = cage.lone_triangles().map(|t| &cage.triangles()[t][..]);
    let quads = cage.quads().iter().map(|quad| &quad.corners[..]);
    for (corners, &rho) in lone.chain(quads).zip(rho.iter()) {
        let log_rho = (rho.ln() - log_area).max(RHO_FLOOR.ln());
        for &corner in corners {
            let value = &mut out[corner as usize];
            if *value == f64::NEG_INFINITY {
                *value = 0.0;
            }
            *value -= log_rho;
        }
    }
}

/// `ρ_f` of a face whose corners, relative to the point, are `p` (3 or 4 of
/// them): the sum of the areas of the triangles from the point to each edge less
/// the length of their sum (the face's vector area, whatever the point); and
/// that length.
///
/// `Σ|aₑ| − |Σaₑ|` cancels to nothing near the face, so it is computed as
/// `2 Σ_{e<e'} (|aₑ||aₑ'| − aₑ·aₑ') / (Σ|aₑ| + |Σaₑ|)`, whose terms are each
/// non-negative and, where `aₑ·aₑ' > 0`, are taken as `|aₑ×aₑ'|² / (|aₑ||aₑ'| + aₑ·aₑ')`.
pub(super) fn excess(p: &[DVec3]) -> (f64, f64) {
    let n = p.len().min(4);
    let mut a = [DVec3::ZERO; 4];
    let mut length = [0.0; 4];
    for e in 0..n {
        a[e] = 0.5 * p[e].cross(p[(e + 1) % n]);
        length[e] = a[e].length();
    }
    let total: f64 = length[..n].iter().sum();
    let area = a[..n].iter().sum::<DVec3>().length();
    let mut pairs = 0.0;
    for e in 0..n {
        for f in e + 1..n {
            let dot = a[e].dot(a[f]);
            let product = length[e] * length[f];
            pairs += if dot > 0.0 {
                a[e].cross(a[f]).length_squared() / (product + dot)
            } else {
                product - dot
            };
        }
    }
    let denominator = total + area;
    let rho = if denominator > 0.0 {
        2.0 * pairs / denominator
    } else {
        0.0
    };
    (rho, area)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition as written, for points where it does not cancel.
    fn direct(p: &[DVec3]) -> f64 {
        let n = p.len();
        let areas: f64 = (0..n)
            .map(|e| 0.5 * p[e].cross(p[(e + 1) % n]).length())
            .sum();
        let vector: DVec3 = (0..n).map(|e| 0.5 * p[e].cross(p[(e + 1) % n])).sum();
        areas - vector.length()
    }

    fn relative_to(x: DVec3, corners: &[DVec3]) -> Vec<DVec3> {
        corners.iter().map(|&c| c - x).collect()
    }

    const TRIANGLE: [DVec3; 3] = [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.2, 0.9, 0.0),
    ];

    #[test]
    fn the_stable_form_equals_the_definition_away_from_the_face() {
        let quad = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.1),
            DVec3::new(1.2, 1.0, -0.1),
            DVec3::new(-0.1, 0.8, 0.05),
        ];
        for x in [
            DVec3::new(0.3, 0.2, 0.7),
            DVec3::new(-1.0, 2.0, -0.3),
            DVec3::new(3.0, 0.4, 0.0),
        ] {
            for corners in [&TRIANGLE[..], &quad[..]] {
                let p = relative_to(x, corners);
                let (stable, direct) = (excess(&p).0, direct(&p));
                assert!(
                    (stable - direct).abs() <= 1e-14 * direct.abs().max(1.0),
                    "{stable} {direct}"
                );
            }
        }
    }

    #[test]
    fn rho_vanishes_on_a_triangle_and_is_positive_elsewhere_in_its_plane() {
        let inside = DVec3::new(0.4, 0.3, 0.0);
        assert!(excess(&relative_to(inside, &TRIANGLE)).0 <= 1e-16);
        let beside = DVec3::new(0.8, 0.8, 0.0);
        assert!(excess(&relative_to(beside, &TRIANGLE)).0 > 1e-3);
    }

    /// Near a face `ρ` shrinks as the squared height (its tetrahedra's slant
    /// areas each exceed their shadows by that order); the stable form keeps its
    /// digits down to heights where the definition as written (rounding of about
    /// 1e-17 here) has lost them all.
    #[test]
    fn rho_shrinks_as_the_squared_height_without_cancelling() {
        let foot = DVec3::new(0.4, 0.3, 0.0);
        let at = |h: f64| excess(&relative_to(foot + DVec3::new(0.0, 0.0, h), &TRIANGLE)).0;
        for h in [1e-4, 1e-6, 1e-9] {
            let ratio = at(h) / at(h / 10.0);
            assert!((ratio - 100.0).abs() < 1e-3, "h {h}: ratio {ratio}");
        }
        assert!(at(1e-9) > 1e-19);
    }
}
