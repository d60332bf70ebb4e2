//! Views that must not mislead: the difference view's colour scale has a floor,
//! so rounding noise at rest is not painted as signal, and it can be fixed.

use crate::common;

use common::editor::*;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use pmvc::app::compare::{Layout, Pane, ViewSettings, DIFFERENCE_FLOOR};
use pmvc::app::{EditorApp, EditorOptions};
use pmvc::coords::Method;

const DIFFERENCE: Pane = Pane::Difference {
    against: pmvc::coords::WeightsId::of(Method::Mvc),
    shown: Method::Pmvc,
};

fn difference_editor(
    pose: bool,
    difference_limit: Option<f32>,
) -> Option<Harness<'static, EditorApp>> {
    let pose = pose.then(guide_pose);
    let mut harness = editor_with(EditorOptions {
        pose,
        view: ViewSettings {
            layout: Layout::Difference,
            difference_limit,
            ..Default::default()
        },
        ..Default::default()
    })?;
    run_until_bound(&mut harness);
    harness.run_steps(3);
    Some(harness)
}

/// Viewport samples (above the colour bar, and not where the world axes are
/// drawn, whose x is red) whose colour is clearly red.
fn red_samples(harness: &mut Harness<'static, EditorApp>) -> usize {
    let rect = harness.state().pane_rects()[0].1;
    let axes = pmvc::app::axes_rect(rect);
    let image = harness.render().expect("the harness renders");
    let mut red = 0;
    let bottom = (rect.top() + rect.height() * 0.75) as u32;
    for y in (rect.top() as u32..bottom).step_by(3) {
        for x in (rect.left() as u32..rect.right() as u32).step_by(3) {
            if axes.contains(egui::pos2(x as f32, y as f32)) {
                continue;
            }
            let [r, g, b, _] = image.get_pixel(x, y).0.map(i32::from);
            if r > g + 60 && r > b + 60 {
                red += 1;
            }
        }
    }
    red
}

#[test]
fn the_difference_view_at_rest_is_white_and_its_scale_stops_at_the_floor() {
    let Some(mut harness) = difference_editor(false, None) else {
        return;
    };
    let app = harness.state_mut();
    let shading = app.shading_of(DIFFERENCE);
    let values = app.read_back(&shading).unwrap().unwrap().values;
    let largest = values.iter().copied().fold(0.0, f32::max);
    // At rest MVC and PMVC differ only by rounding.
    assert!(largest < 1e-5, "largest distance at rest {largest}");
    assert_eq!(shading.colour_limit, DIFFERENCE_FLOOR);
    assert_eq!(
        red_samples(&mut harness),
        0,
        "rounding noise drawn as signal"
    );

    // Posed, the fingers differ by more than the floor and the view shows it.
    let Some(mut posed) = difference_editor(true, None) else {
        return;
    };
    let shading = posed.state_mut().shading_of(DIFFERENCE);
    assert!(shading.colour_limit > DIFFERENCE_FLOOR);
    assert!(red_samples(&mut posed) > 20);
}

#[test]
fn a_fixed_difference_scale_holds_across_poses() {
    let Some(mut harness) = difference_editor(true, Some(0.25)) else {
        return;
    };
    let shading = harness.state_mut().shading_of(DIFFERENCE);
    assert_eq!(shading.colour_limit, 0.25);
    harness.state_mut().reset_pose();
    harness.run_steps(2);
    let shading = harness.state_mut().shading_of(DIFFERENCE);
    assert_eq!(
        shading.colour_limit, 0.25,
        "the scale does not follow the pose"
    );
}

/// A vertex outside the cage (in a gap between two fingers) gets MVC weights
/// with a negative one under every family; the quality table counts it apart, so
/// PMVC's "inside: vertices with λ < 0" stays 0.
#[test]
fn outside_vertices_are_reported_apart_from_the_inside_ones() {
    use pmvc::app::editor::FileRole;
    use pmvc::coords::mvc::{mvc_weights, MvcScratch};
    use pmvc::geometry::{classify_points, PointClass};
    let Some(mut harness) = editor_with(EditorOptions::default()) else {
        return;
    };
    run_until_bound(&mut harness);
    let cage = harness.state().document().cage().clone();
    let (lo, hi) = pmvc::geometry::bounds_of(cage.positions());
    let candidates: Vec<glam::DVec3> = (1..40)
        .flat_map(|i| (1..10).map(move |j| (i, j)))
        .map(|(i, j)| {
            glam::DVec3::new(
                lo.x + (hi.x - lo.x) * i as f64 / 40.0,
                lo.y + (hi.y - lo.y) * j as f64 / 10.0,
                (lo.z + hi.z) / 2.0,
            )
        })
        .collect();
    let classes = classify_points(&cage, &candidates);
    let mut row = vec![0.0; cage.vertex_count()];
    let gap = candidates
        .iter()
        .zip(&classes.classes)
        .filter(|(_, class)| matches!(class, PointClass::Outside))
        .map(|(p, _)| *p)
        .find(|&p| {
            mvc_weights(p, &cage, &mut row, &mut MvcScratch::default());
            row.iter().any(|&w| w < -1e-3)
        })
        .expect("a point between the fingers with a negative MVC weight");
    let inside = classes
        .classes
        .iter()
        .position(|class| matches!(class, PointClass::Inside))
        .map(|i| candidates[i])
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mesh = common::write(dir.path(), "two.obj", &common::points_obj(&[inside, gap]));
    assert!(harness.state_mut().open_file(FileRole::Mesh, &mesh));
    run_until_bound(&mut harness);
    let quality = harness
        .state()
        .document()
        .bound(Method::Pmvc)
        .unwrap()
        .quality;
    assert_eq!(quality.outside_vertices, 1, "{quality:?}");
    assert_eq!(quality.outside_negative_vertices, 1, "{quality:?}");
    assert_eq!(quality.negative_vertices, 0, "{quality:?}");
    assert_eq!(quality.negative_share, 0.0);
    use egui_kittest::kittest::Queryable;
    harness.get_by_label("outside: with λ < 0");
    harness.get_by_label("inside: vertices with λ < 0");

    // The negativity view paints the outside vertex grey, not as negativity, on
    // a log scale by default; the inside one gets its heat colour.
    use pmvc::app::compare::Overlay;
    use pmvc::render::colormap::{self, Scale};
    harness.state_mut().view_mut().overlay = Overlay::Negativity;
    harness.run_steps(2);
    for method in [Method::Mvc, Method::Pmvc] {
        let shading = harness.state_mut().shading_of(Pane::Method(method));
        assert_eq!(shading.scale, Scale::LogMagnitude);
        let read = harness.state().read_back(&shading).unwrap().unwrap();
        let close = |a: [f32; 3], b: [f32; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-3);
        assert!(
            close(read.colours[1], colormap::OUTSIDE),
            "{method}: {:?}",
            read.colours[1]
        );
        let inside = colormap::heat_colour(read.values[0], shading.colour_limit, shading.scale);
        assert!(close(read.colours[0], inside), "{method}");
    }
    // The toolbar's scale buttons set the negativity view's scale alone.
    *harness.state_mut().view_mut().overlay_scale_mut() = Scale::Linear;
    assert_eq!(harness.state().view().negativity_scale, Scale::Linear);
    assert_eq!(harness.state().view().scale, Scale::Linear);
    harness.state_mut().view_mut().overlay = Overlay::Heatmap;
    *harness.state_mut().view_mut().overlay_scale_mut() = Scale::LogMagnitude;
    assert_eq!(harness.state().view().negativity_scale, Scale::Linear);
}

/// With every weight at zero or above and every row's smallest weight zero (the
/// mesh's vertices on the cage's corners), the negativity scale ends at its floor:
/// a magnitude of 0 is not stretched to full colour, nor does the bar claim ±1.
#[test]
fn the_negativity_scale_has_a_floor() {
    use pmvc::app::compare::{Overlay, NEGATIVITY_FLOOR};
    use pmvc::app::editor::FileRole;
    let Some(mut harness) = editor_with(EditorOptions::default()) else {
        return;
    };
    run_until_bound(&mut harness);
    let dir = tempfile::tempdir().unwrap();
    let sphere = pmvc::geometry::procedural::icosphere(1.0, 1);
    let cage = common::write(dir.path(), "sphere.obj", &common::cage_obj(&sphere));
    let corners = common::write(
        dir.path(),
        "corners.obj",
        &common::points_obj(sphere.positions()),
    );
    assert!(harness.state_mut().open_file(FileRole::Cage, &cage));
    assert!(harness.state_mut().open_file(FileRole::Mesh, &corners));
    run_until_bound(&mut harness);
    harness.state_mut().view_mut().overlay = Overlay::Negativity;
    harness.run_steps(2);
    let shading = harness.state_mut().shading_of(Pane::Method(Method::Pmvc));
    assert_eq!(shading.colour_limit, NEGATIVITY_FLOOR);
    let read = harness.state().read_back(&shading).unwrap().unwrap();
    let white = pmvc::render::colormap::ZERO;
    for colour in &read.colours {
        assert!(
            colour.iter().zip(white).all(|(a, b)| (a - b).abs() < 1e-3),
            "{colour:?}"
        );
    }
}

/// The viewport's rectangle, which must not move under the cursor.
fn viewport_rect(harness: &Harness<'static, EditorApp>) -> egui::Rect {
    harness.state().pane_rects()[0].1
}

/// Selecting a handle (its x/y/z row) and starting a bind (its progress line) must
/// not widen the side panel and shift the model under the cursor.
#[test]
fn selecting_a_handle_or_binding_keeps_the_viewport_still() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    let before = viewport_rect(&harness);
    let (handle, at) = isolated_handle(&harness);
    click(&mut harness, at);
    assert_eq!(
        harness.state().document().selection().len(),
        1,
        "handle {handle} selected"
    );
    harness.run_steps(3);
    assert_eq!(viewport_rect(&harness), before, "after selecting a handle");
    // Long numbers in the handle's x/y/z fields.
    let far = glam::DVec3::new(-10.1234, -10.1234, -10.1234);
    harness.state_mut().set_handle_position(handle, far);
    harness.run_steps(3);
    assert_eq!(viewport_rect(&harness), before, "with long coordinates");
    harness.state_mut().set_resolution(24);
    harness.run_steps(3);
    assert!(harness.state().is_binding());
    assert_eq!(viewport_rect(&harness), before, "while binding");
    run_until_bound(&mut harness);
    assert_eq!(viewport_rect(&harness), before, "after the bind");
}

fn asked_for_focus(harness: &Harness<'static, EditorApp>) -> bool {
    harness
        .output()
        .viewport_output
        .values()
        .flat_map(|viewport| &viewport.commands)
        .any(|command| matches!(command, egui::ViewportCommand::Focus))
}

/// Under a bare X server the window starts without keyboard focus and a click
/// does not give it: the editor asks for focus, and again on a click without it.
#[test]
fn the_window_asks_for_keyboard_focus_at_start_and_on_a_click() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.run_steps(2);
    assert!(!asked_for_focus(&harness), "asks once, not every frame");
    let viewports = &mut harness.input_mut().viewports;
    viewports.entry(egui::ViewportId::ROOT).or_default().focused = Some(false);
    let at = egui::pos2(400.0, 600.0);
    harness.hover_at(at);
    harness.step();
    harness.event(egui::Event::PointerButton {
        pos: at,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::NONE,
    });
    harness.step();
    assert!(
        asked_for_focus(&harness),
        "a click without focus asks again"
    );
}

#[test]
fn the_first_run_shows_mvc_and_pmvc_apart_at_once() {
    use egui_kittest::kittest::Queryable;
    let Some(mut harness) = editor_with(EditorOptions::first_run()) else {
        return;
    };
    // The side-by-side view binds PMVC, then MVC.
    for _ in 0..10 {
        run_until_bound(&mut harness);
        harness.run_steps(2);
    }
    let app = harness.state();
    assert!(app.document().weights(Method::Mvc).is_some());
    assert!(app.document().weights(Method::Pmvc).is_some());
    assert_eq!(app.view().layout, Layout::SideBySide);
    assert!(app.view().difference_pane);
    assert_ne!(app.document().pose(), app.document().cage().positions());
    assert!(
        !app.pose_is_unsaved(),
        "the bundled pose is not unsaved work"
    );
    harness.get_by_label(pmvc::app::ui::toolbar::FIRST_RUN_LINE);

    // What the views show, as the vertex shader computes it: MVC's and PMVC's
    // meshes are apart by a visible share of the cage.
    let deformed = |method| {
        let shading = pmvc::render::Shading {
            method,
            ..Default::default()
        };
        app.read_back(&shading).unwrap().unwrap().positions
    };
    let apart = max_distance(&deformed(Method::Mvc), &deformed(Method::Pmvc));
    let diagonal = app.document().cage().diagonal() as f32;
    assert!(
        apart > 0.05 * diagonal,
        "MVC and PMVC differ by only {:.2}% of the cage diagonal",
        100.0 * apart / diagonal
    );

    harness.get_by_label("Hide").click();
    harness.run_steps(2);
    assert!(harness
        .query_by_label(pmvc::app::ui::toolbar::FIRST_RUN_LINE)
        .is_none());
    // The pose is an ordinary edit: Ctrl+Z returns to rest.
    harness.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    harness.run_steps(2);
    let app = harness.state();
    assert_eq!(app.document().pose(), app.document().cage().positions());
}

/// The colour drawn at `at` (points), from a fresh render.
fn pixel_at(harness: &mut Harness<'static, EditorApp>, at: egui::Pos2) -> [u8; 4] {
    let image = harness.render().expect("render");
    let scale = harness.ctx.pixels_per_point();
    image
        .get_pixel((at.x * scale) as u32, (at.y * scale) as u32)
        .0
}

#[test]
fn the_cage_can_be_hidden_handles_resized_and_the_selection_framed() {
    use egui::Key;
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.run_steps(2);
    let framed = harness.state().camera();
    let (handle, at) = isolated_handle(&harness);
    let shown = pixel_at(&mut harness, at);

    // H hides the cage: its handle is no longer drawn and cannot be picked.
    harness.key_press(Key::H);
    harness.run_steps(2);
    assert!(!harness.state().view().show_cage);
    assert_ne!(pixel_at(&mut harness, at), shown, "the handle is not drawn");
    click(&mut harness, at);
    assert!(harness.state().document().selection().is_empty());
    harness.key_press(Key::H);
    harness.run_steps(2);
    assert_eq!(pixel_at(&mut harness, at), shown);

    // A larger handle is picked farther from its centre.
    let beside = at + egui::vec2(12.0, 0.0);
    click(&mut harness, beside);
    assert!(harness.state().document().selection().is_empty());
    harness.state_mut().view_mut().handle_size = 10.0;
    harness.run_steps(2);
    click(&mut harness, beside);
    let selection: Vec<usize> = harness
        .state()
        .document()
        .selection()
        .iter()
        .copied()
        .collect();
    assert_eq!(selection, vec![handle]);

    // F frames the selected handle; Home frames everything again.
    harness.key_press(Key::F);
    harness.run_steps(2);
    let camera = harness.state().camera();
    let position = harness.state().document().pose()[handle].as_vec3();
    assert!(camera.target.distance(position) < 1e-4);
    assert!(camera.distance < 0.5 * framed.distance);
    harness.key_press(Key::Home);
    harness.run_steps(2);
    assert_eq!(harness.state().camera().target, framed.target);
    assert_eq!(harness.state().camera().distance, framed.distance);
}

#[test]
fn the_wireframe_draws_the_mesh_edges_over_the_surface_and_goes_away_again() {
    let Some(mut harness) = editor() else { return };
    run_until_bound(&mut harness);
    harness.run_steps(2);
    let (_, rect) = harness.state().pane_rects()[0];
    let scale = harness.ctx.pixels_per_point();
    let plain = harness.render().unwrap();
    harness.state_mut().view_mut().wireframe = true;
    harness.run_steps(2);
    let wired = harness.render().unwrap();
    let luminance = |p: &image::Rgba<u8>| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
    let (mut darker, mut brighter, mut inside) = (0, 0, 0);
    for y in (rect.top() * scale) as u32..(rect.bottom() * scale) as u32 {
        for x in (rect.left() * scale) as u32..(rect.right() * scale) as u32 {
            let (before, after) = (plain.get_pixel(x, y), wired.get_pixel(x, y));
            inside += 1;
            if luminance(after) + 90 < luminance(before) {
                darker += 1;
            } else if luminance(after) > luminance(before) + 90 {
                brighter += 1;
            }
        }
    }
    // The comb has thousands of triangles: dark lines over a good part of it.
    assert!(darker > inside / 100, "{darker} darker pixels of {inside}");
    assert!(
        brighter < darker / 20,
        "{brighter} brighter, {darker} darker"
    );
    harness.state_mut().view_mut().wireframe = false;
    harness.run_steps(2);
    assert_eq!(
        harness.render().unwrap(),
        plain,
        "off again draws as before"
    );
}

#[test]
fn smooth_shading_normals_follow_the_pose_as_the_cpu_twin_computes_them() {
    let Some(harness) = editor() else { return };
    // The positions are drawn with the weights read as vertex attributes.
    normals_follow_the_pose(harness, true);
}

#[test]
fn smooth_shading_normals_of_weights_split_over_buffers_follow_the_pose() {
    // Storage bindings of 512 KiB split the default scene's weights (1.2 MiB),
    // which are then read from storage alone, and a compute pass finds the
    // positions; the normals' own buffers still fit.
    let Some(state) = render_state_limited_to(small_storage_bindings(512 << 10)) else {
        return;
    };
    normals_follow_the_pose(editor_on(state, Default::default()), false);
}

fn normals_follow_the_pose(mut harness: Harness<'static, EditorApp>, attributes: bool) {
    run_until_bound(&mut harness);
    let method = harness.state().active_method();
    assert_eq!(
        harness.state().attribute_columns(method).is_some(),
        attributes
    );
    let rest = harness.state().document().cage().positions().to_vec();
    // Bend the middle finger: its normals must turn with it.
    for handle in [10, 11, 30, 31] {
        harness
            .state_mut()
            .set_handle_position(handle, rest[handle] + glam::DVec3::new(1.5, 0.5, 0.0));
    }
    harness.run_steps(3);
    // Drawing a frame computes the normals of the pose shown.
    harness.render().unwrap();
    let app = harness.state();
    let method = app.active_method();
    let gpu = app.read_back_normals(method).expect("normals drawn");
    let deformed = app.document().deformed_positions(method);
    let cpu = pmvc::geometry::vertex_normals(&deformed, &app.document().mesh().triangles);
    let rest_normals = pmvc::geometry::vertex_normals(
        &app.document().mesh().positions,
        &app.document().mesh().triangles,
    );
    let mut worst = 0.0f64;
    let mut turned = 0;
    for ((g, c), r) in gpu.iter().zip(&cpu).zip(&rest_normals) {
        let angle = g.as_dvec3().angle_between(*c);
        worst = worst.max(angle);
        turned += usize::from(c.angle_between(*r) > 0.05);
    }
    assert!(
        worst < 2e-3,
        "largest angle between GPU and CPU normals: {worst} rad"
    );
    assert!(
        turned > 100,
        "the pose turns the normals of {turned} vertices"
    );

    // Faceted shading draws differently, and the option comes back.
    let smooth = harness.render().unwrap();
    harness.state_mut().view_mut().smooth_shading = false;
    harness.run_steps(2);
    assert_ne!(harness.render().unwrap(), smooth);
}

#[test]
fn normals_beyond_the_storage_bindings_light_each_face_and_the_menu_says_why() {
    // 256 KiB storage bindings: the comb's triangle corners (349 KiB) do not fit.
    let Some(state) = render_state_limited_to(small_storage_bindings(256 << 10)) else {
        return;
    };
    let options = EditorOptions {
        pose: Some(guide_pose()),
        ..Default::default()
    };
    let mut harness = editor_on(state, options);
    run_until_bound(&mut harness);
    let reason = harness.state().smooth_shading_refusal().expect("refused");
    assert!(
        reason.contains("0.34 MiB") && reason.contains("0.25 MiB"),
        "{reason}"
    );
    // Asked for, smooth shading draws what faceted shading draws.
    assert!(harness.state().view().smooth_shading);
    harness.run_steps(2);
    let asked = harness.render().unwrap();
    harness.state_mut().view_mut().smooth_shading = false;
    harness.run_steps(2);
    assert_eq!(harness.render().unwrap(), asked);
    harness.get_by_label("View").click();
    harness.run_steps(2);
    harness.get_by_label("Smooth shading (unavailable)");
}

#[test]
fn the_first_runs_line_about_the_comb_goes_when_another_scene_opens() {
    use egui_kittest::kittest::Queryable;
    let Some(mut harness) = editor_with(EditorOptions::first_run()) else {
        return;
    };
    run_until_bound(&mut harness);
    harness.get_by_label(pmvc::app::ui::toolbar::FIRST_RUN_LINE);
    harness
        .state_mut()
        .open_bundled(pmvc::app::scenes::BundledScene::Scan);
    harness.run_steps(2);
    assert_eq!(
        harness.state().document().bundled(),
        Some(pmvc::app::scenes::BundledScene::Scan)
    );
    assert!(harness
        .query_by_label(pmvc::app::ui::toolbar::FIRST_RUN_LINE)
        .is_none());
}
