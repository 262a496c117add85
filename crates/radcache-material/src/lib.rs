//! `radcache-material`: the CPU reference ("Rust twin") of the glTF 2.0 metallic-roughness BRDF
//! (glTF 2.0 specification, Appendix B, with `KHR_materials_ior` and `KHR_materials_specular`):
//! evaluation, importance sampling and the sampling pdf.
//!
//! The model, its formulas and its sources are described in `docs/materials.md` (cited here as
//! a bare §N). Each formula lives in one module:
//!
//! | Module | What | Section |
//! |---|---|---|
//! | [`fresnel`] | Schlick Fresnel, F0 from the index of refraction, `KHR_materials_specular` F0 | §2 |
//! | [`ggx`] | α from roughness, Trowbridge–Reitz (GGX) D, Smith Λ and G1, height-correlated V | §3 |
//! | [`brdf`] | [`Material`], the BRDF (diffuse and specular lobes), the diffuse share | §1, §4, §6 |
//! | [`sampling`] | cosine and GGX visible-normal sampling, lobe choice, the mixture pdf | §5 |
//! | [`polygon`] | the irradiance of a uniformly emitting triangle on a Lambertian receiver (Lambert's formula, horizon-clipped) | §7 |
//! | [`normal_map`] | the shading normal from a normal-map texel, kept on the geometric side | §12 |
//! | [`sh`] | real spherical harmonics, bands 0–3: basis, projection, change of frame by evaluation | radiance-caching §2–§3 |
//! | [`glossy`] | the specular lobe's projection table and the glossy radiance of SH coefficients | radiance-caching §3 |
//!
//! **GLSL twin.** `shaders/common/brdf.glsl` (`polygon.glsl`, `normal_map.glsl` for those
//! modules) mirrors the functions one to one (checked by `tests/glsl.rs`; values compared on
//! lavapipe by `tests/tests/brdf_glsl.rs` and `tests/tests/normal_maps.rs`): plain
//! `f32` / `Vec3` arguments (a [`Material`] becomes a GLSL `struct` with the same fields), no
//! traits or generics in the math, functions returning several values return a small struct.
//!
//! **Conventions.**
//! * Every direction is a unit vector in the local shading frame, normal `n = +Z`; `v` points
//!   from the surface towards the viewer, `l` towards the light; both leave the surface.
//! * `v.z <= 0` (the viewer at or below the horizon) or `l.z <= 0` gives a zero BRDF, a zero
//!   pdf, and a zero sample weight; roughness 0 is clamped to [`ggx::ALPHA_MIN`]. No function
//!   returns NaN or Inf for finite inputs (checked by `tests/robustness.rs`).

pub mod brdf;
pub mod fresnel;
pub mod ggx;
pub mod glossy;
pub mod normal_map;
pub mod polygon;
pub mod sampling;
pub mod sh;

pub use brdf::{brdf_eval, brdf_eval_lobes, diffuse_share, BrdfLobes, Material};
pub use normal_map::normal_map_normal;
pub use sampling::{brdf_pdf, brdf_sample, BrdfSample};
