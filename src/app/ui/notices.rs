//! Messages for the user: what happened (info) and what went wrong (errors).
//! The newest show as toasts over the viewport, where the user is looking, and
//! the side panel keeps the latest few.

use crate::app::actions::Action;
use crate::app::ctx::PanelContext;
use egui::Color32;

/// How many notices the side panel lists.
const SHOWN: usize = 6;
/// How many toasts show at once, newest at the bottom.
const TOASTS: usize = 3;
/// Seconds a toast stays: errors longer, as there is more to read and do.
const INFO_SECONDS: f64 = 5.0;
const ERROR_SECONDS: f64 = 15.0;

/// A message shown in the status area.
#[derive(Clone, Debug, PartialEq)]
pub struct Notice {
    pub text: String,
    pub is_error: bool,
    /// When its toast was first drawn (egui's clock).
    toast_since: Option<f64>,
}

impl Notice {
    fn toast_seconds(&self) -> f64 {
        if self.is_error {
            ERROR_SECONDS
        } else {
            INFO_SECONDS
        }
    }
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
            toast_since: None,
        });
    }

    pub fn error(&mut self, text: impl Into<String>) {
        self.list.push(Notice {
            text: text.into(),
            is_error: true,
            toast_since: None,
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

impl Notices {
    /// The newest notices as toasts at the foot of `viewport`, each with a
    /// button that sends `DismissNotice`. A toast leaves after its time; in
    /// deterministic frames (snapshot tests) only a dismissal or newer notices
    /// take it away, since how many frames a bind takes varies.
    pub fn toasts(
        &mut self,
        ctx: &egui::Context,
        viewport: egui::Rect,
        deterministic: bool,
        context: &mut PanelContext,
    ) {
        let now = ctx.input(|i| i.time);
        let mut shown = Vec::new();
        let mut next_expiry = f64::INFINITY;
        for (index, notice) in self.list.iter_mut().enumerate().rev().take(TOASTS) {
            let since = *notice.toast_since.get_or_insert(now);
            let left = since + notice.toast_seconds() - now;
            if deterministic || left > 0.0 {
                next_expiry = next_expiry.min(left);
                shown.push(index);
            }
        }
        if shown.is_empty() {
            return;
        }
        if !deterministic {
            ctx.request_repaint_after(std::time::Duration::from_secs_f64(next_expiry.max(0.05)));
        }
        let width = (viewport.width() * 0.6).clamp(160.0, 640.0);
        egui::Area::new(egui::Id::unique("toasts"))
            .order(egui::Order::Foreground)
            .pivot(egui::Align2::CENTER_BOTTOM)
            // Above the line a transform under way writes at the foot.
            .fixed_pos(egui::pos2(viewport.center().x, viewport.bottom() - 36.0))
            .interactable(true)
            .show(ctx, |ui| {
                ui.set_max_width(width);
                // Oldest first, so the newest sits at the bottom.
                for &index in shown.iter().rev() {
                    let notice = &self.list[index];
                    toast(ui, index, notice, context);
                }
            });
    }
}

fn toast(ui: &mut egui::Ui, index: usize, notice: &Notice, context: &mut PanelContext) {
    let visuals = ui.visuals();
    let (stroke, colour) = if notice.is_error {
        (
            egui::Stroke::new(1.5, Color32::LIGHT_RED),
            Color32::LIGHT_RED,
        )
    } else {
        (visuals.window_stroke, visuals.text_color())
    };
    egui::Frame::popup(ui.style())
        .stroke(stroke)
        .show(ui, |ui| {
            ui.horizontal_top(|ui| {
                if ui.small_button("x").on_hover_text("Dismiss").clicked() {
                    context.send(Action::DismissNotice(index));
                }
                let prefix = if notice.is_error { "Error: " } else { "" };
                ui.add(
                    egui::Label::new(
                        egui::RichText::new(format!("{prefix}{}", notice.text)).color(colour),
                    )
                    .wrap_mode(egui::TextWrapMode::Wrap),
                );
            });
        });
    ui.add_space(4.0);
}
