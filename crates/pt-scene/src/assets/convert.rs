//! Exact conversions from a public original to the bytes of a converted asset (feature
//! `download`). The result is checked against the manifest's size and sha256 like any download,
//! so a conversion either reproduces the stored file bit for bit or is refused.

use super::Conversion;

/// Apply `conversion` to the (decompressed) original.
pub(super) fn convert(conversion: Conversion, original: &[u8]) -> Result<Vec<u8>, String> {
    match conversion {
        Conversion::AsciiPlyToBinary { comments } => ascii_ply_to_binary(original, comments),
    }
}

/// An ASCII PLY of `float x, y, z` vertices and `list uchar int vertex_indices` triangles as a
/// binary little-endian PLY with the same elements in the same order, each coordinate the f32
/// nearest its decimal (Rust's `f32` parsing rounds correctly, as the original conversion did).
fn ascii_ply_to_binary(original: &[u8], comments: &[&str]) -> Result<Vec<u8>, String> {
    let text =
        std::str::from_utf8(original).map_err(|_| "the PLY is not ASCII text".to_string())?;
    let (header, body) = text
        .split_once("end_header\n")
        .ok_or("the PLY has no `end_header` line")?;
    let mut lines = header.lines();
    if lines.next() != Some("ply") || !header.contains("\nformat ascii 1.0\n") {
        return Err("not an ASCII PLY".into());
    }
    // The header must hold exactly the layout this conversion writes.
    let mut vertices = None;
    let mut faces = None;
    let mut layout = Vec::new();
    for line in lines {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["format", ..] | ["comment", ..] | ["obj_info", ..] => {}
            ["element", "vertex", n] => vertices = n.parse::<usize>().ok(),
            ["element", "face", n] => faces = n.parse::<usize>().ok(),
            ["property", rest @ ..] => layout.push(rest.join(" ")),
            _ => return Err(format!("unexpected header line {line:?}")),
        }
    }
    let expected = [
        "float x",
        "float y",
        "float z",
        "list uchar int vertex_indices",
    ];
    if layout != expected {
        return Err(format!("properties {layout:?}, expected {expected:?}"));
    }
    let (Some(nv), Some(nf)) = (vertices, faces) else {
        return Err("the header lacks a vertex or face count".into());
    };
    let mut out = String::from("ply\nformat binary_little_endian 1.0\n");
    for c in comments {
        out.push_str(&format!("comment {c}\n"));
    }
    out.push_str(&format!(
        "element vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
    ));
    let mut bytes = out.into_bytes();
    bytes
        .try_reserve(nv.saturating_mul(12).saturating_add(nf.saturating_mul(13)))
        .map_err(|_| "the PLY declares more elements than fit in memory".to_string())?;
    let mut rows = body.lines();
    for i in 0..nv {
        let row = rows.next().ok_or(format!("vertex {i} is missing"))?;
        let xyz: Vec<f32> = row
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|_| format!("vertex {i} is not three numbers: {row:?}"))?;
        if xyz.len() != 3 {
            return Err(format!("vertex {i} is not three numbers: {row:?}"));
        }
        for v in xyz {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    for i in 0..nf {
        let row = rows.next().ok_or(format!("face {i} is missing"))?;
        let ids: Vec<i32> = row
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|_| format!("face {i} is not a list of indices: {row:?}"))?;
        if ids.len() != 4 || ids[0] != 3 {
            return Err(format!("face {i} is not a triangle: {row:?}"));
        }
        bytes.push(3);
        for v in &ids[1..] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    if rows.any(|r| !r.trim().is_empty()) {
        return Err("the PLY has more rows than its header declares".into());
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_ascii_ply_becomes_the_binary_layout() {
        let ascii = b"ply\nformat ascii 1.0\ncomment x\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 1\n\
            property list uchar int vertex_indices\nend_header\n0 0 0 \n1 0 0\n0 0.1 0\n3 0 1 2\n";
        let b = ascii_ply_to_binary(ascii, &["made here"]).unwrap();
        let header = "ply\nformat binary_little_endian 1.0\ncomment made here\nelement vertex 3\n\
            property float x\nproperty float y\nproperty float z\nelement face 1\n\
            property list uchar int vertex_indices\nend_header\n";
        assert!(b.starts_with(header.as_bytes()));
        let data = &b[header.len()..];
        assert_eq!(data.len(), 3 * 12 + 13);
        assert_eq!(&data[28..32], &0.1f32.to_le_bytes());
        assert_eq!(&data[36..], &[3, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0]);
        let bad = String::from_utf8_lossy(ascii).replace("3 0 1 2", "4 0 1 2 3");
        assert!(ascii_ply_to_binary(bad.as_bytes(), &[]).is_err());
        let short = String::from_utf8_lossy(ascii).replace("3 0 1 2\n", "");
        assert!(ascii_ply_to_binary(short.as_bytes(), &[]).is_err());
    }
}
