//! Names for the instruction sets a build's target features guarantee, so that the lane
//! dispatch can leave out entries such a build can never take (`src/lanes/mod.rs`):
//!
//! - `pt_avx2_build`: x86-64 with AVX2, FMA, BMI1, BMI2, LZCNT and POPCNT (the AVX2 lanes' set);
//! - `pt_avx512_build`: that and AVX-512 F, VL, BW and DQ.
//!
//! A build for the host CPU (`-C target-cpu=native`, pt's own) has one or both on such CPUs;
//! a build for baseline x86-64 has neither and chooses at run time.

use std::collections::HashSet;
use std::env;

const AVX2: [&str; 6] = ["avx2", "fma", "bmi1", "bmi2", "lzcnt", "popcnt"];
const AVX512: [&str; 4] = ["avx512f", "avx512vl", "avx512bw", "avx512dq"];

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(pt_avx2_build)");
    println!("cargo::rustc-check-cfg=cfg(pt_avx512_build)");
    let arch = env::var("CARGO_CFG_TARGET_ARCH").unwrap_or_default();
    let features = env::var("CARGO_CFG_TARGET_FEATURE").unwrap_or_default();
    let features: HashSet<&str> = features.split(',').collect();
    if arch != "x86_64" || !AVX2.iter().all(|f| features.contains(f)) {
        return;
    }
    println!("cargo::rustc-cfg=pt_avx2_build");
    if AVX512.iter().all(|f| features.contains(f)) {
        println!("cargo::rustc-cfg=pt_avx512_build");
    }
}
