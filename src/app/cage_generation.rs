//! Generating a cage in the editor: the job on a background thread with its
//! progress and cancel, the proposal waiting for the user, and what using it
//! does (one undo step, then a bind). The window is `ui/generate_cage.rs`.
//!
//! A proposal belongs to the mesh it was generated around: if the document's
//! mesh changes meanwhile (undo, another file), the proposal is dropped.

use crate::cagegen::{
    generate_cage, AutoCageError, CageOptions, CageStart, CageStats, GeneratedCage, StartReason,
    DEFAULT_CELL_SIZE, DEFAULT_CLEARANCE, MAX_TARGET_VERTICES, MIN_TARGET_VERTICES,
};
use crate::geometry::{Cage, TriMesh};
use crate::render::draw_order::unique_edges;
use glam::DVec3;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc::{channel, Receiver, TryRecvError};
use std::sync::Arc;

/// The proposed cage's colour in the viewport and its stats' heading.
pub const PROPOSAL_GREEN: egui::Color32 = egui::Color32::from_rgb(80, 220, 110);

/// The dots on the points in the gaps a proposed cage bridges.
pub const BRIDGED_GAP_ORANGE: egui::Color32 = egui::Color32::from_rgb(255, 150, 40);

/// At most this many of them are drawn (every k-th), so that a cage bridging
/// tens of thousands keeps the frame quick; the window says which.
pub const MAX_BRIDGED_DOTS: usize = 4096;

/// Draw every this-many-th bridged gap point.
pub fn bridged_dot_stride(bridged: usize) -> usize {
    bridged.div_ceil(MAX_BRIDGED_DOTS).max(1)
}

/// The window's key to the dots, or `None` when the cage bridges no gap.
pub fn bridged_legend(stats: &CageStats) -> Option<String> {
    let bridged = stats.gaps.bridged.len();
    if bridged == 0 {
        return None;
    }
    let stride = bridged_dot_stride(bridged);
    let which = if bridged == 1 {
        "the 1 point".to_owned()
    } else if stride == 1 {
        format!("the {bridged} points")
    } else {
        format!("one in {stride} of the {bridged} points")
    };
    Some(format!(
        "Orange dots in the view: {which} in the gaps this cage bridges"
    ))
}

/// The target a first generation offers when the cage says nothing better.
pub const DEFAULT_TARGET_VERTICES: usize = 64;

/// The loose box a mesh opened alone sits in, this fraction of its diagonal
/// away from it on every side.
const BOX_MARGIN: f64 = 0.05;

/// The window's settings and whatever the job is doing.
pub struct CageGeneration {
    pub(super) open: bool,
    /// About how many vertices to ask for.
    pub target_vertices: usize,
    /// The user set the target: opening the window keeps it.
    pub(super) target_chosen: bool,
    /// Whether to ask for a clearance (else the generator keeps `DEFAULT_CLEARANCE`).
    pub use_clearance: bool,
    /// The clearance, in % of the mesh's bounding-box diagonal.
    pub clearance_percent: f64,
    /// Whether to ask for a voxel size (else the generator's default).
    pub use_cell_size: bool,
    /// Pair triangles into quads where they fit (`CageOptions::quads`).
    pub quads: bool,
    /// The voxel size, in % of the mesh's bounding-box diagonal.
    pub cell_size_percent: f64,
    state: State,
    /// Asked to draw a frame as the job progresses and when it ends.
    repaint: Option<egui::Context>,
}

impl Default for CageGeneration {
    fn default() -> Self {
        Self {
            repaint: None,
            open: false,
            target_vertices: DEFAULT_TARGET_VERTICES,
            target_chosen: false,
            use_clearance: false,
            // The box shows, greyed, what the generator uses when it is off.
            clearance_percent: 100.0 * DEFAULT_CLEARANCE,
            use_cell_size: false,
            quads: false,
            cell_size_percent: 100.0 * DEFAULT_CELL_SIZE,
            state: State::Idle { message: None },
        }
    }
}

enum State {
    /// Nothing under way; the last job's failure or cancel, if any.
    Idle {
        message: Option<String>,
    },
    Running(Job),
    /// A cage generated around `mesh`, not yet used (boxed: its statistics
    /// make it much larger than the other states).
    Proposed(Box<Proposal>),
}

struct Job {
    mesh: Arc<TriMesh>,
    cancel: Arc<AtomicBool>,
    /// The fraction done, as f32 bits.
    progress: Arc<AtomicU32>,
    result: Receiver<Result<GeneratedCage, AutoCageError>>,
}

/// A generated cage shown over the mesh until it is used or discarded.
pub struct Proposal {
    pub generated: GeneratedCage,
    /// Its edges, each once, for the viewport's overlay.
    pub edges: Vec<[u32; 2]>,
    mesh: Arc<TriMesh>,
}

impl CageGeneration {
    /// The window's state, with `repaint` woken by the job.
    pub fn new(repaint: egui::Context) -> Self {
        Self {
            repaint: Some(repaint),
            ..Self::default()
        }
    }

    pub fn is_open(&self) -> bool {
        self.open
    }

    /// Open the window, offering `current_vertices` (the cage's vertex count,
    /// or [`DEFAULT_TARGET_VERTICES`] for a box) unless the user chose a
    /// target before.
    pub fn open_window(&mut self, current_vertices: usize) {
        if !self.target_chosen {
            self.target_vertices = if current_vertices > MIN_TARGET_VERTICES {
                current_vertices.min(MAX_TARGET_VERTICES)
            } else {
                DEFAULT_TARGET_VERTICES
            };
        }
        self.open = true;
    }

    /// Close the window; a running job is cancelled and a proposal dropped.
    pub fn close_window(&mut self) {
        self.cancel();
        self.open = false;
    }

    pub fn is_running(&self) -> bool {
        matches!(self.state, State::Running(_))
    }

    /// The running job's fraction done.
    pub fn progress(&self) -> Option<f32> {
        match &self.state {
            State::Running(job) => Some(f32::from_bits(job.progress.load(Ordering::Relaxed))),
            _ => None,
        }
    }

    pub fn proposal(&self) -> Option<&Proposal> {
        match &self.state {
            State::Proposed(proposal) => Some(proposal),
            _ => None,
        }
    }

    /// Why the last job gave no cage ("cancelled", or the generator's error).
    pub fn message(&self) -> Option<&str> {
        match &self.state {
            State::Idle { message } => message.as_deref(),
            _ => None,
        }
    }

    /// The options the window's settings ask for.
    pub fn options(&self) -> CageOptions {
        CageOptions {
            clearance: self.use_clearance.then_some(self.clearance_percent / 100.0),
            cell_size: self.use_cell_size.then_some(self.cell_size_percent / 100.0),
            quads: self.quads,
            ..CageOptions::new(self.target_vertices)
        }
    }

    /// Start generating around `mesh`, waking the editor as progress is made
    /// and when the job ends. Any job or proposal before it is dropped.
    pub fn start(&mut self, mesh: Arc<TriMesh>) {
        self.cancel();
        let repaint = self.repaint.clone();
        let wake = move || {
            if let Some(ctx) = &repaint {
                ctx.request_repaint();
            }
        };
        let options = self.options();
        let cancel = Arc::new(AtomicBool::new(false));
        let progress = Arc::new(AtomicU32::new(0f32.to_bits()));
        let (send, result) = channel();
        let job_mesh = Arc::clone(&mesh);
        let (job_cancel, job_progress) = (Arc::clone(&cancel), Arc::clone(&progress));
        std::thread::spawn(move || {
            let report = |fraction: f32| {
                job_progress.store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
                wake();
                !job_cancel.load(Ordering::Relaxed)
            };
            let generated = generate_cage(&job_mesh, &options, &report);
            // The editor may have gone; then nobody wants the cage.
            let _ = send.send(generated);
            wake();
        });
        self.state = State::Running(Job {
            mesh,
            cancel,
            progress,
            result,
        });
    }

    /// Stop a running job (its thread ends at its next progress report) and
    /// drop any proposal.
    pub fn cancel(&mut self) {
        let mut message = None;
        if let State::Running(job) = &self.state {
            job.cancel.store(true, Ordering::Relaxed);
            message = Some("cancelled".to_owned());
        }
        self.state = State::Idle { message };
    }

    /// Take a finished job's result; drop a proposal made for another mesh.
    pub fn poll(&mut self, current_mesh: &Arc<TriMesh>) {
        match &self.state {
            State::Running(job) => {
                let finished = match job.result.try_recv() {
                    Ok(result) => result.map_err(|error| match error {
                        AutoCageError::Cancelled => "cancelled".to_owned(),
                        error => error.to_string(),
                    }),
                    Err(TryRecvError::Empty) => return,
                    Err(TryRecvError::Disconnected) => {
                        Err("internal error: the cage generator stopped without a result".into())
                    }
                };
                let mesh = Arc::clone(&job.mesh);
                self.state = match finished {
                    Ok(generated) if Arc::ptr_eq(&mesh, current_mesh) => {
                        State::Proposed(Box::new(Proposal {
                            edges: unique_edges(generated.cage.triangles()),
                            generated,
                            mesh,
                        }))
                    }
                    Ok(_) => State::Idle {
                        message: Some("the mesh changed while the cage was generated".into()),
                    },
                    Err(message) => State::Idle {
                        message: Some(message),
                    },
                };
            }
            State::Proposed(proposal) if !Arc::ptr_eq(&proposal.mesh, current_mesh) => {
                self.state = State::Idle { message: None };
            }
            _ => {}
        }
    }

    pub fn take_proposal(&mut self) -> Option<Proposal> {
        match std::mem::replace(&mut self.state, State::Idle { message: None }) {
            State::Proposed(proposal) => Some(*proposal),
            other => {
                self.state = other;
                None
            }
        }
    }
}

/// The measured properties of a generated cage, one line each: what the CLI
/// prints and the window shows. `seconds` is left out when timings are hidden.
pub fn stats_lines(stats: &CageStats, show_time: bool) -> Vec<String> {
    let faces = if stats.quads > 0 {
        format!(
            "{} quads and {} triangles",
            stats.quads,
            stats.triangles - 2 * stats.quads
        )
    } else {
        format!("{} triangles", stats.triangles)
    };
    let mut lines = vec![format!(
        "vertices: {} (target {}), {faces}, {} shell{}",
        stats.vertices,
        stats.target_vertices,
        stats.shells,
        if stats.shells == 1 { "" } else { "s" }
    )];
    if stats.start != CageStart::Voxels {
        let why = match stats.start_reason {
            Some(StartReason::MoreGapsOpen) => {
                "it keeps open gaps that the cage from the voxels bridged, though it encloses more"
            }
            Some(StartReason::SmallerAndMoreGapsOpen) => {
                "it encloses less than the cage from the voxels, and keeps open gaps that it bridged"
            }
            Some(StartReason::Smaller) | None => "it encloses less than the cage from the voxels",
        };
        lines.push(format!(
            "started from: the {}, tightened and polished; {why}",
            stats.start.name()
        ));
    }
    if !stats.target_reached() {
        let (low, high) = target_range(stats.target_vertices);
        lines.push(format!(
            "target not reached: {} vertices is outside {} ± 15% ({low} to {high})",
            stats.vertices, stats.target_vertices
        ));
        if stats.vertices > high && !stats.cell_size_chosen {
            lines.push(
                "  (larger voxels reach fewer vertices, but parts closer than about three voxels then merge)"
                    .to_owned(),
            );
        } else if stats.vertices > high {
            lines.push("  (coarser voxels were tried too; this cage was the closest)".to_owned());
        }
    }
    lines.push(format!(
        "minimum clearance: {} ({:.2}% of the mesh diagonal {})",
        significant(stats.min_clearance),
        100.0 * stats.min_clearance / stats.mesh_diagonal.max(f64::MIN_POSITIVE),
        significant(stats.mesh_diagonal)
    ));
    lines.push(match (stats.volume_ratio(), stats.mesh_volume_from_voxels) {
        (Some(ratio), false) => format!(
            "volume ratio (cage / mesh): {ratio:.3} ({} / {}; mesh volume from its closed surface)",
            significant(stats.cage_volume),
            significant(stats.mesh_volume)
        ),
        (Some(ratio), true) => format!(
            "volume ratio (cage / mesh): {ratio:.3} ({} / {}; the mesh is open: its volume is where its winding number says inside, within its bounding box)",
            significant(stats.cage_volume),
            significant(stats.mesh_volume)
        ),
        (None, true) => {
            "volume ratio (cage / mesh): none, the mesh is open and its winding number encloses no volume"
                .to_owned()
        }
        (None, false) => "volume ratio (cage / mesh): none, the mesh encloses no volume".to_owned(),
    });
    lines.push(format!("minimum angle: {:.1}°", stats.min_angle_degrees));
    let percent = |length: f64| 100.0 * length / stats.mesh_diagonal.max(f64::MIN_POSITIVE);
    let how = match (stats.cell_size_chosen, stats.cell_size_asked) {
        (true, _) => "chosen for the target and the gaps".to_owned(),
        (false, None) => "as asked".to_owned(),
        (false, Some(asked)) => format!(
            "coarsened from the {} asked, finer than the grid's 512 cells along the longest side allow",
            significant(asked)
        ),
    };
    let replaced = match stats.start {
        CageStart::Voxels => String::new(),
        start => format!(
            "; the cage from these voxels was replaced by the {}",
            start.name()
        ),
    };
    lines.push(format!(
        "voxel size: {} ({:.2}% of the mesh diagonal, {how}{replaced})",
        significant(stats.cell_size),
        percent(stats.cell_size),
    ));
    lines.push(merge_line(stats));
    lines.push(gap_line(stats));
    if show_time {
        lines.push(format!("time: {:.2} s", stats.seconds));
    }
    lines
}

/// Below what distance parts of the mesh may share one part of the cage. A
/// start (a box, a prism) begins around every part, so for it the distance
/// says nothing; which gaps it keeps open is the gap line's to say.
fn merge_line(stats: &CageStats) -> String {
    let percent = |length: f64| 100.0 * length / stats.mesh_diagonal.max(f64::MIN_POSITIVE);
    if stats.start != CageStart::Voxels {
        return format!(
            "parts of the mesh at any distance may share one part of the cage: the {} began around them all, and was kept as it leaves outside every gap point that the cage from the voxels left outside",
            stats.start.name()
        );
    }
    format!(
        "parts of the mesh closer than about {} ({:.1}% of the diagonal) may share one part of the cage{}",
        significant(stats.merge_distance()),
        percent(stats.merge_distance()),
        if stats.merge_set_by_reach() {
            "; to reach the target the cage was allowed half that far from the mesh, and more vertices keep closer parts apart"
        } else if stats.cell_size_chosen
            && stats.cell_size > 1.05 * DEFAULT_CELL_SIZE * stats.mesh_diagonal
        {
            "; a smaller voxel size keeps them apart, with more vertices"
        } else {
            ""
        }
    )
}

/// Which gaps between parts of the mesh the cage keeps open, measured at
/// points in them (midway across, and where they open out).
fn gap_line(stats: &CageStats) -> String {
    let gaps = &stats.gaps;
    let percent = |length: f64| 100.0 * length / stats.mesh_diagonal.max(f64::MIN_POSITIVE);
    let width = |w: f64| format!("{} ({:.1}% of the diagonal)", significant(w), percent(w));
    match (gaps.points, gaps.closed(), gaps.widest_closed) {
        (0, _, _) => "gaps between parts: none narrow enough to be bridged".to_owned(),
        (n, 0, _) => format!("gaps between parts: all open ({n} points in them stay outside)"),
        (n, closed, Some(widest)) => format!(
            "gaps between parts: {closed} of {n} points in them are inside the cage (bridged gaps up to {} wide){}",
            width(widest),
            match gaps.narrowest_open {
                Some(narrowest) => format!("; gaps from {} wide stay open where the cage keeps them", width(narrowest)),
                None => "; none stays open: more vertices keep parts apart".to_owned(),
            }
        ),
        (n, closed, None) => format!("gaps between parts: {closed} of {n} points inside the cage"),
    }
}

/// A length or volume with four significant digits, however small or large
/// the mesh: a fixed number of decimals prints a tiny mesh's figures as 0.
pub fn significant(value: f64) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value}");
    }
    let exponent = value.abs().log10().floor() as i32;
    if (-3..6).contains(&exponent) {
        let decimals = (3 - exponent).max(0) as usize;
        format!("{value:.decimals$}")
    } else {
        format!("{value:.3e}")
    }
}

/// The vertex counts within ±15 % of `target`, as `CageStats::target_reached`
/// counts them (its slack, whole vertices only).
fn target_range(target: usize) -> (usize, usize) {
    let slack = (0.15 * target as f64).floor() as usize;
    (target - slack, target + slack)
}

/// A closed box around `mesh`, [`BOX_MARGIN`] of its diagonal away on every
/// side: the usable cage of a mesh opened alone, until a generated one replaces it.
pub fn loose_box_cage(mesh: &TriMesh) -> Option<Cage> {
    let (lo, hi) = mesh.bounds();
    // A flat or single-point mesh still gets a box of some thickness.
    let margin = DVec3::splat((mesh.diagonal() * BOX_MARGIN).max(1e-3));
    let (lo, hi) = (lo - margin, hi + margin);
    let corner = |i: u32| {
        DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let unit = crate::geometry::procedural::cube_cage(1.0);
    let positions: Vec<DVec3> = (0..8).map(corner).collect();
    // The unit cube's corners are numbered the same way (bit 0: x, 1: y, 2: z).
    let cage = TriMesh {
        positions,
        triangles: unit.triangles().to_vec(),
        triangle_faces: unit.triangle_faces().to_vec(),
    };
    Cage::new(cage).ok().map(|(cage, _)| cage)
}

/// Whether any vertex of `mesh` is inside `cage` (or on it): a cage that holds
/// none of the mesh is no cage for it, even when the mesh lies within its
/// bounding box (in the gaps between a hand's fingers, say). Only vertices in
/// the bounding box are classified, [`REACH_BLOCK`] at a time (so the memory
/// used does not grow with the mesh), stopping at the first block that has
/// one inside.
pub fn cage_reaches(cage: &Cage, mesh: &TriMesh) -> bool {
    let (lo, hi) = crate::geometry::bounds_of(cage.positions());
    let mut in_box = mesh
        .positions
        .iter()
        .copied()
        .filter(|p| p.cmpge(lo).all() && p.cmple(hi).all());
    let mut block = Vec::with_capacity(REACH_BLOCK);
    loop {
        block.clear();
        block.extend(in_box.by_ref().take(REACH_BLOCK));
        if block.is_empty() {
            return false;
        }
        if crate::geometry::classify_points(cage, &block).outside.len() < block.len() {
            return true;
        }
    }
}

/// Vertices [`cage_reaches`] classifies at a time: a mesh inside the cage
/// stops after the first block.
const REACH_BLOCK: usize = 4096;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_keep_four_significant_digits_at_any_scale() {
        assert_eq!(significant(2.7182818e-10), "2.718e-10");
        assert_eq!(significant(0.00781249), "0.007812");
        assert_eq!(significant(3.4641016), "3.464");
        assert_eq!(significant(123456.7), "123457");
        assert_eq!(significant(3.2e9), "3.200e9");
        assert_eq!(significant(0.0), "0");
    }

    #[test]
    fn at_most_the_cap_of_bridged_gap_points_is_drawn_and_the_key_says_which() {
        assert_eq!(bridged_dot_stride(0), 1);
        assert_eq!(bridged_dot_stride(MAX_BRIDGED_DOTS), 1);
        assert_eq!(bridged_dot_stride(MAX_BRIDGED_DOTS + 1), 2);
        // SpikyBox's 8-vertex cage bridges 21,280: one in 6 drawn, 3,547 dots.
        assert_eq!(bridged_dot_stride(21_280), 6);
        assert!(21_280usize.div_ceil(6) <= MAX_BRIDGED_DOTS);
        let mut stats = CageStats::default();
        assert_eq!(bridged_legend(&stats), None);
        // The bundled scan at its hand-made cage's 162 vertices bridges one.
        stats.gaps.bridged = vec![DVec3::ZERO; 1];
        let legend = bridged_legend(&stats).expect("a key");
        assert!(legend.contains("the 1 point in the gaps"), "{legend}");
        stats.gaps.bridged = vec![DVec3::ZERO; 21_280];
        let legend = bridged_legend(&stats).expect("a key");
        assert!(legend.contains("one in 6 of the 21280 points"), "{legend}");
    }

    #[test]
    fn the_target_range_is_fifteen_percent_either_way() {
        assert_eq!(target_range(64), (55, 73));
        assert_eq!(target_range(100), (85, 115));
    }

    #[test]
    fn a_loose_box_encloses_its_mesh() {
        let sphere = crate::geometry::procedural::icosphere(1.0, 1);
        let mesh = TriMesh {
            positions: sphere.positions().to_vec(),
            triangles: sphere.triangles().to_vec(),
            triangle_faces: sphere.triangle_faces().to_vec(),
        };
        let cage = loose_box_cage(&mesh).expect("a box");
        assert_eq!(cage.vertex_count(), 8);
        let classes = crate::geometry::classify_points(&cage, &mesh.positions);
        assert!(classes.outside.is_empty());
        // A single point still gets a box.
        let point = TriMesh {
            positions: vec![DVec3::ONE],
            ..Default::default()
        };
        assert!(loose_box_cage(&point).is_some());
    }
}
