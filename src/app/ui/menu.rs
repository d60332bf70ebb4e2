//! The menu bar: File, Edit, View and Scenes.

//! The menu bar sees the document, the view settings and the recent files,
//! and sends an action for every entry chosen.

use crate::app::actions::{Action, CageRequest, FileAction};
use crate::app::compare::HANDLE_SIZES;
use crate::app::ctx::PanelContext;
use crate::app::scenes::BundledScene;
use crate::render::viewport::MSAA_SAMPLES;

pub fn menu_bar(ui: &mut egui::Ui, cx: &mut PanelContext) {
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| file_menu(ui, cx));
        ui.menu_button("Edit", |ui| edit_menu(ui, cx));
        ui.menu_button("View", |ui| view_menu(ui, cx));
        ui.menu_button("Scenes", |ui| {
            for bundled in BundledScene::ALL {
                if ui.button(bundled.title()).clicked() {
                    cx.send(Action::OpenBundled(bundled));
                }
            }
        });
        ui.menu_button("Help", |ui| {
            if ui.button("Shortcuts").clicked() {
                cx.send(Action::ShowShortcuts);
            }
        });
    });
}

fn file_menu(ui: &mut egui::Ui, cx: &mut PanelContext) {
    if ui.button("Open mesh…").clicked() {
        cx.send(Action::AskForFile(FileAction::OpenMesh));
    }
    if ui.button("Open cage…").clicked() {
        cx.send(Action::AskForFile(FileAction::OpenCage));
    }
    if ui
            .button("Generate cage…")
            .on_hover_text("A cage of about a chosen number of vertices around the mesh, shown before it replaces the current one")
            .clicked()
        {
            cx.send(Action::CageWindow(CageRequest::Open));
        }
    ui.menu_button("Recent", |ui| {
        let recent = cx.shown().recent.clone();
        if recent.is_empty() {
            ui.label("(none)");
        }
        for entry in recent {
            if ui
                .button(entry.label())
                .on_hover_text(entry.paths())
                .clicked()
            {
                cx.send(Action::OpenRecent(entry.clone()));
            }
        }
    });
    ui.separator();
    if ui.button("Open session… (Ctrl+O)").clicked() {
        cx.send(Action::AskForFile(FileAction::OpenSession));
    }
    if ui.button("Save session (Ctrl+S)").clicked() {
        cx.send(Action::SaveSessionAgain);
    }
    if ui.button("Save session as… (Ctrl+Shift+S)").clicked() {
        cx.send(Action::AskForFile(FileAction::SaveSession));
    }
    ui.separator();
    if ui.button("Load pose…").clicked() {
        cx.send(Action::AskForFile(FileAction::LoadPose));
    }
    if ui.button("Save pose…").clicked() {
        cx.send(Action::AskForFile(FileAction::SavePose));
    }
    if ui
        .button("Save cage…")
        .on_hover_text(
            "The rest cage with its faces as read (quads stay quads), and its current \
             pose beside it as NAME.posed.obj",
        )
        .clicked()
    {
        cx.send(Action::AskForFile(FileAction::SaveCage));
    }
    if ui.button("Export deformed mesh…").clicked() {
        cx.send(Action::AskForFile(FileAction::ExportMesh));
    }
    if ui
        .button("Export glTF (poses as shape keys)…")
        .on_hover_text(
            "The mesh as .glb or .gltf: the rest mesh as its base (Blender's Basis), every \
             named pose a morph target (shape key) named after it, and the timeline's keys \
             as its animation, starting at rest",
        )
        .clicked()
    {
        cx.send(Action::AskForFile(FileAction::ExportGltf));
    }
    if ui
        .button("Export glTF, the pose as its base…")
        .on_hover_text(
            "As Export glTF, with the mesh deformed by the current pose as the base shape",
        )
        .clicked()
    {
        cx.send(Action::AskForFile(FileAction::ExportGltfPosedBase));
    }
    if ui
        .button("Export coloured mesh (PLY)…")
        .on_hover_text(
            "The deformed mesh with each vertex in the colour the view gives it \
                 (heatmap, negativity or difference); the header names the scale and range.",
        )
        .clicked()
    {
        cx.send(Action::AskForFile(FileAction::ExportColouredMesh));
    }
    if ui
        .button("Save image…")
        .on_hover_text("The views as drawn, with their titles and colour bars, as PNG.")
        .clicked()
    {
        cx.send(Action::AskForFile(FileAction::SaveImage));
    }
    ui.separator();
    let mut in_window = cx.shown().in_window_dialog;
    let toggle = ui
        .checkbox(&mut in_window, "In-window file dialog")
        .on_hover_text(
            "Use pmvc's own file dialog instead of the system's. It is chosen by itself \
             where the system's cannot appear (no desktop portal).",
        );
    if toggle.changed() {
        cx.send(Action::SetInWindowDialog(in_window));
    }
    ui.separator();
    if ui.button("Quit (Ctrl+Q)").clicked() {
        cx.send(Action::Quit);
    }
}

fn edit_menu(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let model = cx.model();
    let undo = model.undo_label().map(String::from);
    let redo = model.redo_label().map(String::from);
    let undo_text = match &undo {
        Some(action) => format!("Undo {action} (Ctrl+Z)"),
        None => "Undo (Ctrl+Z)".into(),
    };
    if ui
        .add_enabled(undo.is_some(), egui::Button::new(undo_text))
        .clicked()
    {
        cx.send(Action::Undo);
    }
    let redo_text = match &redo {
        Some(action) => format!("Redo {action} (Ctrl+Shift+Z)"),
        None => "Redo (Ctrl+Shift+Z)".into(),
    };
    if ui
        .add_enabled(redo.is_some(), egui::Button::new(redo_text))
        .clicked()
    {
        cx.send(Action::Redo);
    }
    if ui.button("Reset pose").clicked() {
        cx.send(Action::ResetPose);
    }
    if ui.button("Use pose as rest shape (rebind)").clicked() {
        cx.send(Action::PoseAsRest);
    }
}

fn view_menu(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let shown = cx.shown();
    let mut view = shown.view;
    let mut statistics = shown.statistics_shown;
    if ui.checkbox(&mut statistics, "Statistics").changed() {
        cx.send(Action::ShowStatistics(statistics));
    }
    ui.checkbox(
        &mut view.hover_in_shaded,
        "Weights under the cursor (always)",
    );
    let mut highlight = cx.shown().highlight_outside;
    if ui
        .checkbox(&mut highlight, "Highlight outside vertices")
        .changed()
    {
        cx.send(Action::SetHighlightOutside(highlight));
    }
    let mut antialiased = cx.shown().antialiased.unwrap_or(false);
    if ui
        .checkbox(&mut antialiased, "Anti-aliasing (4x MSAA)")
        .changed()
    {
        let samples = if antialiased { MSAA_SAMPLES } else { 1 };
        cx.send(Action::SetSampleCount(samples));
    }
    if ui.button("Frame selection (F)").clicked() {
        cx.send(Action::FrameSelection);
    }
    if ui.button("Frame all (Home)").clicked() {
        cx.send(Action::FrameAll);
    }
    ui.separator();
    ui.checkbox(&mut view.show_cage, "Cage and handles (H)")
        .on_hover_text("Hidden handles cannot be picked or box-selected");
    match cx.shown().smooth_shading_refusal.clone() {
        None => {
            ui.checkbox(&mut view.smooth_shading, "Smooth shading")
                .on_hover_text(
                    "Light the mesh with each vertex's normal of the deformed mesh, \
                         recomputed on the GPU when the pose changes; off: one normal per face \
                         (faceted)",
                );
        }
        Some(reason) => {
            ui.add_enabled(
                false,
                egui::Checkbox::new(&mut false, "Smooth shading (unavailable)"),
            )
            .on_disabled_hover_text(reason);
        }
    }
    ui.checkbox(&mut view.wireframe, "Wireframe")
        .on_hover_text("The mesh's edges over its surface, deformed with it");
    let label = ui.label("Handle size");
    ui.add(
        egui::Slider::new(&mut view.handle_size, HANDLE_SIZES)
            .suffix(" pt")
            .step_by(0.5),
    )
    .labelled_by(label.id);
    if view != cx.shown().view {
        cx.send(Action::SetView(view));
    }
}
