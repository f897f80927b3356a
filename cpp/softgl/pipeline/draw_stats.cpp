#include "softgl/pipeline/draw_stats.h"

namespace softgl {

void DrawStats::add(const DrawStats& o) {
    draws += o.draws; vertices_shaded += o.vertices_shaded; primitives += o.primitives;
    primitives_culled += o.primitives_culled; primitives_clipped += o.primitives_clipped;
    primitives_outside += o.primitives_outside; primitives_invalid += o.primitives_invalid;
    primitives_zero_area += o.primitives_zero_area; primitives_rasterized += o.primitives_rasterized;
    tiles_touched += o.tiles_touched; quads += o.quads; blocks_accepted_whole += o.blocks_accepted_whole;
    fragments_shaded += o.fragments_shaded; fragments_killed_early += o.fragments_killed_early;
    fragments_killed_late += o.fragments_killed_late; fragments_discarded += o.fragments_discarded;
    fragments_hidden += o.fragments_hidden; tiles_hidden_surface += o.tiles_hidden_surface; primitives_depth_hidden += o.primitives_depth_hidden;
    samples_written += o.samples_written; samples_blended += o.samples_blended;
    draws_skipped_no_output += o.draws_skipped_no_output; draws_early_depth += o.draws_early_depth;
    draws_blend_table += o.draws_blend_table; draws_plain_write += o.draws_plain_write;
    draws_late_tests += o.draws_late_tests; draws_constant_color += o.draws_constant_color;
    draws_copied_varying += o.draws_copied_varying; draws_per_lane_color += o.draws_per_lane_color;
    texture_queries_fast += o.texture_queries_fast; draws_with_rollback += o.draws_with_rollback;
    fragments_flat += o.fragments_flat; draws_flat_primitives += o.draws_flat_primitives;
    draws_texture_copy += o.draws_texture_copy; draws_texel_words += o.draws_texel_words;
    blocks_depth_in_place += o.blocks_depth_in_place;
    quads_blended_in_place += o.quads_blended_in_place;
    seconds_vertex += o.seconds_vertex; seconds_setup += o.seconds_setup; seconds_fragment += o.seconds_fragment;
}

}  // namespace softgl
