//! `pmvc cage`: generate a cage of about N vertices around a mesh and write it
//! as OBJ, then print what was measured on it.

use crate::app::cage_generation::stats_lines;
use crate::cagegen::{generate_cage, plan_cage, CageOptions};
use crate::formats::shown_path;
use crate::formats::PendingOutput;
use anyhow::{anyhow, Result};
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
pub struct CageArgs {
    /// The mesh to enclose (.obj, .off, .glb or .gltf): a triangle mesh, closed or not.
    #[arg(long, value_name = "MESH")]
    pub mesh: PathBuf,
    /// Read the mesh from this object of a file with several (as `deform --mesh-object`).
    #[arg(long, value_name = "NAME", value_parser = super::parse::parse_object_name)]
    pub mesh_object: Option<String>,
    /// About how many vertices the cage should have (8 to 20000); the result is
    /// within ±15% of it unless the mesh's shape needs more or allows fewer.
    #[arg(long, value_name = "N")]
    pub vertices: usize,
    /// Output cage as OBJ: closed and outward-facing, of triangles (and quads
    /// with --quads).
    #[arg(long, value_name = "C.obj")]
    pub out: PathBuf,
    /// The gap between the mesh and the cage, as a fraction of the mesh's
    /// bounding-box diagonal (e.g. 0.02; default: 1/256, 0.00390625).
    #[arg(long, value_name = "FRACTION")]
    pub clearance: Option<f64>,
    /// The voxel size, as a fraction of the diagonal (default: chosen for N,
    /// from 1/128 up). Parts closer than about three voxels merge; a size given
    /// here is never coarsened, even when N is then missed.
    #[arg(long, value_name = "FRACTION")]
    pub cell_size: Option<f64>,
    /// Pair triangles into near-planar, well-shaped quads where the quad's
    /// bilinear patch keeps the clearance and every check; they are written as
    /// quads (`f a b c d`).
    #[arg(long)]
    pub quads: bool,
}

pub(super) fn cage(args: &CageArgs) -> Result<()> {
    super::commands::check_output(&args.out, &[&args.mesh], &["obj"], "an OBJ cage")?;
    let mesh = super::commands::read_mesh(&args.mesh, args.mesh_object.as_deref())?;
    let options = CageOptions {
        clearance: args.clearance,
        cell_size: args.cell_size,
        quads: args.quads,
        ..CageOptions::new(args.vertices)
    };
    // Options and the memory they need are checked before any file is made.
    plan_cage(&mesh.mesh, &options)
        .map_err(|error| anyhow!("{}: {error}", shown_path(&args.mesh)))?;
    // Opened before the work, so that an unwritable folder is reported now and
    // a signal while generating removes the temporary file.
    let output = PendingOutput::create(&args.out)?;
    let bar = progress_bar();
    let generated = generate_cage(&mesh.mesh, &options, &|fraction| {
        bar.set_position((fraction.clamp(0.0, 1.0) * 1000.0) as u64);
        true
    });
    bar.finish_and_clear();
    let generated = generated.map_err(|error| anyhow!("{}: {error}", shown_path(&args.mesh)))?;
    let cage = &generated.cage;
    output.finish(|out| {
        crate::formats::write_polygons_obj_to(out, cage.positions(), &cage.polygons())
    })?;
    say!(
        "wrote {}: a cage around {} ({} vertices, {} triangles)",
        shown_path(&args.out),
        shown_path(&args.mesh),
        mesh.mesh.positions.len(),
        mesh.mesh.triangles.len()
    );
    for line in stats_lines(&generated.stats, true) {
        say!("{line}");
    }
    Ok(())
}

/// A progress bar on stderr when it is a terminal; hidden otherwise.
fn progress_bar() -> indicatif::ProgressBar {
    let bar = indicatif::ProgressBar::with_draw_target(
        Some(1000),
        indicatif::ProgressDrawTarget::stderr(),
    );
    if let Ok(style) =
        indicatif::ProgressStyle::with_template("{msg} {wide_bar} {percent}%, {elapsed}")
    {
        bar.set_style(style);
    }
    bar.set_message("generating the cage");
    bar
}
