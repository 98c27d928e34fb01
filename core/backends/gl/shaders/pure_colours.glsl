// Pure colours of thin features (the safe default, point-wise filters on hard-edged content).
// Twin: extend_extreme and filtered_colour in aarecovery/spec/pure_colours.py, which explains
// the rule and its measurements. Included after working.glsl, before blend_model.glsl.
#include "transfer_table.glsl"
// The ridge test's LINE_TOLERANCE, shared with the blocks it marks:
#include "pure_colour_blocks.glsl"

uniform vec3 palette[32];          // O's flat colours, opaque, in the working space
uniform int palette_size;
// INK_SLOTS: the seen-ink test's length, compiled in: the fewest of _INK_SLOT_COUNTS
// (backends/gl/backend.py) that hold O's inks, the slots past them holding a colour that no
// encoded colour comes near. On llvmpipe a loop whose length is a uniform cost far more than
// its arithmetic, and a loop over all 16 slots with a uniform guard as much again
// (docs/performance.md, "The seen-ink test's length compiled in").
#ifndef INK_SLOTS
#define INK_SLOTS 0
#endif
#if INK_SLOTS > 0
uniform vec3 inks[INK_SLOTS];      // O's recurring colours on the cube's faces, encoded
#endif
uniform vec3 key_low;              // O's key range (bin centres of the table's first and last
uniform vec3 key_high;             // filled bins, per column); beyond it the table is extrapolated
uniform float noise_contrast;      // O's compression noise as a contrast (0: not compressed)
uniform float ridge_noise;         // the same, for the ridge test (0: not compressed; no grain)
uniform float luma_purity;         // an extreme whose luma is within this of a flat colour's is
                                   // that colour (0: colours only; is_flat_colour)
// PURE_GATE: 1: the prior acts on drawn content only, `gate` (the local plan's region
//            weight, 0 to 1) of the way (PureColourPrior.drawn_only)
#ifndef PURE_GATE
#define PURE_GATE 0
#endif
// BACKED_OR_SEEN: 1 (with PURE_GATE, on a lossless O): a partial colour is extended only
//            against a flat colour of O or towards a pure colour O shows
//            (PureColourPrior.backed_or_seen)
#ifndef BACKED_OR_SEEN
#define BACKED_OR_SEEN 0
#endif
// NO_EXTENSION: 1: no extreme is extended (the blocks the pure colours' listing found no
//            possible ridge near: backend._pure_colour_lists), the same model as where every test fails
#ifndef NO_EXTENSION
#define NO_EXTENSION 0
#endif

// The prior's switches are compile-time defines, not uniforms: llvmpipe runs both sides of
// every branch under a mask, so a uniform switch paid for every key's sRGB conversions
// (pow) at every fitted pixel.
// CLAMP_ENDS: 1: an extreme at an end of the range reads the table clamped
// TO_CUBE: 0: extend only to a flat colour of O beyond the extreme
#ifndef CLAMP_ENDS
#define CLAMP_ENDS 0
#endif
#ifndef TO_CUBE
#define TO_CUBE 1
#endif
// EXPLAIN_FILTERED: 1: the table must reproduce F at the extreme (a fitted table); 0: the
//            identity table of a neighbourhood filter that keeps flat colours, where F at the
//            extreme must instead stay on O's colour line and keep its contrast
#ifndef EXPLAIN_FILTERED
#define EXPLAIN_FILTERED 1
#endif

const float PALETTE_TOLERANCE = 0.03;
const float RIDGE_MARGIN = 0.1001;
const float INK_LINE_TOLERANCE = 0.025;  // a flat colour beyond the extreme, on its line
const float RIDGE_NOISE_MARGIN = 1.5;
const float EXPLAIN_TOLERANCE = 0.02;
const float ON_LINE_TOLERANCE = 0.15;
const float KEPT_CONTRAST = 0.5;
const float RANGE_TOLERANCE = 0.05;
const float END_TOLERANCE = 1.0 / 255.0;
const float MIN_CONTRAST = 8.5 / 255.0;
const float MIN_REACH = 1.2001;
const float INK_TOLERANCE = 2.0 / 255.0;
const float SHORT_REACH = 1.0001;
const float RIDGE_EDGE_SCALE = 0.5;

vec3 encoded_of(vec4 colour) {
    float coverage = colour.a;
    vec3 straight = clamp(colour.rgb / (coverage > 0.0 ? coverage : 1.0), 0.0, 1.0);
#if WORK_IS_LINEAR
    return linear_to_srgb(straight);
#else
    return straight;
#endif
}

// f of a premultiplied working-space colour whose encoded colour and (clamped) table keys
// are known.
vec4 filtered_colour_of(vec4 colour, vec3 encoded, vec3 keys) {
    float coverage = colour.a;
    vec3 out_colour = transfer_encoded(encoded, keys);
#if WORK_IS_LINEAR
    vec3 decoded = srgb_to_linear(clamp(out_colour, 0.0, 1.0));
#else
    vec3 decoded = out_colour;
#endif
    return vec4(decoded * coverage, coverage);
}

// f of a premultiplied working-space colour, by the table, its keys clamped from below /
// above to O's key range where low_end / high_end.
vec4 filtered_colour_clamped(vec4 colour, bvec3 low_end, bvec3 high_end) {
    vec3 encoded = encoded_of(colour);
    vec3 keys = key_values(encoded);
    keys = mix(keys, max(keys, key_low), vec3(low_end));
    keys = mix(keys, min(keys, key_high), vec3(high_end));
    return filtered_colour_of(colour, encoded, keys);
}

// Both pixels lie on the colour line and are less extreme than `limit` along it.
bool lower_pair(ivec2 first_at, ivec2 second_at, vec4 near, vec4 direction, float limit, ivec2 size) {
    vec4 first = texelFetch(original_work, clamp_to_image(first_at, size), 0) - near;
    vec4 second = texelFetch(original_work, clamp_to_image(second_at, size), 0) - near;
    float t_first = dot(first, direction);
    float t_second = dot(second, direction);
    float reach_sq = LINE_TOLERANCE * LINE_TOLERANCE;
    bool on_line = (dot(first, first) - t_first * t_first < reach_sq)
                && (dot(second, second) - t_second * t_second < reach_sq);
    return on_line && t_first < limit && t_second < limit;
}

struct Extension {
    bool extended;
    vec4 colour;    // the pure colour (the extreme itself where not extended)
    vec4 filtered;  // f of it, where extended
};

// Is the extreme `far` at pixel q a thin feature's partial colour? If so, extend it along the
// line from `near` to the colour cube (with PURE_GATE, `gate`'s share of the way).
Extension extend_extreme(vec4 far, vec4 near, ivec2 q, vec4 filtered_far, ivec2 size, float gate) {
    Extension result = Extension(false, far, far);
#if NO_EXTENSION
    // The blocks with no possible ridge near an open gate (pure_colour_blocks.glsl): none of
    // the tests below passes there, and llvmpipe would run them all under a mask.
    return result;
#endif
#if PURE_GATE
    // Shut (a photo region): never extended, as at the end of the tests below, without them.
    if (!(gate > 0.0)) return result;
#endif
    vec4 span = far - near;
    float len = sqrt(dot(span, span));
    if (!(len > 1e-6)) return result;
    // Extremes within an 8-bit gradient's (or a JPEG's) noise of each other are not a thin feature.
    vec3 far_encoded = encoded_of(far);
    vec3 near_encoded = encoded_of(near);
    vec3 steps = abs(far_encoded - near_encoded);
    if (!(max(max(max(steps.r, steps.g), steps.b), abs(span.a)) >= max(MIN_CONTRAST, noise_contrast))) return result;
    if (q.x <= 0 || q.y <= 0 || q.x >= size.x - 1 || q.y >= size.y - 1) return result;
    // The tests are all required, so their order is free: the ridge test first, as it fails
    // for nearly every extreme (a shape's edge is no ridge), and a GPU skips what follows
    // where a whole group of pixels has failed. llvmpipe runs it under a mask all the same
    // (thin-features pair at 4096^2, the fit's pass clock: 0.31 s; 0.16 s with what follows
    // removed; 0.34 s with it behind a test that fails everywhere), so there its cost is its
    // length (docs/performance.md).
    vec4 direction = span / len;
    float t_far = dot(far - near, direction);
    // Past the noise's contrast too (RIDGE_NOISE_MARGIN in the twin says why).
    float margin = max(RIDGE_MARGIN * len, RIDGE_NOISE_MARGIN * ridge_noise);
    // Opposite pairs of q's neighbours, N/S, W/E, NW/SE, NE/SW, written out: indexing an
    // array with a loop variable makes llvmpipe spill it to memory.
    bool ridge = lower_pair(q + OFFSETS[1], q + OFFSETS[4], near, direction, t_far - margin, size)
              || lower_pair(q + OFFSETS[2], q + OFFSETS[3], near, direction, t_far - margin, size)
              || lower_pair(q + OFFSETS[5], q + OFFSETS[8], near, direction, t_far - margin, size)
              || lower_pair(q + OFFSETS[6], q + OFFSETS[7], near, direction, t_far - margin, size);
    if (!ridge) return result;
    float tolerance_sq = PALETTE_TOLERANCE * PALETTE_TOLERANCE;
    // One loop over the palette for both extremes (a loop costs its full length on llvmpipe,
    // whatever its early exits).
    bool far_pure = false, near_pure = false;
    // The luma test is false for every colour where luma_purity is 0 (an uncompressed O).
    for (int i = 0; i < palette_size; ++i) {
        vec3 miss = far.rgb - palette[i] * far.a;
        far_pure = far_pure || !(miss.r * miss.r + miss.g * miss.g + miss.b * miss.b >= tolerance_sq)
                   || abs(miss.r * LUMA.r + miss.g * LUMA.g + miss.b * LUMA.b) < luma_purity;
#if CLAMP_ENDS || BACKED_OR_SEEN
        vec3 near_miss = near.rgb - palette[i] * near.a;
        near_pure = near_pure || near_miss.r * near_miss.r + near_miss.g * near_miss.g
                                 + near_miss.b * near_miss.b < tolerance_sq
                    || abs(near_miss.r * LUMA.r + near_miss.g * LUMA.g + near_miss.b * LUMA.b) < luma_purity;
#endif
    }
    if (far_pure) return result;
    vec3 far_keys = key_values(far_encoded);
#if EXPLAIN_FILTERED
    vec4 explained = abs(filtered_colour_of(far, far_encoded, far_keys) - filtered_far);
    if (!(max(max(explained.r, explained.g), explained.b) < EXPLAIN_TOLERANCE)) return result;
#endif
#if !EXPLAIN_FILTERED
    // No fitted table: F at the extreme lies on O's colour line and keeps the contrast.
    vec4 moved = filtered_far - near;
    float moved_along = dot(moved, direction);
    if (!(dot(moved, moved) - moved_along * moved_along < ON_LINE_TOLERANCE * ON_LINE_TOLERANCE)
        || !(moved_along >= KEPT_CONTRAST * len)) return result;
#endif
#if CLAMP_ENDS
    // An extreme that is O's darkest or brightest colour is pure (a paper between thin lines),
    // unless the other extreme is the opposite end or a flat colour (spec/pure_colours.extend_extreme).
    vec3 near_keys = key_values(near_encoded);
    bool far_low = all(lessThanEqual(far_keys, key_low + END_TOLERANCE));
    bool far_high = all(greaterThanEqual(far_keys, key_high - END_TOLERANCE));
    bool near_low = all(lessThanEqual(near_keys, key_low + END_TOLERANCE));
    bool near_high = all(greaterThanEqual(near_keys, key_high - END_TOLERANCE));
    if (((far_low && !near_high) || (far_high && !near_low)) && !near_pure) return result;
#endif
    // Largest s >= 1 with near + s span inside the premultiplied cube 0 <= rgb <= alpha <= 1.
    float reach = 1e6;
    for (int c = 0; c < 4; ++c) {
        float step = span[c] - (c < 3 ? span.a : 0.0);
        float room_up = (c < 3 ? near.a : 1.0) - near[c];
        float up = step > 1e-9 ? room_up / step : 1e6;
        float down = span[c] < -1e-9 ? -near[c] / span[c] : 1e6;
        reach = min(reach, min(up, down));
    }
    reach = max(reach, 1.0);
    float cube_reach = reach;
    // A flat colour of O beyond the extreme, on its line, is the feature's ink.
    float nearest = 1e6;
    for (int i = 0; i < palette_size; ++i) {
        vec4 offset = vec4(palette[i], 1.0) - near;
        float along = dot(offset, direction);
        float off_line = dot(offset, offset) - along * along;
        if (along > t_far * (1.0 + RIDGE_MARGIN) && off_line < INK_LINE_TOLERANCE * INK_LINE_TOLERANCE)
            nearest = min(nearest, along / len);
    }
    if (nearest < 1e5) reach = min(nearest, reach);
#if !TO_CUBE
    else return result;
#endif
#if BACKED_OR_SEEN
    // Over a lossless photo: against a flat colour of O, or towards a pure colour O shows.
    bool tested = true;
#else
    bool tested = !(reach > MIN_REACH);
#endif
    if (tested) {
        // The extreme is the ink itself, unless O shows the pure colour: a flat colour
        // stopped the extension, or the cube's point is one of O's inks.
        bool seen = nearest < 1e5 && nearest <= cube_reach;
        vec3 pure_encoded = encoded_of(near + reach * span);
#if INK_SLOTS > 0
        for (int i = 0; i < INK_SLOTS; ++i) {
            vec3 miss = abs(pure_encoded - inks[i]);
            seen = seen || max(max(miss.r, miss.g), miss.b) <= INK_TOLERANCE;
        }
#endif
        if (!(reach > MIN_REACH) && (!seen || !(reach > SHORT_REACH))) return result;
#if BACKED_OR_SEEN
        if (!seen && !near_pure) return result;
#endif
    }
#if PURE_GATE
    reach = 1.0 + gate * (reach - 1.0);
#endif
    result.extended = true;
    result.colour = near + reach * span;
    // At an end of O's key range the extreme is read with the table clamped there (a dark
    // paper, not unseen ink: spec/pure_colours.extend_extreme).
#if CLAMP_ENDS
    bvec3 low_end = lessThanEqual(far_keys, key_low + RANGE_TOLERANCE);
    bvec3 high_end = greaterThanEqual(far_keys, key_high - RANGE_TOLERANCE);
#else
    bvec3 low_end = bvec3(false), high_end = bvec3(false);
#endif
    result.filtered = filtered_colour_clamped(result.colour, low_end, high_end);
    return result;
}
