// A draw blended by table (fragment_ops.h BlendTable: a uniform-only shader, single-sampled, no
// depth/stencil tests, coverage ops or smoothing) needs no quads where a primitive covers whole
// 8x8 blocks: those are blended in place, row by row (apply_blend_table_to_rect), and only the
// rest of the primitive is rasterized.
#pragma once
#include <cstdint>
#include <vector>

#include "softgl/core/simd.h"
#include "softgl/pipeline/draw_stats.h"
#include "softgl/pipeline/early_depth.h"
#include "softgl/pipeline/fragment_ops.h"
#include "softgl/pipeline/raster.h"

namespace softgl {

// p's pixels in `tile` on the RGBA8 buffer `color` (pitch in pixels): a part covered whole (every
// pixel's one sample of `sp` inside every edge) is blended at once; otherwise, per row of blocks,
// the run of covered blocks is, and the rest is rasterized, appended to `quads` for the caller to
// blend. `raster` and `stats` count what rasterizing and blending it all as quads would count.
// `level`: the SIMD level of the raster and the table lookups (the draw plan's).
void blend_covered_part(SimdLevel level, const PrimitiveSetup& p, const TileRect& tile, const SamplePattern& sp,
                        const BlendTable& table, uint8_t* color, size_t pitch, std::vector<Quad>& quads,
                        RasterStats& raster, DrawStats& stats);

// A depth-only draw (DrawPlan::depth_blocks: nothing shaded, one sample per pixel, the quad early
// depth test) likewise needs no quads where p covers whole 8x8 blocks: per row of blocks, the run
// of covered blocks inside p's bounding box is tested in place (early_depth_rect_at, the words and
// decisions of testing its quads), the rest rasterized and appended to `quads` for the caller to
// test. A primitive's pixels are distinct, so the order of their tests changes no word. `raster`
// and `stats` (quads with a passing pixel, fragments killed early) count what rasterizing and
// testing it all as quads would.
void depth_covered_part(SimdLevel level, const PrimitiveSetup& p, const TileRect& tile, const SamplePattern& sp,
                        const EarlyDepth& test, std::vector<Quad>& quads, RasterStats& raster, DrawStats& stats);

}  // namespace softgl
