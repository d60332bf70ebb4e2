//! The comparison widgets drawn over the viewport: the colour bar of a heatmap
//! and the hover box with a vertex's weights. Pure egui painting; the values
//! come from [`super::compare`] and the colours from [`crate::render::colormap`].

use super::compare::{HoverReadout, ValueRange, HOVER_TOP_WEIGHTS};
use crate::coords::quality::NEGATIVE_TOLERANCE;
use crate::render::colormap::{self, Scale};
use crate::render::{Colouring, Shading};
use egui::{Color32, Pos2, Rect, Stroke};

fn colour32([r, g, b]: [f32; 3]) -> Color32 {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    Color32::from_rgb(byte(r), byte(g), byte(b))
}

/// A line above a colour bar; `grey_swatch` when it starts with what the grey
/// vertices mean.
pub struct BarNote {
    pub text: String,
    pub grey_swatch: bool,
}

/// A horizontal colour bar at the bottom of `rect`: the map from −limit to +limit
/// (0 to +limit for distances), with the values' min and max marked.
pub fn draw_colour_bar(
    painter: &egui::Painter,
    rect: Rect,
    shading: &Shading,
    range: ValueRange,
    title: String,
    note: Option<BarNote>,
) {
    let signed = shading.colouring != Colouring::MethodDistance;
    let limit = shading.colour_limit;
    let low = if signed { -limit } else { 0.0 };
    let font = egui::FontId::proportional(12.0);
    let text = Color32::from_gray(235);
    // Distances read as a share of the cage diagonal; the log scale's left end
    // is where it stops resolving, not zero.
    let number = |value: f32| if signed { short(value) } else { percent(value) };
    let left = match (signed, shading.scale) {
        (_, Scale::Linear) => number(low),
        (true, Scale::LogMagnitude) => format!("−{}", short(limit)),
        (false, Scale::LogMagnitude) => {
            format!("≤ {}", number(limit * 10f32.powf(-colormap::LOG_DECADES)))
        }
    };
    let middle = format!(
        "min {} · max {}",
        measured(range.min, signed),
        measured(range.max, signed)
    );
    let width_of = |label: &str| {
        painter
            .layout_no_wrap(label.to_owned(), font.clone(), text)
            .size()
            .x
    };
    let bar_width = (rect.width() - 32.0).clamp(60.0, 320.0);
    // In a narrow view the min/max line gets a row of its own rather than
    // running into the end labels.
    let end_width = width_of(&left).max(width_of(&number(limit)));
    let own_row = width_of(&middle) / 2.0 + end_width + 6.0 > bar_width / 2.0;
    let raise = if own_row { 15.0 } else { 0.0 };
    let bar = Rect::from_min_size(
        Pos2::new(rect.left() + 16.0, rect.bottom() - 42.0 - raise),
        egui::vec2(bar_width, 14.0),
    );
    let mut backdrop = bar.expand2(egui::vec2(8.0, 22.0));
    backdrop.max.y += raise;
    if note.is_some() {
        backdrop.min.y -= 18.0;
    }
    painter.rect_filled(backdrop, 4.0, Color32::from_black_alpha(140));
    let steps = 64;
    let mut mesh = egui::Mesh::default();
    for step in 0..=steps {
        let fraction = step as f32 / steps as f32;
        let value = low + (limit - low) * fraction;
        let colour = colour32(colormap::heat_colour(value, limit, shading.scale));
        let x = bar.left() + bar.width() * fraction;
        mesh.colored_vertex(Pos2::new(x, bar.top()), colour);
        mesh.colored_vertex(Pos2::new(x, bar.bottom()), colour);
        if step > 0 {
            let i = 2 * step as u32;
            mesh.add_triangle(i - 2, i - 1, i);
            mesh.add_triangle(i - 1, i + 1, i);
        }
    }
    painter.add(egui::Shape::mesh(mesh));
    // Where a value sits on the bar (the log scale bends the axis).
    let x_of = |value: f32| {
        let t = colormap::scaled(value, limit, shading.scale);
        let fraction = if signed { (t + 1.0) / 2.0 } else { t };
        bar.left() + bar.width() * fraction.clamp(0.0, 1.0)
    };
    for value in [range.min, range.max] {
        let x = x_of(value);
        painter.line_segment(
            [
                Pos2::new(x, bar.top() - 3.0),
                Pos2::new(x, bar.bottom() + 3.0),
            ],
            Stroke::new(2.0, Color32::BLACK),
        );
    }
    let log = if shading.scale == Scale::LogMagnitude {
        format!(" · log scale, {} decades", colormap::LOG_DECADES)
    } else {
        " · linear scale".to_owned()
    };
    painter.text(
        bar.left_top() - egui::vec2(0.0, 4.0),
        egui::Align2::LEFT_BOTTOM,
        format!("{title}{log}"),
        font.clone(),
        text,
    );
    if let Some(note) = note {
        let swatch = Rect::from_min_size(
            bar.left_top() - egui::vec2(0.0, 36.0),
            egui::vec2(12.0, 12.0),
        );
        let mut at = swatch.left_center();
        if note.grey_swatch {
            painter.rect_filled(swatch, 2.0, colour32(colormap::OUTSIDE));
            at = swatch.right_center() + egui::vec2(6.0, 0.0);
        }
        painter.text(at, egui::Align2::LEFT_CENTER, note.text, font.clone(), text);
    }
    painter.text(
        bar.center_bottom() + egui::vec2(0.0, 2.0 + raise),
        egui::Align2::CENTER_TOP,
        middle,
        font.clone(),
        text,
    );
    painter.text(
        bar.left_bottom() + egui::vec2(0.0, 2.0),
        egui::Align2::LEFT_TOP,
        left,
        font.clone(),
        text,
    );
    painter.text(
        bar.right_bottom() + egui::vec2(0.0, 2.0),
        egui::Align2::RIGHT_TOP,
        number(limit),
        font,
        text,
    );
}

/// Distances below this share of the cage diagonal are the f32 rounding of the
/// positions (about 1e-7 of their size), not a difference between methods.
const DISTANCE_ROUNDING: f32 = 1e-6;

/// A measured minimum or maximum on the colour bar, with rounding noise said to
/// be below what the data resolves rather than printed as a number: weights
/// within [`NEGATIVE_TOLERANCE`] of zero read "0.000", distances under
/// [`DISTANCE_ROUNDING`] of the diagonal "< 1.00e-4%".
fn measured(value: f32, signed: bool) -> String {
    if signed && f64::from(value.abs()) < NEGATIVE_TOLERANCE {
        short(0.0)
    } else if signed {
        short(value)
    } else if value.abs() < DISTANCE_ROUNDING {
        format!("< {}", percent(DISTANCE_ROUNDING))
    } else {
        percent(value)
    }
}

/// A fraction as a percentage with three significant digits ("0.100%").
pub fn percent(fraction: f32) -> String {
    let value = fraction * 100.0;
    if value == 0.0 {
        "0%".into()
    } else if value.abs() >= 0.01 {
        format!("{value:.3}%")
    } else {
        format!("{value:.2e}%")
    }
}

/// A colour-bar number: three decimals, or three significant digits when small.
fn short(value: f32) -> String {
    if value == 0.0 || value.abs() >= 0.01 {
        format!("{value:.3}")
    } else {
        format!("{value:.2e}")
    }
}

/// The hover box: a vertex's largest weights and its most negative one.
pub fn hover_box(ui: &mut egui::Ui, readout: &HoverReadout) {
    ui.strong(format!(
        "vertex {} · {}",
        readout.vertex,
        readout.method.name()
    ));
    ui.label(format!("largest {HOVER_TOP_WEIGHTS} weights:"));
    for (cage_vertex, weight) in &readout.top {
        ui.monospace(format!("λ{cage_vertex:<4} {weight:>9.5}"));
    }
    match readout.most_negative {
        Some((cage_vertex, weight)) => ui.colored_label(
            Color32::from_rgb(120, 150, 255),
            format!("most negative: λ{cage_vertex} = {weight:.5}"),
        ),
        None => ui.label("no negative weight"),
    };
}

#[cfg(test)]
mod tests {
    use super::measured;

    #[test]
    fn rounding_noise_on_the_colour_bar_reads_as_below_resolution() {
        // Two identical deformations differ by f64 cancellation only.
        assert_eq!(measured(4.06e-19, false), "< 1.00e-4%");
        assert_eq!(measured(0.0, false), "< 1.00e-4%");
        assert_eq!(measured(2.5e-3, false), "0.250%");
        assert_eq!(measured(-1e-9, true), "0.000");
        assert_eq!(measured(-0.0132, true), "-0.013");
        assert_eq!(measured(3e-4, true), "3.00e-4");
    }
}
