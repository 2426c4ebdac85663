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
    render(&bundle.scene, &bundle.camera, &opts, None)
        .unwrap()
        .image
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

#[test]
fn eight_threads_and_odd_tiles_give_the_same_image() {
    let a = cornell(1, 16, 9);
    assert_eq!(
        a.as_slice(),
        cornell(8, 16, 9).as_slice(),
        "8 threads differ"
    );
    assert_eq!(
        a.as_slice(),
        cornell(8, 1, 9).as_slice(),
        "1-pixel tiles differ"
    );
    assert_eq!(
        a.as_slice(),
        cornell(3, 64, 9).as_slice(),
        "one tile differs"
    );
}

/// Sample ranges rendered separately (on any thread counts) and merged by sample count equal
/// the whole render bit for bit, through memory and through partial EXR files.
#[test]
fn sample_ranges_merge_into_the_whole_render_exactly() {
    let bundle = presets::cornell_box().unwrap();
    let opts = RenderOptions::new(48, 40).spp(12).seed(77).max_depth(6);
    let whole = render(&bundle.scene, &bundle.camera, &opts, None).unwrap();
    assert_eq!(whole.stats.sample_range, 0..12);

    let dir = std::env::temp_dir().join(format!("pt-determinism-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut merged = PartialRender::empty(&opts, "cornell");
    // Uneven ranges, out of order, each on a different thread count.
    for (i, (range, threads)) in [(7..12, 8), (0..1, 1), (1..7, 2)].into_iter().enumerate() {
        let part = render(
            &bundle.scene,
            &bundle.camera,
            &opts.clone().spp_range(range.clone()).threads(Some(threads)),
            None,
        )
        .unwrap();
        assert_eq!(part.stats.spp, range.end - range.start);
        let path = dir.join(format!("part{i}.exr"));
        PartialRender::new(&part, "cornell")
            .write_exr(&path)
            .unwrap();
        merged
            .merge(&PartialRender::read_exr(&path).unwrap())
            .unwrap();
    }
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(merged.is_complete());
    assert_eq!(
        merged.film, whole.film,
        "merged sums differ from the whole render"
    );
    assert_eq!(
        merged.film.to_image().as_slice(),
        whole.image.as_slice(),
        "merged image differs"
    );
}

/// A cancellation flag that is never set changes nothing; one set before or during the render
/// stops it with `RenderError::Cancelled` before all tiles are done.
#[test]
fn cancellation_stops_the_render_and_an_unset_flag_changes_nothing() {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let bundle = presets::cornell_box().unwrap();
    let opts = RenderOptions::new(64, 64).spp(4).seed(1).threads(Some(2));
    let plain = render(&bundle.scene, &bundle.camera, &opts, None).unwrap();
    let flag = AtomicBool::new(false);
    let controlled = render(
        &bundle.scene,
        &bundle.camera,
        &opts,
        Some(&RenderControl::new().cancel(&flag)),
    )
    .unwrap();
    assert_eq!(plain.film, controlled.film);

    flag.store(true, Ordering::Relaxed);
    let r = render(
        &bundle.scene,
        &bundle.camera,
        &opts,
        Some(&RenderControl::new().cancel(&flag)),
    );
    assert!(matches!(r, Err(RenderError::Cancelled)));

    let stop = AtomicBool::new(false);
    let tiles = AtomicUsize::new(0);
    let on_tile = |p: Progress| {
        tiles.store(p.tiles_total, Ordering::Relaxed);
        stop.store(true, Ordering::Relaxed);
    };
    let control = RenderControl::new().progress(&on_tile).cancel(&stop);
    let r = render(&bundle.scene, &bundle.camera, &opts, Some(&control));
    assert!(matches!(r, Err(RenderError::Cancelled)));
    assert_eq!(tiles.load(Ordering::Relaxed), 16);
}
