//! Animation sampling against hand-computed values (LINEAR, STEP, CUBICSPLINE, slerp), key
//! boundaries, clamping outside the range, and hierarchy/dynamic propagation in a loaded file.

mod common;

use common::{close, close3, load, temp_dir, write};
use glam::{Quat, Vec3, Vec4};
use radcache_scene::writer::{ChannelDesc, GltfBuilder, NodeDesc, PrimitiveDesc};
use radcache_scene::{AnimationKind, Interpolation, Property, Sampler, WarningKind};

fn sampler(interpolation: Interpolation, times: &[f32], values: &[Vec4]) -> Sampler {
    Sampler {
        interpolation,
        times: times.to_vec(),
        values: values.to_vec(),
    }
}

fn v3(x: f32, y: f32, z: f32) -> Vec4 {
    Vec4::new(x, y, z, 0.0)
}

fn rotation_of(v: Vec4) -> Quat {
    let q = Quat::from_vec4(v);
    close(q.length(), 1.0, 1e-5);
    q
}

#[test]
fn linear_translation_with_clamping() {
    let s = sampler(
        Interpolation::Linear,
        &[1.0, 3.0],
        &[v3(0.0, 0.0, 0.0), v3(2.0, 4.0, 6.0)],
    );
    let at = |t| s.sample(t, Property::Translation).truncate();
    close3(at(2.0), Vec3::new(1.0, 2.0, 3.0), 1e-6);
    close3(at(1.5), Vec3::new(0.5, 1.0, 1.5), 1e-6);
    close3(at(1.0), Vec3::ZERO, 0.0);
    close3(at(3.0), Vec3::new(2.0, 4.0, 6.0), 0.0);
    close3(at(-10.0), Vec3::ZERO, 0.0);
    close3(at(10.0), Vec3::new(2.0, 4.0, 6.0), 0.0);
    assert_eq!(s.time_range(), (1.0, 3.0));
    assert!(!s.is_constant());
}

#[test]
fn step_holds_until_next_key() {
    let s = sampler(
        Interpolation::Step,
        &[0.0, 1.0, 2.0],
        &[v3(1.0, 1.0, 1.0), v3(2.0, 2.0, 2.0), v3(3.0, 3.0, 3.0)],
    );
    let x = |t| s.sample(t, Property::Scale).x;
    assert_eq!(
        [x(-1.0), x(0.0), x(0.999), x(1.0), x(1.5), x(2.0), x(7.0)],
        [1.0, 1.0, 1.0, 2.0, 2.0, 3.0, 3.0]
    );
}

#[test]
fn linear_rotation_slerp_takes_the_shortest_path() {
    let id = Vec4::from(Quat::IDENTITY);
    let y90 = Vec4::from(Quat::from_rotation_y(90f32.to_radians()));
    let s = sampler(Interpolation::Linear, &[0.0, 1.0], &[id, y90]);
    let q = rotation_of(s.sample(0.5, Property::Rotation));
    close(
        q.angle_between(Quat::from_rotation_y(45f32.to_radians())),
        0.0,
        1e-4,
    );
    let q = rotation_of(s.sample(0.25, Property::Rotation));
    close(
        q.angle_between(Quat::from_rotation_y(22.5f32.to_radians())),
        0.0,
        1e-4,
    );
    // The same end rotation with a negated quaternion: same path.
    let s = sampler(Interpolation::Linear, &[0.0, 1.0], &[id, -y90]);
    let q = rotation_of(s.sample(0.5, Property::Rotation));
    close(
        q.angle_between(Quat::from_rotation_y(45f32.to_radians())),
        0.0,
        1e-4,
    );
    // +270° about Y is -90°: the shortest path goes through -45°.
    let y270 = Vec4::from(Quat::from_rotation_y(270f32.to_radians()));
    let s = sampler(Interpolation::Linear, &[0.0, 1.0], &[id, y270]);
    let q = rotation_of(s.sample(0.5, Property::Rotation));
    close(
        q.angle_between(Quat::from_rotation_y(-45f32.to_radians())),
        0.0,
        1e-4,
    );
    // Non-unit keys are normalized.
    let s = sampler(Interpolation::Step, &[0.0], &[id * 3.0]);
    rotation_of(s.sample(0.0, Property::Rotation));
}

#[test]
fn rotation_keys_boundaries_and_step() {
    // Keys: identity at t = 0, 90° about Z at t = 1, 180° about Z at t = 3 (hand-written xyzw).
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let keys = [
        Vec4::new(0.0, 0.0, 0.0, 1.0),
        Vec4::new(0.0, 0.0, h, h),
        Vec4::new(0.0, 0.0, 1.0, 0.0),
    ];
    let s = sampler(Interpolation::Linear, &[0.0, 1.0, 3.0], &keys);
    let at = |t: f32| s.sample(t, Property::Rotation);
    let near = |a: Vec4, b: Vec4| {
        assert!(
            (a - b).length() < 1e-5 || (a + b).length() < 1e-5,
            "{a} != {b}"
        )
    };
    // Before the first key, exactly at each key, after the last key.
    near(at(-2.0), keys[0]);
    near(at(0.0), keys[0]);
    near(at(1.0), keys[1]);
    near(at(3.0), keys[2]);
    near(at(9.0), keys[2]);
    // Midway between keys 1 and 2 (t = 2): 135° about Z = (0, 0, sin 67.5°, cos 67.5°).
    near(at(2.0), Vec4::new(0.0, 0.0, 0.923_879_5, 0.382_683_4));
    // A quarter into the first segment: 22.5° about Z = (0, 0, sin 11.25°, cos 11.25°).
    near(at(0.25), Vec4::new(0.0, 0.0, 0.195_090_3, 0.980_785_3));
    // STEP rotations hold the previous key, including just before a key.
    let s = sampler(Interpolation::Step, &[0.0, 1.0, 3.0], &keys);
    let at = |t: f32| s.sample(t, Property::Rotation);
    near(at(0.999), keys[0]);
    near(at(1.0), keys[1]);
    near(at(2.999), keys[1]);
    near(at(3.0), keys[2]);
}

#[test]
fn linear_translation_is_exact_at_interior_keys() {
    let s = sampler(
        Interpolation::Linear,
        &[0.0, 0.5, 2.0],
        &[v3(0.0, 0.0, 0.0), v3(1.0, -1.0, 2.0), v3(4.0, 2.0, 2.0)],
    );
    let at = |t| s.sample(t, Property::Translation).truncate();
    close3(at(0.5), Vec3::new(1.0, -1.0, 2.0), 0.0);
    close3(at(0.25), Vec3::new(0.5, -0.5, 1.0), 1e-6);
    // Second segment: s = (1.5 - 0.5) / 1.5 = 2/3.
    close3(at(1.5), Vec3::new(3.0, 1.0, 2.0), 1e-6);
}

#[test]
fn cubic_spline_matches_the_hermite_formula() {
    // Keys at t = 0 and 2 (Δ = 2): v0 = 1, b0 = 2 (out), a1 = -1 (in), v1 = 3.
    // The in-tangent of key 0 and the out-tangent of key 1 are unused (100).
    let k = |x: f32| v3(x, 0.0, 0.0);
    let s = sampler(
        Interpolation::CubicSpline,
        &[0.0, 2.0],
        &[k(100.0), k(1.0), k(2.0), k(-1.0), k(3.0), k(100.0)],
    );
    let x = |t| s.sample(t, Property::Translation).x;
    // t = 0.5: s = 0.25, h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875:
    // 0.84375·1 + 2·0.140625·2 + 0.15625·3 + 2·(−0.046875)·(−1) = 1.96875
    close(x(0.5), 1.96875, 1e-6);
    // t = 1: s = 0.5: 0.5·1 + 2·0.125·2 + 0.5·3 + 2·(−0.125)·(−1) = 2.75
    close(x(1.0), 2.75, 1e-6);
    close(x(0.0), 1.0, 0.0);
    close(x(2.0), 3.0, 0.0);
    close(x(-5.0), 1.0, 0.0);
    close(x(5.0), 3.0, 0.0);
    assert!(!s.is_constant());
    let flat = sampler(
        Interpolation::CubicSpline,
        &[0.0, 1.0],
        &[k(0.0), k(1.0), k(0.0), k(0.0), k(1.0), k(0.0)],
    );
    assert!(flat.is_constant());
}

#[test]
fn cubic_spline_rotation_is_normalized() {
    let id = Vec4::from(Quat::IDENTITY);
    let y90 = Vec4::from(Quat::from_rotation_y(90f32.to_radians()));
    let s = sampler(
        Interpolation::CubicSpline,
        &[0.0, 1.0],
        &[Vec4::ZERO, id, Vec4::ZERO, Vec4::ZERO, y90, Vec4::ZERO],
    );
    let q = rotation_of(s.sample(0.5, Property::Rotation));
    close(
        q.angle_between(Quat::from_rotation_y(45f32.to_radians())),
        0.0,
        1e-4,
    );
}

#[test]
fn hierarchy_and_dynamic_flags_in_a_loaded_file() {
    let mut b = GltfBuilder::new();
    let tri = PrimitiveDesc::triangles(
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        None,
        vec![0, 1, 2],
        None,
    );
    let mesh = b.add_mesh("tri", &[tri]);
    let child = b.add_node(&NodeDesc {
        name: Some("child".into()),
        translation: Some([0.0, 1.0, 0.0]),
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let parent = b.add_node(&NodeDesc {
        name: Some("parent".into()),
        matrix: Some(glam::Mat4::from_translation(Vec3::new(10.0, 0.0, 0.0)).to_cols_array()),
        children: vec![child],
        ..NodeDesc::default()
    });
    let other = b.add_node(&NodeDesc {
        name: Some("other".into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    let still = b.add_node(&NodeDesc {
        name: Some("still".into()),
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_animation(
        "a",
        &[
            ChannelDesc {
                node: child,
                property: Property::Translation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 2.0],
                values: vec![0.0, 1.0, 0.0, 0.0, 3.0, 0.0],
            },
            ChannelDesc {
                node: still,
                property: Property::Scale,
                interpolation: Interpolation::Step,
                times: vec![1.0, 4.0],
                values: vec![2.0, 2.0, 2.0, 2.0, 2.0, 2.0],
            },
        ],
    );
    b.add_scene("s", &[parent, other, still], None);
    let dir = temp_dir("anim");
    let (s, warnings) = load(&write(&b, &dir, "h"));
    assert_eq!(
        common::warnings_of(&warnings, WarningKind::DefaultCamera).0,
        1
    );
    assert_eq!(s.time_range(), Some((0.0, 4.0)));
    // Instances in traversal order: child (under parent), other, still.
    let nodes: Vec<usize> = s.instances.iter().map(|i| i.node).collect();
    assert_eq!(nodes, vec![child, other, still]);
    let dynamic: Vec<bool> = s.instances.iter().map(|i| i.dynamic).collect();
    assert_eq!(
        dynamic,
        vec![true, false, false],
        "a constant channel does not make a node dynamic"
    );
    assert!(s.animated[child] && !s.animated[still] && !s.dynamic[parent]);
    let m = s.instance_transforms(1.0);
    close3(
        m[0].transform_point3(Vec3::ZERO),
        Vec3::new(10.0, 2.0, 0.0),
        1e-6,
    );
    close3(
        m[2].transform_vector3(Vec3::X),
        Vec3::new(2.0, 0.0, 0.0),
        1e-6,
    );
    close3(
        s.instance_transforms(-1.0)[0].transform_point3(Vec3::ZERO),
        Vec3::new(10.0, 1.0, 0.0),
        1e-6,
    );
    assert_eq!(s.plan().animation.kind, AnimationKind::Geometry);
}
