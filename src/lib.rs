//! Cage-based mesh deformation with positive mean value coordinates (PMVC).
//!
//! Layers, from the bottom up:
//! - [`geometry`]: meshes, cages, file I/O and validation. No GPU or UI code.
//! - [`coords`]: mean value coordinates in closed form, the CPU reference for PMVC,
//!   and the dense weights matrix. No GPU or UI code.
//! - [`gpu`]: the wgpu device and the binding kernels. No UI code.
//! - [`cli`]: the `pmvc` command line.

pub mod app;
pub mod cli;
pub mod coords;
pub mod geometry;
pub mod gpu;
pub mod render;
