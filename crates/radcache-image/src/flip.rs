//! Mean LDR FLIP between two images, through the `nv-flip` crate (NVIDIA's reference C++ FLIP,
//! Andersson et al., "FLIP: A Difference Evaluator for Alternating Images", HPG 2020).
//!
//! Both images are encoded for display first (exposure 0, no tone curve, clamp, sRGB OETF,
//! 8 bits: [`crate::to_srgb8`]'s transform), which is the input LDR-FLIP expects, and compared
//! at FLIP's default 67 pixels per degree (viewer 0.7 m from a 0.7 m wide, 3840-pixel monitor). FLIP
//! filters over neighbourhoods, so non-finite pixels cannot simply be skipped: before encoding,
//! a non-finite pixel takes the other image's value (black in both when both are non-finite),
//! so it adds no error of its own; such pixels are counted separately in [`crate::Metrics`].
//! The mean is over all pixels.
//!
//! `None` when the `flip` cargo feature is off, for empty images, or when
//! `3 · width · height` exceeds `u32::MAX` (an `nv-flip` limit).

use crate::image::Image;

/// Mean FLIP in [0, 1], or `None` (see the module docs). The images must have the same size.
#[cfg(feature = "flip")]
pub(crate) fn mean_flip(reference: &Image, candidate: &Image) -> Option<f64> {
    use crate::color::{display_u8, ToneMap};

    debug_assert_eq!(
        (reference.width(), reference.height()),
        (candidate.width(), candidate.height())
    );
    let (width, height) = (reference.width(), reference.height());
    let values = u64::from(width) * u64::from(height) * 3;
    if values == 0 || values > u64::from(u32::MAX) {
        return None;
    }
    let encode = |v: f32| display_u8(v, 1.0, ToneMap::None);
    let mut ref8 = Vec::with_capacity(values as usize);
    let mut cand8 = Vec::with_capacity(values as usize);
    for (r, c) in reference
        .rgb()
        .chunks_exact(3)
        .zip(candidate.rgb().chunks_exact(3))
    {
        let finite = |p: &[f32]| p.iter().all(|v| v.is_finite());
        let (r, c) = match (finite(r), finite(c)) {
            (true, true) => (r, c),
            (true, false) => (r, r),
            (false, true) => (c, c),
            (false, false) => (&[0.0_f32; 3][..], &[0.0_f32; 3][..]),
        };
        ref8.extend(r.iter().map(|&v| encode(v)));
        cand8.extend(c.iter().map(|&v| encode(v)));
    }
    let ref_image = nv_flip::FlipImageRgb8::with_data(width, height, &ref8);
    let cand_image = nv_flip::FlipImageRgb8::with_data(width, height, &cand8);
    let error_map = nv_flip::flip(ref_image, cand_image, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let pool = nv_flip::FlipPool::from_image(&error_map);
    Some(f64::from(pool.mean()))
}

/// Always `None`: built without the `flip` feature.
#[cfg(not(feature = "flip"))]
pub(crate) fn mean_flip(_reference: &Image, _candidate: &Image) -> Option<f64> {
    None
}
