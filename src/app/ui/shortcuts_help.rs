//! Help > Shortcuts: the shortcut table as the editor matches it, each entry
//! with its keys, what it does and when it works, and the keys a transform
//! under way listens to.

use crate::app::shortcuts::SHORTCUTS;

/// The window, shown or not.
#[derive(Clone, Debug, Default)]
pub struct ShortcutsHelp {
    pub open: bool,
}

/// The keys of a G, R or S transform under way, which are its own.
const TRANSFORM_KEYS: [(&str, &str); 5] = [
    ("X, Y, Z", "Constrain to that world axis (again: free)"),
    (
        "0–9 . -",
        "Type the amount: a distance, degrees or a factor",
    ),
    ("Enter or click", "Confirm the transform (one undo step)"),
    (
        "Esc or right click",
        "Cancel it: the pose comes back exactly",
    ),
    ("Backspace", "Remove the last typed character"),
];

impl ShortcutsHelp {
    pub fn window(&mut self, ctx: &egui::Context) {
        egui::Window::new("Shortcuts")
            .open(&mut self.open)
            .collapsible(false)
            .resizable(false)
            .default_pos(egui::pos2(320.0, 90.0))
            .show(ctx, |ui| {
                ui.label("Each is matched with exactly the modifiers shown.");
                egui::Grid::new("shortcuts")
                    .num_columns(3)
                    .striped(true)
                    .show(ui, |ui| {
                        ui.strong("Keys");
                        ui.strong("Does");
                        ui.strong("Works");
                        ui.end_row();
                        for (keys, scope, shortcut) in SHORTCUTS {
                            ui.monospace(keys.label());
                            ui.label(shortcut.describe());
                            ui.label(scope.describe());
                            ui.end_row();
                        }
                    });
                ui.separator();
                ui.strong("During a transform (G, R, S)");
                egui::Grid::new("transform keys")
                    .num_columns(2)
                    .striped(true)
                    .show(ui, |ui| {
                        for (keys, does) in TRANSFORM_KEYS {
                            ui.monospace(keys);
                            ui.label(does);
                            ui.end_row();
                        }
                    });
            });
    }
}
