//! KHR_lights_punctual units and placement: point I/d², range window, spot cone falloff at the
//! inner/outer/mid angles, directional illuminance, world position/direction from nodes.

mod common;

use common::{close, close3, load, temp_dir, write};
use glam::{Mat4, Quat, Vec3};
use radcache_scene::light::{range_window, spot_falloff};
use radcache_scene::writer::{GltfBuilder, LightDesc, NodeDesc};
use radcache_scene::{AnimationKind, LightKind, PunctualLight, WorldLight};

fn light(kind: LightKind, intensity: f32, range: Option<f32>) -> PunctualLight {
    PunctualLight {
        name: None,
        kind,
        color: Vec3::new(1.0, 0.5, 0.25),
        intensity,
        range,
    }
}

#[test]
fn point_light_inverse_square_and_range() {
    let l = WorldLight::new(&light(LightKind::Point, 10.0, None), &Mat4::IDENTITY);
    let s = l.illuminate(Vec3::new(0.0, 2.0, 0.0));
    close3(s.wi, -Vec3::Y, 1e-6);
    close(s.distance, 2.0, 1e-6);
    close3(s.irradiance, Vec3::new(1.0, 0.5, 0.25) * 10.0 / 4.0, 1e-6);
    close3(
        l.illuminate(Vec3::new(3.0, 0.0, 4.0)).irradiance,
        Vec3::new(1.0, 0.5, 0.25) * 10.0 / 25.0,
        1e-6,
    );
    let r = WorldLight::new(&light(LightKind::Point, 10.0, Some(4.0)), &Mat4::IDENTITY);
    close(
        r.illuminate(Vec3::new(2.0, 0.0, 0.0)).irradiance.x,
        10.0 / 4.0 * 0.9375,
        1e-6,
    );
    assert_eq!(
        r.illuminate(Vec3::new(4.0, 0.0, 0.0)).irradiance,
        Vec3::ZERO
    );
    assert_eq!(
        r.illuminate(Vec3::new(5.0, 0.0, 0.0)).irradiance,
        Vec3::ZERO
    );
    close(range_window(1.0, None), 1.0, 0.0);
}

#[test]
fn spot_falloff_at_inner_mid_outer() {
    let (inner, outer) = (0.2f32, 0.5f32);
    close(spot_falloff(1.0, inner, outer), 1.0, 0.0);
    close(spot_falloff(inner.cos(), inner, outer), 1.0, 1e-5);
    close(spot_falloff(outer.cos(), inner, outer), 0.0, 1e-5);
    // Mid angle 0.35 rad: ((cos .35 − cos .5) / (cos .2 − cos .5))² ≈ 0.3635.
    close(spot_falloff(0.35f32.cos(), inner, outer), 0.3635, 2e-4);
    close(spot_falloff(0.6f32.cos(), inner, outer), 0.0, 0.0);

    let kind = LightKind::Spot {
        inner_cone_angle: inner,
        outer_cone_angle: outer,
    };
    // Identity node: the spot shines down −Z.
    let l = WorldLight::new(&light(kind, 8.0, None), &Mat4::IDENTITY);
    close3(l.direction, -Vec3::Z, 1e-6);
    let at_angle = |a: f32| {
        l.illuminate(Vec3::new(a.sin(), 0.0, -a.cos()) * 2.0)
            .irradiance
            .x
    };
    close(at_angle(0.0), 2.0, 1e-5);
    close(at_angle(inner), 2.0, 1e-4);
    close(at_angle(0.35), 2.0 * 0.3635, 5e-4);
    close(at_angle(outer), 0.0, 1e-4);
    close(at_angle(1.0), 0.0, 0.0);
    assert_eq!(
        l.illuminate(Vec3::Z).irradiance,
        Vec3::ZERO,
        "behind the spot"
    );
}

#[test]
fn directional_light_is_illuminance() {
    let m = Mat4::from_quat(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2));
    let l = WorldLight::new(&light(LightKind::Directional, 3.0, None), &m);
    close3(l.direction, -Vec3::Y, 1e-6);
    for p in [Vec3::ZERO, Vec3::new(100.0, -5.0, 3.0)] {
        let s = l.illuminate(p);
        close3(s.wi, Vec3::Y, 1e-6);
        assert!(s.distance.is_infinite());
        close3(s.irradiance, Vec3::new(3.0, 1.5, 0.75), 1e-6);
    }
}

#[test]
fn loaded_lights_take_their_node_transforms() {
    let mut b = GltfBuilder::new();
    let point = b.add_light(&LightDesc {
        name: Some("p".into()),
        kind: LightKind::Point,
        color: [1.0, 1.0, 1.0],
        intensity: 5.0,
        range: Some(10.0),
    });
    let spot = b.add_light(&LightDesc {
        name: Some("s".into()),
        kind: LightKind::Spot {
            inner_cone_angle: 0.1,
            outer_cone_angle: 0.4,
        },
        color: [0.5, 1.0, 1.0],
        intensity: 20.0,
        range: None,
    });
    let sun = b.add_light(&LightDesc {
        name: Some("sun".into()),
        kind: LightKind::Directional,
        color: [1.0, 1.0, 1.0],
        intensity: 2.0,
        range: None,
    });
    let down = Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2).to_array();
    let n_point = b.add_node(&NodeDesc {
        translation: Some([1.0, 2.0, 3.0]),
        light: Some(point),
        ..NodeDesc::default()
    });
    let n_spot = b.add_node(&NodeDesc {
        translation: Some([0.0, 4.0, 0.0]),
        rotation: Some(down),
        light: Some(spot),
        ..NodeDesc::default()
    });
    let n_sun = b.add_node(&NodeDesc {
        light: Some(sun),
        ..NodeDesc::default()
    });
    let parent = b.add_node(&NodeDesc {
        rotation: Some(down),
        children: vec![n_sun],
        ..NodeDesc::default()
    });
    b.add_scene("s", &[n_point, n_spot, parent], None);
    let dir = temp_dir("lights");
    let (s, _) = load(&write(&b, &dir, "l"));
    assert_eq!(s.lights.len(), 3);
    assert_eq!(s.lights[0].range, Some(10.0));
    assert_eq!(s.lights[1].range, None);
    assert_eq!(
        s.lights[1].kind,
        LightKind::Spot {
            inner_cone_angle: 0.1,
            outer_cone_angle: 0.4
        }
    );
    let w = s.lights_at(0.0);
    close3(w[0].position, Vec3::new(1.0, 2.0, 3.0), 1e-6);
    close3(w[1].position, Vec3::new(0.0, 4.0, 0.0), 1e-6);
    close3(w[1].direction, -Vec3::Y, 1e-6);
    close3(
        w[1].illuminate(Vec3::ZERO).irradiance,
        Vec3::new(0.5, 1.0, 1.0) * 20.0 / 16.0,
        1e-5,
    );
    close3(w[2].direction, -Vec3::Y, 1e-6);
    let plan = s.plan();
    assert_eq!(
        (plan.lights.point, plan.lights.spot, plan.lights.directional),
        (1, 1, 1)
    );
    assert_eq!(plan.animation.kind, AnimationKind::None);
    assert!(s
        .summary()
        .contains("lights: 1 point, 1 spot, 1 directional"));
}
