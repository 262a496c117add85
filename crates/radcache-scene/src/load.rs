//! `Scene::load`: glTF file → [`Scene`] plus warnings.
//!
//! Order of work: parse and validate (gltf crate) → load buffers → animations (to know which nodes
//! move) → nodes and hierarchy of the chosen scene (`scene`, else `scenes[0]`, else every parentless
//! node) → materials and textures → meshes → lights → instances → camera → environment.

use std::path::Path;

use glam::{Mat4, Quat, Vec3, Vec4};

use crate::accessor;
use crate::animation::load_animations;
use crate::camera::{camera_defs, Camera, CameraDef};
use crate::environment::{scene_radiance, EnvOverride, Environment};
use crate::error::{label, Error, Result, Warning, WarningKind, Warnings};
use crate::light::{load_lights, LightInstance};
use crate::material::{load_materials, Material};
use crate::mesh::{load_mesh, VertexNeeds};
use crate::node::{load_nodes, traversal_order, Node};
use crate::resources::{RawInstancing, Source};
use crate::scene::{Instance, Scene};
use crate::texture::TextureLoader;

/// Options of [`Scene::load`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LoadOptions {
    /// Use the camera whose node (or camera) has this name instead of the first camera.
    pub camera_name: Option<String>,
    /// Environment overrides (command line).
    pub env: EnvOverride,
}

impl Scene {
    /// Loads a `.gltf` or `.glb` file. Warnings are logged with `log::warn!` and returned.
    pub fn load(path: &Path, opts: &LoadOptions) -> Result<(Scene, Vec<Warning>)> {
        let src = Source::open(path)?;
        let mut w = Warnings::default();
        let animations = load_animations(&src, &mut w)?;
        let node_count = src.doc.nodes().len();
        let mut targeted = vec![false; node_count];
        let mut animated = vec![false; node_count];
        for ch in animations.iter().flat_map(|a| &a.channels) {
            targeted[ch.node] = true;
            animated[ch.node] |= !ch.sampler.is_constant();
        }
        let mut nodes = load_nodes(&src, &targeted, &mut w)?;
        let roots = scene_roots(&src, &nodes, &mut w);
        let order = traversal_order(&src, &mut nodes, &roots)?;

        let mut textures = TextureLoader::default();
        let (mut materials, material_notes) = load_materials(&src, &mut textures, &mut w)?;
        let default_index = materials.len() as u32;
        let mut default_used = false;
        let mut material_of = |m: Option<usize>| match m {
            Some(i) => i as u32,
            None => {
                default_used = true;
                default_index
            }
        };
        let needs = |i: u32| {
            materials
                .get(i as usize)
                .map_or(VertexNeeds::default(), |m| VertexNeeds {
                    normal_map: m.normal_texture,
                    texcoord1: m.uses_texcoord1(),
                })
        };
        let mut meshes = Vec::new();
        for m in src.doc.meshes() {
            meshes.push(load_mesh(&src, &m, &mut material_of, &needs, &mut w)?);
        }
        if default_used {
            materials.push(Material::default_material());
        }

        let mut dynamic = vec![false; node_count];
        for &n in &order {
            dynamic[n] = animated[n] || nodes[n].parent.is_some_and(|p| dynamic[p]);
        }
        let lights = load_lights(&src)?;
        let light_instances = order
            .iter()
            .filter_map(|&n| nodes[n].light.map(|light| (n, light)))
            .map(|(node, light)| LightInstance {
                light,
                node,
                dynamic: dynamic[node],
            })
            .collect();
        let mut instances = Vec::new();
        let placed = order
            .iter()
            .filter_map(|&n| nodes[n].mesh.map(|mesh| (n, mesh)))
            .filter(|&(_, mesh)| meshes.get(mesh).is_some_and(|m| m.triangle_count() > 0));
        for (node, mesh) in placed {
            let instance = |local| Instance {
                mesh,
                node,
                local,
                dynamic: dynamic[node],
            };
            match src.raw_instancing.get(node).copied().flatten() {
                Some(raw) => {
                    instances.extend(gpu_instances(&src, node, &raw)?.into_iter().map(instance))
                }
                None => instances.push(instance(Mat4::IDENTITY)),
            }
        }
        let material_emission = materials
            .iter()
            .map(|m| {
                let tex = m.emissive_texture.map_or(Vec3::ONE, |t| {
                    textures.images[textures.textures[t.texture].image]
                        .mean_linear()
                        .truncate()
                });
                m.emissive * tex
            })
            .collect();
        let environment = resolve_environment(&src, opts, &mut w);
        let camera_count = order.iter().filter(|&&n| nodes[n].camera.is_some()).count();
        let mut scene = Scene {
            path: path.to_path_buf(),
            nodes,
            roots,
            order,
            meshes,
            materials,
            material_notes,
            material_emission,
            textures: textures.textures,
            images: textures.images,
            lights,
            light_instances,
            instances,
            camera: Camera::framing(&crate::math::Aabb::EMPTY),
            camera_count,
            animations,
            environment,
            animated,
            dynamic,
        };
        scene.camera = select_camera(&src, &scene, opts, &mut w)?;
        warn_if_unlit(&scene, &mut w);
        Ok((scene, w.list))
    }
}

fn scene_roots(src: &Source, nodes: &[Node], w: &mut Warnings) -> Vec<usize> {
    let chosen = src.doc.default_scene().or_else(|| src.doc.scenes().next());
    match chosen {
        Some(s) => s.nodes().map(|n| n.index()).collect(),
        None => {
            if !nodes.is_empty() {
                let msg = format!(
                    "{}: no scene defined; using every parentless node as a root",
                    src.path.display()
                );
                w.push(WarningKind::Other, 1, msg);
            }
            (0..nodes.len())
                .filter(|&i| nodes[i].parent.is_none())
                .collect()
        }
    }
}

fn resolve_environment(src: &Source, opts: &LoadOptions, w: &mut Warnings) -> Environment {
    let chosen = src.doc.default_scene().or_else(|| src.doc.scenes().next());
    let radiance = match chosen {
        Some(s) => match scene_radiance(s.extras()) {
            Ok(r) => r,
            Err(e) => {
                let msg = format!(
                    "{}: {}: extras.environment ignored: {e}",
                    src.path.display(),
                    label("scene", s.index(), s.name())
                );
                w.push(WarningKind::Other, 1, msg);
                None
            }
        },
        None => None,
    };
    Environment::resolve(&opts.env, radiance)
}

/// Display name of a camera node: node name, else camera name, else `#<node>`.
fn camera_name(node: &Node, index: usize, cam_name: Option<&str>) -> String {
    node.name
        .clone()
        .or_else(|| cam_name.map(str::to_string))
        .unwrap_or_else(|| format!("#{index}"))
}

fn select_camera(
    src: &Source,
    scene: &Scene,
    opts: &LoadOptions,
    w: &mut Warnings,
) -> Result<Camera> {
    let defs = camera_defs(&src.doc);
    let candidates: Vec<(usize, usize)> = scene
        .order
        .iter()
        .filter_map(|&n| scene.nodes[n].camera.map(|c| (n, c)))
        .filter(|&(_, c)| c < defs.len())
        .collect();
    let chosen = match &opts.camera_name {
        Some(want) => {
            let found = candidates.iter().find(|&&(n, c)| {
                scene.nodes[n].name.as_deref() == Some(want.as_str())
                    || defs[c].0.as_deref() == Some(want.as_str())
            });
            match found {
                Some(&f) => Some(f),
                None => {
                    return Err(Error::CameraNotFound {
                        path: src.path(),
                        name: want.clone(),
                        available: candidates
                            .iter()
                            .map(|&(n, c)| camera_name(&scene.nodes[n], n, defs[c].0.as_deref()))
                            .collect(),
                    })
                }
            }
        }
        None => candidates.first().copied(),
    };
    let Some((node, cam)) = chosen else {
        let msg = format!(
            "{}: the scene has no camera; using a default camera framing the scene bounds",
            src.path.display()
        );
        w.push(WarningKind::DefaultCamera, 1, msg);
        return Ok(Camera::framing(&scene.bounds_at(0.0)));
    };
    let element = format!(
        "{} {}",
        scene.nodes[node].label(node),
        label("camera", cam, defs[cam].0.as_deref())
    );
    match &defs[cam].1 {
        CameraDef::Perspective(p) => Ok(Camera {
            name: camera_name(&scene.nodes[node], node, defs[cam].0.as_deref()),
            node: Some(node),
            perspective: *p,
            fixed_world_from_camera: glam::Mat4::IDENTITY,
        }),
        CameraDef::Orthographic => Err(Error::OrthographicCamera {
            path: src.path(),
            element,
        }),
        CameraDef::Invalid(reason) => Err(Error::Invalid {
            path: src.path(),
            element,
            reason: reason.clone(),
        }),
    }
}

/// Warns when nothing in `scene` emits light: no emissive material on any triangle, no
/// punctual light, and a black (or absent) environment. Such a scene renders black.
fn warn_if_unlit(scene: &Scene, w: &mut Warnings) {
    let plan = scene.plan();
    let environment_lit = match &scene.environment {
        Environment::None => false,
        Environment::Constant(c) => c.max_element() > 0.0,
        Environment::Map { scale, .. } => *scale > 0.0,
    };
    if plan.has_emissive() || plan.has_punctual_lights() || environment_lit {
        return;
    }
    let msg = format!(
        "{}: the scene has no light source (no emissive material, no KHR_lights_punctual light, \
         no environment), so it renders black; add light with `--env-radiance R,G,B` (a \
         constant sky) or `--env-map FILE.exr`",
        scene.path.display()
    );
    w.push(WarningKind::NoLight, 1, msg);
}

/// The `node_from_object` transforms of node `node`'s `EXT_mesh_gpu_instancing` instances
/// (`T · R · S` of each one's TRANSLATION, ROTATION and SCALE, an absent attribute the identity):
/// the attributes must have one element per instance, the same number each; a rotation is
/// normalized, and a non-finite or zero one is an error naming the node.
fn gpu_instances(src: &Source, node: usize, raw: &RawInstancing) -> Result<Vec<Mat4>> {
    let gltf_node = src.doc.nodes().nth(node);
    let user = label("node", node, gltf_node.as_ref().and_then(|n| n.name()));
    let invalid = |reason: String| Error::Invalid {
        path: src.path(),
        element: user.clone(),
        reason: format!("EXT_mesh_gpu_instancing: {reason}"),
    };
    let read = |index: Option<usize>, key: &str, comps: usize| -> Result<Option<Vec<Vec4>>> {
        let Some(index) = index else {
            return Ok(None);
        };
        let acc = src.doc.accessors().nth(index).ok_or_else(|| {
            invalid(format!(
                "{key} names accessor {index}, which does not exist"
            ))
        })?;
        let u = format!("{user} EXT_mesh_gpu_instancing {key}");
        let v = accessor::read_any_vec(src, &acc, &u, comps)?;
        if let Some(bad) = v.iter().position(|v| !v.is_finite()) {
            return Err(invalid(format!("{key} of instance {bad} is not finite")));
        }
        Ok(Some(v))
    };
    let t = read(raw.translation, "TRANSLATION", 3)?;
    let r = read(raw.rotation, "ROTATION", 4)?;
    let s = read(raw.scale, "SCALE", 3)?;
    let counts: Vec<(&str, usize)> = [("TRANSLATION", &t), ("ROTATION", &r), ("SCALE", &s)]
        .into_iter()
        .filter_map(|(k, v)| v.as_ref().map(|v| (k, v.len())))
        .collect();
    let Some(&(_, count)) = counts.first() else {
        return Err(invalid(
            "no TRANSLATION, ROTATION or SCALE attribute".into(),
        ));
    };
    if let Some((k, n)) = counts.iter().find(|(_, n)| *n != count) {
        return Err(invalid(format!(
            "{k} has {n} elements but {} has {count}",
            counts[0].0
        )));
    }
    let at = |v: &Option<Vec<Vec4>>, i: usize, default: Vec3| {
        v.as_ref().map_or(default, |v| v[i].truncate())
    };
    (0..count)
        .map(|i| {
            let q = r.as_ref().map_or(Quat::IDENTITY, |r| Quat::from_vec4(r[i]));
            if q.length_squared() < 1e-12 {
                return Err(invalid(format!("ROTATION of instance {i} is zero")));
            }
            Ok(Mat4::from_scale_rotation_translation(
                at(&s, i, Vec3::ONE),
                q.normalize(),
                at(&t, i, Vec3::ZERO),
            ))
        })
        .collect()
}
