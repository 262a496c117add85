//! Node TRS animation (glTF `animations`), sampled on the CPU.
//!
//! - LINEAR: component-wise lerp for translation/scale, shortest-path slerp for rotation.
//! - STEP: the value of the last key at or before `t`.
//! - CUBICSPLINE: per the glTF spec, each key stores (in-tangent aₖ, value vₖ, out-tangent bₖ) and
//!   with `Δ = tₖ₊₁ − tₖ`, `s = (t − tₖ)/Δ`:
//!   `p(s) = (2s³−3s²+1)vₖ + Δ(s³−2s²+s)bₖ + (−2s³+3s²)vₖ₊₁ + Δ(s³−s²)aₖ₊₁`.
//! - Rotation results are normalized; times outside the key range clamp to the first/last value.
//!
//! All animations of the file play together on one timeline; the scene time range is the union of
//! all channels' key ranges. Morph-weight channels are ignored (warning).

use glam::{Quat, Vec4};

use crate::accessor;
use crate::error::{label, Error, Result, WarningKind, Warnings};
use crate::math::Trs;
use crate::resources::Source;

/// Keyframe interpolation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// Linear (slerp for rotations).
    Linear,
    /// Piecewise constant.
    Step,
    /// Cubic Hermite spline with in/out tangents.
    CubicSpline,
}

/// The animated node property.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Property {
    /// Translation (xyz).
    Translation,
    /// Rotation quaternion (xyzw).
    Rotation,
    /// Scale (xyz).
    Scale,
}

/// Keyframes of one channel. Vec3 values are stored in `xyz` of a `Vec4`.
#[derive(Clone, Debug, PartialEq)]
pub struct Sampler {
    /// Interpolation mode.
    pub interpolation: Interpolation,
    /// Strictly increasing key times in seconds (at least one).
    pub times: Vec<f32>,
    /// One value per key, or three (in-tangent, value, out-tangent) for CUBICSPLINE.
    pub values: Vec<Vec4>,
}

/// A channel: a sampler driving one property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Target node index.
    pub node: usize,
    /// Target property.
    pub property: Property,
    /// Keyframes.
    pub sampler: Sampler,
}

/// A glTF animation.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Animation name.
    pub name: Option<String>,
    /// Its TRS channels.
    pub channels: Vec<Channel>,
}

fn quat(v: Vec4) -> Quat {
    Quat::from_vec4(v).normalize()
}

impl Sampler {
    /// First and last key times.
    pub fn time_range(&self) -> (f32, f32) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    fn value(&self, k: usize) -> Vec4 {
        match self.interpolation {
            Interpolation::CubicSpline => self.values[3 * k + 1],
            _ => self.values[k],
        }
    }

    /// True when sampling gives the same value at every time.
    pub fn is_constant(&self) -> bool {
        let v0 = self.value(0);
        (0..self.times.len()).all(|k| self.value(k) == v0)
            && (self.interpolation != Interpolation::CubicSpline
                || (0..self.times.len()).all(|k| {
                    self.values[3 * k] == Vec4::ZERO && self.values[3 * k + 2] == Vec4::ZERO
                }))
    }

    /// The value at time `t` (rotations normalized when `property` is `Rotation`).
    pub fn sample(&self, t: f32, property: Property) -> Vec4 {
        let n = self.times.len();
        let fix = |v: Vec4| {
            if property == Property::Rotation {
                Vec4::from(quat(v))
            } else {
                v
            }
        };
        if n == 1 || t.is_nan() || t <= self.times[0] {
            return fix(self.value(0));
        }
        if t >= self.times[n - 1] {
            return fix(self.value(n - 1));
        }
        let k = self
            .times
            .partition_point(|&x| x <= t)
            .saturating_sub(1)
            .min(n - 2);
        let dt = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / dt;
        match self.interpolation {
            Interpolation::Step => fix(self.value(k)),
            Interpolation::Linear => {
                let (a, b) = (self.value(k), self.value(k + 1));
                if property == Property::Rotation {
                    Vec4::from(quat(a).slerp(quat(b), s).normalize())
                } else {
                    a.lerp(b, s)
                }
            }
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let v0 = self.values[3 * k + 1];
                let b0 = self.values[3 * k + 2];
                let a1 = self.values[3 * (k + 1)];
                let v1 = self.values[3 * (k + 1) + 1];
                let p = v0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + b0 * (dt * (s3 - 2.0 * s2 + s))
                    + v1 * (-2.0 * s3 + 3.0 * s2)
                    + a1 * (dt * (s3 - s2));
                fix(p)
            }
        }
    }
}

impl Channel {
    /// Overwrites the channel's property of `trs` with its value at `t`.
    pub fn apply(&self, t: f32, trs: &mut Trs) {
        let v = self.sampler.sample(t, self.property);
        match self.property {
            Property::Translation => trs.translation = v.truncate(),
            Property::Rotation => trs.rotation = Quat::from_vec4(v),
            Property::Scale => trs.scale = v.truncate(),
        }
    }
}

/// Loads all animations, checking channel targets against the node list.
pub(crate) fn load_animations(src: &Source, warnings: &mut Warnings) -> Result<Vec<Animation>> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for anim in src.doc.animations() {
        let anim_label = label("animation", anim.index(), anim.name());
        let mut channels = Vec::new();
        // Channel targets are read from the JSON: gltf 1.4 does not validate them and its
        // `Target::node`/`property` unwrap.
        let json_channels = src
            .doc
            .as_json()
            .animations
            .get(anim.index())
            .map_or(&[][..], |a| &a.channels[..]);
        for (ci, ch) in json_channels.iter().enumerate() {
            let user = format!("{anim_label} channel {ci}");
            let invalid = |reason: String| Error::Invalid {
                path: src.path(),
                element: user.clone(),
                reason,
            };
            let node = ch.target.node.value();
            if node >= src.doc.nodes().len() {
                return Err(invalid(format!("target node {node} does not exist")));
            }
            let Some(sampler) = anim.samplers().nth(ch.sampler.value()) else {
                return Err(invalid(format!(
                    "sampler {} does not exist",
                    ch.sampler.value()
                )));
            };
            use gltf::json::animation::Property as P;
            use gltf::json::validation::Checked;
            let property = match ch.target.path {
                Checked::Valid(P::Translation) => Property::Translation,
                Checked::Valid(P::Rotation) => Property::Rotation,
                Checked::Valid(P::Scale) => Property::Scale,
                Checked::Invalid => return Err(invalid("invalid target path".into())),
                Checked::Valid(P::MorphTargetWeights) => {
                    let msg = format!(
                        "{}: {user}: morph weights channel ignored",
                        src.path.display()
                    );
                    warnings.push(WarningKind::WeightsChannelIgnored, 1, msg);
                    continue;
                }
            };
            if !seen.insert((node, property)) {
                let msg = format!("{}: {user}: node {node} {property:?} is animated twice; the later channel wins", src.path.display());
                warnings.push(WarningKind::DuplicateChannel, 1, msg);
            }
            let sampler = load_sampler(src, &sampler, property, &user)?;
            channels.push(Channel {
                node,
                property,
                sampler,
            });
        }
        out.push(Animation {
            name: anim.name().map(str::to_string),
            channels,
        });
    }
    Ok(out)
}

fn load_sampler(
    src: &Source,
    s: &gltf::animation::Sampler<'_>,
    property: Property,
    user: &str,
) -> Result<Sampler> {
    let invalid = |element: String, reason: String| Error::Invalid {
        path: src.path(),
        element,
        reason,
    };
    let in_user = format!("{user} sampler {} input", s.index());
    let input = s.input();
    let times = accessor::read_floats(src, &input, &in_user, 1)?;
    let in_label = accessor::element_label(&input, &in_user);
    if let Some(position) = times.iter().position(|t| !t.is_finite()) {
        return Err(Error::NonFinite {
            path: src.path(),
            element: in_label,
            position,
        });
    }
    if times.is_empty() {
        return Err(invalid(in_label, "no keyframes".into()));
    }
    if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
        let reason = format!("key times are not strictly increasing at key {}", k + 1);
        return Err(invalid(in_label, reason));
    }
    let interpolation = match s.interpolation() {
        gltf::animation::Interpolation::Linear => Interpolation::Linear,
        gltf::animation::Interpolation::Step => Interpolation::Step,
        gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
    };
    let comps = if property == Property::Rotation { 4 } else { 3 };
    let out_user = format!("{user} sampler {} output", s.index());
    let output = s.output();
    let values = accessor::read_any_vec(src, &output, &out_user, comps)?;
    let out_label = accessor::element_label(&output, &out_user);
    if let Some(position) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            path: src.path(),
            element: out_label,
            position,
        });
    }
    let per_key = if interpolation == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    if values.len() != per_key * times.len() {
        let reason = format!(
            "{} output values for {} keys ({interpolation:?} needs {})",
            values.len(),
            times.len(),
            per_key * times.len()
        );
        return Err(invalid(out_label, reason));
    }
    if property == Property::Rotation
        && (0..times.len()).any(|k| values[per_key * k + per_key / 2].length_squared() < 1e-12)
    {
        return Err(invalid(out_label, "zero-length rotation quaternion".into()));
    }
    Ok(Sampler {
        interpolation,
        times,
        values,
    })
}
