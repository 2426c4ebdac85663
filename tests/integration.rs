//! The end-to-end tests of `pt`, compiled as one test binary.
//!
//! Every file `tests/NAME.rs` is a module here rather than its own crate: each integration-test
//! crate links and optimises its own copy of the renderer, and one binary instead of many
//! saves minutes of CI build time. Run one group with `cargo test --test integration NAME::`.

mod support;

mod accel_cornell;
mod adaptive;
mod agreement_mitsuba;
mod aov_denoise;
mod api_surface;
mod area_lights;
mod bench_scripts;
mod determinism;
mod direct_lighting;
mod environment;
mod examples_cli;
mod examples_fetch;
mod figures;
mod furnace;
mod furnace_bsdf;
mod lanes;
mod mis_glossy;
mod punctual_lights;
mod samplers;
mod scene_analysis;
mod stress_glass;
mod stress_nonfinite;
mod stress_scale;
mod volume_absorption;
