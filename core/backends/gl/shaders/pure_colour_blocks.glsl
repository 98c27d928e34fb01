// Which pixels wake the pure colours' fit around them: where F varies (WAKE_FILTERED), and
// that could be a thin feature's ridge (WAKE_RIDGE). The fit covers O's active blocks within
// 2 pixels of a wake (flag_wakes.comp lists them), without the extension tests where no ridge
// is that near or, gated, where the drawn content's gate is shut on the whole block;
// elsewhere it gives F exactly. Twin: pure_colour_mask in backends/gl/blocks.py and
// possible_ridges in aarecovery/spec/pure_colours.py, which derive the rule. Needs
// working.glsl first (O in the working space, F as uploaded).
const uint WAKE_FILTERED = 1u;
const uint WAKE_RIDGE = 2u;
uniform float ridge_floor;  // RIDGE_NOISE_MARGIN times O's ridge noise: 0 on a lossless O

// Neighbours count for the ridge test within this distance of the extremes' line (the twin's
// LINE_TOLERANCE; pure_colours.glsl includes this file for it).
const float LINE_TOLERANCE = 0.05;
const float RIDGE_BOUND_SLACK = 1e-4;

// Opposite neighbours at a and b from the centre (the differences centre - neighbour) can
// both lie near the extremes' line and below the centre along it.
bool possible_pair(vec4 a, vec4 b) {
    float line_sq = LINE_TOLERANCE * LINE_TOLERANCE + RIDGE_BOUND_SLACK;
    float a_sq = dot(a, a);
    float b_sq = dot(b, b);
    float along = sqrt(max(a_sq - line_sq, 0.0)) * sqrt(max(b_sq - line_sq, 0.0));
    float across = sqrt(min(a_sq, line_sq)) * sqrt(min(b_sq, line_sq));
    float floor_sq = ridge_floor * ridge_floor;
    return a_sq > floor_sq && b_sq > floor_sq && a_sq > 0.0 && b_sq > 0.0
           && dot(a, b) >= along - across - RIDGE_BOUND_SLACK;
}

bool possible_ridge(ivec2 q, ivec2 size) {
    if (q.x <= 0 || q.y <= 0 || q.x >= size.x - 1 || q.y >= size.y - 1) return false;
    vec4 v[9];
    for (int i = 0; i < 9; ++i) v[i] = original_neighbour(q, i, size);
    // N/S, W/E, NW/SE, NE/SW, written out (an index from a loop spills v[] on llvmpipe).
    return possible_pair(v[0] - v[1], v[0] - v[4]) || possible_pair(v[0] - v[2], v[0] - v[3])
        || possible_pair(v[0] - v[5], v[0] - v[8]) || possible_pair(v[0] - v[6], v[0] - v[7]);
}

// The wake bits of pixel p (pure_colour_blocks.frag stores them as p's texel of wakes).
uint pure_colour_wakes(ivec2 p, ivec2 size) {
    uint wakes = filtered_varies(p, size) ? WAKE_FILTERED : 0u;
    if (possible_ridge(p, size)) wakes |= WAKE_RIDGE;
    return wakes;
}
