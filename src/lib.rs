//! Cage-based mesh deformation with positive mean value coordinates (PMVC).
//!
//! Modules, from the bottom up (docs/architecture.md):
//! - [`budget`]: sizes predicted before they are allocated.
//! - [`geometry`]: meshes, cages, quads, validation, inside/outside.
//! - [`coords`]: the coordinate families and the weights matrix.
//! - [`formats`]: every file read or written, meshes and weights alike.
//! - [`cagegen`]: cages generated around a mesh.
//! - [`gpu`]: the wgpu device and the binding kernels. No UI code.
//! - [`render`]: viewport drawing; the vertex shader blends the weights.
//! - [`app`]: the editor.
//! - [`cli`]: the `pmvc` command line.
//!
//! Everything up to `cagegen` builds without any feature; `gpu` needs the `gpu`
//! feature, the rest `editor` (both on by default).

#[cfg(feature = "editor")]
pub mod app;
pub mod budget;
pub mod cagegen;
#[cfg(feature = "editor")]
pub mod cli;
pub mod coords;
pub mod formats;
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(test)]
mod layers;
#[cfg(feature = "python")]
mod python;
#[cfg(feature = "editor")]
pub mod render;
