//! Cage-based mesh deformation with positive mean value coordinates (PMVC).
//!
//! Layers, from the bottom up:
//! - [`geometry`]: meshes, cages, file I/O and validation. No GPU or UI code.
//! - [`coords`]: mean value coordinates in closed form, the CPU reference for PMVC,
//!   and the dense weights matrix. No GPU or UI code.
//! - [`gpu`]: the wgpu device and the binding kernels. No UI code.
//! - [`render`]: viewport drawing; the vertex shader blends the weights.
//! - [`app`]: the editor.
//! - [`cli`]: the `pmvc` command line.
//!
//! `geometry` and `coords` build without any feature; `gpu` needs the `gpu`
//! feature, the rest `editor` (both on by default).

#[cfg(feature = "editor")]
pub mod app;
#[cfg(feature = "editor")]
pub mod cli;
pub mod coords;
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(feature = "python")]
mod python;
#[cfg(feature = "editor")]
pub mod render;
