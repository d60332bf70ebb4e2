//! Geometry: mesh and cage files read and written (OBJ against the reader it
//! replaced, fuzzed readers), cage validation and cages of quads. Builds without
//! features (`cargo test --no-default-features --test geometry`); the parts that
//! run the `pmvc` binary need `editor`.

#[path = "../common/mod.rs"]
mod common;
#[path = "../common/tobj_reference.rs"]
mod tobj_reference;

mod cage_validation;
mod io;
mod obj_reader;
mod quad_cages;
mod reader_fuzz;
