//! The settings and figures of a frame rendered with the irradiance cache (`--method ic`); the
//! frame itself is [`crate::IcRenderer`] (`frame/ic.rs`).
//!
//! Anti-aliasing: `sub_frames` jittered sub-frames (the centre, then the R2 sequence in
//! antithetic pairs) are composited and averaged, which box-filters edges like the reference.
//! Records persist across sub-frames (they are world-space), so later sub-frames mostly reuse the
//! first one's records and only fill the holes their jitter uncovers.

use std::collections::BTreeMap;

use radcache_cache::{IcParams, Preset};

use crate::technique::Technique;

pub use crate::technique::{
    EmitterLight, EmitterShadows, GlossyLight, GlossySpacing, PathGridMode, SkyLight,
    SpecularPaths, SplatMode,
};

/// Declares the settings struct with its fields in two groups, and generates the lists of the
/// groups' field names ([`IcSettings::CONFIG_FIELDS`], [`IcSettings::FRAME_FIELDS`]) and the
/// comparison of the `config` group ([`IcSettings::config_change`]) from the one declaration, so a
/// field added to the struct is classed, listed and compared without another edit.
macro_rules! settings_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident {
            config { $( $(#[$cmeta:meta])* $cfield:ident : $cty:ty $(=> $may:path)?, )* }
            techniques { $( $(#[$tmeta:meta])* $tfield:ident : $tty:ty, )* }
            per_frame { $( $(#[$fmeta:meta])* $ffield:ident : $fty:ty, )* }
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq)]
        pub struct $name {
            $( $(#[$cmeta])* pub $cfield: $cty, )*
            $( $(#[$tmeta])* pub $tfield: $tty, )*
            $( $(#[$fmeta])* pub $ffield: $fty, )*
        }

        impl $name {
            /// The fields that make the renderer (the technique switches among them): fixed for
            /// its lifetime.
            pub const CONFIG_FIELDS: &'static [&'static str] =
                &[$(stringify!($cfield),)* $(stringify!($tfield)),*];
            /// The technique switches: `config` fields that `radcache render --set KEY=VALUE`
            /// sets by their field name ([`Technique`]).
            pub const TECHNIQUES: &'static [&'static str] = &[$(stringify!($tfield)),*];
            /// The fields that may change from frame to frame.
            pub const FRAME_FIELDS: &'static [&'static str] = &[$(stringify!($ffield)),*];

            /// The first `config` field in which `self` differs from `made_with`, with both
            /// values as text (`made_with`'s first); `None` where every one is the same.
            pub fn config_change(&self, made_with: &$name) -> Option<ConfigChange> {
                $(
                    if !settings_struct!(@may made_with.$cfield, self.$cfield $(, $may)?) {
                        return Some(ConfigChange {
                            field: stringify!($cfield),
                            made_with: format!("{:?}", made_with.$cfield),
                            requested: format!("{:?}", self.$cfield),
                        });
                    }
                )*
                $(
                    if self.$tfield != made_with.$tfield {
                        return Some(ConfigChange {
                            field: stringify!($tfield),
                            made_with: made_with.$tfield.name().to_string(),
                            requested: self.$tfield.name().to_string(),
                        });
                    }
                )*
                None
            }

            /// Sets the technique switch `key` to the value named `value`; the error names
            /// the keys or the values there are.
            pub fn set_technique(&mut self, key: &str, value: &str) -> Result<(), String> {
                $(
                    if key == stringify!($tfield) {
                        return match <$tty as Technique>::parse(value) {
                            Some(v) => {
                                self.$tfield = v;
                                Ok(())
                            }
                            None => Err(format!(
                                "`{key}` has no value `{value}`: one of {}",
                                names(<$tty as Technique>::VALUES)
                            )),
                        };
                    }
                )*
                Err(format!(
                    "no technique switch `{key}`: one of {}",
                    Self::TECHNIQUES.join(", ")
                ))
            }

            /// Every technique switch with the name of its value in `self`.
            pub fn techniques(&self) -> Vec<(&'static str, &'static str)> {
                vec![$((stringify!($tfield), self.$tfield.name())),*]
            }

            /// Every technique switch: its key, one line on what it chooses, its default and
            /// its values.
            pub fn technique_help() -> Vec<TechniqueHelp> {
                vec![$(TechniqueHelp {
                    key: stringify!($tfield),
                    help: <$tty as Technique>::HELP,
                    default: <$tty>::default().name(),
                    values: <$tty as Technique>::VALUES.iter().map(|&(n, _)| n).collect(),
                }),*]
            }
        }
    };
    (@may $made:expr, $asked:expr) => {
        $made == $asked
    };
    (@may $made:expr, $asked:expr, $may:path) => {
        $may(&$made, &$asked)
    };
}

/// A renderer made with adaptive anti-aliasing (the composite sums the moments it needs) may
/// render a frame with another target or none (a warm-up frame); one made without may not take
/// it on.
fn anti_aliasing_may_become(made: &Option<AntiAliasing>, asked: &Option<AntiAliasing>) -> bool {
    made.is_some() || asked.is_none()
}

/// The names of `values`, comma-separated.
fn names<T>(values: &[(&'static str, T)]) -> String {
    values
        .iter()
        .map(|(n, _)| *n)
        .collect::<Vec<_>>()
        .join(", ")
}

/// One technique switch for `radcache render --set help` ([`IcSettings::technique_help`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TechniqueHelp {
    /// The key (the `IcSettings` field).
    pub key: &'static str,
    /// One line on what it chooses.
    pub help: &'static str,
    /// The default value's name.
    pub default: &'static str,
    /// Every value's name.
    pub values: Vec<&'static str>,
}

/// A `config` field of [`IcSettings`] that a frame asked to change ([`IcSettings::config_change`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ConfigChange {
    /// The field's name.
    pub field: &'static str,
    /// The value the renderer was made with.
    pub made_with: String,
    /// The value the frame asked for.
    pub requested: String,
}

impl std::fmt::Display for ConfigChange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the cache setting `{}` cannot change between frames: the renderer was made with {} \
             and this frame asks for {} (make a new renderer for it)",
            self.field, self.made_with, self.requested
        )
    }
}

settings_struct! {
    /// Settings of one frame rendered with the cache. Those under `config` and `techniques`
    /// make the renderer ([`crate::IcRenderer::new`] builds its passes, shader variants and
    /// buffers from them) and cannot change between its frames: a frame asking for another
    /// value is refused with an error naming the field ([`IcSettings::config_change`]). The
    /// `techniques` are the switches `radcache render --set KEY=VALUE` sets by field name
    /// ([`IcSettings::set_technique`]; a new one is an enum in `technique.rs` with its
    /// [`Technique`] names, a field here, and the pass that uses it). Those under `per_frame`
    /// may differ from frame to frame.
    pub struct IcSettings {
        config {
            /// Image width in pixels.
            width: u32,
            /// Image height in pixels.
            height: u32,
            /// Cache parameters (`IcParams::preset`).
            params: IcParams,
            /// Largest number of records (memory: 176 bytes each).
            record_capacity: u32,
            /// Repeat the cache phase until a pass over the sub-frames creates no record (see
            /// [`crate::IcRenderer::render`]), so that a next frame that keeps the records finds no hole
            /// where nothing changed (sequences; a single frame does not need it).
            settle_records: bool,
            /// Seconds from this frame to the next (`1 / fps`) when the scene's geometry or lights move
            /// and records are kept: records then follow their instances and carry temporal gradients
            /// and lifespans (`crate::passes::temporal`). 0 (the default) for a single frame or a scene whose
            /// lighting does not change.
            time_step_s: f32,
            /// Adaptive anti-aliasing ([`AntiAliasing`]): more sub-frames after the first `sub_frames`
            /// until the image's sampling error is estimated small enough. `None` (the default) shades
            /// exactly `sub_frames`. A renderer made with it renders frames with another target or
            /// none too (warm-up frames); one made without refuses it.
            anti_aliasing: Option<AntiAliasing> => anti_aliasing_may_become,
        }
        techniques {
            /// Where a constant environment's light (a sky) enters the frame: through the records
            /// (the default) or the direct pass.
            sky: SkyLight,
            /// How the direct pass estimates the light of emissive triangles.
            emitters: EmitterLight,
            /// How many shadow rays the closed-form emitters' light casts after the first sub-frame
            /// ([`EmitterShadows`]).
            emitter_shadows: EmitterShadows,
            /// Where glossy lobes take their indirect light from.
            glossy: GlossyLight,
            /// How records for glossy lobes from the cache are spaced.
            glossy_spacing: GlossySpacing,
            /// How often the records are splatted: once per frame (the default) or at every
            /// sub-frame.
            splat: SplatMode,
            /// Whether the gathers of new records share a radiance grid (docs/cache-frame.md §4.1).
            path_grid: PathGridMode,
            /// Whose paths a pixel's specular lobe takes its indirect light from (docs/materials.md
            /// §10).
            specular_paths: SpecularPaths,
        }
        per_frame {
            /// Jittered sub-frames averaged into the image (anti-aliasing; default 8: on the Cornell box at
            /// 256², 8 sub-frames halve the relMSE of 4 at the same number of direct samples, because
            /// edges dominate the error).
            sub_frames: u32,
            /// Direct-lighting samples per pixel and sub-frame (one ray each, one-sample MIS). Where
            /// the emitters' light is taken in closed form ([`EmitterLight::Analytic`]), a quarter of
            /// them (rounded up) are the emitters' shadow rays, which measured about the noise of all of
            /// them sampled with MIS (docs/cache-frame.md §8.2), and the rest go to the environment.
            direct_samples: u32,
            /// Seed of the random sequences.
            seed: u32,
            /// Frame number.
            frame: u32,
            /// Scene time in seconds.
            time: f32,
            /// Also produce the debug AOVs ([`IcDebug`]).
            debug_aovs: bool,
            /// Records kept across frames that weighed on no pixel for this many frames are evicted at
            /// the start of the next one (memory stays bounded over long sequences).
            evict_after_frames: u32,
        }
    }
}

/// Adaptive anti-aliasing of a frame rendered with the cache (docs/cache-frame.md §7.1): after
/// the `sub_frames` of the cache phase, the frame goes on shading jittered sub-frames (reusing
/// the records: no new record, no hole filling) while the relMSE that the sub-frame sampling
/// leaves in the mean image, estimated from each pixel's second moment
/// ([`crate::frame::aa::sampling_relmse`]), is above `target`, up to `max_sub_frames`. The
/// estimate sees what the sub-frames average (edges, textures, direct-light noise), not the
/// records' own error, which stays the same in every sub-frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AntiAliasing {
    /// The estimated sampling relMSE the frame stops at (`(c−r)²/(r²+0.01)` as
    /// `radcache compare`'s relMSE).
    pub target: f64,
    /// The most sub-frames a frame shades.
    pub max_sub_frames: u32,
    /// Per pixel (docs/cache-frame.md §7.2): the added sub-frames shade only the pixels whose
    /// own sampling error still needs samples ([`crate::frame::aa::plan_pixels`]); otherwise
    /// every pixel.
    pub per_pixel: bool,
}

impl AntiAliasing {
    /// The CLI's default for `preset`: a target about the preset's own error on the Cornell
    /// box at 256² (relMSE 3.4e-4 draft, 2.3e-4 default), so that a scene whose error the
    /// records dominate keeps its sub-frames and one whose edges dominate gets more; at most
    /// 64 sub-frames.
    pub fn preset(preset: Preset) -> Self {
        let target = match preset {
            Preset::Draft => 2e-3,
            Preset::Default => 5e-4,
            Preset::High => 2e-4,
        };
        AntiAliasing {
            target,
            max_sub_frames: 64,
            per_pixel: true,
        }
    }
}

impl IcSettings {
    /// The configuration `radcache render --quality` renders with: `preset`'s cache parameters
    /// and adaptive anti-aliasing ([`AntiAliasing::preset`]), every technique at its default.
    /// The CLI, `radcache convergence` and the benches start from it, so that they measure what
    /// a render renders; the size is the default's until set.
    pub fn preset(preset: Preset) -> IcSettings {
        IcSettings {
            params: IcParams::preset(preset),
            anti_aliasing: Some(AntiAliasing::preset(preset)),
            ..IcSettings::default()
        }
    }
}

impl Default for IcSettings {
    fn default() -> Self {
        IcSettings {
            width: 512,
            height: 512,
            params: IcParams::default(),
            sub_frames: 8,
            direct_samples: 16,
            seed: 0,
            frame: 1,
            time: 0.0,
            record_capacity: 1 << 18,
            debug_aovs: false,
            evict_after_frames: 60,
            settle_records: false,
            time_step_s: 0.0,
            sky: SkyLight::Records,
            emitters: EmitterLight::Analytic,
            emitter_shadows: EmitterShadows::Adaptive,
            glossy: GlossyLight::Records,
            glossy_spacing: GlossySpacing::Lobe,
            anti_aliasing: None,
            splat: SplatMode::Once,
            path_grid: PathGridMode::On,
            specular_paths: SpecularPaths::Pooled,
        }
    }
}

/// Cache figures of one frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IcStats {
    /// Records created at each level (summed over sub-frames), coarsest first.
    pub records_per_level: Vec<u64>,
    /// Records at the end of the frame.
    pub records: u64,
    /// Surface pixels left uncovered by the final splat (summed over the sub-frames that splat:
    /// the first alone with [`SplatMode::Once`]).
    pub holes_left: u64,
    /// With [`SplatMode::Once`]: samples of the later sub-frames that none of the four nearest
    /// centres matched (lit from the closest centre of their 3×3 neighbourhood, or unlit where
    /// no centre there is a surface), summed over the sub-frames.
    pub unmatched_samples: u64,
    /// Requests dropped because the record buffer was full.
    pub dropped_requests: u64,
    /// Records whose irradiance was invalid (stored as black).
    pub rejected_records: u64,
    /// Records kept from the previous frame (0 for a fresh cache).
    pub records_kept: u64,
    /// Records evicted at the start of the frame (unused for `evict_after_frames`).
    pub records_evicted: u64,
    /// Passes of the cache phase over the sub-frames (the last one created no record, unless
    /// the limit of 4 was reached).
    pub cache_passes: u32,
    /// Wall time of the hole-filling submissions (splat, holes, records, neighbours), s.
    pub hole_filling_s: f64,
    /// Wall time of the record-creation submissions alone (records and neighbours), s.
    pub record_pass_s: f64,
    /// Ray queries of the record pass (new records, refreshes and look-ahead evaluations).
    pub record_rays: u64,
    /// Records whose lifespan ended this frame, evaluated again (at their own points, one frame
    /// ahead) by the look-ahead.
    pub records_refreshed: u64,
    /// Ray queries of the look-ahead evaluations of the frame's new and expired records at the
    /// next frame's time (part of `record_rays`).
    pub lookahead_rays: u64,
    /// Wall time of each phase of the frame, s: `pipelines` (creating the passes, [`crate::render_ic`]
    /// only), `setup`, `cache_gbuffer`, `hole_selection`, `record_creation`, `shade`
    /// (G-buffer, direct, splat, composite), `emission`, `readback` (summed over sub-frames).
    /// Host-measured, so it holds on drivers whose timestamps miss asynchronous compute work.
    pub phases_s: BTreeMap<String, f64>,
    /// Sub-frames shaded (`sub_frames`, or more with adaptive anti-aliasing).
    pub sub_frames_shaded: u32,
    /// With adaptive anti-aliasing: the sampling relMSE estimated after the last sub-frame.
    pub aa_relmse_estimate: Option<f64>,
    /// The mean of the pixels' sub-frames: `sub_frames_shaded` unless per-pixel adaptive
    /// anti-aliasing stopped some pixels earlier (docs/cache-frame.md §7.2).
    pub mean_pixel_sub_frames: f64,
    /// The debug AOVs, when asked for.
    pub debug: Option<IcDebug>,
}

/// Debug AOVs of a cache frame (rows top to bottom, averaged over the sub-frames).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct IcDebug {
    /// Indirect radiance albedo/π·E only (RGB interleaved).
    pub indirect: Vec<f32>,
    /// Σw of the final splat.
    pub weight_sum: Vec<f32>,
    /// Records whose zone reaches the pixel.
    pub records_per_pixel: Vec<f32>,
    /// 1 at the pixels where records were created, 0 elsewhere (record positions).
    pub record_positions: Vec<f32>,
}

/// The sub-pixel jitter of sub-frame `k` in pixels: the centre first, then the R2 sequence
/// (Roberts 2018), which covers the pixel evenly for any count, in antithetic pairs: sub-frames
/// `2i − 1` and `2i` take R2 point `i` and its mirror image through the centre. Every odd count
/// of sub-frames is centred on the pixel and an even count `n` is off by `|p_{n/2}|/n` at most
/// `0.5/n` px, as the box-filtered reference. (The plain sequence's first 8 points have their
/// mean 0.108 px off-centre: the image moved by a tenth of a pixel, which on metal_spheres put
/// 40 % of the 8×8-block error into the two blocks across a sharp highlight; docs/cache-frame.md
/// §7.)
pub fn sub_frame_jitter(k: u32) -> [f32; 2] {
    if k == 0 {
        return [0.0, 0.0];
    }
    const G: f64 = 1.324_717_957_244_746;
    let (a1, a2) = (1.0 / G, 1.0 / (G * G));
    let i = f64::from(k.div_ceil(2));
    let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
    [
        (sign * (0.5 - (0.5 + a1 * i).fract())) as f32,
        (sign * (0.5 - (0.5 + a2 * i).fract())) as f32,
    ]
}

#[cfg(test)]
mod tests {
    use super::sub_frame_jitter;

    #[test]
    fn jitter_starts_at_the_centre_and_stays_in_the_pixel() {
        assert_eq!(sub_frame_jitter(0), [0.0, 0.0]);
        for k in 1..64 {
            let j = sub_frame_jitter(k);
            assert!(j.iter().all(|v| (-0.5..0.5).contains(v)), "{j:?}");
        }
        // The centre and the first R2 point share the (+, +) quadrant and its mirror image is
        // in (−, −), so four sub-frames cover three quadrants and five cover all four.
        let quadrants = |n: u32| -> std::collections::BTreeSet<(bool, bool)> {
            (0..n)
                .map(|k| {
                    let j = sub_frame_jitter(k);
                    (j[0] >= 0.0, j[1] >= 0.0)
                })
                .collect()
        };
        assert_eq!(quadrants(4).len(), 3, "{:?}", quadrants(4));
        assert_eq!(quadrants(5).len(), 4, "{:?}", quadrants(5));
    }

    #[test]
    fn jitters_are_centred_on_the_pixel() {
        // A box filter's samples must average to the pixel centre, or the image moves.
        let mean = |n: u32, c: usize| {
            (0..n)
                .map(|k| f64::from(sub_frame_jitter(k)[c]))
                .sum::<f64>()
                / f64::from(n)
        };
        for n in 1..=64u32 {
            let bound = if n % 2 == 1 {
                1e-6
            } else {
                0.5 / f64::from(n) + 1e-6
            };
            let (mx, my) = (mean(n, 0), mean(n, 1));
            assert!(
                mx.abs() <= bound && my.abs() <= bound,
                "n {n}: mean ({mx}, {my})"
            );
        }
        // The default 8 sub-frames: within 0.04 px of the centre (the plain R2 points: 0.108).
        let (mx, my) = (mean(8, 0), mean(8, 1));
        assert!(mx.abs() < 0.04 && my.abs() < 0.04, "{mx} {my}");
    }
}
