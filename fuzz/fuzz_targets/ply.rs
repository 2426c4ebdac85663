//! Any bytes given to the PLY reader give `Ok` or `Err`, never a panic. Seed with
//! `cp ../shared/assets/meshes/*.ply fuzz/corpus/ply/`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = pt_scene::ply::parse_ply(data, std::path::Path::new("fuzz.ply"));
});
