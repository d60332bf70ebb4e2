//! The similarity (rotation and uniform scale) that best maps the rest cage onto
//! the deformed one, as the paper's global variant uses it: Umeyama's least
//! squares over the cage vertices, equally weighted, about their centroids. The
//! rotation is found with Horn's quaternion method (the largest eigenvector of a
//! symmetric 4×4 matrix, by Jacobi sweeps), which gives a proper rotation without
//! the SVD's reflection fix.

use glam::{DMat3, DQuat, DVec3};

/// `deformed ≈ scale · rotation · rest + translation` in the least squares sense.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimilarityFit {
    pub rotation: DMat3,
    pub scale: f64,
    pub translation: DVec3,
}

/// Fit `deformed ≈ s R rest + t` over corresponding points (equal lengths,
/// finite: the caller checks).
pub(super) fn fit_similarity(rest: &[DVec3], deformed: &[DVec3]) -> SimilarityFit {
    let count = rest.len().max(1) as f64;
    let rest_mean = rest.iter().sum::<DVec3>() / count;
    let deformed_mean = deformed.iter().sum::<DVec3>() / count;
    // S = Σ aᵢ bᵢᵀ with a the centred rest and b the centred deformed points.
    let mut cross = [[0.0f64; 3]; 3];
    let mut rest_spread = 0.0;
    for (&a, &b) in rest.iter().zip(deformed) {
        let (a, b) = ((a - rest_mean).to_array(), (b - deformed_mean).to_array());
        for i in 0..3 {
            for j in 0..3 {
                cross[i][j] += a[i] * b[j];
            }
            rest_spread += a[i] * a[i];
        }
    }
    let rotation = DMat3::from_quat(best_rotation(&cross));
    // tr(Rᵀ Σ bᵢ aᵢᵀ) = Σ bᵢ · R aᵢ.
    let aligned: f64 = rest
        .iter()
        .zip(deformed)
        .map(|(&a, &b)| (b - deformed_mean).dot(rotation * (a - rest_mean)))
        .sum();
    let scale = if rest_spread > 0.0 {
        aligned / rest_spread
    } else {
        1.0
    };
    SimilarityFit {
        rotation,
        scale,
        translation: deformed_mean - scale * (rotation * rest_mean),
    }
}

/// Horn (1987): the unit quaternion maximising Σ bᵢ · R aᵢ is the eigenvector of
/// the largest eigenvalue of this symmetric matrix built from S = Σ aᵢ bᵢᵀ.
fn best_rotation(s: &[[f64; 3]; 3]) -> DQuat {
    let [[sxx, sxy, sxz], [syx, syy, syz], [szx, szy, szz]] = *s;
    let mut n = [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ];
    let mut vectors = [[0.0f64; 4]; 4];
    for (i, row) in vectors.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    jacobi_eigen(&mut n, &mut vectors);
    let largest = (0..4)
        .max_by(|&i, &j| n[i][i].total_cmp(&n[j][j]))
        .unwrap_or(0);
    // Column `largest` of `vectors` is (w, x, y, z).
    let [w, x, y, z] = [0, 1, 2, 3].map(|k| vectors[k][largest]);
    let quat = DQuat::from_xyzw(x, y, z, w);
    if quat.length_squared() > 0.0 {
        quat.normalize()
    } else {
        DQuat::IDENTITY
    }
}

/// Cyclic Jacobi rotations on a symmetric 4×4 matrix until it is diagonal to
/// rounding; its eigenvalues end on the diagonal, the eigenvectors in the
/// columns of `vectors`.
fn jacobi_eigen(a: &mut [[f64; 4]; 4], vectors: &mut [[f64; 4]; 4]) {
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 {
        return;
    }
    for _sweep in 0..64 {
        let off: f64 = (0..4)
            .flat_map(|p| ((p + 1)..4).map(move |q| (p, q)))
            .map(|(p, q)| a[p][q] * a[p][q])
            .sum();
        if off.sqrt() <= 1e-18 * scale {
            return;
        }
        for p in 0..4 {
            for q in (p + 1)..4 {
                if a[p][q] == 0.0 {
                    continue;
                }
                // The rotation angle that zeroes a[p][q] (Numerical Recipes' form).
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A ← Jᵀ A J and V ← V J: columns p, q, then rows p, q.
                for row in a.iter_mut().chain(vectors.iter_mut()) {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
                let (row_p, row_q) = (a[p], a[q]);
                a[p] = std::array::from_fn(|k| c * row_p[k] - s * row_q[k]);
                a[q] = std::array::from_fn(|k| s * row_p[k] + c * row_q[k]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_similarity_of_scattered_points() {
        let rest: Vec<DVec3> = (0..9)
            .map(|k| {
                let k = k as f64;
                DVec3::new((1.3 * k).sin(), (0.7 * k).cos() * 2.0, 0.3 * k - 1.0)
            })
            .collect();
        let rotation = DMat3::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 2.4);
        let translation = DVec3::new(3.0, -1.0, 7.0);
        let deformed: Vec<DVec3> = rest
            .iter()
            .map(|&p| 1.7 * (rotation * p) + translation)
            .collect();
        let fit = fit_similarity(&rest, &deformed);
        let rotation_error = (fit.rotation - rotation).to_cols_array();
        assert!(rotation_error.iter().all(|e| e.abs() < 1e-12), "{fit:?}");
        assert!((fit.scale - 1.7).abs() < 1e-12, "{fit:?}");
        assert!((fit.translation - translation).length() < 1e-11, "{fit:?}");
    }
}
