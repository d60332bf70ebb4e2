//! The comparison settings' and read-outs' tests.

use super::*;

#[test]
fn no_more_families_are_compared_than_the_viewport_draws() {
    let mut view = ViewSettings {
        layout: Layout::SideBySide,
        compared: MethodSet::of(&Method::ALL),
        ..Default::default()
    };
    let note = view.fit_compared().expect("six do not fit");
    assert_eq!(view.compared.len(), crate::render::MAX_VIEWS);
    assert!(
        note.starts_with("the viewport shows at most 4 views; left out MEC"),
        "{note}"
    );
    view.difference_pane = true;
    assert!(view
        .fit_compared()
        .unwrap()
        .contains("one of them the difference"));
    assert_eq!(view.compared.len(), crate::render::MAX_VIEWS - 1);
    assert_eq!(view.fit_compared(), None, "what fits stays");
}

fn matrix(rows: &[&[f32]]) -> Weights {
    Weights {
        rows: rows.len(),
        cols: rows[0].len(),
        values: rows.iter().flat_map(|r| r.iter().copied()).collect(),
    }
}

#[test]
fn panes_follow_the_layout() {
    let mut settings = ViewSettings::default();
    assert_eq!(
        settings.panes(Method::Mvc, 3),
        vec![Pane::Method(Method::Mvc)]
    );
    settings.layout = Layout::SideBySide;
    assert_eq!(
        settings.panes(Method::Mvc, 3),
        vec![Pane::Method(Method::Mvc), Pane::Method(Method::Pmvc)]
    );
    settings.difference_pane = true;
    let difference = Pane::Difference {
        against: WeightsId::of(Method::Mvc),
        shown: Method::Pmvc,
    };
    assert_eq!(settings.panes(Method::Pmvc, 3)[2], difference);
    // With room for two views, the difference keeps its place.
    assert_eq!(settings.panes(Method::Pmvc, 2)[1], difference);
    settings.layout = Layout::Difference;
    assert_eq!(settings.panes(Method::Mvc, 3), vec![difference]);
    assert_eq!(settings.colouring(difference), Colouring::MethodDistance);
    settings.compared.set(Method::Mvc, false);
    assert_eq!(settings.compared.iter().collect::<Vec<_>>(), [Method::Pmvc]);
}

#[test]
fn ranges_of_a_column_and_of_row_minima() {
    let weights = matrix(&[&[0.5, 0.6, -0.1], &[0.2, 0.3, 0.5]]);
    assert_eq!(
        column_range(&weights, 2),
        Some(ValueRange {
            min: -0.1,
            max: 0.5
        })
    );
    assert_eq!(column_range(&weights, 3), None);
    assert_eq!(
        row_minimum_range(&weights, weights.cols, 1, &[]),
        Some(ValueRange {
            min: -0.1,
            max: 0.2
        })
    );
    // An outside row is left out.
    assert_eq!(
        row_minimum_range(&weights, weights.cols, 1, &[0]),
        Some(ValueRange { min: 0.2, max: 0.2 })
    );
    assert_eq!(
        ValueRange {
            min: -0.7,
            max: 0.5
        }
        .magnitude(),
        0.7
    );
}

#[test]
fn the_front_vertex_under_the_pointer_wins() {
    let camera = crate::render::OrbitCamera::default();
    let view_projection = camera.view_projection(1.0);
    let towards_eye = (camera.eye() - camera.target).normalize() * 0.5;
    let positions = [camera.target - towards_eye, camera.target + towards_eye];
    let size = glam::Vec2::splat(100.0);
    let centre = glam::Vec2::splat(50.0);
    let picked = vertex_under_pointer(
        &positions,
        view_projection,
        glam::Vec2::ZERO,
        size,
        centre,
        3.0,
    );
    assert_eq!(picked, Some(1));
    let far = glam::Vec2::new(5.0, 5.0);
    assert_eq!(
        vertex_under_pointer(
            &positions,
            view_projection,
            glam::Vec2::ZERO,
            size,
            far,
            3.0
        ),
        None
    );
}
