//! The side-by-side timing scripts of `scripts/bench/` (docs/PERFORMANCE.md, "How the figures
//! are measured"), run on stand-in programs whose rates are known: the ratios, means and
//! efficiencies they print must be those rates' (a script that read the wrong column, swapped
//! its two sides or averaged wrongly fails here). Unix only: the scripts are bash.
#![cfg(unix)]

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::support::Scratch;

/// A fresh folder for one test's stand-ins, removed after it.
fn scratch(name: &str) -> Scratch {
    Scratch::new(&format!("bench-{name}"))
}

/// An executable bash script at `dir/name`.
fn program(dir: &Path, name: &str, body: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, format!("#!/usr/bin/env bash\nset -eu\n{body}\n")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

/// A stand-in render program: writes `bytes` to the file after `--out`, prints the rates of
/// `rates` (space-separated) in turn, one per run of this file.
fn render(dir: &Path, name: &str, rates: &str, bytes: &str) -> PathBuf {
    program(
        dir,
        name,
        &format!(
            r#"out=""; while [ $# -gt 0 ]; do [ "$1" = --out ] && out=$2; shift; done
[ -n "$out" ] && printf '{bytes}' > "$out"
rates=({rates}); n=$(cat "$0.runs" 2>/dev/null || echo 0); echo $((n + 1)) > "$0.runs"
echo "render: 256x256, 16 spp, 1.00 s, ${{rates[$((n % ${{#rates[@]}}))]}} Msamples/s""#
        ),
    )
}

/// The path of a script of `scripts/bench/`.
fn script_path(script: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scripts/bench")
        .join(script)
}

/// Run a script of `scripts/bench/` with `args`; its stdout, which it must exit 0 with.
fn run(script: &str, args: &[&Path], env: &[(&str, &Path)]) -> String {
    let out = Command::new("bash")
        .arg(script_path(script))
        .args(args)
        .envs(env.iter().map(|&(k, v)| (k, v)))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{script} failed: {stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Fails unless `out` holds every one of `lines`.
fn assert_lines(out: &str, lines: &[&str]) {
    for line in lines {
        assert!(out.contains(line), "{line:?} not in {out}");
    }
}

#[test]
fn pair_prints_each_round_and_the_geometric_mean_of_b_over_a() {
    let dir = scratch("pair");
    let a = render(&dir, "a", "2.00", "same");
    let b = render(&dir, "b", "3.00", "same");
    let c = render(&dir, "c", "3.00", "other");
    let arg = PathBuf::from("3");
    let out = run(
        "pair.sh",
        &[&arg, &a, &b, Path::new("--"), Path::new("x")],
        &[],
    );
    assert_eq!(out.matches("B/A 1.5000").count(), 3, "{out}");
    assert!(out.contains("geometric mean B/A: 1.5000"), "{out}");
    assert!(out.contains("images: the same bytes"), "{out}");
    let out = run(
        "pair.sh",
        &[&arg, &b, &c, Path::new("--"), Path::new("x")],
        &[],
    );
    assert!(out.contains("geometric mean B/A: 1.0000"), "{out}");
    assert!(out.contains("images: different"), "{out}");
    // Rates that vary by round: the median is the middle ratio, or the middle two's mean.
    for (rounds, median, mean) in [("3", "1.5000", "1.6510"), ("4", "2.2500", "2.5227")] {
        let one = render(&dir, &format!("one{rounds}"), "1.00", "x");
        let varied = render(&dir, &format!("varied{rounds}"), "1.0 3.0 1.5 9.0", "x");
        let rounds = PathBuf::from(rounds);
        let args = [&rounds, &one, &varied, Path::new("--"), Path::new("x")];
        let out = run("pair.sh", &args, &[]);
        assert!(out.contains(&format!("median B/A: {median}")), "{out}");
        assert!(
            out.contains(&format!("geometric mean B/A: {mean}")),
            "{out}"
        );
    }
}

#[test]
fn pair_serial_runs_the_two_in_turn_on_one_core_alternating_the_first() {
    let dir = scratch("pair-serial");
    let order = dir.join("order");
    // Each side logs its start and its end (by the name pair.sh runs it under) to `order`,
    // and runs long enough (half a second) that two sides started together interleave even
    // on a loaded machine.
    let side = |name: &str, rate: &str| {
        program(
            &dir,
            name,
            &format!(
                r#"me=$(basename "$0"); echo "$me" >> "$PT_TEST_ORDER"; sleep 0.5
out=""; while [ $# -gt 0 ]; do [ "$1" = --out ] && out=$2; shift; done
printf 'x' > "$out"; echo "$me-end" >> "$PT_TEST_ORDER"
echo "render: 256x256, 16 spp, 1.00 s, {rate} Msamples/s""#
            ),
        )
    };
    let (a, b) = (side("one", "2.00"), side("two", "3.00"));
    let rounds = PathBuf::from("2");
    let args = [
        Path::new("--serial"),
        &rounds,
        &a,
        &b,
        Path::new("--"),
        Path::new("x"),
    ];
    let out = run("pair.sh", &args, &[("PT_TEST_ORDER", &order)]);
    assert_eq!(out.matches("B/A 1.5000").count(), 2, "{out}");
    assert!(out.contains("geometric mean B/A: 1.5000"), "{out}");
    let log = std::fs::read_to_string(&order).unwrap();
    let seen: Vec<&str> = log.lines().collect();
    assert_eq!(
        seen,
        ["a", "a-end", "b", "b-end", "b", "b-end", "a", "a-end"],
        "{log}"
    );
    // Side by side (no --serial) the two overlap.
    std::fs::remove_file(&order).unwrap();
    run("pair.sh", &args[1..], &[("PT_TEST_ORDER", &order)]);
    let log = std::fs::read_to_string(&order).unwrap();
    assert!(log.lines().take(2).all(|l| !l.ends_with("-end")), "{log}");
}

#[test]
fn a_program_that_prints_no_rate_stops_the_scripts_with_its_output() {
    let dir = scratch("fail");
    let bad = program(&dir, "bad", "echo 'error: no such scene'; exit 2");
    let good = render(&dir, "good", "2.00", "x");
    let one = PathBuf::from("1");
    for (script, args) in [
        ("pair.sh", vec![&one, &good, &bad]),
        ("round-robin.sh", vec![&one, &good, &bad]),
        ("rays-pair.sh", vec![&one, &bad, &bad, &dir, &dir]),
    ] {
        std::fs::write(dir.join("tris.npy"), "").unwrap();
        let out = Command::new("bash")
            .arg(script_path(script))
            .args(&args)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{script} succeeded: {text}");
        assert!(
            text.contains("no rate") || text.contains("error: no such scene"),
            "{script}: {text}"
        );
    }
}

#[test]
fn round_robin_ranks_every_binary_by_its_own_runs() {
    let dir = scratch("robin");
    // Each binary's four runs (two rounds of every pair of three) in a shuffled order.
    let cases = [
        ("a", "2.00 4.00 1.00 3.00", "4.000", "3.000", "2.500"),
        ("b", "5.00 6.00 8.00 7.00", "8.000", "7.000", "6.500"),
        ("c", "1.50 1.50 1.50 1.50", "1.500", "1.500", "1.500"),
    ];
    let bins: Vec<PathBuf> = cases
        .iter()
        .map(|&(name, rates, ..)| render(&dir, name, rates, "x"))
        .collect();
    let rounds = PathBuf::from("2");
    let mut args: Vec<&Path> = vec![&rounds];
    args.extend(bins.iter().map(PathBuf::as_path));
    args.extend([Path::new("--"), Path::new("x")]);
    let out = run("round-robin.sh", &args, &[]);
    for (bin, &(_, _, best, quartile, median)) in bins.iter().zip(&cases) {
        let line = format!(
            "{}: best {best}, upper quartile {quartile}, median {median} Msamples/s (4 runs)",
            bin.display()
        );
        assert!(out.contains(&line), "{line} not in {out}");
    }
}

/// A stand-in `ray_queries` or `embree-direct`: the table rows `rows` (ray set, closest 1T,
/// any hit 1T) under the first column `first`.
fn rays(dir: &Path, name: &str, first: &str, rows: [(&str, &str, &str); 2]) -> PathBuf {
    let table: String = rows
        .iter()
        .map(|(set, closest, any)| {
            format!("| {first} | 1.00 | {set} | {closest} | 0.00 | {any} | 0.00 | 50.0 | true |\n")
        })
        .collect();
    program(
        dir,
        name,
        &format!("echo '| layout | build ms | ray set | c1 | c2 | o1 | o2 |'\nprintf '{table}'"),
    )
}

#[test]
fn rays_pair_and_against_embree_divide_the_matching_columns() {
    let dir = scratch("rays");
    std::fs::write(dir.join("tris.npy"), "").unwrap();
    let a = rays(
        &dir,
        "a",
        "Eight",
        [
            ("primary", "10.00", "20.00"),
            ("incoherent", "4.00", "5.00"),
        ],
    );
    let b = rays(
        &dir,
        "b",
        "Eight",
        [
            ("primary", "15.00", "10.00"),
            ("incoherent", "5.00", "4.00"),
        ],
    );
    let (three, mesh) = (PathBuf::from("3"), PathBuf::from("meshes/m.obj"));
    let out = run("rays-pair.sh", &[&three, &a, &b, &mesh, &dir], &[]);
    assert_lines(
        &out,
        &[
            "geometric mean B/A, primary: closest 1.5000, any hit 0.5000",
            "geometric mean B/A, incoherent: closest 1.2500, any hit 0.8000",
            "median B/A, incoherent: closest 1.2500, any hit 0.8000",
        ],
    );
    // Embree's table carries other configurations too: only MEDIUM's rows count.
    let embree = program(
        &dir,
        "embree",
        "printf '| MEDIUM+ROBUST | 1 | primary | 1.00 | 0 | 1.00 |\\n\
         | MEDIUM | 1 | primary | 5.00 | 0 | 40.00 |\\n\
         | MEDIUM | 1 | incoherent | 8.00 | 0 | 2.50 |\\n'",
    );
    let out = run(
        "against-embree.sh",
        &[&three, &mesh, &dir, &a],
        &[("PT_EMBREE_DIRECT", &embree)],
    );
    assert_lines(
        &out,
        &[
            "geometric mean pt/Embree, primary: closest 2.0000, any hit 0.5000",
            "geometric mean pt/Embree, incoherent: closest 0.5000, any hit 2.0000",
        ],
    );
    // --alternate: the same ratios, from runs that never overlap (each stand-in fails if it
    // sees the other running at any time in its first second, which two programs started
    // together always do, however loaded the machine).
    let exclusive = |name: &str, other: &str, table: &Path| {
        let (me, them) = (
            dir.join(format!("{name}.on")),
            dir.join(format!("{other}.on")),
        );
        program(
            &dir,
            &format!("{name}-alone"),
            &format!(
                "touch {me:?}; for i in $(seq 50); do [ ! -e {them:?} ] || exit 1; sleep 0.02; \
                 done; rm {me:?}; {table:?}"
            ),
        )
    };
    let (pt_alone, embree_alone) = (
        exclusive("pt", "embree", &a),
        exclusive("embree", "pt", &embree),
    );
    let (alternate, one) = (PathBuf::from("--alternate"), PathBuf::from("1"));
    let out = run(
        "against-embree.sh",
        &[&alternate, &one, &mesh, &dir, &pt_alone],
        &[("PT_EMBREE_DIRECT", &embree_alone)],
    );
    assert_lines(
        &out,
        &["geometric mean pt/Embree, incoherent: closest 0.5000, any hit 2.0000"],
    );
    // The stand-ins do catch overlapping runs: side by side, the script stops.
    let side_by_side = Command::new("bash")
        .arg(script_path("against-embree.sh"))
        .args([&one, &mesh, &dir, &pt_alone])
        .env("PT_EMBREE_DIRECT", &embree_alone)
        .output()
        .unwrap();
    assert!(!side_by_side.status.success());
}

#[test]
fn against_mitsuba_reports_throughput_and_efficiency_ratios() {
    let dir = scratch("mitsuba");
    // The anchors as the script reads them: a scene, a camera line and a stand-in python that
    // answers `cbox.py render` (2 Msamples/s, its image naming its MI_SEED) and `imgcmp.py
    // relmse` (pt's image 0.004; Mitsuba's 0.002 with seed 1, 0.0012 with seed 2).
    let anchors = dir.join("anchors");
    std::fs::create_dir_all(anchors.join("mitsuba")).unwrap();
    std::fs::write(anchors.join("mitsuba/camera.txt"), "--max-depth 7").unwrap();
    let python = program(
        &dir,
        "python",
        r#"case "$2" in
render) printf "mi$MI_SEED" > "$5"; echo "mitsuba cbox 256x256 64 spp: 1.0 s, 2.00 Msamples/s" ;;
relmse) case "$(cat "$3")" in pt) echo 0.004 ;; mi1) echo 0.002 ;; mi2) echo 0.0012 ;; esac ;;
esac"#,
    );
    let pt = render(&dir, "render", "3.00", "pt");
    // What pt was asked for, one line per run.
    let args = dir.join("pt-args");
    let logged = program(
        &dir,
        "logged",
        &format!(
            "echo \"$*\" >> {}\nexec {} \"$@\"",
            args.display(),
            pt.display()
        ),
    );
    let (two, spp) = (PathBuf::from("2"), PathBuf::from("64"));
    let out = run(
        "against-mitsuba.sh",
        &[&two, &spp, &logged],
        &[("PT_ANCHORS", &anchors), ("PT_ANCHORS_PY", &python)],
    );
    // Each run's own seed in both renderers, and its own images' relMSE:
    // (3 / 0.004) / (2 / 0.002) = 0.75, (3 / 0.004) / (2 / 0.0012) = 0.45.
    let asked = std::fs::read_to_string(&args).unwrap();
    assert!(
        asked.lines().next().unwrap().contains("--seed 1"),
        "{asked}"
    );
    assert!(
        asked.lines().nth(1).unwrap().contains("--seed 2"),
        "{asked}"
    );
    assert!(
        out.contains("run 1: pt 3.00 Msamples/s, Mitsuba 2.00, pt/Mitsuba 1.500; relMSE pt 0.004, Mitsuba 0.002; efficiency pt/Mitsuba 0.750"),
        "{out}"
    );
    assert!(
        out.contains("run 2: pt 3.00 Msamples/s, Mitsuba 2.00, pt/Mitsuba 1.500; relMSE pt 0.004, Mitsuba 0.0012; efficiency pt/Mitsuba 0.450"),
        "{out}"
    );
    // The means: relMSE 0.004 and 0.0016, (3 / 0.004) / (2 / 0.0016) = 0.6.
    assert!(
        out.contains("means: pt 3.000 Msamples/s, Mitsuba 2.000, pt/Mitsuba 1.500; relMSE pt 0.004, Mitsuba 0.0016; efficiency pt/Mitsuba 0.600"),
        "{out}"
    );
}
