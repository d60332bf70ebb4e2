//! At start-up, work an editor autosaved and never cleaned up (it crashed, or
//! was killed) is offered back: restore it, discard it, or decide at the next
//! start.

use crate::app::actions::{Action, RecoverAnswer};
use crate::app::ctx::PanelContext;
use crate::app::recovery::LeftBehind;
use crate::formats::shown_path;

#[derive(Debug, Default)]
pub struct RecoveryDialog {
    /// The newest file left behind, and how many there are in all.
    offered: Option<(LeftBehind, usize)>,
    /// Its first frame was drawn.
    drawn: bool,
}

impl RecoveryDialog {
    /// Offer the newest of `found` (newest first), if any.
    pub fn offer(&mut self, found: Vec<LeftBehind>) {
        let count = found.len();
        self.offered = found.into_iter().next().map(|newest| (newest, count));
    }

    pub fn is_open(&self) -> bool {
        self.offered.is_some()
    }

    pub fn ui(&mut self, ctx: &egui::Context, context: &mut PanelContext) {
        let Some((file, count)) = &self.offered else {
            return;
        };
        let age = file
            .written
            .elapsed()
            .map_or_else(|_| "just now".to_owned(), |d| ago(d.as_secs()));
        // A window's first frame only sizes it: at start-up no input brings
        // the next, so ask for it.
        if !self.drawn {
            self.drawn = true;
            ctx.request_repaint();
        }
        let mut answer = None;
        egui::Window::new("Recover unsaved work?")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
            .show(ctx, |ui| {
                ui.label(format!(
                    "An earlier pmvc editor ended without saving its work. It was autosaved {age}:"
                ));
                ui.monospace(shown_path(&file.path).to_string());
                if *count > 1 {
                    ui.label(format!("({} more recovery files are older.)", count - 1));
                }
                ui.horizontal(|ui| {
                    if ui.button("Restore").clicked() {
                        answer = Some(RecoverAnswer::Restore);
                    }
                    if ui.button("Discard").clicked() {
                        answer = Some(RecoverAnswer::Discard);
                    }
                    if ui.button("Not now").clicked() {
                        answer = Some(RecoverAnswer::Later);
                    }
                });
            });
        if let Some(answer) = answer {
            let (file, _) = self.offered.take().expect("shown above");
            context.send(Action::Recover(file.path, answer));
        }
    }
}

/// "3 minutes ago", "2 hours ago".
fn ago(seconds: u64) -> String {
    match seconds {
        0..60 => "less than a minute ago".into(),
        60..3600 => format!("{} minute(s) ago", seconds / 60),
        3600..86400 => format!("{} hour(s) ago", seconds / 3600),
        _ => format!("{} day(s) ago", seconds / 86400),
    }
}
