//! Comparing MVC and PMVC in the editor: the method toggle, side-by-side views,
//! coordinate heatmaps, the negativity and difference views, the hover read-out,
//! the resolution selector and cage subdivision. Driven through egui_kittest on the
//! default scene; see `common::editor` for how a missing GPU is handled.

use crate::common;

use common::editor::*;
use egui::{Key, Modifiers};
use egui_kittest::kittest::Queryable;
use egui_kittest::{Harness, SnapshotResults};
use pmvc::app::compare::{Layout, MethodSet, Overlay, Pane, ViewSettings};
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::coords::Method;
use pmvc::render::colormap::{self, Scale};
use pmvc::render::{Colouring, Shading};

/// The default scene, bound with both methods, in `view`, posed.
fn posed_editor(view: ViewSettings) -> Option<Harness<'static, EditorApp>> {
    let mut harness = editor_with(EditorOptions {
        pose: Some(guide_pose()),
        view,
        ..Default::default()
    })?;
    run_until_bound(&mut harness);
    harness.run_steps(3);
    Some(harness)
}

fn press(harness: &mut Harness<'static, EditorApp>, key: Key) {
    harness.key_press(key);
    harness.run_steps(2);
}

fn cpu_deformed(app: &EditorApp, method: Method) -> Vec<glam::Vec3> {
    app.document()
        .deformed_positions(method)
        .iter()
        .map(|p| p.as_vec3())
        .collect()
}

#[test]
fn the_method_toggle_switches_instantly_without_rebinding() {
    let Some(mut harness) = posed_editor(ViewSettings::default()) else {
        return;
    };
    let binds = harness.state().bind_count();
    assert_eq!(binds, 2, "both methods bound once");
    assert_eq!(harness.state().active_method(), Method::Pmvc);
    let pmvc = harness.state().read_back_deformed().unwrap().unwrap();

    // M cycles through every family: harmonic coordinates are bound on demand
    // the first time they are shown, with the grid control's value.
    press(&mut harness, Key::M);
    assert_eq!(harness.state().active_method(), Method::Harmonic);
    run_until_bound(&mut harness);
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(
        app.bind_count(),
        binds + 1,
        "harmonic bound once, on demand"
    );
    let harmonic = app.read_back_deformed().unwrap().unwrap();
    assert!(max_distance(&harmonic, &cpu_deformed(app, Method::Harmonic)) < 1e-3);
    assert!(
        app.document()
            .bound(Method::Harmonic)
            .unwrap()
            .quality
            .most_negative
            >= -1e-6
    );

    // Green coordinates come next, bound on demand too; the vertex shader applies
    // their face columns as the CPU does.
    press(&mut harness, Key::M);
    assert_eq!(harness.state().active_method(), Method::Green);
    run_until_bound(&mut harness);
    harness.run_steps(2);
    let app = harness.state();
    let green = app.read_back_deformed().unwrap().unwrap();
    assert!(max_distance(&green, &cpu_deformed(app, Method::Green)) < 1e-3);

    // The rest of the families, bound on demand, then back to the first.
    while Method::ALL.last() != Some(&harness.state().active_method()) {
        press(&mut harness, Key::M);
        run_until_bound(&mut harness);
    }
    harness.run_steps(2);
    let app = harness.state();
    // Switching between bound families binds nothing.
    let binds = app.bind_count();
    press(&mut harness, Key::M);
    let app = harness.state();
    assert_eq!(app.active_method(), Method::Mvc);
    assert!(!app.is_binding(), "no bind started");
    assert_eq!(app.bind_count(), binds);
    let mvc = app.read_back_deformed().unwrap().unwrap();
    // Under the pose the methods deform differently, each as its CPU weights say.
    assert!(max_distance(&mvc, &pmvc) > 1e-2);
    assert!(max_distance(&mvc, &cpu_deformed(app, Method::Mvc)) < 1e-3);
    assert!(max_distance(&pmvc, &cpu_deformed(app, Method::Pmvc)) < 1e-3);
    // The comb's fingers pull each other under MVC only.
    assert!(max_distance(&mvc, &harmonic) > 1e-2);

    press(&mut harness, Key::M);
    assert_eq!(harness.state().active_method(), Method::Pmvc);
    assert_eq!(harness.state().bind_count(), binds);

    // The toolbar's control does the same.
    harness.get_by_label("Side by side").click();
    harness.run_steps(2);
    assert_eq!(harness.state().view().layout, Layout::SideBySide);
    assert_eq!(harness.state().bind_count(), binds);
}

#[test]
fn in_side_by_side_view_one_drag_moves_both_meshes() {
    let view = ViewSettings {
        layout: Layout::SideBySide,
        ..Default::default()
    };
    let Some(mut harness) = editor_with(EditorOptions {
        view,
        ..Default::default()
    }) else {
        return;
    };
    run_until_bound(&mut harness);
    let panes = harness.state().pane_rects();
    assert_eq!(panes.len(), 2);
    assert_eq!(panes[0].0, Pane::Method(Method::Mvc));
    assert_eq!(panes[1].0, Pane::Method(Method::Pmvc));
    assert!(
        panes[0].1.right() <= panes[1].1.left(),
        "next to each other"
    );
    let rest: Vec<glam::Vec3> = cpu_deformed(harness.state(), Method::Pmvc);

    // Drag a handle in the right-hand (PMVC) view.
    let app = harness.state();
    let (handle, at) = (0..app.document().pose().len())
        .filter_map(|i| Some((i, app.handle_screen_position_in(1, i)?)))
        .find(|(_, p)| panes[1].1.shrink(40.0).contains(*p))
        .expect("a handle inside the right view");
    // Locked cameras: the same handle sits at the same place in each view.
    let left = app.handle_screen_position_in(0, handle).unwrap();
    assert!((left.x + panes[1].1.left() - panes[0].1.left() - at.x).abs() < 1.0);
    drag_handle(&mut harness, at, at + egui::vec2(40.0, -30.0));
    let app = harness.state();
    assert!(
        app.document().pose()[handle].distance(app.document().cage().positions()[handle]) > 1e-3
    );
    for method in [Method::Mvc, Method::Pmvc] {
        let shading = Shading {
            method,
            ..Default::default()
        };
        let drawn = app.read_back(&shading).unwrap().unwrap().positions;
        assert!(max_distance(&drawn, &rest) > 1e-3, "{method:?} mesh moved");
        assert!(max_distance(&drawn, &cpu_deformed(app, method)) < 1e-3);
    }

    // Unlocked, orbiting the right view leaves the left one alone.
    harness.state_mut().set_cameras_locked(false);
    let left_camera = harness.state().camera_of(0);
    let centre = panes[1].1.center() + egui::vec2(0.0, 200.0);
    drag_handle(&mut harness, centre, centre + egui::vec2(60.0, 0.0));
    assert_eq!(harness.state().camera_of(0), left_camera);
    assert_ne!(harness.state().camera_of(1), left_camera);
}

/// A drag that starts on a handle moves it (elsewhere it orbits).
fn drag_handle(harness: &mut Harness<'static, EditorApp>, from: egui::Pos2, to: egui::Pos2) {
    drag(harness, from, to, Modifiers::NONE);
}

#[test]
fn heatmaps_colour_known_weights_blue_white_red() {
    let Some(harness) = posed_editor(ViewSettings::default()) else {
        return;
    };
    let app = harness.state();
    let mvc = app.document().weights(Method::Mvc).unwrap();
    // The cage vertex whose MVC coordinate is most negative somewhere.
    let (row, column) = app
        .document()
        .bound(Method::Mvc)
        .unwrap()
        .quality
        .most_negative_at
        .expect("MVC is negative in the comb");
    let limit = 0.5;
    for scale in [Scale::Linear, Scale::LogMagnitude] {
        let shading = Shading {
            method: Method::Mvc,
            against: None,
            colouring: Colouring::CageVertexWeight(column as u32),
            scale,
            colour_limit: limit,
            cage_size: 1.0,
        };
        let read_back = app.read_back(&shading).unwrap().unwrap();
        for (vertex, (&value, colour)) in
            read_back.values.iter().zip(&read_back.colours).enumerate()
        {
            assert_eq!(value, mvc.row(vertex)[column], "λ of vertex {vertex}");
            let expected = colormap::heat_colour(value, limit, scale);
            for k in 0..3 {
                assert!(
                    (colour[k] - expected[k]).abs() < 2e-3,
                    "vertex {vertex}: {colour:?} vs {expected:?}"
                );
            }
        }
        // The most negative weight is blue, a zero weight white.
        let blue = read_back.colours[row];
        assert!(blue[2] > blue[0] + 0.1, "{blue:?}");
        if let Some(zero) = read_back.values.iter().position(|&v| v == 0.0) {
            assert_eq!(read_back.colours[zero], colormap::ZERO);
        }
    }
}

#[test]
fn negativity_shows_mvc_negative_and_pmvc_never() {
    let Some(harness) = posed_editor(ViewSettings {
        overlay: Overlay::Negativity,
        ..Default::default()
    }) else {
        return;
    };
    let app = harness.state();
    let lowest = |method| {
        let shading = Shading {
            method,
            colouring: Colouring::MostNegativeWeight,
            ..Default::default()
        };
        let values = app.read_back(&shading).unwrap().unwrap().values;
        values.iter().copied().fold(f32::INFINITY, f32::min)
    };
    assert!(lowest(Method::Mvc) < -0.01, "MVC: {}", lowest(Method::Mvc));
    assert!(
        lowest(Method::Pmvc) >= 0.0,
        "PMVC: {}",
        lowest(Method::Pmvc)
    );
    let quality = |method| app.document().bound(method).unwrap().quality;
    assert!(quality(Method::Mvc).negative_share > 0.0);
    assert_eq!(quality(Method::Pmvc).negative_vertices, 0);
    assert!(quality(Method::Pmvc).max_partition_error < 1e-5);
}

#[test]
fn the_difference_view_shows_the_distance_between_the_deformations() {
    let Some(mut harness) = posed_editor(ViewSettings {
        layout: Layout::Difference,
        ..Default::default()
    }) else {
        return;
    };
    let app = harness.state_mut();
    assert_eq!(
        app.pane_rects()[0].0,
        Pane::Difference {
            against: Method::Mvc.into(),
            shown: Method::Pmvc
        }
    );
    let shading = app.shading_of(Pane::Difference {
        against: Method::Mvc.into(),
        shown: Method::Pmvc,
    });
    assert_eq!(shading.colouring, Colouring::MethodDistance);
    let values = app.read_back(&shading).unwrap().unwrap().values;
    let (mvc, pmvc) = (
        cpu_deformed(app, Method::Mvc),
        cpu_deformed(app, Method::Pmvc),
    );
    let size = shading.cage_size;
    for (i, value) in values.iter().enumerate() {
        let expected = mvc[i].distance(pmvc[i]) / size;
        assert!((value - expected).abs() < 1e-4, "vertex {i}");
    }
    // The colour bar saturates at the largest distance.
    let largest = values.iter().copied().fold(0.0, f32::max);
    assert!(largest > 1e-3);
    assert!((shading.colour_limit - largest).abs() < 1e-3 * largest.max(1.0));
}

#[test]
fn hovering_the_mesh_reads_out_its_largest_and_most_negative_weights() {
    let Some(mut harness) = posed_editor(ViewSettings {
        overlay: Overlay::Heatmap,
        ..Default::default()
    }) else {
        return;
    };
    harness.state_mut().set_active_method(Method::Mvc);
    harness.run_steps(2);
    let weights = harness
        .state()
        .document()
        .weights(Method::Mvc)
        .unwrap()
        .clone();
    // A vertex with a negative MVC weight, where it is drawn.
    let vertex = (0..weights.rows)
        .find(|&i| {
            weights.row(i).iter().any(|&w| w < -1e-3)
                && harness
                    .state_mut()
                    .mesh_vertex_screen_position(0, i)
                    .is_some_and(|p| harness.state().pane_rects()[0].1.shrink(60.0).contains(p))
        })
        .expect("a visible vertex with a negative weight");
    let at = harness
        .state_mut()
        .mesh_vertex_screen_position(0, vertex)
        .unwrap();
    harness.hover_at(at);
    harness.run_steps(3);
    let (pane, readout) = harness
        .state()
        .hover_readout()
        .cloned()
        .expect("a read-out");
    assert_eq!(pane, 0);
    assert_eq!(readout.method, Method::Mvc);
    let row = weights.row(readout.vertex);
    assert_eq!(readout.top.len(), 5);
    let mut sorted: Vec<f32> = row.to_vec();
    sorted.sort_by(|a, b| b.total_cmp(a));
    for (k, (column, weight)) in readout.top.iter().enumerate() {
        assert_eq!(*weight, row[*column]);
        assert_eq!(*weight, sorted[k]);
    }
    let lowest = row.iter().copied().fold(f32::INFINITY, f32::min);
    if lowest < 0.0 {
        assert_eq!(readout.most_negative.map(|(_, w)| w), Some(lowest));
    } else {
        assert_eq!(readout.most_negative, None);
    }
    // The read-out is on screen.
    let title = format!("vertex {} · MVC", readout.vertex);
    harness.get_by_label(&title);
}

#[test]
fn clicking_a_handle_in_heatmap_mode_picks_the_coordinate_shown() {
    let Some(mut harness) = posed_editor(ViewSettings {
        overlay: Overlay::Heatmap,
        heat_vertex: 39,
        ..Default::default()
    }) else {
        return;
    };
    let (handle, at) = isolated_handle(&harness);
    assert_ne!(harness.state().view().heat_vertex, handle);
    click(&mut harness, at);
    assert_eq!(harness.state().view().heat_vertex, handle);
    let app = harness.state_mut();
    let shading = app.shading_of(Pane::Method(Method::Pmvc));
    assert_eq!(
        shading.colouring,
        Colouring::CageVertexWeight(handle as u32)
    );
    // The shared scale reaches the largest |λ| of that coordinate in either method.
    let largest = [Method::Mvc, Method::Pmvc]
        .iter()
        .map(|&m| {
            let weights = app.document().weights(m).unwrap();
            (0..weights.rows)
                .map(|i| weights.row(i)[handle].abs())
                .fold(0.0, f32::max)
        })
        .fold(0.0, f32::max);
    assert!((shading.colour_limit - largest).abs() < 1e-6);
}

#[test]
fn the_resolution_selector_rebinds_pmvc_only() {
    let Some(mut harness) = posed_editor(ViewSettings::default()) else {
        return;
    };
    let binds = harness.state().bind_count();
    let mvc = harness
        .state()
        .document()
        .weights(Method::Mvc)
        .unwrap()
        .clone();
    harness.state_mut().set_resolution(16);
    run_until_bound(&mut harness);
    let app = harness.state();
    assert_eq!(app.bind_count(), binds + 1);
    let bound = app.document().bound(Method::Pmvc).unwrap();
    assert_eq!(bound.options.resolution, 16);
    assert!(std::sync::Arc::ptr_eq(
        app.document().weights(Method::Mvc).unwrap(),
        &mvc
    ));
}

#[test]
fn subdividing_the_cage_keeps_the_pose_and_rebinds_both_methods() {
    let Some(mut harness) = posed_editor(ViewSettings::default()) else {
        return;
    };
    let before = harness.state().document().clone();
    let binds = harness.state().bind_count();
    assert!(harness.state_mut().subdivide_cage());
    run_until_bound(&mut harness);
    let app = harness.state();
    let (vertices, triangles) = (before.cage().vertex_count(), before.cage().triangle_count());
    let edges = triangles * 3 / 2;
    assert_eq!(app.document().cage().vertex_count(), vertices + edges);
    assert_eq!(app.document().cage().triangles().len(), 4 * triangles);
    assert_eq!(&app.document().pose()[..vertices], before.pose());
    assert_eq!(app.bind_count(), binds + 2);
    assert!(app.document().weights(Method::Pmvc).unwrap().cols == vertices + edges);
    assert!(app.document().weights(Method::Mvc).unwrap().cols == vertices + edges);
    // Subdivision does not move the mesh at rest (linear precision of the new cage).
    let rest_cage = app.document().cage().positions().to_vec();
    let at_rest = app
        .document()
        .weights(Method::Pmvc)
        .unwrap()
        .apply(&rest_cage);
    let worst = at_rest
        .iter()
        .zip(&app.document().mesh().positions)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "{worst}");
}

/// One snapshot per view of the posed default document().
#[test]
fn snapshots_of_each_view() {
    let views = [
        ("compare_pmvc", ViewSettings::default(), Method::Pmvc),
        ("compare_mvc", ViewSettings::default(), Method::Mvc),
        (
            "compare_side_by_side",
            ViewSettings {
                layout: Layout::SideBySide,
                difference_pane: true,
                ..Default::default()
            },
            Method::Pmvc,
        ),
        (
            "compare_difference",
            ViewSettings {
                layout: Layout::Difference,
                ..Default::default()
            },
            Method::Pmvc,
        ),
        (
            "compare_positive_families",
            ViewSettings {
                layout: Layout::SideBySide,
                compared: MethodSet::of(&[
                    Method::Pmvc,
                    Method::Harmonic,
                    Method::Mec,
                    Method::Mlc,
                ]),
                ..Default::default()
            },
            Method::Pmvc,
        ),
        (
            "compare_heatmap",
            ViewSettings {
                layout: Layout::SideBySide,
                overlay: Overlay::Heatmap,
                heat_vertex: 9,
                ..Default::default()
            },
            Method::Pmvc,
        ),
        (
            "compare_negativity",
            ViewSettings {
                layout: Layout::SideBySide,
                overlay: Overlay::Negativity,
                ..Default::default()
            },
            Method::Pmvc,
        ),
    ];
    // One result set for all harnesses, so that every view is checked (and
    // updated) before any failure is reported.
    let mut results = SnapshotResults::new();
    for (name, view, method) in views {
        let Some(mut harness) = posed_editor(view) else {
            return;
        };
        harness.state_mut().set_active_method(method);
        // Notices name files by their absolute path, which differs between checkouts.
        harness.state_mut().notices_mut().clear();
        harness.run_steps(3);
        harness.snapshot_options(name, &snapshot_options());
        results.extend_harness(&mut harness);
    }
    results.unwrap();
}

#[test]
fn one_pane_per_family_each_as_its_weights_say() {
    let Some(mut harness) = posed_editor(ViewSettings {
        layout: Layout::SideBySide,
        compared: MethodSet::of(&Method::ALL),
        ..Default::default()
    }) else {
        return;
    };
    harness.run_steps(2);
    let app = harness.state();
    let panes: Vec<Pane> = app.pane_rects().into_iter().map(|(pane, _)| pane).collect();
    // As many as the viewport draws, in menu order.
    let shown: Vec<Pane> = Method::ALL
        .into_iter()
        .take(pmvc::render::MAX_VIEWS)
        .map(Pane::Method)
        .collect();
    assert_eq!(panes, shown, "one pane per family, in menu order");
    let mut deformed = Vec::new();
    for method in Method::ALL.into_iter().take(pmvc::render::MAX_VIEWS) {
        assert!(
            app.document().bound(method).is_some(),
            "{method} bound on demand"
        );
        let shading = Shading {
            method,
            ..Default::default()
        };
        let gpu = app.read_back(&shading).unwrap().unwrap().positions;
        assert!(
            max_distance(&gpu, &cpu_deformed(app, method)) < 1e-3,
            "{method}"
        );
        deformed.push(gpu);
    }
    // Under the pose MVC's fingers pull each other; PMVC's and HC's do not.
    assert!(max_distance(&deformed[0], &deformed[2]) > 1e-2);
    assert!(max_distance(&deformed[0], &deformed[1]) > 1e-2);
}

#[test]
fn cancelling_a_harmonic_bind_keeps_the_bound_families() {
    let Some(mut harness) = posed_editor(ViewSettings::default()) else {
        return;
    };
    let pmvc = harness.state().document().weights(Method::Pmvc).cloned();
    press(&mut harness, Key::M);
    assert_eq!(harness.state().active_method(), Method::Harmonic);
    assert!(
        harness.state().is_binding(),
        "harmonic coordinates bind on demand"
    );
    harness.state_mut().cancel_bind();
    run_until_bound(&mut harness);
    let app = harness.state();
    assert!(app.document().weights(Method::Harmonic).is_none());
    assert!(std::sync::Arc::ptr_eq(
        app.document().weights(Method::Pmvc).unwrap(),
        pmvc.as_ref().unwrap()
    ));
    // The view of the unbound family shows the mesh at rest, and nothing rebinds
    // until asked.
    harness.run_steps(3);
    assert!(!harness.state().is_binding());
}
