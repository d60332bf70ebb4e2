//! The editor's panels, one file each, as in egui's demo app. The quit dialog,
//! the drop dialog, notices and statistics are structs that own their state and
//! draw through a [`crate::app::ctx::PanelContext`], sending actions; the others
//! still add an `impl EditorApp` method that calls the editor directly.

pub mod drop_dialog;
pub mod file_dialog;
pub mod generate_cage;
pub mod menu;
pub mod named_poses;
pub mod notices;
pub mod pose_panel;
pub mod quality_table;
pub mod quit_dialog;
pub mod side_panel;
pub mod statistics;
pub mod toolbar;
