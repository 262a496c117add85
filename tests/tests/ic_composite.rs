//! The composite of the sub-frames after the first when the records are splatted once per frame:
//! the direct pass made to composite adds their samples to the frame's accumulators itself
//! (`DIRECT_COMPOSITE`, docs/cache-frame.md §6.5), and must add exactly what its direct image
//! followed by the composite pass adds.

use radcache_render::{
    frame::settings::sub_frame_jitter, passes::composite::CentreSamples,
    passes::composite::CompositeInputs, passes::composite::CompositeJob,
    passes::composite::CompositePass, passes::composite::CompositeVariant,
    passes::composite::WithCentres, passes::direct::CompositeSubFrame, passes::direct::Composited,
    passes::direct::DirectCompositing, passes::direct::DirectImage, passes::direct::DirectInputs,
    passes::direct::DirectPass, passes::direct::DirectShadows, passes::direct::DirectVariant,
    passes::splat::SplatPass, passes::splat_glossy::GlossySplatPass, EmitterLight, SkyLight,
};
use radcache_tests::ic_fixture::{cornell, Gpu};

/// The Cornell box at 48×40 (its closed-form emitter, adaptive shadows, the anti-aliasing
/// moments): two direct passes made to composite, each with its own accumulators, shade the
/// same sub-frames from the same G-buffers. Sub-frame 0 writes the direct image and the
/// composite pass stores the centre samples in both; in sub-frames 1–4 one direct pass
/// composites itself and the other writes its image for the composite pass. Means, squares,
/// samples without a matching centre and dropped values agree bit for bit.
#[test]
fn the_direct_pass_composites_as_the_composite_pass() {
    let (w, h) = (48, 40);
    let gpu = Gpu::new(&cornell(), None, (w, h));
    let (ctx, shaders) = (&gpu.ctx, &gpu.shaders);
    let direct_variant = DirectVariant {
        shadows: DirectShadows::Adaptive { pixels: w * h },
        ..DirectVariant::new(SkyLight::Direct, EmitterLight::Analytic)
    }
    .to(DirectCompositing { moments: true });
    let direct = || DirectPass::new(ctx, shaders, &gpu.scene, &direct_variant).unwrap();
    let variant = CompositeVariant {
        moments: true,
        ..CompositeVariant::new(w, h)
    }
    .with(WithCentres);
    let composite = || CompositePass::new(ctx, shaders, &gpu.scene, &variant).unwrap();
    // [fused, separate]
    let passes = [(direct(), composite()), (direct(), composite())];
    let splat = SplatPass::new(ctx, shaders, w, h).unwrap();
    let (samples, seed) = (16, 7);
    let inputs = |sub_frame| DirectInputs {
        scene: &gpu.scene,
        gbuffer: &gpu.gbuffer,
        samples,
        sub_frame,
        seed,
        glossy: None,
    };
    for k in 0..5 {
        let jitter = sub_frame_jitter(k);
        let mut rec = ctx.begin("test.sub_frame").unwrap();
        gpu.pass
            .record(&mut rec, &gpu.scene, &gpu.gbuffer, jitter)
            .unwrap();
        if k == 0 {
            // Σw·Ẽ, Σw: every centre holds Ẽ = (0.5, 1, 1.5).
            rec.clear_color(&splat.sum, [1.0, 2.0, 3.0, 2.0]);
        }
        for (i, (direct, composite)) in passes.iter().enumerate() {
            if k == 0 {
                composite.record(&mut rec, CompositeJob::Clear).unwrap();
            }
            let fused = k > 0 && i == 0;
            let outputs = Composited {
                composite,
                splat: &splat,
                sub_frame: fused.then_some(CompositeSubFrame { jitter }),
            };
            direct.record(&mut rec, &inputs(k), &outputs).unwrap();
            let g = &gpu.gbuffer;
            if !fused {
                let centre = if k == 0 {
                    CentreSamples::Store
                } else {
                    CentreSamples::Match
                };
                let inputs = CompositeInputs::own(&gpu.scene, g, &splat, jitter).at(centre);
                composite
                    .record(&mut rec, CompositeJob::Add(&inputs))
                    .unwrap();
            }
        }
        ctx.submit(rec).unwrap().wait().unwrap();
    }
    let [(_, fused), (_, separate)] = &passes;
    let (mean, dropped) = fused.read_mean(ctx).unwrap();
    assert_eq!((mean, dropped), separate.read_mean(ctx).unwrap());
    assert_eq!(dropped, 0);
    let moments = fused.read_moments(ctx).unwrap().unwrap();
    assert_eq!(moments, separate.read_moments(ctx).unwrap().unwrap());
    let (sums, squares) = moments;
    assert!(
        sums.iter().all(|s| s[3] == 5.0),
        "every pixel has 5 samples"
    );
    let lit = sums.iter().filter(|s| s[0] > 0.0).count();
    assert!(lit > (w * h) as usize / 2, "{lit} pixels with light");
    assert!(squares
        .iter()
        .zip(&sums)
        .all(|(q, s)| q[0] >= s[0] * s[0] / 5.0 * 0.999));
    assert_eq!(
        fused.read_unmatched().unwrap(),
        separate.read_unmatched().unwrap()
    );
    drop((passes, splat));
    gpu.end();
}

/// A direct or composite pass made without radiance records has no glossy weights to write or
/// glossy target to add: handed a glossy splat, each refuses with an error that names it (a
/// silent recording would leave the glossy splat's weights unwritten), records nothing, and the
/// same passes record without it.
#[test]
fn passes_made_without_radiance_refuse_a_glossy_splat() {
    let (w, h) = (16, 12);
    let gpu = Gpu::new(&cornell(), None, (w, h));
    let (ctx, shaders) = (&gpu.ctx, &gpu.shaders);
    let variant = DirectVariant::new(SkyLight::Direct, EmitterLight::Analytic);
    let direct = DirectPass::new(ctx, shaders, &gpu.scene, &variant).unwrap();
    let composite =
        CompositePass::new(ctx, shaders, &gpu.scene, &CompositeVariant::new(w, h)).unwrap();
    let splat = SplatPass::new(ctx, shaders, w, h).unwrap();
    let glossy = GlossySplatPass::new(ctx, shaders, w, h, false).unwrap();
    let inputs = |glossy| DirectInputs {
        scene: &gpu.scene,
        gbuffer: &gpu.gbuffer,
        samples: 1,
        sub_frame: 0,
        seed: 1,
        glossy,
    };
    let composited = |glossy| CompositeInputs {
        glossy,
        ..CompositeInputs::own(&gpu.scene, &gpu.gbuffer, &splat, [0.0; 2])
    };
    let mut rec = ctx.begin("test.refused").unwrap();
    let err = direct
        .record(&mut rec, &inputs(Some(&glossy)), &DirectImage)
        .unwrap_err();
    assert!(err.to_string().contains("direct pass"), "{err}");
    assert!(err.to_string().contains("glossy splat"), "{err}");
    let with_glossy = composited(Some(&glossy));
    let err = composite
        .record(&mut rec, CompositeJob::Add(&with_glossy))
        .unwrap_err();
    assert!(err.to_string().contains("composite pass"), "{err}");
    assert!(err.to_string().contains("glossy splat"), "{err}");
    gpu.pass
        .record(&mut rec, &gpu.scene, &gpu.gbuffer, [0.0; 2])
        .unwrap();
    // No records: Σw = 0 everywhere.
    rec.clear_color(&splat.sum, [0.0; 4]);
    rec.clear_color(&splat.count, [0.0; 4]);
    direct
        .record(&mut rec, &inputs(None), &DirectImage)
        .unwrap();
    let plain = composited(None);
    composite.record(&mut rec, CompositeJob::Clear).unwrap();
    composite
        .record(&mut rec, CompositeJob::Add(&plain))
        .unwrap();
    ctx.submit(rec).unwrap().wait().unwrap();
    let (mean, dropped) = composite.read_mean(ctx).unwrap();
    assert_eq!(dropped, 0);
    assert!(mean.iter().any(|p| p[0] > 0.0), "the box is lit");
    drop((direct, composite, splat, glossy));
    gpu.end();
}
