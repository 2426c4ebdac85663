//! The image is a pure function of (scene, options, seed): bit-identical for any thread count,
//! tile size and run.

use pt::prelude::*;

fn cornell(threads: usize, tile_size: u32, seed: u64) -> Image {
    let bundle = presets::cornell_box().unwrap();
    let opts = RenderOptions::new(64, 64)
        .spp(8)
        .seed(seed)
        .threads(Some(threads))
        .tile_size(tile_size);
    render(&bundle.scene, &bundle.camera, &opts).unwrap().image
}

#[test]
fn one_and_two_threads_give_identical_images() {
    let a = cornell(1, 16, 5);
    let b = cornell(2, 16, 5);
    assert!(a.as_slice().iter().any(|&v| v > 0.0));
    assert_eq!(a.as_slice(), b.as_slice(), "1 and 2 threads differ");
}

#[test]
fn tile_size_and_repeated_runs_do_not_matter() {
    let a = cornell(2, 16, 5);
    assert_eq!(
        a.as_slice(),
        cornell(2, 7, 5).as_slice(),
        "tile size changed the image"
    );
    assert_eq!(
        a.as_slice(),
        cornell(2, 16, 5).as_slice(),
        "a second run differs"
    );
}

#[test]
fn the_seed_changes_the_noise() {
    assert_ne!(cornell(2, 16, 5).as_slice(), cornell(2, 16, 6).as_slice());
}
