//! KHR_lights_punctual lights, in the extension's photometric units treated as radiometric
//! (the renderer works in linear RGB "watts"; no 683 lm/W conversion is applied):
//!
//! - point and spot `intensity` is luminous intensity *I* (candela ≈ W/sr),
//! - directional `intensity` is illuminance *E* (lux ≈ W/m²) on a surface facing the light.
//!
//! Lights sit at their node's world position and shine down the node's local −Z axis.
//!
//! **Irradiance formula** ([`WorldLight::illuminate`]), the CPU twin of the GPU code: at a point at
//! distance *d* from a point/spot light, the irradiance on a surface facing the light is
//!
//! `E⊥ = I · color / d² · window(d) · spot(cosθ)`, with
//! `window(d) = clamp(1 − (d/range)⁴, 0, 1)` (1 when range is infinite), and for spots
//! `scale = 1 / max(0.001, cos(inner) − cos(outer))`, `offset = −cos(outer) · scale`,
//! `spot = clamp(cosθ · scale + offset, 0, 1)²` where θ is the angle between the spot axis and the
//! direction from the light to the point (the glTF spec's recommended falloff). Directional:
//! `E⊥ = intensity · color`. The surface's irradiance is `E⊥ · max(0, n·wi)`.

use glam::{Mat4, Vec3};

use crate::error::{label, Error, Result};
use crate::resources::Source;

/// The kind of a punctual light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Point light (intensity in cd).
    Point,
    /// Spot light (intensity in cd), cone angles in radians from the axis.
    Spot {
        /// Angle where the falloff starts.
        inner_cone_angle: f32,
        /// Angle where the light reaches zero.
        outer_cone_angle: f32,
    },
    /// Directional light (intensity in lx).
    Directional,
}

/// A light definition (glTF `KHR_lights_punctual.lights[i]`).
#[derive(Clone, Debug, PartialEq)]
pub struct PunctualLight {
    /// Light name.
    pub name: Option<String>,
    /// Kind and cone angles.
    pub kind: LightKind,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity: candela (point/spot) or lux (directional).
    pub intensity: f32,
    /// Cut-off distance in metres; `None` = infinite.
    pub range: Option<f32>,
}

/// A light placed by a node (a light may be referenced by several nodes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightInstance {
    /// Index into `Scene::lights`.
    pub light: usize,
    /// Index into `Scene::nodes`.
    pub node: usize,
    /// True when the node's world transform changes over the animation range.
    pub dynamic: bool,
}

/// A light in world space at some time.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldLight {
    /// Kind and cone angles.
    pub kind: LightKind,
    /// Linear RGB colour.
    pub color: Vec3,
    /// Intensity: candela (point/spot) or lux (directional).
    pub intensity: f32,
    /// Cut-off distance; `None` = infinite.
    pub range: Option<f32>,
    /// World position (unused for directional lights).
    pub position: Vec3,
    /// Unit world direction the light shines towards (node's −Z).
    pub direction: Vec3,
}

/// Light arriving at a point from a punctual light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the point towards the light.
    pub wi: Vec3,
    /// Distance to the light (`f32::INFINITY` for directional lights).
    pub distance: f32,
    /// Irradiance on a surface facing the light, W/m² per RGB channel.
    pub irradiance: Vec3,
}

/// The spec's range window `clamp(1 − (d/range)⁴, 0, 1)` (1 for an infinite range).
pub fn range_window(distance: f32, range: Option<f32>) -> f32 {
    match range {
        Some(r) if r > 0.0 => (1.0 - (distance / r).powi(4)).clamp(0.0, 1.0),
        _ => 1.0,
    }
}

/// The spec's smooth spot falloff for `cos_theta` (angle from the spot axis).
pub fn spot_falloff(cos_theta: f32, inner_cone_angle: f32, outer_cone_angle: f32) -> f32 {
    let scale = 1.0 / (inner_cone_angle.cos() - outer_cone_angle.cos()).max(0.001);
    let offset = -outer_cone_angle.cos() * scale;
    let a = (cos_theta * scale + offset).clamp(0.0, 1.0);
    a * a
}

impl WorldLight {
    /// Places `light` with a node's world transform.
    pub fn new(light: &PunctualLight, world_from_node: &Mat4) -> WorldLight {
        WorldLight {
            kind: light.kind,
            color: light.color,
            intensity: light.intensity,
            range: light.range,
            position: world_from_node.transform_point3(Vec3::ZERO),
            direction: world_from_node
                .transform_vector3(-Vec3::Z)
                .normalize_or(-Vec3::Z),
        }
    }

    /// Light arriving at world point `p` (see the module docs for the formula).
    pub fn illuminate(&self, p: Vec3) -> LightSample {
        if self.kind == LightKind::Directional {
            return LightSample {
                wi: -self.direction,
                distance: f32::INFINITY,
                irradiance: self.color * self.intensity,
            };
        }
        let to_light = self.position - p;
        let d = to_light.length();
        if d <= 0.0 {
            return LightSample {
                wi: Vec3::Z,
                distance: 0.0,
                irradiance: Vec3::ZERO,
            };
        }
        let wi = to_light / d;
        let mut scale = self.intensity / (d * d) * range_window(d, self.range);
        if let LightKind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } = self.kind
        {
            scale *= spot_falloff(self.direction.dot(-wi), inner_cone_angle, outer_cone_angle);
        }
        LightSample {
            wi,
            distance: d,
            irradiance: self.color * scale,
        }
    }
}

/// Loads the document's light definitions (empty without the extension). Values the extension
/// forbids are errors naming the light: a negative or non-finite intensity or colour component,
/// and spot cones outside `0 ≤ inner < outer ≤ π/2`.
pub(crate) fn load_lights(src: &Source) -> Result<Vec<PunctualLight>> {
    let Some(lights) = src.doc.lights() else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    for l in lights {
        let invalid = |reason: String| Error::Invalid {
            path: src.path(),
            element: label("KHR_lights_punctual light", l.index(), l.name()),
            reason,
        };
        let kind = match l.kind() {
            gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
            gltf::khr_lights_punctual::Kind::Directional => LightKind::Directional,
            gltf::khr_lights_punctual::Kind::Spot {
                inner_cone_angle,
                outer_cone_angle,
            } => {
                let ok = inner_cone_angle >= 0.0
                    && inner_cone_angle < outer_cone_angle
                    && outer_cone_angle <= std::f32::consts::FRAC_PI_2 + 1e-6;
                if !ok {
                    return Err(invalid(format!(
                        "spot cone angles must satisfy 0 <= inner ({inner_cone_angle}) < outer ({outer_cone_angle}) <= pi/2"
                    )));
                }
                LightKind::Spot {
                    inner_cone_angle,
                    outer_cone_angle,
                }
            }
        };
        let color = Vec3::from(l.color());
        if !color.is_finite() || color.min_element() < 0.0 {
            return Err(invalid(format!(
                "colour {color} must be finite and non-negative"
            )));
        }
        let intensity = l.intensity();
        if !intensity.is_finite() || intensity < 0.0 {
            return Err(invalid(format!(
                "intensity {intensity} must be finite and non-negative"
            )));
        }
        out.push(PunctualLight {
            name: l.name().map(str::to_string),
            kind,
            color,
            intensity,
            range: l.range().filter(|r| *r > 0.0 && r.is_finite()),
        });
    }
    Ok(out)
}
