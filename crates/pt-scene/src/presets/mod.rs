//! Scenes built in code: the Cornell box from Cornell's measured data, and the report's figure
//! scenes ([`figure`], [`FIGURES`]) that the examples, benchmarks and tests share.

mod cornell;
pub mod cornell_data;
mod figures;
pub mod spectrum;

pub use cornell::{CornellBox, cornell_box};
pub use figures::{
    DRAGONS, FIGURES, Figure, bunny_in_box, cornell_box_with, dragons, env_lighting, environment,
    figure, specular_box,
};
