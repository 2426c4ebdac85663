//! The public API names no type of the crates pt is built on (issue 8): a program that uses pt
//! must not need `obvhs`, `gltf` or `tobj` in its own `Cargo.toml`, and pt must be free to
//! replace them. `tests/downstream/` proves that the API is usable from outside; this test
//! proves the narrower property that no public signature mentions those crates.
//!
//! It reads every public item's signature (from `pub ` up to its `{`, `;` or, for a field, its
//! `,`; `pub(crate)` items are not public) and looks for paths into the three crates. Paths to
//! pt's own modules of the same name (`crate::gltf::`, `pt_scene::gltf::`) are allowed.

use crate::support;

/// The external crates no public signature may name.
const BACKENDS: [&str; 3] = ["obvhs", "gltf", "tobj"];

/// Prefixes under which a backend's name is one of pt's own modules, not the crate.
const OWN_PREFIXES: [&str; 4] = ["crate::", "super::", "self::", "pt_scene::"];

/// The public signatures in `text`, each with its first line number.
fn public_signatures(text: &str) -> Vec<(usize, String)> {
    let lines: Vec<&str> = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let trimmed = lines[i].trim_start();
        if trimmed.starts_with("pub ") {
            let start = i;
            let mut sig = String::new();
            loop {
                let line = lines[i].trim();
                // A signature ends at the item's body, at `;`, or at a field's `,`.
                let end = line
                    .find(['{', ';'])
                    .or_else(|| line.ends_with(',').then_some(line.len()));
                sig.push_str(&line[..end.unwrap_or(line.len())]);
                sig.push(' ');
                if end.is_some() || i + 1 == lines.len() {
                    break;
                }
                i += 1;
            }
            out.push((start + 1, sig));
        }
        i += 1;
    }
    out
}

/// Whether `sig` names one of the backend crates (rather than pt's own module of that name).
fn names_backend(sig: &str) -> Option<&'static str> {
    for name in BACKENDS {
        for (at, _) in sig.match_indices(name) {
            let before = &sig[..at];
            let after = &sig[at + name.len()..];
            let ident_before = before
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_');
            let ident_after = after
                .chars()
                .next()
                .is_some_and(|c| c.is_alphanumeric() || c == '_');
            if ident_before || ident_after {
                continue; // part of a longer identifier (load_gltf, GltfError, ...)
            }
            let is_path = after.starts_with("::") || before.trim_end().ends_with("use");
            if is_path && !OWN_PREFIXES.iter().any(|p| before.ends_with(p)) {
                return Some(name);
            }
        }
    }
    None
}

#[test]
fn no_backend_type_in_a_public_signature() {
    let mut found = Vec::new();
    let mut checked = 0;
    for f in support::workspace_sources() {
        let text = std::fs::read_to_string(&f).unwrap();
        for (line, sig) in public_signatures(&text) {
            checked += 1;
            if let Some(name) = names_backend(&sig) {
                found.push(format!("{}:{line}: {name}: {}", f.display(), sig.trim()));
            }
        }
    }
    println!("{checked} public signatures checked");
    assert!(checked > 500, "too few public signatures found: {checked}");
    assert!(
        found.is_empty(),
        "public signatures that name a backend crate:\n{}",
        found.join("\n")
    );
}

/// The scanner itself catches what it is meant to catch, and lets pt's own modules pass.
#[test]
fn the_scanner_sees_backend_paths() {
    let leaky = "pub fn bvh(&self) -> &obvhs::cwbvh::CwBvh {\n\
                 pub struct Doc {\n    pub doc: ::gltf::Document,\n}\n\
                 pub fn load(\n    models: Vec<tobj::Model>,\n) -> Mesh;\n\
                 pub use obvhs;\n";
    let sigs = public_signatures(leaky);
    let hits: Vec<_> = sigs.iter().filter_map(|(_, s)| names_backend(s)).collect();
    assert_eq!(hits, ["obvhs", "gltf", "tobj", "obvhs"], "{sigs:?}");

    let clean = "pub fn load_gltf(path: &Path) -> Result<SceneDesc, LoadError> {\n\
                 pub use crate::gltf::GltfOptions;\n\
                 pub(crate) fn inner(m: &[tobj::Model]) {\n\
                 pub fn f(x: pt_scene::gltf::Thing) -> obvhs_like::X;\n";
    let sigs = public_signatures(clean);
    assert_eq!(sigs.len(), 3, "{sigs:?}");
    assert!(
        sigs.iter().all(|(_, s)| names_backend(s).is_none()),
        "{sigs:?}"
    );
}
