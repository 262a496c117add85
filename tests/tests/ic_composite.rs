//! The composite of the sub-frames after the first when the records are splatted once per frame:
//! the direct pass made to composite adds their samples to the frame's accumulators itself
//! (`DIRECT_COMPOSITE`, docs/cache-frame.md §6.5), and must add exactly what its direct image
//! followed by the composite pass adds.

use radcache_render::{
    frame::settings::sub_frame_jitter, passes::composite::CentreSamples,
    passes::composite::CompositeInputs, passes::composite::CompositeJob,
    passes::composite::CompositePass, passes::composite::CompositeVariant,
    passes::direct::CompositeSubFrame, passes::direct::CompositeTargets,
    passes::direct::DirectCompositing, passes::direct::DirectInputs, passes::direct::DirectOutputs,
    passes::direct::DirectPass, passes::direct::DirectShadows, passes::direct::DirectVariant,
    passes::splat::SplatPass, EmitterLight, SkyLight,
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
        composite: Some(DirectCompositing { moments: true }),
        shadows: DirectShadows::Adaptive { pixels: w * h },
        ..DirectVariant::new(SkyLight::Direct, EmitterLight::Analytic)
    };
    let direct = || DirectPass::new(ctx, shaders, &gpu.scene, &direct_variant).unwrap();
    let variant = CompositeVariant {
        moments: true,
        centres: true,
        ..CompositeVariant::new(w, h)
    };
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
    // A direct pass made to composite refuses the plain recording.
    let mut rec = ctx.begin("test.refused").unwrap();
    let plain = passes[0]
        .0
        .record(&mut rec, &inputs(0), &DirectOutputs::Image);
    assert!(plain.is_err());
    drop(rec);
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
            let outputs = DirectOutputs::Composited {
                targets: CompositeTargets {
                    composite,
                    splat: &splat,
                },
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
                let inputs = CompositeInputs {
                    centre,
                    ..CompositeInputs::own(&gpu.scene, g, &splat, jitter)
                };
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
