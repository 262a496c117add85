//! The technique switches of the cache's frame: which estimator or reuse each part of the frame
//! takes (`radcache render`'s technique options). They sit at the bottom of the crate so that the
//! passes that compile them into their shaders and the frame that chooses them both depend
//! downward on one definition (`IcSettings` holds the frame's choice of each).

/// Whose paths estimate a pixel's specular indirect light (scenes with specular materials;
/// docs/materials.md §10).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SpecularPaths {
    /// The pixel's own and those of the pixels of its 3×3 neighbourhood (within its 8×8
    /// workgroup) on its surface, of its material, whose lobes point within twice the lobe's
    /// width of its own: each weighed by the pixel's BRDF over the density it was drawn from.
    /// Unbiased but for the radiance being seen from a point a pixel away; up to nine times the
    /// paths per pixel for the rays of one.
    #[default]
    Pooled,
    /// The pixel's own paths alone.
    PerPixel,
}

/// How often a frame rendered with the cache splats its records (docs/cache-frame.md §6.5).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SplatMode {
    /// Once per frame, at the pixel centres (sub-frame 0, whose jitter is 0): every other
    /// sub-frame interpolates each sample's cached light between the four nearest centres
    /// that match it (the closest centre of its 3×3 neighbourhood where none does), and the
    /// cache phase fills the holes of the centres alone. The splat's cost no longer grows with
    /// the sub-frames.
    #[default]
    Once,
    /// At every sub-frame's own samples, and the cache phase fills the holes of every
    /// sub-frame: the exact per-sample interpolation, one splat per sub-frame.
    PerSubFrame,
}

/// Whether the gather paths of a frame's new records share a radiance grid
/// (docs/cache-frame.md §4.1; `shaders/common/path_grid.glsl`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum PathGridMode {
    /// Where the plan allows it (`ScenePlan::path_grid`: every material Lambertian), a gather
    /// path's vertex whose grid cell already holds enough continuations ends there with their
    /// mean, and the continuations from first hits fill the cells.
    #[default]
    On,
    /// Every gather path continues to its end (Russian roulette).
    Off,
}

/// How the records made for glossy lobes from the cache are spaced (docs/radiance-caching.md
/// §9); records of every other pixel are spaced by the irradiance alone either way.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum GlossySpacing {
    /// Their radius also obeys the glossy gradient limit (`GLOSSY_DENSITY`): density follows
    /// the incoming radiance's directional detail.
    #[default]
    Lobe,
    /// As every record: by the irradiance's rule alone.
    Irradiance,
}

/// Where the specular lobe's indirect light comes from in a frame rendered with the cache
/// (docs/radiance-caching.md §6).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum GlossyLight {
    /// Radiance records for lobes at or above `GLOSSY_ROUGHNESS_MIN`, where the plan has such
    /// materials; sharper lobes (and every lobe otherwise) as [`GlossyLight::Paths`].
    #[default]
    Records,
    /// As [`GlossyLight::Records`] with each record's coefficients taken as constant over its
    /// zone (no translational gradients): for measuring what the gradients bring
    /// (docs/radiance-caching.md §7).
    RecordsWithoutGradients,
    /// BRDF-sampled paths per pixel and sub-frame (docs/materials.md §10).
    Paths,
}

impl GlossyLight {
    /// Glossy lobes take their light from radiance records (with or without gradients).
    pub fn records(self) -> bool {
        matches!(
            self,
            GlossyLight::Records | GlossyLight::RecordsWithoutGradients
        )
    }
}

/// How the cache's direct pass estimates the light of emissive triangles (docs/cache-frame.md
/// §2.2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum EmitterLight {
    /// Where the plan allows it (`ScenePlan::analytic_emitters`: a few untextured emitters),
    /// the unshadowed light in closed form times the visible fraction of the light samples
    /// (the ratio estimator); elsewhere as [`EmitterLight::Sampled`].
    #[default]
    Analytic,
    /// One-sample MIS of light and BSDF sampling.
    Sampled,
}

impl EmitterLight {
    /// The shader define of `self` for a scene whose plan allows the closed form
    /// (`analytic_allowed`).
    pub fn define(self, analytic_allowed: bool) -> Option<(&'static str, &'static str)> {
        (self == EmitterLight::Analytic && analytic_allowed)
            .then_some(("HAS_ANALYTIC_EMITTERS", "1"))
    }
}

/// How many shadow rays the direct pass casts toward emitters whose light is in closed form
/// ([`EmitterLight::Analytic`]; docs/cache-frame.md §8.2) in the sub-frames after the first.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum EmitterShadows {
    /// Sub-frame 0 casts a quarter of the direct samples at every pixel and classes each pixel
    /// by what its 3×3 neighbourhood saw: the emitters wholly visible, wholly hidden, or a
    /// penumbra (dilated by the same neighbourhood). Later sub-frames cast one ray where the
    /// pixel was lit or hidden, where the ratio estimator is exact whatever the count, and a
    /// quarter of the samples in penumbrae; a sub-frame that sees a lit or hidden pixel
    /// otherwise than sub-frame 0 did marks it a penumbra. Where the pixel and all its 3×3
    /// neighbours saw the same at sub-frame 0 (the emitters, and each punctual light's shadow
    /// ray), later sub-frames take that answer and cast no ray.
    #[default]
    Adaptive,
    /// A quarter of the direct samples at every pixel and sub-frame.
    Fixed,
}

/// Where the light of a constant environment (a sky) enters a frame rendered with the cache
/// (docs/cache-frame.md §8.3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum SkyLight {
    /// The records' gathers count it on a first-segment miss and the direct pass leaves it
    /// out: the sky's smooth irradiance is interpolated like the indirect light, and the
    /// direct pass spends no ray on it (on the courtyard at 256², 16 of the 17 rays per pixel
    /// and sub-frame were sky rays; measured in `bench/results.csv`, case `sky_*`).
    #[default]
    Records,
    /// The direct pass samples it at every pixel (one-sample MIS with BSDF sampling), as it
    /// samples emitters.
    Direct,
}

impl SkyLight {
    /// The shader define of `self` for a scene with (`constant_env`) or without a constant
    /// environment: none unless the sky goes through the records of a scene that has one.
    pub fn define(self, constant_env: bool) -> Option<(&'static str, &'static str)> {
        (self == SkyLight::Records && constant_env).then_some(("IC_SKY_IN_RECORDS", "1"))
    }
}

/// A technique switch as `radcache render --set KEY=VALUE` names it: its values' names, one
/// line on what it chooses, and its default (the type's `Default`). The key is the
/// [`crate::IcSettings`] field that holds it.
pub trait Technique: Copy + Default + PartialEq + 'static {
    /// One line on what the switch chooses.
    const HELP: &'static str;
    /// Every value with its name, the default's among them.
    const VALUES: &'static [(&'static str, Self)];

    /// The value's name.
    fn name(self) -> &'static str {
        Self::VALUES
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("?", |(n, _)| n)
    }

    /// The value named `name`.
    fn parse(name: &str) -> Option<Self> {
        Self::VALUES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, v)| v)
    }
}

impl Technique for SpecularPaths {
    const HELP: &'static str =
        "whose paths a pixel's specular lobe takes its indirect light from (docs/materials.md §10)";
    const VALUES: &'static [(&'static str, Self)] =
        &[("pooled", Self::Pooled), ("per-pixel", Self::PerPixel)];
}

impl Technique for SplatMode {
    const HELP: &'static str = "how often the records are splatted (docs/cache-frame.md §6.5)";
    const VALUES: &'static [(&'static str, Self)] =
        &[("once", Self::Once), ("per-sub-frame", Self::PerSubFrame)];
}

impl Technique for PathGridMode {
    const HELP: &'static str =
        "whether the records' gather paths share a radiance grid (docs/cache-frame.md §4.1)";
    const VALUES: &'static [(&'static str, Self)] = &[("on", Self::On), ("off", Self::Off)];
}

impl Technique for GlossySpacing {
    const HELP: &'static str =
        "how records for glossy lobes are spaced (docs/radiance-caching.md §9)";
    const VALUES: &'static [(&'static str, Self)] =
        &[("lobe", Self::Lobe), ("irradiance", Self::Irradiance)];
}

impl Technique for GlossyLight {
    const HELP: &'static str =
        "where glossy lobes take their indirect light from (docs/radiance-caching.md §6)";
    const VALUES: &'static [(&'static str, Self)] = &[
        ("records", Self::Records),
        ("records-no-gradients", Self::RecordsWithoutGradients),
        ("paths", Self::Paths),
    ];
}

impl Technique for EmitterLight {
    const HELP: &'static str =
        "how the direct pass estimates emissive triangles' light (docs/cache-frame.md §2.2)";
    const VALUES: &'static [(&'static str, Self)] =
        &[("analytic", Self::Analytic), ("sampled", Self::Sampled)];
}

impl Technique for EmitterShadows {
    const HELP: &'static str =
        "how many shadow rays the lights cast after sub-frame 0 (docs/cache-frame.md §8.2)";
    const VALUES: &'static [(&'static str, Self)] =
        &[("adaptive", Self::Adaptive), ("fixed", Self::Fixed)];
}

impl Technique for SkyLight {
    const HELP: &'static str =
        "where a constant environment's light enters the frame (docs/cache-frame.md §8.3)";
    const VALUES: &'static [(&'static str, Self)] =
        &[("records", Self::Records), ("direct", Self::Direct)];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<T: Technique + std::fmt::Debug>() {
        assert!(T::VALUES.iter().any(|&(_, v)| v == T::default()));
        for &(name, value) in T::VALUES {
            assert_eq!(T::parse(name), Some(value));
            assert_eq!(value.name(), name);
        }
        assert_eq!(T::parse("no-such-value"), None);
    }

    #[test]
    fn every_value_is_named_once_and_parses_back() {
        check::<SpecularPaths>();
        check::<SplatMode>();
        check::<PathGridMode>();
        check::<GlossySpacing>();
        check::<GlossyLight>();
        check::<EmitterLight>();
        check::<EmitterShadows>();
        check::<SkyLight>();
    }
}
