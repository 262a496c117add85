//! The emission rule (front face = counter-clockwise side; both faces when double-sided),
//! mirrored instances, emitter power and power-proportional sampling.

mod common;

use common::{close, close3, load, temp_dir, write};
use glam::{Mat4, Vec3};
use radcache_scene::writer::{GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{emitted_radiance, luminance, EmissiveTriangle, EmitterTable};

const TRI: [Vec3; 3] = [Vec3::ZERO, Vec3::X, Vec3::Y];

#[test]
fn front_face_only_unless_double_sided() {
    let le = Vec3::new(3.0, 2.0, 1.0);
    let t = EmissiveTriangle::new((0, 0, 0), &TRI, &Mat4::IDENTITY, le, false).unwrap();
    close3(t.normal, Vec3::Z, 0.0);
    close(t.area, 0.5, 0.0);
    assert_eq!(t.emitted_radiance(Vec3::new(0.3, 0.2, 1.0).normalize()), le);
    assert_eq!(t.emitted_radiance(-Vec3::Z), Vec3::ZERO);
    assert_eq!(
        t.emitted_radiance(Vec3::X),
        Vec3::ZERO,
        "grazing direction emits nothing"
    );
    let d = EmissiveTriangle::new((0, 0, 0), &TRI, &Mat4::IDENTITY, le, true).unwrap();
    assert_eq!(d.emitted_radiance(Vec3::Z), le);
    assert_eq!(d.emitted_radiance(-Vec3::Z), le);
    close(t.power(), luminance(le) * 0.5 * std::f32::consts::PI, 1e-6);
    close(d.power(), 2.0 * t.power(), 1e-6);
    assert_eq!(emitted_radiance(Vec3::Y, le, false, -Vec3::Y), Vec3::ZERO);
}

#[test]
fn transforms_move_the_front_face() {
    let le = Vec3::ONE;
    // Rotating 180° about X turns the front face to −Z.
    let r = Mat4::from_rotation_x(std::f32::consts::PI);
    let t = EmissiveTriangle::new((0, 0, 0), &TRI, &r, le, false).unwrap();
    close3(t.normal, -Vec3::Z, 1e-6);
    // A mirror (negative determinant) flips the winding (glTF spec): the front stays the mirror
    // image of the original front, +Z here.
    let m = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
    let t = EmissiveTriangle::new((0, 0, 0), &TRI, &m, le, false).unwrap();
    close3(t.normal, Vec3::Z, 1e-6);
    // Scaling scales the area; a zero scale makes no emitter.
    let t = EmissiveTriangle::new(
        (0, 0, 0),
        &TRI,
        &Mat4::from_scale(Vec3::splat(2.0)),
        le,
        false,
    )
    .unwrap();
    close(t.area, 2.0, 1e-6);
    assert!(
        EmissiveTriangle::new((0, 0, 0), &TRI, &Mat4::from_scale(Vec3::ZERO), le, false).is_none()
    );
}

fn emissive_scene(double_sided: bool) -> radcache_scene::Scene {
    let mut m = MaterialDesc::emitter("lamp", [0.5; 3], [5.0, 5.0, 5.0]);
    m.double_sided = double_sided;
    let b = common::triangle_scene(Some(m), |_| {});
    let dir = temp_dir("emit");
    load(&write(&b, &dir, "e")).0
}

#[test]
fn loaded_emitters_follow_the_rule() {
    for double_sided in [false, true] {
        let s = emissive_scene(double_sided);
        let e = s.emitters_at(0.0);
        assert_eq!(e.triangles.len(), 1);
        let t = &e.triangles[0];
        close3(t.radiance, Vec3::splat(5.0), 1e-6);
        assert_eq!(t.double_sided, double_sided);
        assert_eq!(t.emitted_radiance(Vec3::Z), Vec3::splat(5.0));
        let back = if double_sided {
            Vec3::splat(5.0)
        } else {
            Vec3::ZERO
        };
        assert_eq!(t.emitted_radiance(-Vec3::Z), back);
        let sides = if double_sided { 2.0 } else { 1.0 };
        close(
            e.total_power,
            5.0 * 0.5 * std::f32::consts::PI * sides,
            1e-5,
        );
        assert_eq!(e.sample(0.3), Some((0, 1.0)));
    }
}

/// splitmix64 → uniform f32 in [0, 1).
fn uniform(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

#[test]
fn sampling_frequencies_match_the_pmf() {
    // Triangles of different sizes and radiances (one single-sided, one double-sided).
    let mut tris = Vec::new();
    for (k, (scale, le, ds)) in [
        (1.0, 1.0, false),
        (2.0, 0.5, false),
        (0.5, 8.0, true),
        (3.0, 0.1, false),
        (1.0, 4.0, true),
    ]
    .into_iter()
    .enumerate()
    {
        let m = Mat4::from_scale(Vec3::splat(scale));
        tris.push(EmissiveTriangle::new((k, 0, k), &TRI, &m, Vec3::splat(le), ds).unwrap());
    }
    let table = EmitterTable::new(tris.clone());
    let total: f32 = tris.iter().map(|t| t.power()).sum();
    close(table.total_power, total, 1e-4);
    for (i, t) in tris.iter().enumerate() {
        close(table.table.pmf[i], t.power() / total, 1e-6);
    }
    assert_eq!(table.table.prob.len(), 5);
    assert_eq!(table.table.alias.len(), 5);
    let n = 400_000;
    let mut counts = [0usize; 5];
    let mut rng = 7u64;
    for _ in 0..n {
        let (i, pmf) = table.sample(uniform(&mut rng)).unwrap();
        close(pmf, table.table.pmf[i], 0.0);
        counts[i] += 1;
    }
    for (i, &c) in counts.iter().enumerate() {
        let p = f64::from(table.table.pmf[i]);
        let sigma = (p * (1.0 - p) / n as f64).sqrt();
        let freq = c as f64 / n as f64;
        assert!(
            (freq - p).abs() < 5.0 * sigma + 1e-9,
            "triangle {i}: frequency {freq} vs pmf {p}"
        );
    }
}

#[test]
fn textured_emission_uses_the_texture_mean_for_power() {
    let mut b = GltfBuilder::new();
    // 2x1 texture: one white texel, one black (sRGB 255 and 0): mean linear 0.5.
    let tex = b
        .add_texture_rgba8(2, 1, &[255, 255, 255, 255, 0, 0, 0, 255], 33071)
        .unwrap();
    let mut m = MaterialDesc::emitter("lamp", [1.0; 3], [2.0; 3]);
    m.emissive_texture = Some(tex);
    let mat = b.add_material(&m);
    let mut prim = PrimitiveDesc::triangles(
        TRI.map(|p| p.to_array()).to_vec(),
        None,
        vec![0, 1, 2],
        Some(mat),
    );
    prim.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let mesh = b.add_mesh("m", &[prim]);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    let dir = temp_dir("emit-tex");
    let (s, _) = load(&write(&b, &dir, "t"));
    assert_eq!(s.textures.len(), 1);
    assert!(s.images[0].srgb);
    close3(s.material_emission[0], Vec3::ONE, 1e-6);
    close3(s.emitters_at(0.0).triangles[0].radiance, Vec3::ONE, 1e-6);
}
