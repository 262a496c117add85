//! The cache's G-buffer pass on lavapipe against CPU ray casting, rasterized and ray traced
//! (Cornell box; a scene of front, back, double-sided and mirrored emitters).

use glam::{DVec3, Vec3};
use radcache_scene::Scene;
use radcache_tests::ic_fixture::*;
use radcache_tests::scenes::pixel_to_ndc;

/// Pixels checked per kind: surfaces, background, visible emission, emitters seen from behind,
/// mirrored instances.
#[derive(Debug, Default)]
struct Checked {
    surface: usize,
    background: usize,
    emitting: usize,
    dark_emitter: usize,
    mirrored: usize,
}

/// Compares every pixel of `g` away from silhouettes with the CPU ray through its sample
/// position (centre + `jitter`).
fn check_gbuffer(scene: &Scene, gpu: &Gpu, g: &GRead, jitter: [f32; 2]) -> Checked {
    let (w, h) = gpu.size;
    let tris = world_triangles(scene);
    let view = scene.camera_at(0.0);
    let o = view.position.as_dvec3();
    let ray_at = |i: usize, dx: f64, dy: f64| {
        let sx = f64::from(i as u32 % w) + 0.5 + f64::from(jitter[0]) + dx;
        let sy = f64::from(i as u32 / w) + 0.5 + f64::from(jitter[1]) + dy;
        let (nx, ny) = pixel_to_ndc(sx, sy, w, h);
        view.ray_direction(nx, ny, w as f32 / h as f32).as_dvec3()
    };
    let tol = 1e-4 * f64::from(gpu.scene.scene_scale());
    let triangle = |d: DVec3| cast(&tris, o, d, f64::MAX).map(|h| h.1);
    let tan_half = (view.perspective.yfov * 0.5).tan();
    let mut c = Checked::default();
    for i in 0..(w * h) as usize {
        // Rasterization rules decide samples on an edge: skip those within 0.05 px of one.
        let d = ray_at(i, 0.0, 0.0);
        let probes = [(0.05, 0.0), (-0.05, 0.0), (0.0, 0.05), (0.0, -0.05)];
        let centre = triangle(d);
        if probes
            .iter()
            .any(|&(dx, dy)| triangle(ray_at(i, dx, dy)) != centre)
        {
            continue;
        }
        let hit = cast(&tris, o, d, f64::MAX);
        let Some((t, k, u, v)) = hit else {
            let all = [
                g.position[i],
                g.normal[i],
                g.geometric[i],
                g.albedo[i],
                g.emission[i],
            ];
            assert!(
                all.iter().flatten().all(|v| *v == 0.0),
                "background pixel {i}: {all:?}"
            );
            c.background += 1;
            continue;
        };
        let tri = &tris[k];
        let p = o + d * t;
        assert_eq!(g.position[i][3], 1.0, "pixel {i} is not a surface");
        close("position", i, xyz(g.position[i]), p, tol);
        let sees_front = tri.front.dot(d) < 0.0;
        let ng = if sees_front { tri.front } else { -tri.front };
        assert!(
            xyz(g.geometric[i]).dot(ng) > 1.0 - 1e-5,
            "pixel {i} geometric normal {:?} vs {ng}",
            g.geometric[i]
        );
        assert_eq!(g.geometric[i][3], tri.material as f32, "pixel {i} material");
        let b = [1.0 - u - v, u, v];
        let ns = (0..3)
            .map(|j| tri.n[j].as_dvec3() * b[j])
            .sum::<DVec3>()
            .normalize();
        let ns = if sees_front { ns } else { -ns };
        let ns = if ns.dot(ng) > 0.0 { ns } else { ng };
        close("shading normal", i, xyz(g.normal[i]), ns, 1e-4);
        let depth = (p - o).dot(view.forward.as_dvec3()) as f32;
        let cos_view = ng.dot(-d) as f32;
        let footprint =
            radcache_cache::radius::pixel_footprint(depth, tan_half, h as f32, cos_view);
        let rel = (g.normal[i][3] / footprint - 1.0).abs();
        assert!(
            rel < 1e-3,
            "pixel {i} footprint {} vs {footprint}",
            g.normal[i][3]
        );
        let material = &scene.materials[tri.material as usize];
        let albedo = material
            .diffuse_albedo()
            .clamp(Vec3::ZERO, Vec3::ONE)
            .as_dvec3();
        close("albedo", i, xyz(g.albedo[i]), albedo, 1e-6);
        let le = scene.material_emission[tri.material as usize].as_dvec3();
        let emits = sees_front || material.double_sided;
        let expected = if emits { le } else { DVec3::ZERO };
        close(
            "emission",
            i,
            xyz(g.emission[i]),
            expected,
            1e-5 * le.max_element(),
        );
        c.surface += 1;
        c.emitting += usize::from(expected.max_element() > 0.0);
        c.dark_emitter += usize::from(le.max_element() > 0.0 && !emits);
        c.mirrored += usize::from(tri.mirrored);
    }
    c
}

/// Both ways of making the G-buffer (rasterized; ray traced, which scenes of many triangles
/// get) against CPU ray casting. The tall image is dispatched in 16 classes of rows
/// (`radcache_shared::dispatch`): every pixel must still be the one its workgroup's row says.
#[test]
fn gbuffer_matches_cpu_ray_casting() {
    assert_eq!(radcache_shared::dispatch::image_dispatch(24, 1024)[2], 16);
    let cases = [
        (cornell(), (64, 64)),
        (faces_scene(), (40, 32)),
        (cornell(), (24, 1024)),
    ];
    for ((scene, size), traced) in cases.iter().flat_map(|c| [(c, false), (c, true)]) {
        let (scene, size) = (scene, *size);
        let gpu = Gpu::with_gbuffer(scene, None, size, Some(traced));
        for jitter in [[0.0, 0.0], [0.3, -0.4]] {
            let scopes = gpu.render(jitter, None);
            assert!(scopes.iter().any(|s| s == "gbuffer"), "{scopes:?}");
            let c = check_gbuffer(scene, &gpu, &gpu.read_gbuffer(), jitter);
            eprintln!("{size:?} traced {traced} jitter {jitter:?}: {c:?}");
            let n = (size.0 * size.1) as usize;
            assert!(
                c.surface + c.background > n / 2,
                "too few pixels checked: {c:?}"
            );
            assert!(c.emitting > 4, "{c:?}");
            if size.0 == 40 {
                assert!(
                    c.background > 20 && c.dark_emitter > 10 && c.mirrored > 20,
                    "{c:?}"
                );
            }
        }
        gpu.end();
    }
}
