//! EXR input: the RGB beauty, AOV layers and [`Metadata`] of a file written by
//! [`crate::write_exr`] (or any scan-line/tiled, non-deep EXR with `R`, `G`, `B` channels).
//!
//! Plain RGB or RGBA files written by other tools (e.g. environment maps), in `f16`, `f32` or
//! `u32`, read the same way. All parts ("layers" in the `exr` crate) and channels are gathered
//! under their full names: in a multi-part file a channel of a named part is prefixed with
//! `<part name>.` unless its name already starts so; in a single-part file the part name (if
//! any) is only a label and channel names are used as they are. Channels without a `.` form the beauty: `R`, `G`,
//! `B` are required, `A` and other unprefixed channels are ignored. Channels named
//! `<layer>.<channel>` become a [`Layer`] named after the text before the last `.`; a layer's
//! channels are ordered `R, G, B, A, X, Y, Z`, then others alphabetically (EXR itself stores
//! channels sorted by name). Layers whose name this crate does not accept (e.g. containing `.`)
//! are skipped with a warning. `f16` and `u32` samples are converted to `f32`. Only the largest
//! mip/rip level is read. All parts must share one size.
//!
//! Decoding errors, and panics inside the `exr` crate on malformed input, become
//! [`Error::ExrRead`] naming the file; a missing or unreadable file is [`Error::Io`].

use std::collections::BTreeMap;
use std::path::Path;

use exr::image::{AnyChannels, FlatSamples, Image as ExrImage, Layers};
#[allow(clippy::wildcard_imports)] // the reader builder's extension traits
use exr::prelude::traits::*;

use crate::error::{Error, Result};
use crate::image::{Image, Layer};
use crate::metadata::{string, Metadata};

type AnyImage = ExrImage<Layers<AnyChannels<FlatSamples>>>;

/// Reads the beauty, AOV layers and metadata of the EXR at `path`.
pub fn read_exr(path: impl AsRef<Path>) -> Result<(Image, Metadata)> {
    let path = path.as_ref();
    let exr_image = decode(path)?;
    let content_error = |message: String| Error::ExrContent {
        path: path.to_owned(),
        message,
    };

    let Some(first) = exr_image.layer_data.first() else {
        return Err(content_error("the file has no layers".into()));
    };
    let (width, height) = (first.size.x(), first.size.y());
    let (Ok(w32), Ok(h32)) = (u32::try_from(width), u32::try_from(height)) else {
        return Err(content_error(format!("size {width}x{height} is too large")));
    };

    // Full channel name -> samples, across all parts.
    let mut channels: BTreeMap<String, Vec<f32>> = BTreeMap::new();
    for layer in &exr_image.layer_data {
        if layer.size != first.size {
            return Err(content_error(format!(
                "parts have different sizes ({width}x{height} and {}x{})",
                layer.size.x(),
                layer.size.y()
            )));
        }
        let prefix = match &layer.attributes.layer_name {
            Some(name) if exr_image.layer_data.len() > 1 && !name.as_slice().is_empty() => {
                Some(format!("{}.", string(name)))
            }
            _ => None,
        };
        for channel in &layer.channel_data.list {
            let name = string(&channel.name);
            let name = match &prefix {
                Some(prefix) if !name.starts_with(prefix.as_str()) => format!("{prefix}{name}"),
                _ => name,
            };
            let samples = to_f32(&channel.sample_data);
            if samples.len() != width * height {
                return Err(content_error(format!(
                    "channel '{name}' is subsampled, which is not supported"
                )));
            }
            if channels.contains_key(&name) {
                return Err(content_error(format!(
                    "channel '{name}' appears in more than one part"
                )));
            }
            channels.insert(name, samples);
        }
    }

    let rgb = interleave(&channels, &["R", "G", "B"]).ok_or_else(|| {
        let found: Vec<&str> = channels.keys().map(String::as_str).collect();
        content_error(format!("no R, G, B channels (found: {})", found.join(", ")))
    })?;
    let mut image = Image::from_rgb(w32, h32, rgb)?;
    for (name, channel_names) in group_layers(&channels) {
        let names: Vec<String> = channel_names
            .iter()
            .map(|c| format!("{name}.{c}"))
            .collect();
        let name_refs: Vec<&str> = names.iter().map(String::as_str).collect();
        let data = interleave(&channels, &name_refs).unwrap_or_default();
        match Layer::new(name.clone(), channel_names, data).and_then(|l| image.add_layer(l)) {
            Ok(()) => {}
            Err(e) => log::warn!("{}: skipping layer '{name}': {e}", path.display()),
        }
    }

    let attributes = exr_image
        .attributes
        .other
        .iter()
        .chain(first.attributes.other.iter());
    let metadata = Metadata::from_attributes(attributes, path)?;
    Ok((image, metadata))
}

/// Decodes every part and channel of the largest resolution level.
fn decode(path: &Path) -> Result<AnyImage> {
    let read = || {
        exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_file(path)
    };
    // The `exr` crate is meant to return errors on malformed files; this guard turns any
    // remaining panic into an error as well (`AssertUnwindSafe`: nothing is shared).
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(read)) {
        Ok(result) => result.map_err(|e| Error::exr_read(path, e)),
        Err(_) => Err(Error::ExrRead {
            path: path.to_owned(),
            source: exr::error::Error::Invalid("the decoder panicked on this file".into()),
        }),
    }
}

fn to_f32(samples: &FlatSamples) -> Vec<f32> {
    match samples {
        FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
        FlatSamples::F32(v) => v.clone(),
        // Ids and counts: precision loss above 2^24 is accepted.
        FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
    }
}

/// Interleaves the named channels pixel by pixel; `None` if any is missing.
fn interleave(channels: &BTreeMap<String, Vec<f32>>, names: &[&str]) -> Option<Vec<f32>> {
    let planes: Vec<&Vec<f32>> = names
        .iter()
        .map(|n| channels.get(*n))
        .collect::<Option<_>>()?;
    let pixels = planes.first().map_or(0, |p| p.len());
    let mut out = Vec::with_capacity(pixels * planes.len());
    for i in 0..pixels {
        out.extend(planes.iter().map(|p| p[i]));
    }
    Some(out)
}

/// Layer name -> channel names (canonical order) for every `<layer>.<channel>` channel.
fn group_layers(channels: &BTreeMap<String, Vec<f32>>) -> BTreeMap<String, Vec<String>> {
    let mut layers: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for full in channels.keys() {
        if let Some((layer, channel)) = full.rsplit_once('.') {
            layers
                .entry(layer.to_owned())
                .or_default()
                .push(channel.to_owned());
        }
    }
    for names in layers.values_mut() {
        names.sort_by(|a, b| channel_rank(a).cmp(&channel_rank(b)).then(a.cmp(b)));
    }
    layers
}

/// Canonical channel order: colour, alpha, then vector components, then anything else.
fn channel_rank(name: &str) -> usize {
    ["R", "G", "B", "A", "X", "Y", "Z"]
        .iter()
        .position(|c| *c == name)
        .unwrap_or(usize::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn canonical_channel_order() {
        let mut channels = BTreeMap::new();
        for name in [
            "albedo.B", "albedo.G", "albedo.R", "n.Z", "n.X", "n.Y", "m.b", "m.a",
        ] {
            channels.insert(name.to_owned(), vec![0.0]);
        }
        let layers = group_layers(&channels);
        assert_eq!(layers["albedo"], ["R", "G", "B"]);
        assert_eq!(layers["n"], ["X", "Y", "Z"]);
        assert_eq!(layers["m"], ["a", "b"]);
    }

    #[test]
    fn interleave_planes() {
        let mut channels = BTreeMap::new();
        channels.insert("a".to_owned(), vec![1.0, 2.0]);
        channels.insert("b".to_owned(), vec![3.0, 4.0]);
        assert_eq!(
            interleave(&channels, &["a", "b"]),
            Some(vec![1.0, 3.0, 2.0, 4.0])
        );
        assert_eq!(interleave(&channels, &["a", "c"]), None);
    }
}
