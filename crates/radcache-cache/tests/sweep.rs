//! Randomized sweep over every public function with degenerate inputs mixed in (zero vectors,
//! antiparallel and unnormalised normals, R = 0, negative and infinite distances, zero strata
//! counts): no output may be NaN or infinite (distances come out as at most `IC_FAR`).
//! Inputs are bounded by 1e6 in magnitude (positions, radiance, gradients) except distances,
//! which may be `+inf` (a miss). NaN inputs are out of scope (see the crate docs).
//! `RADCACHE_SWEEP_ITERS` overrides the number of iterations (default 200 000).

use glam::Vec3;
use radcache_cache::extrapolate::*;
use radcache_cache::radius::*;
use radcache_cache::record::*;
use radcache_cache::sampling::*;
use radcache_cache::temporal::*;
use radcache_cache::weight::*;
use radcache_cache::{luminance_rec709, IcParams, IC_FAR};

struct Gen(u32);

impl Gen {
    fn u(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(1);
        unit_float_from_bits(ircache_hash(self.0))
    }
    fn pick<T: Copy>(&mut self, xs: &[T]) -> T {
        xs[((self.u() * xs.len() as f32) as usize).min(xs.len() - 1)]
    }
    fn scalar(&mut self) -> f32 {
        let special = [0.0, -0.0, 1e-30, 1e-6, 0.5, 1.0, 2.0, -1.0, -1e-6, 1e6];
        if self.u() < 0.5 {
            self.pick(&special)
        } else {
            (self.u() - 0.3) * 10f32.powf(6.0 * self.u() - 3.0)
        }
    }
    fn dist(&mut self) -> f32 {
        if self.u() < 0.3 {
            self.pick(&[f32::INFINITY, 0.0, -1.0, 1e-30, IC_FAR, 3e38])
        } else {
            self.scalar().abs()
        }
    }
    fn vec(&mut self) -> Vec3 {
        let special = [
            Vec3::ZERO,
            Vec3::X,
            -Vec3::X,
            Vec3::Z,
            -Vec3::Z,
            Vec3::splat(1e-20),
            Vec3::new(0.0, 0.0, -0.0),
        ];
        if self.u() < 0.4 {
            self.pick(&special)
        } else {
            Vec3::new(self.scalar(), self.scalar(), self.scalar())
        }
    }
    fn unit(&mut self) -> Vec3 {
        normalize_or_z(self.vec())
    }
    fn uint(&mut self) -> u32 {
        self.pick(&[0, 1, 2, 3, 7, 16, 48, 1000, u32::MAX])
    }
}

fn ok(x: f32, what: &str) {
    assert!(x.is_finite(), "{what} produced {x}");
}

fn okv(v: Vec3, what: &str) {
    assert!(v.is_finite(), "{what} produced {v}");
}

#[test]
fn no_nan_or_inf_anywhere() {
    let iterations: u32 = std::env::var("RADCACHE_SWEEP_ITERS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200_000);
    let mut g = Gen(1);
    for _ in 0..iterations {
        let (u1, u2) = (g.unit(), g.unit());
        let (p, p_i, n, n_i) = (g.vec(), g.vec(), g.vec(), g.pick(&[u1, -u2, Vec3::ZERO]));
        let n = if g.u() < 0.2 { -n_i } else { n }; // antiparallel pairs
        let (r, r2, s1, s2) = (g.dist(), g.dist(), g.scalar(), g.scalar());
        let (j, k, m, nn) = (g.uint(), g.uint(), g.uint(), g.uint());
        let (e, e1) = (g.vec().abs(), g.vec());
        let grads = [g.vec(), g.vec(), g.vec()];
        let grads2 = [g.vec(), g.vec(), g.vec()];
        let (t, b) = basis_from_normal(n);
        okv(t, "basis t");
        okv(b, "basis b");
        okv(normalize_or_z(n), "normalize_or_z");
        okv(
            frame_to_world(e1, t, b, n_i) + world_to_frame(e1, t, b, n_i),
            "frame maps",
        );
        ok(
            stratum_phi_centre(k, nn) + stratum_phi_start(k, nn) + azimuth_from_unit(g.u()),
            "azimuths",
        );
        okv(horizontal_u(s1) + horizontal_v(s1), "horizontal vectors");
        ok(
            stratum_tan_centre(j, m) + stratum_tan_mean(j, m),
            "tan weights",
        );
        let (m_small, n_small) = (m.min(4096), nn.min(4096)); // j*N must not overflow u32
        okv(
            stratum_direction_local(j.min(5000), k.min(5000), m_small, n_small, s1, s2),
            "direction",
        );
        let (xi, psi) = stratum_jitter(j, k);
        ok(
            xi + psi + stratum_projected_solid_angle(m, nn),
            "jitter / solid angle",
        );
        ok(
            inverse_distance(r, s1)
                + harmonic_mean_distance(s1.abs(), s2)
                + harmonic_mean_distance(r, r2),
            "distances",
        );
        okv(rotational_gradient_coeff(j, k, m, nn), "rot coeff");
        okv(
            polar_wall_coeff(j, k, m, nn) + azimuthal_wall_coeff(j, k, m, nn),
            "wall coeffs",
        );
        okv(wall_term(e, e1, r, r2, s1), "wall term");
        ok(
            sanitize_radius(r) + gradient_limit_radius(r, e1, &grads),
            "gradient limit",
        );
        ok(neighbour_clamp(r, r2, s1), "neighbour clamp");
        let (a, bb) = neighbour_clamp_pair(r, p, r2, p_i);
        ok(a + bb, "neighbour pair");
        ok(
            pixel_footprint(s1, s2, g.scalar(), g.scalar())
                + pixel_footprint_from_differentials(p, p_i),
            "footprint",
        );
        let (lo, hi) = radius_bounds(s1, s2, g.scalar(), g.scalar());
        ok(lo + hi, "bounds");
        ok(
            clamp_radius(r, s1, s2) + gradient_attenuation(r, s1),
            "clamp",
        );
        let f = finalize_radius(r, e1, &grads, r2, s1, s2);
        for (x, w) in [
            (f.r_orig, "r_orig"),
            (f.r_used, "r_used"),
            (f.r_lo, "r_lo"),
            (f.r_hi, "r_hi"),
            (f.grad_t_scale, "scale"),
        ] {
            ok(x, w);
            assert!((0.0..=IC_FAR).contains(&x));
        }
        assert!(f.r_used > 0.0 && f.grad_t_scale <= 1.0);
        for kind in [WeightKind::Ward, WeightKind::TabellionLamorlette] {
            let w = record_weight(kind, p, n, WeightRecord { p: p_i, n: n_i, r }, s1, s2);
            ok(w, "weight");
            assert!((0.0..=1000.0).contains(&w));
            ok(
                splat_radius(kind, r, s1, s2)
                    + validity_scale(kind, s1)
                    + weight_unit(kind, s1)
                    + coverage_threshold(kind, s1, s2),
                "splat",
            );
        }
        ok(
            position_error(p, p_i, n_i, r.min(1e6)) + normal_error(n, n_i),
            "errors",
        );
        let x = extrapolate_irradiance(e1, &grads, &grads2, p, n, p_i, n_i);
        okv(x, "extrapolation");
        assert!(x.cmpge(Vec3::ZERO).all());
        okv(clamp_extrapolation(e1, e), "clamp extrapolation");
        okv(
            temporal_gradient(e, e1) + temporal_extrapolate(e, e1, s1),
            "temporal",
        );
        ok(
            temporal_lifespan(e, e1, s1, s2) + luminance_rec709(e1),
            "lifespan",
        );
    }
}

#[test]
fn records_from_degenerate_samples_are_finite() {
    let mut g = Gen(99);
    for _ in 0..300 {
        let (m, n) = (g.pick(&[1u32, 2, 3, 8, 16]), g.pick(&[1u32, 3, 24, 48]));
        let l: Vec<Vec3> = (0..m * n).map(|_| g.vec().abs()).collect();
        let r: Vec<f32> = (0..m * n).map(|_| g.dist()).collect();
        let rec = compute_record(&l, &r, m, n, g.vec(), g.scalar());
        okv(rec.e, "E");
        for c in 0..3 {
            okv(rec.grad_r[c], "grad_r");
            okv(rec.grad_t[c], "grad_t");
        }
        for d in [
            rec.r_harmonic,
            rec.r_min,
            rec.r_min_restricted,
            rec.radius(),
        ] {
            assert!(d.is_finite() && (0.0..=IC_FAR).contains(&d));
        }
        let params = IcParams::default();
        let (lo, hi) = params.radius_bounds(g.scalar());
        let f = finalize_radius(rec.radius(), rec.e, &rec.grad_t, f32::INFINITY, lo, hi);
        assert!(f.r_used.is_finite() && f.r_used > 0.0);
    }
}
