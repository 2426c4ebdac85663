//! The integration tests of `pt-scene`, compiled as one test binary (one link and one copy of
//! the monomorphised code instead of one per file). Run one group with
//! `cargo test -p pt-scene --test integration NAME::`.

mod conventions;
mod download;
mod environment_files;
mod fuzz_stable;
mod gltf_closed_form;
mod gltf_features;
mod hostile;
mod real_meshes;
mod scene_files;
mod support;
