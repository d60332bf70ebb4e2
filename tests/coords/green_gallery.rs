//! The gallery's twisted bar (docs/comparison.md): a round bar in a box cage
//! turned a quarter turn from end to end. Green coordinates keep the bar's
//! cross-sections round; PMVC, whose deformation is a blend of the cage's vertex
//! positions, squashes them. Figures are printed with `--nocapture`.

use pmvc::coords::{bind_cpu, BindOptions, BindProgress, Method};
use pmvc::formats::load_mesh;
use pmvc::geometry::classify_points;
use pmvc::geometry::twisted_bar::{cross_sections, twisted_bar, CrossSections};

const POSE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/poses/twisted-bar.obj");

#[test]
fn green_keeps_the_twisted_bars_cross_sections_round_where_pmvc_squashes_them() {
    let bar = twisted_bar();
    let points = &bar.mesh.positions;
    let classes = classify_points(&bar.cage, points);
    assert!(classes.outside.is_empty(), "the bar lies inside its cage");
    let measure = |method: Method| -> CrossSections {
        let weights = bind_cpu(
            points,
            &classes.classes,
            &bar.cage,
            BindOptions::for_method(method),
            &BindProgress::default(),
        )
        .expect("bound");
        let moves = method.column_displacements(&bar.cage, &bar.twisted);
        cross_sections(&weights.apply_displacements(points, &moves), points)
    };
    let (pmvc, green, mvc) = (
        measure(Method::Pmvc),
        measure(Method::Green),
        measure(Method::Mvc),
    );
    println!("twisted bar, middle three fifths of the rings:");
    for (name, sections) in [("MVC", mvc), ("PMVC 32²", pmvc), ("Green", green)] {
        println!(
            "  {name}: worst out-of-round {:.2}%, ring edge length ratio spread {:.4}",
            100.0 * sections.worst_out_of_round,
            sections.edge_ratio_spread
        );
    }
    assert!(
        green.worst_out_of_round < 0.5 * pmvc.worst_out_of_round,
        "Green {green:?} against PMVC {pmvc:?}"
    );
    assert!(green.edge_ratio_spread < pmvc.edge_ratio_spread);
}

/// The pose the gallery loads is this scene's twisted cage.
#[test]
fn the_gallerys_pose_file_is_the_twisted_cage() {
    let bar = twisted_bar();
    if std::env::var_os("PMVC_WRITE_POSES").is_some() {
        let mesh = pmvc::geometry::TriMesh {
            positions: bar.twisted.clone(),
            triangles: bar.cage.triangles().to_vec(),
            triangle_faces: (0..bar.cage.triangle_count() as u32).collect(),
        };
        pmvc::formats::write_obj(std::path::Path::new(POSE), &mesh).expect("written");
    }
    let pose = load_mesh(std::path::Path::new(POSE)).expect("docs/poses/twisted-bar.obj");
    assert_eq!(pose.mesh.positions.len(), bar.twisted.len());
    let worst = pose
        .mesh
        .positions
        .iter()
        .zip(&bar.twisted)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(worst < 1e-6, "{worst:e}");
}
