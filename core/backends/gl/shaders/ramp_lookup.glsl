// The ramp lookup: the filter's table averaged across each pixel where O is a ramp, added to
// a straight sRGB-encoded result as far as the model did not act, where F is not flat; the
// pass ramp_lookup.frag (.comp) over F's active blocks after the Jacobi steps. Twin: ramp_slopes,
// ramp_delta and ramp_lookup in aarecovery/spec/ramp_lookup.py, which explains the rule and
// its measurements; the lookup acts only where F varies (working.glsl's filtered_varies, the
// twin's _varies). Needs working.glsl (colour, neighbourhood and F as uploaded, filtered_image);
// O must be uploaded sRGB-encoded (the plan takes no ramp lookup for linear inputs).
#include "transfer_table.glsl"

const int RAMP_SAMPLES = 3;
const float RAMP_BEND = 1.0 / 255.0;

uniform sampler2D original_image;  // O as uploaded: straight, sRGB-encoded
uniform sampler2D transfer_bends;  // 256 x 1: the table's bends summed from its first bin (table_bends)

ivec3 bend_low_bins(vec3 keys) {
    return max(ivec3(floor(clamp(keys * 256.0 - 0.5, 0.0, 255.0))) - 1, ivec3(0));
}

ivec3 bend_high_bins(vec3 keys) {
    return ivec3(ceil(clamp(keys * 256.0 - 0.5, 0.0, 255.0)));
}

// The table's bends between the lowest and the highest of a pixel's sample keys (_bend_between).
float bend_between(vec3 low_keys, vec3 high_keys) {
    ivec3 low = bend_low_bins(low_keys);
    ivec3 high = bend_high_bins(high_keys);
#if TABLE_KEY == 0
    float red = texelFetch(transfer_bends, ivec2(high.r, 0), 0).r - texelFetch(transfer_bends, ivec2(low.r, 0), 0).r;
    float green = texelFetch(transfer_bends, ivec2(high.g, 0), 0).g - texelFetch(transfer_bends, ivec2(low.g, 0), 0).g;
    float blue = texelFetch(transfer_bends, ivec2(high.b, 0), 0).b - texelFetch(transfer_bends, ivec2(low.b, 0), 0).b;
    return max(red, max(green, blue));
#elif SCALE_KEY || SHIFT_KEY
    return texelFetch(transfer_bends, ivec2(high.r, 0), 0).r - texelFetch(transfer_bends, ivec2(low.r, 0), 0).r;
#else
    vec3 spans = texelFetch(transfer_bends, ivec2(high.r, 0), 0).rgb - texelFetch(transfer_bends, ivec2(low.r, 0), 0).rgb;
    return max(spans.r, max(spans.g, spans.b));
#endif
}

vec3 minmod(vec3 a, vec3 b) {
    return mix(vec3(0.0), sign(a) * min(abs(a), abs(b)), greaterThan(a * b, vec3(0.0)));
}

vec3 clipped_transfer(vec3 encoded) {
    return clamp(transfer_encoded(encoded, key_values(encoded)), 0.0, 1.0);
}

// Whether pixel p takes the lookup: O opaque around it, a ramp in some channel, and the
// table bending between its samples' keys; with O's colour and slopes there (ramp_delta).
bool ramp_takes(ivec2 p, ivec2 size, out vec3 centre, out vec3 along_x, out vec3 along_y) {
    vec4 middle = texelFetch(original_image, p, 0);
    vec4 north = texelFetch(original_image, clamp_to_image(p + ivec2(0, -1), size), 0);
    vec4 west = texelFetch(original_image, clamp_to_image(p + ivec2(-1, 0), size), 0);
    vec4 east = texelFetch(original_image, clamp_to_image(p + ivec2(1, 0), size), 0);
    vec4 south = texelFetch(original_image, clamp_to_image(p + ivec2(0, 1), size), 0);
    centre = middle.rgb;
    along_x = minmod(east.rgb - centre, centre - west.rgb);
    along_y = minmod(south.rgb - centre, centre - north.rgb);
    bool opaque = min(min(middle.a, north.a), min(min(west.a, east.a), south.a)) >= 1.0;
    if (!opaque || (all(equal(along_x, vec3(0.0))) && all(equal(along_y, vec3(0.0))))) return false;
    // Every sample lies within `reach` of O per channel, and every key rises with each channel.
    vec3 reach = (abs(along_x) + abs(along_y)) * abs(0.5 / float(RAMP_SAMPLES) - 0.5);
    vec3 low_corner = clamp(centre - reach, 0.0, 1.0);
    vec3 high_corner = clamp(centre + reach, 0.0, 1.0);
    return bend_between(key_values(low_corner), key_values(high_corner)) > RAMP_BEND;
}

// The table's mean across the pixel less f(O), for a pixel that takes the lookup.
vec3 ramp_average(vec3 centre, vec3 along_x, vec3 along_y) {
    vec3 total = vec3(0.0);
    // v (rows) outer, u (columns) inner: the specification's order of the sum.
    for (int j = 0; j < RAMP_SAMPLES; ++j) {
        float v = (float(j) + 0.5) / float(RAMP_SAMPLES) - 0.5;
        for (int i = 0; i < RAMP_SAMPLES; ++i) {
            float u = (float(i) + 0.5) / float(RAMP_SAMPLES) - 0.5;
            total += clipped_transfer(clamp(centre + along_x * u + along_y * v, 0.0, 1.0));
        }
    }
    return total * (1.0 / float(RAMP_SAMPLES * RAMP_SAMPLES)) - clipped_transfer(centre);
}

// The table's mean across the pixel less f(O) (ramp_delta); 0 where it takes no lookup.
vec3 ramp_delta(ivec2 p, ivec2 size) {
    vec3 centre, along_x, along_y;
    if (!ramp_takes(p, size, centre, along_x, along_y)) return vec3(0.0);
    return ramp_average(centre, along_x, along_y);
}

// A straight result with the ramp lookup's `delta` added by the model's confidence `beta`
// (ramp_lookup).
vec4 ramp_added(vec4 straight, vec3 delta, float beta) {
    return vec4(clamp(straight.rgb + (1.0 - beta) * delta, 0.0, 1.0), straight.a);
}
