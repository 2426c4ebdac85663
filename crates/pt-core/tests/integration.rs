//! The integration tests of `pt-core`, compiled as one test binary (one link and one copy of
//! the monomorphised code instead of one per file). Run one group with
//! `cargo test -p pt-core --test integration NAME::`.

mod bsdf_stats;
mod environment_filtering;
mod harness_rejects;
mod light_stats;
mod registry;
mod self_intersection;
