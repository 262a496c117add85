//! Bounds-checked accessor reading (dense and sparse), independent of the gltf crate's readers.
//!
//! Every offset and length is checked with overflow-safe arithmetic against the buffer view and
//! the loaded buffer before any byte is read, so that out-of-range accessors produce an
//! [`Error::Accessor`] naming the accessor, its user (mesh/primitive/attribute or animation) and
//! the buffer view, instead of a panic.

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};

use crate::error::{label, Error, Result};
use crate::resources::Source;

/// Accessors without a buffer view are zero-filled; refuse absurd sizes for them (in components,
/// each held as an f64 while reading: 2^24 components = 128 MiB).
const MAX_ZERO_FILL_COMPONENTS: usize = 1 << 24;

fn component_size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

fn read_component(t: DataType, b: &[u8]) -> f64 {
    match t {
        DataType::I8 => f64::from(b[0] as i8),
        DataType::U8 => f64::from(b[0]),
        DataType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
        DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
        DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
    }
}

fn normalize(t: DataType, v: f64) -> f64 {
    match t {
        DataType::I8 => (v / 127.0).max(-1.0),
        DataType::U8 => v / 255.0,
        DataType::I16 => (v / 32767.0).max(-1.0),
        DataType::U16 => v / 65535.0,
        DataType::U32 | DataType::F32 => v,
    }
}

struct Reader<'a> {
    src: &'a Source,
    element: String,
}

impl Reader<'_> {
    fn err(&self, reason: String) -> Error {
        Error::Accessor {
            path: self.src.path(),
            element: self.element.clone(),
            reason,
        }
    }

    /// Returns the bytes of a buffer view: decoded, where it is `EXT_meshopt_compression`
    /// compressed, or its buffer's after checking it lies inside.
    fn view_bytes(&self, view: &gltf::buffer::View<'_>) -> Result<&[u8]> {
        if let Some(decoded) = self
            .src
            .decoded_views
            .get(view.index())
            .and_then(Option::as_deref)
        {
            return Ok(decoded);
        }
        let data = self
            .src
            .buffers
            .get(view.buffer().index())
            .map(|d| d.0.as_slice())
            .unwrap_or(&[]);
        let end = view.offset().checked_add(view.length());
        match end {
            Some(end) if end <= data.len() => Ok(&data[view.offset()..end]),
            _ => Err(self.err(format!(
                "buffer view {} (offset {}, length {}) exceeds buffer {} ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                view.buffer().index(),
                data.len()
            ))),
        }
    }

    /// Checks that `count` elements of `elem` bytes at `offset` with `stride` fit in `len` bytes.
    fn check_range(
        &self,
        what: &str,
        offset: usize,
        stride: usize,
        elem: usize,
        count: usize,
        len: usize,
    ) -> Result<()> {
        if count == 0 {
            return Ok(());
        }
        let end = stride
            .checked_mul(count - 1)
            .and_then(|x| x.checked_add(offset))
            .and_then(|x| x.checked_add(elem));
        match end {
            Some(end) if end <= len => Ok(()),
            _ => Err(self.err(format!(
                "{what}: {count} elements of {elem} bytes (offset {offset}, stride {stride}) exceed the buffer view's {len} bytes"
            ))),
        }
    }

    /// Reads all components as f64 (not normalized), applying sparse substitution.
    fn raw(&self, acc: &gltf::Accessor<'_>) -> Result<(usize, Vec<f64>)> {
        let comps = match acc.dimensions() {
            Dimensions::Scalar => 1,
            Dimensions::Vec2 => 2,
            Dimensions::Vec3 => 3,
            Dimensions::Vec4 => 4,
            other => return Err(self.err(format!("unsupported accessor type {other:?}"))),
        };
        let t = acc.data_type();
        let csize = component_size(t);
        let elem = comps * csize;
        let count = acc.count();
        let mut out;
        if let Some(view) = acc.view() {
            let bytes = self.view_bytes(&view)?;
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(self.err(format!(
                    "byteStride {stride} is smaller than the element size {elem}"
                )));
            }
            self.check_range("accessor", acc.offset(), stride, elem, count, bytes.len())?;
            out = Vec::with_capacity(count * comps);
            for i in 0..count {
                let base = acc.offset() + i * stride;
                for c in 0..comps {
                    let at = base + c * csize;
                    out.push(read_component(t, &bytes[at..at + csize]));
                }
            }
        } else {
            if count
                .checked_mul(comps)
                .is_none_or(|n| n > MAX_ZERO_FILL_COMPONENTS)
            {
                return Err(self.err(format!(
                    "count {count} is too large for an accessor without bufferView"
                )));
            }
            out = vec![0.0; count * comps];
        }
        if let Some(sparse) = acc.sparse() {
            self.apply_sparse(&sparse, t, comps, count, &mut out)?;
        }
        Ok((comps, out))
    }

    fn apply_sparse(
        &self,
        sparse: &gltf::accessor::sparse::Sparse<'_>,
        t: DataType,
        comps: usize,
        count: usize,
        out: &mut [f64],
    ) -> Result<()> {
        use gltf::accessor::sparse::IndexType;
        let n = sparse.count();
        if n > count {
            return Err(self.err(format!("sparse count {n} exceeds accessor count {count}")));
        }
        let ind = sparse.indices();
        let isize = match ind.index_type() {
            IndexType::U8 => 1,
            IndexType::U16 => 2,
            IndexType::U32 => 4,
        };
        let itype = match ind.index_type() {
            IndexType::U8 => DataType::U8,
            IndexType::U16 => DataType::U16,
            IndexType::U32 => DataType::U32,
        };
        let ibytes = self.view_bytes(&ind.view())?;
        self.check_range(
            "sparse indices",
            ind.offset(),
            isize,
            isize,
            n,
            ibytes.len(),
        )?;
        let vals = sparse.values();
        let csize = component_size(t);
        let elem = comps * csize;
        let vbytes = self.view_bytes(&vals.view())?;
        self.check_range("sparse values", vals.offset(), elem, elem, n, vbytes.len())?;
        for k in 0..n {
            let at = ind.offset() + k * isize;
            let idx = read_component(itype, &ibytes[at..at + isize]) as usize;
            if idx >= count {
                return Err(self.err(format!("sparse index {idx} out of range (count {count})")));
            }
            for c in 0..comps {
                let at = vals.offset() + k * elem + c * csize;
                out[idx * comps + c] = read_component(t, &vbytes[at..at + csize]);
            }
        }
        Ok(())
    }
}

fn reader<'a>(src: &'a Source, acc: &gltf::Accessor<'_>, user: &str) -> Reader<'a> {
    let element = format!("{user} {}", label("accessor", acc.index(), acc.name()));
    Reader { src, element }
}

/// The label used in errors for `acc` when read by `user`.
pub(crate) fn element_label(acc: &gltf::Accessor<'_>, user: &str) -> String {
    format!("{user} {}", label("accessor", acc.index(), acc.name()))
}

/// Reads a float-valued accessor with `comps` components per element, normalizing integer
/// components where the accessor says `normalized` (glTF spec, "Animations"/"Meshes").
pub(crate) fn read_floats(
    src: &Source,
    acc: &gltf::Accessor<'_>,
    user: &str,
    comps: usize,
) -> Result<Vec<f32>> {
    let r = reader(src, acc, user);
    let (have, raw) = r.raw(acc)?;
    if have != comps {
        return Err(r.err(format!(
            "expected {comps} components per element, found {have}"
        )));
    }
    let t = acc.data_type();
    let norm = acc.normalized() || t == DataType::F32;
    if !norm && t == DataType::U32 {
        return Err(r.err("unsigned int components are not allowed for float data".into()));
    }
    Ok(raw
        .into_iter()
        .map(|v| {
            if norm {
                normalize(t, v) as f32
            } else {
                v as f32
            }
        })
        .collect())
}

/// Reads a VEC3 float accessor.
pub(crate) fn read_vec3(src: &Source, acc: &gltf::Accessor<'_>, user: &str) -> Result<Vec<Vec3>> {
    Ok(read_floats(src, acc, user, 3)?
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect())
}

/// Reads a VEC2 float accessor.
pub(crate) fn read_vec2(src: &Source, acc: &gltf::Accessor<'_>, user: &str) -> Result<Vec<Vec2>> {
    Ok(read_floats(src, acc, user, 2)?
        .chunks_exact(2)
        .map(Vec2::from_slice)
        .collect())
}

/// Reads a float accessor of any of 1..=4 components into `Vec4`s (unused lanes zero).
pub(crate) fn read_any_vec(
    src: &Source,
    acc: &gltf::Accessor<'_>,
    user: &str,
    comps: usize,
) -> Result<Vec<Vec4>> {
    let data = read_floats(src, acc, user, comps)?;
    Ok(data
        .chunks_exact(comps.max(1))
        .map(|c| {
            let mut v = [0.0f32; 4];
            v[..c.len()].copy_from_slice(c);
            Vec4::from_array(v)
        })
        .collect())
}

/// Reads a SCALAR index accessor of unsigned byte/short/int components.
pub(crate) fn read_indices(src: &Source, acc: &gltf::Accessor<'_>, user: &str) -> Result<Vec<u32>> {
    let r = reader(src, acc, user);
    if !matches!(
        acc.data_type(),
        DataType::U8 | DataType::U16 | DataType::U32
    ) {
        return Err(r.err(format!(
            "index component type {:?} is not an unsigned integer",
            acc.data_type()
        )));
    }
    let (comps, raw) = r.raw(acc)?;
    if comps != 1 {
        return Err(r.err("indices must be SCALAR".into()));
    }
    Ok(raw.into_iter().map(|v| v as u32).collect())
}
