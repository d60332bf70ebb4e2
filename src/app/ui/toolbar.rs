//! The comparison controls above the viewport: the method shown, the layout,
//! which methods are compared, and the colouring. They edit a copy of the view
//! settings and send it back when it changed.

use crate::app::actions::Action;
use crate::app::compare::{Layout, Overlay, ViewSettings, DIFFERENCE_LIMITS};
use crate::app::ctx::PanelContext;
use crate::coords::{BindOptions, Method, QuadSplit, Twin, WeightsId};
use crate::render::colormap::Scale;
use crate::render::MAX_VIEWS;

/// What the first run shows, in one line.
pub const FIRST_RUN_LINE: &str = "The middle finger's handles are pulled up. \
    Left, MVC: negative weights make the fingers beside it sink. Middle, PMVC: they stay. \
    Right: the distance between the two. Drag any handle to try.";

/// The first run's line, with a button that dismisses it.
pub fn first_run_line(ui: &mut egui::Ui, cx: &mut PanelContext) {
    ui.horizontal(|ui| {
        if ui.small_button("Hide").clicked() {
            cx.send(Action::HideFirstRunLine);
        }
        ui.label(egui::RichText::new(FIRST_RUN_LINE).strong());
    });
}

pub fn toolbar(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let mut view = cx.shown().view;
    // Sent after the view settings, which they change further.
    let mut later = Vec::new();
    ui.horizontal_wrapped(|ui| {
        ui.label("Method (M):");
        let active = cx.shown().bind_options.method;
        let mut method = active;
        for family in Method::ALL {
            ui.selectable_value(&mut method, family, family.name())
                .on_hover_text(family.spec().summary);
        }
        if method != active {
            cx.send(Action::SetMethod(method));
        }
        ui.separator();
        ui.label("View:");
        let layout = &mut view.layout;
        ui.selectable_value(layout, Layout::Single, "Single");
        ui.selectable_value(layout, Layout::SideBySide, "Side by side");
        ui.selectable_value(layout, Layout::Difference, "Difference");
        match view.layout {
            Layout::SideBySide => comparison_controls(ui, &mut view, &mut later),
            Layout::Difference => {
                let has_quads = cx.document().cage().has_quads();
                let setting = cx.shown().bind_options;
                difference_controls(ui, &mut view, &mut later, setting, has_quads)
            }
            Layout::Single => {}
        }
        ui.separator();
        ui.label("Colour:");
        let overlay = &mut view.overlay;
        ui.selectable_value(overlay, Overlay::Shaded, "Shaded");
        ui.selectable_value(overlay, Overlay::Heatmap, "Heatmap λi");
        ui.selectable_value(overlay, Overlay::Negativity, "Negativity");
        if view.overlay == Overlay::Heatmap {
            heatmap_controls(ui, cx, &mut view);
        }
        if view.overlay != Overlay::Shaded || view.layout != Layout::Single {
            let scale = view.overlay_scale_mut();
            ui.selectable_value(scale, Scale::Linear, "Linear");
            ui.selectable_value(scale, Scale::LogMagnitude, "Log");
        }
    });
    if view != cx.shown().view {
        cx.send(Action::SetView(view));
    }
    for action in later {
        cx.send(action);
    }
}

/// Which coordinate function the heatmap shows: a cage vertex's, or (Green
/// coordinates) a cage triangle's ψ.
fn heatmap_controls(ui: &mut egui::Ui, cx: &PanelContext, view: &mut ViewSettings) {
    let document = cx.document();
    // Green's ψ columns as bound: a triangle's each, or on QGC the lone
    // triangles' then four corner normals per quad.
    let triangles = document.bound(Method::Green).map_or_else(
        || document.cage().triangle_count(),
        |set| set.options.columns(document.cage()) - Method::Green.vertex_columns(document.cage()),
    );
    let mut of_triangle = view.heat_triangle.is_some();
    let label = ui.label("of");
    egui::ComboBox::from_id_salt("heatmap of")
        .selected_text(if of_triangle {
            "ψj of face"
        } else {
            "λi of vertex"
        })
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut of_triangle, false, "λi of vertex")
                .on_hover_text(
                    "Every family: the coordinate of cage vertex i (φi for Green; for \
                     Somigliana Bxx, the x-from-x entry of its 3×3 block)",
                );
            ui.selectable_value(&mut of_triangle, true, "ψj of face")
                .on_hover_text(
                    "Green coordinates: ψ column j, the function of cage triangle j; \
                     on quads (QGC) the lone triangles' columns, then four per quad, \
                     one per corner normal (the colour bar names which). Somigliana: \
                     Fxx, the x-from-x entry of triangle j's face block",
                );
        })
        .response
        .labelled_by(label.id);
    if of_triangle {
        let mut triangle = view.heat_triangle.unwrap_or(0);
        let label = ui.label("j =");
        ui.add(egui::DragValue::new(&mut triangle).range(0..=triangles.saturating_sub(1)))
            .labelled_by(label.id)
            .on_hover_text(
                "ψ column: a cage triangle in the order the faces are triangulated, or (QGC) \
                 a quad's corner after the lone triangles",
            );
        view.heat_triangle = Some(triangle);
    } else {
        view.heat_triangle = None;
        let last = cx.document().pose().len().saturating_sub(1);
        let label = ui.label("i =");
        ui.add(egui::DragValue::new(&mut view.heat_vertex).range(0..=last))
            .labelled_by(label.id)
            .on_hover_text("Cage vertex whose coordinate is shown (or click its handle)");
    }
}

/// Which methods the side-by-side layout shows.
fn comparison_controls(ui: &mut egui::Ui, view: &mut ViewSettings, later: &mut Vec<Action>) {
    // The viewport draws at most MAX_VIEWS panes: a family past them is not
    // offered, rather than left out of the picture without a word.
    let room = MAX_VIEWS - usize::from(view.difference_pane);
    let full = format!(
        "The viewport shows at most {MAX_VIEWS} views{}: clear a family first",
        if view.difference_pane {
            ", one of them the difference"
        } else {
            ""
        }
    );
    if Method::ALL.len() > 2 {
        ui.menu_button("Compare…", |ui| {
            for family in Method::ALL {
                let mut shown = view.compared.contains(family);
                let offered = shown || view.compared.len() < room;
                let checkbox = egui::Checkbox::new(&mut shown, family.name());
                if ui
                    .add_enabled(offered, checkbox)
                    .on_disabled_hover_text(&full)
                    .changed()
                {
                    view.compared.set(family, shown);
                }
            }
        });
    }
    let difference_fits = view.difference_pane || view.compared.len() < MAX_VIEWS;
    ui.add_enabled(
        difference_fits,
        egui::Checkbox::new(&mut view.difference_pane, "+ difference"),
    )
    .on_disabled_hover_text(format!(
        "The viewport shows at most {MAX_VIEWS} views: clear a family first"
    ));
    if view.difference_pane {
        difference_scale_controls(ui, view, later);
    }
    let mut locked = view.cameras_locked;
    if ui.checkbox(&mut locked, "Lock cameras").changed() {
        later.push(Action::SetCamerasLocked(locked));
    }
}

/// Which two methods the difference compares: "[MVC] vs [PMVC] shown", or a
/// family against a twin of itself: on a cage with quads bound split along a
/// diagonal ("[itself, split: shorter diagonal] vs [PMVC] shown"), or at its
/// parameter's reference value ("[itself, exact] vs [PMVC] shown").
fn difference_controls(
    ui: &mut egui::Ui,
    view: &mut ViewSettings,
    later: &mut Vec<Action>,
    setting: BindOptions,
    has_quads: bool,
) {
    let shown = view.difference[1];
    let setting = BindOptions {
        method: shown,
        ..setting
    };
    // The twins on offer: those that would differ from the shown family as
    // the settings bind it.
    let mut twins: Vec<Twin> = Vec::new();
    if has_quads {
        twins.extend([QuadSplit::Shorter, QuadSplit::Longer].map(Twin::Split));
    }
    twins.push(Twin::Reference);
    twins.retain(|twin| twin.options(setting).is_some());
    let held = match (view.difference_split, view.difference_reference) {
        (Some(split), _) => Some(Twin::Split(split)),
        (None, true) => Some(Twin::Reference),
        (None, false) => None,
    };
    let mut against = (view.difference[0], held.filter(|twin| twins.contains(twin)));
    let twin_label = |twin: Twin| match twin {
        Twin::Split(split) => format!("itself, split: {} diagonal", split.id()),
        Twin::Reference => {
            let name = WeightsId::twin(shown, twin).to_string();
            // "PMVC (exact)" → "itself, exact"
            let inner = name.rsplit_once(" (").map_or(name.as_str(), |(_, r)| r);
            format!("itself, {}", inner.trim_end_matches(')'))
        }
    };
    let selected = match against.1 {
        Some(twin) => twin_label(twin),
        None => against.0.name().to_owned(),
    };
    // Tall enough for every family and twin: a list that scrolls hides entries.
    let list_height = ui.ctx().content_rect().height();
    egui::ComboBox::from_label("vs")
        .selected_text(selected)
        .height(list_height)
        .show_ui(ui, |ui| {
            for family in Method::ALL {
                ui.selectable_value(&mut against, (family, None), family.name());
            }
            let family = against.0;
            for &twin in &twins {
                let hover = match twin {
                    Twin::Split(_) => {
                        "The shown family bound with the cage's quads split along this diagonal: \
                         how far the invisible split moves the mesh"
                    }
                    Twin::Reference => {
                        "The shown family at its reference setting (PMVC: exact, no cube map): \
                         how far the approximation moves the mesh"
                    }
                };
                ui.selectable_value(&mut against, (family, Some(twin)), twin_label(twin))
                    .on_hover_text(hover);
            }
        });
    view.difference[0] = against.0;
    view.difference_split = match against.1 {
        Some(Twin::Split(split)) => Some(split),
        _ => None,
    };
    view.difference_reference = against.1 == Some(Twin::Reference);
    let mut chosen = shown;
    egui::ComboBox::from_label("shown")
        .selected_text(chosen.name())
        .height(list_height)
        .show_ui(ui, |ui| {
            for family in Method::ALL {
                ui.selectable_value(&mut chosen, family, family.name());
            }
        });
    view.difference[1] = chosen;
    difference_scale_controls(ui, view, later);
}

/// Auto (the largest distance, at least `compare::DIFFERENCE_FLOOR`) or a fixed end
/// of the difference's colour scale, shared by every difference view.
fn difference_scale_controls(ui: &mut egui::Ui, view: &mut ViewSettings, later: &mut Vec<Action>) {
    let mut fixed = view.difference_limit.is_some();
    let toggle = ui.checkbox(&mut fixed, "fixed scale").on_hover_text(
        "Keep the difference's colour scale at one distance (in % of the cage diagonal) \
         across poses and views; pmvc edit --difference-limit sets it for a run",
    );
    if toggle.changed() {
        // The scale shown now, which the editor measures.
        later.push(Action::FixDifferenceScale(fixed));
    }
    if let Some(limit) = view.difference_limit {
        let mut percent = limit * 100.0;
        let field = ui.add(
            egui::DragValue::new(&mut percent)
                .speed(0.01)
                .range(DIFFERENCE_LIMITS.start() * 100.0..=DIFFERENCE_LIMITS.end() * 100.0)
                .suffix("%"),
        );
        if field.changed() {
            view.difference_limit = Some(percent / 100.0);
        }
    }
}
