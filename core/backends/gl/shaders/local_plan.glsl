// The local plan's factor of beta, in three passes over the whole image, each reading the
// last (LOCAL_PASS 1, 2, 3): O's flat pixels, their sums along rows, then the sums along
// columns, the region's flat share, the pixel's drawn ink (read from O) and the factor.
// DRAWN_INK and INK_GATE (pass 3): the drawn ink counts as hard-edged for the strength, and
// opens the gate of pure colours too. Defines, not uniforms: without one, its counts are not
// compiled into the 49-texel loop, which llvmpipe runs line by line for every pixel whose F
// varies (the 4096 x 4096 photo pair's pass 3 without the gate, pass clock, three processes
// of each in turn: 0.41-0.50 -> 0.34-0.46 s).
// Twin: flat_pixels, flat_share, hard_edged_weight, ink_weight and LocalStrength.factor in
// aarecovery/spec/local_plan.py. With
// LOCAL_ENCODE the uploaded O is linear light and is sRGB-encoded first. With
// FACTOR_FOR_BETA, pass 3 counts no drawn ink where F is flat around the pixel (below).
// With KEPT_INK, pass 3 also gives the drawn ink's weight towards O where the gate leaves the
// ink out, times how fully F kept O's contrast (LocalStrength.kept_ink, kept_contrast).
// Needs colour.glsl.

// Pass 3's switches, off in passes 1 and 2 (which compile ink_weight but never call it).
#ifndef DRAWN_INK
#define DRAWN_INK 0
#endif
#ifndef INK_GATE
#define INK_GATE 0
#endif
#ifndef KEPT_INK
#define KEPT_INK 0
#endif
// The gate's count of the ink: for the gate, or for the kept ink towards O.
#if INK_GATE || KEPT_INK
#define GATE_INK 1
#else
#define GATE_INK 0
#endif

const float FLAT_SPAN = 0.5 / 255.0;
const int REGION_RADIUS = 8;
const float TEXTURED_SHARE = 0.1;
const float HARD_EDGED_SHARE = 0.3;
const int INK_RADIUS = 3;
const int INK_REPEATS = 3;
const float INK_NEAR_SPAN = 3.5 / 255.0;
const float INK_DARK = 5.5 / 255.0;
const float INK_TIE = 0.25 / 255.0;
const float INK_GATE_SHARE_LOW = 0.0;
const float INK_GATE_SHARE_HIGH = 0.3;
const int INK_GATE_REPEATS = 2;
const float INK_LUMA_SATURATION = 90.5 / 255.0;
const float INK_LUMA_DARK = 31.5 / 255.0;
const float LUMA_TIE = 0.00005 / 255.0;
const float KEPT_CONTRAST_LOW = 0.9;
const float KEPT_CONTRAST_HIGH = 1.05;
const float STEEPENED_CONTRAST_HIGH = 1.2;

uniform sampler2D original_image;  // O as uploaded (passes 1 and 3)
uniform sampler2D local_input;     // the previous pass's output (passes 2 and 3)
uniform float textured;            // the factor in textured regions (pass 3)
uniform vec2 ink_shares;           // the strength's ink shares, low and high: LocalStrength.ink_shares (pass 3)
uniform float ink_gate_span;       // within what the gate's ink recurs: FLAT_SPAN, wider on a JPEG (pass 3)
#if FACTOR_FOR_BETA || KEPT_INK
uniform sampler2D filtered_image;  // F as uploaded (pass 3)
#endif

vec3 original_encoded(ivec2 p, ivec2 size) {
    vec3 c = texelFetch(original_image, clamp(p, ivec2(0), size - 1), 0).rgb;
#if LOCAL_ENCODE
    c = linear_to_srgb(c);
#endif
    return c;
}

// 1 where the pixel holds drawn ink: an extreme of its 3 x 3 neighbourhood whose colour
// recurs exactly in the 7 x 7 square (its part inside the image), with few colours a few
// levels from it, and not near black; smooth in the pixel's share of that ink, at the
// strength's shares (.x) and at the gate's (.y), which counts recurrences within
// ink_gate_span: with INK_BY_LUMA (the span wider than FLAT_SPAN: a JPEG) by luma for ink
// neither saturated nor dark (local_plan.py: INK_LUMA_SATURATION). A define, not a test of
// the span: llvmpipe ran the luma arithmetic for every texel, and pass 3 took 1.5 times as
// long on a PNG photo.
vec2 ink_weight(ivec2 p, ivec2 size, bool needed) {
    vec3 brightest = vec3(0.0);
    vec3 darkest = vec3(0.0);
    float high = -1.0;
    float low = 4.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = original_encoded(p + ivec2(dx, dy), size);
            float b = c.r + c.g + c.b;
            // Sums within INK_TIE tie: the first in row order stays (local_plan.py says why).
            if (b > high + INK_TIE) { high = b; brightest = c; }
            if (b < low - INK_TIE) { low = b; darkest = c; }
        }
    }
#if INK_BY_LUMA
    vec2 top = vec2(max(brightest.r, max(brightest.g, brightest.b)), max(darkest.r, max(darkest.g, darkest.b)));
    vec2 bottom = vec2(min(brightest.r, min(brightest.g, brightest.b)), min(darkest.r, min(darkest.g, darkest.b)));
    bvec2 by_luma = bvec2(top.x - bottom.x <= INK_LUMA_SATURATION && top.x >= INK_LUMA_DARK,
                          top.y - bottom.y <= INK_LUMA_SATURATION && top.y >= INK_LUMA_DARK);
    vec2 ink_luma = vec2(dot(brightest, LUMA), dot(darkest, LUMA));
#endif
    // One read of the square counts both extremes' repeats (the counts are exact integers).
    ivec2 equal = ivec2(0);
    ivec2 near = ivec2(0);
#if GATE_INK
    ivec2 gate_equal = ivec2(0);
    ivec2 gate_near = ivec2(0);
#endif
    // Not needed: the loop ends at once (a test around it would still run it under a mask on
    // llvmpipe; a loop whose lanes have all left ends).
    for (int dy = -INK_RADIUS; dy <= INK_RADIUS && needed; ++dy) {
        for (int dx = -INK_RADIUS; dx <= INK_RADIUS; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;  // not there
            vec3 c = original_encoded(q, size);
            vec3 d0 = abs(c - brightest);
            vec3 d1 = abs(c - darkest);
            vec2 distance = vec2(max(d0.r, max(d0.g, d0.b)), max(d1.r, max(d1.g, d1.b)));
#if DRAWN_INK
            ivec2 is_near = ivec2(lessThanEqual(distance, vec2(INK_NEAR_SPAN)));
            ivec2 is_equal = ivec2(lessThanEqual(distance, vec2(FLAT_SPAN)));
            equal += is_equal;
            near += (1 - is_equal) * is_near;
#endif
#if GATE_INK
#if INK_BY_LUMA
            vec2 gate_distance = mix(distance, abs(vec2(dot(c, LUMA)) - ink_luma) - LUMA_TIE, by_luma);
#else
            vec2 gate_distance = distance;
#endif
            ivec2 is_gate_equal = ivec2(lessThanEqual(gate_distance, vec2(ink_gate_span)));
            gate_equal += is_gate_equal;
            gate_near += (1 - is_gate_equal) * ivec2(lessThanEqual(gate_distance, vec2(INK_NEAR_SPAN)));
#endif
        }
    }
    vec3 centre = original_encoded(p, size);
    vec2 weight = vec2(0.0);
    for (int side = 0; side < 2; ++side) {
        vec3 ink = side == 0 ? brightest : darkest;
        vec3 other = side == 0 ? darkest : brightest;
        // The strength's test, then the gate's (fewer recurrences, within its span).
        bool bright = max(ink.r, max(ink.g, ink.b)) > INK_DARK;
        bvec2 drawn = bvec2(DRAWN_INK != 0 && bright && 2 * near[side] <= equal[side] && equal[side] >= INK_REPEATS,
#if GATE_INK
                            bright && 2 * gate_near[side] <= gate_equal[side] && gate_equal[side] >= INK_GATE_REPEATS);
#else
                            false);
#endif
        vec3 across = other - ink;
        vec3 from_ink = centre - ink;
        float span = sqrt(across.r * across.r + across.g * across.g + across.b * across.b);
        float share = span > 0.0 ? 1.0 - sqrt(from_ink.r * from_ink.r + from_ink.g * from_ink.g
                                              + from_ink.b * from_ink.b) / span : 0.0;
        vec2 t = clamp((vec2(share) - vec2(ink_shares.x, INK_GATE_SHARE_LOW))
                       / vec2(ink_shares.y - ink_shares.x, INK_GATE_SHARE_HIGH - INK_GATE_SHARE_LOW), 0.0, 1.0);
        weight = max(weight, mix(vec2(0.0), t * t * (3.0 - 2.0 * t), drawn));
    }
    return weight;
}

#if LOCAL_PASS != 1
// The sum of local_input's 2 REGION_RADIUS + 1 values along the pixel's row (pass 2) or
// column (pass 3), those outside the image counting 0: whole numbers below 2^24, exact in
// any order. With REGION_GATHER (GL 4.0's
// textureGather) two texels a read: the 4096 x 4096 photo pair's pass 2 took 0.115 s with
// a texelFetch each, 0.078 s by pairs (pass clock, llvmpipe), the same sums.
float region_sum(ivec2 p, ivec2 size) {
    ivec2 axis = LOCAL_PASS == 2 ? ivec2(1, 0) : ivec2(0, 1);
    int along = LOCAL_PASS == 2 ? p.x : p.y;
    int length_ = LOCAL_PASS == 2 ? size.x : size.y;
    float count = 0.0;
#if REGION_GATHER
    vec2 texel = 1.0 / vec2(size);
    for (int d = -REGION_RADIUS; d < REGION_RADIUS; d += 2) {
        // The 2 x 2 texels from q (.w) along +x (.z) and +y (.x): the coordinate is their
        // shared corner, half a texel from where the choice of texels changes.
        ivec2 q = p + d * axis;
        vec4 quad = textureGather(local_input, vec2(q + 1) * texel);
        ivec2 at = ivec2(along + d, along + d + 1);
        vec2 inside = vec2(greaterThanEqual(at, ivec2(0))) * vec2(lessThan(at, ivec2(length_)));
        count += dot(LOCAL_PASS == 2 ? quad.wz : quad.wx, inside);
    }
    if (along + REGION_RADIUS < length_) count += texelFetch(local_input, p + REGION_RADIUS * axis, 0).r;
#else
    for (int d = -REGION_RADIUS; d <= REGION_RADIUS; ++d) {
        if (along + d >= 0 && along + d < length_) count += texelFetch(local_input, p + d * axis, 0).r;
    }
#endif
    return count;
}
#endif

#if KEPT_INK
// The largest channel's span of `image`'s 3 x 3 neighbourhood (borders replicated),
// sRGB-encoded with LOCAL_ENCODE.
float encoded_span(sampler2D image, ivec2 p, ivec2 size) {
    vec3 lowest = vec3(2.0);
    vec3 highest = vec3(-1.0);
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = texelFetch(image, clamp(p + ivec2(dx, dy), ivec2(0), size - 1), 0).rgb;
#if LOCAL_ENCODE
            c = linear_to_srgb(c);
#endif
            lowest = min(lowest, c);
            highest = max(highest, c);
        }
    }
    vec3 span = highest - lowest;
    return max(span.r, max(span.g, span.b));
}

// How fully F kept O's contrast around p, 0 to 1, full at KEPT_CONTRAST_HIGH (.x) and at
// STEEPENED_CONTRAST_HIGH (.y) (twin: kept_contrast).
vec2 kept_contrast(ivec2 p, ivec2 size) {
    float original_span = encoded_span(original_image, p, size);
    float ratio = original_span > 0.0 ? encoded_span(filtered_image, p, size) / original_span : 0.0;
    vec2 t = clamp((vec2(ratio) - KEPT_CONTRAST_LOW)
                   / (vec2(KEPT_CONTRAST_HIGH, STEEPENED_CONTRAST_HIGH) - KEPT_CONTRAST_LOW), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}
#endif

// Passes 1 and 2: their value in .x; pass 3: the factor and the gate of pure colours on drawn
// content only (LocalStrength.gate: the regions' weight, with ink_gate the larger of it and
// the drawn ink), and with KEPT_INK the kept ink towards O (LocalStrength.kept_ink; else 0).
vec3 local_plan(ivec2 p, ivec2 size) {
#if LOCAL_PASS == 1
    // Flat: the 3 x 3 neighbourhood (borders replicated) spans at most FLAT_SPAN in every
    // channel, and is not black.
    vec3 lowest = vec3(2.0);
    vec3 brightest = vec3(-1.0);
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = original_encoded(p + ivec2(dx, dy), size);
            lowest = min(lowest, c);
            brightest = max(brightest, c);
        }
    }
    vec3 span = brightest - lowest;
    bool flat_ = max(span.r, max(span.g, span.b)) <= FLAT_SPAN
                 && max(brightest.r, max(brightest.g, brightest.b)) > FLAT_SPAN;
    return vec3(flat_ ? 1.0 : 0.0, 0.0, 0.0);
#elif LOCAL_PASS == 2
    return vec3(region_sum(p, size), 0.0, 0.0);
#else
    float count = region_sum(p, size);
    ivec2 low = max(p - REGION_RADIUS, ivec2(0));
    ivec2 high = min(p + REGION_RADIUS, size - 1);
    float inside = float((high.x - low.x + 1) * (high.y - low.y + 1));
    float t = clamp((count / inside - TEXTURED_SHARE) / (HARD_EDGED_SHARE - TEXTURED_SHARE), 0.0, 1.0);
    float region = t * t * (3.0 - 2.0 * t);
    bool needed = true;
#if FACTOR_FOR_BETA
    // The factor only multiplies beta (no pure colours' gate, nor towards O, read it), and
    // where F is flat around the pixel its edge strength, and so beta, is exactly 0: the ink
    // there changes nothing, and its 49 texels are not read (the factor there is not the
    // specification's; nothing reads it). Equal uploaded texels are equal working values.
    vec4 filtered_here = texelFetch(filtered_image, p, 0);
    bool filtered_flat = true;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec4 neighbour = texelFetch(filtered_image, clamp(p + ivec2(dx, dy), ivec2(0), size - 1), 0);
            filtered_flat = filtered_flat && all(equal(neighbour, filtered_here));
        }
    }
    needed = !filtered_flat;
#endif
    // The ink is at most 1: at a full region weight it changes neither value.
    vec2 ink = (DRAWN_INK != 0 || GATE_INK != 0) && region < 1.0 ? ink_weight(p, size, needed) : vec2(0.0);
    float weight = DRAWN_INK != 0 ? max(region, ink.x) : region;
    float gate = INK_GATE != 0 ? max(region, ink.y) : region;
#if KEPT_INK
    vec2 kept = kept_contrast(p, size);
    float kept_ink = max(max(region, ink.y) * kept.x, kept.y);
#else
    float kept_ink = 0.0;
#endif
    return vec3(textured + (1.0 - textured) * weight, gate, kept_ink);
#endif
}
