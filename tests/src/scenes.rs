//! Small scenes written with `GltfBuilder` for the GPU correctness tests, and the statistics the
//! tests compare with (mean and standard error over independent per-pixel estimates).

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use radcache_render::{
    render_ic, render_path, Budget, FrameOutput, GpuScene, IcSettings, PathSettings,
};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{BufferLayout, GltfBuilder, LightDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{LoadOptions, Scene};
use radcache_vk::{Context, ShaderCompiler};

/// A fresh folder under the system temp dir, unique to this process and `tag`.
pub fn temp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("radcache-tests-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("creating {}: {e}", dir.display()));
    dir
}

/// Loads a scene with the default options (panics on error).
pub fn load(path: &Path) -> Scene {
    Scene::load(path, &LoadOptions::default())
        .unwrap_or_else(|e| panic!("loading {}: {e}", path.display()))
        .0
}

/// Writes `builder` as `dir/<name>.gltf` with the buffer embedded and loads it.
pub fn write_and_load(builder: &GltfBuilder, dir: &Path, name: &str) -> Scene {
    let path = dir.join(format!("{name}.gltf"));
    builder
        .write(&path, BufferLayout::Embedded)
        .unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
    load(&path)
}

/// Mean and standard error of the mean of independent estimates.
#[derive(Debug, Clone, Copy)]
pub struct MeanSe {
    /// Sample mean.
    pub mean: f64,
    /// Standard error of the mean: sample standard deviation / √n.
    pub se: f64,
    /// Number of estimates.
    pub n: usize,
}

/// Mean and standard error of `values` (at least two).
pub fn mean_se(values: &[f64]) -> MeanSe {
    let n = values.len();
    assert!(n >= 2, "need at least two estimates, got {n}");
    let mean = values.iter().sum::<f64>() / n as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    MeanSe {
        mean,
        se: (var / n as f64).sqrt(),
        n,
    }
}

/// A horizontal rectangle `[x0, x1] × [z0, z1]` at height `y`, facing +Y (counter-clockwise seen
/// from above), with +Y vertex normals.
pub fn plane_y(x: [f32; 2], z: [f32; 2], y: f32, material: usize) -> PrimitiveDesc {
    PrimitiveDesc::triangles(
        vec![
            [x[0], y, z[0]],
            [x[0], y, z[1]],
            [x[1], y, z[1]],
            [x[1], y, z[0]],
        ],
        Some(vec![[0.0, 1.0, 0.0]; 4]),
        vec![0, 1, 2, 0, 2, 3],
        Some(material),
    )
}

/// A vertical rectangle `[y0, y1] × [z0, z1]` at `x`, with vertex normals `(normal_x, 0, 0)`
/// (±1: the side it faces), e.g. a coloured panel a hair in front of a side wall.
pub fn plane_x(y: [f32; 2], z: [f32; 2], x: f32, normal_x: f32, material: usize) -> PrimitiveDesc {
    PrimitiveDesc::triangles(
        vec![
            [x, y[0], z[0]],
            [x, y[0], z[1]],
            [x, y[1], z[1]],
            [x, y[1], z[0]],
        ],
        Some(vec![[normal_x, 0.0, 0.0]; 4]),
        vec![0, 1, 2, 0, 2, 3],
        Some(material),
    )
}

/// The materials of a closed test room lit from under its ceiling: Lambertian white (0.75) and
/// red (0.7, 0.15, 0.1), and a double-sided emitter of radiance 12 (indices in that order).
pub fn lit_room_materials(b: &mut GltfBuilder) -> [usize; 3] {
    use radcache_scene::writer::MaterialDesc;
    let white = b.add_material(&MaterialDesc::diffuse("white", [0.75, 0.75, 0.75]));
    let red = b.add_material(&MaterialDesc::diffuse("red", [0.7, 0.15, 0.1]));
    let light = b.add_material(&MaterialDesc {
        double_sided: true,
        ..MaterialDesc::emitter("light", [0.0; 3], [12.0; 3])
    });
    [white, red, light]
}

/// An axis-aligned cube of half-size `half` centred at the origin, faces outward (flat normals,
/// counter-clockwise seen from outside).
pub fn cube(half: f32, material: usize) -> PrimitiveDesc {
    let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let u = Vec3::AXES[(axis + 1) % 3] * half;
            let v = Vec3::AXES[(axis + 2) % 3] * half;
            let c = n * half;
            let mut quad = [c - u - v, c + u - v, c + u + v, c - u + v];
            if (quad[1] - quad[0]).cross(quad[2] - quad[0]).dot(n) < 0.0 {
                quad.swap(1, 3);
            }
            let base = positions.len() as u32;
            for p in quad {
                positions.push(p.to_array());
                normals.push(n.to_array());
            }
            indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        }
    }
    PrimitiveDesc::triangles(positions, Some(normals), indices, Some(material))
}

/// Adds a perspective camera node (aspect ratio left to the image) at `position` with
/// `rotation`; returns the node index.
pub fn camera_node(b: &mut GltfBuilder, position: Vec3, rotation: Quat, yfov: f32) -> usize {
    let cam = b.add_perspective_camera("camera", yfov, None, 0.05, None);
    b.add_node(&NodeDesc {
        name: Some("camera".into()),
        translation: Some(position.to_array()),
        rotation: Some(rotation.normalize().to_array()),
        camera: Some(cam),
        ..NodeDesc::default()
    })
}

/// Adds a white point light of `intensity` (candela) and its node at `position`; returns the
/// node index.
pub fn point_light_node(b: &mut GltfBuilder, position: [f32; 3], intensity: f32) -> usize {
    let light = b.add_light(&LightDesc {
        name: None,
        kind: LightKind::Point,
        color: [1.0; 3],
        intensity,
        range: None,
    });
    b.add_node(&NodeDesc {
        translation: Some(position),
        light: Some(light),
        ..NodeDesc::default()
    })
}

/// The scene `name` of `b`'s meshes `(mesh, rotation)`, one node each, a camera node
/// ([`camera_node`]: position, rotation, vertical field of view) and a white point light
/// ([`point_light_node`]: position, intensity), written and loaded back.
pub fn meshes_camera_light_scene(
    mut b: GltfBuilder,
    name: &str,
    meshes: &[(usize, Quat)],
    camera: (Vec3, Quat, f32),
    light: ([f32; 3], f32),
) -> Scene {
    let mut roots: Vec<usize> = meshes
        .iter()
        .map(|&(mesh, q)| {
            b.add_node(&NodeDesc {
                mesh: Some(mesh),
                rotation: (q != Quat::IDENTITY).then(|| q.to_array()),
                ..NodeDesc::default()
            })
        })
        .collect();
    roots.push(camera_node(&mut b, camera.0, camera.1, camera.2));
    roots.push(point_light_node(&mut b, light.0, light.1));
    b.add_scene(name, &roots, None);
    write_and_load(&b, &temp_dir(name), name)
}

/// The scene `name` of one node `node` holding `b`'s mesh `mesh` and a camera node
/// ([`camera_node`]: position, rotation, vertical field of view), with the scene's `extras`
/// (an environment, say), written and loaded back.
pub fn mesh_camera_scene(
    mut b: GltfBuilder,
    name: &str,
    (node, mesh): (&str, usize),
    camera: (Vec3, Quat, f32),
    extras: Option<serde_json::Value>,
) -> Scene {
    let roots = vec![
        b.add_node(&NodeDesc {
            name: Some(node.into()),
            mesh: Some(mesh),
            ..NodeDesc::default()
        }),
        camera_node(&mut b, camera.0, camera.1, camera.2),
    ];
    b.add_scene(name, &roots, extras);
    write_and_load(&b, &temp_dir(name), name)
}

/// Image-space position (pixels, x right, y down, origin at the top-left corner) of NDC point
/// `(x, y)` with y up, for a `width × height` image.
pub fn ndc_to_pixel(x: f32, y: f32, width: u32, height: u32) -> (f64, f64) {
    (
        (f64::from(x) + 1.0) * 0.5 * f64::from(width),
        (1.0 - f64::from(y)) * 0.5 * f64::from(height),
    )
}

/// NDC point (x right, y up) of image-space position `(px, py)` (pixels, y down).
pub fn pixel_to_ndc(px: f64, py: f64, width: u32, height: u32) -> (f32, f32) {
    (
        (px / f64::from(width) * 2.0 - 1.0) as f32,
        (1.0 - py / f64::from(height) * 2.0) as f32,
    )
}

/// A polygon in image space (pixels, x right, y down), vertices ordered so that its
/// [`signed_area`] is positive.
pub type Polygon = Vec<(f64, f64)>;

/// Signed area of a polygon (shoelace).
pub fn signed_area(p: &[(f64, f64)]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a.0 * b.1 - b.0 * a.1
        })
        .sum::<f64>()
        * 0.5
}

/// The convex hull (Andrew's monotone chain) of `points`, with positive signed area.
pub fn convex_hull(points: &[(f64, f64)]) -> Polygon {
    let mut pts = points.to_vec();
    pts.sort_by(|a, b| a.partial_cmp(b).expect("finite points"));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::new();
    let backward: Vec<(f64, f64)> = pts.iter().rev().copied().collect();
    for chain in [&pts, &backward] {
        let start = hull.len();
        for &p in chain {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Signed distance-like test of `p` against every edge of the convex polygon `poly` (positive
/// area): the smallest distance from `p` to an edge line, positive inside.
pub fn inside_margin(poly: &[(f64, f64)], p: (f64, f64)) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let (ex, ey) = (b.0 - a.0, b.1 - a.1);
            let len = (ex * ex + ey * ey).sqrt();
            (ex * (p.1 - a.1) - ey * (p.0 - a.0)) / len
        })
        .fold(f64::INFINITY, f64::min)
}

/// Clips the convex polygon `subject` by the convex polygon `clip` (both with positive area;
/// Sutherland–Hodgman).
pub fn clip_convex(subject: &[(f64, f64)], clip: &[(f64, f64)]) -> Polygon {
    let mut out = subject.to_vec();
    let n = clip.len();
    for i in 0..n {
        if out.is_empty() {
            break;
        }
        let (a, b) = (clip[i], clip[(i + 1) % n]);
        let side = |p: (f64, f64)| (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0);
        let input = std::mem::take(&mut out);
        for j in 0..input.len() {
            let (p, q) = (input[j], input[(j + 1) % input.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                out.push(p);
            }
            if (sp >= 0.0) != (sq >= 0.0) {
                let t = sp / (sp - sq);
                out.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1)));
            }
        }
    }
    out
}

/// The unit square of pixel `(x, y)` as a polygon with positive signed area.
pub fn pixel_square(x: u32, y: u32) -> Polygon {
    let (x0, y0) = (f64::from(x), f64::from(y));
    vec![
        (x0, y0),
        (x0 + 1.0, y0),
        (x0 + 1.0, y0 + 1.0),
        (x0, y0 + 1.0),
    ]
}

/// How far apart two convex polygons (positive area) are: the largest gap between their
/// projections over the edge normals of both (separating axis theorem). Positive: disjoint, with
/// at least that distance between them; zero or negative: they touch or overlap.
pub fn separation(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let mut best = f64::NEG_INFINITY;
    for poly in [a, b] {
        let n = poly.len();
        for i in 0..n {
            let (p, q) = (poly[i], poly[(i + 1) % n]);
            let (ex, ey) = (q.0 - p.0, q.1 - p.1);
            let len = (ex * ex + ey * ey).sqrt();
            let axis = (ey / len, -ex / len);
            let range = |s: &[(f64, f64)]| {
                s.iter()
                    .map(|v| v.0 * axis.0 + v.1 * axis.1)
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(x), hi.max(x))
                    })
            };
            let (ra, rb) = (range(a), range(b));
            best = best.max((rb.0 - ra.1).max(ra.0 - rb.1));
        }
    }
    best
}

/// Where pixel `(x, y)` lies relative to a convex image-space region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Coverage {
    /// The whole pixel is inside (every corner at least `eps` inside).
    Inside,
    /// The whole pixel is outside (separated by more than `eps`).
    Outside,
    /// The region covers this fraction of the pixel's area.
    Partial(f64),
}

/// Coverage of pixel `(x, y)` by the convex polygon `poly` (positive area), with a margin of
/// `eps` pixels for the two exact cases.
pub fn pixel_coverage(poly: &[(f64, f64)], x: u32, y: u32, eps: f64) -> Coverage {
    let square = pixel_square(x, y);
    if square.iter().all(|&c| inside_margin(poly, c) > eps) {
        Coverage::Inside
    } else if separation(poly, &square) > eps {
        Coverage::Outside
    } else {
        Coverage::Partial(signed_area(&clip_convex(&square, poly)).max(0.0))
    }
}

/// Relative float slack for f32 accumulation and camera-matrix round-off (far below any
/// statistical tolerance used here).
pub const FLOAT_SLACK: f64 = 1e-5;

/// Renders with the path tracer and checks the output is complete, finite and non-negative.
pub fn render(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    gpu: &mut GpuScene,
    size: (u32, u32),
    spp: u32,
    seed: u32,
) -> FrameOutput {
    let settings = PathSettings {
        width: size.0,
        height: size.1,
        budget: Budget::Samples(spp),
        seed,
        chunk_target_ms: 200.0,
        ..PathSettings::default()
    };
    let out = render_path(ctx, shaders, scene, gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(out.spp, spp);
    assert_eq!(out.pixels.len(), (size.0 * size.1) as usize);
    assert_eq!(out.nonfinite_pixels, 0, "non-finite pixels");
    for (i, p) in out.pixels.iter().enumerate() {
        assert!(
            p.iter().all(|c| c.is_finite() && *c >= 0.0),
            "pixel {i} is {p:?}"
        );
    }
    out
}

/// One channel of every pixel, as f64.
pub fn channel(out: &FrameOutput, c: usize) -> Vec<f64> {
    out.pixels.iter().map(|p| f64::from(p[c])).collect()
}

/// `scene` at `size` with the path tracer (`spp` samples, `seed`; checked by [`render`]) and with
/// the cache at its default settings, on one GPU upload.
pub fn path_and_cache(
    ctx: &Context,
    shaders: &ShaderCompiler,
    scene: &Scene,
    size: (u32, u32),
    spp: u32,
    seed: u32,
) -> (FrameOutput, FrameOutput) {
    let mut gpu = GpuScene::new(ctx, scene, None).unwrap();
    let pt = render(ctx, shaders, scene, &mut gpu, size, spp, seed);
    let settings = IcSettings {
        width: size.0,
        height: size.1,
        ..IcSettings::default()
    };
    let (ic, _) = render_ic(ctx, shaders, scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    (pt, ic)
}
