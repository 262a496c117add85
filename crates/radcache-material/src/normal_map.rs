//! Normal mapping (`docs/materials.md` §12): the shading normal from a tangent-space normal-map
//! texel, with the guards that keep it usable. Unlike the rest of the crate this works in world
//! space: the inputs are the surface's normals and tangent as the renderer has them.

use glam::{Vec3, Vec4};

/// Declared in `radcache_shared::consts` (generated for GLSL).
pub use radcache_shared::consts::NORMAL_MAP_COS_MIN;

/// A unit vector perpendicular to the unit vector `n` (the tangent used where the vertex tangent
/// is unusable): `n × x̂`, or `n × ŷ` when `n` is near the x axis.
pub fn normal_map_perpendicular(n: Vec3) -> Vec3 {
    let a = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    n.cross(a).normalize()
}

/// The tangent-space normal of a linear texel `rgb` in `[0, 1]`: `2·rgb − 1`, x and y times
/// `scale` (glTF `normalTexture.scale`). Not normalized.
pub fn normal_map_decode(texel: Vec3, scale: f32) -> Vec3 {
    let m = texel * 2.0 - Vec3::ONE;
    Vec3::new(m.x * scale, m.y * scale, m.z)
}

/// The shading normal at a point with unit interpolated normal `n`, unit geometric normal `ng`
/// (on the same side of the surface: both outward, or both flipped), tangent `tangent` (xyz in
/// the same space, any length; w its handedness, with a mirroring transform's sign already
/// applied; w = 0 is taken as +1) and normal-map texel `texel` (linear) with `scale`:
///
/// 1. `n` on the far side of `ng` (`n·ng ≤ 0`) is replaced by `ng`, as without a normal map;
/// 2. the tangent is made perpendicular to `n` (Gram–Schmidt) and normalized; when nothing is
///    left of it, [`normal_map_perpendicular`] takes its place;
/// 3. bitangent `b = (n × t)·sign(w)`, and `ns = normalize(t·x + b·y + n·z)` with `(x, y, z)` =
///    [`normal_map_decode`]; a zero or non-finite result gives `n`;
/// 4. `ns·ng = c < ε = NORMAL_MAP_COS_MIN` is bent toward `ng`: `normalize(ns + (ε − c)·ng)`,
///    whose cosine to `ng` is `ε/√(1 − c² + ε²) ≥ ε/√(1 + ε²)` (never zero, never past `ng`).
pub fn normal_map_normal(n: Vec3, ng: Vec3, tangent: Vec4, texel: Vec3, scale: f32) -> Vec3 {
    let n = if n.dot(ng) > 0.0 { n } else { ng };
    let t_in = tangent.truncate();
    let t = t_in - n * n.dot(t_in);
    let len = t.length();
    let t = if len > 1e-6 * t_in.length() {
        t / len
    } else {
        normal_map_perpendicular(n)
    };
    let sign = if tangent.w < 0.0 { -1.0 } else { 1.0 };
    let b = n.cross(t) * sign;
    let m = normal_map_decode(texel, scale);
    let mapped = t * m.x + b * m.y + n * m.z;
    let l = mapped.length();
    let ns = if l > 0.0 && l.is_finite() {
        mapped / l
    } else {
        n
    };
    let c = ns.dot(ng);
    if c < NORMAL_MAP_COS_MIN {
        let bent = ns + ng * (NORMAL_MAP_COS_MIN - c);
        bent / bent.length()
    } else {
        ns
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: Vec4 = Vec4::new(1.0, 0.0, 0.0, 1.0);

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-6
    }

    #[test]
    fn a_flat_texel_or_scale_zero_keeps_the_interpolated_normal() {
        let n = Vec3::new(0.1, 1.0, -0.2).normalize();
        let flat = Vec3::new(0.5, 0.5, 1.0);
        for (ng, t) in [
            (Vec3::Y, T),
            (Vec3::new(0.0, 0.8, 0.6), Vec4::new(0.3, -0.1, 2.0, -1.0)),
        ] {
            assert!(close(normal_map_normal(n, ng, t, flat, 1.0), n));
            assert!(close(normal_map_normal(n, ng, t, flat, 3.0), n));
            let tilted = Vec3::new(0.9, 0.2, 0.6);
            assert!(close(normal_map_normal(n, ng, t, tilted, 0.0), n));
        }
    }

    #[test]
    fn a_tilted_texel_tilts_by_its_angle() {
        // (sin θ, 0, cos θ) in tangent space, tangent +x, normal +y: the normal tilts toward +x
        // by θ; with the bitangent (−z for w = +1, +z for w = −1) a y component tilts along it.
        for theta in [0.1f32, 0.35, 0.7, 1.2] {
            let texel = (Vec3::new(theta.sin(), 0.0, theta.cos()) + Vec3::ONE) * 0.5;
            let ns = normal_map_normal(Vec3::Y, Vec3::Y, T, texel, 1.0);
            let want = Vec3::new(theta.sin(), theta.cos(), 0.0);
            assert!(close(ns, want), "θ {theta}: {ns} != {want}");
            let texel = (Vec3::new(0.0, theta.sin(), theta.cos()) + Vec3::ONE) * 0.5;
            let up = normal_map_normal(Vec3::Y, Vec3::Y, T, texel, 1.0);
            assert!(close(up, Vec3::new(0.0, theta.cos(), -theta.sin())), "{up}");
            let mirrored =
                normal_map_normal(Vec3::Y, Vec3::Y, T * Vec4::new(1., 1., 1., -1.), texel, 1.0);
            assert!(
                close(mirrored, Vec3::new(0.0, theta.cos(), theta.sin())),
                "{mirrored}"
            );
        }
        // The scale multiplies x and y: tan θ' = scale · tan θ.
        let texel = (Vec3::new(0.6, 0.0, 0.8) + Vec3::ONE) * 0.5;
        let ns = normal_map_normal(Vec3::Y, Vec3::Y, T, texel, 0.5);
        assert!((ns.x / ns.y - 0.5 * 0.75).abs() < 1e-6, "{ns}");
    }

    #[test]
    fn the_tangent_is_made_perpendicular_to_the_normal() {
        // A tangent leaning out of the tangent plane gives the same frame as its projection.
        let texel = Vec3::new(0.8, 0.3, 0.7);
        let a = normal_map_normal(Vec3::Y, Vec3::Y, Vec4::new(2.0, 1.5, 0.0, 1.0), texel, 1.0);
        let b = normal_map_normal(Vec3::Y, Vec3::Y, T, texel, 1.0);
        assert!(close(a, b), "{a} != {b}");
        // Parallel to the normal, zero or NaN: a perpendicular instead, still a unit normal.
        for bad in [
            Vec4::new(0.0, 2.0, 0.0, 1.0),
            Vec4::ZERO,
            Vec4::splat(f32::NAN),
        ] {
            let ns = normal_map_normal(Vec3::Y, Vec3::Y, bad, texel, 1.0);
            assert!(
                ns.is_finite() && (ns.length() - 1.0).abs() < 1e-6,
                "{bad}: {ns}"
            );
            assert!(
                (ns.y - b.y).abs() < 1e-6,
                "same tilt from the normal: {ns} vs {b}"
            );
        }
    }

    #[test]
    fn the_shading_normal_stays_on_the_geometric_side() {
        let ng = Vec3::Y;
        // Texels pointing sideways and into the surface, big scales, a normal past the horizon.
        for texel in [
            Vec3::new(1.0, 0.5, 0.5),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(1.0, 1.0, 0.6),
        ] {
            for scale in [1.0f32, 10.0, -4.0, 1e30] {
                for n in [
                    Vec3::Y,
                    Vec3::new(0.0, -0.6, 0.8),
                    Vec3::new(0.99, 0.141, 0.0),
                ] {
                    let ns = normal_map_normal(n.normalize(), ng, T, texel, scale);
                    assert!(ns.is_finite(), "{texel} {scale} {n}: {ns}");
                    assert!((ns.length() - 1.0).abs() < 1e-5, "{ns}");
                    let e = NORMAL_MAP_COS_MIN;
                    let least = e / (1.0 + e * e).sqrt() - 1e-6;
                    assert!(ns.dot(ng) >= least, "{texel} {scale}: {ns}");
                }
            }
        }
        // Within the limit a tilt is kept as it is.
        let texel = (Vec3::new(0.99, 0.0, 0.141) + Vec3::ONE) * 0.5;
        let ns = normal_map_normal(Vec3::Y, ng, T, texel, 1.0);
        assert!(ns.y > 0.1 && ns.y < 0.2, "{ns}");
    }
}
