//! OpenEXR files (feature `exr`): linear images ([`Image::write_exr`]) and partial renders
//! ([`PartialRender::write_exr`], [`PartialRender::read_exr`]), the one place pt reads and
//! writes the format.
//!
//! Files are written with increasing line order and a partial render's fields in one
//! attribute, so the same image, or the same partial render, gives the same bytes whatever
//! order the parallel compression finishes in and in every process.

use std::collections::HashMap;
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image as ExrImage, Layer,
    LayerAttributes, LineOrder, ReadChannels, ReadLayers, SmallVec, SpecificChannels, Text, Vec2,
    WritableImage, read,
};

use crate::film::{AuxSum, Film, PixelSum};
use crate::image::{Image, ImageError};
use crate::partial::{MAX_PARTIAL_PIXELS, PartialRender, normalise, parse_ranges};
use crate::render::RenderOutput;

/// The text attribute of a partial render that holds its fields, one `key=value` per line.
const FIELDS: &str = "pt.partial";

/// A field's value on one line: backslashes and line breaks escaped.
fn escape(v: &str) -> String {
    v.replace('\\', "\\\\")
        .replace('\n', "\\n")
        .replace('\r', "\\r")
}

/// The inverse of [`escape`].
fn unescape(v: &str) -> String {
    let mut out = String::with_capacity(v.len());
    let mut chars = v.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            match chars.next() {
                Some('n') => out.push('\n'),
                Some('r') => out.push('\r'),
                Some(other) => out.push(other),
                None => out.push('\\'),
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// The value of the `pt.format` field of partial renders.
const FORMAT: &str = "pt-partial-1";
const COLOURS: [&str; 3] = ["R", "G", "B"];
/// The auxiliary outputs' channels, in [`AuxSum::raw`]'s order.
const AUX: [&str; 6] = [
    "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z",
];

fn decode(path: &Path, message: impl Into<String>) -> ImageError {
    ImageError::Decode {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

fn exr_error(path: &Path, e: exr::error::Error) -> ImageError {
    match e {
        exr::error::Error::Io(source) => ImageError::Io {
            path: path.to_path_buf(),
            source,
        },
        other => decode(path, other.to_string()),
    }
}

/// Chunks in increasing line order (byte-identical files for identical images), compressed
/// losslessly (ZIP for 16 scan lines: small and still quick to decode).
fn deterministic(encoding: Encoding) -> Encoding {
    Encoding {
        line_order: LineOrder::Increasing,
        ..encoding
    }
}

/// Write one layer of named channels, sorted as the format wants, deterministically.
fn write_channels(
    path: &Path,
    size: (usize, usize),
    attributes: LayerAttributes,
    channels: Vec<AnyChannel<FlatSamples>>,
) -> Result<(), ImageError> {
    let layer = Layer::new(
        size,
        attributes,
        deterministic(Encoding::SMALL_LOSSLESS),
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    ExrImage::from_layer(layer)
        .write()
        .to_file(path)
        .map_err(|e| exr_error(path, e))
}

impl Image {
    /// Write a linear RGB OpenEXR file with 32-bit float channels.
    pub fn write_exr(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        let path = path.as_ref();
        let (w, h) = (self.width() as usize, self.height() as usize);
        let data = self.as_slice();
        let pixels = SpecificChannels::rgb(|p: Vec2<usize>| {
            let i = 3 * (p.y() * w + p.x());
            (data[i], data[i + 1], data[i + 2])
        });
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            deterministic(Encoding::SMALL_LOSSLESS),
            pixels,
        );
        ExrImage::from_layer(layer)
            .write()
            .to_file(path)
            .map_err(|e| match e {
                exr::error::Error::Io(source) => ImageError::Io {
                    path: path.to_path_buf(),
                    source,
                },
                other => ImageError::Encode {
                    path: path.to_path_buf(),
                    message: other.to_string(),
                },
            })
    }
}

impl RenderOutput {
    /// Write the image as a linear OpenEXR file with 32-bit float channels `R`, `G`, `B`, and
    /// the auxiliary outputs the render has as further layers: `albedo.{R,G,B}` and
    /// `normal.{X,Y,Z}` ([`crate::aov`]). Without AOVs this is [`Image::write_exr`].
    pub fn write_exr(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        let path = path.as_ref();
        let layers: Vec<(&Image, &[&str])> = [
            Some((&self.image, &COLOURS[..])),
            self.albedo.as_ref().map(|a| (a, &AUX[..3])),
            self.normal.as_ref().map(|n| (n, &AUX[3..])),
        ]
        .into_iter()
        .flatten()
        .collect();
        if layers.len() == 1 {
            return self.image.write_exr(path);
        }
        let (w, h) = (self.image.width() as usize, self.image.height() as usize);
        let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(9);
        for (image, names) in layers {
            for (k, name) in names.iter().enumerate() {
                let data = image
                    .as_slice()
                    .iter()
                    .skip(k)
                    .step_by(3)
                    .copied()
                    .collect();
                channels.push(AnyChannel::new(*name, FlatSamples::F32(data)));
            }
        }
        write_channels(path, (w, h), LayerAttributes::default(), channels)
    }
}

impl PartialRender {
    /// Write as a partial EXR (see the [module documentation](crate::partial) for the
    /// layout): viewable as an image, and exact for [`PartialRender::read_exr`].
    pub fn write_exr(&self, path: impl AsRef<Path>) -> Result<(), ImageError> {
        let path = path.as_ref();
        let (w, h) = (self.film.width() as usize, self.film.height() as usize);
        let pixels = self.film.pixels();
        let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(16);
        for (k, name) in COLOURS.iter().enumerate() {
            let mean = pixels.iter().map(|p| p.mean().to_array()[k]).collect();
            channels.push(AnyChannel::new(*name, FlatSamples::F32(mean)));
            for word in 0..4 {
                let data = pixels
                    .iter()
                    .map(|p| (p.raw().0[k] as u128 >> (32 * word)) as u32)
                    .collect();
                channels.push(AnyChannel::new(
                    format!("pt.sum.{name}.{word}").as_str(),
                    FlatSamples::U32(data),
                ));
            }
        }
        let counts = pixels.iter().map(|p| p.raw().1).collect();
        channels.push(AnyChannel::new("pt.count", FlatSamples::U32(counts)));
        if self.film.has_aux() {
            let aux = self.film.aux();
            for (k, name) in AUX.iter().enumerate() {
                let means = aux
                    .iter()
                    .zip(pixels)
                    .map(|(a, p)| {
                        let n = p.count();
                        if k < 3 {
                            a.albedo(n).to_array()[k]
                        } else {
                            a.normal(n).to_array()[k - 3]
                        }
                    })
                    .collect();
                channels.push(AnyChannel::new(*name, FlatSamples::F32(means)));
                for word in 0..2 {
                    let data = aux
                        .iter()
                        .map(|a| (a.raw()[k] as u64 >> (32 * word)) as u32)
                        .collect();
                    channels.push(AnyChannel::new(
                        format!("pt.aux.{name}.{word}").as_str(),
                        FlatSamples::U32(data),
                    ));
                }
            }
        }

        // One text attribute holds every field: the exr crate keeps attributes in a hash map
        // whose order changes from process to process, so several would make equal renders
        // write different bytes.
        let mut fields = String::new();
        let mut text = |key: &str, value: String| {
            fields.push_str(key);
            fields.push('=');
            fields.push_str(&escape(&value));
            fields.push('\n');
        };
        text("pt.format", FORMAT.to_string());
        text("pt.spp", self.spp.to_string());
        text("pt.seed", self.seed.to_string());
        text("pt.ranges", self.ranges_text());
        text("pt.label", self.label.clone());
        text("pt.non_finite", self.film.non_finite_samples().to_string());
        text("pt.clamped", self.film.clamped_samples().to_string());
        text("pt.saturated", self.film.saturated_samples().to_string());
        let mut attributes = LayerAttributes::named("pt partial render");
        attributes.other.insert(
            Text::from(FIELDS),
            AttributeValue::Text(Text::new_or_panic(fields.as_str())),
        );
        write_channels(path, (w, h), attributes, channels)
    }

    /// Read a partial EXR written by [`PartialRender::write_exr`]. Errors name the file
    /// and what is wrong (not a partial render, missing channel, bad attribute, counts
    /// that disagree with the ranges).
    pub fn read_exr(path: impl AsRef<Path>) -> Result<Self, ImageError> {
        let path = path.as_ref();
        if !path.is_file() {
            return Err(ImageError::Io {
                path: path.to_path_buf(),
                source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
            });
        }
        // The header first: a small file may claim a data window of 100000x100000 (40 GB
        // of channels); nothing is decoded for a window larger than a film can be.
        let meta =
            exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e))?;
        for header in meta.headers.iter() {
            let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
            if w * h > MAX_PARTIAL_PIXELS {
                return Err(decode(
                    path,
                    format!(
                        "its data window claims {w}x{h} pixels, more than a render can have \
                         ({MAX_PARTIAL_PIXELS})"
                    ),
                ));
            }
        }
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(|e| exr_error(path, e))?;
        let layer = image.layer_data;
        let mut attrs: HashMap<String, String> = layer
            .attributes
            .other
            .iter()
            .filter_map(|(k, v)| match v {
                AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
                _ => None,
            })
            .collect();
        // The fields in one attribute (files before it had one attribute per field).
        if let Some(fields) = attrs.remove(FIELDS) {
            for line in fields.lines() {
                let (k, v) = line
                    .split_once('=')
                    .ok_or_else(|| decode(path, format!("bad {FIELDS} line {line:?}")))?;
                attrs.insert(k.to_string(), unescape(v));
            }
        }
        let get = |key: &str| {
            attrs
                .get(key)
                .ok_or_else(|| decode(path, format!("not a pt partial render (no {key})")))
        };
        if get("pt.format")? != FORMAT {
            return Err(decode(
                path,
                format!("unknown partial format {:?}", get("pt.format")?),
            ));
        }
        fn number<T: std::str::FromStr>(path: &Path, key: &str, v: &str) -> Result<T, ImageError> {
            v.parse()
                .map_err(|_| decode(path, format!("attribute {key} is not a number: {v:?}")))
        }
        let spp: u32 = number(path, "pt.spp", get("pt.spp")?)?;
        let seed: u64 = number(path, "pt.seed", get("pt.seed")?)?;
        let non_finite: u64 = number(path, "pt.non_finite", get("pt.non_finite")?)?;
        let clamped: u64 = number(path, "pt.clamped", get("pt.clamped")?)?;
        // Absent in files written before it existed.
        let saturated: u64 = match attrs.get("pt.saturated") {
            Some(v) => number(path, "pt.saturated", v)?,
            None => 0,
        };
        let ranges_text = get("pt.ranges")?;
        // Ranges inside one file are disjoint: overlapping ones would count samples twice.
        if let Some(mut parsed) = parse_ranges(ranges_text) {
            parsed.sort_by_key(|r| r.start);
            if parsed.windows(2).any(|w| w[1].start < w[0].end) {
                return Err(decode(
                    path,
                    format!("overlapping sample ranges {ranges_text:?}"),
                ));
            }
        }
        let ranges = parse_ranges(ranges_text)
            .map(normalise)
            .filter(|r| r.iter().all(|r| r.end <= spp))
            .ok_or_else(|| {
                decode(
                    path,
                    format!("bad sample ranges {ranges_text:?} for {spp} spp"),
                )
            })?;
        let label = get("pt.label")?.clone();
        // The examples' labels name the spp; one that disagrees with the attribute was
        // edited.
        let words: Vec<&str> = label.split_whitespace().collect();
        if let Some(w) = words.windows(2).find(|w| w[0] == "spp")
            && w[1] != spp.to_string()
        {
            return Err(decode(
                path,
                format!("pt.spp is {spp} but the label says spp {}", w[1]),
            ));
        }

        let size = layer.size;
        let (w, h) = (
            u32::try_from(size.0).map_err(|_| decode(path, "image too wide"))?,
            u32::try_from(size.1).map_err(|_| decode(path, "image too tall"))?,
        );
        let n = size.0 * size.1;
        let channel = |name: &str| -> Result<&[u32], ImageError> {
            let c = layer
                .channel_data
                .list
                .iter()
                .find(|c| c.name.to_string() == name)
                .ok_or_else(|| decode(path, format!("missing channel {name}")))?;
            match &c.sample_data {
                FlatSamples::U32(v) if v.len() == n => Ok(v),
                _ => Err(decode(
                    path,
                    format!("channel {name} is not {n} u32 samples"),
                )),
            }
        };
        let counts = channel("pt.count")?;
        let mut words = Vec::with_capacity(12);
        for name in COLOURS {
            for word in 0..4 {
                words.push(channel(&format!("pt.sum.{name}.{word}"))?);
            }
        }
        let held: u32 = ranges.iter().map(|r| r.end - r.start).sum();
        let mut pixels = Vec::with_capacity(n);
        for i in 0..n {
            if counts[i] != held {
                return Err(decode(
                    path,
                    format!(
                        "pixel {} holds {} samples but the ranges {ranges_text:?} give {held}",
                        i, counts[i]
                    ),
                ));
            }
            let mut sum = [0i128; 3];
            for (k, s) in sum.iter_mut().enumerate() {
                let mut v = 0u128;
                for word in 0..4 {
                    v |= u128::from(words[4 * k + word][i]) << (32 * word);
                }
                *s = v as i128;
            }

            pixels.push(PixelSum::from_raw(sum, counts[i]));
        }
        let mut film = Film::from_parts(w, h, pixels, non_finite, clamped);
        film.set_saturated(saturated);
        // Auxiliary sums: all of their channels or none.
        let has_aux = layer
            .channel_data
            .list
            .iter()
            .any(|c| c.name.to_string().starts_with("pt.aux."));
        if has_aux {
            let mut words = Vec::with_capacity(12);
            for name in AUX {
                for word in 0..2 {
                    words.push(channel(&format!("pt.aux.{name}.{word}"))?);
                }
            }
            let aux = (0..n)
                .map(|i| {
                    AuxSum::from_raw(std::array::from_fn(|k| {
                        (u64::from(words[2 * k][i]) | u64::from(words[2 * k + 1][i]) << 32) as i64
                    }))
                })
                .collect();
            film.set_aux(aux);
        }
        Ok(Self {
            film,
            spp,
            seed,
            ranges,
            label,
        })
    }
}

#[cfg(test)]
// A partial render's sample ranges are a list that often holds one range.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;
    use crate::color::Rgb;
    use glam::Vec3;

    #[test]
    fn files_round_trip_exactly_and_bad_files_are_named() {
        let dir = std::env::temp_dir().join(format!("pt-partial-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Five samples per pixel, with values that stress the fixed-point sums.
        let mut film = Film::new(3, 2);
        for (i, l) in [
            Rgb::new(f32::NAN, 0.0, 0.0),
            Rgb::new(-2.5, 1e-19, 3e7),
            Rgb::splat(100.0),
            Rgb::new(0.1, 0.2, 0.3),
            Rgb::new(f32::MIN_POSITIVE, 1e-30, 65504.0),
        ]
        .into_iter()
        .enumerate()
        {
            for y in 0..2 {
                for x in 0..3 {
                    film.add_sample_clamped(x, y, l * (1.0 + (x + 3 * y + i as u32) as f32), 1e6);
                }
            }
        }
        let p = PartialRender {
            film,
            spp: 8,
            seed: u64::MAX - 3,
            ranges: vec![0..2, 5..8],
            label: "cornell, label with spaces".into(),
        };
        let path = dir.join("p.exr");
        p.write_exr(&path).unwrap();
        let back = PartialRender::read_exr(&path).unwrap();
        assert_eq!(back, p, "the file holds the film exactly");

        // With auxiliary sums (negative normals, albedo at both ends of its range).
        let mut with_aux = Film::with_aux(2, 1);
        for i in 0..5 {
            let t = i as f32;
            with_aux.add_sample(0, 0, Rgb::splat(t));
            with_aux.add_aux(
                0,
                0,
                Rgb::new(1.0, 0.0, 0.3 * t),
                Vec3::new(-1.0, 0.1 * t, 1.0),
            );
            with_aux.add_sample(1, 0, Rgb::splat(t));
            with_aux.add_aux(1, 0, Rgb::splat(0.25), Vec3::ZERO);
        }
        let q = PartialRender {
            film: with_aux,
            spp: 5,
            seed: 2,
            ranges: vec![0..5],
            label: "aux".into(),
        };
        let aux_path = dir.join("aux.exr");
        q.write_exr(&aux_path).unwrap();
        assert_eq!(PartialRender::read_exr(&aux_path).unwrap(), q);
        assert_eq!(back.film.non_finite_samples(), 6);
        assert!(back.film.clamped_samples() > 0);

        // Counts that disagree with the ranges: the file is refused, and named.
        let bad = dir.join("bad.exr");
        let mut r = p.clone();
        r.ranges = vec![0..6];
        r.write_exr(&bad).unwrap();
        let err = PartialRender::read_exr(&bad).unwrap_err().to_string();
        assert!(err.contains("bad.exr") && err.contains("samples"), "{err}");

        // Overlapping ranges inside one file would count samples twice.
        let overlap = dir.join("overlap.exr");
        let mut r = p.clone();
        r.ranges = vec![0..2, 1..4];
        r.write_exr(&overlap).unwrap();
        let err = PartialRender::read_exr(&overlap).unwrap_err().to_string();
        assert!(
            err.contains("overlap.exr") && err.contains("overlapping"),
            "{err}"
        );

        // A label that names another spp than the attribute was edited.
        let edited = dir.join("edited.exr");
        let mut r = p.clone();
        r.label = "cornell_box 3x2 spp 16 max-depth 8".into();
        r.write_exr(&edited).unwrap();
        let err = PartialRender::read_exr(&edited).unwrap_err().to_string();
        assert!(
            err.contains("edited.exr") && err.contains("spp 16"),
            "{err}"
        );

        // Saturated samples survive the file.
        let mut film = Film::new(1, 1);
        film.add_sample(0, 0, Rgb::splat(1e30));
        let s = PartialRender {
            film,
            spp: 1,
            seed: 0,
            ranges: vec![0..1],
            label: "saturated".into(),
        };
        let sat = dir.join("sat.exr");
        s.write_exr(&sat).unwrap();
        assert_eq!(
            PartialRender::read_exr(&sat)
                .unwrap()
                .film
                .saturated_samples(),
            1
        );

        // A data window claiming 100000x100000 pixels (40 GB of channels) in a small file is
        // refused from the header, before anything is allocated.
        let bomb = dir.join("bomb.exr");
        let mut bytes = std::fs::read(&path).unwrap();
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len() + 4;
        bytes[at + 8..at + 12].copy_from_slice(&99_999i32.to_le_bytes());
        bytes[at + 12..at + 16].copy_from_slice(&99_999i32.to_le_bytes());
        std::fs::write(&bomb, bytes).unwrap();
        let err = PartialRender::read_exr(&bomb).unwrap_err().to_string();
        assert!(
            err.contains("bomb.exr") && err.contains("100000x100000"),
            "{err}"
        );

        // A plain image is not a partial render.
        let plain = dir.join("plain.exr");
        crate::image::Image::new(2, 2).write_exr(&plain).unwrap();
        let err = PartialRender::read_exr(&plain).unwrap_err().to_string();
        assert!(
            err.contains("plain.exr") && err.contains("not a pt partial"),
            "{err}"
        );
        let err = PartialRender::read_exr(dir.join("missing.exr"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing.exr"), "{err}");
        std::fs::write(dir.join("junk.exr"), b"not an exr").unwrap();
        let err = PartialRender::read_exr(dir.join("junk.exr"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("junk.exr"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_same_image_or_partial_render_gives_the_same_bytes() {
        let dir = std::env::temp_dir().join(format!("pt-exr-bytes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Tall enough for many chunks, so parallel compression could finish out of order.
        let mut img = Image::new(64, 512);
        for y in 0..512 {
            for x in 0..64 {
                img.set(
                    x,
                    y,
                    Rgb::new(x as f32 * 0.37, y as f32 / 7.0, (x ^ y) as f32),
                );
            }
        }
        let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
        for _ in 0..4 {
            img.write_exr(&a).unwrap();
            img.write_exr(&b).unwrap();
            assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        }
        // A partial render too (each hash map of attributes iterates in its own order), and
        // its label survives line breaks and backslashes.
        let mut film = crate::film::Film::new(64, 512);
        for y in 0..512 {
            for x in 0..64 {
                film.add_sample(x, y, Rgb::new(y as f32, x as f32, 2.0));
            }
        }
        let part = PartialRender {
            film,
            spp: 1,
            seed: 3,
            ranges: vec![0..1],
            label: "two\nlines \\ and\r more".into(),
        };
        for _ in 0..4 {
            part.write_exr(&a).unwrap();
            part.write_exr(&b).unwrap();
            assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
        }
        assert_eq!(PartialRender::read_exr(&a).unwrap(), part);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
