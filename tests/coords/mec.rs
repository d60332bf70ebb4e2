//! Maximum entropy coordinates against a second solver written here from the
//! definition (the prior as a plain product, a BFGS minimisation of log Z in
//! world units), and their promises on convex and non-convex cages of
//! triangles and of quads: positivity, partition of unity, linear precision to
//! 1e-10 of the diagonal, invariance under rotation, scaling and a translation
//! to 1e7, and interpolation on the cage.

use glam::{DMat3, DQuat, DVec3};
use pmvc::coords::{
    bind_cpu, mec, weights_at, BindOptions, BindProgress, Method, PmvcIntegration, RowScratch,
};
use pmvc::geometry::procedural_quads::{cage_from_polygons, quad_comb, twisted_box};
use pmvc::geometry::{classify_points, procedural, quads, Cage, PointClass};

fn cages() -> Vec<(&'static str, Cage)> {
    vec![
        ("icosphere", procedural::icosphere(1.0, 1)),
        (
            "comb",
            procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5),
        ),
        (
            "star",
            procedural::extrude(&procedural::star_outline(6, 0.4, 1.0), -0.3, 0.3),
        ),
        ("twisted box (quads)", twisted_box(2.0, 0.6)),
        ("bent quad comb", quad_comb(3, 1.0, 0.25, 3.0, 1.0, 0.3)),
    ]
}

/// MEC of an inside point through the one-row entry every bind uses, in f64.
fn row(cage: &Cage, x: DVec3) -> Vec<f64> {
    let mut out = vec![f64::NAN; cage.vertex_count()];
    weights_at(
        x,
        PointClass::Inside,
        cage,
        Method::Mec,
        &PmvcIntegration::of(BindOptions::for_method(Method::Mec)),
        &mut out,
        &mut RowScratch::default(),
    );
    out
}

/// The faces as drawn: lone triangles and quads.
fn faces(cage: &Cage) -> Vec<Vec<u32>> {
    cage.polygons()
}

/// A face's corners less `x`, and the halves of their edges' cross products.
fn edge_areas(cage: &Cage, face: &[u32], x: DVec3) -> Vec<DVec3> {
    let p: Vec<DVec3> = face
        .iter()
        .map(|&i| cage.positions()[i as usize] - x)
        .collect();
    let n = p.len();
    (0..n).map(|e| 0.5 * p[e].cross(p[(e + 1) % n])).collect()
}

/// The cage's area, `Σ_f |vector area of f|`: the unit areas are measured in.
fn cage_area(cage: &Cage) -> f64 {
    faces(cage)
        .iter()
        .map(|face| {
            edge_areas(cage, face, DVec3::ZERO)
                .iter()
                .sum::<DVec3>()
                .length()
        })
        .sum()
}

/// The definition as written: `ρ_f = Σ_e area(x, e) − |vector area of f|`, in
/// units of the cage's area.
fn rho(cage: &Cage, face: &[u32], x: DVec3) -> f64 {
    let halves = edge_areas(cage, face, x);
    let areas: f64 = halves.iter().map(|a| a.length()).sum();
    (areas - halves.iter().sum::<DVec3>().length()) / cage_area(cage)
}

/// The prior `mᵢ = Π ρ_f` over the faces not incident to `i`, divided by the
/// product over all faces (common to every vertex): `1 / Π ρ_f` over the faces
/// incident to `i`, in plain f64, rescaled to a largest value of 1.
fn reference_prior(cage: &Cage, x: DVec3) -> Vec<f64> {
    let mut prior = vec![1.0; cage.vertex_count()];
    for face in faces(cage) {
        let r = rho(cage, &face, x);
        for &i in &face {
            prior[i as usize] /= r;
        }
    }
    let top = prior.iter().copied().fold(0.0, f64::max);
    prior.iter().map(|m| m / top).collect()
}

/// `log Z(μ)` and its gradient, `μ` in inverse world units.
fn log_z(prior: &[f64], offsets: &[DVec3], mu: DVec3) -> (f64, DVec3, Vec<f64>) {
    let exponents: Vec<f64> = offsets.iter().map(|d| -mu.dot(*d)).collect();
    let shift = exponents.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let terms: Vec<f64> = prior
        .iter()
        .zip(&exponents)
        .map(|(m, e)| m * (e - shift).exp())
        .collect();
    let z: f64 = terms.iter().sum();
    let w: Vec<f64> = terms.iter().map(|t| t / z).collect();
    let gradient = -w.iter().zip(offsets).map(|(w, d)| *w * *d).sum::<DVec3>();
    (z.ln() + shift, gradient, w)
}

/// BFGS on `log Z` from `μ = 0` with a backtracking line search, to a gradient
/// of 1e-13 cage diagonals; the weights at the end.
fn reference_mec(cage: &Cage, x: DVec3) -> Vec<f64> {
    let prior = reference_prior(cage, x);
    let offsets: Vec<DVec3> = cage.positions().iter().map(|&v| v - x).collect();
    let tolerance = 1e-13 * cage.diagonal();
    let mut mu = DVec3::ZERO;
    let (mut f, mut g, mut w) = log_z(&prior, &offsets, mu);
    let mut inverse = DMat3::IDENTITY * (1.0 / cage.diagonal().powi(2));
    for _ in 0..2000 {
        if g.length() <= tolerance {
            return w;
        }
        let direction = -(inverse * g);
        let mut t = 1.0;
        let (next_mu, next_f, next_g, next_w) = loop {
            let trial = mu + t * direction;
            let (tf, tg, tw) = log_z(&prior, &offsets, trial);
            // Past the rounding of log Z, a smaller gradient decides.
            if tf <= f + 1e-4 * t * g.dot(direction)
                || (tf <= f + 1e-14 * f.abs().max(1.0) && tg.length() < g.length())
            {
                break (trial, tf, tg, tw);
            }
            t *= 0.5;
            assert!(t > 1e-30, "reference line search failed at {x}");
        };
        let s = next_mu - mu;
        let y = next_g - g;
        let sy = s.dot(y);
        if sy > 0.0 {
            let rho = 1.0 / sy;
            let left = DMat3::IDENTITY - rho * outer(s, y);
            inverse = left * inverse * left.transpose() + rho * outer(s, s);
        }
        (mu, f, g, w) = (next_mu, next_f, next_g, next_w);
    }
    panic!(
        "reference BFGS did not converge at {x}: gradient {}",
        g.length()
    );
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

#[test]
fn the_incident_face_form_of_the_prior_is_the_product_over_the_other_faces() {
    let cage = procedural::cube_cage(1.0);
    let x = DVec3::new(0.2, -0.3, 0.4);
    let faces = faces(&cage);
    let literal: Vec<f64> = (0..cage.vertex_count() as u32)
        .map(|i| {
            faces
                .iter()
                .filter(|face| !face.contains(&i))
                .map(|face| rho(&cage, face, x))
                .product()
        })
        .collect();
    let top = literal.iter().copied().fold(0.0, f64::max);
    let literal: Vec<f64> = literal.iter().map(|m| m / top).collect();
    assert!(worst_difference(&literal, &reference_prior(&cage, x)) < 1e-13);
}

#[test]
fn mec_agrees_with_an_independent_quasi_newton_solver() {
    for (name, cage) in cages() {
        let points = procedural::points_inside(&cage, 40, 5, 1e-2);
        let mut worst = 0.0f64;
        for &x in &points {
            worst = worst.max(worst_difference(&row(&cage, x), &reference_mec(&cage, x)));
        }
        println!("{name}: max |MEC − BFGS reference| {worst:e}");
        assert!(
            worst <= 1e-8,
            "{name}: MEC differs from the reference by {worst}"
        );
    }
}

#[test]
fn mec_is_positive_sums_to_one_and_reproduces_the_point() {
    for (name, cage) in cages() {
        let points = procedural::points_inside(&cage, 300, 9, 1e-4);
        let (mut sum_error, mut position_error, mut min) = (0.0f64, 0.0f64, f64::INFINITY);
        for &x in &points {
            let w = row(&cage, x);
            sum_error = sum_error.max((w.iter().sum::<f64>() - 1.0).abs());
            let moved: DVec3 = w
                .iter()
                .zip(cage.positions())
                .map(|(w, &v)| *w * (v - x))
                .sum();
            position_error = position_error.max(moved.length() / cage.diagonal());
            min = min.min(w.iter().copied().fold(f64::INFINITY, f64::min));
        }
        println!(
            "{name}: |Σw − 1| {sum_error:e}, linear precision {position_error:e}, min {min:e}"
        );
        assert!(
            sum_error <= 1e-12,
            "{name}: partition of unity off by {sum_error}"
        );
        assert!(
            position_error <= 1e-10,
            "{name}: linear precision {position_error}"
        );
        assert!(min > 0.0, "{name}: weight {min}");
    }
}

/// A map of the scene, its name, and how far the weights may move under it.
type SceneMap = (&'static str, Box<dyn Fn(DVec3) -> DVec3>, f64);

/// The same answers after a rotation, a scaling (areas enter the prior in
/// units of the cage's area) and a translation to 1e7 from the origin.
#[test]
fn mec_is_invariant_under_rotation_scaling_and_a_far_translation() {
    let turn = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.9);
    let maps: [SceneMap; 3] = [
        ("rotated", Box::new(move |p| turn * p), 1e-9),
        ("scaled by 1000", Box::new(|p| 1000.0 * p), 1e-9),
        // Positions at 1e7 are rounded to 2e-9: the geometry itself moves that much.
        ("moved to 1e7", Box::new(|p| p + DVec3::splat(1e7)), 1e-7),
    ];
    for (name, cage) in cages() {
        let points = procedural::points_inside(&cage, 30, 13, 1e-2);
        for (map_name, map, tolerance) in &maps {
            let moved = cage_mapped(&cage, map);
            let mut worst = 0.0f64;
            let mut precision = 0.0f64;
            for &x in &points {
                let (w, y) = (row(&cage, x), map(x));
                let v = row(&moved, y);
                worst = worst.max(worst_difference(&w, &v));
                let offset: DVec3 = v
                    .iter()
                    .zip(moved.positions())
                    .map(|(w, &p)| *w * (p - y))
                    .sum();
                precision = precision.max(offset.length() / moved.diagonal());
            }
            println!(
                "{name} {map_name}: weights differ by {worst:e}, linear precision {precision:e}"
            );
            assert!(worst <= *tolerance, "{name} {map_name}: {worst}");
            assert!(
                precision <= 1e-10,
                "{name} {map_name}: linear precision {precision}"
            );
        }
    }
}

/// `cage` with every vertex mapped, its faces triangulated again (a quad's
/// diagonal is chosen from its positions).
fn cage_mapped(cage: &Cage, map: &dyn Fn(DVec3) -> DVec3) -> Cage {
    let positions: Vec<DVec3> = cage.positions().iter().map(|&p| map(p)).collect();
    let (mapped, _) =
        cage_from_polygons(&positions, &cage.polygons()).expect("a moved cage is valid");
    assert_eq!(mapped.quads().len(), cage.quads().len());
    mapped
}

/// Through the bind every front end uses: on a vertex its own weight is one,
/// on a face its interpolation, and a point just inside is close to it.
#[test]
fn mec_interpolates_on_the_cage() {
    for (name, cage) in cages() {
        let mut points: Vec<DVec3> = cage.positions().to_vec();
        let mut expected: Vec<Vec<f64>> = (0..cage.vertex_count())
            .map(|i| {
                (0..cage.vertex_count())
                    .map(|j| f64::from(u8::from(i == j)))
                    .collect()
            })
            .collect();
        for t in (0..cage.triangle_count()).step_by(3) {
            let [a, b, c] = cage.triangle(t);
            let x = (a + 2.0 * b + 3.0 * c) / 6.0;
            let mut w = vec![0.0; cage.vertex_count()];
            match cage.quad_of_triangle(t) {
                // On a patch: its bilinear basis at the point.
                Some(k) => {
                    let q = cage.quad(k);
                    let uv = quads::nearest_uv(&q, x, [0.5, 0.5]);
                    let x = quads::bilinear_point(&q, uv[0], uv[1]);
                    let basis = quads::bilinear_basis(uv[0], uv[1]);
                    for (&i, b) in cage.quads()[k].corners.iter().zip(basis) {
                        w[i as usize] += b;
                    }
                    points.push(x);
                }
                None => {
                    for (&i, b) in cage.triangles()[t].iter().zip([1.0, 2.0, 3.0]) {
                        w[i as usize] += b / 6.0;
                    }
                    points.push(x);
                }
            }
            expected.push(w);
        }
        let classes = classify_points(&cage, &points);
        let weights = bind_cpu(
            &points,
            &classes.classes,
            &cage,
            BindOptions::for_method(Method::Mec),
            &BindProgress::default(),
        )
        .unwrap();
        let mut worst = 0.0f64;
        for (k, want) in expected.iter().enumerate() {
            let got: Vec<f64> = weights.row(k).iter().map(|&w| f64::from(w)).collect();
            worst = worst.max(worst_difference(&got, want));
        }
        println!("{name}: on the cage, max |w − interpolation| {worst:e}");
        assert!(worst <= 1e-5, "{name}: {worst}");
    }
}

/// Where MVC go negative in the comb, MEC stay positive, through the f32 bind.
#[test]
fn mec_stays_positive_where_mvc_go_negative() {
    let cage = procedural::extrude(&procedural::comb_outline(5, 1.0, 0.25, 4.0), -0.5, 0.5);
    let points: Vec<DVec3> = (1..20)
        .map(|k| DVec3::new(1.75, 1.0 + 0.2 * f64::from(k), 0.0))
        .collect();
    let classes = classify_points(&cage, &points);
    let bind = |method| {
        bind_cpu(
            &points,
            &classes.classes,
            &cage,
            BindOptions::for_method(method),
            &BindProgress::default(),
        )
        .unwrap()
    };
    let (mvc, mec) = (bind(Method::Mvc), bind(Method::Mec));
    println!("comb: MVC min {}, MEC min {}", mvc.min(), mec.min());
    assert!(mvc.min() < -0.01);
    assert!(mec.min() >= 0.0);
}

/// A point outside every hull has no MEC: the solver says so, and the bind
/// follows the outside policy (MVC) for points classified outside.
#[test]
fn outside_the_cage_mec_rows_are_mvc_rows() {
    let cage = procedural::icosphere(1.0, 1);
    let x = DVec3::new(1.5, 0.2, -0.1);
    let mut out = vec![0.0; cage.vertex_count()];
    assert!(mec::mec_weights_inside(x, &cage, &mut out, &mut Default::default()).is_err());
    let classes = classify_points(&cage, &[x]);
    let bind = |method| {
        bind_cpu(
            &[x],
            &classes.classes,
            &cage,
            BindOptions::for_method(method),
            &BindProgress::default(),
        )
        .unwrap()
    };
    assert_eq!(bind(Method::Mec), bind(Method::Mvc));
}

/// Nearing a quad, the weight off its corners goes to zero with the distance
/// when the quad is planar; among its corners the limit is the bilinear basis
/// only where their priors agree (a box of squares). Elsewhere it is another
/// interpolation of the corners, and on a bent quad weight stays off them: the
/// printed gaps are the jump to the on-surface rows (docs/coordinates.md, MEC).
#[test]
fn nearing_a_quad_mec_tends_to_an_interpolation_of_its_corners() {
    let cages = [
        ("box of squares", twisted_box(2.0, 0.0)),
        ("twisted box", twisted_box(2.0, 0.6)),
        ("bent quad comb", quad_comb(3, 1.0, 0.25, 3.0, 1.0, 0.3)),
    ];
    let (u, v) = (0.3, 0.6);
    for (name, cage) in cages {
        let (mut gap, mut bent_off) = (0.0f64, 0.0f64);
        for k in 0..cage.quads().len() {
            let q = cage.quad(k);
            let corners = cage.quads()[k].corners;
            let foot = quads::bilinear_point(&q, u, v);
            let inward = -quads::bilinear_normal(&q, u, v).normalize();
            let planar = quads::out_of_plane(&q) <= 1e-12 * cage.diagonal();
            let mut bilinear = vec![0.0; cage.vertex_count()];
            for (&i, b) in corners.iter().zip(quads::bilinear_basis(u, v)) {
                bilinear[i as usize] += b;
            }
            for h in [1e-4, 1e-8] {
                let w = row(&cage, foot + h * inward);
                let off: f64 = (0..w.len())
                    .filter(|&i| !corners.contains(&(i as u32)))
                    .map(|i| w[i])
                    .sum();
                if planar {
                    assert!(off <= 2.0 * h, "{name} quad {k}, h {h}: {off} off the quad");
                } else {
                    bent_off = bent_off.max(off);
                }
                if h == 1e-8 {
                    gap = gap.max(worst_difference(&w, &bilinear));
                }
            }
        }
        println!(
            "{name}: at 1e-8 from a quad, max |w − bilinear| {gap:.2e}, weight off a bent quad {bent_off:.2e}"
        );
        if name == "box of squares" {
            assert!(gap <= 1e-7, "{name}: {gap}");
        }
    }
}

/// The figures docs/coordinates.md quotes: time and Newton iterations per point,
/// the weights at the centre of a cube of twelve triangles, and the weights
/// near a sliver of the comb's cap. `cargo test --release
/// --no-default-features --test coords mec_figures -- --ignored --nocapture`.
#[test]
#[ignore = "measurement: prints the figures of the docs"]
fn mec_figures() {
    let mut scenes = cages();
    scenes.push(("sphere of 402 vertices", procedural::uv_sphere(1.0, 21, 20)));
    let mut scratch = mec::MecScratch::default();
    crate::solver_cost::print_solver_cost(scenes, |x, cage, out| {
        mec::mec_weights_inside(x, cage, out, &mut scratch).map(|solve| solve.iterations)
    });
    let cube = procedural::cube_cage(1.0);
    let w = row(&cube, DVec3::ZERO);
    let faces = faces(&cube);
    let degree = |i: usize| faces.iter().filter(|f| f.contains(&(i as u32))).count();
    for (i, &w) in w.iter().enumerate() {
        println!(
            "cube of 12 triangles, centre: corner {i} on {} faces, weight {w:.4}",
            degree(i)
        );
    }
    let comb = procedural::extrude(&procedural::comb_outline(4, 1.0, 0.25, 3.0), -0.5, 0.5);
    let [a, b, c] = comb.triangle(7);
    let normal = (b - a).cross(c - a).normalize();
    for h in [1e-2, 1e-5, 1e-8] {
        let w = row(&comb, (a + 2.0 * b + 3.0 * c) / 6.0 - h * normal);
        let corners = comb.triangles()[7];
        let got: Vec<f64> = corners.iter().map(|&i| w[i as usize]).collect();
        println!("comb cap sliver {a} {b} {c}, h {h}: corner weights {got:.4?} (barycentric 1/6, 1/3, 1/2)");
    }
}

/// Newton converges to 1e-12 of the diagonal at points 1e-4, 1e-7 and 2e-9 of
/// the diagonal inside every face (2e-9: just off the on-surface band, where
/// the prior spans the most), never falling back to the outside policy.
#[test]
fn mec_converges_close_to_every_face() {
    let mut rng = procedural::SplitMix64(5);
    for (name, cage) in cages() {
        let mut scratch = mec::MecScratch::default();
        let mut out = vec![0.0; cage.vertex_count()];
        let (mut count, mut most) = (0, 0);
        for h in [1e-4, 1e-7, 2e-9] {
            for t in 0..cage.triangle_count() {
                let [a, b, c] = cage.triangle(t);
                let inward = -(b - a).cross(c - a).normalize();
                for _ in 0..5 {
                    let (mut u, mut v) = (rng.unit(), rng.unit());
                    if u + v > 1.0 {
                        (u, v) = (1.0 - u, 1.0 - v);
                    }
                    let x = a + u * (b - a) + v * (c - a) + h * cage.diagonal() * inward;
                    // A bent quad's patch is not its triangles: keep the points inside.
                    if classify_points(&cage, &[x]).classes[0] != PointClass::Inside {
                        continue;
                    }
                    let solve = mec::mec_weights_inside(x, &cage, &mut out, &mut scratch)
                        .unwrap_or_else(|e| panic!("{name} {x}: {e}"));
                    assert!(solve.residual <= mec::TOLERANCE, "{name} {x}: {solve:?}");
                    most = most.max(solve.iterations);
                    count += 1;
                }
            }
        }
        println!("{name}: {count} points near the faces, at most {most} Newton iterations");
        assert!(count > 0);
    }
}
