//! The side panel's choice of object, shown where the mesh's or the cage's
//! file has several (an OBJ's `o` objects, a glTF's nodes): what was read is
//! selected, and choosing another reads it in its place, as opening a file
//! does (one undo step).

use crate::app::actions::{Action, FileRole};
use crate::app::ctx::PanelContext;
use crate::formats::{FileObjects, MeshFormat};

/// One combo box per file with a choice of objects; nothing otherwise.
pub fn object_choice(ui: &mut egui::Ui, cx: &mut PanelContext) {
    let document = cx.document();
    let mesh = document
        .mesh_file()
        .filter(|file| file.objects.has_choice())
        .map(|file| (file.objects.clone(), default_label(file.format)));
    let cage = document.cage_objects().clone();
    let cage_default = match document.cage_path().map(crate::formats::gltf::is_gltf_path) {
        Some(true) => default_label(MeshFormat::Gltf),
        _ => default_label(MeshFormat::Obj),
    };
    if let Some((objects, default)) = mesh {
        choice(ui, cx, FileRole::Mesh, &objects, default);
    }
    if cage.has_choice() {
        choice(ui, cx, FileRole::Cage, &cage, cage_default);
    }
}

/// What a file gives where no object is named.
fn default_label(format: MeshFormat) -> &'static str {
    match format {
        MeshFormat::Gltf => "(the first mesh)",
        _ => "(all objects together)",
    }
}

fn choice(
    ui: &mut egui::Ui,
    cx: &mut PanelContext,
    role: FileRole,
    objects: &FileObjects,
    default: &str,
) {
    let label = match role {
        FileRole::Mesh => "Mesh object",
        FileRole::Cage => "Cage object",
    };
    let mut chosen = objects.read.clone();
    egui::ComboBox::from_label(label)
        .selected_text(chosen.as_deref().unwrap_or(default))
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut chosen, None, default);
            for name in &objects.names {
                ui.selectable_value(&mut chosen, Some(name.clone()), name);
            }
        })
        .response
        .on_hover_text(format!(
            "The file has {} objects; choosing one reads it in place of the {}, as opening a file does (Ctrl+Z undoes it)",
            objects.names.len(),
            match role {
                FileRole::Mesh => "mesh",
                FileRole::Cage => "cage",
            }
        ));
    if chosen != objects.read {
        cx.send(Action::OpenObject {
            role,
            object: chosen,
        });
    }
}
