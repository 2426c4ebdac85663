//! PLY (Stanford polygon file format) meshes: ASCII, binary little-endian and binary big-endian.
//!
//! Reads the `vertex` element's `x y z` (and `nx ny nz`, and `u v` / `s t` / `texture_u
//! texture_v` when present) and the `face` element's `vertex_indices` (or `vertex_index`) list;
//! polygons are triangulated as fans. Other elements and properties are read and skipped. Every
//! count in the header is checked against the data before anything is allocated for it, so a
//! corrupt header cannot make the reader allocate gigabytes; every failure is a [`LoadError`]
//! naming the file and the header line, vertex or face.

use std::path::Path;

use glam::{Vec2, Vec3};
use pt_core::Mesh;
use pt_core::pt_accel::TriangleMesh;

use crate::error::LoadError;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    body: usize,
}

fn parse_header(data: &[u8], path: &Path) -> Result<Header, LoadError> {
    let err = |line: usize, msg: &str| LoadError::parse(path, format!("header line {line}"), msg);
    let mut pos = 0;
    let mut line_no = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(end) = data[pos..].iter().position(|&b| b == b'\n') else {
            return Err(err(line_no + 1, "header ends without `end_header`"));
        };
        let raw = &data[pos..pos + end];
        pos += end + 1;
        line_no += 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| err(line_no, "header is not ASCII text"))?
            .trim_end_matches('\r')
            .trim();
        let words: Vec<&str> = line.split_ascii_whitespace().collect();
        if line_no == 1 {
            if line != "ply" {
                return Err(err(1, "not a PLY file (first line is not `ply`)"));
            }
            continue;
        }
        match words.as_slice() {
            [] => {}
            ["comment", ..] | ["obj_info", ..] => {}
            ["format", f, version] => {
                if *version != "1.0" {
                    return Err(err(line_no, &format!("unsupported PLY version {version}")));
                }
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::BinaryLittleEndian,
                    "binary_big_endian" => Format::BinaryBigEndian,
                    other => return Err(err(line_no, &format!("unknown format `{other}`"))),
                });
            }
            ["element", name, count] => {
                let count = count.parse::<usize>().map_err(|_| {
                    err(
                        line_no,
                        &format!("element count `{count}` is not a non-negative integer"),
                    )
                })?;
                elements.push(Element {
                    name: (*name).to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            ["property", "list", count, item, name] => {
                let count = Scalar::parse(count)
                    .ok_or_else(|| err(line_no, &format!("unknown type `{count}`")))?;
                let item = Scalar::parse(item)
                    .ok_or_else(|| err(line_no, &format!("unknown type `{item}`")))?;
                if matches!(count, Scalar::F32 | Scalar::F64) {
                    return Err(err(line_no, "list count type must be an integer type"));
                }
                let element = elements
                    .last_mut()
                    .ok_or_else(|| err(line_no, "property before any element"))?;
                element.props.push(Property {
                    name: (*name).to_string(),
                    kind: Kind::List { count, item },
                });
            }
            ["property", ty, name] => {
                let ty = Scalar::parse(ty)
                    .ok_or_else(|| err(line_no, &format!("unknown type `{ty}`")))?;
                let element = elements
                    .last_mut()
                    .ok_or_else(|| err(line_no, "property before any element"))?;
                element.props.push(Property {
                    name: (*name).to_string(),
                    kind: Kind::Scalar(ty),
                });
            }
            ["end_header"] => break,
            _ => return Err(err(line_no, &format!("cannot parse `{line}`"))),
        }
    }
    let format = format.ok_or_else(|| err(line_no, "no `format` line before `end_header`"))?;
    Ok(Header {
        format,
        elements,
        body: pos,
    })
}

/// A stream of numbers from the body of the file.
trait Source {
    fn read(&mut self, ty: Scalar) -> Option<f64>;
    /// Bytes (binary) or a lower bound of characters (ASCII) left, for sanity checks of counts.
    fn remaining(&self) -> usize;
}

struct Binary<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Source for Binary<'_> {
    #[inline]
    fn read(&mut self, ty: Scalar) -> Option<f64> {
        let n = ty.size();
        let bytes = self.data.get(self.pos..self.pos + n)?;
        self.pos += n;
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(bytes);
        if self.big_endian {
            b[..n].reverse();
        }
        Some(match ty {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }

    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }
}

struct Ascii<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Source for Ascii<'_> {
    fn read(&mut self, ty: Scalar) -> Option<f64> {
        while self.pos < self.data.len() && self.data[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < self.data.len() && !self.data[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let token = std::str::from_utf8(&self.data[start..self.pos]).ok()?;
        let v: f64 = token.parse().ok()?;
        // Integer types must hold integers in their range.
        let ok = match ty {
            Scalar::F32 | Scalar::F64 => true,
            Scalar::I8 => v.fract() == 0.0 && (-128.0..=127.0).contains(&v),
            Scalar::U8 => v.fract() == 0.0 && (0.0..=255.0).contains(&v),
            Scalar::I16 => v.fract() == 0.0 && (-32768.0..=32767.0).contains(&v),
            Scalar::U16 => v.fract() == 0.0 && (0.0..=65535.0).contains(&v),
            Scalar::I32 => v.fract() == 0.0 && (-2147483648.0..=2147483647.0).contains(&v),
            Scalar::U32 => v.fract() == 0.0 && (0.0..=4294967295.0).contains(&v),
        };
        ok.then_some(v)
    }

    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }
}

/// Smallest encoding of one element in the body (bytes for binary; characters for ASCII, where
/// every value takes at least one digit and one separator).
fn min_element_size(e: &Element, format: Format) -> usize {
    e.props
        .iter()
        .map(|p| match (format, p.kind) {
            (Format::Ascii, _) => 2,
            (_, Kind::Scalar(s)) => s.size(),
            (_, Kind::List { count, .. }) => count.size(),
        })
        .sum()
}

/// Vertex attributes found in the file.
#[derive(Default)]
struct Vertices {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    uvs: Option<Vec<Vec2>>,
}

fn read_body(
    src: &mut impl Source,
    header: &Header,
    path: &Path,
) -> Result<(Vertices, Vec<[u32; 3]>), LoadError> {
    let mut vertices = Vertices::default();
    let mut triangles = Vec::new();
    let mut vertex_count = None;
    for element in &header.elements {
        let min = min_element_size(element, header.format).max(1);
        // (+1: the last ASCII value may have no separator after it.)
        if element.count > (src.remaining() + 1) / min {
            return Err(LoadError::parse(
                path,
                format!("element `{}`", element.name),
                format!(
                    "header announces {} elements but the file ends before them",
                    element.count
                ),
            ));
        }
        match element.name.as_str() {
            "vertex" => {
                vertices = read_vertices(src, element, path)?;
                vertex_count = Some(vertices.positions.len());
            }
            "face" => {
                let n = vertex_count.ok_or_else(|| {
                    LoadError::parse(
                        path,
                        "element `face`",
                        "faces come before the vertex element",
                    )
                })?;
                triangles = read_faces(src, element, n, path)?;
            }
            _ => {
                for i in 0..element.count {
                    for p in &element.props {
                        skip_property(src, p).ok_or_else(|| truncated(path, &element.name, i))?;
                    }
                }
            }
        }
    }
    Ok((vertices, triangles))
}

fn truncated(path: &Path, element: &str, i: usize) -> LoadError {
    LoadError::parse(
        path,
        format!("{element} {i}"),
        "unexpected end of data or malformed value",
    )
}

fn skip_property(src: &mut impl Source, p: &Property) -> Option<()> {
    match p.kind {
        Kind::Scalar(s) => src.read(s).map(|_| ()),
        Kind::List { count, item } => {
            let n = src.read(count)?;
            if n < 0.0 {
                return None;
            }
            for _ in 0..n as usize {
                src.read(item)?;
            }
            Some(())
        }
    }
}

fn read_vertices(src: &mut impl Source, e: &Element, path: &Path) -> Result<Vertices, LoadError> {
    let find = |names: &[&str]| {
        e.props
            .iter()
            .position(|p| names.contains(&p.name.as_str()))
    };
    let (Some(ix), Some(iy), Some(iz)) = (find(&["x"]), find(&["y"]), find(&["z"])) else {
        return Err(LoadError::parse(
            path,
            "element `vertex`",
            "vertex element lacks x, y or z",
        ));
    };
    let normal = match (find(&["nx"]), find(&["ny"]), find(&["nz"])) {
        (Some(a), Some(b), Some(c)) => Some([a, b, c]),
        _ => None,
    };
    let uv = match (
        find(&["u", "s", "texture_u"]),
        find(&["v", "t", "texture_v"]),
    ) {
        (Some(a), Some(b)) => Some([a, b]),
        _ => None,
    };
    let mut out = Vertices {
        positions: Vec::with_capacity(e.count),
        normals: normal.map(|_| Vec::with_capacity(e.count)),
        uvs: uv.map(|_| Vec::with_capacity(e.count)),
    };
    let mut values = vec![0.0f64; e.props.len()];
    for i in 0..e.count {
        for (k, p) in e.props.iter().enumerate() {
            values[k] = match p.kind {
                Kind::Scalar(s) => src.read(s).ok_or_else(|| truncated(path, "vertex", i))?,
                Kind::List { .. } => {
                    skip_property(src, p).ok_or_else(|| truncated(path, "vertex", i))?;
                    0.0
                }
            };
        }
        let p = Vec3::new(values[ix] as f32, values[iy] as f32, values[iz] as f32);
        if let Some(problem) = crate::error::position_problem(p) {
            return Err(LoadError::invalid(path, format!("vertex {i}"), problem));
        }
        out.positions.push(p);
        if let (Some([a, b, c]), Some(ns)) = (normal, out.normals.as_mut()) {
            ns.push(Vec3::new(
                values[a] as f32,
                values[b] as f32,
                values[c] as f32,
            ));
        }
        if let (Some([a, b]), Some(uvs)) = (uv, out.uvs.as_mut()) {
            uvs.push(Vec2::new(values[a] as f32, values[b] as f32));
        }
    }
    Ok(out)
}

fn read_faces(
    src: &mut impl Source,
    e: &Element,
    vertex_count: usize,
    path: &Path,
) -> Result<Vec<[u32; 3]>, LoadError> {
    let indices_prop = e
        .props
        .iter()
        .position(|p| {
            matches!(p.kind, Kind::List { .. })
                && (p.name == "vertex_indices" || p.name == "vertex_index")
        })
        .ok_or_else(|| {
            LoadError::parse(
                path,
                "element `face`",
                "face element lacks a vertex_indices list",
            )
        })?;
    let mut triangles = Vec::with_capacity(e.count);
    let mut polygon: Vec<u32> = Vec::new();
    for i in 0..e.count {
        for (k, p) in e.props.iter().enumerate() {
            if k != indices_prop {
                skip_property(src, p).ok_or_else(|| truncated(path, "face", i))?;
                continue;
            }
            let Kind::List { count, item } = p.kind else {
                unreachable!("checked above")
            };
            let n = src.read(count).ok_or_else(|| truncated(path, "face", i))?;
            // NaN (an ASCII `nan` count) is refused too.
            if n.is_nan() || n < 3.0 {
                return Err(LoadError::invalid(
                    path,
                    format!("face {i}"),
                    format!("has {n} vertices, fewer than 3"),
                ));
            }
            polygon.clear();
            for _ in 0..n as usize {
                let v = src.read(item).ok_or_else(|| truncated(path, "face", i))?;
                // NaN and fractions are refused too (they would become vertex 0).
                if !(v >= 0.0 && v < vertex_count as f64 && v.fract() == 0.0) {
                    return Err(LoadError::invalid(
                        path,
                        format!("face {i}"),
                        format!(
                            "vertex index {v} is out of range or not an index (the file has {vertex_count} vertices)"
                        ),
                    ));
                }
                polygon.push(v as u32);
            }
            for j in 1..polygon.len() - 1 {
                triangles.push([polygon[0], polygon[j], polygon[j + 1]]);
            }
        }
    }
    Ok(triangles)
}

/// Parse PLY data; `path` is used in error messages only.
pub fn parse_ply(data: &[u8], path: &Path) -> Result<Mesh, LoadError> {
    let header = parse_header(data, path)?;
    let body = &data[header.body..];
    let (vertices, triangles) = match header.format {
        Format::Ascii => read_body(&mut Ascii { data: body, pos: 0 }, &header, path)?,
        Format::BinaryLittleEndian | Format::BinaryBigEndian => read_body(
            &mut Binary {
                data: body,
                pos: 0,
                big_endian: header.format == Format::BinaryBigEndian,
            },
            &header,
            path,
        )?,
    };
    if triangles.is_empty() {
        return Err(LoadError::invalid(
            path,
            "element `face`",
            "the file has no faces",
        ));
    }
    let geometry = TriangleMesh::new(vertices.positions, triangles)
        .map_err(|e| LoadError::invalid(path, "mesh", e.to_string()))?;
    let mut mesh = Mesh::new(geometry);
    if let Some(n) = vertices.normals {
        mesh = mesh
            .with_normals(n)
            .map_err(|e| LoadError::invalid(path, "normals", e.to_string()))?;
    }
    if let Some(uv) = vertices.uvs {
        mesh = mesh
            .with_uvs(uv)
            .map_err(|e| LoadError::invalid(path, "uvs", e.to_string()))?;
    }
    Ok(mesh)
}

/// Read a PLY file.
pub fn load_ply(path: impl AsRef<Path>) -> Result<Mesh, LoadError> {
    let path = path.as_ref();
    let data = crate::Limits::default().read_file(path)?;
    parse_ply(&data, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n";

    fn binary(big_endian: bool) -> Vec<u8> {
        let fmt = if big_endian {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let mut d = format!("ply\nformat {fmt} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement edge 1\nproperty int a\nproperty int b\nelement face 1\nproperty uchar flags\nproperty list uchar uint vertex_indices\nend_header\n").into_bytes();
        let f = |d: &mut Vec<u8>, v: f32| {
            d.extend(if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        let u = |d: &mut Vec<u8>, v: u32| {
            d.extend(if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            })
        };
        for p in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]] {
            for c in p {
                f(&mut d, c);
            }
        }
        u(&mut d, 0);
        u(&mut d, 1);
        d.push(7);
        d.push(3);
        for i in [0, 1, 2] {
            u(&mut d, i);
        }
        d
    }

    #[test]
    fn ascii_with_normals_and_a_quad() {
        let m = parse_ply(ASCII.as_bytes(), Path::new("square.ply")).unwrap();
        assert_eq!(m.geometry().positions().len(), 4);
        assert_eq!(m.geometry().indices(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals().unwrap()[2], Vec3::Z);
    }

    #[test]
    fn binary_both_endians_skipping_other_elements() {
        for be in [false, true] {
            let m = parse_ply(&binary(be), Path::new("t.ply")).unwrap();
            assert_eq!(m.geometry().positions()[2], Vec3::new(0.0, 2.0, 0.0));
            assert_eq!(m.geometry().indices(), &[[0, 1, 2]]);
        }
    }

    fn err(data: &[u8]) -> String {
        parse_ply(data, Path::new("bad.ply"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn malformed_files_give_clear_errors() {
        assert!(err(b"plx\n").contains("not a PLY file"));
        assert!(err(b"ply\nformat ascii 1.0\nelement vertex 3\n").contains("without `end_header`"));
        assert!(err(b"ply\nformat weird 1.0\nend_header\n").contains("unknown format"));
        assert!(
            err(b"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n")
                .contains("header line 3")
        );
        assert!(
            err(b"ply\nformat ascii 1.0\nproperty float x\nend_header\n")
                .contains("before any element")
        );
        assert!(
            err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion x\nend_header\n")
                .contains("unknown type")
        );
        // Truncated body: header promises more than the data holds (no huge allocation).
        let big = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
        assert!(err(big.as_bytes()).contains("file ends before them"));
        let cut = &binary(false)[..binary(false).len() - 3];
        assert!(err(cut).contains("face 0"), "{}", err(cut));
        // Bad data.
        let oob = ASCII.replace("4 0 1 2 3", "3 0 1 9");
        assert!(err(oob.as_bytes()).contains("face 0: vertex index 9 is out of range"));
        let nan = ASCII.replace("1 1 0 0 0 1", "1 nan 0 0 0 1");
        assert!(
            err(nan.as_bytes()).contains("vertex 2"),
            "{}",
            err(nan.as_bytes())
        );
        let two = ASCII.replace("4 0 1 2 3", "2 0 1");
        assert!(err(two.as_bytes()).contains("fewer than 3"));
        let frac = ASCII.replace("4 0 1 2 3", "3 0 1.5 2");
        assert!(err(frac.as_bytes()).contains("face 0"));
    }
}
