//! Any bytes given to the glTF loader (and the scene builder after it) give `Ok` or `Err`, never
//! a panic. `cargo +nightly fuzz run gltf -- -dict=...` from the workspace root; seed the corpus
//! with the sample files (`mkdir -p fuzz/corpus/gltf && cp ../shared/assets/gltf/*.glb fuzz/corpus/gltf/`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(desc) = pt_scene::gltf::load_gltf_slice(data, "fuzz.glb") {
        let _ = desc.build(&pt_scene::BuildOptions::default());
    }
});
