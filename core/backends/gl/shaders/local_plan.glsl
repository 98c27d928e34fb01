// The local plan's factor of beta, in three passes over the whole image, each reading the
// last (LOCAL_PASS 1, 2, 3): O's flat pixels, their sums along rows, then the sums along
// columns, the region's flat share and the factor. Twin: flat_pixels, flat_share,
// hard_edged_weight and LocalStrength.factor in aarecovery/spec/local_plan.py. With
// LOCAL_ENCODE the uploaded O is linear light and is sRGB-encoded first. Needs colour.glsl.

const float FLAT_SPAN = 0.5 / 255.0;
const int REGION_RADIUS = 8;
const float TEXTURED_SHARE = 0.1;
const float HARD_EDGED_SHARE = 0.3;

uniform sampler2D original_image;  // O as uploaded (pass 1)
uniform sampler2D local_input;     // the previous pass's output (passes 2 and 3)
uniform float textured;            // the factor in textured regions (pass 3)

float local_plan(ivec2 p, ivec2 size) {
#if LOCAL_PASS == 1
    // Flat: the 3 x 3 neighbourhood (borders replicated) spans at most FLAT_SPAN in every
    // channel, and is not black.
    vec3 lowest = vec3(2.0);
    vec3 brightest = vec3(-1.0);
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = texelFetch(original_image, clamp(p + ivec2(dx, dy), ivec2(0), size - 1), 0).rgb;
#if LOCAL_ENCODE
            c = linear_to_srgb(c);
#endif
            lowest = min(lowest, c);
            brightest = max(brightest, c);
        }
    }
    vec3 span = brightest - lowest;
    bool flat_ = max(span.r, max(span.g, span.b)) <= FLAT_SPAN
                 && max(brightest.r, max(brightest.g, brightest.b)) > FLAT_SPAN;
    return flat_ ? 1.0 : 0.0;
#elif LOCAL_PASS == 2
    // Counts are whole numbers below 2^24: float sums are exact, in any order.
    float count = 0.0;
    for (int d = -REGION_RADIUS; d <= REGION_RADIUS; ++d) {
        int x = p.x + d;
        if (x >= 0 && x < size.x) count += texelFetch(local_input, ivec2(x, p.y), 0).r;
    }
    return count;
#else
    float count = 0.0;
    for (int d = -REGION_RADIUS; d <= REGION_RADIUS; ++d) {
        int y = p.y + d;
        if (y >= 0 && y < size.y) count += texelFetch(local_input, ivec2(p.x, y), 0).r;
    }
    ivec2 low = max(p - REGION_RADIUS, ivec2(0));
    ivec2 high = min(p + REGION_RADIUS, size - 1);
    float inside = float((high.x - low.x + 1) * (high.y - low.y + 1));
    float t = clamp((count / inside - TEXTURED_SHARE) / (HARD_EDGED_SHARE - TEXTURED_SHARE), 0.0, 1.0);
    float weight = t * t * (3.0 - 2.0 * t);
    return textured + (1.0 - textured) * weight;
#endif
}
