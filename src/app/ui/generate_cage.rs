//! File > Generate cage…: a target vertex count and an optional clearance, a
//! progress bar with Cancel while the cage is generated in the background, then
//! its measured properties and the choice to use it, discard it or generate
//! again. The proposal is drawn over the mesh (green) until then.

use crate::app::actions::{Action, CageRequest};
use crate::app::cage_generation::{
    bridged_legend, stats_lines, CageGeneration, BRIDGED_GAP_ORANGE, PROPOSAL_GREEN,
};
use crate::app::ctx::PanelContext;
use crate::cagegen::{
    DEFAULT_CELL_SIZE, DEFAULT_CLEARANCE, FINEST_CELL_SIZE_FOR_GAPS, MAX_TARGET_VERTICES,
    MIN_TARGET_VERTICES,
};

/// The window, while it is open: it owns its settings and job
/// ([`CageGeneration`]) and sends what the user asks for.
pub fn window(generation: &mut CageGeneration, ctx: &egui::Context, cx: &mut PanelContext) {
    if !generation.open {
        return;
    }
    let mut open = true;
    let mut request = None;
    egui::Window::new("Generate cage")
        .open(&mut open)
        .collapsible(false)
        .resizable(false)
        .default_pos(egui::pos2(60.0, 90.0))
        .show(ctx, |ui| request = contents(generation, ui, cx));
    if let Some(request) = request {
        cx.send(Action::CageWindow(request));
    }
    if !open {
        cx.send(Action::CageWindow(CageRequest::Close));
    }
}

fn contents(
    generation: &mut CageGeneration,
    ui: &mut egui::Ui,
    cx: &PanelContext,
) -> Option<CageRequest> {
    let mut request = None;
    let running = generation.is_running();
    let mesh = cx.document().mesh();
    ui.label(format!(
        "Around {}: {} vertices, {} triangles",
        cx.document().title(),
        mesh.positions.len(),
        mesh.triangles.len()
    ));
    ui.add_enabled_ui(!running, |ui| {
            egui::Grid::new("generate cage settings")
                .num_columns(2)
                .show(ui, |ui| {
                    let label = ui.label("Target vertices");
                    let target = ui
                        .add(
                            egui::DragValue::new(&mut generation.target_vertices)
                                .range(MIN_TARGET_VERTICES..=MAX_TARGET_VERTICES)
                                .speed(1.0),
                        )
                        .labelled_by(label.id)
                        .on_hover_text("About how many vertices the cage should have; within ±15% counts as reached");
                    if target.changed() {
                        generation.target_chosen = true;
                    }
                    ui.end_row();
                    optional_percent(
                        ui,
                        (&mut generation.use_clearance, "Clearance"),
                        &format!(
                            "The gap between the mesh and the cage; off: {:.2}% of the diagonal",
                            100.0 * DEFAULT_CLEARANCE
                        ),
                        &mut generation.clearance_percent,
                        (0.1, 49.0),
                    );
                    optional_percent(
                        ui,
                        (&mut generation.use_cell_size, "Voxel size"),
                        &format!(
                            "Off: chosen for the target and the gaps, from {:.2}% of the diagonal up, or down to {:.2}% to keep gaps open. Larger voxels reach fewer vertices; parts closer than about three voxels merge",
                            100.0 * DEFAULT_CELL_SIZE,
                            100.0 * FINEST_CELL_SIZE_FOR_GAPS
                        ),
                        &mut generation.cell_size_percent,
                        (0.2, 20.0),
                    );
                    ui.label("Quads");
                    ui.checkbox(&mut generation.quads, "where they fit")
                        .on_hover_text("Pair triangles into near-planar, near-square quads (bilinear patches) wherever a quad keeps the clearance and every check");
                    ui.end_row();
                });
        });
    if let Some(fraction) = generation.progress() {
        ui.add(egui::ProgressBar::new(fraction).show_percentage());
        if ui.button("Cancel").clicked() {
            request = Some(CageRequest::Cancel);
        }
        return request;
    }
    if let Some(proposal) = generation.proposal() {
        ui.colored_label(PROPOSAL_GREEN, "Proposed cage (green in the view):");
        for line in stats_lines(&proposal.generated.stats, !cx.shown().hide_timings) {
            ui.label(line);
        }
        if let Some(legend) = bridged_legend(&proposal.generated.stats) {
            ui.colored_label(BRIDGED_GAP_ORANGE, legend);
        }
        ui.horizontal(|ui| {
            if ui.button("Use this cage").clicked() {
                request = Some(CageRequest::Use);
            }
            if ui.button("Discard").clicked() {
                request = Some(CageRequest::Cancel);
            }
            if ui.button("Generate again").clicked() {
                request = Some(CageRequest::Generate);
            }
        });
        return request;
    }
    if let Some(message) = generation.message() {
        ui.colored_label(ui.visuals().error_fg_color, message);
    }
    if ui.button("Generate").clicked() {
        request = Some(CageRequest::Generate);
    }
    request
}

/// A grid row: a checkbox that turns a setting on, and its value in % of the
/// mesh's diagonal, greyed out while the generator's default is used.
fn optional_percent(
    ui: &mut egui::Ui,
    (enabled, label): (&mut bool, &str),
    hover: &str,
    percent: &mut f64,
    (min, max): (f64, f64),
) {
    ui.checkbox(enabled, label).on_hover_text(hover);
    ui.add_enabled(
        *enabled,
        egui::DragValue::new(percent)
            .range(min..=max)
            .speed(0.01 * (max - min).sqrt())
            .suffix("% of the mesh diagonal"),
    );
    ui.end_row();
}
