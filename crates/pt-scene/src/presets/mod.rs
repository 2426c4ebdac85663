//! Scenes built in code.

mod cornell;
pub mod cornell_data;
pub mod spectrum;

pub use cornell::{CornellBox, cornell_box};
