//! The `pmvc` command line, run as a user runs it: its commands, messages,
//! outputs, point sets, metadata, glTF files, pipeline cache and backend choice.

#[path = "../cli_support/mod.rs"]
mod cli_support;
#[path = "../common/mod.rs"]
mod common;

mod backend_choice;
mod bad_input;
mod cli;
mod cli_cage;
mod cli_exact_pmvc;
mod cli_green;
#[cfg(unix)]
mod cli_messages;
mod cli_metadata;
mod cli_point_sets;
mod cli_somigliana;
#[cfg(unix)]
mod cli_streamed_writes;
mod gltf;
#[cfg(unix)]
mod outputs;
mod pipeline_cache;
mod round_trip;
