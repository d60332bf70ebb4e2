//! Coordinates: MVC, PMVC, harmonic, Green, maximum entropy and maximum likelihood coordinates, bounded biharmonic weights, local barycentric coordinates against references and
//! their properties, far-field exactness, origin offsets, weights metadata and
//! the figures the docs quote. Builds without features
//! (`cargo test --no-default-features --test coords`); the parts that run the
//! `pmvc` binary need `editor`.

#[path = "../common/mod.rs"]
mod common;

mod bbw;
mod bbw_reference;
mod coords_properties;
mod coords_reference;
mod doc_figures;
mod far_field;
mod green;
mod green_family;
mod green_gallery;
mod harmonic;
mod lbc;
mod lbc_reference;
mod mec;
mod mlc;
mod mlc_smoothing;
mod origin_offsets;
mod pointwise_family;
mod qgc;
mod solver_cost;
mod weights_metadata;
