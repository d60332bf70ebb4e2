//! Temporary entry point for manual testing of the editor until `pmvc edit` is
//! wired in `src/cli.rs`: `cargo run --example editor -- [MESH CAGE] [--pose P]
//! [--resolution N] [--method mvc|pmvc] [--screenshot PATH]`.

use pmvc::app::{run_editor, EditorOptions};
use std::path::PathBuf;

fn main() -> anyhow::Result<()> {
    let mut options = EditorOptions::default();
    let mut files = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--pose" => options.pose = args.next().map(PathBuf::from),
            "--screenshot" => options.screenshot = args.next().map(PathBuf::from),
            "--method" => {
                options.method = match args.next().as_deref() {
                    Some("mvc") => Some(pmvc::coords::Method::Mvc),
                    Some("pmvc") => Some(pmvc::coords::Method::Pmvc),
                    other => anyhow::bail!("--method needs mvc or pmvc, got {other:?}"),
                }
            }
            "--resolution" => {
                let value = args.next().unwrap_or_default();
                options.resolution =
                    Some(value.parse().map_err(|_| {
                        anyhow::anyhow!("--resolution needs a number, got {value:?}")
                    })?);
            }
            _ => files.push(PathBuf::from(arg)),
        }
    }
    let mut files = files.into_iter();
    options.mesh = files.next();
    options.cage = files.next();
    run_editor(options)
}
