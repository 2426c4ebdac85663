//! Any bytes given to the OBJ loader (and the scene builder after it) give `Ok` or `Err`, never a
//! panic. Seed with `cp ../shared/assets/meshes/*.obj ../shared/assets/cornell/*/*.obj fuzz/corpus/obj/`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(desc) = pt_scene::obj::load_obj_scene_from_bytes(data, "fuzz.obj") {
        let _ = desc.build(&pt_scene::BuildOptions::default());
    }
});
