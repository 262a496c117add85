//! `EXT_meshopt_compression` (gltfpack's `-c`, gltf-transform's `meshopt`): the three bitstreams
//! and the three filters of the extension's Appendices A and B, decoded without trusting the input.
//!
//! A compressed buffer view names its source bytes, its element count and stride, a mode and a
//! filter; [`decode`] returns the `count · stride` bytes the view holds, which the loader keeps per
//! view for the accessors to read (the view's fallback buffer has no data of its own and is never
//! loaded). A view declares at most [`max_decoded_len`] of its compressed bytes, so a file decodes
//! to at most 64 times its size. Every read is bounds
//! checked and every stream must be consumed exactly to its tail, so a damaged file is refused with
//! the reason instead of decoded into garbage; out-of-range indices it may still produce are caught
//! where the mesh is read, as for an uncompressed file.

/// How the bytes are coded (`mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Vertex attributes and any other element data: byte-wise deltas (header `0xa0`).
    Attributes,
    /// A triangle list's indices: edge and vertex FIFOs (header `0xe1`).
    Triangles,
    /// Any other index sequence: deltas against two baselines (header `0xd1`).
    Indices,
}

/// What is applied to each element after [`Mode::Attributes`] decoding (`filter`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Filter {
    None,
    /// Unit vectors in octahedral coordinates, four 8- or 16-bit components.
    Octahedral,
    /// Unit quaternions without their largest component, four 16-bit components.
    Quaternion,
    /// 32-bit floats as an 8-bit exponent and a 24-bit mantissa.
    Exponential,
}

impl Mode {
    pub(crate) fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "ATTRIBUTES" => Self::Attributes,
            "TRIANGLES" => Self::Triangles,
            "INDICES" => Self::Indices,
            _ => return None,
        })
    }
}

impl Filter {
    pub(crate) fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "NONE" => Self::None,
            "OCTAHEDRAL" => Self::Octahedral,
            "QUATERNION" => Self::Quaternion,
            "EXPONENTIAL" => Self::Exponential,
            _ => return None,
        })
    }
}

/// The largest ratio of decoded to compressed bytes any stream can reach, with `slack` bytes for
/// small streams: 64 for attributes (a group of 16 unchanged bytes costs 2 header bits), 12 for
/// triangles (at least one code byte per three 32-bit indices), 4 for indices (a byte per index).
/// A view declaring more than that is refused before anything is allocated.
pub(crate) fn max_decoded_len(mode: Mode, compressed: usize) -> usize {
    let ratio = match mode {
        Mode::Attributes => 64,
        Mode::Triangles => 12,
        Mode::Indices => 4,
    };
    compressed.saturating_mul(ratio).saturating_add(4096)
}

/// Checks the extension's rules on `count`, `stride`, `mode` and `filter` (its "must hold" list).
pub(crate) fn check_layout(
    mode: Mode,
    filter: Filter,
    count: usize,
    stride: usize,
) -> Result<(), String> {
    match mode {
        Mode::Attributes if stride == 0 || !stride.is_multiple_of(4) || stride > 256 => {
            return Err(format!(
                "byteStride {stride} of an ATTRIBUTES view must be a multiple of 4 up to 256"
            ))
        }
        Mode::Triangles | Mode::Indices if stride != 2 && stride != 4 => {
            return Err(format!(
                "byteStride {stride} of an index view must be 2 or 4"
            ))
        }
        Mode::Triangles if !count.is_multiple_of(3) => {
            return Err(format!(
                "count {count} of a TRIANGLES view is not a multiple of 3"
            ))
        }
        Mode::Triangles | Mode::Indices if filter != Filter::None => {
            return Err(format!(
                "filter {filter:?} applies to ATTRIBUTES views only"
            ))
        }
        _ => {}
    }
    let fits = match filter {
        Filter::None => true,
        Filter::Octahedral => stride == 4 || stride == 8,
        Filter::Quaternion => stride == 8,
        Filter::Exponential => stride.is_multiple_of(4),
    };
    if !fits {
        return Err(format!(
            "filter {filter:?} does not take byteStride {stride}"
        ));
    }
    Ok(())
}

/// The `count · stride` bytes coded in `data` (the layout checked by [`check_layout`]).
pub(crate) fn decode(
    mode: Mode,
    filter: Filter,
    count: usize,
    stride: usize,
    data: &[u8],
) -> Result<Vec<u8>, String> {
    check_layout(mode, filter, count, stride)?;
    let mut out = match mode {
        Mode::Attributes => decode_attributes(data, count, stride)?,
        Mode::Triangles => write_indices(&decode_triangles(data, count)?, stride),
        Mode::Indices => write_indices(&decode_index_sequence(data, count)?, stride),
    };
    match filter {
        Filter::None => {}
        Filter::Octahedral => octahedral(&mut out, stride),
        Filter::Quaternion => quaternion(&mut out),
        Filter::Exponential => exponential(&mut out),
    }
    Ok(out)
}

/// Reads bytes front to back, up to an end that excludes the stream's tail.
struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
    end: usize,
}

impl<'a> Reader<'a> {
    fn byte(&mut self) -> Result<u8, String> {
        let b = *self
            .data
            .get(self.pos)
            .filter(|_| self.pos < self.end)
            .ok_or("the stream ends early")?;
        self.pos += 1;
        Ok(b)
    }

    fn bytes(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.end);
        let end = end.ok_or("the stream ends early")?;
        let s = &self.data[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    /// An unsigned LEB128 value of at most 32 bits.
    fn varint(&mut self) -> Result<u32, String> {
        let mut v = 0u32;
        for shift in (0..35).step_by(7) {
            let b = self.byte()?;
            v |= u32::from(b & 0x7f) << shift;
            if b & 0x80 == 0 {
                return Ok(v);
            }
        }
        Err("a varint is longer than 5 bytes".into())
    }

    /// Fails unless everything before the tail was read.
    fn finish(&self) -> Result<(), String> {
        if self.pos == self.end {
            Ok(())
        } else {
            Err(format!(
                "{} bytes are left between the coded data and the tail",
                self.end - self.pos
            ))
        }
    }
}

/// The header byte, checked.
fn header(data: &[u8], expected: u8) -> Result<(), String> {
    match data.first() {
        Some(&b) if b == expected => Ok(()),
        Some(&b) => Err(format!(
            "header byte is {b:#04x}, not {expected:#04x} (another codec or version)"
        )),
        None => Err("the stream is empty".into()),
    }
}

fn unzigzag8(v: u8) -> u8 {
    if v & 1 != 0 {
        !(v >> 1)
    } else {
        v >> 1
    }
}

fn unzigzag32(v: u32) -> u32 {
    if v & 1 != 0 {
        !(v >> 1)
    } else {
        v >> 1
    }
}

/// Mode 0: attribute blocks of up to 256 elements, each stored as `stride` byte columns in groups of
/// 16 (2 header bits a group: zero, 2-bit or 4-bit deltas with a sentinel, or whole bytes), the
/// deltas zigzag coded against the previous element; the first element's baseline is the last
/// `stride` bytes of the 32-byte (or `stride`-byte) tail.
fn decode_attributes(data: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    header(data, 0xa0)?;
    let tail = stride.max(32);
    if data.len() < 1 + tail {
        return Err(format!(
            "{} bytes cannot hold the header and the {tail}-byte tail",
            data.len()
        ));
    }
    let mut last = data[data.len() - stride..].to_vec();
    let mut r = Reader {
        data,
        pos: 1,
        end: data.len() - tail,
    };
    let mut out = vec![0u8; count * stride];
    let block_max = ((8192 / stride) & !15).min(256);
    let mut deltas = [0u8; 16];
    for block in (0..count).step_by(block_max) {
        let elements = (count - block).min(block_max);
        let groups = elements.div_ceil(16);
        for (k, last) in last.iter_mut().enumerate() {
            let modes = r.bytes(groups.div_ceil(4))?;
            for g in 0..groups {
                let bits = (modes[g / 4] >> ((g % 4) * 2)) & 3;
                read_group(&mut r, bits, &mut deltas)?;
                let n = (elements - g * 16).min(16);
                for (i, &d) in deltas[..n].iter().enumerate() {
                    *last = last.wrapping_add(unzigzag8(d));
                    out[(block + g * 16 + i) * stride + k] = *last;
                }
            }
        }
    }
    r.finish()?;
    Ok(out)
}

/// The 16 zigzag-coded deltas of one group, coded as `bits` says.
fn read_group(r: &mut Reader<'_>, bits: u8, deltas: &mut [u8; 16]) -> Result<(), String> {
    match bits {
        0 => deltas.fill(0),
        3 => deltas.copy_from_slice(r.bytes(16)?),
        _ => {
            // 2 bits (4 per byte) or 4 bits (2 per byte), first delta in the high bits; the
            // all-ones value says the delta follows as a byte after the packed ones.
            let width = if bits == 1 { 2 } else { 4 };
            let sentinel = (1u8 << width) - 1;
            let packed = r.bytes(16 * width / 8)?;
            let per_byte = 8 / width;
            for (i, d) in deltas.iter_mut().enumerate() {
                let shift = 8 - width * (i % per_byte + 1);
                let v = (packed[i / per_byte] >> shift) & sentinel;
                *d = if v == sentinel { r.byte()? } else { v };
            }
        }
    }
    Ok(())
}

/// A 16-entry FIFO; index 0 is the most recent push.
struct Fifo<T: Copy + Default> {
    items: [T; 16],
    pushed: usize,
}

impl<T: Copy + Default> Fifo<T> {
    fn new() -> Self {
        Self {
            items: [T::default(); 16],
            pushed: 0,
        }
    }

    fn push(&mut self, v: T) {
        self.items[self.pushed & 15] = v;
        self.pushed = self.pushed.wrapping_add(1);
    }

    fn get(&self, i: usize) -> T {
        self.items[self.pushed.wrapping_sub(1 + i) & 15]
    }
}

/// Mode 1: one code byte per triangle (an edge from the edge FIFO and a new, recent, adjacent or
/// explicit third vertex, or three vertices through the 16-byte `codeaux` table), explicit indices
/// as LEB128 zigzag deltas from the last one.
fn decode_triangles(data: &[u8], count: usize) -> Result<Vec<u32>, String> {
    header(data, 0xe1)?;
    let triangles = count / 3;
    if data.len() < 1 + triangles + 16 {
        return Err(format!(
            "{} bytes cannot hold {triangles} triangle codes and the 16-byte table",
            data.len()
        ));
    }
    let codeaux = &data[data.len() - 16..];
    let codes = &data[1..1 + triangles];
    let mut r = Reader {
        data,
        pos: 1 + triangles,
        end: data.len() - 16,
    };
    let mut edges: Fifo<(u32, u32)> = Fifo::new();
    let mut vertices: Fifo<u32> = Fifo::new();
    let (mut next, mut last) = (0u32, 0u32);
    let mut out = Vec::with_capacity(count);
    let explicit = |r: &mut Reader<'_>, last: &mut u32| -> Result<u32, String> {
        *last = last.wrapping_add(unzigzag32(r.varint()?));
        Ok(*last)
    };
    for &code in codes {
        let (hi, lo) = ((code >> 4) as usize, (code & 15) as usize);
        let (a, b, c);
        if hi < 15 {
            // An edge seen recently and a third vertex.
            (a, b) = edges.get(hi);
            c = match lo {
                0 => {
                    next = next.wrapping_add(1);
                    next.wrapping_sub(1)
                }
                1..=12 => vertices.get(lo),
                13 | 14 => {
                    last = if lo == 13 {
                        last.wrapping_sub(1)
                    } else {
                        last.wrapping_add(1)
                    };
                    last
                }
                _ => explicit(&mut r, &mut last)?,
            };
            if !(1..=12).contains(&lo) {
                vertices.push(c);
            }
            edges.push((c, b));
            edges.push((a, c));
        } else {
            // Three vertices: new ones, recent ones through `codeaux`, or (0xfe / 0xff) explicit.
            let zw = if lo < 14 { codeaux[lo] } else { r.byte()? };
            if lo >= 14 && zw == 0 {
                next = 0;
            }
            let mut fresh = || {
                next = next.wrapping_add(1);
                next.wrapping_sub(1)
            };
            a = if lo == 15 {
                explicit(&mut r, &mut last)?
            } else {
                fresh()
            };
            let (z, w) = ((zw >> 4) as usize, (zw & 15) as usize);
            let mut third = |f: usize, r: &mut Reader<'_>| -> Result<u32, String> {
                Ok(match f {
                    0 => fresh(),
                    15 if lo >= 14 => explicit(r, &mut last)?,
                    _ => vertices.get(f - 1),
                })
            };
            b = third(z, &mut r)?;
            c = third(w, &mut r)?;
            vertices.push(a);
            let pushed = |f: usize| f == 0 || (f == 15 && lo >= 14);
            if pushed(z) {
                vertices.push(b);
            }
            if pushed(w) {
                vertices.push(c);
            }
            edges.push((b, a));
            edges.push((c, b));
            edges.push((a, c));
        }
        out.extend([a, b, c]);
    }
    r.finish()?;
    Ok(out)
}

/// Mode 2: each index a LEB128 value whose low bit picks one of two baselines and whose other bits
/// are a zigzag delta from it.
fn decode_index_sequence(data: &[u8], count: usize) -> Result<Vec<u32>, String> {
    header(data, 0xd1)?;
    if data.len() < 1 + 4 {
        return Err(format!("{} bytes cannot hold the 4-byte tail", data.len()));
    }
    let mut r = Reader {
        data,
        pos: 1,
        end: data.len() - 4,
    };
    let mut last = [0u32; 2];
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        let v = r.varint()?;
        let base = (v & 1) as usize;
        let delta = if v & 2 != 0 { !(v >> 2) } else { v >> 2 };
        last[base] = last[base].wrapping_add(delta);
        out.push(last[base]);
    }
    r.finish()?;
    Ok(out)
}

/// Indices as little-endian `u16` or `u32`.
fn write_indices(indices: &[u32], stride: usize) -> Vec<u8> {
    if stride == 2 {
        indices
            .iter()
            .flat_map(|&i| (i as u16).to_le_bytes())
            .collect()
    } else {
        indices.iter().flat_map(|&i| i.to_le_bytes()).collect()
    }
}

/// Signed components of `stride / 4` bytes each.
fn read_signed(bytes: &[u8]) -> f32 {
    match bytes.len() {
        1 => f32::from(bytes[0] as i8),
        _ => f32::from(i16::from_le_bytes([bytes[0], bytes[1]])),
    }
}

fn write_signed(bytes: &mut [u8], v: f32) {
    match bytes.len() {
        1 => bytes[0] = (v as i8) as u8,
        _ => bytes.copy_from_slice(&(v as i16).to_le_bytes()),
    }
}

/// Filter 1: x, y in octahedral coordinates over a K-bit 1.0 (the third component) to a unit
/// vector as normalized integers of the same width; the fourth component is kept.
fn octahedral(out: &mut [u8], stride: usize) {
    let c = stride / 4;
    let max = if c == 1 { 127.0 } else { 32767.0 };
    for e in out.chunks_exact_mut(stride) {
        let one = read_signed(&e[2 * c..3 * c]);
        let mut x = read_signed(&e[..c]) / one;
        let mut y = read_signed(&e[c..2 * c]) / one;
        let z = 1.0 - x.abs() - y.abs();
        let t = z.min(0.0);
        x -= t.copysign(x);
        y -= t.copysign(y);
        let len = (x * x + y * y + z * z).sqrt();
        for (i, v) in [x, y, z].into_iter().enumerate() {
            let q = if len > 0.0 {
                (v / len * max).round()
            } else {
                0.0
            };
            write_signed(&mut e[i * c..(i + 1) * c], q);
        }
    }
}

/// Filter 2: three 16-bit components scaled by √2 over a K-bit 1.0 (the fourth, whose low two
/// bits name the omitted largest component) to a unit quaternion as normalized `i16`.
fn quaternion(out: &mut [u8]) {
    let range = std::f32::consts::FRAC_1_SQRT_2;
    for e in out.chunks_exact_mut(8) {
        let input: [i16; 4] = std::array::from_fn(|i| i16::from_le_bytes([e[2 * i], e[2 * i + 1]]));
        let one = f32::from(input[3] | 3);
        let [x, y, z] = [0, 1, 2].map(|i| f32::from(input[i]) / one * range);
        let w = (1.0 - x * x - y * y - z * z).max(0.0).sqrt();
        let max = (input[3] & 3) as usize;
        for (k, v) in [w, x, y, z].into_iter().enumerate() {
            let slot = (max + k) % 4;
            let q = (v * 32767.0).round() as i16;
            e[2 * slot..2 * slot + 2].copy_from_slice(&q.to_le_bytes());
        }
    }
}

/// Filter 3: each 32-bit word as `2^e · m`, `e` its signed top 8 bits and `m` its signed low 24.
fn exponential(out: &mut [u8]) {
    for w in out.chunks_exact_mut(4) {
        let v = i32::from_le_bytes([w[0], w[1], w[2], w[3]]);
        let (e, m) = (v >> 24, (v << 8) >> 8);
        let f = (f64::from(m) * 2f64.powi(e)) as f32;
        w.copy_from_slice(&f.to_le_bytes());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The worked example of Appendix A: one group of 4-bit deltas with two sentinels.
    #[test]
    fn a_group_of_4_bit_deltas_decodes_as_the_specification_says() {
        let bytes = [0x17, 0x5f, 0xf0, 0xbc, 0x77, 0xa9, 0x21, 0x00, 0x34, 0xb5];
        let mut r = Reader {
            data: &bytes,
            pos: 0,
            end: bytes.len(),
        };
        let mut deltas = [0u8; 16];
        read_group(&mut r, 2, &mut deltas).unwrap();
        r.finish().unwrap();
        let signed: Vec<i8> = deltas.iter().map(|&d| unzigzag8(d) as i8).collect();
        assert_eq!(
            signed,
            [-1, -4, -3, 26, -91, 0, -6, 6, -4, -4, 5, -5, 1, -1, 0, 0]
        );
    }

    /// Unsigned LEB128, low groups first: the specification's first two examples. (Its third,
    /// `0xff 0xa0 0x05 => 0x1fd005`, reads the groups high first, which contradicts the other two
    /// and LEB128; meshoptimizer's decoder reads it as 0x1507f, as here.)
    #[test]
    fn varints_read_as_unsigned_leb128() {
        for (bytes, v) in [
            (&[0x7f][..], 0x7f),
            (&[0x81, 0x04][..], 0x201),
            (&[0xff, 0xa0, 0x05][..], 0x1507f),
            (&[0x80, 0x80, 0x80, 0x80, 0x0f][..], 0xf000_0000),
        ] {
            let mut r = Reader {
                data: bytes,
                pos: 0,
                end: bytes.len(),
            };
            assert_eq!(r.varint().unwrap(), v);
            r.finish().unwrap();
        }
    }

    #[test]
    fn the_filters_decode_unit_vectors_quaternions_and_floats() {
        // Octahedral, 8-bit, K = 8: (0, 0) over one is +Z; (127, 0) is +X.
        let mut v = vec![0, 0, 127, 9, 127, 0, 127, 0];
        octahedral(&mut v, 4);
        assert_eq!(v, [0, 0, 127, 9, 127, 0, 0, 0]);
        // The lower hemisphere: x + y past one folds to negative z.
        let mut v = vec![127, 127, 127, 0];
        octahedral(&mut v, 4);
        let z = v[2] as i8;
        assert!(z <= -126, "{v:?}");
        // Quaternion: the identity stores three zeros and the largest component's index (3 = w
        // is the component after z in the cyclic order from index 3: slots (3+1)%4 = 0 ..).
        let one = (1i16 << 11) - 1; // K = 12
        let mut q: Vec<u8> = [0i16, 0, 0, (one & !3) | 3]
            .iter()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        quaternion(&mut q);
        let out: Vec<i16> = q
            .chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]))
            .collect();
        assert_eq!(out, [0, 0, 0, 32767]);
        // Exponential: 3 · 2^-1 and -5 · 2^2.
        let words = [(-1i32 << 24) | 3, (2 << 24) | (-5i32 & 0x00ff_ffff)];
        let mut f: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        exponential(&mut f);
        let out: Vec<f32> = f
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        assert_eq!(out, [1.5, -20.0]);
    }

    #[test]
    fn damaged_streams_are_refused_with_the_reason() {
        let e = decode(Mode::Attributes, Filter::None, 4, 4, &[0xa1; 40]).unwrap_err();
        assert!(e.contains("0xa1"), "{e}");
        // One group of raw bytes needs 16 bytes per column; give the header and the tail only.
        let mut short = vec![0xa0, 0b11];
        short.extend([0u8; 32]);
        let e = decode(Mode::Attributes, Filter::None, 4, 4, &short).unwrap_err();
        assert!(e.contains("ends early"), "{e}");
        let e = decode(Mode::Triangles, Filter::None, 4, 2, &[0xe1; 40]).unwrap_err();
        assert!(e.contains("multiple of 3"), "{e}");
        let e = decode(Mode::Indices, Filter::None, 2, 4, &[0xd1, 0x02, 0, 0, 0, 0]).unwrap_err();
        assert!(e.contains("ends early"), "{e}");
    }

    #[test]
    fn an_index_sequence_follows_its_two_baselines() {
        // +5 on baseline 0, +7 on baseline 1, -1 on baseline 0: 5, 7, 4.
        let zig = |d: i32, base: u32| (((d << 1) ^ (d >> 31)) as u32) << 1 | base;
        let mut data = vec![0xd1];
        for v in [zig(5, 0), zig(7, 1), zig(-1, 0)] {
            assert!(v < 0x80);
            data.push(v as u8);
        }
        data.extend([0; 4]);
        let out = decode(Mode::Indices, Filter::None, 3, 4, &data).unwrap();
        assert_eq!(out, [5, 0, 0, 0, 7, 0, 0, 0, 4, 0, 0, 0]);
    }
}
