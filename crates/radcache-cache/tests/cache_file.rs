//! Cache files: a round trip keeps every record bit for bit, and each refusal class (not a cache
//! file, another version, truncated, corrupted, another scene, other parameters or settings, too
//! many records) gives its own error naming the file, never a panic.

use std::path::{Path, PathBuf};

use radcache_cache::cache_file::{
    CacheFile, CacheFileError, CacheIdentity, CacheRecords, CacheSettings, RadianceBlock, Refusal,
    BYTES_PER_RECORD, HEADER_LEN, RADIANCE_BYTES_PER_RECORD,
};
use radcache_cache::{ErrorControl, IcParams};
use radcache_shared::gpu::{GpuRecord, GpuRecordTemporal};

fn identity() -> CacheIdentity {
    CacheIdentity {
        scene_hash: 0x1234_5678_9abc_def0,
        settings: CacheSettings {
            width: 64,
            height: 48,
            time_step_s: 0.0,
        },
        params: IcParams::draft(),
    }
}

/// `n` records whose every word differs (including NaN bit patterns, kept as bits).
fn records(n: usize) -> CacheRecords {
    let word =
        |i: usize, k: usize| (i * 1000 + k) as u32 ^ (0x7fc0_0000 * k.is_multiple_of(7) as u32);
    let mut records = Vec::new();
    let mut temporal = Vec::new();
    for i in 0..n {
        let mut r: GpuRecord = bytemuck::Zeroable::zeroed();
        let w: &mut [u32] = bytemuck::cast_slice_mut(std::slice::from_mut(&mut r));
        w.iter_mut().enumerate().for_each(|(k, w)| *w = word(i, k));
        records.push(r);
        let mut t: GpuRecordTemporal = bytemuck::Zeroable::zeroed();
        let w: &mut [u32] = bytemuck::cast_slice_mut(std::slice::from_mut(&mut t));
        w.iter_mut()
            .enumerate()
            .for_each(|(k, w)| *w = word(i, k + 100));
        temporal.push(t);
    }
    CacheRecords {
        records,
        temporal,
        last_used: (0..n as u32).map(|i| i % 5).collect(),
        frames: 7,
        lifespans: false,
        sky: true,
        radiance: Vec::new(),
    }
}

/// `records(n)` with a radiance block per record, every word distinct (NaN patterns included).
fn records_with_radiance(n: usize) -> CacheRecords {
    let mut r = records(n);
    r.radiance = (0..n)
        .map(|i| {
            let mut block: RadianceBlock = bytemuck::Zeroable::zeroed();
            let w: &mut [u32] = bytemuck::cast_slice_mut(&mut block);
            for (k, w) in w.iter_mut().enumerate() {
                *w = (i * 10_000 + k) as u32 | (0x7f80_0000 * (k % 11 == 3) as u32);
            }
            block
        })
        .collect();
    r
}

/// Rewrites the header checksum after an edit of bytes 0..120.
fn reseal_header(b: &mut [u8]) {
    let crc = crc32fast::hash(&b[..HEADER_LEN - 4]);
    b[HEADER_LEN - 4..HEADER_LEN].copy_from_slice(&crc.to_le_bytes());
}

/// Clears the high halves of the strata words (bytes 56..64), as versions 1 and 2 wrote them.
fn clear_fine_strata(b: &mut [u8]) {
    for at in [56, 60] {
        let w = u32::from_le_bytes(b[at..at + 4].try_into().unwrap());
        b[at..at + 4].copy_from_slice(&(w & 0xffff).to_le_bytes());
    }
}

/// Clears the high half of the levels word (bytes 68..72), as versions 1 to 3 wrote it.
fn clear_falloff(b: &mut [u8]) {
    let w = u32::from_le_bytes(b[68..72].try_into().unwrap());
    b[68..72].copy_from_slice(&(w & 0xffff).to_le_bytes());
}

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("radcache-cache-file-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn bytes(n: usize) -> Vec<u8> {
    CacheFile::new(identity(), records(n)).encode()
}

/// Loads `path` for `identity()` with room for 100 records; the error must name the file.
fn refusal(path: &Path, id: &CacheIdentity) -> (Refusal, String) {
    let err = CacheFile::load(path, id, 100).unwrap_err();
    let text = err.to_string();
    assert!(text.contains(&path.display().to_string()), "{text}");
    match err {
        CacheFileError::Refused { refusal, .. } => (refusal, text),
        other => panic!("not a refusal: {other}"),
    }
}

#[test]
fn a_round_trip_keeps_every_record_bit_for_bit() {
    let original = records(9);
    let path = write("round.rcache", &bytes(9));
    let file = CacheFile::load(&path, &identity(), 9).unwrap();
    assert_eq!(file.header.record_count, 9);
    assert_eq!(file.header.identity, identity());
    let same = |a: &[u8], b: &[u8]| a == b;
    assert!(same(
        bytemuck::cast_slice(&file.records.records),
        bytemuck::cast_slice(&original.records)
    ));
    assert!(same(
        bytemuck::cast_slice(&file.records.temporal),
        bytemuck::cast_slice(&original.temporal)
    ));
    assert_eq!(file.records.last_used, original.last_used);
    assert_eq!(
        (
            file.records.frames,
            file.records.lifespans,
            file.records.sky
        ),
        (7, false, true)
    );
    // An empty cache is a valid file too.
    let empty = CacheFile::decode(&bytes(0)).unwrap();
    assert_eq!(empty.header.record_count, 0);
    assert_eq!(bytes(0).len(), HEADER_LEN);
    let text = file.header.describe();
    assert!(
        text.contains("records: 9")
            && text.contains("strata_m: 8")
            && text.contains("sky in the records: yes"),
        "{text}"
    );
}

#[test]
fn a_file_that_is_not_a_cache_file_is_refused() {
    let path = write("not.rcache", b"glTF this is something else entirely");
    let (r, text) = refusal(&path, &identity());
    assert!(matches!(r, Refusal::NotACacheFile), "{text}");
    assert!(text.contains("not a radcache cache file"), "{text}");
}

#[test]
fn another_format_version_is_refused() {
    for version in [0u32, 5] {
        let mut b = bytes(3);
        b[8..12].copy_from_slice(&version.to_le_bytes());
        let (r, text) = refusal(&write("version.rcache", &b), &identity());
        assert!(
            matches!(
                r,
                Refusal::Version {
                    found,
                    oldest: 1,
                    newest: 4
                } if found == version
            ),
            "{text}"
        );
        assert!(text.contains("reads versions 1 to 4"), "{text}");
    }
}

#[test]
fn a_truncated_file_is_refused_wherever_it_was_cut() {
    let b = bytes(3);
    for cut in [0, 5, 10, HEADER_LEN - 1, HEADER_LEN, b.len() - 1] {
        let path = write(&format!("cut{cut}.rcache"), &b[..cut]);
        let (r, text) = refusal(&path, &identity());
        assert!(
            matches!(r, Refusal::Truncated { .. }),
            "cut at {cut}: {text}"
        );
        assert!(text.contains("truncated"), "{text}");
    }
}

#[test]
fn a_corrupted_file_is_refused() {
    let b = bytes(3);
    // A flipped bit anywhere after the version: in the header (its checksum), in a record, in a
    // temporal state, in a mark; and bytes appended after the records.
    for at in [
        13,
        40,
        90,
        HEADER_LEN + 5,
        HEADER_LEN + 3 * 176 + 20,
        b.len() - 2,
    ] {
        let mut c = b.clone();
        c[at] ^= 0x10;
        let (r, text) = refusal(&write(&format!("flip{at}.rcache"), &c), &identity());
        assert!(matches!(r, Refusal::Corrupt(_)), "bit at {at}: {text}");
        assert!(text.contains("corrupted"), "{text}");
    }
    let mut c = b.clone();
    c.extend_from_slice(&[0; 4]);
    let (r, text) = refusal(&write("long.rcache", &c), &identity());
    assert!(matches!(r, Refusal::Corrupt(_)), "{text}");
}

#[test]
fn a_file_of_another_scene_is_refused() {
    let path = write("scene.rcache", &bytes(3));
    let other = CacheIdentity {
        scene_hash: 42,
        ..identity()
    };
    let (r, text) = refusal(&path, &other);
    assert!(matches!(r, Refusal::OtherScene { scene: 42, .. }), "{text}");
    assert!(text.contains("another scene"), "{text}");
}

#[test]
fn other_cache_parameters_are_refused_by_name() {
    let path = write("params.rcache", &bytes(3));
    let mut other = identity();
    other.params.accuracy = 0.2;
    other.params.strata_n = 30;
    let (r, text) = refusal(&path, &other);
    assert!(matches!(r, Refusal::OtherParams(_)), "{text}");
    assert!(
        text.contains("accuracy 0.3 (this render: 0.2)") && text.contains("strata_n 24"),
        "{text}"
    );
    let mut preset = identity();
    preset.params = IcParams::default();
    assert!(matches!(refusal(&path, &preset).0, Refusal::OtherParams(_)));
}

/// The radius rule is kept in the header's flags: a file made with the Hessian rule reads back
/// with it and is refused by a render that uses the split sphere, and the other way round.
#[test]
fn the_error_control_rule_round_trips_and_is_refused_when_it_differs() {
    let mut hessian = identity();
    hessian.params.error_control = ErrorControl::Hessian;
    let path = write(
        "hessian.rcache",
        &CacheFile::new(hessian, records(2)).encode(),
    );
    let file = CacheFile::load(&path, &hessian, 100).unwrap();
    assert_eq!(
        file.header.identity.params.error_control,
        ErrorControl::Hessian
    );
    assert!(file.header.describe().contains("error_control: Hessian"));
    let (r, text) = refusal(&path, &identity());
    assert!(matches!(r, Refusal::OtherParams(_)), "{text}");
    assert!(
        text.contains("error_control Hessian (this render: SplitSphere)"),
        "{text}"
    );
    let split = write("split.rcache", &bytes(2));
    let (r, text) = refusal(&split, &hessian);
    assert!(matches!(r, Refusal::OtherParams(_)), "{text}");
}

#[test]
fn other_settings_are_refused() {
    let path = write("settings.rcache", &bytes(3));
    let mut other = identity();
    other.settings.width = 128;
    let (r, text) = refusal(&path, &other);
    assert!(matches!(r, Refusal::OtherSettings(_)), "{text}");
    assert!(
        text.contains("made at 64x48, this render is 128x48"),
        "{text}"
    );
    let mut other = identity();
    other.settings.time_step_s = 1.0 / 24.0;
    assert!(matches!(
        refusal(&path, &other).0,
        Refusal::OtherSettings(_)
    ));
}

#[test]
fn more_records_than_the_capacity_are_refused() {
    let path = write("many.rcache", &bytes(101));
    let (r, text) = refusal(&path, &identity());
    assert!(
        matches!(
            r,
            Refusal::TooManyRecords {
                count: 101,
                capacity: 100
            }
        ),
        "{text}"
    );
}

#[test]
fn a_missing_file_is_an_io_error_naming_it() {
    let path = dir().join("absent.rcache");
    let err = CacheFile::read(&path).unwrap_err();
    assert!(matches!(err, CacheFileError::Io { .. }));
    assert!(err.to_string().contains("absent.rcache"), "{err}");
}

#[test]
fn radiance_blocks_round_trip_and_are_checked_like_the_records() {
    let original = records_with_radiance(5);
    let b = CacheFile::new(identity(), original.clone()).encode();
    assert_eq!(
        b.len() as u64,
        HEADER_LEN as u64 + 5 * (BYTES_PER_RECORD + RADIANCE_BYTES_PER_RECORD)
    );
    let path = write("radiance.rcache", &b);
    let file = CacheFile::load(&path, &identity(), 5).unwrap();
    assert!(file.header.radiance);
    assert_eq!(
        bytemuck::cast_slice::<RadianceBlock, u8>(&file.records.radiance),
        bytemuck::cast_slice::<RadianceBlock, u8>(&original.radiance)
    );
    assert_eq!(file.records.last_used, original.last_used);
    let text = file.header.describe();
    assert!(text.contains("radiance coefficients: yes"), "{text}");
    let plain = CacheFile::decode(&bytes(5)).unwrap();
    assert!(!plain.header.radiance && plain.records.radiance.is_empty());
    assert!(plain
        .header
        .describe()
        .contains("radiance coefficients: no"));

    // A flipped word in a block fails the payload checksum; a cut block is truncation.
    let mut bad = b.clone();
    let last = bad.len() - 7;
    bad[last] ^= 0x10;
    let (r, text) = refusal(&write("radiance-bad.rcache", &bad), &identity());
    assert!(matches!(r, Refusal::Corrupt(_)), "{text}");
    let cut = &b[..b.len() - 100];
    let (r, text) = refusal(&write("radiance-cut.rcache", cut), &identity());
    assert!(matches!(r, Refusal::Truncated { .. }), "{text}");
    // The flag without the blocks' bytes (header resealed) is a length mismatch.
    let mut lie = bytes(5);
    let flags = u32::from_le_bytes(lie[96..100].try_into().unwrap()) | 8;
    lie[96..100].copy_from_slice(&flags.to_le_bytes());
    reseal_header(&mut lie);
    let (r, text) = refusal(&write("radiance-lie.rcache", &lie), &identity());
    assert!(matches!(r, Refusal::Corrupt(_)), "{text}");
    assert!(text.contains("payload bytes"), "{text}");
}

/// From version 3 the strata words carry the fine strata in their high halves; a version-2
/// file's records all had `strata_m × strata_n`, which it reads as its fine strata too.
#[test]
fn fine_strata_round_trip_and_older_files_read_as_uniform() {
    let mut id = identity();
    id.params = IcParams::default();
    assert_ne!(
        (id.params.strata_m, id.params.strata_n),
        (id.params.fine_strata_m, id.params.fine_strata_n)
    );
    let b = CacheFile::new(id, records(2)).encode();
    let file = CacheFile::load(&write("fine.rcache", &b), &id, 4).unwrap();
    assert_eq!(file.header.identity.params, id.params);
    let text = file.header.describe();
    let (m, n) = (id.params.strata_m, id.params.strata_n);
    let (fm, fn_) = (id.params.fine_strata_m, id.params.fine_strata_n);
    assert!(
        text.contains(&format!("strata_m: {m}")) && text.contains(&format!("fine_strata_m: {fm}")),
        "{text}"
    );
    // The same header as version 2 with the high halves cleared, as version 2 wrote it.
    let mut v2 = b.clone();
    v2[8..12].copy_from_slice(&2u32.to_le_bytes());
    clear_fine_strata(&mut v2);
    clear_falloff(&mut v2);
    reseal_header(&mut v2);
    let uniform = IcParams {
        fine_strata_m: m,
        fine_strata_n: n,
        strata_falloff: false,
        ..id.params
    };
    let (r, text) = refusal(&write("v2-fine.rcache", &v2), &id);
    assert!(matches!(r, Refusal::OtherParams(_)), "{text}");
    assert!(
        text.contains(&format!("fine_strata_m {m} (this render: {fm})"))
            && text.contains(&format!("fine_strata_n {n} (this render: {fn_})")),
        "{text}"
    );
    let old = CacheIdentity {
        params: uniform,
        ..id
    };
    let file = CacheFile::load(&write("v2-uniform.rcache", &v2), &old, 4).unwrap();
    assert_eq!(file.header.identity.params, uniform);
    // A version-3 header without fine strata is not one this build wrote.
    let mut zero = b;
    let w = u32::from_le_bytes(zero[56..60].try_into().unwrap());
    zero[56..60].copy_from_slice(&(w & 0xffff).to_le_bytes());
    reseal_header(&mut zero);
    let (r, text) = refusal(&write("v3-zero.rcache", &zero), &id);
    assert!(matches!(r, Refusal::Corrupt(_)), "{text}");
    assert!(text.contains("fine strata"), "{text}");
}

/// From version 4 bit 16 of the levels word is the strata falloff; a version-3 file's fine
/// strata had none, and a render with it refuses the file by name.
#[test]
fn strata_falloff_round_trips_and_older_files_have_none() {
    let mut id = identity();
    id.params = IcParams::default();
    assert!(id.params.strata_falloff && !IcParams::draft().strata_falloff);
    let b = CacheFile::new(id, records(2)).encode();
    let file = CacheFile::load(&write("falloff.rcache", &b), &id, 4).unwrap();
    assert_eq!(file.header.identity.params, id.params);
    assert!(file.header.describe().contains("strata_falloff: 1"));
    let mut v3 = b.clone();
    v3[8..12].copy_from_slice(&3u32.to_le_bytes());
    clear_falloff(&mut v3);
    reseal_header(&mut v3);
    let (r, text) = refusal(&write("v3-falloff.rcache", &v3), &id);
    assert!(matches!(r, Refusal::OtherParams(_)), "{text}");
    assert!(text.contains("strata_falloff 0 (this render: 1)"), "{text}");
    let without = CacheIdentity {
        params: IcParams {
            strata_falloff: false,
            ..id.params
        },
        ..id
    };
    let file = CacheFile::load(&write("v3-plain.rcache", &v3), &without, 4).unwrap();
    assert_eq!(
        (file.header.version, file.header.identity.params),
        (3, without.params)
    );
    // Other bits above the levels in a version-4 header are not what this build writes.
    let mut junk = b;
    junk[70] |= 0x02;
    reseal_header(&mut junk);
    let (r, text) = refusal(&write("v4-junk.rcache", &junk), &id);
    assert!(matches!(r, Refusal::Corrupt(_)), "{text}");
    assert!(text.contains("levels word"), "{text}");
}

#[test]
fn a_version_1_file_is_read_and_cannot_claim_radiance_blocks() {
    // Version 1 is version 2 without the radiance flag, and version 2 is version 3 without
    // the fine strata: the same bytes with the old number and the strata words' high halves
    // cleared.
    let mut v1 = bytes(4);
    v1[8..12].copy_from_slice(&1u32.to_le_bytes());
    clear_fine_strata(&mut v1);
    reseal_header(&mut v1);
    let file = CacheFile::load(&write("v1.rcache", &v1), &identity(), 4).unwrap();
    assert_eq!(file.header.version, 1);
    assert_eq!(file.records.records.len(), 4);
    assert!(!file.header.radiance && file.records.radiance.is_empty());
    let original = records(4);
    assert_eq!(
        bytemuck::cast_slice::<GpuRecord, u8>(&file.records.records),
        bytemuck::cast_slice::<GpuRecord, u8>(&original.records)
    );
    // A version-1 header with the radiance flag is not a file version 1 ever wrote.
    let mut claim = CacheFile::new(identity(), records_with_radiance(4)).encode();
    claim[8..12].copy_from_slice(&1u32.to_le_bytes());
    clear_fine_strata(&mut claim);
    reseal_header(&mut claim);
    let (r, text) = refusal(&write("v1-claim.rcache", &claim), &identity());
    assert!(matches!(r, Refusal::Corrupt(_)), "{text}");
}
