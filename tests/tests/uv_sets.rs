//! Texture coordinate sets and `KHR_texture_transform` on lavapipe (docs/materials.md §13),
//! against the CPU's evaluation of the references (`TextureRef::map`).
//!
//! - A quad facing the camera under a uniform sky, its base colour and its emission textured
//!   with NEAREST-filtered 4 × 4 textures of distinct texels: (a) both through TEXCOORD_0, each
//!   through its own transform (offset, rotation and scale; one texture, two references), and
//!   (b) through TEXCOORD_1, whose mapping is unlike TEXCOORD_0's (the emission by `texCoord` 1,
//!   the base colour by the transform's `texCoord` override, with a transform). Where every
//!   corner of a pixel maps into one texel of each texture, the pixel is exactly emission texel
//!   × factor + base colour texel × sky (a plane under a uniform sky sees only the sky): checked
//!   per pixel in the path tracer, its albedo AOV and the cache frame (G-buffer, emission pass,
//!   records of E = πL). The same pixels under the references' other set or without their
//!   transforms differ, so a renderer that dropped either fails.
//! - The same quad with a normal map of 16 texels tilted by distinct angles, through TEXCOORD_1
//!   and a transform, lit by a directional light along its normal: every pixel inside one texel
//!   is ρ/π · E · cos θ of that texel (the cosine between the mapped and the geometric normal does
//!   not depend on the tangent's direction), in both renderers.
//! - An emitter over a floor whose emission reference maps all of it into one texel of a texture
//!   whose other texels are dark (through TEXCOORD_1 and a transform, TEXCOORD_0 spanning the
//!   texture): the floor's radiance is ρ/π · L · texel · the emitter's projected solid angle
//!   (Lambert's formula), light sampling and BSDF sampling alike, in both renderers.
//! - Every pass shader compiles and validates with every material define at once.

use std::f64::consts::PI;

use glam::{Quat, Vec2, Vec3};
use radcache_material::polygon::triangle_projected_solid_angle;
use radcache_render::{render_ic, render_path, Budget, GpuScene, IcSettings, PathSettings};
use radcache_scene::light::LightKind;
use radcache_scene::math::srgb_to_linear;
use radcache_scene::writer::{
    GltfBuilder, LightDesc, MaterialDesc, NodeDesc, PrimitiveDesc, TexCoordDesc,
};
use radcache_scene::{CameraView, Scene, TextureRef, TextureTransform};
use radcache_tests::scenes::{
    camera_node, pixel_to_ndc, plane_y, render, temp_dir, write_and_load,
};
use radcache_tests::{context, finish, shader_root, shaders};

/// Texels per side of the test textures.
const N: usize = 4;
/// The quad spans [−QUAD, QUAD]² at z = 0; the camera at z = 3 sees [−1, 1]².
const QUAD: f32 = 2.0;
const SKY: f32 = 1.0;
const EMISSION: [f32; 3] = [0.5, 0.4, 0.3];
const SIZE: (u32, u32) = (48, 48);

/// RGBA8 texels, row-major, all distinct: texture `k` of two.
fn texels(k: usize) -> Vec<u8> {
    (0..N * N)
        .flat_map(|i| {
            let i = (i * 7 + k * 5) % (N * N);
            [
                (20 + 15 * i) as u8,
                (250 - 13 * i) as u8,
                (60 + 97 * i % 190) as u8,
                255,
            ]
        })
        .collect()
}

/// Linear RGB of texel (x, y) of the image reference `r` samples (sRGB decoded).
fn texel_linear(scene: &Scene, r: &TextureRef, (x, y): (usize, usize)) -> [f64; 3] {
    let image = &scene.images[scene.textures[r.texture].image];
    let t = image.texel_linear(x as u32, y as u32);
    [t.x, t.y, t.z].map(f64::from)
}

/// The texel (wrap REPEAT) a NEAREST lookup takes at `uv`, or `None` when `uv` lies within `eps`
/// (texels) of a texel edge.
fn nearest_texel(uv: Vec2, eps: f64) -> Option<(i64, i64)> {
    let p = [f64::from(uv.x) * N as f64, f64::from(uv.y) * N as f64];
    let cell = p.map(|v| v.floor());
    if p.iter()
        .zip(&cell)
        .any(|(v, c)| v - c < eps || c + 1.0 - v < eps)
    {
        return None;
    }
    Some((cell[0] as i64, cell[1] as i64))
}

/// The corners of a pixel: where all four map into one texel, the whole pixel does (its image
/// under the camera and the affine maps is convex, and so is a texel's cell).
const CORNERS: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
/// The centre of a pixel.
const CENTRE: [(f64, f64); 1] = [(0.5, 0.5)];

/// The texel reference `r` takes at every point `at` (offsets in the pixel) of pixel
/// `(px, py)`, or `None` when they fall in different texels or on an edge. `uvs` gives the two
/// sets at a world point of the quad (z = 0).
fn pixel_texel(
    view: &CameraView,
    (px, py): (u32, u32),
    at: &[(f64, f64)],
    r: &TextureRef,
    uvs: &dyn Fn(Vec3) -> (Vec2, Vec2),
) -> Option<(usize, usize)> {
    let aspect = SIZE.0 as f32 / SIZE.1 as f32;
    let mut found = None;
    for &(dx, dy) in at {
        let (x, y) = pixel_to_ndc(f64::from(px) + dx, f64::from(py) + dy, SIZE.0, SIZE.1);
        let d = view.ray_direction(x, y, aspect);
        let p = view.position + d * (-view.position.z / d.z);
        let (a, b) = uvs(p);
        let t = nearest_texel(r.map(a, b), 1e-3)?;
        match found {
            None => found = Some(t),
            Some(f) if f == t => {}
            Some(_) => return None,
        }
    }
    found.map(|(x, y)| {
        (
            x.rem_euclid(N as i64) as usize,
            y.rem_euclid(N as i64) as usize,
        )
    })
}

/// TEXCOORD_0 of the quad at world point p: u along +x, v down (−y), the quad's corners at 0 and 1.
fn uv0_at(p: Vec3) -> Vec2 {
    Vec2::new((p.x + QUAD) / (2.0 * QUAD), (QUAD - p.y) / (2.0 * QUAD))
}

/// TEXCOORD_1: another affine map, axes swapped and scaled (a turn and a mirror).
fn uv1_at(p: Vec3) -> Vec2 {
    Vec2::new(0.5 + 0.35 * p.y, 0.45 + 0.3 * p.x)
}

fn tt(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> TextureTransform {
    TextureTransform {
        offset: Vec2::from(offset),
        rotation,
        scale: Vec2::from(scale),
    }
}

/// The quad of material `mat` (both sets of texture coordinates), its node and a camera on +Z
/// that sees [−1, 1]² of it.
fn quad_nodes(b: &mut GltfBuilder, mat: usize, tag: &str) -> Vec<usize> {
    let corners = [[-QUAD, -QUAD], [QUAD, -QUAD], [QUAD, QUAD], [-QUAD, QUAD]];
    let at = |c: &[f32; 2]| Vec3::new(c[0], c[1], 0.0);
    let quad = PrimitiveDesc {
        texcoords: Some(corners.iter().map(|c| uv0_at(at(c)).to_array()).collect()),
        texcoords1: Some(corners.iter().map(|c| uv1_at(at(c)).to_array()).collect()),
        ..PrimitiveDesc::triangles(
            corners.iter().map(|c| [c[0], c[1], 0.0]).collect(),
            Some(vec![[0.0, 0.0, 1.0]; 4]),
            vec![0, 1, 2, 0, 2, 3],
            Some(mat),
        )
    };
    let mesh = b.add_mesh(tag, &[quad]);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let yfov = 2.0 * (1.0f32 / 3.0).atan();
    vec![
        node,
        camera_node(b, Vec3::new(0.0, 0.0, 3.0), Quat::IDENTITY, yfov),
    ]
}

/// The quad's scene: emission `emit_uv` of texture 0 (× EMISSION) and base colour `base_uv` of
/// texture `base_tex` (0 or 1), under the sky, both textures NEAREST and REPEAT.
fn quad_scene(tag: &str, emit_uv: TexCoordDesc, base_uv: TexCoordDesc, base_tex: usize) -> Scene {
    let mut b = GltfBuilder::new();
    let textures: Vec<usize> = (0..2)
        .map(|k| {
            let t = b
                .add_texture_rgba8(N as u32, N as u32, &texels(k), 10497)
                .unwrap();
            b.set_mag_filter(t, 9728);
            t
        })
        .collect();
    let mat = b.add_material(&MaterialDesc {
        emissive: EMISSION,
        emissive_texture: Some(textures[0]),
        emissive_uv: emit_uv,
        base_color_texture: Some(textures[base_tex]),
        base_color_uv: base_uv,
        ..MaterialDesc::diffuse(tag, [1.0; 3])
    });
    let roots = quad_nodes(&mut b, mat, tag);
    let sky = serde_json::json!({"environment": {"radiance": [SKY, SKY, SKY]}});
    b.add_scene(tag, &roots, Some(sky));
    let scene = write_and_load(&b, &temp_dir(tag), tag);
    assert!(scene.materials[0].is_lambertian());
    scene
}

/// Per pixel: the expected (emission + base colour × sky, base colour) where both references
/// take one texel at every point `at` of the pixel.
fn expected(scene: &Scene, at: &[(f64, f64)]) -> Vec<Option<([f64; 3], [f64; 3])>> {
    let view = scene.camera_at(0.0);
    let m = &scene.materials[0];
    let (emit, base) = (m.emissive_texture.unwrap(), m.base_color_texture.unwrap());
    let uvs = |p: Vec3| (uv0_at(p), uv1_at(p));
    let mut out = Vec::new();
    for py in 0..SIZE.1 {
        for px in 0..SIZE.0 {
            let e = pixel_texel(&view, (px, py), at, &emit, &uvs);
            let b = pixel_texel(&view, (px, py), at, &base, &uvs);
            out.push(e.zip(b).map(|(e, b)| {
                let le = texel_linear(scene, &emit, e);
                let rho = texel_linear(scene, &base, b);
                (
                    std::array::from_fn(|c| {
                        f64::from(EMISSION[c]) * le[c] + rho[c] * f64::from(SKY)
                    }),
                    rho,
                )
            }));
        }
    }
    out
}

/// Checks `got` against the expected values where there are any (|error| ≤ 2e-4 relative, the
/// sRGB decode in f32); returns the number of pixels checked.
fn check(what: &str, got: &[[f32; 3]], expected: &[Option<[f64; 3]>]) -> usize {
    let mut n = 0;
    let mut worst = 0.0f64;
    for (i, e) in expected.iter().enumerate() {
        let Some(e) = e else { continue };
        n += 1;
        for c in 0..3 {
            let err = (f64::from(got[i][c]) - e[c]).abs();
            worst = worst.max(err);
            assert!(
                err <= 2e-4 * e[c].max(1.0),
                "{what}: pixel ({}, {}) channel {c}: {}, expected {}",
                i as u32 % SIZE.0,
                i as u32 / SIZE.0,
                got[i][c],
                e[c]
            );
        }
    }
    eprintln!("{what}: {n} pixels exact, worst |error| {worst:.2e}");
    n
}

/// Renders `scene` with the path tracer (with AOVs) and the cache frame and checks both per
/// pixel; `wrong` is the scene with the references' sets or transforms dropped, which must
/// differ on most checked pixels.
fn render_and_check(tag: &str, scene: &Scene, wrong: &Scene) {
    let exp = expected(scene, &CORNERS);
    let beauty: Vec<Option<[f64; 3]>> = exp.iter().map(|e| e.map(|v| v.0)).collect();
    let albedo: Vec<Option<[f64; 3]>> = exp.iter().map(|e| e.map(|v| v.1)).collect();
    let checked = beauty.iter().flatten().count();
    assert!(
        checked >= 600,
        "{tag}: only {checked} pixels lie inside single texels"
    );
    // What the wrong mapping shows at the checked pixels' centres.
    let other = expected(wrong, &CENTRE);
    let differ = beauty
        .iter()
        .zip(&other)
        .filter(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => a.iter().zip(&b.0).any(|(x, y)| (x - y).abs() > 1e-2),
            (Some(_), None) => true,
            _ => false,
        })
        .count();
    eprintln!("{tag}: {checked} pixels checked, {differ} of them differ under the wrong mapping");
    assert!(
        differ * 4 > checked * 3,
        "{tag}: the test cannot tell the mapping from the wrong one ({differ} of {checked} differ)"
    );

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, scene, None).unwrap();
    let defines = gpu.material_defines();
    eprintln!("{tag}: defines {defines:?}");
    let settings = PathSettings {
        width: SIZE.0,
        height: SIZE.1,
        budget: Budget::Samples(4),
        seed: 5,
        aovs: true,
        ..PathSettings::default()
    };
    let path = render_path(&ctx, &shaders, scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(path.nonfinite_pixels, 0);
    check(&format!("{tag}, path tracer"), &path.pixels, &beauty);
    let aovs = path.aovs.as_ref().expect("AOVs asked for");
    let aov: Vec<[f32; 3]> = aovs
        .albedo
        .chunks_exact(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    check(&format!("{tag}, albedo AOV"), &aov, &albedo);
    let settings = IcSettings {
        width: SIZE.0,
        height: SIZE.1,
        ..IcSettings::default()
    };
    let (ic, _) = render_ic(&ctx, &shaders, scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(ic.nonfinite_pixels, 0);
    check(&format!("{tag}, cache frame"), &ic.pixels, &beauty);
    drop(gpu);
    finish(ctx);
}

fn uv(tex_coord: u32, transform: Option<TextureTransform>, over: Option<u32>) -> TexCoordDesc {
    TexCoordDesc {
        tex_coord,
        transform,
        transform_tex_coord: over,
    }
}

#[test]
fn transformed_references_sample_the_texels_the_cpu_transform_selects() {
    // One texture, two references with different transforms (per reference, not per texture).
    let t_emit = tt([0.3, -0.2], 0.5, [1.7, 1.3]);
    let t_base = tt([-0.1, 0.4], -1.1, [2.3, 0.8]);
    let scene = quad_scene(
        "uv-transform",
        uv(0, Some(t_emit), None),
        uv(0, Some(t_base), None),
        0,
    );
    let plan = scene.plan();
    assert!(plan.uv_transform && !plan.texcoord1, "{plan}");
    let m = &scene.materials[0];
    assert_eq!(m.emissive_texture.unwrap().transform, t_emit);
    assert_eq!(m.base_color_texture.unwrap().transform, t_base);
    assert_eq!(
        m.emissive_texture.unwrap().texture,
        m.base_color_texture.unwrap().texture
    );
    let plain = quad_scene("uv-transform-none", uv(0, None, None), uv(0, None, None), 0);
    render_and_check("transforms", &scene, &plain);
}

#[test]
fn texcoord1_references_sample_the_second_set() {
    let t_base = tt([0.2, 0.1], 0.7, [1.5, -1.2]);
    // The emission by texCoord 1; the base colour by the transform's texCoord override.
    let scene = quad_scene(
        "uv-set1",
        uv(1, None, None),
        uv(0, Some(t_base), Some(1)),
        1,
    );
    let plan = scene.plan();
    assert!(plan.uv_transform && plan.texcoord1, "{plan}");
    let mesh = &scene.meshes[0];
    assert_eq!(mesh.texcoords1.len(), mesh.positions.len());
    let m = &scene.materials[0];
    assert_eq!(m.emissive_texture.unwrap().tex_coord, 1);
    assert_eq!(m.base_color_texture.unwrap().tex_coord, 1);
    let set0 = quad_scene(
        "uv-set1-as-0",
        uv(0, None, None),
        uv(0, Some(t_base), None),
        1,
    );
    render_and_check("TEXCOORD_1", &scene, &set0);
}

/// Normal-map texels: tilt θ_k = 0.07·k towards azimuth 2.4·k, encoded as glTF stores them.
fn tilted_texels() -> Vec<u8> {
    (0..N * N)
        .flat_map(|k| {
            let (theta, phi) = (0.07 * k as f32, 2.4 * k as f32);
            let v = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            let b = v.map(|c| ((c + 1.0) * 0.5 * 255.0).round() as u8);
            [b[0], b[1], b[2], 255]
        })
        .collect()
}

const RHO: f32 = 0.8;
const SUN: f32 = 2.0;

/// The quad with a NEAREST normal map mapped by `normal_uv`, lit by a directional light of
/// illuminance SUN along −Z (onto the quad, along its normal), no sky.
fn normal_scene(tag: &str, normal_uv: TexCoordDesc) -> Scene {
    let mut b = GltfBuilder::new();
    let tex = b
        .add_texture_rgba8(N as u32, N as u32, &tilted_texels(), 10497)
        .unwrap();
    b.set_mag_filter(tex, 9728);
    let mat = b.add_material(&MaterialDesc {
        normal_texture: Some((tex, 1.0)),
        normal_uv,
        ..MaterialDesc::diffuse(tag, [RHO; 3])
    });
    let mut roots = quad_nodes(&mut b, mat, tag);
    let sun = b.add_light(&LightDesc {
        name: Some("sun".into()),
        kind: LightKind::Directional,
        color: [1.0; 3],
        intensity: SUN,
        range: None,
    });
    roots.push(b.add_node(&NodeDesc {
        light: Some(sun),
        translation: Some([0.0, 0.0, 5.0]),
        ..NodeDesc::default()
    }));
    b.add_scene(tag, &roots, None);
    write_and_load(&b, &temp_dir(tag), tag)
}

/// Per pixel: ρ/π · E · cos θ of the normal-map texel that holds every point `at` of the pixel.
fn expected_shading(scene: &Scene, at: &[(f64, f64)]) -> Vec<Option<[f64; 3]>> {
    let view = scene.camera_at(0.0);
    let r = scene.materials[0].normal_texture.unwrap();
    let image = &scene.images[scene.textures[r.texture].image];
    assert!(!image.srgb, "normal maps are linear");
    let uvs = |p: Vec3| (uv0_at(p), uv1_at(p));
    let mut out = Vec::new();
    for py in 0..SIZE.1 {
        for px in 0..SIZE.0 {
            out.push(pixel_texel(&view, (px, py), at, &r, &uvs).map(|(x, y)| {
                let t = image.texel_linear(x as u32, y as u32);
                let v = [t.x, t.y, t.z].map(|c| 2.0 * f64::from(c) - 1.0);
                let cos = v[2] / (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                [f64::from(RHO) / PI * f64::from(SUN) * cos; 3]
            }));
        }
    }
    out
}

#[test]
fn a_normal_map_through_texcoord1_and_a_transform_shades_by_its_texels() {
    let map = uv(0, Some(tt([0.15, -0.3], 2.2, [1.4, 1.1])), Some(1));
    let scene = normal_scene("uv-normal", map);
    let plan = scene.plan();
    assert!(
        plan.normal_maps && plan.texcoord1 && plan.uv_transform,
        "{plan}"
    );
    let exp = expected_shading(&scene, &CORNERS);
    let checked = exp.iter().flatten().count();
    assert!(
        checked >= 600,
        "only {checked} pixels lie inside single texels"
    );
    let wrong = expected_shading(&normal_scene("uv-normal-as-0", uv(0, None, None)), &CENTRE);
    let differ = exp
        .iter()
        .zip(&wrong)
        .filter(|(a, b)| match (a, b) {
            (Some(a), Some(b)) => (a[0] - b[0]).abs() > 1e-3,
            (Some(_), None) => true,
            _ => false,
        })
        .count();
    eprintln!(
        "normal map: {checked} pixels checked, {differ} differ under TEXCOORD_0 untransformed"
    );
    assert!(differ * 4 > checked * 3, "{differ} of {checked}");

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let path = render(&ctx, &shaders, &scene, &mut gpu, SIZE, 4, 3);
    check("normal map, path tracer", &path.pixels, &exp);
    let settings = IcSettings {
        width: SIZE.0,
        height: SIZE.1,
        ..IcSettings::default()
    };
    let (ic, _) = render_ic(&ctx, &shaders, &scene, &mut gpu, &settings, &mut |_| {}).unwrap();
    assert_eq!(ic.nonfinite_pixels, 0);
    check("normal map, cache frame", &ic.pixels, &exp);
    drop(gpu);
    finish(ctx);
}

const FLOOR_RGB: [f32; 3] = [0.8, 0.6, 0.4];
const FLOOR_Y: f32 = 1.0;
const LAMP_Y: f32 = 3.0;
const LAMP_HALF: f32 = 1.0;
const LAMP_L: f32 = 4.0;

#[test]
fn an_emitter_lights_the_floor_with_the_texel_its_reference_maps_to() {
    // A 2 × 2 emissive texture, one bright texel (1, 0) among dark ones. The lamp's TEXCOORD_0
    // spans the texture; its TEXCOORD_1 spans [0, 1]², which the transform (through the
    // override) shrinks into texel (1, 0): offset (0.6, 0.15), scale 0.3, turned. Its whole
    // surface emits that texel, so the floor sees a uniform emitter of radiance L · texel.
    let tag = "uv-emitter";
    let mut b = GltfBuilder::new();
    let rgba: [u8; 16] = [
        10, 10, 10, 255, 255, 200, 150, 255, //
        30, 5, 5, 255, 5, 30, 5, 255,
    ];
    let tex = b.add_texture_rgba8(2, 2, &rgba, 33071).unwrap();
    b.set_mag_filter(tex, 9728);
    let floor = b.add_material(&MaterialDesc::diffuse("floor", FLOOR_RGB));
    let t = tt([0.6, 0.15], 0.4, [0.3, 0.3]);
    let lamp = b.add_material(&MaterialDesc {
        emissive_texture: Some(tex),
        emissive_uv: uv(0, Some(t), Some(1)),
        ..MaterialDesc::emitter("lamp", [0.0; 3], [LAMP_L; 3])
    });
    let floor_mesh = b.add_mesh(
        "floor",
        &[plane_y([-3.0, 3.0], [-3.0, 3.0], FLOOR_Y, floor)],
    );
    // Facing down: counter-clockwise seen from below.
    let h = LAMP_HALF;
    let corners = [
        [-h, LAMP_Y, -h],
        [-h, LAMP_Y, h],
        [h, LAMP_Y, h],
        [h, LAMP_Y, -h],
    ];
    let lamp_quad = PrimitiveDesc {
        texcoords: Some(vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]]),
        texcoords1: Some(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),
        ..PrimitiveDesc::triangles(
            corners.to_vec(),
            Some(vec![[0.0, -1.0, 0.0]; 4]),
            vec![0, 2, 1, 0, 3, 2],
            Some(lamp),
        )
    };
    let lamp_mesh = b.add_mesh("lamp", &[lamp_quad]);
    let roots = vec![
        b.add_node(&NodeDesc {
            mesh: Some(floor_mesh),
            ..NodeDesc::default()
        }),
        b.add_node(&NodeDesc {
            mesh: Some(lamp_mesh),
            ..NodeDesc::default()
        }),
        camera_node(
            &mut b,
            Vec3::new(0.2, 2.4, 0.1),
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            1.2,
        ),
    ];
    b.add_scene(tag, &roots, None);
    let scene = write_and_load(&b, &temp_dir(tag), tag);
    let plan = scene.plan();
    assert!(
        plan.texcoord1 && plan.uv_transform && plan.has_emissive(),
        "{plan}"
    );
    assert!(!plan.specular && !plan.analytic_emitters);
    // The CPU mapping: every corner of TEXCOORD_1 lands in texel (1, 0).
    let r = scene.materials[1].emissive_texture.unwrap();
    for c in [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE] {
        let p = r.map(Vec2::ZERO, c) * 2.0;
        assert!(p.x > 1.0 && p.x < 2.0 && p.y > 0.0 && p.y < 1.0, "{p}");
    }
    let le: [f64; 3] = std::array::from_fn(|c| {
        f64::from(LAMP_L) * f64::from(srgb_to_linear(f32::from(rgba[4 + c]) / 255.0))
    });

    let size = (32u32, 32u32);
    let view = scene.camera_at(0.0);
    let aspect = size.0 as f32 / size.1 as f32;
    let lamp_tris = [
        [corners[0], corners[2], corners[1]].map(Vec3::from),
        [corners[0], corners[3], corners[2]].map(Vec3::from),
    ];
    let omega = |p: Vec3| -> f64 {
        lamp_tris
            .iter()
            .map(|t| f64::from(triangle_projected_solid_angle(p, Vec3::Y, *t)))
            .sum()
    };
    // Per pixel, the mean over an 8 × 8 grid of the floor points it sees.
    let mut exp = Vec::new();
    for py in 0..size.1 {
        for px in 0..size.0 {
            let mut sum = 0.0;
            for j in 0..8 {
                for i in 0..8 {
                    let sx = f64::from(px) + (f64::from(i) + 0.5) / 8.0;
                    let sy = f64::from(py) + (f64::from(j) + 0.5) / 8.0;
                    let (x, y) = pixel_to_ndc(sx, sy, size.0, size.1);
                    let d = view.ray_direction(x, y, aspect);
                    sum += omega(view.position + d * ((FLOOR_Y - view.position.y) / d.y));
                }
            }
            let w = sum / 64.0;
            exp.push(std::array::from_fn::<f64, 3, _>(|c| {
                f64::from(FLOOR_RGB[c]) / PI * le[c] * w
            }));
        }
    }

    let ctx = context();
    let shaders = shaders();
    let mut gpu = GpuScene::new(&ctx, &scene, None).unwrap();
    let a = render(&ctx, &shaders, &scene, &mut gpu, size, 64, 1);
    let b = render(&ctx, &shaders, &scene, &mut gpu, size, 64, 2);
    let cache = |gpu: &mut GpuScene, seed: u32| {
        let settings = IcSettings {
            width: size.0,
            height: size.1,
            seed,
            ..IcSettings::default()
        };
        render_ic(&ctx, &shaders, &scene, gpu, &settings, &mut |_| {})
            .unwrap()
            .0
    };
    let (ca, cb) = (cache(&mut gpu, 1), cache(&mut gpu, 2));
    drop(gpu);
    finish(ctx);
    for (what, a, b) in [
        ("path tracer", &a.pixels, &b.pixels),
        ("cache frame", &ca.pixels, &cb.pixels),
    ] {
        check_blocks(what, size, a, b, &exp);
    }
}

/// The image's 8 × 8 blocks of two independent renders against `exp`: each block's sum of the
/// mean within 5 standard errors (from the renders' differences) plus 0.1 % for the 8 × 8
/// quadrature of the expected pixels and f32 accumulation.
fn check_blocks(what: &str, size: (u32, u32), a: &[[f32; 3]], b: &[[f32; 3]], exp: &[[f64; 3]]) {
    let (mut worst, mut worst_se) = (0.0f64, 0.0f64);
    let (mut got_all, mut exp_all) = (0.0, 0.0);
    for by in (0..size.1).step_by(8) {
        for bx in (0..size.0).step_by(8) {
            for c in 0..3 {
                let (mut got, mut want, mut var) = (0.0, 0.0, 0.0);
                for y in by..by + 8 {
                    for x in bx..bx + 8 {
                        let i = (y * size.0 + x) as usize;
                        let (va, vb) = (f64::from(a[i][c]), f64::from(b[i][c]));
                        got += 0.5 * (va + vb);
                        var += 0.25 * (va - vb).powi(2);
                        want += exp[i][c];
                    }
                }
                let se = var.sqrt();
                let tol = 5.0 * se + 1e-3 * want;
                assert!(
                    (got - want).abs() <= tol,
                    "{what}: block ({bx}, {by}) channel {c}: {got}, expected {want} ± {tol}"
                );
                worst = worst.max((got - want).abs() / want.max(1e-12));
                worst_se = worst_se.max((got - want).abs() / se.max(1e-12));
                got_all += got;
                exp_all += want;
            }
        }
    }
    eprintln!(
        "{what}: blocks within {worst:.4} relative, {worst_se:.2} SE; sum {got_all:.3}, \
         expected {exp_all:.3}"
    );
}

#[test]
fn every_pass_compiles_with_every_material_define() {
    let defines = [
        ("HAS_SPECULAR", "1"),
        ("HAS_ALPHA", "1"),
        ("HAS_NORMAL_MAPS", "1"),
        ("HAS_UV_TRANSFORM", "1"),
        ("HAS_TEXCOORD1", "1"),
        ("HAS_EMITTERS", "1"),
        ("HAS_LIGHTS", "1"),
        ("HAS_ENV_CONSTANT", "1"),
        ("HAS_ENV_MAP", "1"),
        ("HAS_RADIANCE_CACHE", "1"),
    ];
    let compiler = shaders();
    let out = temp_dir("uv-defines");
    let passes: Vec<String> =
        radcache_tests::shader_check::entry_shaders(&shader_root().join("passes"))
            .unwrap()
            .into_iter()
            .map(|p| format!("passes/{p}"))
            .collect();
    // At least every pass that reads the scene (includes common/scene.glsl).
    for scene_pass in [
        "aov.comp",
        "composite.comp",
        "direct.comp",
        "emission.comp",
        "gbuffer.frag",
        "gbuffer.vert",
        "path_trace.comp",
        "record.comp",
        "temporal.comp",
    ] {
        let path = format!("passes/{scene_pass}");
        assert!(passes.contains(&path), "{path} not found in {passes:?}");
    }
    for path in &passes {
        let spirv = compiler
            .compile(path, &defines)
            .unwrap_or_else(|e| panic!("{path} with every define: {e}"));
        let file = out.join(format!("{}.spv", path.replace('/', "_")));
        std::fs::write(&file, bytemuck::cast_slice::<u32, u8>(&spirv)).unwrap();
        let val = std::process::Command::new("spirv-val")
            .args(["--target-env", "vulkan1.3"])
            .arg(&file)
            .output()
            .expect("spirv-val (scripts/setup.sh installs spirv-tools)");
        assert!(
            val.status.success(),
            "{path}: spirv-val: {}{}",
            String::from_utf8_lossy(&val.stdout),
            String::from_utf8_lossy(&val.stderr)
        );
    }
}
