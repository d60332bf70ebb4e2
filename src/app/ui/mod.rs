//! The editor's panels, one file each, as in egui's demo app. Each owns its
//! state (a struct, or none for the menu, the toolbar, the side panel's own
//! sections and the quality table) and draws through a
//! [`crate::app::ctx::PanelContext`]: read-only views of what it shows, and a
//! queue of actions. No panel touches the editor itself, nor imports it: what
//! panels and the editor share (actions, commands, the dialogs' answers) is in
//! leaf files below both.

pub mod drop_dialog;
pub mod file_dialog;
pub mod generate_cage;
pub mod menu;
pub mod named_poses;
pub mod notices;
pub mod object_choice;
pub mod pose_panel;
pub mod quality_table;
pub mod recovery_dialog;
pub mod shortcuts_help;
pub mod side_panel;
pub mod statistics;
pub mod timeline;
pub mod toolbar;
pub mod unsaved_dialog;
