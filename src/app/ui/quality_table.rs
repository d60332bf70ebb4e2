//! The quality table: one column per bound method, one row per measure.

use crate::app::ctx::PanelContext;
use crate::app::document::WeightSet;
use crate::coords::quality::NEGATIVE_TOLERANCE;

/// A row of the table: its name and how a method's weights show in it.
type QualityRow = (&'static str, fn(&WeightSet) -> String);

const ROWS: [QualityRow; 5] = [
    ("inside: vertices with λ < 0", |set| {
        format!("{:.1} %", 100.0 * set.quality.negative_share)
    }),
    ("inside: most negative λ", |set| {
        // Above −NEGATIVE_TOLERANCE a weight is solver rounding, not a negative
        // weight: show it as the 0 the first row counts it as, not as "-0.0000".
        let most_negative = set.quality.most_negative;
        let shown = if most_negative < -NEGATIVE_TOLERANCE {
            most_negative
        } else {
            0.0
        };
        format!("{shown:.4}")
    }),
    ("max |Σλ - 1|", |set| {
        format!("{:.1e}", set.quality.max_partition_error)
    }),
    ("max |Σλ(c - x)| / size", |set| {
        format!("{:.1e}", set.quality.max_linear_precision_error)
    }),
    ("bind time", |set| {
        format!("{:.2} s", set.bind_time.as_secs_f32())
    }),
];

/// Per bound method: negativity, partition of unity, linear precision.
pub fn quality_table(ui: &mut egui::Ui, cx: &PanelContext) {
    ui.label("Quality");
    let document = cx.document();
    let methods: Vec<_> = document.bound_methods().collect();
    if methods.is_empty() {
        ui.label("(nothing bound yet)");
        return;
    }
    let outside = document.outside().len();
    egui::Grid::new("quality")
        .num_columns(methods.len() + 1)
        .striped(true)
        .show(ui, |ui| {
            ui.label("");
            // The name of what was bound: QMVC for MVC on quads, "(shorter split)".
            for &method in &methods {
                let name = document.bound(method).map_or(method.name().into(), |set| {
                    set.options.family_name(document.cage())
                });
                ui.strong(name);
            }
            ui.end_row();
            for (name, value) in ROWS {
                if cx.shown().hide_timings && name == "bind time" {
                    continue;
                }
                ui.label(name);
                for &method in &methods {
                    ui.label(document.bound(method).map_or("—".into(), value));
                }
                ui.end_row();
            }
            ui.label("outside vertices").on_hover_text(
                "Vertices outside the cage follow each family's outside policy \
                     (MVC weights under MVC, PMVC and HC; Green coordinates' own \
                     exterior extension under Green), so their negative weights are \
                     counted here, not above.",
            );
            for _ in &methods {
                ui.label(outside.to_string());
            }
            ui.end_row();
            if outside > 0 {
                ui.label("outside: with λ < 0");
                for &method in &methods {
                    ui.label(document.bound(method).map_or("—".into(), |set| {
                        set.quality.outside_negative_vertices.to_string()
                    }));
                }
                ui.end_row();
            }
        });
}
