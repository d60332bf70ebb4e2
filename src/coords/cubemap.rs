//! The cube-map discretisation of the PMVC integral, shared by the CPU reference and
//! the GPU kernels so that both integrate exactly the same texels.
//!
//! Around a point x sit six axis-aligned faces of `R × R` texels on the cube
//! `max(|u|,|v|,|n|) = 1`. Every texel casts one ray from x through its centre. The
//! ray's first cage hit at t > 0 (either side of the triangle) contributes
//! `w = Ω / r` spread over the hit triangle's vertices by its barycentrics, where Ω is
//! the texel's exact solid angle and `r = |hit − x|` is the Euclidean distance.
//! Because the texel set is centrally symmetric, `Σ Ω·d̂ = 0`, which gives linear
//! precision up to rounding.

use glam::DVec3;

/// One face of the cube: a texel at face coordinates `(u, v)` looks along
/// `u·right + v·up + normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CubeFace {
    pub right: DVec3,
    pub up: DVec3,
    pub normal: DVec3,
}

/// The six faces in the order +X, −X, +Y, −Y, +Z, −Z. The GPU kernels use this order.
pub const CUBE_FACES: [CubeFace; 6] = [
    CubeFace {
        right: DVec3::Y,
        up: DVec3::Z,
        normal: DVec3::X,
    },
    CubeFace {
        right: DVec3::Z,
        up: DVec3::Y,
        normal: DVec3::NEG_X,
    },
    CubeFace {
        right: DVec3::Z,
        up: DVec3::X,
        normal: DVec3::Y,
    },
    CubeFace {
        right: DVec3::X,
        up: DVec3::Z,
        normal: DVec3::NEG_Y,
    },
    CubeFace {
        right: DVec3::X,
        up: DVec3::Y,
        normal: DVec3::Z,
    },
    CubeFace {
        right: DVec3::Y,
        up: DVec3::X,
        normal: DVec3::NEG_Z,
    },
];

/// Face coordinate of the centre of texel `index` along one axis: `−1 + (2·index + 1)/R`.
pub fn texel_centre(index: u32, resolution: u32) -> f64 {
    -1.0 + (2.0 * f64::from(index) + 1.0) / f64::from(resolution)
}

/// Face coordinate of the lower edge of texel `index` along one axis.
pub fn texel_edge(index: u32, resolution: u32) -> f64 {
    -1.0 + 2.0 * f64::from(index) / f64::from(resolution)
}

/// Solid angle of the face rectangle `[0,u]×[0,v]` at distance 1, signed like `u·v`.
fn corner_solid_angle(u: f64, v: f64) -> f64 {
    (u * v).atan2((u * u + v * v + 1.0).sqrt())
}

/// Exact solid angle of texel `(i, j)` of an `R × R` cube face.
pub fn texel_solid_angle(i: u32, j: u32, resolution: u32) -> f64 {
    let (u0, u1) = (texel_edge(i, resolution), texel_edge(i + 1, resolution));
    let (v0, v1) = (texel_edge(j, resolution), texel_edge(j + 1, resolution));
    corner_solid_angle(u1, v1) - corner_solid_angle(u0, v1) - corner_solid_angle(u1, v0)
        + corner_solid_angle(u0, v0)
}

/// Per-texel constants of one face (the same for all six by symmetry), row-major with
/// `j` (the `up` coordinate) as the row: `Ω / |(u, v, 1)|`, so that a hit at ray
/// parameter `t` along `(u, v, 1)` weighs `w = Ω / (t·|(u,v,1)|) = table / t`.
#[derive(Clone, Debug)]
pub struct TexelTable {
    pub resolution: u32,
    /// Face coordinate of each texel centre, `R` values.
    pub centres: Vec<f64>,
    /// `Ω / |(u, v, 1)|` for texel `(i, j)` at `j·R + i`.
    pub solid_angle_over_length: Vec<f64>,
    /// Row length of the padded layout below: `R` rounded up to [`TEXEL_LANES`].
    pub stride: usize,
    /// `centres` padded to `stride` with NaN, whose depth keys never win a texel.
    pub padded_centres: Vec<f64>,
    /// `Ω·d̂` in face coordinates, then 1, for texel `(i, j)` at `j·stride + i`; zero
    /// in the padding. A hit's weight times its barycentrics is linear in `Ω·d̂`, so
    /// the CPU reference sums these per triangle; the 1 counts texels.
    pub texel_directions: Vec<[f64; 4]>,
}

/// Texels per step of the CPU rasteriser's inner loop.
pub const TEXEL_LANES: usize = 4;

impl TexelTable {
    pub fn new(resolution: u32) -> Self {
        assert!(resolution > 0, "cube-map resolution must be positive");
        let centres: Vec<f64> = (0..resolution)
            .map(|i| texel_centre(i, resolution))
            .collect();
        let mut solid_angle_over_length = Vec::with_capacity((resolution * resolution) as usize);
        for j in 0..resolution {
            for i in 0..resolution {
                let (u, v) = (centres[i as usize], centres[j as usize]);
                let length = (u * u + v * v + 1.0).sqrt();
                solid_angle_over_length.push(texel_solid_angle(i, j, resolution) / length);
            }
        }
        let r = resolution as usize;
        let stride = r.div_ceil(TEXEL_LANES) * TEXEL_LANES;
        let mut padded_centres = centres.clone();
        padded_centres.resize(stride, f64::NAN);
        let mut texel_directions = vec![[0.0; 4]; stride * r];
        for j in 0..r {
            for i in 0..r {
                let (u, v) = (centres[i], centres[j]);
                let w = solid_angle_over_length[j * r + i];
                texel_directions[j * stride + i] = [w * u, w * v, w, 1.0];
            }
        }
        Self {
            resolution,
            centres,
            solid_angle_over_length,
            stride,
            padded_centres,
            texel_directions,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_solid_angles_cover_the_sphere() {
        for resolution in [1, 2, 7, 32] {
            let mut total = 0.0;
            for j in 0..resolution {
                for i in 0..resolution {
                    let omega = texel_solid_angle(i, j, resolution);
                    assert!(omega > 0.0);
                    total += omega;
                }
            }
            let sphere = 6.0 * total;
            assert!(
                (sphere - 4.0 * std::f64::consts::PI).abs() < 1e-12,
                "R={resolution}: {sphere}"
            );
        }
    }

    #[test]
    fn faces_are_right_handed_and_opposite_in_pairs() {
        let mut normals_sum = DVec3::ZERO;
        for face in CUBE_FACES {
            assert_eq!(face.right.dot(face.up), 0.0);
            assert_eq!(face.right.cross(face.up), face.normal);
            normals_sum += face.normal;
        }
        assert_eq!(normals_sum, DVec3::ZERO);
    }

    #[test]
    fn texel_centres_are_symmetric() {
        let resolution = 32;
        for i in 0..resolution {
            assert_eq!(
                texel_centre(i, resolution),
                -texel_centre(resolution - 1 - i, resolution)
            );
        }
    }
}
