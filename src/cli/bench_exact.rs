//! `pmvc bench --exact-error`: the cube map's quantisation error made visible.
//! For the bundled comb (its first-run pose) and each shared model (its
//! `X_Cage_Deformed.obj`), PMVC at cube-map resolutions 8 to 128 against exact
//! PMVC, over the rows inside the cage: the weights' difference (mean and
//! largest) and the deformed points' distance (largest and mean, as a share of
//! the cage diagonal), beside MVC's distance from exact PMVC, the whole
//! MVC–PMVC difference the cube map approximates.

use crate::coords::EXACT_RESOLUTION;
use crate::coords::{bind_cpu_f64, BindOptions, BindProgress, Method, QuadSplit, WeightsF64};
use crate::geometry::{Cage, PointClass};
use anyhow::Result;
use glam::DVec3;

/// The resolutions compared with exact.
pub const RESOLUTIONS: [u32; 5] = [8, 16, 32, 64, 128];

/// One scene to measure: its mesh points, cage and a pose of the cage.
pub struct Scene {
    pub name: String,
    pub points: Vec<DVec3>,
    pub cage: Cage,
    pub pose: Vec<DVec3>,
}

/// One line of the table: a family against exact PMVC on one scene.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ExactErrorRow {
    pub scene: String,
    pub inside_rows: usize,
    /// "PMVC 32²", or "MVC" for the whole difference.
    pub family: String,
    pub weight_error_mean: f64,
    pub weight_error_max: f64,
    /// Deformed points' distance from exact PMVC's, in cage diagonals.
    pub deformation_max: f64,
    pub deformation_mean: f64,
}

/// The bundled comb with its first-run pose (the middle prong pulled up).
pub fn comb_scene() -> Scene {
    let cage = crate::app::scenes::comb_cage();
    let pose = crate::app::scenes::comb_demo_pose(&cage);
    Scene {
        name: "comb (bundled)".to_owned(),
        points: crate::app::scenes::comb_mesh().positions,
        cage,
        pose,
    }
}

/// A shared model: `X.obj`, `X_Cage.obj` and `X_Cage_Deformed.obj` in `data`.
pub fn shared_scene(data: &std::path::Path, name: &str) -> Result<Scene> {
    let mesh = crate::formats::load_mesh(&data.join(format!("{name}.obj")))?;
    let (cage, _) = crate::formats::load_cage(&data.join(format!("{name}_Cage.obj")))?;
    // A pose need not be a valid cage (a quad may fold): only its vertices count.
    let posed = crate::formats::load_mesh(&data.join(format!("{name}_Cage_Deformed.obj")))?;
    let pose = posed.mesh.positions;
    anyhow::ensure!(
        pose.len() == cage.vertex_count(),
        "{name}: the deformed cage has {} vertices, the cage {}",
        pose.len(),
        cage.vertex_count()
    );
    Ok(Scene {
        name: name.to_owned(),
        points: mesh.mesh.positions,
        cage,
        pose,
    })
}

/// Every row of the table for `scene`. A cage's quads are split along their
/// shorter diagonal for every family here, so that the comparison is on one
/// cage and its figures are those of docs/coordinates.md.
pub fn measure(scene: &Scene) -> Result<Vec<ExactErrorRow>> {
    let split = if scene.cage.has_quads() {
        QuadSplit::Shorter
    } else {
        QuadSplit::None
    };
    let options = |method: Method, resolution: u32| BindOptions {
        resolution,
        quads: split,
        ..BindOptions::for_method(method)
    };
    let exact_options = options(Method::Pmvc, EXACT_RESOLUTION);
    let classes = exact_options.classify(&scene.cage, &scene.points).classes;
    let inside: Vec<usize> = (0..scene.points.len())
        .filter(|&i| classes[i] == PointClass::Inside)
        .collect();
    let inside_points: Vec<DVec3> = inside.iter().map(|&i| scene.points[i]).collect();
    let inside_classes = vec![PointClass::Inside; inside.len()];
    let bind = |options: BindOptions| {
        bind_cpu_f64(
            &inside_points,
            &inside_classes,
            &scene.cage,
            options,
            &BindProgress::default(),
        )
    };
    let exact = bind(exact_options)?;
    let diagonal = scene.cage.diagonal();
    let rest = scene.cage.positions();
    let exact_deformed = deformed(&exact, rest, &scene.pose);
    let mut rows = Vec::new();
    let mut compare = |family: String, weights: &WeightsF64| {
        let (mean, max) = weight_error(weights, &exact);
        let distances: Vec<f64> = deformed(weights, rest, &scene.pose)
            .iter()
            .zip(&exact_deformed)
            .map(|(a, b)| a.distance(*b) / diagonal)
            .collect();
        rows.push(ExactErrorRow {
            scene: scene.name.clone(),
            inside_rows: inside.len(),
            family,
            weight_error_mean: mean,
            weight_error_max: max,
            deformation_max: distances.iter().copied().fold(0.0, f64::max),
            deformation_mean: distances.iter().sum::<f64>() / distances.len().max(1) as f64,
        });
    };
    for resolution in RESOLUTIONS {
        let weights = bind(options(Method::Pmvc, resolution))?;
        compare(format!("PMVC {resolution}²"), &weights);
    }
    let mvc = bind(options(Method::Mvc, 0))?;
    compare("MVC".to_owned(), &mvc);
    Ok(rows)
}

/// Each row's points moved by the cage's move from `rest` to `pose`.
fn deformed(weights: &WeightsF64, rest: &[DVec3], pose: &[DVec3]) -> Vec<DVec3> {
    weights
        .values
        .chunks(weights.cols)
        .map(|row| {
            row.iter()
                .zip(rest.iter().zip(pose))
                .map(|(&w, (&r, &p))| (p - r) * w)
                .sum::<DVec3>()
        })
        .collect()
}

/// Mean and largest |a − b| over every weight.
fn weight_error(a: &WeightsF64, b: &WeightsF64) -> (f64, f64) {
    let (sum, max) = a
        .values
        .iter()
        .zip(&b.values)
        .map(|(x, y)| (x - y).abs())
        .fold((0.0, 0.0f64), |(sum, max), d| (sum + d, max.max(d)));
    (sum / a.values.len().max(1) as f64, max)
}

/// The table as markdown.
pub fn markdown(rows: &[ExactErrorRow]) -> String {
    let mut text = String::from(
        "| scene | inside rows | against exact PMVC | weight error, mean | largest | deformation difference (cage diagonals), largest | mean |\n|---|---|---|---|---|---|---|\n",
    );
    for row in rows {
        text.push_str(&format!(
            "| {} | {} | {} | {:.1e} | {:.1e} | {:.1e} | {:.1e} |\n",
            row.scene,
            row.inside_rows,
            row.family,
            row.weight_error_mean,
            row.weight_error_max,
            row.deformation_max,
            row.deformation_mean
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::procedural;

    #[test]
    fn the_cube_map_error_falls_with_resolution_and_stays_below_mvc() {
        let cage = procedural::extrude(&procedural::comb_outline(3, 1.0, 0.3, 2.0), -0.5, 0.5);
        let points = procedural::points_inside(&cage, 40, 7, 1e-2);
        let pose: Vec<DVec3> = cage
            .positions()
            .iter()
            .map(|&p| {
                if p.y > 1.9 && p.x < 1.1 {
                    p + DVec3::Y
                } else {
                    p
                }
            })
            .collect();
        let scene = Scene {
            name: "comb".into(),
            points,
            cage,
            pose,
        };
        let rows = measure(&scene).unwrap();
        assert_eq!(rows.len(), RESOLUTIONS.len() + 1);
        let errors: Vec<f64> = rows.iter().map(|r| r.weight_error_mean).collect();
        assert!(errors[4] < errors[0] / 8.0, "8² to 128²: {errors:?}");
        let mvc = rows.last().unwrap();
        assert!(mvc.deformation_max > rows[2].deformation_max, "{rows:?}");
        assert!(markdown(&rows).contains("| comb | 40 | PMVC 32² |"));
    }
}
