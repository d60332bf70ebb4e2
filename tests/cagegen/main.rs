//! Generated cages (`autocage`): bounds, shapes, quads and bad input. Builds
//! without features (`cargo test --no-default-features --test cagegen`); the
//! parts that read the editor's summary or run the `pmvc` binary need `editor`.

#[path = "../common/mod.rs"]
mod common;

mod autocage;
mod autocage_bad_input;
mod autocage_bounds;
mod autocage_bundled;
mod autocage_quads;
// Reads the generation summary the editor and `pmvc cage` print.
#[cfg(feature = "editor")]
mod autocage_shapes;
