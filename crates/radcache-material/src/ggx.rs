//! The Trowbridge–Reitz (GGX) microfacet distribution and its Smith masking–shadowing terms
//! (`docs/materials.md` §3). Directions are in the local frame, `n = +Z`.

use glam::Vec3;

/// Smallest α used: glTF roughness 0 (a perfect mirror) is clamped to this value so that D,
/// the pdf and the sample weights stay finite (the peak of D is `1/(π α²) ≈ 3.2·10⁵`).
/// Declared in `radcache_shared::consts` (generated for GLSL).
pub use radcache_shared::consts::ALPHA_MIN;
use radcache_shared::consts::SMITH_LAMBDA_MASKED;

/// `α = roughness²` (glTF Appendix B), with roughness clamped to `[0, 1]` and α to
/// [`ALPHA_MIN`] from below.
pub fn alpha_from_roughness(roughness: f32) -> f32 {
    let r = roughness.clamp(0.0, 1.0);
    (r * r).max(ALPHA_MIN)
}

/// The GGX normal distribution of the microfacet normal `m` (a unit vector, local frame):
///
/// `D(m) = α² / (π ((n·m)²(α² − 1) + 1)²)` for `n·m > 0`, else 0,
///
/// evaluated as `1 / (π α² ((m_x² + m_y²)/α² + m_z²)²)`, which keeps its precision near `m = n`
/// for small α. Normalised so that `∫ D(m)(n·m) dm = 1`.
///
/// Sources: Walter, Marschner, Li, Torrance 2007 (eq. 33); glTF Appendix B (specular BRDF).
pub fn ggx_d(alpha: f32, m: Vec3) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = (m.x * m.x + m.y * m.y) / a2 + m.z * m.z;
    1.0 / (std::f32::consts::PI * a2 * t * t)
}

/// `sqrt(α² + (1 − α²) c²)`, the recurring term of Λ, G1 and V (`c` a cosine to `n`).
fn smith_root(alpha: f32, cos_theta: f32) -> f32 {
    let a2 = alpha * alpha;
    (a2 + (1.0 - a2) * cos_theta * cos_theta).sqrt()
}

/// Smith's Λ for GGX: `Λ(ω) = (−1 + sqrt(1 + α² tan²θ))/2 = (sqrt(α² + (1 − α²)c²)/c − 1)/2`,
/// `c = cosθ > 0` (Heitz 2014, GGX case). Returns `SMITH_LAMBDA_MASKED = f32::MAX` for `c <= 0`
/// (fully masked).
pub fn smith_lambda(alpha: f32, cos_theta: f32) -> f32 {
    if cos_theta <= 0.0 {
        return SMITH_LAMBDA_MASKED;
    }
    0.5 * (smith_root(alpha, cos_theta) / cos_theta - 1.0)
}

/// Smith's masking function `G1(ω) = 1/(1 + Λ(ω)) = 2c/(c + sqrt(α² + (1 − α²)c²))`,
/// 0 for `c <= 0` (Heitz 2014; Walter et al. 2007, eq. 34).
pub fn smith_g1(alpha: f32, cos_theta: f32) -> f32 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    2.0 * cos_theta / (cos_theta + smith_root(alpha, cos_theta))
}

/// The height-correlated Smith visibility term `V = G2/(4 |n·l| |n·v|)` with
/// `G2 = 1/(1 + Λ(v) + Λ(l))` (Heitz 2014, height-correlated form), in the glTF form (Appendix B):
///
/// `V = 0.5 / (n·l · sqrt(α² + (1 − α²)(n·v)²) + n·v · sqrt(α² + (1 − α²)(n·l)²))`.
///
/// 0 unless both `n·l > 0` and `n·v > 0`. The denominator is at least `α·max(n·l, n·v)`.
pub fn smith_v_correlated(alpha: f32, n_dot_l: f32, n_dot_v: f32) -> f32 {
    if n_dot_l <= 0.0 || n_dot_v <= 0.0 {
        return 0.0;
    }
    let denom = n_dot_l * smith_root(alpha, n_dot_v) + n_dot_v * smith_root(alpha, n_dot_l);
    if denom <= 0.0 {
        return 0.0;
    }
    0.5 / denom
}
