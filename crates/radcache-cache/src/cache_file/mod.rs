//! Cache files (`radcache render --cache-out/--cache-in`, `radcache cache build|info`): a cache's
//! records with their temporal state and last-use marks (and, where the scene has glossy lobes
//! from the cache, their radiance blocks), behind a versioned header that says what they were
//! made for, so they are never used for another scene or other parameters.
//!
//! Layout (little-endian; every record field is a 4-byte word):
//!
//! | bytes | field |
//! |---|---|
//! | 0..8 | magic `RADCACHE` |
//! | 8..12 | format version ([`FORMAT_VERSION`]; versions from [`OLDEST_VERSION`] are read) |
//! | 12..20 | scene content hash (`radcache_scene::Scene::content_hash`, FNV-1a 64) |
//! | 20..32 | settings: width, height (u32), time step in s (f32) |
//! | 32..36 | CRC-32 of the settings' 12 bytes (the settings hash) |
//! | 36..88 | [`IcParams`], 13 words in declaration order (`weight_kind` as its GLSL constant; from version 3 the high 16 bits of `strata_m` and `strata_n` hold `fine_strata_m` and `fine_strata_n`, from version 4 bit 16 of `levels` `strata_falloff`) |
//! | 88..92 | record count n |
//! | 92..96 | the renderer's frame count at export (the clock of the last-use marks and of the temporal state's frame numbers) |
//! | 96..100 | flags (bit 0: the records carry lifespans; bit 1: they hold a constant environment's light, the sky; bit 2: the Hessian error control sized them, `IcParams::error_control`; bit 3, from version 2: the payload holds their radiance blocks) |
//! | 100..108 | `size_of::<GpuRecord>()`, `size_of::<GpuRecordTemporal>()` (u32 each) |
//! | 108..116 | payload length in bytes (u64) = n · (176 + 96 + 4), plus n · 512 with radiance blocks |
//! | 116..120 | CRC-32 of the payload |
//! | 120..124 | CRC-32 of bytes 0..120 |
//! | 124.. | payload: n `GpuRecord`, n `GpuRecordTemporal`, n last-use marks (u32), then with bit 3 n [`RadianceBlock`]s |
//!
//! Version 1 had no bit 3 (its records never carry radiance blocks); it is read as it was
//! written. Versions 1 and 2 had no fine strata: every record was gathered with `strata_m ×
//! strata_n`, which a reader takes as their fine strata too; versions 1 to 3 had no strata falloff. A file with the flag but a renderer without radiance records, or the reverse, is the
//! renderer's to settle (`radcache_render::IcRenderer::import_cache`).
//!
//! [`CacheFile::decode`] refuses, in this order: a file that does not start with the magic, a
//! format version it cannot read, a file shorter than its header or payload (truncated), a header or payload
//! whose checksum or lengths are wrong (corrupted); [`CacheHeader::check`] then refuses a file made
//! for another scene, with other cache parameters or settings, or holding more records than the
//! renderer's capacity. Every refusal is a [`Refusal`]; read through a path it names the file.

mod error;
mod params;

use std::path::Path;

use radcache_shared::consts::RECORD_RADIANCE_VEC4S;
pub use radcache_shared::gpu::RadianceBlock;
use radcache_shared::gpu::{GpuRecord, GpuRecordTemporal};

use crate::params::{ErrorControl, IcParams};

pub use error::{CacheFileError, Refusal};
pub use params::ParamValue;

use params::{param_values, param_words, params_from_words};

/// The first eight bytes of a cache file.
pub const MAGIC: [u8; 8] = *b"RADCACHE";
/// The format version this build writes.
pub const FORMAT_VERSION: u32 = 4;
/// The oldest format version this build reads (version 1: no radiance blocks).
pub const OLDEST_VERSION: u32 = 1;
/// Bytes of the header (the payload starts here).
pub const HEADER_LEN: usize = 124;
/// Payload bytes per record: the record, its temporal state and its last-use mark.
pub const BYTES_PER_RECORD: u64 =
    (std::mem::size_of::<GpuRecord>() + std::mem::size_of::<GpuRecordTemporal>() + 4) as u64;
/// Bytes of one record's radiance block (`RECORD_RADIANCE_VEC4S` uvec4).
pub const RADIANCE_BYTES_PER_RECORD: u64 = RECORD_RADIANCE_VEC4S as u64 * 16;

/// Payload bytes per record, with or without its radiance block.
pub fn payload_bytes_per_record(radiance: bool) -> u64 {
    BYTES_PER_RECORD
        + if radiance {
            RADIANCE_BYTES_PER_RECORD
        } else {
            0
        }
}

const FLAG_LIFESPANS: u32 = 1;
const FLAG_SKY: u32 = 2;
const FLAG_HESSIAN: u32 = 4;
const FLAG_RADIANCE: u32 = 8;

/// The settings besides the cache parameters that the records depend on (not the camera).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CacheSettings {
    /// Image width (records' pixel footprints and creation pixels are in its pixels).
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Seconds per frame of temporal caching (0 without lifespans).
    pub time_step_s: f32,
}

impl CacheSettings {
    fn bytes(&self) -> [u8; 12] {
        let mut b = [0u8; 12];
        b[0..4].copy_from_slice(&self.width.to_le_bytes());
        b[4..8].copy_from_slice(&self.height.to_le_bytes());
        b[8..12].copy_from_slice(&self.time_step_s.to_bits().to_le_bytes());
        b
    }

    /// The settings hash: CRC-32 of the three fields' little-endian bytes.
    pub fn hash(&self) -> u32 {
        crc32fast::hash(&self.bytes())
    }
}

/// What a cache is made for: the scene's content, the settings and the cache parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CacheIdentity {
    /// `Scene::content_hash`.
    pub scene_hash: u64,
    /// The camera-independent settings.
    pub settings: CacheSettings,
    /// The cache parameters.
    pub params: IcParams,
}

/// A cache's records as a renderer exports and imports them (same length each; `radiance` is
/// empty or of the same length too).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CacheRecords {
    /// The records.
    pub records: Vec<GpuRecord>,
    /// Their temporal state (same index).
    pub temporal: Vec<GpuRecordTemporal>,
    /// Their last-use marks (the renderer's frame count, 0 = never used).
    pub last_used: Vec<u32>,
    /// The renderer's frame count when they were exported.
    pub frames: u32,
    /// The records carry lifespans (temporal caching of moving geometry or lights).
    pub lifespans: bool,
    /// The records hold a constant environment's light (the sky; `radcache_render::SkyLight`).
    pub sky: bool,
    /// Their radiance blocks (same index), or none: records without radiance coefficients.
    pub radiance: Vec<RadianceBlock>,
}

/// The header of a cache file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CacheHeader {
    /// Format version.
    pub version: u32,
    /// What the records were made for.
    pub identity: CacheIdentity,
    /// The settings hash stored in the file.
    pub settings_hash: u32,
    /// Records in the file.
    pub record_count: u32,
    /// The renderer's frame count at export.
    pub frames: u32,
    /// The records carry lifespans.
    pub lifespans: bool,
    /// The records hold the sky's light.
    pub sky: bool,
    /// The payload holds the records' radiance blocks.
    pub radiance: bool,
    /// Payload bytes.
    pub payload_len: u64,
    /// CRC-32 of the payload.
    pub payload_crc: u32,
}

/// A decoded cache file.
#[derive(Clone, Debug, PartialEq)]
pub struct CacheFile {
    /// Its header.
    pub header: CacheHeader,
    /// Its records.
    pub records: CacheRecords,
}

fn push_words<T: bytemuck::Pod>(out: &mut Vec<u8>, items: &[T]) {
    for w in bytemuck::cast_slice::<T, u32>(items) {
        out.extend_from_slice(&w.to_le_bytes());
    }
}

fn words(bytes: &[u8]) -> Vec<u32> {
    bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Reads little-endian words from a slice known to be long enough.
struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn u32(&mut self) -> u32 {
        let (head, rest) = self.0.split_at(4);
        self.0 = rest;
        u32::from_le_bytes([head[0], head[1], head[2], head[3]])
    }

    fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | (u64::from(self.u32()) << 32)
    }
}

impl CacheFile {
    /// A file of `records` made for `identity`. Panics when the record, temporal and mark
    /// vectors differ in length, or the radiance blocks are neither absent nor one per record
    /// (a renderer's export always gives equal lengths).
    pub fn new(identity: CacheIdentity, records: CacheRecords) -> CacheFile {
        let n = records.records.len();
        assert!(
            records.temporal.len() == n && records.last_used.len() == n,
            "a cache's records, temporal states and marks differ in number"
        );
        let radiance = !records.radiance.is_empty();
        assert!(
            !radiance || records.radiance.len() == n,
            "a cache's records and radiance blocks differ in number"
        );
        let header = CacheHeader {
            version: FORMAT_VERSION,
            identity,
            settings_hash: identity.settings.hash(),
            record_count: n as u32,
            frames: records.frames,
            lifespans: records.lifespans,
            sky: records.sky,
            radiance,
            payload_len: n as u64 * payload_bytes_per_record(radiance),
            payload_crc: 0,
        };
        let mut file = CacheFile { header, records };
        file.header.payload_crc = crc32fast::hash(&file.payload());
        file
    }

    fn payload(&self) -> Vec<u8> {
        let r = &self.records;
        let mut out = Vec::with_capacity(self.header.payload_len as usize);
        push_words(&mut out, &r.records);
        push_words(&mut out, &r.temporal);
        push_words(&mut out, &r.last_used);
        push_words(&mut out, &r.radiance);
        out
    }

    /// The file's bytes.
    pub fn encode(&self) -> Vec<u8> {
        let h = &self.header;
        let mut out = Vec::with_capacity(HEADER_LEN + h.payload_len as usize);
        out.extend_from_slice(&MAGIC);
        let word = |out: &mut Vec<u8>, v: u32| out.extend_from_slice(&v.to_le_bytes());
        word(&mut out, h.version);
        out.extend_from_slice(&h.identity.scene_hash.to_le_bytes());
        out.extend_from_slice(&h.identity.settings.bytes());
        word(&mut out, h.settings_hash);
        for w in param_words(&h.identity.params) {
            word(&mut out, w);
        }
        word(&mut out, h.record_count);
        word(&mut out, h.frames);
        let hessian = h.identity.params.error_control == ErrorControl::Hessian;
        let flags = [
            (h.lifespans, FLAG_LIFESPANS),
            (h.sky, FLAG_SKY),
            (hessian, FLAG_HESSIAN),
            (h.radiance, FLAG_RADIANCE),
        ];
        word(&mut out, flags.iter().filter(|f| f.0).map(|f| f.1).sum());
        word(&mut out, std::mem::size_of::<GpuRecord>() as u32);
        word(&mut out, std::mem::size_of::<GpuRecordTemporal>() as u32);
        out.extend_from_slice(&h.payload_len.to_le_bytes());
        word(&mut out, h.payload_crc);
        let crc = crc32fast::hash(&out);
        word(&mut out, crc);
        debug_assert_eq!(out.len(), HEADER_LEN);
        out.extend_from_slice(&self.payload());
        out
    }

    /// Decodes and validates a file's bytes (magic, version, lengths, checksums).
    pub fn decode(bytes: &[u8]) -> Result<CacheFile, Refusal> {
        let header = CacheHeader::decode(bytes)?;
        let len = bytes.len() as u64;
        let expected = HEADER_LEN as u64 + header.payload_len;
        if len < expected {
            return Err(Refusal::Truncated { len, expected });
        }
        if len > expected {
            return Err(Refusal::Corrupt(format!(
                "{} bytes after the {} records",
                len - expected,
                header.record_count
            )));
        }
        let payload = &bytes[HEADER_LEN..];
        let crc = crc32fast::hash(payload);
        if crc != header.payload_crc {
            return Err(Refusal::Corrupt(format!(
                "the records' checksum is {crc:08x}, the header says {:08x}",
                header.payload_crc
            )));
        }
        let n = header.record_count as usize;
        let (records, rest) = payload.split_at(n * std::mem::size_of::<GpuRecord>());
        let (temporal, rest) = rest.split_at(n * std::mem::size_of::<GpuRecordTemporal>());
        let (marks, blocks) = rest.split_at(n * 4);
        let records = CacheRecords {
            records: bytemuck::cast_slice::<u32, GpuRecord>(&words(records)).to_vec(),
            temporal: bytemuck::cast_slice::<u32, GpuRecordTemporal>(&words(temporal)).to_vec(),
            last_used: words(marks),
            frames: header.frames,
            lifespans: header.lifespans,
            sky: header.sky,
            radiance: bytemuck::cast_slice::<u32, RadianceBlock>(&words(blocks)).to_vec(),
        };
        Ok(CacheFile { header, records })
    }

    /// Reads and validates the file at `path` (errors name it).
    pub fn read(path: &Path) -> Result<CacheFile, CacheFileError> {
        let bytes = std::fs::read(path).map_err(|source| CacheFileError::Io {
            path: path.to_owned(),
            source,
        })?;
        CacheFile::decode(&bytes).map_err(|refusal| CacheFileError::Refused {
            path: path.to_owned(),
            refusal,
        })
    }

    /// Reads the file at `path` and checks that it was made for `identity` and fits in
    /// `capacity` records (errors name it).
    pub fn load(
        path: &Path,
        identity: &CacheIdentity,
        capacity: u32,
    ) -> Result<CacheFile, CacheFileError> {
        let file = CacheFile::read(path)?;
        file.header
            .check(identity, capacity)
            .map_err(|refusal| CacheFileError::Refused {
                path: path.to_owned(),
                refusal,
            })?;
        Ok(file)
    }
}

impl CacheHeader {
    /// Decodes and validates the header at the start of `bytes` (magic, version, header length
    /// and checksum, the sizes it announces).
    pub fn decode(bytes: &[u8]) -> Result<CacheHeader, Refusal> {
        let len = bytes.len() as u64;
        let truncated = || Refusal::Truncated {
            len,
            expected: HEADER_LEN as u64,
        };
        let prefix = bytes.len().min(MAGIC.len());
        if bytes[..prefix] != MAGIC[..prefix] {
            return Err(Refusal::NotACacheFile);
        }
        if bytes.len() < 12 {
            return Err(truncated());
        }
        let mut r = Reader(&bytes[8..]);
        let version = r.u32();
        if !(OLDEST_VERSION..=FORMAT_VERSION).contains(&version) {
            return Err(Refusal::Version {
                found: version,
                oldest: OLDEST_VERSION,
                newest: FORMAT_VERSION,
            });
        }
        if bytes.len() < HEADER_LEN {
            return Err(truncated());
        }
        let stored = u32::from_le_bytes(bytes[HEADER_LEN - 4..HEADER_LEN].try_into().unwrap());
        let crc = crc32fast::hash(&bytes[..HEADER_LEN - 4]);
        if crc != stored {
            return Err(Refusal::Corrupt(format!(
                "the header's checksum is {crc:08x}, it says {stored:08x}"
            )));
        }
        let scene_hash = r.u64();
        let settings = CacheSettings {
            width: r.u32(),
            height: r.u32(),
            time_step_s: f32::from_bits(r.u32()),
        };
        let settings_hash = r.u32();
        let mut w = [0u32; 13];
        w.iter_mut().for_each(|w| *w = r.u32());
        let mut params = params_from_words(&w, version)?;
        let (record_count, frames, flags) = (r.u32(), r.u32(), r.u32());
        if flags & FLAG_HESSIAN != 0 {
            params.error_control = ErrorControl::Hessian;
        }
        let sizes = (r.u32() as usize, r.u32() as usize);
        let (payload_len, payload_crc) = (r.u64(), r.u32());
        let ours = (
            std::mem::size_of::<GpuRecord>(),
            std::mem::size_of::<GpuRecordTemporal>(),
        );
        if sizes != ours {
            return Err(Refusal::Corrupt(format!(
                "records of {} and {} bytes, this radcache's are {} and {}",
                sizes.0, sizes.1, ours.0, ours.1
            )));
        }
        let known = match version {
            1 => FLAG_LIFESPANS | FLAG_SKY | FLAG_HESSIAN,
            _ => FLAG_LIFESPANS | FLAG_SKY | FLAG_HESSIAN | FLAG_RADIANCE,
        };
        let radiance = flags & FLAG_RADIANCE != 0;
        let per_record = payload_bytes_per_record(radiance);
        if payload_len != u64::from(record_count) * per_record {
            return Err(Refusal::Corrupt(format!(
                "{payload_len} payload bytes for {record_count} records of {per_record}"
            )));
        }
        if settings_hash != settings.hash() || flags & !known != 0 {
            return Err(Refusal::Corrupt("inconsistent settings or flags".into()));
        }
        Ok(CacheHeader {
            version,
            identity: CacheIdentity {
                scene_hash,
                settings,
                params,
            },
            settings_hash,
            record_count,
            frames,
            lifespans: flags & FLAG_LIFESPANS != 0,
            sky: flags & FLAG_SKY != 0,
            radiance,
            payload_len,
            payload_crc,
        })
    }

    /// Refuses records made for another scene, with other cache parameters or settings, or
    /// more than `capacity` of them.
    pub fn check(&self, expected: &CacheIdentity, capacity: u32) -> Result<(), Refusal> {
        let ours = &self.identity;
        if ours.scene_hash != expected.scene_hash {
            return Err(Refusal::OtherScene {
                file: ours.scene_hash,
                scene: expected.scene_hash,
            });
        }
        let mut differ: Vec<String> = param_values(&ours.params)
            .iter()
            .zip(param_values(&expected.params))
            .filter(|(a, b)| a.1.bits() != b.1.bits())
            .map(|(a, b)| format!("{} {} (this render: {})", a.0, a.1, b.1))
            .collect();
        let rule = |p: &IcParams| format!("{:?}", p.error_control);
        if ours.params.error_control != expected.params.error_control {
            differ.push(format!(
                "error_control {} (this render: {})",
                rule(&ours.params),
                rule(&expected.params)
            ));
        }
        if !differ.is_empty() {
            return Err(Refusal::OtherParams(differ.join(", ")));
        }
        let (s, e) = (&ours.settings, &expected.settings);
        if (s.width, s.height) != (e.width, e.height) {
            return Err(Refusal::OtherSettings(format!(
                "made at {}x{}, this render is {}x{}",
                s.width, s.height, e.width, e.height
            )));
        }
        if s.time_step_s.to_bits() != e.time_step_s.to_bits() {
            return Err(Refusal::OtherSettings(format!(
                "a time step of {} s (0: no lifespans), this render's is {} s",
                s.time_step_s, e.time_step_s
            )));
        }
        if self.record_count > capacity {
            return Err(Refusal::TooManyRecords {
                count: self.record_count,
                capacity,
            });
        }
        Ok(())
    }

    /// The header as `name: value` lines (`radcache cache info`).
    pub fn describe(&self) -> String {
        let id = &self.identity;
        let s = &id.settings;
        let mut text = format!(
            "format version: {}\nscene content hash: {:016x}\nsettings: {}x{}, time step {} s \
             (hash {:08x})\nrecords: {} ({} payload bytes, checksum {:08x})\nrenderer frames: \
             {}\nlifespans: {}\nsky in the records: {}\nradiance coefficients: {}\ncache \
             parameters:\n",
            self.version,
            id.scene_hash,
            s.width,
            s.height,
            s.time_step_s,
            self.settings_hash,
            self.record_count,
            self.payload_len,
            self.payload_crc,
            self.frames,
            if self.lifespans { "yes" } else { "no" },
            if self.sky { "yes" } else { "no" },
            if self.radiance { "yes" } else { "no" },
        );
        for (name, value) in param_values(&id.params) {
            text.push_str(&format!("  {name}: {value}\n"));
        }
        text.push_str(&format!("  error_control: {:?}\n", id.params.error_control));
        text
    }

    /// The cache parameters by name (for a JSON report).
    pub fn param_values(&self) -> Vec<(&'static str, ParamValue)> {
        param_values(&self.identity.params)
    }
}
