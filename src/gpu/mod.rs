//! The wgpu device and the binding kernels. Never imports egui: the editor hands in
//! its own device, and the command line makes one.
