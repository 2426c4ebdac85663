//! What the gltf crate's readers assume but do not check: buffer and image sizes against the
//! limits, accessors and views within their buffers. Each check runs before the read it guards
//! (found by fuzzing: the readers panic or allocate without bound otherwise).

use std::path::Path;

use crate::error::LoadError;
use crate::limits::Limits;

/// `%XX` escapes of a relative URI decoded (glTF URIs are RFC 3986).
pub(crate) fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The file an external (not `data:`) URI names, relative to `base`.
pub(crate) fn uri_file(uri: &str, base: Option<&Path>) -> Option<std::path::PathBuf> {
    if uri.starts_with("data:") {
        return None;
    }
    let rel = percent_decode(uri);
    Some(base.map_or_else(|| Path::new(&rel).to_path_buf(), |b| b.join(&rel)))
}

/// Check every buffer before the `gltf` crate reads it: an external file must be a regular
/// file no larger than its declared `byteLength` (plus alignment padding), and the declared
/// length within the limits.
pub(crate) fn check_buffers(
    doc: &::gltf::Document,
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<(), LoadError> {
    for buffer in doc.buffers() {
        let element = format!("buffer {}", buffer.index());
        let declared = buffer.length() as u64;
        Limits::check(
            path,
            &element,
            "max_file_bytes",
            declared,
            limits.max_file_bytes,
        )?;
        let ::gltf::buffer::Source::Uri(uri) = buffer.source() else {
            continue;
        };
        let Some(file) = uri_file(uri, base) else {
            continue;
        };
        let meta = std::fs::metadata(&file).map_err(|source| LoadError::Io {
            path: file.clone(),
            source,
        })?;
        if !meta.is_file() {
            return Err(LoadError::invalid(
                path,
                element,
                format!(
                    "{} is not a regular file (a directory, device or FIFO)",
                    file.display()
                ),
            ));
        }
        if meta.len() > declared.next_multiple_of(4) + 4 {
            return Err(LoadError::invalid(
                path,
                element,
                format!(
                    "declares {declared} bytes but {} holds {}; refusing to read it",
                    file.display(),
                    meta.len()
                ),
            ));
        }
    }
    Ok(())
}

/// The pixel count an image declares in its header, checked against the limits before it is
/// decoded (uri files and buffer views; a `data:` URI is decoded by the `gltf` crate within
/// the `image` crate's own allocation limit and checked after).
pub(crate) fn check_image(
    image: &::gltf::Image<'_>,
    json: &::gltf::json::Image,
    buffers: &[::gltf::buffer::Data],
    path: &Path,
    base: Option<&Path>,
    limits: &Limits,
) -> Result<(), LoadError> {
    let element = format!("image {}", image.index());
    let invalid = |m: String| LoadError::invalid(path, &element, m);
    let dims = if let Some(file) = json.uri.as_deref().and_then(|u| uri_file(u, base)) {
        let meta = std::fs::metadata(&file).map_err(|source| LoadError::Io {
            path: file.clone(),
            source,
        })?;
        if !meta.is_file() {
            return Err(invalid(format!("{} is not a regular file", file.display())));
        }
        Limits::check(
            path,
            &element,
            "max_file_bytes",
            meta.len(),
            limits.max_file_bytes,
        )?;
        image::ImageReader::open(&file)
            .and_then(image::ImageReader::with_guessed_format)
            .map_err(|e| invalid(format!("{}: {e}", file.display())))?
            .into_dimensions()
            .map_err(|e| invalid(format!("{}: {e}", file.display())))?
    } else if let ::gltf::image::Source::View { view, .. } = image.source() {
        let data = &buffers[view.buffer().index()];
        let bytes = &data[view.offset()..view.offset() + view.length()];
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| invalid(e.to_string()))?
            .into_dimensions()
            .map_err(|e| invalid(e.to_string()))?
    } else {
        return Ok(());
    };
    let pixels = u64::from(dims.0) * u64::from(dims.1);
    Limits::check(
        path,
        element,
        "max_image_pixels",
        pixels,
        limits.max_image_pixels,
    )
}

/// Check what the `gltf` crate's readers assume but do not check, and panic on when it is false
/// (found by fuzzing): the accessor has the type the reader will read, is not sparse, has a buffer
/// view, a stride no smaller than its element, and lies within its view and the view within the
/// loaded buffer.
pub(crate) fn check_accessor(
    a: &::gltf::Accessor<'_>,
    dimensions: ::gltf::accessor::Dimensions,
    types: &[::gltf::accessor::DataType],
    buffers: &[::gltf::buffer::Data],
) -> Result<(), String> {
    let index = a.index();
    if a.dimensions() != dimensions || !types.contains(&a.data_type()) {
        return Err(format!(
            "accessor {index} is {:?} of {:?}, expected {dimensions:?} of one of {types:?}",
            a.dimensions(),
            a.data_type()
        ));
    }
    if a.sparse().is_some() {
        return Err(format!(
            "accessor {index} is sparse, which pt does not read"
        ));
    }
    let Some(view) = a.view() else {
        return Err(format!("accessor {index} has no buffer view"));
    };
    check_view(&view, buffers)?;
    let element = a.size();
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(format!(
            "accessor {index}: byte stride {stride} is smaller than an element ({element} bytes)"
        ));
    }
    let end = (a.count().max(1) - 1)
        .checked_mul(stride)
        .and_then(|n| n.checked_add(a.offset()))
        .and_then(|n| n.checked_add(element));
    match end {
        Some(end) if end <= view.length() => Ok(()),
        _ => Err(format!(
            "accessor {index} ({} elements of {element} bytes, stride {stride}, offset {}) \
             runs past its buffer view ({} bytes)",
            a.count(),
            a.offset(),
            view.length()
        )),
    }
}

/// A buffer view must lie within the data actually loaded for its buffer.
pub(crate) fn check_view(
    view: &::gltf::buffer::View<'_>,
    buffers: &[::gltf::buffer::Data],
) -> Result<(), String> {
    let loaded = buffers.get(view.buffer().index()).map_or(0, |d| d.0.len());
    match view.offset().checked_add(view.length()) {
        Some(end) if end <= loaded => Ok(()),
        _ => Err(format!(
            "buffer view {} (offset {}, {} bytes) runs past the {loaded} bytes of buffer {}",
            view.index(),
            view.offset(),
            view.length(),
            view.buffer().index()
        )),
    }
}
