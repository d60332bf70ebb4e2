//! Messages for the user: what happened (info) and what went wrong (errors).

use crate::app::actions::Action;
use crate::app::ctx::PanelContext;
use egui::Color32;

/// How many notices the side panel lists.
const SHOWN: usize = 6;

/// A message shown in the status area.
#[derive(Clone, Debug, PartialEq)]
pub struct Notice {
    pub text: String,
    pub is_error: bool,
}

#[derive(Clone, Debug, Default)]
pub struct Notices {
    list: Vec<Notice>,
}

impl Notices {
    pub fn info(&mut self, text: impl Into<String>) {
        self.list.push(Notice {
            text: text.into(),
            is_error: false,
        });
    }

    pub fn error(&mut self, text: impl Into<String>) {
        self.list.push(Notice {
            text: text.into(),
            is_error: true,
        });
    }

    pub fn all(&self) -> &[Notice] {
        &self.list
    }

    pub fn clear(&mut self) {
        self.list.clear();
    }

    /// The latest error, if any.
    pub fn last_error(&self) -> Option<&str> {
        self.list
            .iter()
            .rev()
            .find(|n| n.is_error)
            .map(|n| n.text.as_str())
    }
}

impl Notices {
    /// Remove the notice at `index` (as [`Self::all`] lists them), if it is there.
    pub fn dismiss(&mut self, index: usize) {
        if index < self.list.len() {
            self.list.remove(index);
        }
    }

    /// The latest notices, newest first, each with a button that sends
    /// `DismissNotice`; the panel sees only its own list.
    pub fn ui(&self, ui: &mut egui::Ui, context: &mut PanelContext) {
        for (index, notice) in self.list.iter().enumerate().rev().take(SHOWN) {
            // Not horizontal_wrapped: there a text just wider than the space left
            // beside the button widens the whole panel. Here it wraps in that space.
            ui.horizontal_top(|ui| {
                let colour = if notice.is_error {
                    Color32::LIGHT_RED
                } else {
                    ui.visuals().text_color()
                };
                if ui.small_button("x").clicked() {
                    context.send(Action::DismissNotice(index));
                }
                ui.add(
                    egui::Label::new(egui::RichText::new(&notice.text).color(colour))
                        .wrap_mode(egui::TextWrapMode::Wrap),
                );
            });
        }
    }
}
