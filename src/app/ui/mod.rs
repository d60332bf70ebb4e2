//! The editor's panels, one file each, as in egui's demo app: each adds an
//! `impl EditorApp` method that draws its panel and calls the editor's actions.

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
