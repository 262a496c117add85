//! Perspective cameras.
//!
//! A camera looks down its node's local −Z axis with +Y up (glTF). The scene's camera is the first
//! camera node in node traversal order (scene roots in order, depth-first, children in order),
//! unless `LoadOptions::camera_name` names one (matched against the node name, then the camera
//! name). A scene without a camera gets a default camera framing its bounds (see
//! [`Camera::framing`]). Orthographic cameras are rejected.

use glam::{Mat4, Vec3};

use crate::math::Aabb;

/// Perspective projection parameters (glTF `camera.perspective`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Perspective {
    /// Vertical field of view in radians.
    pub yfov: f32,
    /// Width / height; `None` = use the output image's aspect ratio.
    pub aspect_ratio: Option<f32>,
    /// Near plane distance (m).
    pub znear: f32,
    /// Far plane distance (m); `None` = infinite.
    pub zfar: Option<f32>,
}

/// The scene's selected camera.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Display name (node name, else camera name, else `#<node>`; `"default"` when generated).
    pub name: String,
    /// The camera node; `None` for a generated default camera.
    pub node: Option<usize>,
    /// Projection.
    pub perspective: Perspective,
    /// World transform used when `node` is `None`.
    pub fixed_world_from_camera: Mat4,
}

/// A camera's world-space frame at some time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraView {
    /// Rigid (orthonormal) camera-to-world transform: columns right, up, back (+Z), position.
    pub world_from_camera: Mat4,
    /// Eye position.
    pub position: Vec3,
    /// Unit viewing direction (camera −Z).
    pub forward: Vec3,
    /// Unit up vector (camera +Y).
    pub up: Vec3,
    /// Unit right vector (camera +X; image right).
    pub right: Vec3,
    /// Projection.
    pub perspective: Perspective,
}

impl CameraView {
    /// Builds the view from a node's world transform, removing scale and shear.
    pub fn from_world(world_from_node: &Mat4, perspective: Perspective) -> CameraView {
        let position = world_from_node.transform_point3(Vec3::ZERO);
        let forward = world_from_node
            .transform_vector3(-Vec3::Z)
            .normalize_or(-Vec3::Z);
        let up0 = world_from_node.transform_vector3(Vec3::Y);
        let mut right = forward.cross(up0).normalize_or_zero();
        if right == Vec3::ZERO {
            right = forward.any_orthonormal_vector();
        }
        let up = right.cross(forward);
        CameraView {
            world_from_camera: Mat4::from_cols(
                right.extend(0.0),
                up.extend(0.0),
                (-forward).extend(0.0),
                position.extend(1.0),
            ),
            position,
            forward,
            up,
            right,
            perspective,
        }
    }
}

impl Perspective {
    /// The aspect ratio (width / height) to render with: the camera's own, else `image_aspect`.
    pub fn aspect_or(&self, image_aspect: f32) -> f32 {
        self.aspect_ratio.unwrap_or(image_aspect)
    }

    /// `clip_from_view` for a right-handed view space looking down −Z: depth maps `znear → 0` and
    /// `zfar → 1` (infinite far plane when `zfar` is `None`); after the perspective divide NDC x
    /// points to image right and y to image **up** (flip y for Vulkan's framebuffer).
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        match self.zfar {
            Some(zfar) => Mat4::perspective_rh(self.yfov, aspect, self.znear, zfar),
            None => Mat4::perspective_infinite_rh(self.yfov, aspect, self.znear),
        }
    }
}

impl CameraView {
    /// `view_from_world`: the inverse of the rigid `world_from_camera`.
    pub fn view_from_world(&self) -> Mat4 {
        self.world_from_camera.inverse()
    }

    /// `clip_from_world = clip_from_view(aspect) · view_from_world` (see
    /// [`Perspective::clip_from_view`]).
    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        self.perspective.clip_from_view(aspect) * self.view_from_world()
    }

    /// Normalized device coordinates of world point `p` (x right, y up, depth in `[0, 1]` inside
    /// the frustum), or `None` when `p` is not in front of the camera.
    pub fn project(&self, p: Vec3, aspect: f32) -> Option<Vec3> {
        let clip = self.clip_from_world(aspect) * p.extend(1.0);
        (clip.w > 0.0).then(|| clip.truncate() / clip.w)
    }

    /// Unit world direction of the primary ray through NDC point `(x, y)` (x right, y up, both in
    /// `[−1, 1]` across the image): the inverse of [`CameraView::project`] for directions.
    pub fn ray_direction(&self, x: f32, y: f32, aspect: f32) -> Vec3 {
        let tan_half = (self.perspective.yfov * 0.5).tan();
        (self.forward + self.right * (x * tan_half * aspect) + self.up * (y * tan_half)).normalize()
    }
}

impl Camera {
    /// A default camera looking down −Z at `bounds` so that its bounding sphere fits a 45° view.
    pub fn framing(bounds: &Aabb) -> Camera {
        let (center, radius) = if bounds.is_empty() {
            (Vec3::ZERO, 1.0)
        } else {
            (bounds.center(), (bounds.size().length() * 0.5).max(1e-3))
        };
        let yfov = 45f32.to_radians();
        let distance = radius / (yfov * 0.5).sin();
        Camera {
            name: "default".into(),
            node: None,
            perspective: Perspective {
                yfov,
                aspect_ratio: None,
                znear: (distance - radius).max(distance * 1e-3) * 0.5,
                zfar: None,
            },
            fixed_world_from_camera: Mat4::from_translation(center + Vec3::new(0.0, 0.0, distance)),
        }
    }
}

/// A camera definition read from JSON: perspective, or orthographic (unsupported).
#[derive(Clone, Debug)]
pub(crate) enum CameraDef {
    Perspective(Perspective),
    Orthographic,
    Invalid(String),
}

/// Reads camera definitions straight from the JSON (the gltf crate's accessor unwraps when the
/// `type` and the projection object disagree).
pub(crate) fn camera_defs(doc: &gltf::Document) -> Vec<(Option<String>, CameraDef)> {
    use gltf::json::camera::Type;
    use gltf::json::validation::Checked;
    doc.as_json()
        .cameras
        .iter()
        .map(|c| {
            let def = match (&c.type_, &c.perspective, &c.orthographic) {
                (Checked::Valid(Type::Perspective), Some(p), _) => {
                    let ok = p.yfov > 0.0
                        && p.yfov < std::f32::consts::PI
                        && p.znear > 0.0
                        && p.znear.is_finite();
                    if ok {
                        CameraDef::Perspective(Perspective {
                            yfov: p.yfov,
                            aspect_ratio: p.aspect_ratio.filter(|a| *a > 0.0 && a.is_finite()),
                            znear: p.znear,
                            zfar: p.zfar.filter(|f| *f > p.znear && f.is_finite()),
                        })
                    } else {
                        CameraDef::Invalid(format!(
                            "invalid perspective (yfov {}, znear {})",
                            p.yfov, p.znear
                        ))
                    }
                }
                (Checked::Valid(Type::Orthographic), _, _) => CameraDef::Orthographic,
                _ => CameraDef::Invalid("type and projection object disagree".into()),
            };
            (c.name.clone(), def)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn view_basis_is_orthonormal() {
        let p = Perspective {
            yfov: 1.0,
            aspect_ratio: None,
            znear: 0.1,
            zfar: None,
        };
        let m = Mat4::from_scale_rotation_translation(
            Vec3::splat(2.0),
            glam::Quat::from_rotation_y(std::f32::consts::PI),
            Vec3::new(1.0, 2.0, 3.0),
        );
        let v = CameraView::from_world(&m, p);
        assert!((v.forward - Vec3::Z).length() < 1e-5);
        assert!((v.right + Vec3::X).length() < 1e-5);
        assert!((v.up - Vec3::Y).length() < 1e-5);
        assert_eq!(v.position, Vec3::new(1.0, 2.0, 3.0));
        let c = Camera::framing(&Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        });
        assert!(c.fixed_world_from_camera.w_axis.z > 1.0);
    }

    #[test]
    fn projection_and_rays_agree() {
        let p = Perspective {
            yfov: 0.8,
            aspect_ratio: Some(1.5),
            znear: 0.1,
            zfar: Some(20.0),
        };
        let m = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(1.0, -2.0, 0.5),
        );
        let v = CameraView::from_world(&m, p);
        let aspect = p.aspect_or(1.0);
        assert_eq!(aspect, 1.5);
        for (x, y) in [(0.0, 0.0), (0.5, -0.25), (-0.9, 0.8)] {
            let d = v.ray_direction(x, y, aspect);
            let ndc = v.project(v.position + d * 3.0, aspect).unwrap();
            assert!(
                (ndc.x - x).abs() < 1e-4 && (ndc.y - y).abs() < 1e-4,
                "{ndc}"
            );
            assert!(ndc.z > 0.0 && ndc.z < 1.0);
        }
        assert!(v.project(v.position - v.forward, aspect).is_none());
        // The top edge of the image is at yfov / 2 above the axis.
        let top = v.ray_direction(0.0, 1.0, aspect);
        assert!((top.angle_between(v.forward) - 0.4).abs() < 1e-5);
    }
}
