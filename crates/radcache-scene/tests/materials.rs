//! Materials: KHR_materials_ior and KHR_materials_specular, the specification's default material,
//! extensions radcache does not implement (named once, with a count), occlusion textures, a
//! missing texture file, and which scenes need the full BRDF (`ScenePlan::specular`; the bundled
//! scenes' materials in `plan.rs`).

mod common;

use std::path::PathBuf;

use common::{load, shared_model, temp_dir, triangle_scene, warnings_of, write};
use glam::{Vec3, Vec4};
use radcache_scene::writer::{write_files, GltfBuilder, MaterialDesc, NodeDesc, PrimitiveDesc};
use radcache_scene::{Error, LoadOptions, Scene, WarningKind, IOR_INFINITE};
use serde_json::{json, Value};

/// `n` triangles side by side, triangle `i` with material `i`, as a builder.
fn triangles_with(materials: &[MaterialDesc]) -> GltfBuilder {
    let mut b = GltfBuilder::new();
    let mut prims = Vec::new();
    for (i, m) in materials.iter().enumerate() {
        let mat = b.add_material(m);
        let x = 2.0 * i as f32;
        let mut p = PrimitiveDesc::triangles(
            vec![[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]],
            Some(vec![[0.0, 0.0, 1.0]; 3]),
            vec![0, 1, 2],
            Some(mat),
        );
        p.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        prims.push(p);
    }
    let mesh = b.add_mesh("tris", &prims);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    b
}

/// Writes `b` after `f` has edited its JSON; returns the `.gltf` path.
fn write_edited(b: &GltfBuilder, tag: &str, f: impl FnOnce(&mut Value)) -> PathBuf {
    let dir = temp_dir(tag);
    let (mut root, bin) = b.to_json(Some("m.bin"));
    f(&mut root);
    let path = dir.join("m.gltf");
    write_files(&path, &root, Some(("m.bin", &bin))).unwrap();
    path
}

/// The F0 of a dielectric of index `ior` (glTF Appendix B, KHR_materials_ior).
fn f0(ior: f32) -> f32 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

#[test]
fn ior_and_specular_are_read_and_clamped() {
    let names = [
        "plain", "water", "zero", "low", "huge", "spec", "strong", "nolayer",
    ];
    let mats: Vec<MaterialDesc> = names
        .iter()
        .map(|n| MaterialDesc::metal_rough(n, [0.5; 3], 0.0, 0.5))
        .collect();
    let b = triangles_with(&mats);
    let path = write_edited(&b, "ior", |r| {
        let m = &mut r["materials"];
        m[1]["extensions"] = json!({"KHR_materials_ior": {"ior": 1.33}});
        m[2]["extensions"] = json!({"KHR_materials_ior": {"ior": 0}});
        m[3]["extensions"] = json!({"KHR_materials_ior": {"ior": 0.5}});
        // Overflows f32: non-finite, so the default with a warning.
        m[4]["extensions"] = json!({"KHR_materials_ior": {"ior": 1e39}});
        m[5]["extensions"] = json!({"KHR_materials_specular": {
            "specularFactor": 0.25, "specularColorFactor": [0.5, 2.0, 0.0]}});
        m[6]["extensions"] = json!({"KHR_materials_specular": {
            "specularFactor": 3.0, "specularColorFactor": [-1.0, 1.0, 1.0]}});
        m[7]["extensions"] = json!({"KHR_materials_specular": {"specularFactor": 0.0}});
        r["extensionsUsed"] = json!(["KHR_materials_ior", "KHR_materials_specular"]);
    });
    let (s, w) = load(&path);
    let m = &s.materials;
    assert_eq!(m.len(), 8);
    // No extension: the specification's defaults.
    assert_eq!(
        (m[0].ior, m[0].specular_factor, m[0].specular_color),
        (1.5, 1.0, Vec3::ONE)
    );
    assert!(!m[0].is_lambertian());
    assert_eq!(m[1].ior, 1.33);
    // ior 0: infinite, Fresnel 1 at every angle.
    assert_eq!(m[2].ior, IOR_INFINITE);
    assert_eq!(f0(m[2].ior), 1.0);
    assert!((1.0 / IOR_INFINITE).is_normal());
    assert_eq!(m[3].ior, 1.0);
    assert_eq!(m[4].ior, 1.5);
    assert!(
        w.iter().any(|w| w
            .message
            .contains("material 4 \"huge\": non-finite ior; using 1.5")),
        "{w:?}"
    );
    assert_eq!(m[5].specular_factor, 0.25);
    assert_eq!(m[5].specular_color, Vec3::new(0.5, 2.0, 0.0));
    assert_eq!(m[5].ior, 1.5);
    assert_eq!(m[6].specular_factor, 1.0);
    assert_eq!(m[6].specular_color, Vec3::new(0.0, 1.0, 1.0));
    // specularFactor 0 with metallic 0: exactly Lambertian.
    assert_eq!(m[7].specular_factor, 0.0);
    assert!(m[7].is_lambertian());
    assert!(s.plan().specular);
    assert_eq!(
        warnings_of(&w, WarningKind::MaterialExtensionIgnored),
        (0, 0)
    );
}

#[test]
fn required_ior_and_specular_load() {
    // gltf-json 1.4 parses KHR_materials_specular but would refuse it in extensionsRequired.
    let b = triangles_with(&[MaterialDesc::diffuse("d", [0.5; 3])]);
    let path = write_edited(&b, "req", |r| {
        r["materials"][0]["extensions"]["KHR_materials_ior"] = json!({"ior": 1.7});
        let used = json!(["KHR_materials_ior", "KHR_materials_specular"]);
        r["extensionsUsed"] = used.clone();
        r["extensionsRequired"] = used;
    });
    let (s, _) = load(&path);
    assert_eq!(s.materials[0].ior, 1.7);
    assert_eq!(s.materials[0].specular_factor, 0.0);
}

#[test]
fn specular_textures_are_ignored_once_per_material() {
    let mut b = GltfBuilder::new();
    let tex = b.add_texture_rgba8(1, 1, &[255; 4], 10497).unwrap();
    let mut prims = Vec::new();
    for name in ["both", "colour", "none"] {
        let mat = b.add_material(&MaterialDesc::metal_rough(name, [1.0; 3], 0.0, 1.0));
        prims.push(PrimitiveDesc::triangles(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            None,
            vec![0, 1, 2],
            Some(mat),
        ));
    }
    let mesh = b.add_mesh("m", &prims);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    let path = write_edited(&b, "spectex", |r| {
        let m = &mut r["materials"];
        m[0]["extensions"] = json!({"KHR_materials_specular": {
            "specularFactor": 0.5, "specularTexture": {"index": tex},
            "specularColorFactor": [0.2, 0.3, 0.4], "specularColorTexture": {"index": tex}}});
        m[1]["extensions"] = json!({"KHR_materials_specular": {
            "specularColorTexture": {"index": tex}}});
        m[2]["extensions"] = json!({"KHR_materials_specular": {"specularFactor": 0.75}});
        r["extensionsUsed"] = json!(["KHR_materials_specular"]);
    });
    let (s, w) = load(&path);
    let ignored: Vec<&str> = w
        .iter()
        .filter(|w| w.kind == WarningKind::TextureIgnored)
        .map(|w| w.message.as_str())
        .collect();
    assert_eq!(ignored.len(), 2, "{ignored:?}");
    assert!(
        ignored[0].contains("material 0 \"both\"")
            && ignored[0].contains(
                "specularTexture and specularColorTexture not supported; using the factors"
            )
    );
    assert!(
        ignored[1].contains("material 1 \"colour\"") && ignored[1].contains("specularColorTexture")
    );
    let m = &s.materials;
    assert_eq!(
        (m[0].specular_factor, m[0].specular_color),
        (0.5, Vec3::new(0.2, 0.3, 0.4))
    );
    assert_eq!(
        (m[1].specular_factor, m[1].specular_color),
        (1.0, Vec3::ONE)
    );
    assert_eq!(m[2].specular_factor, 0.75);
    // The ignored textures are not loaded.
    assert!(s.textures.is_empty());
}

#[test]
fn primitives_without_material_get_the_specification_default() {
    let (s, _) = load(&write(
        &triangle_scene(None, |_| {}),
        &temp_dir("default"),
        "d",
    ));
    assert_eq!(s.materials.len(), 1);
    let d = &s.materials[0];
    assert_eq!(d.name.as_deref(), Some("default"));
    assert_eq!(d.base_color, Vec4::ONE);
    assert_eq!((d.metallic, d.roughness), (1.0, 1.0));
    assert_eq!(
        (d.ior, d.specular_factor, d.specular_color),
        (1.5, 1.0, Vec3::ONE)
    );
    assert_eq!(d.emissive, Vec3::ZERO);
    assert!(d.base_color_texture.is_none() && d.metallic_roughness_texture.is_none());
    assert!(!d.is_lambertian());
    assert!(s.plan().specular);
    // A white metal reflects nothing diffusely.
    assert_eq!(d.diffuse_albedo(), Vec3::ZERO);
}

#[test]
fn unsupported_material_extensions_are_named_once_with_a_count() {
    let mut b = GltfBuilder::new();
    let tex = b
        .add_texture_rgba8(1, 1, &[200, 100, 50, 255], 10497)
        .unwrap();
    let names = ["glass", "bottle", "car", "plain"];
    let mats: Vec<MaterialDesc> = names
        .iter()
        .map(|n| MaterialDesc {
            base_color_texture: Some(tex),
            ..MaterialDesc::diffuse(n, [0.8, 0.7, 0.6])
        })
        .collect();
    let mut prims = Vec::new();
    for m in &mats {
        let i = b.add_material(m);
        let mut p = PrimitiveDesc::triangles(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            None,
            vec![0, 1, 2],
            Some(i),
        );
        p.texcoords = Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        prims.push(p);
    }
    let mesh = b.add_mesh("m", &prims);
    let node = b.add_node(&NodeDesc {
        mesh: Some(mesh),
        ..NodeDesc::default()
    });
    b.add_scene("s", &[node], None);
    let path = write_edited(&b, "unsup", |r| {
        let m = &mut r["materials"];
        for i in [0, 1] {
            m[i]["extensions"]["KHR_materials_transmission"] = json!({"transmissionFactor": 1.0});
            m[i]["extensions"]["KHR_materials_volume"] = json!({"thicknessFactor": 0.1});
        }
        m[2]["extensions"]["KHR_materials_clearcoat"] = json!({"clearcoatFactor": 1.0});
        // Implemented (docs/materials.md §13): not a note.
        m[2]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] =
            json!({"KHR_texture_transform": {"scale": [2.0, 2.0]}});
        m[1]["occlusionTexture"] = json!({"index": tex});
        r["extensionsUsed"] = json!([
            "KHR_materials_clearcoat",
            "KHR_materials_specular",
            "KHR_materials_transmission",
            "KHR_materials_volume",
            "KHR_texture_transform"
        ]);
    });
    let (s, w) = load(&path);
    let notes: Vec<(&str, usize)> = w
        .iter()
        .filter(|w| w.kind == WarningKind::MaterialExtensionIgnored)
        .map(|w| (w.message.as_str(), w.count))
        .collect();
    assert_eq!(notes.len(), 3, "{notes:?}");
    let expect = [
        ("KHR_materials_clearcoat", 1, "material 2 \"car\""),
        (
            "KHR_materials_transmission",
            2,
            "material 0 \"glass\", material 1 \"bottle\"",
        ),
        (
            "KHR_materials_volume",
            2,
            "material 0 \"glass\", material 1 \"bottle\"",
        ),
    ];
    for ((msg, count), (name, n, users)) in notes.iter().zip(expect) {
        assert!(
            msg.contains(&format!("extension {name} is not implemented")),
            "{msg}"
        );
        assert!(msg.contains(users) && msg.contains("m.gltf"), "{msg}");
        assert_eq!(*count, n, "{msg}");
    }
    for (msg, _) in &notes {
        assert!(
            msg.ends_with("they render with the core metallic-roughness model"),
            "{msg}"
        );
    }

    let n = &s.material_notes;
    assert_eq!(
        n.unsupported_extensions,
        vec![
            ("KHR_materials_clearcoat".to_string(), 1),
            ("KHR_materials_transmission".to_string(), 2),
            ("KHR_materials_volume".to_string(), 2),
        ]
    );
    assert_eq!(n.occlusion_textures, 1);
    // Rendered with the core model: the factors and the base colour texture as written.
    for m in &s.materials {
        assert_eq!(m.base_color, Vec4::new(0.8, 0.7, 0.6, 1.0));
        assert!(m.is_lambertian() && m.base_color_texture.is_some());
    }

    let summary = s.to_string();
    for (name, n) in [
        ("KHR_materials_clearcoat", "1 material)"),
        ("KHR_materials_transmission", "2 materials)"),
        ("KHR_materials_volume", "2 materials)"),
    ] {
        assert_eq!(summary.matches(name).count(), 1, "{summary}");
        assert!(summary.contains(&format!("{name} ({n}")), "{summary}");
    }
    // Implemented: in the plan's line, not among the extensions not implemented.
    let unsupported = summary
        .lines()
        .find(|l| l.contains("material extensions not implemented"))
        .unwrap_or_default();
    assert!(!unsupported.contains("KHR_texture_transform"), "{summary}");
    assert!(
        summary.contains("KHR_texture_transform applied"),
        "{summary}"
    );
    let car = s.materials[2].base_color_texture.unwrap();
    assert_eq!(car.transform.scale, glam::Vec2::splat(2.0));
    assert!(
        summary.contains("material extensions not implemented"),
        "{summary}"
    );
    assert_eq!(
        summary.matches("occlusion textures").count(),
        1,
        "{summary}"
    );
    assert!(
        summary.contains("occlusion textures: not used (1 material; a global-illumination renderer computes occlusion itself)"),
        "{summary}"
    );
    assert!(summary.contains("materials: lambertian only (no specular code compiled)"));
}

#[test]
fn a_plain_scene_has_no_material_notes() {
    let b = triangles_with(&[MaterialDesc::diffuse("d", [0.5; 3])]);
    let (s, w) = load(&write(&b, &temp_dir("plain"), "p"));
    assert_eq!(s.material_notes, Default::default());
    assert_eq!(
        warnings_of(&w, WarningKind::MaterialExtensionIgnored),
        (0, 0)
    );
    let summary = s.to_string();
    assert!(
        !summary.contains("occlusion") && !summary.contains("extensions"),
        "{summary}"
    );
}

#[test]
fn refused_required_extensions_name_the_file_and_the_extension() {
    for (name, why) in [
        ("KHR_draco_mesh_compression", "Draco"),
        ("KHR_meshopt_compression", "vertex codec 1"),
        ("KHR_texture_basisu", "Basis Universal"),
        ("EXT_texture_webp", "WebP"),
    ] {
        let b = triangles_with(&[MaterialDesc::diffuse("d", [0.5; 3])]);
        let path = write_edited(&b, "required", |r| {
            r["extensionsUsed"] = json!([name]);
            r["extensionsRequired"] = json!([name]);
        });
        let e = match Scene::load(&path, &LoadOptions::default()) {
            Ok(_) => panic!("a file requiring {name} loaded"),
            Err(e) => e,
        };
        assert!(
            matches!(&e, Error::UnsupportedExtension { name: n, path: p, .. } if n == name && *p == path),
            "{e:?}"
        );
        let text = e.to_string();
        assert!(
            text.starts_with(&format!("{}: ", path.display()))
                && text.contains(&format!("requires the glTF extension \"{name}\""))
                && text.contains(why),
            "{text}"
        );
    }
}

#[test]
fn lantern_names_its_missing_base_colour_texture() {
    let path = shared_model("Lantern/glTF/Lantern.gltf");
    let e = match Scene::load(&path, &LoadOptions::default()) {
        Ok(_) => panic!("Lantern loaded although Lantern_baseColor.png is missing"),
        Err(e) => e,
    };
    assert!(matches!(&e, Error::Invalid { .. }), "{e:?}");
    let text = e.to_string();
    assert!(
        text.starts_with(&format!("{}: ", path.display()))
            && text.contains("Lantern_baseColor.png")
            && text.contains("cannot read image file"),
        "{text}"
    );
}

#[test]
fn damaged_helmet_needs_the_full_brdf_and_has_an_unused_occlusion_map() {
    let path = shared_model("DamagedHelmet/glTF-Binary/DamagedHelmet.glb");
    let (s, w) = load(&path);
    assert_eq!(s.materials.len(), 1);
    let m = &s.materials[0];
    // Default factors (metallic 1) with a metallic-roughness texture.
    assert_eq!((m.metallic, m.roughness), (1.0, 1.0));
    assert!(m.metallic_roughness_texture.is_some() && m.base_color_texture.is_some());
    assert!(!m.is_lambertian());
    let plan = s.plan();
    assert!(plan.specular);
    assert!(plan
        .to_string()
        .contains("materials: metallic-roughness BRDF (specular lobes compiled in)"));
    // Its one material is metallic: no vertex for the radiance grid.
    assert!(!plan.path_grid());
    assert!(plan
        .to_string()
        .contains("gather paths: to their end (no Lambertian material: no radiance grid)"));
    assert_eq!(s.material_notes.occlusion_textures, 1);
    assert!(s.material_notes.unsupported_extensions.is_empty());
    assert_eq!(
        s.to_string()
            .matches("occlusion textures: not used")
            .count(),
        1
    );
    assert_eq!(
        warnings_of(&w, WarningKind::MaterialExtensionIgnored),
        (0, 0)
    );
}

#[test]
fn the_writer_emits_specular_and_ior_only_when_they_differ_from_the_defaults() {
    let mut b = GltfBuilder::new();
    let tex = b
        .add_texture_rgba8(1, 1, &[0, 128, 255, 255], 10497)
        .unwrap();
    b.add_material(&MaterialDesc::diffuse("lambert", [0.5; 3]));
    b.add_material(&MaterialDesc {
        metallic_roughness_texture: Some(tex),
        ..MaterialDesc::metal_rough("metal", [0.9; 3], 1.0, 0.3)
    });
    b.add_material(&MaterialDesc {
        ior: Some(1.33),
        ..MaterialDesc::emitter("lamp", [0.5; 3], [4.0; 3])
    });
    let (root, _) = b.to_json(None);
    let m = &root["materials"];
    assert_eq!(
        m[0]["extensions"],
        json!({"KHR_materials_specular": {"specularFactor": 0.0}})
    );
    assert!(m[1].get("extensions").is_none(), "{}", m[1]);
    assert_eq!(
        m[1]["pbrMetallicRoughness"]["metallicRoughnessTexture"],
        json!({"index": tex})
    );
    assert_eq!(
        m[2]["extensions"],
        json!({
            "KHR_materials_emissive_strength": {"emissiveStrength": 4.0},
            "KHR_materials_ior": {"ior": 1.33},
            "KHR_materials_specular": {"specularFactor": 0.0}
        })
    );
    assert_eq!(
        root["extensionsUsed"],
        json!([
            "KHR_materials_emissive_strength",
            "KHR_materials_ior",
            "KHR_materials_specular"
        ])
    );
    assert!(root.get("extensionsRequired").is_none());
}
