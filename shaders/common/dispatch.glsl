// common/dispatch.glsl — the order of a dispatch's workgroups on lavapipe. interleaved_pixel: the
// pixel of an invocation of a 2D image pass of 8×8 workgroups
// dispatched as radcache_shared::dispatch::image_dispatch says: (columns, ⌈rows/K⌉, K), and
// workgroup (x, j, c) takes row of tiles j·K + c (docs/cache-frame.md §11). Include after the
// pass's `layout(local_size_x = …, local_size_y = …) in;` (it reads gl_WorkGroupSize); a pass
// returns where the pixel is past the image, as for the partial tiles at its edges.
//
// lavapipe hands each of its threads one contiguous block of a dispatch's workgroups (x
// fastest, then y, then z). In the plain (columns, rows) order a block is a band of the image's
// rows, and where the cost per pixel changes down the image one thread works on while the
// others idle; in this order a block holds whole classes of rows c, K + c, 2K + c, …, each
// spread over the image. Every tile is still done once and nothing changes within a tile, so a
// pass gives the same pixels bit for bit. A GPU schedules workgroups dynamically and loses
// nothing. A dispatch with one z-slice is the plain order.
#ifndef RADCACHE_DISPATCH_GLSL
#define RADCACHE_DISPATCH_GLSL

// The item that workgroup `i` of a 1D dispatch of `n` works on (the record pass's requests,
// which hole selection appends roughly in image order): taken in K = clamp(n/8, 1, 16) classes
// c, K + c, 2K + c, …, the longer classes first, so that each thread's block holds items from
// the whole list. A bijection of [0, n); radcache_shared::dispatch::interleaved_index.
uint interleaved_index(uint i, uint n) {
    uint k = clamp(n / 8u, 1u, 16u);
    if (k <= 1u || i >= n) {
        return i;
    }
    uint q = n / k;
    uint rem = n % k;
    uint long_items = rem * (q + 1u);
    uint class_index, j;
    if (i < long_items) {
        class_index = i / (q + 1u);
        j = i % (q + 1u);
    } else {
        uint s = i - long_items;
        class_index = rem + s / q;
        j = s % q;
    }
    return j * k + class_index;
}

uvec2 interleaved_pixel() {
    uint row = gl_WorkGroupID.y * gl_NumWorkGroups.z + gl_WorkGroupID.z;
    return uvec2(gl_WorkGroupID.x, row) * gl_WorkGroupSize.xy + gl_LocalInvocationID.xy;
}

#endif
