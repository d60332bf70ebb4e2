//! The editor: its flows driven through egui_kittest with the wgpu renderer
//! (`ui-tests`; lavapipe on CI, snapshots in tests/snapshots), sessions, scenes,
//! bundled assets, offscreen renders and the layout of its sources. Without an
//! adapter the flows print "not run", unless `PMVC_REQUIRE_GPU=1`.

#[path = "../common/mod.rs"]
mod common;

#[cfg(feature = "ui-tests")]
mod editor_app;
mod editor_assets;
#[cfg(feature = "ui-tests")]
mod editor_attributes;
#[cfg(feature = "ui-tests")]
mod editor_autosave_failures;
#[cfg(feature = "ui-tests")]
mod editor_cage;
#[cfg(feature = "ui-tests")]
mod editor_chunks;
#[cfg(feature = "ui-tests")]
mod editor_compare;
#[cfg(feature = "ui-tests")]
mod editor_drop;
#[cfg(feature = "ui-tests")]
mod editor_exact_twin;
#[cfg(feature = "ui-tests")]
mod editor_far_from_origin;
#[cfg(feature = "ui-tests")]
mod editor_files;
#[cfg(feature = "ui-tests")]
mod editor_green;
mod editor_layout;
#[cfg(feature = "ui-tests")]
mod editor_model;
#[cfg(feature = "ui-tests")]
mod editor_objects;
mod editor_offscreen;
#[cfg(feature = "ui-tests")]
mod editor_panels;
#[cfg(feature = "ui-tests")]
mod editor_parameters;
#[cfg(feature = "ui-tests")]
mod editor_pose_tools;
#[cfg(feature = "ui-tests")]
mod editor_quads;
#[cfg(feature = "ui-tests")]
mod editor_recovery;
mod editor_scene;
#[cfg(feature = "ui-tests")]
mod editor_sessions;
#[cfg(feature = "ui-tests")]
mod editor_shortcuts;
mod editor_somigliana;
#[cfg(feature = "ui-tests")]
mod editor_timeline;
#[cfg(feature = "ui-tests")]
mod editor_toasts;
#[cfg(feature = "ui-tests")]
mod editor_undo;
#[cfg(feature = "ui-tests")]
mod editor_unsaved;
#[cfg(feature = "ui-tests")]
mod editor_views;
mod session_fuzz;
mod session_loading;
