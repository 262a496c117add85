//! The dispatch of a 2D image pass of 8×8 workgroups, and the order in which its workgroups
//! take the image's rows of tiles (`shaders/common/dispatch.glsl`, docs/cache-frame.md §11).
//!
//! lavapipe's compute thread pool hands each of its `T` threads one contiguous block of a
//! dispatch's workgroups (`N/T` of them, x fastest, then y, then z). Dispatched as
//! `(columns, rows)`, a block is a band of rows of the image, and where the cost per pixel
//! changes down the image (a sky above a street, shadowed boxes on a floor, the emitter's edges
//! at the top of a room) one thread works on while the others idle. So an image pass is
//! dispatched as `(columns, ⌈rows/K⌉, K)`: workgroup `(x, j, c)` takes row of tiles `j·K + c`
//! (none where that is past the image), and a block of consecutive workgroups holds whole
//! classes `c` of rows `c, K + c, 2K + c, …`, each spread over the whole image.

/// Side of the square tiles (workgroups) of the image passes, in pixels.
pub const TILE: u32 = 8;

/// The largest number of classes: enough for a 16-thread lavapipe (a class or more each).
pub const MAX_CLASSES: u32 = 16;

/// The number of classes `K` for `rows` rows of tiles: `rows/8` clamped to `[1, MAX_CLASSES]`,
/// so that each class has at least 8 rows spread over the image (1, the plain order, below 16).
pub fn row_classes(rows: u32) -> u32 {
    (rows / 8).clamp(1, MAX_CLASSES)
}

/// The workgroups of an image pass over `width × height` pixels: `(columns, ⌈rows/K⌉, K)`.
pub fn image_dispatch(width: u32, height: u32) -> [u32; 3] {
    let rows = height.div_ceil(TILE);
    let classes = row_classes(rows);
    [width.div_ceil(TILE), rows.div_ceil(classes), classes]
}

/// The row of tiles of workgroup `(_, j, c)` of a dispatch with `classes` z-slices
/// (`interleaved_pixel` in GLSL); at or past the image's rows the workgroup has nothing to do.
pub fn tile_row(j: u32, c: u32, classes: u32) -> u32 {
    j * classes + c
}

/// The item that workgroup `i` of a 1D dispatch of `n` works on (`interleaved_index` in GLSL;
/// the record pass's requests, which hole selection appends roughly in image order): items in
/// `K = clamp(n/8, 1, MAX_CLASSES)` classes `c, K + c, 2K + c, …`, class 0 first, the longer
/// classes (`⌈n/K⌉` items) before the shorter, so that each thread's block of workgroups holds
/// items from the whole list. A bijection of `[0, n)`; `i ≥ n` is returned as it is.
pub fn interleaved_index(i: u32, n: u32) -> u32 {
    let k = (n / 8).clamp(1, MAX_CLASSES);
    if k <= 1 || i >= n {
        return i;
    }
    let (q, rem) = (n / k, n % k);
    let long = rem * (q + 1);
    let (class, j) = if i < long {
        (i / (q + 1), i % (q + 1))
    } else {
        let s = i - long;
        (rem + s / q, s % q)
    };
    j * k + class
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows of tiles in lavapipe's order of workgroups (y, then z; x does not change the
    /// row), those past the image left out.
    fn rows_in_dispatch_order(height: u32) -> Vec<u32> {
        let rows = height.div_ceil(TILE);
        let [_, y, z] = image_dispatch(64, height);
        (0..z)
            .flat_map(|c| (0..y).map(move |j| tile_row(j, c, z)))
            .filter(|&row| row < rows)
            .collect()
    }

    #[test]
    fn every_row_of_tiles_is_taken_once() {
        for height in 1..=4000u32 {
            let rows = height.div_ceil(TILE);
            let mut order = rows_in_dispatch_order(height);
            order.sort_unstable();
            assert_eq!(order, (0..rows).collect::<Vec<_>>(), "{height} px");
            // At most K − 1 workgroup rows fall past the image.
            let [_, y, z] = image_dispatch(8, height);
            assert!(y * z - rows < z, "{height} px");
        }
    }

    /// The quarters of the image that the `k`-th of `threads` equal blocks of `order` reaches.
    fn quarters(order: &[u32], rows: u32, threads: usize, k: usize) -> usize {
        let band = order.len() / threads;
        let mut hit = [false; 4];
        for &row in &order[k * band..(k + 1) * band] {
            hit[(row * 4 / rows) as usize] = true;
        }
        hit.iter().filter(|&&h| h).count()
    }

    #[test]
    fn every_thread_s_block_reaches_every_quarter_of_the_image() {
        // lavapipe's share of a thread, for the thread counts of 2- to 16-core machines, where
        // the block has at least 8 rows; in plain order a block reaches one or two quarters.
        for height in (128..=24_000u32).step_by(8) {
            let rows = height / TILE;
            let order = rows_in_dispatch_order(height);
            for threads in [2, 3, 4, 6, 8, 12, 16] {
                if order.len() / threads < 8 {
                    continue;
                }
                for k in 0..threads {
                    let hit = quarters(&order, rows, threads, k);
                    assert_eq!(hit, 4, "{height} px, {threads} threads, block {k}");
                }
            }
        }
        let plain: Vec<u32> = (0..128).collect();
        assert_eq!(quarters(&plain, 128, 2, 0), 2);
    }

    #[test]
    fn every_item_of_a_1d_dispatch_is_taken_once_and_spread() {
        for n in 0..=3000u32 {
            let order: Vec<u32> = (0..n).map(|i| interleaved_index(i, n)).collect();
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..n).collect::<Vec<_>>(), "{n} items");
            if n >= 128 {
                // Each of 2–16 threads' blocks reaches every quarter of the list.
                for threads in [2, 3, 4, 8, 16] {
                    if order.len() / threads < 8 {
                        continue;
                    }
                    for k in 0..threads {
                        assert_eq!(quarters(&order, n, threads, k), 4, "{n} items, {threads}");
                    }
                }
            }
        }
        assert_eq!(interleaved_index(7, 7), 7);
        // 64 items in 8 classes: 0, 8, 16, … first.
        assert_eq!([1, 8].map(|i| interleaved_index(i, 64)), [8, 1]);
    }

    #[test]
    fn image_dispatches() {
        assert_eq!(image_dispatch(1024, 1024), [128, 8, 16]);
        assert_eq!(image_dispatch(1920, 1080), [240, 9, 16]);
        assert_eq!(image_dispatch(256, 256), [32, 8, 4]);
        assert_eq!(image_dispatch(96, 72), [12, 9, 1]);
        assert_eq!(image_dispatch(1, 1), [1, 1, 1]);
        // 1024 px: the first workgroups take tile rows 0, 16, 32, …; the second class 1, 17, ….
        assert_eq!(
            [tile_row(0, 0, 16), tile_row(1, 0, 16), tile_row(0, 1, 16)],
            [0, 16, 1]
        );
    }
}
