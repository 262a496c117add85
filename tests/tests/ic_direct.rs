//! The cache's direct-lighting and composite passes on lavapipe: direct light against closed
//! forms (point light, constant sky) and independent estimates (a CPU light-sampling estimate on
//! the Cornell box, the furnace), and the composite's sums, sub-frame mean and guard.

use std::f64::consts::PI;

use glam::{DVec3, Quat, Vec3};
use radcache_render::{
    passes::composite::CompositeInputs, passes::composite::CompositeJob,
    passes::composite::CompositePass, passes::composite::CompositeVariant,
    passes::direct::DirectPass, passes::direct::DirectVariant, passes::emission::EmissionPass,
    passes::splat::SplatPass, EmitterLight, EnvMap, SkyLight,
};
use radcache_scene::light::LightKind;
use radcache_scene::writer::{GltfBuilder, LightDesc, MaterialDesc, NodeDesc};
use radcache_scene::{Environment, Scene};
use radcache_tests::direct_cpu::{agree, cpu_direct};
use radcache_tests::ic_fixture::*;
use radcache_tests::scenes::{
    camera_node, load, mean_se, pixel_to_ndc, plane_y, temp_dir, write_and_load,
};

const ALBEDO: [f32; 3] = [0.8, 0.5, 0.25];

/// A diffuse plane (albedo [`ALBEDO`], facing up) seen from above, its far side beyond the image's
/// top rows (background there), with an optional point light (position, cd) and constant sky.
fn plane_scene(name: &str, light: Option<(Vec3, f32)>, sky: Option<[f32; 3]>) -> Scene {
    let mut b = GltfBuilder::new();
    let mat = b.add_material(&MaterialDesc::diffuse("plane", ALBEDO));
    let mesh = b.add_mesh("plane", &[plane_y([-4.0, 4.0], [-3.0, 3.0], 0.0, mat)]);
    let mut roots = vec![b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    })];
    let rotation = Quat::from_rotation_x(-0.6);
    roots.push(camera_node(&mut b, Vec3::new(0.0, 2.0, 3.0), rotation, 0.7));
    if let Some((position, intensity)) = light {
        let kind = LightKind::Point;
        let desc = LightDesc {
            name: None,
            kind,
            color: [1.0; 3],
            intensity,
            range: None,
        };
        let l = b.add_light(&desc);
        roots.push(b.add_node(&NodeDesc {
            translation: Some(position.to_array()),
            light: Some(l),
            ..NodeDesc::default()
        }));
    }
    let extras = sky.map(|l| serde_json::json!({"environment": {"radiance": l}}));
    b.add_scene(name, &roots, extras);
    write_and_load(&b, &temp_dir(name), name)
}

#[test]
fn direct_light_matches_a_point_light_and_a_constant_sky() {
    let (light, intensity, sky) = (Vec3::new(0.3, 1.5, 0.2), 5.0, [0.5, 1.0, 2.0]);
    let albedo = Vec3::from(ALBEDO).as_dvec3();
    // The sky is sampled here ([`SkyLight::Direct`]) or left to the records, where the pass
    // must leave it out entirely: no light, no ray.
    for (name, point, sky_light) in [
        ("ic-passes-point", true, SkyLight::Direct),
        ("ic-passes-sky", false, SkyLight::Direct),
        ("ic-passes-sky-in-records", false, SkyLight::Records),
    ] {
        let scene = plane_scene(
            name,
            point.then_some((light, intensity)),
            (!point).then_some(sky),
        );
        let gpu = Gpu::new(&scene, None, (32, 24));
        let direct = direct_pass(&gpu, sky_light, EmitterLight::Sampled).unwrap();
        let in_records = sky_light == SkyLight::Records;
        let samples = 4;
        let scopes = gpu.render([0.1, 0.2], Some((&direct, samples, 7)));
        assert!(scopes.iter().any(|s| s == "direct"), "{scopes:?}");
        let position = gpu.read(&gpu.gbuffer.position);
        let out = gpu.read(&gpu.gbuffer.direct);
        let mut surfaces = 0;
        for (i, (p, d)) in position.iter().zip(&out).enumerate() {
            let expected = if p[3] == 0.0 || in_records {
                DVec3::ZERO
            } else if point {
                // ρ/π · I · cosθ / d², exact: a punctual light has no randomness.
                let to = light.as_dvec3() - xyz(*p);
                let d2 = to.length_squared();
                albedo / PI * f64::from(intensity) * (to.y / d2.sqrt()) / d2
            } else {
                // Every cosine-sampled ray sees the sky with weight 1: exactly ρ·L.
                albedo * Vec3::from(sky).as_dvec3()
            };
            surfaces += u64::from(p[3] != 0.0);
            let tol = 1e-5 * expected.max_element() + 1e-9;
            close("direct", i, xyz(*d), expected, tol);
        }
        assert!(
            surfaces > 100 && surfaces < 32 * 24,
            "{surfaces} surface pixels"
        );
        // The point light: one shadow ray per pixel, no sampling (nothing to sample); the sky:
        // one BSDF ray per sample (only BSDF sampling finds a constant environment), or none
        // when the records bring it.
        let expected_rays = if point {
            surfaces
        } else if in_records {
            0
        } else {
            surfaces * u64::from(samples)
        };
        assert_eq!(direct.rays().unwrap(), expected_rays);
        drop(direct);
        gpu.end();
    }
}

/// Both estimators of the emitters' light agree with the CPU's: one-sample MIS (unbiased) and the
/// closed form times the sampled visible fraction (the ratio estimator: consistent, its bias in
/// penumbrae below this test's resolution at 4 samples).
#[test]
fn direct_light_is_unbiased_on_the_cornell_box() {
    let scene = cornell();
    assert!(scene.plan().analytic_emitters);
    let gpu = Gpu::new(&scene, None, (16, 16));
    gpu.render([0.0; 2], None);
    let g = gpu.read_gbuffer();
    let cpu = cpu_direct(&scene, &g, 256);
    for emitters in [EmitterLight::Sampled, EmitterLight::Analytic] {
        eprintln!("{emitters:?}:");
        direct_agrees_with_the_cpu(&gpu, &g, &cpu, emitters);
    }
    gpu.end();
}

/// The direct pass for `gpu`'s scene, writing the direct image.
fn direct_pass(
    gpu: &Gpu,
    sky: SkyLight,
    emitters: EmitterLight,
) -> radcache_render::Result<DirectPass> {
    let variant = DirectVariant::new(sky, emitters);
    DirectPass::new(&gpu.ctx, &gpu.shaders, &gpu.scene, &variant)
}

fn direct_agrees_with_the_cpu(gpu: &Gpu, g: &GRead, cpu: &[DVec3], emitters: EmitterLight) {
    let direct = direct_pass(gpu, SkyLight::Direct, emitters).unwrap();
    let mut runs = Vec::new();
    for (samples, seed) in [(4, 11), (256, 12)] {
        gpu.render([0.0; 2], Some((&direct, samples, seed)));
        runs.push(
            gpu.read(&gpu.gbuffer.direct)
                .into_iter()
                .map(xyz)
                .collect::<Vec<_>>(),
        );
        let rays = direct.rays().unwrap();
        assert!(
            rays > 0 && rays <= 2 * 256 * u64::from(samples),
            "{rays} rays"
        );
    }
    let pixels: Vec<usize> = (0..256).filter(|&i| g.position[i][3] > 0.0).collect();
    assert!(pixels.len() > 200, "{} surface pixels", pixels.len());
    agree("4 samples vs CPU", &runs[0], cpu, &pixels);
    agree("256 samples vs CPU", &runs[1], cpu, &pixels);
    agree("4 vs 256 samples", &runs[0], &runs[1], &pixels);
}

/// In a scene with specular materials the closed form serves the Lambertian pixels (base
/// colour / π times the closed-form irradiance times the sampled visible fraction) and the
/// others keep the emitters in their one-sample MIS: both agree with sampling everywhere, on
/// the walls and on the metal spheres, and the walls trace far fewer rays.
#[test]
fn closed_form_emitters_in_a_specular_scene_agree_with_sampling() {
    let scene = load(
        &std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../assets/metal_spheres/metal_spheres.gltf"),
    );
    let plan = scene.plan();
    assert!(plan.specular && plan.analytic_emitters, "{plan:?}");
    let gpu = Gpu::new(&scene, None, (32, 32));
    gpu.render([0.0; 2], None);
    let g = gpu.read_gbuffer();
    let run = |emitters: EmitterLight, samples: u32, seed: u32| -> (Vec<DVec3>, u64) {
        let direct = direct_pass(&gpu, SkyLight::Direct, emitters).unwrap();
        gpu.render([0.0; 2], Some((&direct, samples, seed)));
        let out = gpu.read(&gpu.gbuffer.direct).into_iter().map(xyz).collect();
        (out, direct.rays().unwrap())
    };
    let (sampled, sampled_rays) = run(EmitterLight::Sampled, 256, 21);
    let (analytic, analytic_rays) = run(EmitterLight::Analytic, 256, 22);
    let lambertian = |i: usize| {
        let material = g.geometric[i][3].max(0.0) as usize;
        scene.materials[material].is_lambertian()
    };
    let surfaces: Vec<usize> = (0..32 * 32).filter(|&i| g.position[i][3] > 0.0).collect();
    let (walls, metal): (Vec<usize>, Vec<usize>) = surfaces.iter().partition(|&&i| lambertian(i));
    assert!(
        walls.len() > 500 && metal.len() > 50,
        "{} wall and {} metal pixels",
        walls.len(),
        metal.len()
    );
    assert!(analytic
        .iter()
        .all(|v| v.is_finite() && v.min_element() >= 0.0));
    agree("walls: closed form vs sampled", &analytic, &sampled, &walls);
    agree(
        "metal: closed form scene vs sampled",
        &analytic,
        &sampled,
        &metal,
    );
    eprintln!("direct rays: sampled {sampled_rays}, closed form {analytic_rays}");
    assert!(
        (analytic_rays as f64) < 0.7 * sampled_rays as f64,
        "{analytic_rays} rays against {sampled_rays}"
    );
    gpu.end();
}

#[test]
fn direct_light_in_the_furnace_is_albedo_times_emission() {
    let (albedo, le) = (0.5, 1.0);
    let dir = temp_dir("ic-passes-furnace");
    let scene = load(&radcache_scene::assets::write_furnace(&dir, albedo, le).unwrap());
    let gpu = Gpu::new(&scene, None, (16, 16));
    // Every direction sees an emitting wall: irradiance π·Le, direct ρ/π · π·Le = ρ·Le.
    let expected = f64::from(albedo * le);
    let sampled = direct_pass(&gpu, SkyLight::Direct, EmitterLight::Sampled).unwrap();
    gpu.render([0.0; 2], Some((&sampled, 4, 3)));
    let out = gpu.read(&gpu.gbuffer.direct);
    for c in 0..3 {
        let values: Vec<f64> = out.iter().map(|p| f64::from(p[c])).collect();
        assert!(values.iter().all(|v| v.is_finite() && *v >= 0.0));
        let m = mean_se(&values);
        assert!(
            (m.mean - expected).abs() <= 5.0 * m.se + 1e-5,
            "channel {c}: {m:?}, expected {expected}"
        );
    }
    // The closed form: the walls' projected solid angles (the adjacent walls cut by the
    // horizon, the receiver's own wall wholly below it) sum to π, and every light sample is
    // visible, so every pixel is exact, without noise.
    assert!(scene.plan().analytic_emitters, "{:?}", scene.plan());
    let analytic = direct_pass(&gpu, SkyLight::Direct, EmitterLight::Analytic);
    let analytic = analytic.unwrap();
    gpu.render([0.0; 2], Some((&analytic, 4, 3)));
    let position = gpu.read(&gpu.gbuffer.position);
    let out = gpu.read(&gpu.gbuffer.direct);
    for (i, (p, d)) in position.iter().zip(&out).enumerate() {
        assert!(p[3] > 0.0, "pixel {i} sees no wall");
        close(
            "analytic direct",
            i,
            xyz(*d),
            DVec3::splat(expected),
            1e-4 * expected,
        );
    }
    drop((sampled, analytic));
    gpu.end();
}

/// Texel of an equirectangular `w × h` map seen along `d`, unless `d` is within 10⁻³ texel of a
/// texel edge (where f32 and f64 may disagree).
fn env_texel(d: DVec3, w: u32, h: u32) -> Option<usize> {
    let u = (0.5 + d.x.atan2(-d.z) / (2.0 * PI)) * f64::from(w);
    let v = d.y.clamp(-1.0, 1.0).acos() / PI * f64::from(h);
    let edge = |x: f64| (x - x.round()).abs() < 1e-3;
    (!edge(u) && !edge(v)).then(|| v.floor() as usize * w as usize + u.floor() as usize)
}

#[test]
fn composite_sums_direct_indirect_emission_and_environment() {
    let mut scene = faces_scene();
    let (ew, eh, env_scale) = (8, 4, 1.5);
    let texels: Vec<[f32; 3]> = (0..ew * eh)
        .map(|i| {
            [
                0.1 * (i % ew + 1) as f32,
                0.3 * (i / ew + 1) as f32,
                0.05 * i as f32,
            ]
        })
        .collect();
    let map = EnvMap::from_rgb(std::path::Path::new("sky"), ew, eh, texels.clone()).unwrap();
    scene.environment = Environment::Map {
        path: "sky".into(),
        scale: env_scale,
    };
    let (w, h) = (40, 32);
    let gpu = Gpu::new(&scene, Some(&map), (w, h));
    let (ctx, shaders) = (&gpu.ctx, &gpu.shaders);
    let direct = direct_pass(&gpu, SkyLight::Direct, EmitterLight::Sampled).unwrap();
    let splat = SplatPass::new(ctx, shaders, w, h).unwrap();
    let variant = CompositeVariant::new(w, h);
    let composite = CompositePass::new(ctx, shaders, &gpu.scene, &variant).unwrap();
    let emission = EmissionPass::new(ctx, shaders, &gpu.scene).unwrap();
    let jitter = [0.2, -0.3];
    gpu.render(jitter, Some((&direct, 4, 9)));
    let g = gpu.read_gbuffer();
    let lit = gpu.read(&gpu.gbuffer.direct);
    // One sub-frame with a constant splat sum (Σw·Ẽ, Σw) in every pixel.
    let sub_frame = |sum: Px, clear: bool| {
        let mut rec = ctx.begin("test.composite").unwrap();
        if clear {
            composite.record(&mut rec, CompositeJob::Clear).unwrap();
        }
        for (image, value) in [(&splat.sum, sum), (&splat.count, [0.0; 4])] {
            rec.clear_color(image, value);
        }
        let inputs = CompositeInputs::own(&gpu.scene, &gpu.gbuffer, &splat, jitter);
        composite
            .record(&mut rec, CompositeJob::Add(&inputs))
            .unwrap();
        names(&ctx.submit(rec).unwrap().wait().unwrap())
    };
    // No record reaches any pixel (Σw = 0: no indirect light), then Ẽ = (1, 2, 3) everywhere.
    sub_frame([0.0; 4], true);
    let scopes = sub_frame([2.0, 4.0, 6.0, 2.0], false);
    assert!(scopes.iter().any(|s| s == "composite"), "{scopes:?}");
    let (mean, bad) = composite.read_mean(ctx).unwrap();
    assert_eq!(bad, 0);
    let view = scene.camera_at(0.0);
    let (mut surfaces, mut sky) = (0, 0);
    for (i, m) in mean.iter().enumerate() {
        let m = DVec3::from(m.map(f64::from));
        if g.position[i][3] > 0.0 {
            let indirect = xyz(g.albedo[i]) / PI * DVec3::new(1.0, 2.0, 3.0) * 0.5;
            close(
                "surface",
                i,
                m,
                xyz(lit[i]) + indirect,
                1e-5 * (m.max_element() + 1.0),
            );
            surfaces += 1;
        } else {
            let sx = f64::from(i as u32 % w) + 0.5 + f64::from(jitter[0]);
            let sy = f64::from(i as u32 / w) + 0.5 + f64::from(jitter[1]);
            let (nx, ny) = pixel_to_ndc(sx, sy, w, h);
            let d = view.ray_direction(nx, ny, w as f32 / h as f32).as_dvec3();
            if let Some(t) = env_texel(d, ew, eh) {
                let expected = Vec3::from(texels[t]).as_dvec3() * f64::from(env_scale);
                close("environment", i, m, expected, 1e-5 * expected.max_element());
                sky += 1;
            }
        }
    }
    assert!(
        surfaces > 500 && sky > 100,
        "{surfaces} surface and {sky} sky pixels"
    );
    // The emission pass adds the box-filtered emission: nothing away from emitters, the exact
    // radiance where the pixel and its 8 neighbours all see the same emitting face.
    let mut rec = ctx.begin("test.emission").unwrap();
    emission.record(&mut rec, &gpu.scene, &composite).unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    let (with_emission, _) = composite.read_mean(ctx).unwrap();
    let (mut dark, mut inside) = (0, 0);
    for i in 0..(w * h) as usize {
        let (x, y) = ((i as u32 % w) as i64, (i as u32 / w) as i64);
        let block: Vec<usize> = (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            .filter(|&(a, b)| a >= 0 && b >= 0 && a < i64::from(w) && b < i64::from(h))
            .map(|(a, b)| (b * i64::from(w) + a) as usize)
            .collect();
        let key = |j: usize| (g.geometric[j], g.emission[j]);
        let added =
            DVec3::from(with_emission[i].map(f64::from)) - DVec3::from(mean[i].map(f64::from));
        let tol = 1e-5 * (DVec3::from(mean[i].map(f64::from)).max_element() + 10.0);
        if block.iter().all(|&j| xyz(g.emission[j]) == DVec3::ZERO) {
            close("no emission", i, added, DVec3::ZERO, 0.0);
            dark += 1;
        } else if block.len() == 9 && block.iter().all(|&j| key(j) == key(i)) {
            close("emission", i, added, xyz(g.emission[i]), tol);
            inside += 1;
        }
    }
    assert!(
        dark > 500 && inside > 10,
        "{dark} dark and {inside} emitting pixels checked"
    );
    // A non-finite splat sum: every surface pixel is dropped (0) and counted, the sky unchanged.
    sub_frame([f32::INFINITY, f32::INFINITY, f32::INFINITY, 1.0], true);
    let (guarded, bad) = composite.read_mean(ctx).unwrap();
    assert_eq!(bad, surfaces as u64);
    for (i, (a, b)) in guarded.iter().zip(&mean).enumerate() {
        let expected = if g.position[i][3] > 0.0 { [0.0; 3] } else { *b };
        assert_eq!(*a, expected, "pixel {i}");
    }
    drop((direct, splat, composite, emission));
    gpu.end();
}
