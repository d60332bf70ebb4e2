//! File > Generate cage…: a target vertex count and an optional clearance, a
//! progress bar with Cancel while the cage is generated in the background, then
//! its measured properties and the choice to use it, discard it or generate
//! again. The proposal is drawn over the mesh (green) until then.

use crate::app::cage_generation::stats_lines;
use crate::app::editor::EditorApp;
use crate::geometry::autocage::{MAX_TARGET_VERTICES, MIN_TARGET_VERTICES};
use egui::{Color32, Pos2, Stroke};

/// The proposed cage's colour in the viewport and its stats' heading.
const PROPOSAL_GREEN: Color32 = Color32::from_rgb(80, 220, 110);

/// What the user asked for this frame.
enum Request {
    Generate,
    Cancel,
    Use,
    Discard,
}

impl EditorApp {
    pub(in crate::app) fn generate_cage_window(&mut self, ctx: &egui::Context) {
        if !self.cage_generation.open {
            return;
        }
        let mut open = true;
        let mut request = None;
        egui::Window::new("Generate cage")
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .default_pos(egui::pos2(60.0, 90.0))
            .show(ctx, |ui| request = self.generate_cage_contents(ui));
        match request {
            Some(Request::Generate) => self.start_cage_generation(),
            Some(Request::Cancel | Request::Discard) => self.cage_generation.cancel(),
            Some(Request::Use) => {
                self.use_generated_cage();
            }
            None => {}
        }
        if !open {
            self.close_cage_generation();
        }
    }

    fn generate_cage_contents(&mut self, ui: &mut egui::Ui) -> Option<Request> {
        let mut request = None;
        let running = self.cage_generation.is_running();
        let mesh = self.model.document().mesh();
        ui.label(format!(
            "Around {}: {} vertices, {} triangles",
            self.model.document().title(),
            mesh.positions.len(),
            mesh.triangles.len()
        ));
        let generation = &mut self.cage_generation;
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
                        "The gap between the mesh and the cage; off: 0.78% of the diagonal",
                        &mut generation.clearance_percent,
                        (0.1, 49.0),
                    );
                    optional_percent(
                        ui,
                        (&mut generation.use_cell_size, "Voxel size"),
                        "Off: chosen for the target, from 0.78% of the diagonal up. Larger voxels reach fewer vertices; parts closer than about three voxels merge",
                        &mut generation.cell_size_percent,
                        (0.2, 20.0),
                    );
                });
        });
        if let Some(fraction) = generation.progress() {
            ui.add(egui::ProgressBar::new(fraction).show_percentage());
            if ui.button("Cancel").clicked() {
                request = Some(Request::Cancel);
            }
            return request;
        }
        if let Some(proposal) = generation.proposal() {
            ui.colored_label(PROPOSAL_GREEN, "Proposed cage (green in the view):");
            for line in stats_lines(&proposal.generated.stats, !self.hide_timings) {
                ui.label(line);
            }
            ui.horizontal(|ui| {
                if ui.button("Use this cage").clicked() {
                    request = Some(Request::Use);
                }
                if ui.button("Discard").clicked() {
                    request = Some(Request::Discard);
                }
                if ui.button("Generate again").clicked() {
                    request = Some(Request::Generate);
                }
            });
            return request;
        }
        if let Some(message) = generation.message() {
            ui.colored_label(ui.visuals().error_fg_color, message);
        }
        if ui.button("Generate").clicked() {
            request = Some(Request::Generate);
        }
        request
    }

    /// The proposed cage's edges over view `pane`, in green.
    pub(in crate::app) fn draw_proposed_cage(&self, painter: &egui::Painter, pane: usize) {
        let Some(proposal) = self.cage_generation.proposal() else {
            return;
        };
        let Some((_, projection)) = self.viewport.pane(pane) else {
            return;
        };
        let screen: Vec<Option<Pos2>> = proposal
            .generated
            .cage
            .positions()
            .iter()
            .map(|p| projection.project_world(*p).map(|at| Pos2::new(at.x, at.y)))
            .collect();
        let stroke = Stroke::new(1.5, PROPOSAL_GREEN);
        for [a, b] in &proposal.edges {
            if let (Some(Some(from)), Some(Some(to))) =
                (screen.get(*a as usize), screen.get(*b as usize))
            {
                painter.line_segment([*from, *to], stroke);
            }
        }
    }
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
