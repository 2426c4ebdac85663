//! OBJ text as tobj should see it, and tobj's errors turned into ones that name the file and line.

use std::path::Path;

use crate::error::LoadError;

/// OBJ bytes as the text tobj should see: a UTF-8 byte-order mark dropped, old Mac (CR-only)
/// and Windows line ends made LF; bytes that are not UTF-8 are an error naming their line
/// (tobj would only say "read error").
pub(crate) fn prepare_text(bytes: &[u8], path: &Path) -> Result<String, LoadError> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        LoadError::parse(
            path,
            format!("line {line}"),
            format!("byte 0x{:02x} is not UTF-8 text (OBJ is text)", bytes[at]),
        )
    })?;
    Ok(if text.contains('\r') {
        text.replace("\r\n", "\n").replace('\r', "\n")
    } else {
        text.to_string()
    })
}

/// A tobj error with the line it happened on (tobj reports none) and what the line should hold.
pub(crate) fn tobj_error(path: &Path, text: &str, e: tobj::LoadError) -> LoadError {
    match e {
        tobj::LoadError::OpenFileFailed | tobj::LoadError::ReadError => LoadError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(e.to_string()),
        },
        other => {
            let location = locate_error(text, &other)
                .map_or_else(|| "file".to_string(), |line| format!("line {line}"));
            let hint = match other {
                tobj::LoadError::PositionParseError | tobj::LoadError::ColorParseError => {
                    ": a `v` line holds x y z, x y z w, or x y z r g b"
                }
                tobj::LoadError::FaceParseError | tobj::LoadError::InvalidPolygon => {
                    ": an `f` line holds three or more vertex indices"
                }
                _ => "",
            };
            LoadError::parse(path, location, format!("{other}{hint}"))
        }
    }
}

pub(crate) fn short_face_error(path: &Path, line: usize, corners: usize) -> LoadError {
    LoadError::parse(
        path,
        format!("line {line}"),
        format!("a face needs at least three vertices, this one has {corners}"),
    )
}

/// The line of the first face statement with fewer than three corners, which tobj drops
/// silently (a file of only such faces then has "no faces").
pub(crate) fn short_face(text: &str) -> Option<(usize, usize)> {
    text.lines().enumerate().find_map(|(i, raw)| {
        let line = raw.split('#').next().unwrap_or("").trim();
        let rest = line
            .strip_prefix("f ")
            .or_else(|| line.strip_prefix("f\t"))?;
        let n = rest.split_whitespace().count();
        (n < 3).then_some((i + 1, n))
    })
}

/// The 1-based line of the first statement that causes `e`, by re-reading the file with the
/// same rules tobj applies (numbers must parse, face indices must be in range, negative indices
/// count back from the current end).
pub(crate) fn locate_error(text: &str, e: &tobj::LoadError) -> Option<usize> {
    use tobj::LoadError as E;
    let numbers_ok = |rest: &str, min: usize, max: usize| {
        let v: Vec<&str> = rest.split_whitespace().collect();
        v.len() >= min && v.len() <= max && v.iter().all(|x| x.parse::<f32>().is_ok())
    };
    let (mut nv, mut nvt, mut nvn) = (0i64, 0i64, 0i64);
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut words = line.splitn(2, char::is_whitespace);
        let key = words.next().unwrap_or("");
        let rest = words.next().unwrap_or("").trim();
        let bad = match key {
            "v" => {
                nv += 1;
                // tobj reads x y z, x y z w and x y z r g b.
                let n = rest.split_whitespace().count();
                matches!(e, E::PositionParseError | E::ColorParseError)
                    && (!numbers_ok(rest, 3, 6) || n == 5)
            }
            "vt" => {
                nvt += 1;
                matches!(e, E::TexcoordParseError) && !numbers_ok(rest, 1, 3)
            }
            "vn" => {
                nvn += 1;
                matches!(e, E::NormalParseError) && !numbers_ok(rest, 3, 3)
            }
            "f" => {
                let corners: Vec<&str> = rest.split_whitespace().collect();
                let mut bad =
                    corners.len() < 3 && matches!(e, E::InvalidPolygon | E::FaceParseError);
                for c in &corners {
                    let parts: Vec<&str> = c.split('/').collect();
                    let check = |idx: Option<&&str>, n: i64, err: bool| match idx {
                        Some(s) if !s.is_empty() => match s.parse::<i64>() {
                            Ok(k) => {
                                let k = if k < 0 { n + k + 1 } else { k };
                                err && (k < 1 || k > n)
                            }
                            Err(_) => matches!(e, E::FaceParseError),
                        },
                        _ => false,
                    };
                    bad |= check(parts.first(), nv, matches!(e, E::FaceVertexOutOfBounds))
                        || check(parts.get(1), nvt, matches!(e, E::FaceTexCoordOutOfBounds))
                        || check(parts.get(2), nvn, matches!(e, E::FaceNormalOutOfBounds));
                    if parts.first().is_none_or(|s| s.is_empty()) && matches!(e, E::FaceParseError)
                    {
                        bad = true;
                    }
                }
                bad
            }
            _ => false,
        };
        if bad {
            return Some(i + 1);
        }
    }
    None
}
