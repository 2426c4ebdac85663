//! The PLY header: format, elements and their properties, each count checked against the file's
//! size before anything is allocated for it.

use std::path::Path;

use crate::error::LoadError;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Format {
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scalar {
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

    pub(crate) fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Clone, Debug)]
pub(crate) struct Property {
    pub(crate) name: String,
    pub(crate) kind: Kind,
}

#[derive(Clone, Debug)]
pub(crate) struct Element {
    pub(crate) name: String,
    pub(crate) count: usize,
    pub(crate) props: Vec<Property>,
}

pub(crate) struct Header {
    pub(crate) format: Format,
    pub(crate) elements: Vec<Element>,
    pub(crate) body: usize,
}

pub(crate) fn parse_header(data: &[u8], path: &Path) -> Result<Header, LoadError> {
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
