//! The PLY body: numbers from ASCII or binary data, read into vertices and fan-triangulated faces,
//! every element and property bounded by the header's checked counts.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::error::LoadError;
use crate::ply::header::{Element, Format, Header, Kind, Property, Scalar};

/// A stream of numbers from the body of the file.
pub(crate) trait Source {
    fn read(&mut self, ty: Scalar) -> Option<f64>;
    /// Bytes (binary) or a lower bound of characters (ASCII) left, for sanity checks of counts.
    fn remaining(&self) -> usize;
}

pub(crate) struct Binary<'a> {
    pub(crate) data: &'a [u8],
    pub(crate) pos: usize,
    pub(crate) big_endian: bool,
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

pub(crate) struct Ascii<'a> {
    pub(crate) data: &'a [u8],
    pub(crate) pos: usize,
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
pub(crate) fn min_element_size(e: &Element, format: Format) -> usize {
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
pub(crate) struct Vertices {
    pub(crate) positions: Vec<Vec3>,
    pub(crate) normals: Option<Vec<Vec3>>,
    pub(crate) uvs: Option<Vec<Vec2>>,
}

pub(crate) fn read_body(
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

pub(crate) fn truncated(path: &Path, element: &str, i: usize) -> LoadError {
    LoadError::parse(
        path,
        format!("{element} {i}"),
        "unexpected end of data or malformed value",
    )
}

pub(crate) fn skip_property(src: &mut impl Source, p: &Property) -> Option<()> {
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

pub(crate) fn read_vertices(
    src: &mut impl Source,
    e: &Element,
    path: &Path,
) -> Result<Vertices, LoadError> {
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

pub(crate) fn read_faces(
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
