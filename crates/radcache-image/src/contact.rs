//! Contact sheets: the frames of a sequence reduced and tiled into one image, for a glance at a
//! whole animation (`radcache render --contact-sheet sheet.png`).
//!
//! Each frame is reduced by the smallest integer factor `f` that fits it into a `max_cell`
//! square (`f = max(⌈w/max_cell⌉, ⌈h/max_cell⌉, 1)`): every cell pixel is the mean of the finite
//! values of its `f × f` block (0 when none is finite, so a bad pixel never spreads). Cells are laid
//! out row by row, in the order given, in `⌈√n⌉` columns, with a [`GAP`]-pixel black border around
//! and between them; every cell has the size of the first frame's.

use crate::error::{Error, Result};
use crate::image::Image;

/// Black pixels around and between the cells.
pub const GAP: u32 = 2;

/// `image` reduced by the integer factor `factor` (see the module docs).
pub fn reduce(image: &Image, factor: u32) -> Image {
    let f = factor.max(1);
    let (w, h) = (image.width().div_ceil(f), image.height().div_ceil(f));
    let mut out = Image::new(w, h);
    let src = image.rgb();
    let width = image.width() as usize;
    let dst = out.rgb_mut();
    for y in 0..h {
        for x in 0..w {
            let (mut sum, mut n) = ([0.0f64; 3], [0u32; 3]);
            for sy in y * f..((y + 1) * f).min(image.height()) {
                for sx in x * f..((x + 1) * f).min(image.width()) {
                    let i = 3 * (sy as usize * width + sx as usize);
                    for c in 0..3 {
                        let v = src[i + c];
                        if v.is_finite() {
                            sum[c] += f64::from(v);
                            n[c] += 1;
                        }
                    }
                }
            }
            let o = 3 * (y as usize * w as usize + x as usize);
            for c in 0..3 {
                dst[o + c] = if n[c] > 0 {
                    (sum[c] / f64::from(n[c])) as f32
                } else {
                    0.0
                };
            }
        }
    }
    out
}

/// The reduction factor that fits a `width × height` frame into a `max_cell` square.
pub fn reduction_factor(width: u32, height: u32, max_cell: u32) -> u32 {
    let m = max_cell.max(1);
    width.div_ceil(m).max(height.div_ceil(m)).max(1)
}

/// Tiles `frames` (already reduced, all of one size) into a contact sheet; errors when there is
/// no frame or a frame's size differs from the first's.
pub fn contact_sheet(frames: &[Image]) -> Result<Image> {
    let first = frames
        .first()
        .ok_or_else(|| Error::InvalidImage("a contact sheet needs at least one frame".into()))?;
    let (cw, ch) = (first.width(), first.height());
    let n = frames.len() as u32;
    let columns = (f64::from(n).sqrt().ceil() as u32).max(1);
    let rows = n.div_ceil(columns);
    let width = columns * (cw + GAP) + GAP;
    let height = rows * (ch + GAP) + GAP;
    let mut sheet = Image::new(width, height);
    let dst = sheet.rgb_mut();
    for (k, frame) in frames.iter().enumerate() {
        if (frame.width(), frame.height()) != (cw, ch) {
            return Err(Error::InvalidImage(format!(
                "contact sheet frame {k} is {}x{}, not {cw}x{ch} like the first",
                frame.width(),
                frame.height()
            )));
        }
        let k = k as u32;
        let (x0, y0) = (
            GAP + (k % columns) * (cw + GAP),
            GAP + (k / columns) * (ch + GAP),
        );
        for y in 0..ch {
            let src = &frame.rgb()[(3 * y * cw) as usize..(3 * (y + 1) * cw) as usize];
            let o = 3 * ((y0 + y) * width + x0) as usize;
            dst[o..o + src.len()].copy_from_slice(src);
        }
    }
    Ok(sheet)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn constant(w: u32, h: u32, v: f32) -> Image {
        Image::from_rgb(w, h, vec![v; (3 * w * h) as usize]).unwrap()
    }

    #[test]
    fn reduction_averages_finite_values_per_block() {
        let mut img = constant(5, 3, 1.0);
        // Block (0, 0) of a 2× reduction: pixels (0,0), (1,0), (0,1), (1,1).
        img.rgb_mut()[0] = 5.0;
        img.rgb_mut()[3] = f32::NAN;
        let r = reduce(&img, 2);
        assert_eq!((r.width(), r.height()), (3, 2));
        assert_eq!(r.pixel(0, 0)[0], (5.0 + 1.0 + 1.0) / 3.0);
        assert_eq!(r.pixel(0, 0)[1], 1.0);
        // The last column and row are partial blocks.
        assert_eq!(r.pixel(2, 1), [1.0; 3]);
        let all_nan = Image::from_rgb(1, 1, vec![f32::NAN; 3]).unwrap();
        assert_eq!(reduce(&all_nan, 4).pixel(0, 0), [0.0; 3]);
        assert_eq!(reduction_factor(256, 256, 160), 2);
        assert_eq!(reduction_factor(100, 40, 160), 1);
        assert_eq!(reduction_factor(1000, 200, 160), 7);
    }

    #[test]
    fn frames_are_tiled_row_by_row_with_gaps() {
        let frames: Vec<Image> = (0..5).map(|k| constant(4, 3, k as f32 + 1.0)).collect();
        let sheet = contact_sheet(&frames).unwrap();
        // 5 frames: 3 columns, 2 rows.
        assert_eq!(sheet.width(), 3 * (4 + GAP) + GAP);
        assert_eq!(sheet.height(), 2 * (3 + GAP) + GAP);
        assert_eq!(sheet.pixel(0, 0), [0.0; 3]);
        assert_eq!(sheet.pixel(GAP, GAP), [1.0; 3]);
        assert_eq!(sheet.pixel(GAP + 2 * (4 + GAP) + 3, GAP + 2), [3.0; 3]);
        assert_eq!(sheet.pixel(GAP + (4 + GAP), GAP + (3 + GAP)), [5.0; 3]);
        // The sixth cell is empty.
        assert_eq!(sheet.pixel(GAP + 2 * (4 + GAP), GAP + (3 + GAP)), [0.0; 3]);
        assert!(contact_sheet(&[]).is_err());
        assert!(contact_sheet(&[constant(4, 3, 1.0), constant(3, 3, 1.0)]).is_err());
    }
}
