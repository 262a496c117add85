//! `KHR_texture_transform`: the 2×3 matrix a texture reference applies to its texture
//! coordinates (docs/materials.md §13), and the reading of its JSON object.

use glam::Vec2;

/// `KHR_texture_transform` of a texture reference: `uv' = T · R · S · (u, v, 1)` with `S` the
/// scale, `T` the offset and `R` the rotation by `rotation` radians (docs/materials.md §13).
///
/// **The rotation's sign.** The specification says the rotation turns the UVs "counter-clockwise
/// around the origin", equivalent to turning the image clockwise, in glTF's texture space (u
/// right, v down: the origin is the image's top-left corner). As seen in that space, that is
/// `R = [[cos, sin], [−sin, cos]]` (rows): `u' = cos·u + sin·v`, `v' = −sin·u + cos·v`. This is
/// what the specification's own example needs ("offset [0, 1], rotation π/2, scale [0.5, 0.5]
/// uses only the lower left quadrant of the image, rotated clockwise 90°") and what the Khronos
/// sample viewer and the TextureTransformTest sample model use. The GLSL listing in the
/// specification, `mat3(cos, sin, 0, −sin, cos, 0, 0, 0, 1)` (column-major), reads as the
/// transposed matrix, the counter-clockwise turn of a v-up frame; it contradicts the example and
/// the implementations (KhronosGroup/glTF issue 1563), and is not followed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureTransform {
    /// `offset` (default `[0, 0]`).
    pub offset: Vec2,
    /// `rotation` in radians (default 0).
    pub rotation: f32,
    /// `scale` (default `[1, 1]`).
    pub scale: Vec2,
}

impl Default for TextureTransform {
    fn default() -> Self {
        TextureTransform::IDENTITY
    }
}

impl TextureTransform {
    /// No transform: offset 0, rotation 0, scale 1.
    pub const IDENTITY: TextureTransform = TextureTransform {
        offset: Vec2::ZERO,
        rotation: 0.0,
        scale: Vec2::ONE,
    };

    /// True when the transform leaves every texture coordinate as it is.
    pub fn is_identity(&self) -> bool {
        self.matrix() == TextureTransform::IDENTITY.matrix()
    }

    /// The two rows of the 2×3 matrix `T · R · S`: `u' = m[0]·(u, v, 1)`, `v' = m[1]·(u, v, 1)`.
    pub fn matrix(&self) -> [[f32; 3]; 2] {
        let (s, c) = self.rotation.sin_cos();
        let (sx, sy) = (self.scale.x, self.scale.y);
        [
            [c * sx, s * sy, self.offset.x],
            [-s * sx, c * sy, self.offset.y],
        ]
    }

    /// `uv` transformed: `T · R · S · (u, v, 1)`.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [r0, r1] = self.matrix();
        Vec2::new(
            r0[0] * uv.x + r0[1] * uv.y + r0[2],
            r1[0] * uv.x + r1[1] * uv.y + r1[2],
        )
    }
}

/// Reads a `KHR_texture_transform` JSON object: the transform and its `texCoord` override, or
/// what is wrong with it.
pub(crate) fn parse_transform(
    v: &serde_json::Value,
) -> std::result::Result<(TextureTransform, Option<u32>), String> {
    let Some(obj) = v.as_object() else {
        return Err("is not an object".into());
    };
    let number = |key: &str, x: &serde_json::Value| {
        x.as_f64()
            .map(|x| x as f32)
            .ok_or_else(|| format!("{key} is not a number"))
    };
    let pair = |key: &str, default: Vec2| -> std::result::Result<Vec2, String> {
        match obj.get(key) {
            None => Ok(default),
            Some(serde_json::Value::Array(a)) if a.len() == 2 => {
                Ok(Vec2::new(number(key, &a[0])?, number(key, &a[1])?))
            }
            Some(_) => Err(format!("{key} is not an array of two numbers")),
        }
    };
    let rotation = match obj.get("rotation") {
        None => 0.0,
        Some(x) => number("rotation", x)?,
    };
    let tex_coord = match obj.get("texCoord") {
        None => None,
        Some(x) => Some(
            x.as_u64()
                .and_then(|t| u32::try_from(t).ok())
                .ok_or("texCoord is not a non-negative integer")?,
        ),
    };
    let transform = TextureTransform {
        offset: pair("offset", Vec2::ZERO)?,
        rotation,
        scale: pair("scale", Vec2::ONE)?,
    };
    Ok((transform, tex_coord))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec2, b: Vec2) {
        assert!((a - b).abs().max_element() < 1e-6, "{a} against {b}");
    }

    #[test]
    fn the_transform_is_translation_rotation_scale() {
        let t = TextureTransform {
            offset: Vec2::new(0.25, -0.5),
            rotation: 0.3,
            scale: Vec2::new(2.0, 0.5),
        };
        let (s, c) = 0.3f32.sin_cos();
        for uv in [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::new(0.7, -1.3)] {
            // S, then R (u' = cos·u + sin·v, v' = −sin·u + cos·v), then T.
            let scaled = uv * Vec2::new(2.0, 0.5);
            let rotated = Vec2::new(c * scaled.x + s * scaled.y, -s * scaled.x + c * scaled.y);
            close(t.apply(uv), rotated + Vec2::new(0.25, -0.5));
        }
        assert!(TextureTransform::IDENTITY.is_identity() && !t.is_identity());
        close(
            TextureTransform::IDENTITY.apply(Vec2::new(0.3, 0.9)),
            Vec2::new(0.3, 0.9),
        );
    }

    #[test]
    fn the_specification_example_uses_the_lower_left_quadrant_turned_clockwise() {
        // KHR_texture_transform's example: offset [0, 1], rotation π/2, scale [0.5, 0.5] "utilizes
        // only the lower left quadrant of the source image, rotated clockwise 90°" (v down).
        let t = TextureTransform {
            offset: Vec2::new(0.0, 1.0),
            rotation: std::f32::consts::FRAC_PI_2,
            scale: Vec2::splat(0.5),
        };
        // The unit square's corners land on the lower left quadrant's: u' = v/2, v' = 1 − u/2.
        close(t.apply(Vec2::new(0.0, 0.0)), Vec2::new(0.0, 1.0));
        close(t.apply(Vec2::new(1.0, 0.0)), Vec2::new(0.0, 0.5));
        close(t.apply(Vec2::new(1.0, 1.0)), Vec2::new(0.5, 0.5));
        close(t.apply(Vec2::new(0.0, 1.0)), Vec2::new(0.5, 1.0));
        // Rotating the UVs counter-clockwise as seen in texture space (v down): +u turns to −v.
        let r = TextureTransform {
            rotation: std::f32::consts::FRAC_PI_2,
            ..TextureTransform::IDENTITY
        };
        close(r.apply(Vec2::X), Vec2::new(0.0, -1.0));
        close(r.apply(Vec2::Y), Vec2::new(1.0, 0.0));
    }

    #[test]
    fn raw_transforms_are_parsed_with_their_defaults_and_checked() {
        let json = serde_json::json!({"offset": [0.5, 0.25], "rotation": 1.0, "scale": [2, 3], "texCoord": 1});
        let (t, set) = parse_transform(&json).unwrap();
        assert_eq!(
            (t.offset, t.rotation, t.scale, set),
            (Vec2::new(0.5, 0.25), 1.0, Vec2::new(2.0, 3.0), Some(1))
        );
        let (t, set) = parse_transform(&serde_json::json!({})).unwrap();
        assert_eq!((t, set), (TextureTransform::IDENTITY, None));
        for bad in [
            serde_json::json!([1, 2]),
            serde_json::json!({"offset": [1]}),
            serde_json::json!({"scale": "big"}),
            serde_json::json!({"rotation": [0]}),
            serde_json::json!({"texCoord": -1}),
            serde_json::json!({"texCoord": 0.5}),
        ] {
            assert!(parse_transform(&bad).is_err(), "{bad}");
        }
    }
}
