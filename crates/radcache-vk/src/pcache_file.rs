//! The on-disk pipeline cache file: radcache's header, the index of pipeline keys and the driver's
//! `vkGetPipelineCacheData` blob.
//!
//! Layout (little-endian):
//!
//! | bytes | field |
//! |-------|-------|
//! | 8     | magic `RCPIPEC\0` |
//! | 4     | format version ([`FORMAT_VERSION`]) |
//! | 4 × 3 | vendor id, device id, driver version |
//! | 16    | `pipelineCacheUUID` |
//! | 4     | number of keys |
//! | 8     | bytes of driver data |
//! | 8     | FNV-1a checksum of everything after the header |
//! | 8 × n | pipeline keys (sorted) |
//! | …     | driver data, itself starting with Vulkan's `VkPipelineCacheHeaderVersionOne` |
//!
//! [`decode`] refuses anything that is not exactly such a file for this device and driver —
//! truncated, garbage, another device's, a bad checksum, or driver data whose Vulkan header names
//! another device — so that the driver only ever sees data it wrote itself.

use std::fmt;
use std::path::Path;

/// The first bytes of a radcache pipeline cache file.
pub(crate) const MAGIC: [u8; 8] = *b"RCPIPEC\0";
/// Bumped whenever the layout above changes.
pub(crate) const FORMAT_VERSION: u32 = 1;
/// Bytes of radcache's header.
pub(crate) const HEADER_LEN: usize = 8 + 4 + 12 + 16 + 4 + 8 + 8;
/// Bytes of `VkPipelineCacheHeaderVersionOne`.
pub(crate) const VK_HEADER_LEN: usize = 32;

/// FNV-1a offset basis (64 bit).
pub(crate) const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// Folds `bytes` into the FNV-1a hash `h` (start from [`FNV_OFFSET`]). A stable hash: the same
/// bytes give the same value on every machine and toolchain, as a file on disk needs.
pub(crate) fn fnv1a(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(FNV_PRIME);
    }
    h
}

/// Which device and driver a cache file belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Identity {
    pub vendor_id: u32,
    pub device_id: u32,
    pub driver_version: u32,
    pub uuid: [u8; 16],
}

impl Identity {
    /// The file name of this device's cache (the driver version is checked inside).
    pub(crate) fn file_name(&self) -> String {
        let uuid: String = self.uuid.iter().map(|b| format!("{b:02x}")).collect();
        format!(
            "pipelines-{:04x}-{:04x}-{uuid}.bin",
            self.vendor_id, self.device_id
        )
    }
}

/// What a cache file holds.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Contents {
    /// Keys of the pipelines created through this cache (see `pcache::PipelineKey`).
    pub keys: Vec<u64>,
    /// The driver's cache data.
    pub data: Vec<u8>,
}

/// Why a file was not used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Rejection {
    /// Shorter than its header says.
    Truncated { len: usize, expected: usize },
    /// Not a radcache pipeline cache (wrong magic).
    NotACacheFile,
    /// Written by another version of radcache's format.
    Version(u32),
    /// Written for another device or driver.
    Foreign { found: Identity },
    /// The checksum does not match the contents.
    Checksum,
    /// The driver data's Vulkan header is malformed or names another device.
    VulkanHeader(&'static str),
}

impl fmt::Display for Rejection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rejection::Truncated { len, expected } => {
                write!(f, "truncated ({len} bytes, expected {expected})")
            }
            Rejection::NotACacheFile => write!(f, "not a radcache pipeline cache"),
            Rejection::Version(v) => {
                write!(f, "format version {v} (this build reads {FORMAT_VERSION})")
            }
            Rejection::Foreign { found } => write!(
                f,
                "written for another device or driver (vendor {:#06x}, device {:#06x}, driver \
                 version {:#x})",
                found.vendor_id, found.device_id, found.driver_version
            ),
            Rejection::Checksum => write!(f, "checksum mismatch (corrupt)"),
            Rejection::VulkanHeader(what) => write!(f, "driver data: {what}"),
        }
    }
}

/// The file's bytes.
pub(crate) fn encode(id: &Identity, contents: &Contents) -> Vec<u8> {
    let mut body = Vec::with_capacity(contents.keys.len() * 8 + contents.data.len());
    for k in &contents.keys {
        body.extend_from_slice(&k.to_le_bytes());
    }
    body.extend_from_slice(&contents.data);
    let mut out = Vec::with_capacity(HEADER_LEN + body.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&id.vendor_id.to_le_bytes());
    out.extend_from_slice(&id.device_id.to_le_bytes());
    out.extend_from_slice(&id.driver_version.to_le_bytes());
    out.extend_from_slice(&id.uuid);
    out.extend_from_slice(&(contents.keys.len() as u32).to_le_bytes());
    out.extend_from_slice(&(contents.data.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv1a(FNV_OFFSET, &body).to_le_bytes());
    out.extend_from_slice(&body);
    out
}

/// Little-endian reads from a slice already checked to be long enough.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0; N];
        out.copy_from_slice(&self.bytes[self.at..self.at + N]);
        self.at += N;
        out
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
}

/// The contents of a file written by [`encode`] for `id`, or why it cannot be used.
pub(crate) fn decode(id: &Identity, bytes: &[u8]) -> Result<Contents, Rejection> {
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(Rejection::NotACacheFile);
    }
    if bytes.len() < HEADER_LEN {
        return Err(Rejection::Truncated {
            len: bytes.len(),
            expected: HEADER_LEN,
        });
    }
    let mut r = Reader { bytes, at: 8 };
    let version = r.u32();
    if version != FORMAT_VERSION {
        return Err(Rejection::Version(version));
    }
    let found = Identity {
        vendor_id: r.u32(),
        device_id: r.u32(),
        driver_version: r.u32(),
        uuid: r.take(),
    };
    if found != *id {
        return Err(Rejection::Foreign { found });
    }
    let n_keys = r.u32() as usize;
    let data_len = r.u64();
    let checksum = r.u64();
    let expected = (n_keys as u64)
        .checked_mul(8)
        .and_then(|k| k.checked_add(data_len))
        .and_then(|b| b.checked_add(HEADER_LEN as u64))
        .filter(|&e| e <= usize::MAX as u64)
        .map_or(usize::MAX, |e| e as usize);
    if bytes.len() != expected {
        return Err(Rejection::Truncated {
            len: bytes.len(),
            expected,
        });
    }
    let body = &bytes[HEADER_LEN..];
    if fnv1a(FNV_OFFSET, body) != checksum {
        return Err(Rejection::Checksum);
    }
    let keys = body[..n_keys * 8]
        .chunks_exact(8)
        .map(|c| u64::from_le_bytes(c.try_into().expect("8-byte chunk")))
        .collect();
    let data = body[n_keys * 8..].to_vec();
    check_vulkan_header(id, &data)?;
    Ok(Contents { keys, data })
}

/// Checks the `VkPipelineCacheHeaderVersionOne` at the start of the driver's data (empty data
/// is accepted: a cache with nothing in it).
pub(crate) fn check_vulkan_header(id: &Identity, data: &[u8]) -> Result<(), Rejection> {
    if data.is_empty() {
        return Ok(());
    }
    if data.len() < VK_HEADER_LEN {
        return Err(Rejection::VulkanHeader(
            "shorter than a Vulkan cache header",
        ));
    }
    let mut r = Reader { bytes: data, at: 0 };
    let header_len = r.u32() as usize;
    let header_version = r.u32();
    let vendor = r.u32();
    let device = r.u32();
    let uuid: [u8; 16] = r.take();
    if header_len < VK_HEADER_LEN || header_len > data.len() {
        return Err(Rejection::VulkanHeader("bad header size"));
    }
    if header_version != 1 {
        return Err(Rejection::VulkanHeader("unknown header version"));
    }
    if vendor != id.vendor_id || device != id.device_id || uuid != id.uuid {
        return Err(Rejection::VulkanHeader("written by another device"));
    }
    Ok(())
}

/// Writes `bytes` to a hidden temporary file beside `path` (a `tempfile`, private to the user),
/// fsynced, then renamed over `path`: another radcache process reading the file sees the old one
/// or the new one, never a part; concurrent writers each rename a whole file (the last one wins).
pub(crate) fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(path.file_name().unwrap_or_default());
    prefix.push(".");
    let mut temp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(".tmp")
        .tempfile_in(dir)?;
    temp.write_all(bytes)?;
    temp.as_file().sync_all()?;
    temp.persist(path).map(drop).map_err(|e| e.error)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn id() -> Identity {
        Identity {
            vendor_id: 0x10005,
            device_id: 0,
            driver_version: 0x6400007,
            uuid: *b"0123456789abcdef",
        }
    }

    /// Driver data with a valid Vulkan header for `id` and some payload.
    fn driver_data(id: &Identity) -> Vec<u8> {
        let mut d = Vec::new();
        d.extend_from_slice(&32u32.to_le_bytes());
        d.extend_from_slice(&1u32.to_le_bytes());
        d.extend_from_slice(&id.vendor_id.to_le_bytes());
        d.extend_from_slice(&id.device_id.to_le_bytes());
        d.extend_from_slice(&id.uuid);
        d.extend_from_slice(b"compiled pipelines");
        d
    }

    fn file() -> Vec<u8> {
        let contents = Contents {
            keys: vec![3, 1 << 40, u64::MAX],
            data: driver_data(&id()),
        };
        encode(&id(), &contents)
    }

    #[test]
    fn round_trip() {
        let contents = decode(&id(), &file()).unwrap();
        assert_eq!(contents.keys, vec![3, 1 << 40, u64::MAX]);
        assert_eq!(contents.data, driver_data(&id()));
        let empty = encode(&id(), &Contents::default());
        assert_eq!(decode(&id(), &empty).unwrap(), Contents::default());
    }

    #[test]
    fn every_truncation_is_refused() {
        let bytes = file();
        for len in 0..bytes.len() {
            let err = decode(&id(), &bytes[..len]).unwrap_err();
            let expected = if len < MAGIC.len() {
                Rejection::NotACacheFile
            } else {
                Rejection::Truncated {
                    len,
                    expected: if len < HEADER_LEN {
                        HEADER_LEN
                    } else {
                        bytes.len()
                    },
                }
            };
            assert_eq!(err, expected, "length {len}");
        }
    }

    #[test]
    fn garbage_and_trailing_bytes_are_refused() {
        assert_eq!(
            decode(&id(), b"\x89PNG\r\n\x1a\n not a cache at all"),
            Err(Rejection::NotACacheFile)
        );
        let mut longer = file();
        longer.push(0);
        assert!(matches!(
            decode(&id(), &longer),
            Err(Rejection::Truncated { .. })
        ));
    }

    #[test]
    fn a_flipped_byte_in_the_body_fails_the_checksum() {
        let clean = file();
        for at in HEADER_LEN..clean.len() {
            let mut bytes = clean.clone();
            bytes[at] ^= 0x40;
            assert_eq!(decode(&id(), &bytes), Err(Rejection::Checksum), "byte {at}");
        }
    }

    #[test]
    fn another_device_or_driver_is_foreign() {
        let bytes = file();
        let mut other = id();
        other.uuid[15] ^= 1;
        assert!(matches!(
            decode(&other, &bytes),
            Err(Rejection::Foreign { .. })
        ));
        let mut newer = id();
        newer.driver_version += 1;
        let err = decode(&newer, &bytes).unwrap_err();
        assert!(
            err.to_string().contains("another device or driver"),
            "{err}"
        );
        let mut version = bytes.clone();
        version[8] = 9;
        assert_eq!(decode(&id(), &version), Err(Rejection::Version(9)));
    }

    #[test]
    fn driver_data_of_another_device_is_refused() {
        let mut other = id();
        other.device_id = 7;
        let contents = Contents {
            keys: vec![],
            data: driver_data(&other),
        };
        let bytes = encode(&id(), &contents);
        assert_eq!(
            decode(&id(), &bytes),
            Err(Rejection::VulkanHeader("written by another device"))
        );
        let short = Contents {
            keys: vec![],
            data: vec![1, 2, 3],
        };
        assert!(matches!(
            decode(&id(), &encode(&id(), &short)),
            Err(Rejection::VulkanHeader(_))
        ));
    }

    #[test]
    fn fnv1a_is_the_reference_hash() {
        // Published FNV-1a 64 test vectors.
        assert_eq!(fnv1a(FNV_OFFSET, b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(FNV_OFFSET, b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(FNV_OFFSET, b"foobar"), 0x8594_4171_f739_67e8);
    }
}
