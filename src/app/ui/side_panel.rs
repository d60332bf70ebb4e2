//! The side panel: the scene, binding (each family's parameter, progress and
//! cancel), quality, the selected handle's position, and the notices.

use crate::app::actions::Action;
use crate::app::commands::{Command, GestureKind, POSE_EDIT};
use crate::app::ctx::PanelContext;
use crate::app::ui::named_poses::PoseBlend;
use crate::app::ui::notices::Notices;
use crate::app::ui::object_choice::object_choice;
use crate::app::ui::pose_panel::PosePanel;
use crate::app::ui::quality_table::quality_table;
use crate::app::ui::statistics::StatisticsPanel;
use crate::app::ui::timeline::TimelinePanel;
use crate::coords::QuadSplit;
use std::time::Duration;

/// The panels the side panel shows below its own sections.
pub struct Sections<'a> {
    pub pose_tools: &'a mut PosePanel,
    pub named_poses: &'a mut PoseBlend,
    pub timeline: &'a mut TimelinePanel,
    pub statistics: &'a StatisticsPanel,
    pub notices: &'a Notices,
}

pub fn side_panel(ui: &mut egui::Ui, cx: &mut PanelContext, sections: Sections) {
    let ctx = ui.ctx().clone();
    ui.heading(cx.document().title());
    ui.label(format!(
        "{} mesh vertices, {} cage vertices",
        cx.document().mesh().positions.len(),
        cx.document().pose().len()
    ));
    object_choice(ui, cx);
    ui.separator();
    binding_section(ui, cx, &ctx);
    ui.separator();
    quality_table(ui, cx);
    ui.separator();
    selection_section(ui, cx);
    ui.separator();
    sections.pose_tools.ui(ui, cx);
    ui.separator();
    sections.named_poses.ui(ui, cx);
    ui.separator();
    sections.timeline.ui(ui, cx);
    ui.separator();
    ui.small("Left-drag: orbit / move handles · Right-drag or Shift+middle: pan · Wheel: zoom · Ctrl+drag: box select · Shift+click: toggle · X/Y/Z: axis · G/R/S: move/rotate/scale · O: soft selection · Shift+right click: 3D cursor · F: frame selection · Home: frame all · H: cage · M: next method · Esc: deselect");
    if sections.statistics.is_shown() {
        ui.separator();
        sections.statistics.ui(ui, cx);
    }
    ui.separator();
    sections.notices.ui(ui, cx);
}

fn binding_section(ui: &mut egui::Ui, cx: &mut PanelContext, ctx: &egui::Context) {
    let family_parameters = cx.shown().family_parameters.clone();
    ui.label("Binding");
    for (family, bound_value) in family_parameters {
        let Some(spec) = family.spec().parameter else {
            continue;
        };
        let value = parameter_choice(ui, &spec, bound_value).0;
        if value != bound_value {
            cx.send(Action::SetFamilyParameter(family, value));
        }
    }
    deform_settings(ui, cx);
    quads_choice(ui, cx);
    if ui
            .button("Subdivide cage")
            .on_hover_text(
                "1-to-4 midpoint subdivision, keeping the pose; smooths the coordinates near sharp reflex edges. Rebinds.",
            )
            .clicked()
        {
            cx.send(Action::SubdivideCage);
        }
    if let Some(status) = cx.shown().bind_status {
        ui.add(
            egui::ProgressBar::new(status.fraction)
                .text(format!("{} / {} vertices", status.done, status.total)),
        );
        let remaining = status.remaining.map_or("estimating…".into(), |r| {
            format!("{:.1} s left", r.as_secs_f32())
        });
        let elapsed = if cx.shown().hide_timings {
            String::new()
        } else {
            format!(
                " — {:.1} s elapsed, {remaining}",
                status.elapsed.as_secs_f32()
            )
        };
        ui.label(format!(
            "{} {}{elapsed}",
            if status.cancelling {
                "Cancelling"
            } else {
                "Binding"
            },
            status.options.family_name(cx.document().cage()),
        ));
        if ui.button("Cancel").clicked() {
            cx.send(Action::CancelBind);
        }
        ctx.request_repaint_after(Duration::from_millis(100));
    } else {
        let document = cx.document();
        let unbound = (cx.shown().wanted.iter()).any(|&m| document.bound(m).is_none());
        if unbound && ui.button("Bind").clicked() {
            cx.send(Action::StartBind);
        }
    }
    if let Some(set) = cx.document().bound(cx.shown().bind_options.method) {
        ui.label(format!("Bound on {}", set.device));
    }
    if cx.document().bound_methods().next().is_some() {
        let outside = cx.document().outside().len();
        ui.label(format!("{outside} mesh vertices outside the cage"));
        let mut highlight = cx.shown().highlight_outside;
        if outside > 0 && ui.checkbox(&mut highlight, "Highlight them").changed() {
            cx.send(Action::SetHighlightOutside(highlight));
        }
    }
}

/// A parameter's list of the spec's choices, showing `current`: the value
/// chosen (`current` if none) and the list's response.
fn parameter_choice(
    ui: &mut egui::Ui,
    spec: &crate::coords::ParameterSpec,
    current: u32,
) -> (u32, egui::Response) {
    let mut value = current;
    let response = egui::ComboBox::from_label(spec.label)
        .selected_text((spec.format)(value))
        .show_ui(ui, |ui| {
            for &choice in spec.choices {
                ui.selectable_value(&mut value, choice, (spec.format)(choice));
            }
        })
        .response;
    (value, response)
}

/// The settings the shown families read when their weights deform a pose
/// (Somigliana's bulging): changing one moves the mesh and binds nothing.
fn deform_settings(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let mut specs: Vec<crate::coords::ParameterSpec> = Vec::new();
    for family in &cx.shown().wanted {
        for spec in family.spec().deform_parameters {
            if specs.iter().all(|listed| listed.key != spec.key) {
                specs.push(*spec);
            }
        }
    }
    for spec in specs {
        let current = cx.document().deform_value(spec.key);
        let (value, response) = parameter_choice(ui, &spec, current);
        response.on_hover_text(
            "Read when the weights deform the pose: changing it binds nothing again.",
        );
        if value != current {
            cx.send(Action::SetDeformParameter(spec.key, value));
        }
    }
}

/// On a cage with quads: bind them as bilinear patches, or split along a
/// diagonal as before, to reproduce earlier results or see what the split does.
fn quads_choice(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let cage = cx.document().cage();
    if !cage.has_quads() {
        return;
    }
    let quads = cage.quads().len();
    let current = cx.shown().bind_options.quads;
    let mut chosen = current;
    egui::ComboBox::from_label("Quads")
        .selected_text(quad_split_label(current))
        .show_ui(ui, |ui| {
            for split in QuadSplit::ALL {
                ui.selectable_value(&mut chosen, split, quad_split_label(split));
            }
        })
        .response
        .on_hover_text(format!(
            "The cage has {quads} quads. As bilinear patches the weights do not depend on how a quad is indexed or split (MVC on them is QMVC, Green QGC); split, they depend on the diagonal."
        ));
    if chosen != current {
        cx.send(Action::SetQuadSplit(chosen));
    }
}

fn quad_split_label(split: QuadSplit) -> &'static str {
    match split {
        QuadSplit::None => "bilinear patches",
        QuadSplit::Shorter => "split: shorter diagonal",
        QuadSplit::Longer => "split: longer diagonal",
    }
}

fn selection_section(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let selection = cx.document().selection();
    ui.label(format!("Selection: {} handle(s)", selection.len()));
    if let (1, Some(&handle)) = (selection.len(), selection.iter().next()) {
        let mut position = cx.document().pose()[handle];
        let (mut changed, mut drag_started, mut drag_stopped) = (false, false, false);
        ui.label(format!("Handle {handle}"));
        // Fields of a fixed share of the panel: a field sized by its number
        // would widen the panel and move the model under the cursor.
        ui.horizontal(|ui| {
            let spacing = ui.spacing().item_spacing.x;
            let label_width = 3.0 * (ui.spacing().icon_width + 2.0 * spacing);
            let field_size = egui::vec2(
                ((ui.available_width() - label_width) / 3.0).max(40.0),
                ui.spacing().interact_size.y,
            );
            for (label, value) in [
                ("x", &mut position.x),
                ("y", &mut position.y),
                ("z", &mut position.z),
            ] {
                let label = ui.label(label);
                let field = ui
                    .add_sized(
                        field_size,
                        egui::DragValue::new(value).speed(0.01).max_decimals(4),
                    )
                    .labelled_by(label.id);
                changed |= field.changed();
                drag_started |= field.drag_started();
                drag_stopped |= field.drag_stopped();
            }
        });
        // Dragging a field is one undo step; typing a value is one each.
        // The gesture under way when this frame's actions run: one begun
        // this frame counts.
        let dragging =
            drag_started || cx.model().gesture_under_way() == Some(GestureKind::NumericDrag);
        if drag_started {
            cx.send(Action::Apply(Command::BeginGesture(
                GestureKind::NumericDrag,
            )));
        }
        if changed && dragging {
            let mut pose = cx.document().pose().to_vec();
            pose[handle] = position;
            cx.send(Action::Apply(Command::PreviewGesture(pose)));
        } else if changed {
            cx.send(Action::SetHandlePosition(handle, position));
        }
        if drag_stopped && dragging {
            cx.send(Action::Apply(Command::EndGesture {
                action: POSE_EDIT.into(),
            }));
        }
    }
    let model = cx.model();
    let (can_undo, can_redo) = (model.undo_label().is_some(), model.redo_label().is_some());
    ui.horizontal(|ui| {
        if ui.button("Reset pose").clicked() {
            cx.send(Action::ResetPose);
        }
        if ui
            .add_enabled(can_undo, egui::Button::new("Undo"))
            .clicked()
        {
            cx.send(Action::Undo);
        }
        if ui
            .add_enabled(can_redo, egui::Button::new("Redo"))
            .clicked()
        {
            cx.send(Action::Redo);
        }
    });
}
